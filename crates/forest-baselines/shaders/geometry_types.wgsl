// Types and level-of-detail functions of the geometry-based methods (full geometry,
// stochastic simplification, discrete LODs + billboards), shared by geometry.wgsl (cull) and
// geometry_draw.wgsl. Host mirrors: forest_format::model::RefVertex, forest_render::gpu_types::Geo*,
// and the pure functions of forest_bake::lod (lambda, area_scale, fade, lambda_band,
// band_lambda, band_elements), which the tests check against this code's results.

struct GeoVertex {
    pos: vec3<f32>,
    // Sky visibility of the side `normal` faces (the front) at this corner.
    sky_front: f32,
    normal: vec3<f32>,
    material: u32,
    uv: vec2<f32>,
    // Leaf rank in the species' shuffled order; NONE for branches and LOD 1/2 vertices.
    element: u32,
    // Sky visibility of the back side.
    sky_back: f32,
}

struct GeoMaterial {
    // rgb: Kd (linear); a: translucency.
    kd: vec4<f32>,
    // Texture layer (NONE: none), alpha tested (0/1).
    layer: u32,
    alpha_tested: u32,
    pad: vec2<u32>,
}

struct GeoSpecies {
    // Bounding sphere (object space): centre, radius.
    sphere: vec4<f32>,
    // First vertex of LOD 0, 1, 2; w: first billboard layer.
    lod_first: vec4<u32>,
    // Vertex counts of LOD 0, 1, 2; w: unused.
    lod_count: vec4<u32>,
    // Branch vertices at the start of LOD 0, leaves N, offset into leaf_end / leaf_centre.
    branch_vertices: u32,
    leaves: u32,
    leaf_base: u32,
    // r of the area-preservation factor.
    r: f32,
    // Mean shaded leaf colour (linear) for contrast preservation.
    mean_leaf: vec3<f32>,
    // The hybrid's switch unit (forest_render::forms::switch_unit): metres of switch distance
    // per focal pixel at scale 1.
    switch_unit: f32,
    // Optical depth per voxel length of the opacity-volume code 1.0 (0: no self-shadowing).
    opacity_depth: f32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

// The method and its parameters (forest_render::geometry::MeshMethod).
struct Method {
    // 0: full geometry, 1: stochastic simplification, 2: discrete LODs + billboards.
    mode: u32,
    // Nearest distance bands first (full geometry) and each tree's triangles in their
    // presorted front-to-back order (full geometry, LODs).
    depth_sort: u32,
    area: u32,
    contrast: u32,
    // Stochastic: d0 (m), ln ½ / ln h, fading width.
    d0: f32,
    exponent: f32,
    fade: f32,
    // Mip bias of the material textures' lookups: 0, or -16 (the finest level) for the
    // reference.
    texture_bias: f32,
    // LODs: distances (m) where LOD 1, LOD 2 and billboards start.
    lod: vec4<f32>,
}

const BANDS: u32 = 16u;

// A visible-list entry (geometry.wgsl's geo_scatter): the instance's index in its low
// VISIBLE_ID_BITS bits (forest_format::forest::MAX_INSTANCES fits), the order bin of the
// direction from the view's eye to it (order_bin) above them.
const VISIBLE_ID_BITS: u32 = 24u;
const VISIBLE_ID_MASK: u32 = 0xFFFFFFu;

// The bin of the object-space direction `v` from the eye to a tree (mirrors
// forest_baselines::geometry::order_bin): 8 azimuths × 3 elevation bands.
fn order_bin(v: vec3<f32>) -> u32 {
    let len = length(v);
    var u = vec3<f32>(1.0, 0.0, 0.0);
    if (len > 1e-12) { u = v / len; }
    let turns = atan2(u.z, u.x) / 6.283185307;
    let azimuth = u32(floor(turns * 8.0 + 8.5)) % 8u;
    var band = 1u;
    if (u.y < -0.5) { band = 0u; } else if (u.y > 0.5) { band = 2u; }
    return band * 8u + azimuth;
}

fn lod_lambda(m: Method, d: f32) -> f32 {
    if (d <= m.d0) { return 1.0; }
    let b = (m.d0 / d) * (m.d0 / d);
    return clamp(pow(b, m.exponent), 1e-9, 1.0);
}

fn lod_area_scale(r_in: f32, lambda: f32) -> f32 {
    if (lambda >= 1.0) { return 1.0; }
    let r = clamp(r_in, 1e-9, 1.0);
    let l = max(lambda, 1e-9);
    let s = (1.0 - pow(1.0 - r, 1.0 / l)) / r;
    return clamp(s, 1.0, 1.0 / l);
}

fn lod_fade(u: f32, lambda: f32, width: f32) -> f32 {
    let r = min(1.0 - lambda, width * lambda);
    if (r <= 0.0) { return select(0.0, 1.0, u < lambda); }
    return clamp((lambda + r - u) / (2.0 * r), 0.0, 1.0);
}

fn lambda_band(lambda: f32) -> u32 {
    let b = floor(-2.0 * log2(max(lambda, 1e-9)));
    return min(u32(max(b, 0.0)), BANDS - 1u);
}

fn band_lambda(k: u32) -> f32 {
    return exp2(-f32(k) / 2.0);
}

fn band_elements(k: u32, n: u32, width: f32) -> u32 {
    let f = min(band_lambda(k) * (1.0 + width), 1.0);
    return min(u32(ceil(f * f32(n))), n);
}

// Distance band of depth sorting: ⌊2·log2 d⌋ for d in [1, 256) m.
fn distance_band(d: f32) -> u32 {
    return min(u32(max(floor(2.0 * log2(max(d, 1.0))), 0.0)), BANDS - 1u);
}

// The draw band of a tree at object-space distance d (forest_render::geometry::cpu_band).
fn method_band(m: Method, d: f32) -> u32 {
    if (m.mode == 1u) { return lambda_band(lod_lambda(m, d)); }
    if (m.mode == 2u) {
        var lod = 0u;
        var start = 1.0;
        for (var k = 0u; k < 3u; k++) {
            if (d >= m.lod[k]) { lod = k + 1u; start = m.lod[k]; }
        }
        let sub = min(u32(max(floor(2.0 * log2(max(d / start, 1.0))), 0.0)), 3u);
        return lod * 4u + sub;
    }
    return select(0u, distance_band(d), m.depth_sort != 0u);
}
