// The ground's pattern: soil with patches of moss, two octaves of hashed value noise (23 m and
// 6.1 m) through a smooth step. Pure functions of world (x, z), with no bindings, so that a host
// drawing its own ground can import them (`#import ground`) and match the library's. Mirrors
// options::ground_moss.

// One of 2^24 values in [0, 1) per lattice point: a 32-bit integer hash (after Chris Wellons'
// "lowbias32").
fn ground_hash(ix: i32, iz: i32) -> f32 {
    var h = (bitcast<u32>(ix) * 0x8da6b343u) ^ (bitcast<u32>(iz) * 0xd8163841u);
    h = (h ^ (h >> 16u)) * 0x7feb352du;
    h = (h ^ (h >> 15u)) * 0x846ca68bu;
    h = h ^ (h >> 16u);
    return f32(h >> 8u) / 16777216.0;
}

// Smooth value noise in [0, 1) with unit lattice spacing.
fn ground_noise(p: vec2<f32>) -> f32 {
    let f = floor(p);
    let i = vec2<i32>(f);
    let t = p - f;
    let s = t * t * (3.0 - 2.0 * t);
    let a = mix(ground_hash(i.x, i.y), ground_hash(i.x + 1, i.y), s.x);
    let b = mix(ground_hash(i.x, i.y + 1), ground_hash(i.x + 1, i.y + 1), s.x);
    return mix(a, b, s.y);
}

// How much moss covers the ground at world (x, z), in [0, 1].
fn ground_moss(xz: vec2<f32>) -> f32 {
    let m = 0.65 * ground_noise(xz / 23.0) + 0.35 * ground_noise(xz / 6.1);
    let t = clamp((m - 0.3) / 0.4, 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}
