//! The runtime of the quad-stream forest renderer (Liu, Hua & Bao 2010) on wgpu.
//!
//! ```text
//! SpeciesData::load (atlases) + Forest ─► GpuScene (uploaded once) ─► QuadStream
//! per frame: set_camera (the one upload) ─► encode: cull ─► refine × (l − 1) ─► draw
//! ```
//! [`reference`](mod@reference) computes passes 1 and 2 on the CPU over the same tables; tests
//! require the GPU's stream to equal it quad for quad. The rival methods (full geometry, stochastic
//! simplification, discrete LODs + billboards, the hybrid) live in the `forest-baselines`
//! crate, which builds on this one.
//!
//! One frame of a forest, headless (`no_run`: it needs a GPU adapter, lavapipe will do, and a
//! forest with its atlases; `forest-baselines`' `examples/embed` draws into a host's own pass):
//!
//! ```no_run
//! use forest_format::forest::Forest;
//! use forest_render::{Camera, GpuContext, GpuScene, QuadStream, RendererOptions, SpeciesData};
//! use glam::Vec3;
//!
//! let ctx = GpuContext::headless()?;
//! let forest = Forest::load("f.forest".as_ref())?;
//! let species = forest
//!     .species
//!     .iter()
//!     .map(|s| SpeciesData::load(s.as_ref()))
//!     .collect::<Result<Vec<_>, _>>()?;
//! let scene = GpuScene::new(&ctx, &species, &forest)?;
//! let opts = RendererOptions { viewport: (800, 600), ..Default::default() };
//! let mut stream = QuadStream::new(&ctx.device, scene, &opts)?;
//! let target = forest_render::target::Target::new(&ctx, 800, 600);
//! let camera = Camera {
//!     eye: Vec3::new(0.0, 1.7, -30.0),
//!     target: Vec3::new(0.0, 3.0, 0.0),
//!     fov_y_deg: 60.0,
//!     near: 0.1,
//!     far: 5000.0,
//!     viewport: (800, 600),
//!     epsilon: 16.0,
//! };
//! let stats = stream.render_fitted(&ctx, &camera, &target)?;
//! println!("{} quads", stats.quads);
//! target.read(&ctx).save("forest.png")?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![deny(missing_docs)]

// The public modules are what a host uses; `extend` is what a crate adding a drawing form
// builds on. The rest (GPU resources, passes, receivers) is private.
mod bindings;
pub mod camera;
mod capacity;
pub mod context;
pub mod error;
pub mod extend;
mod forms;
pub mod fragments;
pub mod frame;
pub mod gpu_types;
pub mod load;
mod opacity;
pub mod options;
mod passes;
mod receivers;
pub mod reference;
pub mod scene;
pub mod shaders;
pub mod shadow;
mod shadow_maps;
pub mod stats;
pub mod stream;
mod stream_buffers;
pub mod target;
mod terrain;
pub mod view;
pub mod work;

// The crate's own tests name it as its users do.
#[cfg(test)]
extern crate self as forest_render;
#[cfg(test)]
mod layout_tests;

pub use camera::Camera;
pub use capacity::{Capacity, CapacityInput, MAX_QUADS};
pub use context::{ColourFormat, GpuContext, RenderError};
pub use forms::DEFAULT_SWITCH_PIXELS;
pub use frame::{FrameParams, Targets};
pub use load::{load_scene, named_view, start_view};
pub use options::{Background, DebugView, RendererOptions, StreamOptions};
pub use scene::{GpuScene, SpeciesData};
pub use stats::FrameStats;
pub use stream::QuadStream;
pub use view::{ForestView, Form, FrameInputs};
