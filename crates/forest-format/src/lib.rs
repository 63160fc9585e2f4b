//! On-disk formats and GPU-facing plain-old-data types of the quad-stream forest renderer.
//!
//! This crate is shared by the offline bake (`preprocess/`) and the wgpu runtime, and has no
//! wgpu dependency. It defines:
//! - [`node::QuadNode`]: one node of a slab image's quad hierarchy, exactly as the GPU reads it;
//! - [`directions`]: the sampling directions over the upper hemisphere, their triangulation and
//!   the barycentric blend of the 1–3 directions around a view direction;
//! - [`slab`]: the image-space conventions that map a slab pixel back to object space;
//! - [`shading`]: the one shading model every renderer of the project uses;
//! - [`atlas`]: the baked atlas (manifest, colour, nodes), its atomic writer and checked loader;
//! - [`forest`], [`terrain`]: forest files and the height field the trees stand on (the
//!   generator and the named views live in `forest-scene`);
//! - [`camera_path`]: recorded camera paths for the viewer;
//! - [`model`]: a species' prepared model for the geometry-based methods and the hybrid.
//! - [`cutout`]: convex polygons in texture space that trim alpha-tested cards.
//!
//! The one shading model, without a GPU or any file, lit at eight in the morning:
//!
//! ```
//! use forest_format::shading::Lighting;
//!
//! // A leaf facing the morning sun is brighter than one facing away.
//! let light = Lighting::at_hour(8.0, 65.0);
//! let leaf = glam::Vec3::new(0.2, 0.4, 0.1);
//! let lit = light.shade(leaf, light.sun_dir, 1.0, 1.0, 0.0);
//! let away = light.shade(leaf, -light.sun_dir, 1.0, 1.0, 0.0);
//! assert!(lit.length() > away.length());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![deny(missing_docs)]

pub mod atlas;
pub mod atomic;
pub mod bounded;
pub mod camera_path;
pub mod colour;
pub mod cutout;
pub mod directions;
pub mod error;
pub mod forest;
pub mod limits;
pub mod model;
pub mod node;
pub mod nodes_codec;
pub mod noise;
pub mod opacity;
pub mod results_csv;
pub mod shading;
pub mod slab;
pub mod species;
pub mod terrain;
pub mod trim;
pub mod wind;

pub use atlas::{Atlas, AtlasManifest, BakeParams, ColourEncoding, PlaneFit};
pub use error::FormatError;
pub use node::QuadNode;
