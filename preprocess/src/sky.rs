//! Sky visibility (ambient occlusion by the tree itself), traced once per triangle and shared
//! by the slab images and the triangle methods, so that every method sees the same occlusion.
//!
//! For each side of a triangle, `SIDE²` stratified points on it each trace one alpha-tested ray
//! in a stratified cosine-weighted direction about that side's normal; a ray that leaves the
//! model sees the sky. Each corner gets the barycentric-weighted mean of the points (points on
//! transparent texels are skipped where any opaque one exists, as the bake never shades them),
//! so the value interpolated over the triangle follows where the occlusion is. The "front" of a
//! triangle is the side its shading normals point to, the side [`forest_format::shading`] turns
//! the normal to when the viewer is there.

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use crate::sampling::{hash, unit};
use crate::trace::Scene;

/// Points per side of the stratification grid: `SIDE²` rays per triangle side.
pub const SIDE: u32 = 4;

/// Sky visibility of each triangle's corners, `[front, back]` sides, each in `[0, 1]`.
pub type TriangleSky = [[f32; 3]; 2];

/// A cosine-weighted direction about unit `n` for `u ∈ [0,1)²` (Malley's method).
pub fn cosine_direction(n: Vec3, u: Vec2) -> Vec3 {
    let (t, b) = n.any_orthonormal_pair();
    let r = u.x.sqrt();
    let phi = std::f32::consts::TAU * u.y;
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u.x).max(0.0).sqrt()).normalize()
}

/// The front side's unit normal of triangle `t`: its geometric normal turned towards its mean
/// shading normal.
pub fn front_normal(t: &crate::mesh::Tri) -> Vec3 {
    let geo = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).normalize_or_zero();
    if geo.dot(t.n[0] + t.n[1] + t.n[2]) >= 0.0 {
        geo
    } else {
        -geo
    }
}

/// Sky visibility of every triangle of `scene` (in its triangle order).
pub fn triangle_sky(scene: &Scene) -> Vec<TriangleSky> {
    let mesh = scene.mesh;
    let eps = crate::bounding_sphere(mesh).radius * 1e-5;
    let n = SIDE * SIDE;
    scene
        .tris
        .par_iter()
        .enumerate()
        .map(|(ti, t)| {
            let front = front_normal(t);
            let tested = mesh.materials[t.material as usize].alpha.is_some();
            let mut out = [[1.0f32; 3]; 2];
            for (side, normal) in [front, -front].into_iter().enumerate() {
                let (mut seen, mut weight) = ([0f32; 3], [0f32; 3]);
                let (mut seen_all, mut weight_all) = ([0f32; 3], [0f32; 3]);
                let samples: Vec<([f32; 3], Vec3, Vec3, bool)> = (0..n)
                    .map(|s| {
                        let h = hash(ti as u32 ^ hash(s * 2 + side as u32));
                        let u = ((s % SIDE) as f32 + unit(h)) / SIDE as f32;
                        let v = ((s / SIDE) as f32 + unit(hash(h))) / SIDE as f32;
                        let r = u.sqrt();
                        let b = [1.0 - r, r * (1.0 - v), r * v];
                        let p = t.p[0] * b[0] + t.p[1] * b[1] + t.p[2] * b[2];
                        let uv = t.uv[0] * b[0] + t.uv[1] * b[1] + t.uv[2] * b[2];
                        // The direction's stratum is a shuffle of the point's, so that
                        // directions and points are both stratified but not correlated.
                        let k = (s * 7 + 3) % n;
                        let h2 = hash(h ^ 0x68e3_1da4);
                        let du = Vec2::new(
                            ((k % SIDE) as f32 + unit(h2)) / SIDE as f32,
                            ((k / SIDE) as f32 + unit(hash(h2))) / SIDE as f32,
                        );
                        let opaque =
                            !tested || mesh.alpha(t.material, uv) >= crate::mesh::ALPHA_CUTOFF;
                        (b, p, cosine_direction(normal, du), opaque)
                    })
                    .collect();
                // Transparent points count only where a vertex has no opaque one: trace them
                // only then.
                let all = (0..3)
                    .any(|c| samples.iter().filter(|x| x.3).map(|x| x.0[c]).sum::<f32>() <= 0.0);
                for &(b, p, dir, opaque) in samples.iter().filter(|x| all || x.3) {
                    let sky = !scene.occluded(p + normal * eps, dir, eps, f32::INFINITY, ti as u32);
                    let sky = f32::from(u8::from(sky));
                    for c in 0..3 {
                        seen_all[c] += b[c] * sky;
                        weight_all[c] += b[c];
                        if opaque {
                            seen[c] += b[c] * sky;
                            weight[c] += b[c];
                        }
                    }
                }
                for c in 0..3 {
                    out[side][c] = if weight[c] > 0.0 {
                        seen[c] / weight[c]
                    } else {
                        seen_all[c] / weight_all[c].max(1e-9)
                    };
                }
            }
            out
        })
        .collect()
}

/// The sky visibility at barycentric `(b1, b2)` of triangle `tri` on the side a viewer along
/// `view` (unit, from the viewer towards the surface) sees.
pub fn sky_at(scene: &Scene, sky: &[TriangleSky], tri: u32, bary: Vec2, view: Vec3) -> f32 {
    let t = &scene.tris[tri as usize];
    let side = usize::from(front_normal(t).dot(view) > 0.0);
    let c = sky[tri as usize][side];
    c[0] * (1.0 - bary.x - bary.y) + c[1] * bary.x + c[2] * bary.y
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cosine_directions_lie_in_the_hemisphere_with_the_cosine_mean() {
        let n = Vec3::new(0.3, 0.8, -0.5).normalize();
        let mut mean_cos = 0.0;
        let m = 64;
        for i in 0..m {
            for j in 0..m {
                let d = cosine_direction(
                    n,
                    Vec2::new((i as f32 + 0.5) / m as f32, (j as f32 + 0.5) / m as f32),
                );
                assert!((d.length() - 1.0).abs() < 1e-5);
                assert!(d.dot(n) >= 0.0);
                mean_cos += d.dot(n);
            }
        }
        // E[cos θ] under a cosine-weighted density is 2/3.
        mean_cos /= (m * m) as f32;
        assert!((mean_cos - 2.0 / 3.0).abs() < 2e-3, "{mean_cos}");
    }
}
