// Wind: where the frame's wind (camera.wind, camera.wind_time) moves a tree's point. Every
// method moves its vertices through `swayed`, its culls grow their spheres by `wind_reach_now`.
// Mirrors forest_format::wind (swayed, bend, reach_now, hash, the constants), operation for operation.
// Used in a module that declares `camera`.

#import common

const WIND_TAU: f32 = 6.2831855;
// forest_format::wind::BEND, MAX_LEAN, FLUTTER, MAX_RELATIVE_HEIGHT, GUST_PERIODS (a test
// compares them).
const WIND_BEND: f32 = 2.5e-4;
const WIND_MAX_LEAN: f32 = 0.2;
const WIND_FLUTTER: f32 = 0.004;
const WIND_MAX_RELATIVE_HEIGHT: f32 = 1.5;
const WIND_GUST_PERIODS: vec2<f32> = vec2<f32>(4.6, 2.1);

// PCG's output permutation (forest_format::wind::hash).
fn wind_hash(x: u32) -> u32 {
    let h = x * 747796405u + 2891336453u;
    let g = ((h >> ((h >> 28u) + 4u)) ^ h) * 277803737u;
    return (g >> 22u) ^ g;
}

fn wind_hash01(x: u32) -> f32 {
    return f32(wind_hash(x) >> 8u) / 16777216.0;
}

// The lean (the top's offset over the height) at speed u.
fn wind_lean(u: f32) -> f32 {
    let b = WIND_BEND * u * u;
    return b / (1.0 + b / WIND_MAX_LEAN);
}

// The gust waves at a foot `at` (world x, z): in [−1, 1], travelling downwind.
fn wind_gusts(dir: vec2<f32>, speed: f32, time: f32, at: vec2<f32>) -> f32 {
    let s = dot(at, dir) - speed * time;
    let c = dot(at, vec2<f32>(-dir.y, dir.x));
    let long = max(speed * WIND_GUST_PERIODS.x, 37.0);
    let short = max(speed * WIND_GUST_PERIODS.y, 17.0);
    return 0.6 * sin(WIND_TAU * s / long + 0.9 * sin(WIND_TAU * c / 53.0))
        + 0.4 * sin(WIND_TAU * s / short + 2.1 + 0.7 * sin(WIND_TAU * c / 29.0));
}

// A tree's height above its foot (metres): its bounding sphere's top (object space, the
// foot at y = 0), scaled (forest_format::wind::SwayedTree::from_sphere).
fn wind_height(sphere: vec4<f32>, scale: f32) -> f32 {
    return max((sphere.y + sphere.w) * scale, 1e-3);
}

// A tree's bend at the frame's instant (forest_format::wind::bend): the top's offset over the
// height (world x, z), the speed it feels (m/s) and its sway's phase in [0, 1). Calm: zero.
fn wind_bend(foot: vec3<f32>, height: f32, seed: u32) -> vec4<f32> {
    let dx = camera.wind.x;
    let dz = camera.wind.y;
    let speed = camera.wind.z;
    let gust = camera.wind.w;
    let time = camera.wind_time.x;
    let dir = vec2<f32>(dx, dz);
    let u = max(speed * (1.0 + gust * wind_gusts(dir, speed, time, foot.xz)), 0.0);
    let lean = wind_lean(u);
    let freq = clamp(2.2 / sqrt(height), 0.15, 2.0);
    let phase = wind_hash01(seed);
    let along = lean * (0.25 + 0.5 * gust) * sin(WIND_TAU * (freq * time + phase));
    let across = lean * (0.1 + 0.3 * gust)
        * sin(WIND_TAU * (1.37 * freq * time + 2.0 * phase) + 1.0);
    let top = dir * (lean + along) + vec2<f32>(-dz, dx) * across;
    return vec4<f32>(top, u, phase);
}

// The farthest any point of the tree standing at `foot`, `height_in` metres tall, instance
// `seed`, is moved at the frame's instant (metres; forest_format::wind::reach_now, whose
// comment derives the bound): what the culls grow its bounding sphere by.
fn wind_reach_now(foot: vec3<f32>, height_in: f32, seed: u32) -> f32 {
    if (camera.wind.z <= 0.0) { return 0.0; }
    let height = max(height_in, 1e-3);
    let b = wind_bend(foot, height, seed);
    let f = length(vec3<f32>(0.4 * camera.wind.x, 0.6, 0.4 * camera.wind.y)) * WIND_FLUTTER
        * b.z * WIND_MAX_RELATIVE_HEIGHT;
    let t = length(b.xy);
    let most = t * height * WIND_MAX_RELATIVE_HEIGHT + f;
    let k = t + f / height;
    var turn = 2.0;
    if (k < 1.0) { turn = 1.0 / sqrt((1.0 + sqrt(1.0 - k * k)) * 0.5); }
    return 1.01 * turn * most;
}

// Where point `p` (world) of the tree standing at `foot` (world), `height` metres tall with a
// crown of `radius` metres, instance `seed`, is in the frame's wind.
fn swayed(p: vec3<f32>, foot: vec3<f32>, height_in: f32, radius: f32, seed: u32) -> vec3<f32> {
    let dx = camera.wind.x;
    let dz = camera.wind.y;
    let time = camera.wind_time.x;
    if (camera.wind.z <= 0.0) { return p; }
    let height = max(height_in, 1e-3);
    let b = wind_bend(foot, height, seed);
    let top = vec3<f32>(b.x, 0.0, b.y);
    let u = b.z;
    let phase = b.w;
    let q = p - foot;
    let rel = clamp(q.y / height, -WIND_MAX_RELATIVE_HEIGHT, WIND_MAX_RELATIVE_HEIGHT);
    let rim = min(length(q.xz) / max(radius, 1e-3), 1.0);
    let wave = dot(q, vec3<f32>(1.9, 2.3, 1.7)) + WIND_TAU * phase;
    let flutter_freq = 2.0 + phase;
    let flutter = WIND_FLUTTER * u * rim * max(rel, 0.0)
        * sin(WIND_TAU * flutter_freq * time + wave);
    let offset = top * (height * rel) + vec3<f32>(0.4 * dx, 0.6, 0.4 * dz) * flutter;
    let moved = q + offset;
    let len = length(moved);
    if (len > 0.0) { return foot + moved * (length(q) / len); }
    return p;
}
