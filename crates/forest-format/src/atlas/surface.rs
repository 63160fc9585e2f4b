//! The surface attributes on disk at a reduced resolution: `surface.png` holds every layer at
//! `resolution / SURFACE_SCALE`, each texel the coverage-weighted mean of its block (straight,
//! not premultiplied: a leaf's edge keeps its normal and sky visibility instead of fading
//! towards the empty texels beside it), and loading brings it back to the slab resolution by
//! bilinear filtering weighted by the blocks' coverage, then premultiplies it by each texel's
//! own coverage.

use super::Layers;

/// Texels of the slab images per texel of the stored surface attributes, along each axis.
///
/// Why 2: the normals, sky visibility and translucency of foliage are high in entropy
/// (averaged over many leaves per texel) and compress badly (PNG; JPEG even at quality 80
/// barely halves them, with errors of 11 codes); at the default 512² the full-resolution
/// mosaic was 6.6 MB of an 8.6 MB atlas (oak). At half resolution it is 1.86 MB, and the
/// relit quad stream's FLIP against the reference rises by 2.4 % under a 55° sun and 0.9 %
/// under a 15° sun (oak, one tree filling a 320² view). A plain box filter of the
/// premultiplied values, which faded leaf edges towards their empty neighbours, gave 1 % and
/// 6 %, and at a quarter of the resolution 4 % and 13 % for about 0.55 MB.
pub const SURFACE_SCALE: u32 = 2;

/// Each `f × f` block's coverage: the mean of `alpha`'s channel 3.
fn block_coverage(alpha: &Layers, f: usize) -> Vec<f32> {
    let r = alpha.resolution as usize;
    let h = r / f;
    let mut out = vec![0f32; alpha.count as usize * h * h];
    for l in 0..alpha.count as usize {
        let a = alpha.layer(l as u32);
        for y in 0..h {
            for x in 0..h {
                let mut sum = 0u32;
                for dy in 0..f {
                    for dx in 0..f {
                        sum += u32::from(a[((y * f + dy) * r + x * f + dx) * 4 + 3]);
                    }
                }
                out[(l * h + y) * h + x] = sum as f32 / (f * f) as f32;
            }
        }
    }
    out
}

impl Layers {
    /// Premultiplied surface layers (`self`, every channel at most the coverage of `alpha`'s
    /// layers of the same size) reduced by `f` along each axis: each block's coverage-weighted
    /// mean, straight (`Σ value / Σ alpha`, scaled to 0–255); 0 where a block is uncovered.
    pub fn surface_downsampled(&self, alpha: &Layers, f: u32) -> Layers {
        let (r, f) = (self.resolution as usize, f as usize);
        assert_eq!(
            (alpha.resolution, alpha.count),
            (self.resolution, self.count)
        );
        let h = r / f;
        let mut rgba = vec![0u8; self.count as usize * h * h * 4];
        for l in 0..self.count as usize {
            let (src, a) = (self.layer(l as u32), alpha.layer(l as u32));
            let dst = &mut rgba[l * h * h * 4..(l + 1) * h * h * 4];
            for y in 0..h {
                for x in 0..h {
                    let (mut sum, mut cover) = ([0u32; 4], 0u32);
                    for dy in 0..f {
                        for dx in 0..f {
                            let i = ((y * f + dy) * r + x * f + dx) * 4;
                            cover += u32::from(a[i + 3]);
                            for c in 0..4 {
                                sum[c] += u32::from(src[i + c]);
                            }
                        }
                    }
                    for c in 0..4 {
                        if let Some(v) = (sum[c] * 255 + cover / 2).checked_div(cover) {
                            dst[(y * h + x) * 4 + c] = v.min(255) as u8;
                        }
                    }
                }
            }
        }
        Layers {
            resolution: h as u32,
            count: self.count,
            rgba,
        }
    }

    /// [`Self::surface_downsampled`]'s layers brought back up by `f` along each axis for the
    /// coverage `alpha` (layers of the result's resolution, alpha in channel 3): bilinear
    /// between block centres (clamped at the layer's edges, so layers never mix), each
    /// neighbour weighted by its block's coverage, then premultiplied by the texel's own
    /// coverage.
    pub fn surface_upsampled(&self, alpha: &Layers, f: u32) -> Layers {
        let (h, f) = (self.resolution as usize, f as usize);
        let r = h * f;
        assert_eq!((alpha.resolution as usize, alpha.count), (r, self.count));
        let cover = block_coverage(alpha, f);
        let mut rgba = vec![0u8; self.count as usize * r * r * 4];
        let last = (h - 1) as f32;
        for l in 0..self.count as usize {
            let src = self.layer(l as u32);
            let full = alpha.layer(l as u32);
            let dst = &mut rgba[l * r * r * 4..(l + 1) * r * r * 4];
            let cov = &cover[l * h * h..(l + 1) * h * h];
            for y in 0..r {
                let fy = ((y as f32 + 0.5) / f as f32 - 0.5).clamp(0.0, last);
                let (y0, ty) = (fy.floor() as usize, fy.fract());
                let y1 = (y0 + 1).min(h - 1);
                for x in 0..r {
                    let a = full[(y * r + x) * 4 + 3];
                    if a == 0 {
                        continue;
                    }
                    let fx = ((x as f32 + 0.5) / f as f32 - 0.5).clamp(0.0, last);
                    let (x0, tx) = (fx.floor() as usize, fx.fract());
                    let x1 = (x0 + 1).min(h - 1);
                    let taps = [
                        (x0, y0, (1.0 - tx) * (1.0 - ty)),
                        (x1, y0, tx * (1.0 - ty)),
                        (x0, y1, (1.0 - tx) * ty),
                        (x1, y1, tx * ty),
                    ];
                    let (mut sum, mut weight) = ([0f32; 4], 0f32);
                    for (xx, yy, w) in taps {
                        let w = w * cov[yy * h + xx];
                        weight += w;
                        for (c, s) in sum.iter_mut().enumerate() {
                            *s += w * f32::from(src[(yy * h + xx) * 4 + c]);
                        }
                    }
                    if weight <= 0.0 {
                        continue;
                    }
                    for (c, s) in sum.iter().enumerate() {
                        let v = s / weight * f32::from(a) / 255.0;
                        dst[(y * r + x) * 4 + c] = (v.round() as u8).min(a);
                    }
                }
            }
        }
        Layers {
            resolution: r as u32,
            count: self.count,
            rgba,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn covered(resolution: u32, count: u32, alpha: impl Fn(usize) -> u8) -> Layers {
        let n = (resolution * resolution * count) as usize;
        Layers {
            resolution,
            count,
            rgba: (0..n).flat_map(|i| [0, 0, 0, alpha(i)]).collect(),
        }
    }

    /// Premultiply straight values `s(i)` by `alpha`'s coverage.
    fn premultiplied(alpha: &Layers, s: impl Fn(usize) -> [u8; 4]) -> Layers {
        Layers {
            rgba: alpha
                .rgba
                .chunks_exact(4)
                .enumerate()
                .flat_map(|(i, p)| {
                    s(i).map(|v| ((u32::from(v) * u32::from(p[3]) + 127) / 255) as u8)
                })
                .collect(),
            ..alpha.clone()
        }
    }

    #[test]
    fn constants_and_linear_ramps_come_back_under_full_coverage() {
        let (r, f) = (16u32, 2u32);
        let alpha = covered(r, 2, |_| 255);
        // Layer 0 constant, layer 1 a ramp along x (exact under both filters inside).
        let surface = premultiplied(&alpha, |i| {
            let x = i % r as usize;
            if i < (r * r) as usize {
                [90, 40, 200, 255]
            } else {
                [(x * 16) as u8, 0, 0, 0]
            }
        });
        let small = surface.surface_downsampled(&alpha, f);
        assert_eq!((small.resolution, small.count), (8, 2));
        // Block means: the ramp's pairs (0, 16) → 8, (32, 48) → 40, …
        assert_eq!(small.layer(1)[0], 8);
        assert_eq!(small.layer(1)[4], 40);
        let back = small.surface_upsampled(&alpha, f);
        assert_eq!(back.layer(0), surface.layer(0));
        for y in 0..r as usize {
            for x in 1..r as usize - 1 {
                let got = back.layer(1)[(y * r as usize + x) * 4];
                assert!(got.abs_diff((x * 16) as u8) <= 1, "x {x}: {got}");
            }
        }
        // Layers never mix: the edge of layer 1 holds its own values.
        assert!(back.layer(1)[0] <= 16);
    }

    #[test]
    fn edges_keep_their_straight_values_and_stay_within_the_coverage() {
        // Coverage varying texel to texel, half the texels empty: a straight value that is
        // constant where covered comes back at every covered texel (premultiplied by its own
        // coverage), with no fade towards the empty neighbours.
        let r = 16u32;
        let alpha = covered(r, 1, |i| {
            if (i * 7 + i / 3) % 2 == 0 {
                0
            } else {
                (60 + (i * 37) % 196) as u8
            }
        });
        let surface = premultiplied(&alpha, |_| [200, 120, 30, 90]);
        let back = surface
            .surface_downsampled(&alpha, 2)
            .surface_upsampled(&alpha, 2);
        for (p, (q, a)) in back
            .rgba
            .chunks_exact(4)
            .zip(surface.rgba.chunks_exact(4).zip(alpha.rgba.chunks_exact(4)))
        {
            assert!(p.iter().all(|&v| v <= a[3]), "{p:?} over {}", a[3]);
            for c in 0..4 {
                assert!(
                    p[c].abs_diff(q[c]) <= 1,
                    "{p:?} against {q:?} at coverage {}",
                    a[3]
                );
            }
        }
    }
}
