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
//! - [`forest`], [`generate`], [`terrain`]: forest files, the clumped-forest generator and the
//!   height field the trees stand on;
//! - [`camera_path`]: recorded camera paths for the viewer.

pub mod atlas;
pub mod atomic;
pub mod bounded;
pub mod camera_path;
pub mod directions;
pub mod error;
pub mod forest;
pub mod generate;
pub mod node;
pub mod nodes_codec;
pub mod opacity;
pub mod shading;
pub mod slab;
pub mod species;
pub mod terrain;
pub mod trim;

pub use atlas::{Atlas, AtlasManifest, BakeParams, ColourEncoding, PlaneFit};
pub use error::FormatError;
pub use node::QuadNode;
