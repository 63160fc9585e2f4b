//! The runtime of the quad-stream forest renderer (Liu, Hua & Bao 2010) on wgpu.
//!
//! ```text
//! SpeciesData::load (atlases) + Forest ─► GpuScene (uploaded once) ─► QuadStream
//! per frame: set_camera (the one upload) ─► encode: cull ─► refine × (l − 1) ─► draw
//! ```
//! [`reference`] computes passes 1 and 2 on the CPU over the same tables; tests require the
//! GPU's stream to equal it quad for quad. The rival methods (full geometry, stochastic
//! simplification, discrete LODs + billboards, the hybrid) live in the `forest-baselines`
//! crate, which builds on this one.

pub mod camera;
pub mod capacity;
pub mod context;
pub mod error;
pub mod forms;
pub mod frame;
pub mod gpu_types;
pub mod opacity;
pub mod options;
pub mod passes;
pub mod reference;
pub mod scene;
pub mod stats;
pub mod stream;
pub mod target;
pub mod terrain;
pub mod work;

pub use camera::Camera;
pub use context::{ColourFormat, GpuContext, RenderError};
pub use frame::{FrameParams, Targets};
pub use options::{Background, DebugView, RendererOptions, StreamOptions};
pub use scene::{GpuScene, SpeciesData};
pub use stats::FrameStats;
pub use stream::QuadStream;
