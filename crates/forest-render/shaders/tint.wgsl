// Every tree its own colour, and the seasons (mirrors forest_format::colour operation for
// operation; see its page for the model). In a module that declares `camera`.

const TINT_LEAF_TRANSLUCENCY: f32 = 0.35;
const TINT_LUMA: vec3<f32> = vec3<f32>(0.2126, 0.7152, 0.0722);

// The key a tree's numbers are hashed from: its index, or its explicit value's code.
fn tint_key(instance: u32, code: u32) -> u32 {
    return select(code, instance, code == 0u);
}

// One round of the PCG hash, all 32 bits (forest_format::colour::mix).
fn tint_mix(key: u32) -> u32 {
    let h = key * 747796405u + 2891336453u;
    return ((h >> ((h >> 28u) + 4u)) ^ h) * 277803737u;
}

// A tree's four numbers in [-1, 1): hue, saturation, brightness, season phase.
fn tree_randoms(key: u32) -> vec4<f32> {
    let k = tint_mix(key) * 4u;
    return 2.0 * vec4<f32>(instance_hash(k + 1u), instance_hash(k + 2u),
                           instance_hash(k + 3u), instance_hash(k + 4u)) - 1.0;
}

// The leaves' key at ramp position s (tint rgb, strength w).
fn season_key(c: TreeColour, s: f32) -> vec4<f32> {
    let summer = vec4<f32>(1.0, 1.0, 1.0, 0.0);
    let t = clamp(s, 0.0, 1.0) * 3.0;
    if (t < 1.0) { return c.spring + (summer - c.spring) * t; }
    if (t < 2.0) { return summer + (c.autumn - summer) * (t - 1.0); }
    return c.autumn + (c.late_autumn - c.autumn) * min(t - 2.0, 1.0);
}

// Whether a species coloured `c` changes any albedo in the camera's season (else
// tree_albedo returns it as it is).
fn tree_coloured(c: TreeColour) -> bool {
    return any(c.amplitude != vec4<f32>(0.0)) || camera.season.x > 0.0;
}

// The albedo every method draws for albedo `a` (linear, not premultiplied) and translucency
// `tau` of the tree `key` of a species coloured `c`, in the camera's season.
fn tree_albedo(a: vec3<f32>, tau: f32, key: u32, c: TreeColour) -> vec3<f32> {
    if (!tree_coloured(c)) { return a; }
    let season_on = camera.season.x > 0.0;
    let r = tree_randoms(key);
    let leafness = clamp(tau / TINT_LEAF_TRANSLUCENCY, 0.0, 1.0);
    let k = vec3<f32>(0.57735026);
    let angle = r.x * c.amplitude.x;
    let sn = sin(angle);
    let cs = cos(angle);
    var leaf = a * cs + cross(k, a) * sn + k * (dot(k, a) * (1.0 - cs));
    let y = dot(leaf, TINT_LUMA);
    leaf = vec3<f32>(y) + (leaf - vec3<f32>(y)) * (1.0 + r.y * c.amplitude.y);
    leaf = leaf * (1.0 + r.z * c.amplitude.z);
    if (season_on) {
        let sk = season_key(c, camera.season.y + r.w * c.phase.x);
        let tinted = sk.rgb * max(dot(leaf, TINT_LUMA), 0.0);
        leaf = leaf + (tinted - leaf) * sk.w;
    }
    let bark = a * (1.0 + r.z * c.amplitude.w);
    return clamp(bark + (leaf - bark) * leafness, vec3<f32>(0.0), vec3<f32>(1.0));
}
