//! The surface attributes on disk at a reduced resolution: `surface.png` holds every layer at
//! `resolution / SURFACE_SCALE` (a box filter of the premultiplied attributes), and loading
//! brings it back to the slab resolution by bilinear filtering within each layer, clamped to
//! the coverage.

use super::Layers;

/// Texels of the slab images per texel of the stored surface attributes, along each axis.
///
/// Why 2: the normals, sky visibility and translucency of foliage are high in entropy
/// (averaged over many leaves per texel) and compress badly (PNG, JPEG even at quality 80
/// barely halves them, with errors of 11 codes); at the default 512² the full-resolution
/// mosaic was 6.6 MB of an 8.6 MB atlas (oak). At half resolution it is 1.9 MB, and the
/// relit quad stream's FLIP against the reference rose by 1 % under a 55° sun and 6 % under
/// a 15° sun (oak, one tree filling a 320² view); at a quarter, by 4 % and 13 % for about
/// 0.55 MB.
pub const SURFACE_SCALE: u32 = 2;

impl Layers {
    /// Every layer box-filtered down by `f` along each axis (`resolution` a multiple of `f`):
    /// the mean of each `f × f` block, rounded.
    pub fn downsampled(&self, f: u32) -> Layers {
        let (r, f) = (self.resolution as usize, f as usize);
        let h = r / f;
        let mut rgba = vec![0u8; self.count as usize * h * h * 4];
        for l in 0..self.count as usize {
            let src = self.layer(l as u32);
            let dst = &mut rgba[l * h * h * 4..(l + 1) * h * h * 4];
            for y in 0..h {
                for x in 0..h {
                    for c in 0..4 {
                        let mut sum = 0u32;
                        for dy in 0..f {
                            for dx in 0..f {
                                sum += u32::from(src[((y * f + dy) * r + x * f + dx) * 4 + c]);
                            }
                        }
                        let n = (f * f) as u32;
                        dst[(y * h + x) * 4 + c] = ((sum + n / 2) / n) as u8;
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

    /// Every layer brought up by `f` along each axis with bilinear filtering between texel
    /// centres (clamped at the layer's edges, so layers never mix), each channel then clamped
    /// to the coverage of `alpha` (layers of the result's resolution, alpha in channel 3).
    pub fn upsampled(&self, f: u32, alpha: &Layers) -> Layers {
        let (h, f) = (self.resolution as usize, f as usize);
        let r = h * f;
        assert_eq!((alpha.resolution as usize, alpha.count), (r, self.count));
        let mut rgba = vec![0u8; self.count as usize * r * r * 4];
        let last = (h - 1) as f32;
        for l in 0..self.count as usize {
            let src = self.layer(l as u32);
            let cover = alpha.layer(l as u32);
            let dst = &mut rgba[l * r * r * 4..(l + 1) * r * r * 4];
            for y in 0..r {
                let fy = ((y as f32 + 0.5) / f as f32 - 0.5).clamp(0.0, last);
                let (y0, ty) = (fy.floor() as usize, fy.fract());
                let y1 = (y0 + 1).min(h - 1);
                for x in 0..r {
                    let fx = ((x as f32 + 0.5) / f as f32 - 0.5).clamp(0.0, last);
                    let (x0, tx) = (fx.floor() as usize, fx.fract());
                    let x1 = (x0 + 1).min(h - 1);
                    let a = cover[(y * r + x) * 4 + 3];
                    for c in 0..4 {
                        let g = |xx: usize, yy: usize| f32::from(src[(yy * h + xx) * 4 + c]);
                        let top = g(x0, y0) + (g(x1, y0) - g(x0, y0)) * tx;
                        let bottom = g(x0, y1) + (g(x1, y1) - g(x0, y1)) * tx;
                        let v = (top + (bottom - top) * ty).round() as u8;
                        dst[(y * r + x) * 4 + c] = v.min(a);
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

    fn opaque(resolution: u32, count: u32) -> Layers {
        Layers {
            resolution,
            count,
            rgba: vec![255; (resolution * resolution * count * 4) as usize],
        }
    }

    #[test]
    fn a_box_filter_then_bilinear_filter_keeps_constants_and_linear_ramps() {
        let (r, f) = (16u32, 2u32);
        // Layer 0 constant, layer 1 a ramp along x (exact under both filters inside).
        let mut l = opaque(r, 2);
        for y in 0..r as usize {
            for x in 0..r as usize {
                let i = (y * r as usize + x) * 4;
                l.rgba[i..i + 4].copy_from_slice(&[90, 40, 200, 255]);
                let j = (r * r) as usize * 4 + i;
                l.rgba[j] = (x * 16) as u8;
            }
        }
        let small = l.downsampled(f);
        assert_eq!((small.resolution, small.count), (8, 2));
        // Block means: the ramp's pairs (0, 16) → 8, (32, 48) → 40, …
        assert_eq!(small.layer(1)[0], 8);
        assert_eq!(small.layer(1)[4], 40);
        let back = small.upsampled(f, &opaque(r, 2));
        assert_eq!(back.layer(0), l.layer(0));
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
    fn upsampled_channels_stay_within_the_coverage() {
        let mut small = opaque(4, 1);
        small.rgba.iter_mut().for_each(|v| *v = 200);
        let mut cover = opaque(8, 1);
        for (i, p) in cover.rgba.chunks_exact_mut(4).enumerate() {
            p[3] = (i * 4) as u8;
        }
        let up = small.upsampled(2, &cover);
        for (p, c) in up.rgba.chunks_exact(4).zip(cover.rgba.chunks_exact(4)) {
            assert!(p.iter().all(|&v| v <= c[3]), "{p:?} over {}", c[3]);
        }
    }
}
