// The environment: an endless ground plane at y = 0 and the sky behind it, drawn first as one
// full-screen triangle; the terrain's height field, drawn as a triangle mesh over the plane; and
// the distance haze every method's fragments go through (`hazed`). Imported by draw.wgsl and
// geometry_draw.wgsl, which declare `camera` at binding 0. Mirrors
// options::Atmosphere,
// gpu_types::GpuEnvironment and forest_format::terrain::Terrain.

#import common
#import ground

struct Environment {
    // xyz: the ground's second albedo, moss (linear); w unused.
    ground: vec4<f32>,
    // xyz: sky colour at the horizon, also the haze's colour; w: haze extinction per metre at
    // y = 0.
    horizon: vec4<f32>,
    // xyz: sky colour at the zenith; w: the haze's falloff per metre of height (0: uniform).
    zenith: vec4<f32>,
    // x: cosine of the sun disc's radius (> 1: no disc); yzw unused. The sun itself (its
    // direction and colour) is the frame's light, in the camera.
    sun: vec4<f32>,
    // xyz: the ground's first albedo, soil; w unused.
    albedo: vec4<f32>,
    // x, y: world x and z of sample (0, 0); z: metres between samples; w: 1 with a terrain.
    terrain: vec4<f32>,
    // x, y: samples along x and z.
    terrain_size: vec4<u32>,
}

@group(0) @binding(8) var<uniform> env: Environment;
// The terrain's heights in metres, row after row (sample (i, j) at j·size.x + i).
@group(0) @binding(13) var<storage, read> terrain_heights: array<f32>;

// The haze's optical depth from the eye to `p`: extinction σ₀·exp(−k·y) integrated along the
// segment (mirrors options::Atmosphere::optical_depth).
fn optical_depth(p: vec3<f32>) -> f32 {
    let eye = camera.eye;
    let k = env.zenith.w;
    let x = k * (p.y - eye.y);
    var f = exp(-k * eye.y) * (1.0 - 0.5 * x);
    if (abs(x) >= 1e-3) { f = (exp(-k * eye.y) - exp(-k * p.y)) / x; }
    return env.horizon.w * distance(p, eye) * f;
}

// The sky irradiance of forest_format::shading::Lighting::default(): the light the
// atmosphere's sky and haze colours are given for.
const REFERENCE_SKY: vec3<f32> = vec3<f32>(0.32, 0.38, 0.48);

// How the frame's light tints the sky and the haze: its sky irradiance over the reference's,
// per channel (1 under the default light), so that a sinking sun dims and warms them.
fn sky_tint() -> vec3<f32> {
    return camera.sky_light.rgb / REFERENCE_SKY;
}

// Premultiplied colour `c` (exposure applied) of a surface at `world` seen through the haze:
// it keeps T = exp(−τ) and takes (1 − T) of the horizon colour (tinted by the light, scaled by
// the exposure as every radiance is), in proportion to its coverage.
fn hazed(c: vec4<f32>, world: vec3<f32>) -> vec4<f32> {
    if (env.horizon.w <= 0.0) { return c; }
    let t = exp(-optical_depth(world));
    let haze = env.horizon.rgb * sky_tint() * camera.exposure;
    return vec4<f32>(c.rgb * t + haze * (c.a * (1.0 - t)), c.a);
}

// The world direction (not normalised, in front of the eye) through pixel `pixel`: the 3×3 of
// the view-projection maps a direction d to clip (r0·d, r1·d, ·, r3·d) (the eye itself projects
// to x = y = w = 0 under any perspective), so d is normal to r0 − x·r3 and r1 − y·r3.
fn view_ray(pixel: vec2<f32>) -> vec3<f32> {
    let m = camera.view_proj;
    let ndc = vec2<f32>(2.0 * pixel.x / camera.viewport.x - 1.0,
                        1.0 - 2.0 * pixel.y / camera.viewport.y);
    let r0 = vec3<f32>(m[0].x, m[1].x, m[2].x);
    let r1 = vec3<f32>(m[0].y, m[1].y, m[2].y);
    let r3 = vec3<f32>(m[0].w, m[1].w, m[2].w);
    var d = cross(r0 - ndc.x * r3, r1 - ndc.y * r3);
    if (dot(d, r3) < 0.0) { d = -d; }
    return d;
}

// The sky seen along unit direction `d`: the horizon colour rising to the zenith's (tinted by
// the light), the sun's disc with a faint glow around it; scaled by the exposure.
fn sky(d: vec3<f32>) -> vec3<f32> {
    let up = clamp(d.y, 0.0, 1.0);
    var c = mix(env.horizon.rgb, env.zenith.rgb, sqrt(up)) * sky_tint();
    let s = dot(d, camera.sun);
    if (env.sun.x <= 1.0) {
        c = c + camera.sun_colour.rgb * (0.25 * pow(max(s, 0.0), 256.0));
        if (s >= env.sun.x) { c = camera.sun_colour.rgb * 1.5; }
    }
    return c * camera.exposure;
}

struct EnvironmentOut {
    @location(0) colour: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

// One triangle covering the screen.
@vertex
fn vs_environment(@builtin(vertex_index) vi: u32) -> @builtin(position) vec4<f32> {
    let x = select(-1.0, 3.0, vi == 1u);
    let y = select(-1.0, 3.0, vi == 2u);
    return vec4<f32>(x, y, 0.0, 1.0);
}

// The ground where the pixel's ray meets y = 0 (hazed, at the hit's depth), else the sky at the
// depth of a point at infinity (the far end of the depth range under either depth convention).
@fragment
fn fs_environment(@builtin(position) frag: vec4<f32>) -> EnvironmentOut {
    let d = normalize(view_ray(frag.xy));
    let eye = camera.eye;
    var out: EnvironmentOut;
    let t = -eye.y / d.y;
    if (d.y != 0.0 && t > 0.0 && !under_terrain(eye + d * t)) {
        let p = eye + d * t;
        let clip = camera.view_proj * vec4<f32>(p, 1.0);
        out.colour = hazed(vec4<f32>(ground_shade(p, vec3<f32>(0.0, 1.0, 0.0)), 1.0), p);
        out.depth = clamp(clip.z / clip.w, 0.0, 1.0);
    } else {
        let clip = camera.view_proj * vec4<f32>(d, 0.0);
        out.colour = vec4<f32>(sky(d), 1.0);
        out.depth = clamp(clip.z / clip.w, 0.0, 1.0);
    }
    return out;
}

// Whether the plane's point `p` lies under the terrain's mesh, which draws the ground there:
// inside the grid by more than half a cell (the mesh's skirts close the rest).
fn under_terrain(p: vec3<f32>) -> bool {
    if (env.terrain.w == 0.0) { return false; }
    let s = env.terrain.z;
    let lo = env.terrain.xy + vec2<f32>(0.5 * s);
    let hi = env.terrain.xy + (vec2<f32>(env.terrain_size.xy) - vec2<f32>(1.5)) * s;
    return all(p.xz > lo) && all(p.xz < hi);
}

fn terrain_sample(i: i32, j: i32) -> f32 {
    let n = vec2<i32>(env.terrain_size.xy);
    let c = clamp(vec2<i32>(i, j), vec2<i32>(0), n - vec2<i32>(1));
    return terrain_heights[c.y * n.x + c.x];
}

// Sample (i, j)'s position on the perimeter walk of the grid: along j = 0, up i = n.x − 1,
// back along j = n.y − 1, down i = 0 (2·(n.x − 1) + 2·(n.y − 1) steps, then round again).
fn perimeter(step: u32) -> vec2<u32> {
    let n = env.terrain_size.xy - vec2<u32>(1u);
    let s = step % (2u * (n.x + n.y));
    if (s < n.x) { return vec2<u32>(s, 0u); }
    if (s < n.x + n.y) { return vec2<u32>(n.x, s - n.x); }
    if (s < 2u * n.x + n.y) { return vec2<u32>(n.x - (s - n.x - n.y), n.y); }
    return vec2<u32>(0u, n.y - (s - 2u * n.x - n.y));
}

struct TerrainOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
}

// The terrain's mesh: 6 vertices per cell, split along the diagonal from sample (i, j) to
// (i+1, j+1) as forest_format::terrain::Terrain::height interpolates, then 6 per segment of a
// vertical skirt from the border down to the plane at y = 0. Normals by central differences of
// the heights (one-sided at the border).
@vertex
fn vs_terrain(@builtin(vertex_index) vi: u32) -> TerrainOut {
    let n = env.terrain_size.xy;
    let cells = (n.x - 1u) * (n.y - 1u);
    let cell = vi / 6u;
    let k = vi % 6u;
    var ij: vec2<u32>;
    var skirt_bottom = false;
    if (cell < cells) {
        var corner = array<vec2<u32>, 6>(
            vec2<u32>(0u, 0u), vec2<u32>(1u, 0u), vec2<u32>(1u, 1u),
            vec2<u32>(0u, 0u), vec2<u32>(1u, 1u), vec2<u32>(0u, 1u));
        ij = vec2<u32>(cell % (n.x - 1u), cell / (n.x - 1u)) + corner[k];
    } else {
        // Segment from perimeter step s to s + 1: top a, top b, bottom b; top a, bottom b,
        // bottom a.
        let s = cell - cells;
        var next = array<u32, 6>(0u, 1u, 1u, 0u, 1u, 0u);
        ij = perimeter(s + next[k]);
        skirt_bottom = k == 2u || k == 4u || k == 5u;
    }
    let i = i32(ij.x);
    let j = i32(ij.y);
    let sp = env.terrain.z;
    let h = select(terrain_sample(i, j), 0.0, skirt_bottom);
    let world = vec3<f32>(env.terrain.x + f32(ij.x) * sp, h, env.terrain.y + f32(ij.y) * sp);
    let i0 = max(i - 1, 0);
    let i1 = min(i + 1, i32(n.x) - 1);
    let j0 = max(j - 1, 0);
    let j1 = min(j + 1, i32(n.y) - 1);
    let dx = (terrain_sample(i1, j) - terrain_sample(i0, j)) / (f32(i1 - i0) * sp);
    let dz = (terrain_sample(i, j1) - terrain_sample(i, j0)) / (f32(j1 - j0) * sp);
    var out: TerrainOut;
    out.clip = camera.view_proj * vec4<f32>(world, 1.0);
    out.world = world;
    out.normal = vec3<f32>(-dx, 1.0, -dz);
    return out;
}

// Soil with patches of moss at world (x, z) (mirrors options::ground_albedo).
fn ground_albedo(xz: vec2<f32>) -> vec3<f32> {
    return mix(env.albedo.rgb, env.ground.rgb, ground_moss(xz));
}

// The ground at `world` with unit normal `n` under the shared shading model
// (forest_format::shading: open sky, no translucency), in the sun unless the module's shadow
// lookup (shadow_on.wgsl or shadow_off.wgsl) finds a caster.
fn ground_shade(world: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    return shade_light(ground_albedo(world.xz), n, sun_shadow(world, n), 1.0, 0.0);
}

// The terrain, shaded as the plane is at its interpolated normal, then hazed.
@fragment
fn fs_terrain(in: TerrainOut) -> @location(0) vec4<f32> {
    return hazed(vec4<f32>(ground_shade(in.world, normalize(in.normal)), 1.0), in.world);
}
