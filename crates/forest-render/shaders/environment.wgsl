// The environment: an endless ground plane at y = 0 and the sky behind it, drawn first as one
// full-screen triangle, and the distance haze every method's fragments go through (`hazed`).
// Appended to draw.wgsl and geometry_draw.wgsl, which declare `camera` at binding 0. Mirrors
// options::Atmosphere and gpu_types::GpuEnvironment.

struct Environment {
    // xyz: lit ground colour (linear); w unused.
    ground: vec4<f32>,
    // xyz: sky colour at the horizon, also the haze's colour; w: haze extinction per metre at
    // y = 0.
    horizon: vec4<f32>,
    // xyz: sky colour at the zenith; w: the haze's falloff per metre of height (0: uniform).
    zenith: vec4<f32>,
    // xyz: unit direction towards the sun; w: cosine of the disc's radius (> 1: no disc).
    sun: vec4<f32>,
    // xyz: the sun's colour; w unused.
    sun_colour: vec4<f32>,
}

@group(0) @binding(8) var<uniform> env: Environment;

// The haze's optical depth from the eye to `p`: extinction σ₀·exp(−k·y) integrated along the
// segment (mirrors options::Atmosphere::optical_depth).
fn optical_depth(p: vec3<f32>) -> f32 {
    let eye = camera.eye.xyz;
    let k = env.zenith.w;
    let x = k * (p.y - eye.y);
    var f = exp(-k * eye.y) * (1.0 - 0.5 * x);
    if (abs(x) >= 1e-3) { f = (exp(-k * eye.y) - exp(-k * p.y)) / x; }
    return env.horizon.w * distance(p, eye) * f;
}

// Premultiplied colour `c` of a surface at `world` seen through the haze: it keeps
// T = exp(−τ) and takes (1 − T) of the horizon colour, in proportion to its coverage.
fn hazed(c: vec4<f32>, world: vec3<f32>) -> vec4<f32> {
    if (env.horizon.w <= 0.0) { return c; }
    let t = exp(-optical_depth(world));
    return vec4<f32>(c.rgb * t + env.horizon.rgb * (c.a * (1.0 - t)), c.a);
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

// The sky seen along unit direction `d`: the horizon colour rising to the zenith's, the sun's
// disc with a faint glow around it.
fn sky(d: vec3<f32>) -> vec3<f32> {
    let up = clamp(d.y, 0.0, 1.0);
    var c = mix(env.horizon.rgb, env.zenith.rgb, sqrt(up));
    let s = dot(d, env.sun.xyz);
    if (env.sun.w <= 1.0) {
        c = c + env.sun_colour.rgb * (0.25 * pow(max(s, 0.0), 256.0));
        if (s >= env.sun.w) { c = env.sun_colour.rgb * 1.5; }
    }
    return c;
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
    let eye = camera.eye.xyz;
    var out: EnvironmentOut;
    let t = -eye.y / d.y;
    if (d.y != 0.0 && t > 0.0) {
        let p = eye + d * t;
        let clip = camera.view_proj * vec4<f32>(p, 1.0);
        out.colour = hazed(vec4<f32>(env.ground.rgb, 1.0), p);
        out.depth = clamp(clip.z / clip.w, 0.0, 1.0);
    } else {
        let clip = camera.view_proj * vec4<f32>(d, 0.0);
        out.colour = vec4<f32>(sky(d), 1.0);
        out.depth = clamp(clip.z / clip.w, 0.0, 1.0);
    }
    return out;
}
