//! Ray tracing the slab images (layered depth images) of one model.
//!
//! For every direction, pixel and jittered sample, one ray enters the bounding sphere at its
//! front (sphere depth 0) and runs along `−dir`. Its first solid hit in each slab gives what
//! the run-time light needs, averaged into that slab's pixel: premultiplied albedo =
//! Σ albedo / spp, alpha = hits / spp, depth = mean sphere depth of the hits, and the surface
//! attributes (normal facing the ray, sky visibility from [`crate::sky`], translucency) as
//! coverage-weighted means stored premultiplied. No light is traced. Per sample the hits are opaque (alpha-tested), so front-to-back compositing within
//! a slab reduces to taking its first hit; partial coverage comes from the samples.

use std::sync::atomic::{AtomicU64, Ordering};

use forest_format::shading::Surface;
use forest_format::shading::{hemi_oct_encode, srgb_decode_table, srgb_encode};
use forest_format::slab::{DirectionFrame, Sphere};
use glam::{Vec2, Vec3};
use rayon::prelude::*;

use crate::trace::Scene;

/// The traced slab images of all layers (`layer = direction·slabs + slab`).
#[derive(Clone, Debug, PartialEq)]
pub struct SlabImages {
    /// Side in pixels.
    pub resolution: u32,
    /// Number of layers.
    pub layers: u32,
    /// RGBA8 per layer pixel: premultiplied, sRGB-encoded albedo; linear alpha.
    pub rgba: Vec<u8>,
    /// RGBA8 per layer pixel, linear and premultiplied by the alpha: the hemispherical
    /// octahedral code of the mean normal in the direction's frame
    /// ([`forest_format::shading::hemi_oct_encode`]) in R and G, sky visibility in B,
    /// translucency in A.
    pub surface: Vec<u8>,
    /// Mean sphere depth of the hits per layer pixel, in `[0,1]` (0 where blank).
    pub depth: Vec<f32>,
}

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

/// Sample offset `k` of `spp` within pixel `seed`: stratified on an `n × n` grid when `spp`
/// is a square, else uniformly jittered; each in `[0,1)²`.
pub fn sample_offset(seed: u32, k: u32, spp: u32) -> Vec2 {
    let h1 = hash(seed ^ hash(k.wrapping_mul(0x9e37_79b9)));
    let h2 = hash(h1 ^ 0x5bd1_e995);
    let n = (spp as f32).sqrt().round() as u32;
    if spp == 1 {
        Vec2::splat(0.5)
    } else if n * n == spp {
        Vec2::new(
            ((k % n) as f32 + unit(h1)) / n as f32,
            ((k / n) as f32 + unit(h2)) / n as f32,
        )
    } else {
        Vec2::new(unit(h1), unit(h2))
    }
}

/// What to trace: the framing sphere, the direction frames and the slab layout.
#[derive(Clone, Copy, Debug)]
pub struct SlabSetup<'a> {
    /// The sphere every image frames.
    pub sphere: Sphere,
    /// One frame per sampling direction.
    pub frames: &'a [DirectionFrame],
    /// Slabs per direction.
    pub slabs: u32,
    /// Image side in pixels.
    pub resolution: u32,
    /// Samples per pixel.
    pub spp: u32,
}

/// Trace every layer, with `sky` the sky visibility of the scene's triangles
/// ([`crate::sky::triangle_sky`]). `progress(done, total)` is called as image rows complete.
pub fn trace_layers(
    scene: &Scene,
    sky: &[crate::sky::TriangleSky],
    setup: &SlabSetup,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> SlabImages {
    let SlabSetup {
        sphere,
        frames,
        slabs,
        resolution,
        spp,
    } = *setup;
    let sphere = &sphere;
    let r = resolution as usize;
    let layers = frames.len() as u32 * slabs;
    let total_rows = (frames.len() * r) as u64;
    let done = AtomicU64::new(0);
    let table = srgb_decode_table();
    let diameter = 2.0 * sphere.radius;
    // One task per (direction, row); each returns `slabs` rows of colour, surface and depth.
    let rows: Vec<SlabRows> = (0..frames.len() * r)
        .into_par_iter()
        .map(|task| {
            let (di, y) = (task / r, task % r);
            let frame = &frames[di];
            let mut rgba = vec![[0u8; 4]; slabs as usize * r];
            let mut surface = vec![[0u8; 4]; slabs as usize * r];
            let mut depth = vec![0f32; slabs as usize * r];
            let mut acc = vec![Acc::default(); slabs as usize];
            for x in 0..r {
                acc.iter_mut().for_each(|a| *a = Acc::default());
                let seed = hash((di as u32) << 26 ^ (y as u32) << 13 ^ x as u32);
                for k in 0..spp {
                    let off = sample_offset(seed, k, spp);
                    let u = (x as f32 + off.x) / resolution as f32;
                    let v = (y as f32 + off.y) / resolution as f32;
                    let origin = sphere.image_to_object(frame, u, v, 0.0);
                    let dir = -frame.dir;
                    let mut tmin = 0.0f32;
                    while let Some(hit) = scene.closest(origin, dir, tmin, diameter) {
                        let d = hit.t / diameter;
                        let s = ((d * slabs as f32) as u32).min(slabs - 1);
                        let hit_surface = surface_at(scene, sky, &table, &hit, dir);
                        let a = &mut acc[s as usize];
                        a.albedo += hit_surface.albedo;
                        a.normal += hit_surface.normal;
                        a.sky += hit_surface.sky_visibility;
                        a.translucency += hit_surface.translucency;
                        a.hits += 1;
                        a.depth += d;
                        if s + 1 >= slabs {
                            break;
                        }
                        tmin = diameter * (s + 1) as f32 / slabs as f32;
                    }
                }
                for s in 0..slabs as usize {
                    let a = &acc[s];
                    if a.hits == 0 {
                        continue;
                    }
                    let alpha = a.hits as f32 / spp as f32;
                    let colour = (a.albedo / spp as f32).min(Vec3::splat(alpha));
                    let a8 = (alpha * 255.0).round() as u8;
                    rgba[s * r + x] = [
                        (srgb_encode(colour.x) * 255.0).round() as u8,
                        (srgb_encode(colour.y) * 255.0).round() as u8,
                        (srgb_encode(colour.z) * 255.0).round() as u8,
                        a8,
                    ];
                    // The mean normal in the direction's frame (z towards the viewer).
                    let n = a.normal.try_normalize().unwrap_or(frame.dir);
                    let local = Vec3::new(n.dot(frame.right), n.dot(frame.up), n.dot(frame.dir));
                    let e = hemi_oct_encode(local);
                    let hits = a.hits as f32;
                    // Premultiplied by the stored alpha, never above it.
                    let q = |v: f32| ((v.clamp(0.0, 1.0) * f32::from(a8)).round() as u8).min(a8);
                    surface[s * r + x] =
                        [q(e.x), q(e.y), q(a.sky / hits), q(a.translucency / hits)];
                    depth[s * r + x] = a.depth / hits;
                }
            }
            let n = done.fetch_add(1, Ordering::Relaxed) + 1;
            if n.is_multiple_of(64) || n == total_rows {
                progress(n, total_rows);
            }
            (rgba, surface, depth)
        })
        .collect();
    let mut out = SlabImages {
        resolution,
        layers,
        rgba: vec![0; layers as usize * r * r * 4],
        surface: vec![0; layers as usize * r * r * 4],
        depth: vec![0.0; layers as usize * r * r],
    };
    for (task, (rgba, surface, depth)) in rows.into_iter().enumerate() {
        let (di, y) = (task / r, task % r);
        for s in 0..slabs as usize {
            let layer = di * slabs as usize + s;
            let base = (layer * r + y) * r;
            for x in 0..r {
                out.rgba[(base + x) * 4..(base + x) * 4 + 4].copy_from_slice(&rgba[s * r + x]);
                out.surface[(base + x) * 4..(base + x) * 4 + 4]
                    .copy_from_slice(&surface[s * r + x]);
                out.depth[base + x] = depth[s * r + x];
            }
        }
    }
    out
}

/// One task's rows, `slabs` of each: colour, surface attributes, depth.
type SlabRows = (Vec<[u8; 4]>, Vec<[u8; 4]>, Vec<f32>);

/// One slab pixel's sums over its samples' hits.
#[derive(Clone, Copy, Default)]
struct Acc {
    albedo: Vec3,
    normal: Vec3,
    sky: f32,
    translucency: f32,
    hits: u32,
    depth: f32,
}

/// What the shading model needs of a hit seen along `dir`: albedo, the normal turned towards
/// the viewer, the sky visibility of that side and the translucency.
pub fn surface_at(
    scene: &Scene,
    sky: &[crate::sky::TriangleSky],
    table: &[f32; 256],
    hit: &crate::trace::Hit,
    dir: Vec3,
) -> Surface {
    let tri = &scene.tris[hit.tri as usize];
    let (b1, b2) = (hit.bary.x, hit.bary.y);
    let b0 = 1.0 - b1 - b2;
    let uv = tri.uv[0] * b0 + tri.uv[1] * b1 + tri.uv[2] * b2;
    let mut n = (tri.n[0] * b0 + tri.n[1] * b1 + tri.n[2] * b2)
        .try_normalize()
        .unwrap_or(tri.n[0]);
    if n.dot(dir) > 0.0 {
        n = -n; // two-sided: face the viewer
    }
    let material = &scene.mesh.materials[tri.material as usize];
    let albedo = match material.colour {
        Some(t) => material.kd * scene.mesh.textures[t].linear_rgb(uv, table),
        None => material.kd,
    };
    Surface {
        albedo,
        normal: n,
        sky_visibility: crate::sky::sky_at(scene, sky, hit.tri, hit.bary, dir),
        translucency: material.translucency,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_offsets_are_stratified_and_deterministic() {
        for k in 0..16 {
            let o = sample_offset(77, k, 16);
            assert!(o.x >= (k % 4) as f32 / 4.0 && o.x < (k % 4 + 1) as f32 / 4.0);
            assert!(o.y >= (k / 4) as f32 / 4.0 && o.y < (k / 4 + 1) as f32 / 4.0);
            assert_eq!(o, sample_offset(77, k, 16));
        }
        assert_eq!(sample_offset(1, 0, 1), Vec2::splat(0.5));
        let o = sample_offset(5, 2, 3);
        assert!((0.0..1.0).contains(&o.x) && (0.0..1.0).contains(&o.y));
    }
}
