//! Deterministic sample jitter shared by the bake's tracers: an integer hash, a unit
//! number from it, and stratified points on a triangle.

/// A 32-bit integer hash (lowbias32) for deterministic sample jitter.
pub(crate) fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// The top 24 bits of a hash as a number in `[0, 1)`.
pub(crate) fn unit(x: u32) -> f32 {
    (x >> 8) as f32 / (1u32 << 24) as f32
}

/// Barycentric weights of point `s` of `side²` stratified, jittered points on triangle `tri`
/// (`salt` separates the users' jitter): stratum `(s mod side, s div side)` of the unit square,
/// warped onto the triangle by `(1 − √u, √u(1 − v), √u·v)`, uniform by area.
pub(crate) fn stratified_barycentric(tri: u32, s: u32, side: u32, salt: u32) -> [f32; 3] {
    let h = hash(tri ^ hash(s ^ salt));
    let u = ((s % side) as f32 + unit(h)) / side as f32;
    let v = ((s / side) as f32 + unit(hash(h))) / side as f32;
    let r = u.sqrt();
    [1.0 - r, r * (1.0 - v), r * v]
}
