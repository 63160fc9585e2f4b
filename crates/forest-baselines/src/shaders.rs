//! The geometry renderer's WGSL modules: the runtime's common module (camera, helpers) first,
//! then this crate's types and stages.

use forest_render::passes::{
    COMMON_WGSL, COUNT_OFF_WGSL, ENVIRONMENT_WGSL, GROUND_WGSL, SHADOW_ON_WGSL,
};

/// Structs shared by the geometry renderer's modules.
pub const GEOMETRY_TYPES_WGSL: &str = include_str!("../shaders/geometry_types.wgsl");

/// WGSL of the full-geometry draw, reading the sun's shadow maps as group 2 (without
/// fragment counting; see
/// `forest_render::passes::counting_source`).
pub const GEOMETRY_DRAW_WGSL: [&str; 7] = [
    COMMON_WGSL,
    GEOMETRY_TYPES_WGSL,
    include_str!("../shaders/geometry_draw.wgsl"),
    GROUND_WGSL,
    ENVIRONMENT_WGSL,
    SHADOW_ON_WGSL,
    COUNT_OFF_WGSL,
];

/// The light views' casting pass (`shaders/geometry_cast.wgsl`), appended to
/// [`GEOMETRY_DRAW_WGSL`].
pub const GEOMETRY_CAST_WGSL: &str = include_str!("../shaders/geometry_cast.wgsl");

/// WGSL of the full-geometry culling.
pub const GEOMETRY_CULL_WGSL: [&str; 3] = [
    COMMON_WGSL,
    GEOMETRY_TYPES_WGSL,
    include_str!("../shaders/geometry.wgsl"),
];
