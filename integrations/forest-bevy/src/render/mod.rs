//! The render world's side: the forests and cameras extracted each frame, one GPU scene (and
//! its models, for the model methods) per forest asset on Bevy's own device, one prepared
//! renderer per (camera, forest), and the draw in the `Core3d` schedule after the main opaque
//! pass.
//!
//! ```text
//! ExtractSchedule  extract          forests (asset, world_from_forest), cameras, sun, ambient
//! Render/Prepare   prepare_forests  GpuScene per asset (and GpuModels, once a view draws a
//!                                   model method); per view: renderer (re)built for the
//!                                   view's format, MSAA, depth and size; camera written
//! Core3d           cast_forests     after Bevy's shadow passes: each cascade's light-view
//!                                   stream drawn depth-only into its layer
//! Core3d/MainPass  draw_forests     cull + refine, then quads (blended) and their opaque
//!                                   depth into the view's target, before transparent meshes
//! ```
//! (`extract.rs`, `prepare.rs`, `draw.rs`.)

mod draw;
mod extract;
mod prepare;

pub use draw::{cast_forests, draw_forests};
pub use extract::{Extracted, ExtractedForest, ExtractedForestCamera, extract};
pub use prepare::{ForestRenderState, prepare_forests};
