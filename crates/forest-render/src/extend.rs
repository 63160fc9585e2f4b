//! The extension API: what a crate that adds a drawing form builds on. The baselines'
//! geometry renderer is one; it uses nothing of this crate beyond this module, the public
//! modules and the crate root.
//!
//! A form:
//! - implements [`crate::view::Form`] over a [`crate::view::FrameInputs`], which writes its
//!   camera uniform ([`crate::gpu_types::GpuCamera`], `struct Camera` in WGSL) and so gets
//!   every per-frame parameter;
//! - composes its WGSL with the runtime's modules ([`crate::shaders::Composer`]);
//! - lays out its bind groups with the runtime's helpers ([`Slot`], [`numbered`],
//!   [`layout_entries`]), reads the opacity volume ([`opacity_texture`], [`opacity_entry`])
//!   and the terrain ([`GpuTerrain`], [`heights_entry`], [`environment_uniform`]);
//! - receives the sun's shadows as the runtime's group 2 ([`receiver_layout`],
//!   [`receiver_entries`]) and casts into the cascades' maps ([`Caster`], [`ShadowTargets`],
//!   [`depth_pass`]);
//! - shares a forest with the quad stream in the hybrid ([`FORMS_QUADS`], [`FORMS_GEOMETRY`],
//!   [`GEOMETRY_ALWAYS`], [`switch_unit`]), each tree's share of each form mirrored on the CPU
//!   ([`quad_share`], [`lod_shares`] and their screen-door thresholds);
//! - checks what it allocates against the device ([`within_limit`], [`storage_limit`],
//!   [`GeometryCapacity`]) and reads its counters back as the stream does ([`StatsRing`],
//!   [`query_parts`]).

pub use crate::bindings::{Slot, layout_entries, numbered};
pub use crate::capacity::{BLOCK, GeometryCapacity, WG};
pub use crate::error::{storage_limit, within_limit};
pub use crate::forms::{
    DEFAULT_SWITCH_PIXELS, FORMS_GEOMETRY, FORMS_QUADS, GEOMETRY_ALWAYS, dither_threshold,
    form_threshold, instance_hash, lod_share, lod_shares, lod_threshold, quad_share, switch_unit,
};
pub use crate::opacity::{check_volumes, opacity_entry, opacity_texture};
pub use crate::passes::cast::cast_pipeline;
pub use crate::passes::draw::draw_pipeline;
pub use crate::receivers::{SHADOW_FORMAT, receiver_entries, receiver_layout};
pub use crate::scene::gpu_instances;
pub use crate::shadow_maps::{Caster, ShadowTargets, depth_pass};
pub use crate::stats::{StatsRing, query_parts};
pub use crate::terrain::{GpuTerrain, HEIGHTS_BINDING, environment_uniform, heights_entry};
