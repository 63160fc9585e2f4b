// Types and level-of-detail functions of the geometry-based methods (full geometry,
// stochastic simplification, discrete LODs + billboards), shared by geometry.wgsl (cull) and
// geometry_draw.wgsl. Host mirrors: forest_format::model::RefVertex,
// forest_render::gpu_types::Geo*, and the pure functions of forest_bake::lod (lambda, area_scale,
// fade, lambda_band, band_lambda, band_elements), which the tests check against this code's
// results.

#import common

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
    // Where the hybrid draws its near trees in mesh LOD 1 and LOD 2, as fractions of the
    // switch distance (0: never; forest_baselines::geometry::GeometrySpecies::lod_from).
    lod1_from: f32,
    lod2_from: f32,
    pad0: u32,
    // The species' colours in the forest (tint.wgsl).
    colour: TreeColour,
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

// Whether the hybrid draws a species' near trees in its mesh LODs this frame: under full
// geometry (mode 0) with a switch (forms: neither the quad stream alone nor geometry alone)
// and a measured start for LOD 1 or 2.
fn lod_bands_on(m: Method, forms: vec4<f32>, sp: GeoSpecies) -> bool {
    return m.mode == 0u && (sp.lod1_from > 0.0 || sp.lod2_from > 0.0)
        && forms.x < 3.0e38 && (forms.x > 0.0 || forms.y > 0.0);
}

// The shares of a tree's mesh LODs 1 and 2 and coarser (forest_render::forms::lod_shares):
// LOD k draws the pixels whose lod_threshold lies in [c(k+1), c(k)), c = (WEIGHT_ONE, x, y, 0).
// (0, 0) outside the hybrid's LOD bands: LOD 0 draws every pixel.
fn lod_shares(m: Method, forms: vec4<f32>, sp: GeoSpecies, d: f32, unit: f32, id: u32)
    -> vec2<u32> {
    if (!lod_bands_on(m, forms, sp)) { return vec2<u32>(0u); }
    let c2 = lod_share(forms, d, unit, id, sp.lod2_from);
    let c1 = max(lod_share(forms, d, unit, id, sp.lod1_from), c2);
    return vec2<u32>(c1, c2);
}

// The share range [lo, hi) of mesh LOD k (0 to 2) of a tree with lod_shares `c`.
fn lod_range(k: u32, c: vec2<u32>) -> vec2<u32> {
    let bounds = array<u32, 4>(WEIGHT_ONE, c.x, c.y, 0u);
    return vec2<u32>(bounds[k + 1u], bounds[k]);
}

// The mesh LOD of a species' vertex `vi` (its index in the vertex buffer).
fn vertex_lod(sp: GeoSpecies, vi: u32) -> u32 {
    if (vi >= sp.lod_first.z) { return 2u; }
    return select(0u, 1u, vi >= sp.lod_first.y);
}

// Under the hybrid's LOD bands, the draw band of mesh LOD `k` of a tree at object-space
// distance d, with the switch at s (object-space metres): LOD 0 in bands 0 to 7 from the eye
// to the next LOD's start, LOD 1 in 8 to 11 and LOD 2 in 12 to 15 up to the next start (the
// switch for LOD 2), each split evenly: nearest first for the depth test, one LOD per band.
fn lod_band(k: u32, d: f32, s: f32, sp: GeoSpecies) -> u32 {
    let starts = array<f32, 4>(0.0, sp.lod1_from, sp.lod2_from, 1.0);
    var end = 1.0;
    for (var j = 2u; j > k; j--) {
        if (starts[j] > 0.0) { end = starts[j]; }
    }
    let start = starts[k] * s;
    let n = select(4.0, 8.0, k == 0u);
    let sub = u32(clamp(floor(n * (d - start) / max(end * s - start, 1e-6)), 0.0, n - 1.0));
    return select(4u + 4u * k, 0u, k == 0u) + sub;
}

// The mesh LOD a band of a species under the hybrid's LOD bands draws (lod_band).
fn band_lod(band: u32) -> u32 {
    if (band < 8u) { return 0u; }
    return select(2u, 1u, band < 12u);
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
