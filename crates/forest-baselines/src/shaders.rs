//! The geometry renderer's WGSL modules, composed with the runtime's
//! ([`forest_render::shaders::Composer`]): each file names what it imports (`common` for the
//! camera and helpers, `environment`, the `shadow` and `count` slots).

use forest_render::shaders::Composer;

/// Structs and level-of-detail functions shared by the geometry renderer's modules
/// (module `geometry_types`).
pub const GEOMETRY_TYPES_WGSL: &str = include_str!("../shaders/geometry_types.wgsl");
/// The full-geometry culling (module `geometry`).
pub const GEOMETRY_CULL_WGSL: &str = include_str!("../shaders/geometry.wgsl");
/// The full-geometry draw, reading the sun's shadow maps as group 2 (module `geometry_draw`).
pub const GEOMETRY_DRAW_WGSL: &str = include_str!("../shaders/geometry_draw.wgsl");
/// The light views' casting pass (module `geometry_cast`, importing the draw).
pub const GEOMETRY_CAST_WGSL: &str = include_str!("../shaders/geometry_cast.wgsl");

/// The runtime's modules with the geometry renderer's.
pub fn composer() -> Composer<'static> {
    Composer::runtime()
        .with_module("geometry_types", GEOMETRY_TYPES_WGSL)
        .with_module("geometry", GEOMETRY_CULL_WGSL)
        .with_module("geometry_draw", GEOMETRY_DRAW_WGSL)
        .with_module("geometry_cast", GEOMETRY_CAST_WGSL)
}

/// The culling module's source.
pub fn cull_source() -> String {
    composer().composed(&["geometry"])
}

/// The draw module's source (without fragment counting).
pub fn draw_source() -> String {
    composer().composed(&["geometry_draw"])
}

/// The draw module's source with the fragment-count hooks that count.
pub fn counting_draw_source() -> String {
    composer()
        .fill("count", "count_on")
        .composed(&["geometry_draw"])
}

/// The light views' casting module's source (the draw with the casting pass).
pub fn cast_source() -> String {
    composer().composed(&["geometry_cast"])
}
