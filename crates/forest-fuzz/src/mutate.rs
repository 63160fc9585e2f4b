//! Seeded mutations for the smoke run: byte flips, overwrites of 4-byte fields with extreme
//! values, truncations, splices within the input and bytes that matter to text formats.
//! Not coverage-guided (that is AFL++'s job in `fuzz/afl`); enough to keep every target
//! exercised by `cargo test`.

use forest_format::noise::SplitMix64;

/// One to four mutations of `seed`.
pub fn mutate(seed: &[u8], rng: &mut SplitMix64) -> Vec<u8> {
    let mut b = seed.to_vec();
    let pick = |rng: &mut SplitMix64, n: usize| (rng.next_u64() % n.max(1) as u64) as usize;
    for _ in 0..1 + pick(rng, 4) {
        match pick(rng, 6) {
            0 if !b.is_empty() => {
                let i = pick(rng, b.len());
                b[i] ^= 1 << pick(rng, 8);
            }
            1 if b.len() >= 4 => {
                // A length or count field set to an extreme value.
                let i = pick(rng, b.len() - 3);
                let v = [u32::MAX, 1 << 31, 1 << 24, 0x00ff_ffff, 0][pick(rng, 5)];
                b[i..i + 4].copy_from_slice(&v.to_le_bytes());
            }
            2 => b.truncate(pick(rng, b.len() + 1)),
            3 if !b.is_empty() => {
                let i = pick(rng, b.len());
                let j = pick(rng, b.len());
                let chunk = b[i..(i + 16).min(b.len())].to_vec();
                b.splice(j..j, chunk);
            }
            4 if !b.is_empty() => {
                let i = pick(rng, b.len());
                b[i] = [b'0', b'9', b'-', b'e', b'"', b'{', b']', b'.', 0xff][pick(rng, 9)];
            }
            _ => b.push(rng.next_u64() as u8),
        }
    }
    b
}
