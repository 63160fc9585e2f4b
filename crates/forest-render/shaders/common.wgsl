// Types and helpers shared by every pass. Every pass's module imports it.
// Host mirrors: crates/forest-render/src/gpu_types.rs (layouts checked by a naga test).

struct Camera {
    view_proj: mat4x4<f32>,
    // Eye position (world, metres).
    eye: vec3<f32>,
    // The refinement threshold ε, in pixels.
    epsilon: f32,
    // Unit view direction (world).
    forward: vec3<f32>,
    // The far span K, in units of ε: a tree narrower than K·ε pixels whose nearest aspect's
    // parallax stays within ε is a far tree (StreamOptions::far_span, tree_class in cull.wgsl).
    far_span: f32,
    // Viewport size in pixels.
    viewport: vec2<f32>,
    // Debug view of the draw pass (0 off, 1 levels, 2 blend weights, 3 wireframe; see
    // forest_render::options::DebugView).
    debug_view: f32,
    // Stream flags (FLAG_*, see forest_render::options::StreamOptions).
    stream_flags: f32,
    // Frustum planes (xyz·p + w >= 0 inside), world space, normals unit length.
    planes: array<vec4<f32>, 6>,
    // Which form draws each tree (the hybrid method, see quad_share): x metres + y focal
    // pixels × the tree's switch unit = the switch distance; z: the transition band's width as a
    // fraction of it; w: the per-instance jitter of the band's start, a fraction of the switch
    // distance. (0, 0, ·, ·): every tree is drawn as quads; x ≥ 3e38: every tree as geometry.
    forms: vec4<f32>,
    // The light (forest_format::shading::Lighting), world space, linear RGB: the unit
    // direction towards the sun, and the exposure every radiance is scaled by.
    sun: vec3<f32>,
    exposure: f32,
    // xyz: sun irradiance; w unused.
    sun_colour: vec4<f32>,
    // xyz: sky irradiance on a surface facing up; w unused.
    sky_light: vec4<f32>,
    // xyz: ground-bounce irradiance on a surface facing down; w unused.
    ground_light: vec4<f32>,
    // The sun's shadow cascades (forest_render::shadow): world -> shadow clip of each
    // (orthographic, depth 0 towards the sun), the view depth (metres along forward) where
    // each ends, each one's texel (metres) and depth bias (clip units).
    shadow: array<mat4x4<f32>, 4>,
    shadow_splits: vec4<f32>,
    shadow_texel: vec4<f32>,
    shadow_bias: vec4<f32>,
    // Cascades in use (0: no shadows), the maps' side (texels), the receivers' offset
    // (texels), and 1 for reverse-Z maps (a host's), else 0.
    shadow_cascades: f32,
    shadow_side: f32,
    shadow_offset: f32,
    shadow_reverse_z: f32,
    // xyz: the eye whose distances choose each tree's form and level of detail (eye, except in
    // a light view: the eye of the view it casts for); w unused.
    form_eye: vec4<f32>,
    // A light view's receiver region: planes (xyz·p + w >= 0 inside) of the view slice its
    // map serves; x of caster_floor: the lowest receiver's height, y: the longest sweep
    // (metres). All zero: every tree casts (casts_into, forest_render::shadow::caster_planes).
    casters: array<vec4<f32>, 6>,
    caster_floor: vec4<f32>,
    // The frame's wind (forest_format::wind::Wind::uniform, mirrored by wind.wgsl): xy the unit
    // direction it blows towards (world x, z), z its mean speed (m/s; 0: calm), w its
    // gustiness; wind_time.x the instant (seconds).
    wind: vec4<f32>,
    wind_time: vec4<f32>,
    // The frame's season (forest_format::colour): x 1 when leaves follow the seasons' ramp (0:
    // the models' own colours), y where on it (0 spring to 1 late autumn).
    season: vec4<f32>,
}

// Whether a caster's bounding sphere (world centre `c`, radius `r`) can shadow the light
// view's receiver region (camera.casters, camera.caster_floor): swept from `c` away from the
// sun until its top is below the lowest receiver, or caster_floor.y metres at most, it stays
// inside every plane; each plane's test is offset by the sweep's reach across it. A view
// camera's zero planes pass every tree (forest_render::shadow::casts_into is the CPU mirror).
fn casts_into(c: vec3<f32>, r: f32) -> bool {
    let sun = camera.sun;
    var sweep = camera.caster_floor.y;
    if (sun.y > 1e-3) { sweep = min(sweep, max(c.y + r - camera.caster_floor.x, 0.0) / sun.y); }
    for (var k = 0u; k < 6u; k++) {
        let pl = camera.casters[k];
        if (dot(pl.xyz, c) + pl.w + sweep * max(-dot(pl.xyz, sun), 0.0) < -r) { return false; }
    }
    return true;
}

// The project's one shading model (mirrors forest_format::shading::Lighting::shade): albedo
// `a`, unit world normal `n` facing the viewer, sun visibility `v`, sky visibility `s`,
// translucency `tau`, under the frame's light; linear RGB, exposure applied.
fn shade_light(a: vec3<f32>, n: vec3<f32>, v: f32, s: f32, tau: f32) -> vec3<f32> {
    let ndl = dot(n, camera.sun);
    let direct = max(ndl, 0.0) + tau * max(-ndl, 0.0);
    let hemi = 0.5 + 0.5 * n.y;
    let ambient = (camera.sky_light.rgb * hemi + camera.ground_light.rgb * (1.0 - hemi)) * s;
    return a * (ambient + camera.sun_colour.rgb * (v * direct)) * camera.exposure;
}

// The march towards the sun through a tree's opacity volume (mirrors
// forest_format::opacity: VOLUME_RESOLUTION, MARCH_STEPS, START_VOXELS, COARSE_LEVEL,
// COARSE_STEPS, MID_STEPS, COARSE_QUAD_LEVEL, MID_QUAD_LEVEL).
const OPACITY_RES: f32 = 32.0;
const OPACITY_STEPS: u32 = 16u;
const OPACITY_START: f32 = 0.5;
const OPACITY_COARSE_LEVEL: u32 = 2u;
const OPACITY_COARSE_STEPS: u32 = 6u;
const OPACITY_MID_STEPS: u32 = 8u;
const OPACITY_COARSE_QUAD_LEVEL: u32 = 2u;
const OPACITY_MID_QUAD_LEVEL: u32 = 4u;

// The mip level (x) and samples (y) a plain quad's corners march, by the quad's hierarchy
// level (mirrors forest_format::opacity::quad_march).
fn quad_march(quad_level: u32) -> vec2<u32> {
    if (quad_level <= OPACITY_COARSE_QUAD_LEVEL) {
        return vec2<u32>(OPACITY_COARSE_LEVEL, OPACITY_COARSE_STEPS);
    }
    if (quad_level <= OPACITY_MID_QUAD_LEVEL) { return vec2<u32>(1u, OPACITY_MID_STEPS); }
    return vec2<u32>(0u, OPACITY_STEPS);
}

// Distances along unit `d` from `u` to where the ray enters and leaves [0, 1]³
// (opacity::cube_span).
fn cube_span(u: vec3<f32>, d: vec3<f32>) -> vec2<f32> {
    var enter = -3.0e38;
    var exit = 3.0e38;
    for (var i = 0u; i < 3u; i++) {
        if (abs(d[i]) > 1e-8) {
            let a = -u[i] / d[i];
            let b = (1.0 - u[i]) / d[i];
            enter = max(enter, min(a, b));
            exit = min(exit, max(a, b));
        } else if (u[i] < 0.0 || u[i] > 1.0) {
            return vec2<f32>(0.0);
        }
    }
    return vec2<f32>(enter, exit);
}

// Transmittance towards the sun from object-space point `p` of a tree of species `k`
// (mirrors forest_format::opacity::OpacityVolume::transmittance): `vol` holds every species'
// volume stacked along z (species k at slices k·R ..), `sphere` is the species' bounding
// sphere, `max_depth` its volume's coding, `sun` the unit direction towards the sun in object
// space. Sampled at level 0, so any stage may call it.
fn sun_transmittance(vol: texture_3d<f32>, samp: sampler, k: u32, sphere: vec4<f32>,
                     max_depth: f32, p: vec3<f32>, sun: vec3<f32>) -> f32 {
    return opacity_march(vol, samp, k, sphere, max_depth, p, sun, 0u, OPACITY_STEPS);
}

// sun_transmittance through the volume's mip level OPACITY_COARSE_LEVEL in
// OPACITY_COARSE_STEPS samples, for forms that march per fragment (mirrors
// OpacityVolume::coarse_transmittance).
fn sun_transmittance_coarse(vol: texture_3d<f32>, samp: sampler, k: u32, sphere: vec4<f32>,
                            max_depth: f32, p: vec3<f32>, sun: vec3<f32>) -> f32 {
    return opacity_march(vol, samp, k, sphere, max_depth, p, sun, OPACITY_COARSE_LEVEL,
                         OPACITY_COARSE_STEPS);
}

// Object-space point `p` in the unit cube a volume spans around `sphere` (xyz centre, w
// radius): [0, 1]³ inside (opacity::cube_point).
fn opacity_cube_point(sphere: vec4<f32>, p: vec3<f32>) -> vec3<f32> {
    return (p - (sphere.xyz - vec3<f32>(sphere.w))) / (2.0 * sphere.w);
}

// The march of `steps` samples through mip level `level` (opacity::march). Optical depth is
// per level-0 voxel length at every level.
fn opacity_march(vol: texture_3d<f32>, samp: sampler, k: u32, sphere: vec4<f32>,
                 max_depth: f32, p: vec3<f32>, sun: vec3<f32>, level: u32, steps: u32) -> f32 {
    if (max_depth <= 0.0) { return 1.0; }
    let u = opacity_cube_point(sphere, p);
    let span = cube_span(u, sun);
    let start = max(OPACITY_START / OPACITY_RES, span.x);
    let exit = span.y;
    if (exit <= start) { return 1.0; }
    let dt = (exit - start) / f32(steps);
    var sum = 0.0;
    for (var i = 0u; i < steps; i++) {
        let s = opacity_code(vol, samp, k, u + sun * (start + (f32(i) + 0.5) * dt), level);
        sum = sum + s * s;
    }
    return exp(-sum * max_depth * dt * OPACITY_RES);
}

// The volume's code of species `k` at cube coordinates `x` ([0, 1]³), mip level `level`
// (trilinear; z clamped within the species' slices). The slice count is level 0's, divided:
// lavapipe returns level 0's depth for textureDimensions(vol, level) of a 3D texture.
fn opacity_code(vol: texture_3d<f32>, samp: sampler, k: u32, x: vec3<f32>, level: u32) -> f32 {
    let res = OPACITY_RES / f32(1u << level);
    let slices = f32(textureDimensions(vol).z >> level);
    let z = (f32(k) * res + clamp(x.z * res, 0.5, res - 0.5)) / slices;
    return textureSampleLevel(vol, samp, vec3<f32>(x.xy, z), f32(level)).r;
}

const LN_2: f32 = 0.6931472;

// Where a view ray meets a tree whose image has no depth (a billboard, whose texels show
// the crown's first surfaces): along unit `d` (object space, away from the eye) from the
// bounding sphere's front through `p`, the point at which the opacity volume has stopped half
// the ray's light (its median depth), or `p` where it stops less. Coarse level,
// OPACITY_COARSE_STEPS samples across the sphere's diameter.
fn median_depth_point(vol: texture_3d<f32>, samp: sampler, k: u32, sphere: vec4<f32>,
                      max_depth: f32, p: vec3<f32>, d: vec3<f32>) -> vec3<f32> {
    if (max_depth <= 0.0) { return p; }
    let front = p - d * sphere.w;
    let u = opacity_cube_point(sphere, front);
    // The diameter is one cube side: 1 in cube units.
    let dt = 1.0 / f32(OPACITY_COARSE_STEPS);
    let per_step = max_depth * dt * OPACITY_RES;
    var tau = 0.0;
    for (var i = 0u; i < OPACITY_COARSE_STEPS; i++) {
        let s = opacity_code(vol, samp, k, u + d * ((f32(i) + 0.5) * dt), OPACITY_COARSE_LEVEL);
        let step = s * s * per_step;
        if (tau + step >= LN_2) {
            // Half the light is spent within this step: linearly in its optical depth.
            let f = (LN_2 - tau) / max(step, 1e-6);
            return front + d * (2.0 * sphere.w * (f32(i) + f) * dt);
        }
        tau = tau + step;
    }
    return p;
}

// Object direction -> world direction (the instance's rotation about +Y).
fn to_world_dir(inst: Instance, d: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(inst.cos_rot * d.x + inst.sin_rot * d.z, d.y,
                     -inst.sin_rot * d.x + inst.cos_rot * d.z);
}

// Unit vector (z ≥ 0) of a hemispherical octahedral code (mirrors
// forest_format::shading::hemi_oct_decode).
fn hemi_oct_decode(e: vec2<f32>) -> vec3<f32> {
    let a = e * 2.0 - 1.0;
    let p = vec2<f32>(a.x + a.y, a.x - a.y) * 0.5;
    let v = vec3<f32>(p.x, p.y, max(1.0 - abs(p.x) - abs(p.y), 0.0));
    return v / max(length(v), 1e-6);
}

struct Instance {
    position: vec3<f32>,
    scale: f32,
    cos_rot: f32,
    sin_rot: f32,
    species: u32,
    // 0: the tree's colour comes from the hash of its index; else its explicit value's code.
    colour: u32,
}

// A species' colours in the forest (forest_format::colour::TreeColour; see tint.wgsl):
// amplitudes of the hue turn (radians), saturation, brightness and bark brightness; x of
// phase: the season's spread between trees; the spring, autumn and late-autumn keys (tint
// rgb, strength w).
struct TreeColour {
    amplitude: vec4<f32>,
    phase: vec4<f32>,
    spring: vec4<f32>,
    autumn: vec4<f32>,
    late_autumn: vec4<f32>,
}

struct Species {
    // xyz: bounding sphere centre (object space); w: radius.
    sphere: vec4<f32>,
    directions: u32,
    slabs: u32,
    levels: u32,
    // First direction frame / direction triangle / layer (colour array and roots) / node.
    dir_base: u32,
    tri_base: u32,
    tri_count: u32,
    layer_base: u32,
    node_base: u32,
    // Direction triangles for views from below, after the tri_count upper ones.
    lower_tri_count: u32,
    // Slab image side in texels.
    resolution: u32,
    // The hybrid's switch unit: metres of switch distance per focal pixel at scale 1
    // (forms::switch_unit).
    switch_unit: f32,
    // Optical depth per voxel length of the species' opacity-volume code 1.0 (0: none).
    opacity_depth: f32,
    colour: TreeColour,
}

// One direction frame: dir, right, up (xyz of each), object space.
struct Frame {
    dir: vec4<f32>,
    right: vec4<f32>,
    up: vec4<f32>,
}

// A quad of the stream: 16 bytes.
//   instance: instance index.
//   node: global node index (species node base + local index).
//   pos: level (bits 0..4) | x (4..16) | y (16..28) | slab (28..32).
//   dir_weight: direction index within the species (bits 0..8) | lo (8..20) | hi (20..32): the
//     aspect's share [lo, hi) of its tree's blend, cumulative over the tree's aspects in
//     drawing order, in units of 1/WEIGHT_ONE.
struct Quad {
    instance: u32,
    node: u32,
    pos: u32,
    dir_weight: u32,
}

// Frame state written by the GPU, read back for statistics.
struct State {
    presort: u32,       // chosen presort direction
    n: u32,             // quads in the stream being refined (then in the final stream)
    total: u32,         // scan total
    pmin: u32,          // refine: smallest prefix among refined quads (0xffffffff: none)
    overflow_cull: u32, // level-0 quads dropped (composited ones, then the farthest trees')
    overflow_refine: u32, // quads left unrefined for lack of room
    visible: u32,       // trees passing the frustum test
    quads: u32,         // quads in the final stream
    composites: u32,    // far trees' composited quads at level 0, before any are dropped
    per_level: array<u32, 16>,
}

// Composited quads at the front of the stream: those of `composites` not dropped for room
// (the dropped quads are the stream's first).
fn kept_composites(composites: u32, overflow_cull: u32) -> u32 {
    return composites - min(composites, overflow_cull);
}

// Dispatch arguments (x, y, z) for each kind of dispatch, and the draw arguments.
struct Args {
    items: vec4<u32>,   // ceil(m / 256) workgroups, m the plain quads (w unused)
    blocks: vec4<u32>,  // ceil(m / 512)
    draw: vec4<u32>,    // plain quads: vertex count 4, instance count n − kept composites, 0, 0
    draw_composite: vec4<u32>, // composited quads: 4, kept composites, 0, 0
}

const WG: u32 = 256u;
const WEIGHT_ONE: u32 = 4095u;
// Stream flags in camera.stream_flags; mirror forest_render::options::FLAG_*.
const FLAG_DITHER: u32 = 1u;
const FLAG_NEAREST: u32 = 2u;
const FLAG_DEPTH_ERROR: u32 = 4u;
const FLAG_UNTRIMMED: u32 = 8u;
const FLAG_FAR_BLEND: u32 = 16u;
const FLAG_FAR_SLABS: u32 = 32u;
// Bits 8–19 of the flags: aspect sharpening in units of 1/WEIGHT_ONE (StreamOptions::sharpen).
const SHARPEN_SHIFT: u32 = 8u;
const SHARPEN_MASK: u32 = 4095u;
// Largest sharpening (StreamOptions::sharpen); mirrors options::SHARPEN_MAX.
const SHARPEN_MAX: u32 = 1364u;
// Bits 20–23 of the flags: the sharpening reach R in units of the far span
// (StreamOptions::sharpen_reach; 1: off), its steps and their width (1 / REACH_STEPS).
const REACH_SHIFT: u32 = 20u;
const REACH_MASK: u32 = 15u;
const REACH_STEPS: u32 = 16u;
const REACH_STEP: f32 = 0.0625;
// tree_class of a far tree (cull.wgsl).
const FAR_CLASS: u32 = 255u;
// A far tree's slabs drawn as one quad: level 0 at column 1, which level 0 lacks (mirrors
// Quad::COMPOSITE_POS); its node is the root of the front-most slab present.
const COMPOSITE_POS: u32 = 16u;
const BLOCK: u32 = 512u;
const NONE: u32 = 0xffffffffu;
const NODE_TEX_WIDTH: u32 = 4096u;
const PRESORT_TEX_WIDTH: u32 = 4096u;

fn quad_level(q: Quad) -> u32 { return q.pos & 15u; }
fn quad_composite(q: Quad) -> bool { return q.pos == COMPOSITE_POS; }
fn quad_x(q: Quad) -> u32 { return (q.pos >> 4u) & 4095u; }
fn quad_y(q: Quad) -> u32 { return (q.pos >> 16u) & 4095u; }
fn quad_slab(q: Quad) -> u32 { return q.pos >> 28u; }
fn quad_dir(q: Quad) -> u32 { return q.dir_weight & 255u; }
fn quad_lo(q: Quad) -> u32 { return (q.dir_weight >> 8u) & 4095u; }
fn quad_hi(q: Quad) -> u32 { return q.dir_weight >> 20u; }
fn pack_dir(dir: u32, lo: u32, hi: u32) -> u32 { return dir | (lo << 8u) | (hi << 20u); }
fn stream_flags(c: Camera) -> u32 { return u32(c.stream_flags); }

// Slab-relative depth error bound of a node's 4-bit code (forest_format::node::ERROR_BOUNDS).
fn node_error(node: vec2<u32>) -> f32 {
    var b = array<f32, 16>(0.0, 0.0078125, 0.011048543, 0.015625, 0.022097087, 0.03125,
        0.044194173, 0.0625, 0.088388346, 0.125, 0.17677669, 0.25, 0.35355338, 0.5,
        0.70710677, 1.0);
    return b[(node.x >> 24u) & 15u];
}
// Mean of a node's 4 corner depths, slab-relative.
fn node_mean_depth(node: vec2<u32>) -> f32 {
    let d = node.y;
    let sum = (d & 255u) + ((d >> 8u) & 255u) + ((d >> 16u) & 255u) + (d >> 24u);
    return f32(sum) / 1020.0;
}
fn unorm12(x: f32) -> u32 {
    return u32(floor(clamp(x, 0.0, 1.0) * 4095.0 + 0.5));
}

// A per-instance number in [0, 1) (a PCG hash; exact in f32: 24 bits over 2^24).
fn instance_hash(instance: u32) -> f32 {
    var h = instance * 747796405u + 2891336453u;
    h = ((h >> ((h >> 28u) + 4u)) ^ h) * 277803737u;
    return f32(h >> 8u) / 16777216.0;
}

// The quad stream's share of a tree in units of 1/WEIGHT_ONE (hybrid::quad_share mirrors it):
// 0 while the tree is nearer than its switch distance s (drawn as geometry only), WEIGHT_ONE
// from the end of its transition band on (quads only), and in between the fraction of its
// pixels the quads draw. The band starts at s·(1 + jitter·h) with h the instance's hash, so
// a ring of trees at one distance does not change form in the same frame, and is
// band·start wide. `d`: eye to bounding-sphere centre (metres), `unit`: the species' switch
// unit times the tree's scale.
fn quad_share(forms: vec4<f32>, d: f32, unit: f32, instance: u32) -> u32 {
    let s = forms.x + forms.y * unit;
    if (s <= 0.0) { return WEIGHT_ONE; }
    if (s >= 3.0e38) { return 0u; }
    let start = s * (1.0 + forms.w * instance_hash(instance));
    let width = start * forms.z;
    if (width <= 0.0) { return select(0u, WEIGHT_ONE, d >= start); }
    return unorm12((d - start) / width);
}

// Ordered-dither threshold of a pixel for a tree, in [0, WEIGHT_ONE): an 8×8 Bayer matrix,
// shifted per instance so that neighbouring trees do not share a pattern.
fn dither_threshold(pixel: vec2<f32>, instance: u32) -> u32 {
    let x = u32(pixel.x) & 7u;
    let y = u32(pixel.y) & 7u;
    let xy = x ^ y;
    let b = ((xy & 1u) << 5u) | ((y & 1u) << 4u) | ((xy & 2u) << 2u) | ((y & 2u) << 1u)
        | ((xy & 4u) >> 1u) | ((y & 4u) >> 2u);
    let u = fract((f32(b) + 0.5) / 64.0 + instance_hash(instance));
    return min(u32(u * f32(WEIGHT_ONE)), WEIGHT_ONE - 1u);
}

// The screen-door threshold that splits a tree in its transition band between the forms: the
// quads keep the pixels whose threshold is below the tree's quad share, the geometry the
// others, so every pixel is drawn by exactly one form. The matrix is transposed and the
// instance salted, so it does not follow the aspects' dither.
fn form_threshold(pixel: vec2<f32>, instance: u32) -> u32 {
    return dither_threshold(pixel.yx, instance ^ 0x5bd1e995u);
}

// The hybrid's share of a tree given to its mesh LOD starting at `start` (a fraction of the
// switch distance; 0: none) and the coarser ones, in units of 1/WEIGHT_ONE
// (forest_render::forms::lod_share mirrors it): the quad share of a switch `start` times
// nearer, with the same band and jitter. 0 when there is no such LOD, or no switch.
fn lod_share(forms: vec4<f32>, d: f32, unit: f32, instance: u32, start: f32) -> u32 {
    let s = forms.x + forms.y * unit;
    if (start <= 0.0 || s <= 0.0 || s >= 3.0e38) { return 0u; }
    return quad_share(vec4<f32>(forms.x * start, forms.y * start, forms.z, forms.w), d, unit,
                      instance);
}

// The screen-door threshold that splits a tree in a crossfade between its mesh LODs: the
// coarser LOD keeps the pixels whose threshold is below its share (lod_share), the finer one
// the others. Salted apart from form_threshold.
fn lod_threshold(pixel: vec2<f32>, instance: u32) -> u32 {
    return dither_threshold(pixel, instance ^ 0x27d4eb2fu);
}

fn pack_pos(level: u32, x: u32, y: u32, slab: u32) -> u32 {
    return level | (x << 4u) | (y << 16u) | (slab << 28u);
}

// Instance transform: rotate about +Y, scale, translate (object -> world).
fn to_world(inst: Instance, p: vec3<f32>) -> vec3<f32> {
    let s = p * inst.scale;
    return vec3<f32>(inst.cos_rot * s.x + inst.sin_rot * s.z, s.y,
                     -inst.sin_rot * s.x + inst.cos_rot * s.z) + inst.position;
}

// World point -> object point (the inverse of to_world).
fn to_object_point(inst: Instance, w: vec3<f32>) -> vec3<f32> {
    return to_object_dir(inst, w - inst.position) / inst.scale;
}

// World direction -> object direction (inverse rotation; scale does not change directions).
fn to_object_dir(inst: Instance, d: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(inst.cos_rot * d.x - inst.sin_rot * d.z, d.y,
                     inst.sin_rot * d.x + inst.cos_rot * d.z);
}

// Object-space point of a slab image: u, v in [0,1] (v down), t slab-relative depth.
fn slab_point(sp: Species, f: Frame, slab: u32, u: f32, v: f32, t: f32) -> vec3<f32> {
    let r = sp.sphere.w;
    let d = (f32(slab) + t) / f32(sp.slabs);
    return sp.sphere.xyz + f.right.xyz * ((2.0 * u - 1.0) * r) + f.up.xyz * ((1.0 - 2.0 * v) * r)
        + f.dir.xyz * ((1.0 - 2.0 * d) * r);
}

// Octahedral projection of the upper hemisphere (see forest_format::directions::disk_point);
// for views from below the caller negates y (disk_point_lower).
fn disk_point(d: vec3<f32>) -> vec2<f32> {
    let den = abs(d.x) + max(d.y, 0.0) + abs(d.z);
    if (den > 0.0) {
        return vec2<f32>(d.x / den, d.z / den);
    }
    return vec2<f32>(0.0, 0.0);
}
