//! The rival methods, drawn by the same runtime as the quad stream (`forest-render`) so that
//! every comparison shares the scene, the camera and the targets:
//!
//! - [`geometry`]: full geometry (the ground-truth reference when supersampled, the
//!   brute-force baseline at 1×), stochastic simplification (Cook et al. 2007) and discrete
//!   LODs + billboards, drawn from the species' prepared models (which the bake writes into
//!   each atlas, [`forest_format::model`]: this crate needs neither the models nor the bake);
//! - [`hybrid`]: the nearest trees as geometry, the rest as the quad stream;
//! - [`methods`]: every method behind one run-time switch.
//!
//! The paper's method itself lives in `forest-render`, which depends on nothing here.
//!
//! The supersampled reference of a forest, drawn from its species' own models (`no_run`: it
//! needs a GPU adapter, lavapipe will do, and the files):
//!
//! ```no_run
//! use forest_baselines::{GeometryRenderer, GeometrySpecies, MeshMethod, PreparedGeometry};
//! use forest_format::forest::Forest;
//! use forest_render::{Camera, ForestView, GpuContext, RendererOptions, SpeciesData};
//!
//! let ctx = GpuContext::headless()?;
//! let forest = Forest::load("f.forest".as_ref())?;
//! let oak = SpeciesData::load("oak.atlas".as_ref())?;
//! // The prepared model `forest bake` wrote into the atlas folder.
//! let model = forest_format::model::PreparedModel::load("oak.atlas".as_ref())?
//!     .ok_or("oak.atlas has no prepared model")?;
//! let species = GeometrySpecies::new(model.into(), &oak.atlas.manifest);
//! let prepared = PreparedGeometry::new(&[species]);
//! let (w, h) = (4 * 400, 4 * 300);
//! let opts = RendererOptions { viewport: (w, h), ..Default::default() };
//! let mut geometry = GeometryRenderer::with_targets(&ctx, &prepared, &forest, &opts)?;
//! geometry.set_method(&ctx, MeshMethod::Reference)?;
//! let camera = Camera {
//!     eye: glam::Vec3::new(0.0, 1.7, -30.0),
//!     target: glam::Vec3::new(0.0, 3.0, 0.0),
//!     fov_y_deg: 60.0,
//!     near: 0.1,
//!     far: 5000.0,
//!     viewport: (w, h),
//!     epsilon: 16.0,
//! };
//! let target = forest_render::target::Target::new(&ctx, w, h);
//! geometry.render_frame(&ctx, &camera, &target)?;
//! // Box-filter the 4×4 samples down to 400×300 for the reference image.
//! let image = image::imageops::thumbnail(&target.read(&ctx), 400, 300);
//! image.save("reference.png")?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![deny(missing_docs)]

pub mod geometry;
pub mod gpu_types;
pub mod hybrid;
pub mod methods;
pub mod shaders;

pub use geometry::{GeometryRenderer, GeometrySpecies, GpuModels, MeshMethod, PreparedGeometry};
pub use hybrid::{Hybrid, Near};
pub use methods::{ForestRenderer, Method, MethodStats};
