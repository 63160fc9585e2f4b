//! The geometry renderer's WGSL modules: the runtime's common module (camera, helpers) first,
//! then this crate's types and stages.

use forest_render::passes::{
    COMMON_WGSL, COUNT_OFF_WGSL, ENVIRONMENT_WGSL, GROUND_WGSL, SHADOW_OFF_WGSL,
};

/// Structs shared by the geometry renderer's modules.
pub const GEOMETRY_TYPES_WGSL: &str = include_str!("../shaders/geometry_types.wgsl");

/// WGSL of the full-geometry draw (without fragment counting; see
/// `forest_render::passes::counting_source`).
pub const GEOMETRY_DRAW_WGSL: [&str; 7] = [
    COMMON_WGSL,
    GEOMETRY_TYPES_WGSL,
    include_str!("../shaders/geometry_draw.wgsl"),
    GROUND_WGSL,
    ENVIRONMENT_WGSL,
    SHADOW_OFF_WGSL,
    COUNT_OFF_WGSL,
];

/// WGSL of the full-geometry culling.
pub const GEOMETRY_CULL_WGSL: [&str; 3] = [
    COMMON_WGSL,
    GEOMETRY_TYPES_WGSL,
    include_str!("../shaders/geometry.wgsl"),
];
