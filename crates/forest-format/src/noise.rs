//! Seeded, platform-independent randomness and smooth noise (forest and terrain
//! generation).

/// SplitMix64: a small, fast, well-mixed generator (deterministic across platforms).
#[derive(Clone, Debug)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// Uniform in `[0, 1)`.
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
}

fn lattice(ix: i32, iy: i32, seed: u64) -> f32 {
    let mut h = SplitMix64(seed ^ (ix as u32 as u64) << 32 ^ iy as u32 as u64);
    h.next_f32() * 2.0 - 1.0
}

/// Smooth value noise in `[−1, 1]` with unit lattice spacing.
pub fn value_noise(x: f32, y: f32, seed: u64) -> f32 {
    let (fx, fy) = (x.floor(), y.floor());
    let (ix, iy) = (fx as i32, fy as i32);
    let s = |t: f32| t * t * (3.0 - 2.0 * t);
    let (tx, ty) = (s(x - fx), s(y - fy));
    // Lattice coordinates wrap (and `as` saturates) far from the origin: the noise repeats
    // there instead of overflowing.
    let (jx, jy) = (ix.wrapping_add(1), iy.wrapping_add(1));
    let a = lattice(ix, iy, seed) * (1.0 - tx) + lattice(jx, iy, seed) * tx;
    let b = lattice(ix, jy, seed) * (1.0 - tx) + lattice(jx, jy, seed) * tx;
    a * (1.0 - ty) + b * ty
}

/// Turbulence in `[0, 1]`: 4 octaves of |value noise|.
pub fn turbulence(x: f32, y: f32, seed: u64) -> f32 {
    let mut sum = 0.0;
    let mut norm = 0.0;
    for o in 0..4 {
        let f = (1 << o) as f32;
        sum += value_noise(x * f, y * f, seed.wrapping_add(o as u64)).abs() / f;
        norm += 1.0 / f;
    }
    sum / norm
}
