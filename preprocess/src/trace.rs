//! Alpha-tested ray queries over a compressed wide BVH (obvhs' CWBVH, built with PLOC).

use glam::{Vec2, Vec3, Vec3A};
use obvhs::{
    BvhBuildParams,
    cwbvh::{CwBvh, builder::build_cwbvh_from_tris},
    ray::{Ray, RayHit},
    triangle::Triangle,
};

use crate::mesh::{ALPHA_CUTOFF, Mesh, Tri};

/// A ray hit with everything shading needs.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Distance along the (unit) ray direction.
    pub t: f32,
    /// Triangle index in [`Scene::tris`].
    pub tri: u32,
    /// Barycentric coordinates of vertices 1 and 2.
    pub bary: Vec2,
}

/// The model ready for tracing: triangles reordered to the BVH's leaf order.
pub struct Scene<'a> {
    /// The model (materials, textures).
    pub mesh: &'a Mesh,
    /// Triangles in BVH order.
    pub tris: Vec<Tri>,
    /// What the ray test reads of each triangle, in the same order: a third of a [`Tri`]'s
    /// bytes, so that the many leaf cards a ray crosses in a crown stay in cache.
    edges: Vec<Edges>,
    bvh: CwBvh,
}

/// A triangle's first vertex and its two edges from it, as Möller–Trumbore uses them.
#[derive(Clone, Copy, Debug)]
struct Edges {
    p0: Vec3,
    e1: Vec3,
    e2: Vec3,
}

impl Edges {
    fn new(t: &Tri) -> Self {
        Self {
            p0: t.p[0],
            e1: t.p[1] - t.p[0],
            e2: t.p[2] - t.p[0],
        }
    }
}

/// Möller–Trumbore: `(t, b1, b2)` when the ray hits the triangle within `[tmin, tmax]`.
pub fn intersect(tri: &Tri, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> Option<(f32, Vec2)> {
    intersect_edges(&Edges::new(tri), o, d, tmin, tmax)
}

/// [`intersect`] on a triangle's precomputed edges.
#[inline]
fn intersect_edges(t: &Edges, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> Option<(f32, Vec2)> {
    let (e1, e2) = (t.e1, t.e2);
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det.abs() < 1e-20 {
        return None;
    }
    let inv = 1.0 / det;
    let tv = o - t.p0;
    let b1 = tv.dot(pv) * inv;
    if !(0.0..=1.0).contains(&b1) {
        return None;
    }
    let qv = tv.cross(e1);
    let b2 = d.dot(qv) * inv;
    if b2 < 0.0 || b1 + b2 > 1.0 {
        return None;
    }
    let t = e2.dot(qv) * inv;
    (t >= tmin && t <= tmax).then_some((t, Vec2::new(b1, b2)))
}

/// The BVH's ray. Negative zeros in the direction become positive: obvhs picks a child's near
/// plane by `direction < 0` but inverts `-0.0` to a negative value, and then misses every box
/// (views along an axis, such as the zenith, came out blank).
fn bvh_ray(o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> Ray {
    Ray::new(Vec3A::from(o), Vec3A::from(d) + Vec3A::ZERO, tmin, tmax)
}

impl<'a> Scene<'a> {
    /// Build the BVH (in parallel) over the mesh's triangles.
    pub fn new(mesh: &'a Mesh) -> Self {
        let bvh_tris: Vec<Triangle> = mesh
            .tris
            .iter()
            .map(|t| Triangle {
                v0: Vec3A::from(t.p[0]),
                v1: Vec3A::from(t.p[1]),
                v2: Vec3A::from(t.p[2]),
            })
            .collect();
        let mut build_time = std::time::Duration::ZERO;
        let bvh = build_cwbvh_from_tris(&bvh_tris, BvhBuildParams::medium_build(), &mut build_time);
        let tris: Vec<Tri> = bvh
            .primitive_indices
            .iter()
            .map(|&i| mesh.tris[i as usize])
            .collect();
        let edges = tris.iter().map(Edges::new).collect();
        Self {
            mesh,
            tris,
            edges,
            bvh,
        }
    }

    /// Whether triangle `i` is solid at barycentrics `b` (alpha test).
    fn solid(&self, i: usize, b: Vec2) -> bool {
        let t = &self.tris[i];
        if self.mesh.materials[t.material as usize].alpha.is_none() {
            return true;
        }
        let uv = t.uv[0] * (1.0 - b.x - b.y) + t.uv[1] * b.x + t.uv[2] * b.y;
        self.mesh.alpha(t.material, uv) >= ALPHA_CUTOFF
    }

    /// Closest alpha-tested hit along `o + t·d` (unit `d`) with `t ∈ [tmin, tmax]`.
    pub fn closest(&self, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> Option<Hit> {
        let ray = bvh_ray(o, d, tmin, tmax);
        let mut hit = RayHit::none();
        let mut bary = Vec2::ZERO;
        let found = self.bvh.ray_traverse(ray, &mut hit, |r, id| {
            match intersect_edges(&self.edges[id], o, d, r.tmin, r.tmax) {
                Some((t, b)) if t < r.tmax && self.solid(id, b) => {
                    bary = b;
                    t
                }
                _ => f32::INFINITY,
            }
        });
        // `bary` belongs to the last hit returned, which is the closest: the traversal accepts
        // every `t < tmax` and then lowers `tmax` to it.
        found.then_some(Hit {
            t: hit.t,
            tri: hit.primitive_id,
            bary,
        })
    }

    /// Whether anything solid lies on `o + t·d`, `t ∈ [tmin, tmax]`, ignoring triangle `skip`.
    pub fn occluded(&self, o: Vec3, d: Vec3, tmin: f32, tmax: f32, skip: u32) -> bool {
        let ray = bvh_ray(o, d, tmin, tmax);
        !self.bvh.ray_traverse_miss(ray, |r, id| {
            if id as u32 == skip {
                return f32::INFINITY;
            }
            match intersect_edges(&self.edges[id], o, d, r.tmin, r.tmax) {
                Some((t, b)) if self.solid(id, b) => t,
                _ => f32::INFINITY,
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(p: [Vec3; 3]) -> Tri {
        Tri {
            p,
            uv: [Vec2::ZERO; 3],
            n: [Vec3::Z; 3],
            material: 0,
        }
    }

    #[test]
    fn moller_trumbore_has_analytic_answers() {
        let t = tri([Vec3::ZERO, Vec3::X, Vec3::Y]);
        let (dist, b) = intersect(&t, Vec3::new(0.25, 0.5, 2.0), -Vec3::Z, 0.0, 10.0).unwrap();
        assert!((dist - 2.0).abs() < 1e-6);
        assert!((b - Vec2::new(0.25, 0.5)).length() < 1e-6);
        assert!(intersect(&t, Vec3::new(0.75, 0.5, 2.0), -Vec3::Z, 0.0, 10.0).is_none());
        assert!(intersect(&t, Vec3::new(0.2, 0.2, 2.0), -Vec3::Z, 0.0, 1.0).is_none());
        assert!(intersect(&t, Vec3::new(0.2, 0.2, 2.0), Vec3::X, 0.0, 10.0).is_none());
    }
}
