// Types of the full-geometry renderer, shared by geometry.wgsl (cull) and geometry_draw.wgsl.
// Host mirrors: forest_bake::RefVertex and the structs in crates/forest-render/src/geometry.rs.

struct GeoVertex {
    pos: vec3<f32>,
    sun_visibility: f32,
    normal: vec3<f32>,
    material: u32,
    uv: vec2<f32>,
    pad: vec2<f32>,
}

struct GeoMaterial {
    // rgb: Kd (linear); a: translucency.
    kd: vec4<f32>,
    // Texture layer (NONE: none), alpha tested (0/1).
    layer: u32,
    alpha_tested: u32,
    pad: vec2<u32>,
}

struct Light {
    sun_dir: vec4<f32>,
    sun: vec4<f32>,
    sky: vec4<f32>,
    ground: vec4<f32>,
}

