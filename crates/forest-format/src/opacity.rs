//! The opacity volume: a tree's own foliage as a density on a voxel grid, so that a crown can
//! shade itself under any run-time sun (the statistical approach of volumetric foliage
//! shadowing: the transmittance towards the sun is `exp(−∫σ ds)` through the leaf-area
//! density σ, instead of exact rays through every leaf).
//!
//! The grid is a cube of [`VOLUME_RESOLUTION`]³ voxels around the tree's bounding sphere
//! (centre ± radius on each axis). Each voxel holds the optical depth across one voxel
//! length, `τ = G·A/h²` for the alpha-tested surface area `A` splatted into it, voxel side
//! `h` and the projection factor `G` ([`LEAF_PROJECTION`]), coded in 8 bits as
//! `τ = max_depth · (code/255)²` (square-root coding keeps sparse twigs and dense cores
//! apart). [`OpacityVolume::transmittance`] is the CPU mirror of `sun_transmittance` in the
//! runtime's `common.wgsl`: [`MARCH_STEPS`] trilinear samples along the ray from
//! [`START_VOXELS`] voxels off the surface to the cube's side.
//!
//! Forms that march per fragment (composited far quads, billboards) march the volume's mip
//! level [`COARSE_LEVEL`] in [`COARSE_STEPS`] samples instead
//! ([`OpacityVolume::coarse_transmittance`]): a far tree's pixels span many voxels, and on a
//! CPU rasteriser the full march per fragment cost a tenth of the quad stream's draw time. A
//! plain quad's corners march the level that suits the quad's size ([`quad_march`]).

use std::path::Path;

use glam::Vec3;

use crate::error::FormatError;
use crate::slab::Sphere;

/// Voxels along each side of every opacity volume (one size for all, so that a scene's
/// volumes share one GPU texture).
pub const VOLUME_RESOLUTION: u32 = 32;
/// Samples along a ray towards the sun.
pub const MARCH_STEPS: u32 = 16;
/// Voxels a ray travels before its first sample: a surface point does not shadow itself.
pub const START_VOXELS: f32 = 0.5;
/// Mip level of the volume that the per-fragment march reads (level `l` has
/// `VOLUME_RESOLUTION >> l` voxels a side).
pub const COARSE_LEVEL: u32 = 2;
/// Samples of the per-fragment march along a ray towards the sun (about one level-
/// [`COARSE_LEVEL`] voxel a step across the cube).
pub const COARSE_STEPS: u32 = 6;
/// Samples of the march through mip level 1.
pub const MID_STEPS: u32 = 8;
/// Quads of hierarchy levels up to this one march level [`COARSE_LEVEL`] at their corners
/// (see [`quad_march`]).
pub const COARSE_QUAD_LEVEL: u32 = 2;
/// Quads of hierarchy levels above [`COARSE_QUAD_LEVEL`] and up to this one march level 1.
pub const MID_QUAD_LEVEL: u32 = 4;

/// The march a plain quad's corners take, by the quad's hierarchy level: the volume's mip
/// level and the samples along the ray (mirrors `quad_march` in `common.wgsl`). A quad
/// interpolates its corners' transmittance, so detail finer than the quad is lost anyway: a
/// coarse quad (level ≤ [`COARSE_QUAD_LEVEL`], at least 8 level-0 voxels wide) reads the
/// coarse level, which also smooths what its far-apart corners see; a fine one the full volume.
pub const fn quad_march(quad_level: u32) -> (u32, u32) {
    if quad_level <= COARSE_QUAD_LEVEL {
        (COARSE_LEVEL, COARSE_STEPS)
    } else if quad_level <= MID_QUAD_LEVEL {
        (1, MID_STEPS)
    } else {
        (0, MARCH_STEPS)
    }
}

/// The largest optical depth per voxel length an atlas may record for code 255: a voxel that
/// dense passes e^−100 of the light, so anything denser draws the same. The bundled trees' are
/// 1.8 to 7.
pub const MAX_VOXEL_DEPTH: f32 = 100.0;

/// Projection factor of leaf area onto a ray for randomly (spherically) oriented leaves.
pub const LEAF_PROJECTION: f32 = 1.0;

/// A tree's opacity volume (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct OpacityVolume {
    /// Voxels per side.
    pub resolution: u32,
    /// Optical depth per voxel length of code 255 (≥ 0, finite; 0 for an empty volume).
    pub max_depth: f32,
    /// `resolution³` codes, x fastest, then y, then z (object-space axes; voxel `(i, j, k)`
    /// is centred at `centre − radius + (i + ½, j + ½, k + ½)·h`).
    pub codes: Vec<u8>,
}

impl OpacityVolume {
    /// Code a grid of optical depths per voxel length (`resolution³` values, ≥ 0; those
    /// beyond [`MAX_VOXEL_DEPTH`] code as it).
    pub fn from_depths(resolution: u32, depths: &[f32]) -> Self {
        assert_eq!(depths.len(), (resolution as usize).pow(3));
        let max_depth = depths
            .iter()
            .copied()
            .filter(|d| d.is_finite())
            .fold(0.0f32, f32::max)
            // Denser voxels draw the same: they code as 255, the densest an atlas records.
            .min(MAX_VOXEL_DEPTH);
        let codes = depths
            .iter()
            .map(|&d| {
                if max_depth > 0.0 && d.is_finite() {
                    ((d.max(0.0) / max_depth).sqrt() * 255.0).round() as u8
                } else {
                    0
                }
            })
            .collect();
        Self {
            resolution,
            max_depth,
            codes,
        }
    }

    /// An empty volume (no self-shadowing).
    pub fn empty(resolution: u32) -> Self {
        Self {
            resolution,
            max_depth: 0.0,
            codes: vec![0; (resolution as usize).pow(3)],
        }
    }

    /// The code of voxel `(i, j, k)` as the GPU's R8Unorm texel reads it, in `[0, 1]`.
    fn unorm(&self, i: u32, j: u32, k: u32) -> f32 {
        let r = self.resolution as usize;
        f32::from(self.codes[i as usize + r * (j as usize + r * k as usize)]) / 255.0
    }

    /// Optical depth per voxel length at `u` (the cube mapped to `[0, 1]³`): the codes
    /// filtered trilinearly between voxel centres (clamped to the outer voxels), then decoded.
    pub fn sample(&self, u: Vec3) -> f32 {
        let r = self.resolution;
        let x = (u * r as f32 - 0.5).clamp(Vec3::ZERO, Vec3::splat(r as f32 - 1.0));
        let i0 = x.floor();
        let f = x - i0;
        let (i, j, k) = (i0.x as u32, i0.y as u32, i0.z as u32);
        let n = |a: u32| (a + 1).min(r - 1);
        let mut s = 0.0;
        for (dk, wk) in [(k, 1.0 - f.z), (n(k), f.z)] {
            for (dj, wj) in [(j, 1.0 - f.y), (n(j), f.y)] {
                for (di, wi) in [(i, 1.0 - f.x), (n(i), f.x)] {
                    s += wi * wj * wk * self.unorm(di, dj, dk);
                }
            }
        }
        self.max_depth * s * s
    }

    /// Transmittance from object-space point `p` towards unit direction `dir` through the
    /// tree whose bounding sphere the volume frames, in `[0, 1]`.
    pub fn transmittance(&self, sphere: &Sphere, p: Vec3, dir: Vec3) -> f32 {
        Self::level_transmittance(self, 0, MARCH_STEPS, sphere, p, dir)
    }

    /// The volume at half the resolution (`resolution` even): each voxel holds the mean
    /// optical depth of the 2³ it covers, coded as [`Self::from_depths`] codes with the same
    /// `max_depth` (so the code is the root mean square of theirs).
    pub fn downsampled(&self) -> Self {
        assert!(self.resolution >= 2 && self.resolution.is_multiple_of(2));
        let h = self.resolution / 2;
        let mut codes = Vec::with_capacity((h as usize).pow(3));
        for k in 0..h {
            for j in 0..h {
                for i in 0..h {
                    let mut sum = 0.0f32;
                    for c in 0..8u32 {
                        let (a, b, d) = (2 * i + (c & 1), 2 * j + (c >> 1 & 1), 2 * k + (c >> 2));
                        sum += self.unorm(a, b, d).powi(2);
                    }
                    codes.push(((sum / 8.0).sqrt() * 255.0).round() as u8);
                }
            }
        }
        Self {
            resolution: h,
            max_depth: self.max_depth,
            codes,
        }
    }

    /// Mip levels `0 ..= last` of the volume, finest first (each from the one before).
    pub fn mips(&self, last: u32) -> Vec<Self> {
        let mut levels = vec![self.clone()];
        for _ in 0..last {
            let next = levels[levels.len() - 1].downsampled();
            levels.push(next);
        }
        levels
    }

    /// The per-fragment forms' transmittance (CPU mirror of `sun_transmittance_coarse` in
    /// `common.wgsl`): [`COARSE_STEPS`] samples of `coarse`, this volume's mip level
    /// [`COARSE_LEVEL`] ([`Self::mips`]), along the same ray as [`Self::transmittance`].
    pub fn coarse_transmittance(coarse: &Self, sphere: &Sphere, p: Vec3, dir: Vec3) -> f32 {
        Self::level_transmittance(coarse, COARSE_LEVEL, COARSE_STEPS, sphere, p, dir)
    }

    /// The march of `steps` samples through `mip`, a volume's mip level `level`
    /// ([`Self::mips`]), along the same ray as [`Self::transmittance`] (CPU mirror of
    /// `opacity_march` in `common.wgsl`); optical depth stays per level-0 voxel length.
    pub fn level_transmittance(
        mip: &Self,
        level: u32,
        steps: u32,
        sphere: &Sphere,
        p: Vec3,
        dir: Vec3,
    ) -> f32 {
        march(
            cube_point(sphere, p),
            dir,
            mip.resolution << level,
            steps,
            |x| mip.sample(x),
        )
    }

    /// Where a view ray meets a tree whose image has no depth (CPU mirror of
    /// `median_depth_point` in `common.wgsl`): along unit `dir` from the bounding sphere's
    /// front through `p` (object space), the point at which `coarse`, this volume's mip level
    /// [`COARSE_LEVEL`], has stopped half the ray's light, linearly within the step of
    /// [`COARSE_STEPS`] across the diameter where that happens; `p` where it stops less.
    pub fn median_depth_point(coarse: &Self, sphere: &Sphere, p: Vec3, dir: Vec3) -> Vec3 {
        let front = p - dir * sphere.radius;
        let u = cube_point(sphere, front);
        let dt = 1.0 / COARSE_STEPS as f32;
        let fine = (coarse.resolution << COARSE_LEVEL) as f32;
        let mut tau = 0.0;
        for i in 0..COARSE_STEPS {
            let step = coarse.sample(u + dir * ((i as f32 + 0.5) * dt)) * dt * fine;
            if tau + step >= std::f32::consts::LN_2 {
                let f = (std::f32::consts::LN_2 - tau) / step.max(1e-6);
                return front + dir * (2.0 * sphere.radius * (i as f32 + f) * dt);
            }
            tau += step;
        }
        p
    }

    /// The volume as an 8-bit grey PNG: `resolution` wide, slice `k` at rows
    /// `k·resolution ..`.
    pub fn encode_png(&self) -> Vec<u8> {
        let r = self.resolution;
        crate::atlas::codecs::encode_png(r, r * r, &self.codes, image::ExtendedColorType::L8)
    }

    /// Decode [`Self::encode_png`]'s bytes (`file` names them in errors) of a volume with
    /// `resolution` voxels per side and `max_depth`.
    pub fn decode_png(
        bytes: &[u8],
        resolution: u32,
        max_depth: f32,
        file: &Path,
    ) -> Result<Self, FormatError> {
        let (w, h) = (resolution, resolution * resolution);
        let dims = crate::bounded::image_dimensions(bytes, Some(image::ImageFormat::Png), file)?;
        if dims != (w, h) {
            return Err(FormatError::invalid(
                file,
                format!(
                    "opacity volume is {}×{} pixels, expected {w}×{h} ({resolution} slices of \
                     {resolution}²)",
                    dims.0, dims.1
                ),
            ));
        }
        let img = match crate::bounded::decode_image(bytes, Some(image::ImageFormat::Png), file)? {
            image::DynamicImage::ImageLuma8(i) => i,
            other => {
                return Err(FormatError::invalid(
                    file,
                    format!("opacity volume is {:?}, expected 8-bit grey", other.color()),
                ));
            }
        };
        if img.dimensions() != (w, h) {
            return Err(FormatError::invalid(
                file,
                format!(
                    "decoded to {}×{} pixels, expected {w}×{h}",
                    img.width(),
                    img.height()
                ),
            ));
        }
        let v = Self {
            resolution,
            max_depth,
            codes: img.into_raw(),
        };
        v.check_scale().map_err(|e| FormatError::invalid(file, e))?;
        Ok(v)
    }

    /// Check the codes against `max_depth` as [`Self::from_depths`] writes them: the densest
    /// voxel codes as 255 when `max_depth` > 0, and every code is 0 when it is 0.
    pub fn check_scale(&self) -> Result<(), String> {
        let densest = self.codes.iter().copied().max().unwrap_or(0);
        match (self.max_depth > 0.0, densest) {
            (true, 255) | (false, 0) => Ok(()),
            (true, c) => Err(format!(
                "the densest voxel codes as {c}, but a volume of max_depth {} codes its \
                 densest as 255",
                self.max_depth
            )),
            (false, c) => Err(format!(
                "max_depth is 0 (no self-shadowing), but a voxel codes as {c}"
            )),
        }
    }
}

/// Object-space point `p` in the unit cube a volume spans around `sphere` (its bounding
/// cube: `[0, 1]³` inside).
fn cube_point(sphere: &Sphere, p: Vec3) -> Vec3 {
    (p - (sphere.center - Vec3::splat(sphere.radius))) / (2.0 * sphere.radius)
}

/// The march of [`OpacityVolume::transmittance`] from unit-cube point `u` along unit `dir`,
/// with `depth(x)` the optical depth per length of a voxel of a `resolution`-voxel grid at
/// `x`: `steps` midpoint samples over the part of the ray inside the cube, from
/// [`START_VOXELS`] of those voxels on (or from where a ray from outside enters).
pub fn march(u: Vec3, dir: Vec3, resolution: u32, steps: u32, depth: impl Fn(Vec3) -> f32) -> f32 {
    let (enter, exit) = cube_span(u, dir);
    let start = (START_VOXELS / resolution as f32).max(enter);
    if exit <= start {
        return 1.0;
    }
    let dt = (exit - start) / steps as f32;
    let sum: f32 = (0..steps)
        .map(|k| depth(u + dir * (start + (k as f32 + 0.5) * dt)))
        .sum();
    (-sum * dt * resolution as f32).exp()
}

/// Distances along unit `dir` from `u` to where the ray enters and leaves `[0, 1]³` (the
/// slab method; entry 0 or less from inside; exit ≤ entry when the ray misses the cube or it
/// lies behind).
pub fn cube_span(u: Vec3, dir: Vec3) -> (f32, f32) {
    let (mut enter, mut exit) = (f32::NEG_INFINITY, f32::INFINITY);
    for (u, d) in [(u.x, dir.x), (u.y, dir.y), (u.z, dir.z)] {
        if d.abs() > 1e-8 {
            let (a, b) = (-u / d, (1.0 - u) / d);
            enter = enter.max(a.min(b));
            exit = exit.min(a.max(b));
        } else if !(0.0..=1.0).contains(&u) {
            return (0.0, 0.0);
        }
    }
    (enter, exit)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere() -> Sphere {
        Sphere {
            center: Vec3::new(0.0, 2.0, 0.0),
            radius: 2.0,
        }
    }

    #[test]
    fn a_uniform_slab_attenuates_by_beer_lambert() {
        // A uniform medium filling the cube: from the centre straight up the ray crosses
        // half the cube less the start offset.
        let r = 16;
        let tau = 0.05;
        let v = OpacityVolume::from_depths(r, &vec![tau; (r as usize).pow(3)]);
        let s = sphere();
        let t = v.transmittance(&s, s.center, Vec3::Y);
        let voxels = r as f32 / 2.0 - START_VOXELS;
        let expected = (-tau * voxels).exp();
        assert!((t - expected).abs() < 1e-4, "{t} vs {expected}");
        // Along a diagonal the path is √3 longer.
        let d = Vec3::ONE.normalize();
        let t = v.transmittance(&s, s.center, d);
        let expected = (-tau * (voxels * 3f32.sqrt() + START_VOXELS * (3f32.sqrt() - 1.0))).exp();
        assert!((t - expected).abs() < 1e-3, "{t} vs {expected}");
    }

    #[test]
    fn a_blocker_shadows_only_the_points_behind_it() {
        let r = 16u32;
        let mut depths = vec![0.0; (r as usize).pow(3)];
        // A dense layer at voxel rows y = 12, 13 over the whole cube.
        for k in 0..r {
            for j in 12..14 {
                for i in 0..r {
                    depths[(i + r * (j + r * k)) as usize] = 5.0;
                }
            }
        }
        let v = OpacityVolume::from_depths(r, &depths);
        let s = sphere();
        let below = s.center - Vec3::Y;
        let above = s.center + Vec3::Y * 1.9;
        assert!(v.transmittance(&s, below, Vec3::Y) < 1e-3);
        assert!((v.transmittance(&s, below, -Vec3::Y) - 1.0).abs() < 1e-6);
        assert!((v.transmittance(&s, above, Vec3::Y) - 1.0).abs() < 1e-6);
        // Sideways under the layer nothing is crossed.
        assert!((v.transmittance(&s, below, Vec3::X) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn codes_round_trip_through_png_and_decode_by_their_square() {
        let r = 8u32;
        let depths: Vec<f32> = (0..r.pow(3)).map(|i| (i % 7) as f32 * 0.3).collect();
        let v = OpacityVolume::from_depths(r, &depths);
        assert!((v.max_depth - 1.8).abs() < 1e-6);
        let back =
            OpacityVolume::decode_png(&v.encode_png(), r, v.max_depth, Path::new("o.png")).unwrap();
        assert_eq!(back, v);
        // At a voxel centre the sample is the voxel's decoded code.
        for (i, &d) in depths.iter().enumerate().step_by(37) {
            let (x, y, z) = (i as u32 % r, i as u32 / r % r, i as u32 / (r * r));
            let u = (Vec3::new(x as f32, y as f32, z as f32) + 0.5) / r as f32;
            assert!((v.sample(u) - d).abs() <= 0.02 * v.max_depth, "{i}");
        }
        let err = OpacityVolume::decode_png(&v.encode_png(), 4, 1.0, Path::new("o.png"));
        assert!(err.unwrap_err().to_string().contains("expected 4×16"));
    }

    #[test]
    fn rays_enter_and_leave_the_cube_where_expected() {
        let exit = |u, d| cube_span(u, d).1;
        assert!((exit(Vec3::splat(0.5), Vec3::Y) - 0.5).abs() < 1e-6);
        assert!((exit(Vec3::new(0.25, 0.5, 0.5), -Vec3::X) - 0.25).abs() < 1e-6);
        // From outside: entering at 0.5, leaving at 1.5; leaving or missing: an empty span.
        let (a, b) = cube_span(Vec3::new(-0.5, 0.5, 0.5), Vec3::X);
        assert!((a - 0.5).abs() < 1e-6 && (b - 1.5).abs() < 1e-6);
        let (a, b) = cube_span(Vec3::new(1.5, 0.5, 0.5), Vec3::X);
        assert!(b <= a.max(0.0));
        let (a, b) = cube_span(Vec3::new(-0.5, 2.0, 0.5), Vec3::X);
        assert!(b <= a);
        assert_eq!(
            OpacityVolume::empty(4).transmittance(&sphere(), Vec3::ZERO, Vec3::Y),
            1.0
        );
    }

    #[test]
    fn a_ray_from_outside_is_attenuated_only_inside() {
        // A uniform medium; a point below the cube looking up crosses the whole cube's height
        // (no start offset: it is not on a surface inside).
        let r = 16;
        let tau = 0.05;
        let v = OpacityVolume::from_depths(r, &vec![tau; (r as usize).pow(3)]);
        let s = sphere();
        let below = s.center - Vec3::Y * (s.radius * 1.5);
        let t = v.transmittance(&s, below, Vec3::Y);
        let expected = (-tau * r as f32).exp();
        assert!((t - expected).abs() < 1e-4, "{t} vs {expected}");
    }
}
