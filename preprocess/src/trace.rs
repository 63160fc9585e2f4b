//! Alpha-tested ray queries over a compressed wide BVH (obvhs' CWBVH, built with PLOC), whose
//! alpha-tested triangles are cut to their texture's opaque hull ([`crate::cutout`]).

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
    /// Triangle index in [`Scene::tris`] (the mesh's order).
    pub tri: u32,
    /// Barycentric coordinates of vertices 1 and 2 of that triangle.
    pub bary: Vec2,
}

/// The model ready for tracing.
pub struct Scene<'a> {
    /// The model (materials, textures).
    pub mesh: &'a Mesh,
    /// Triangles, in the mesh's order: what [`Hit::tri`] indexes.
    pub tris: &'a [Tri],
    /// What the ray test reads, in the BVH's leaf order: 40 bytes per piece against a
    /// [`Tri`]'s 100, so that the many leaf cards a ray crosses in a crown stay in cache.
    pieces: Vec<Piece>,
    /// Each piece's corners as barycentrics `(b1, b2)` of its triangle, in the same order.
    corners: Vec<[Vec2; 3]>,
    bvh: CwBvh,
}

/// One primitive of the BVH: a triangle's first vertex, its two edges from it (as
/// Möller–Trumbore uses them) and which triangle it is.
#[derive(Clone, Copy, Debug)]
struct Piece {
    p0: Vec3,
    e1: Vec3,
    e2: Vec3,
    /// Index in [`Scene::tris`].
    tri: u32,
}

impl Piece {
    /// Triangle `t` whole, as triangle `tri`.
    fn new(t: &Tri, tri: u32) -> Self {
        Self {
            p0: t.p[0],
            e1: t.p[1] - t.p[0],
            e2: t.p[2] - t.p[0],
            tri,
        }
    }
}

/// Below this `|det| / (|e1|·|e2|)` (the sine of the angle between the ray and the
/// triangle's plane, times the sine of the triangle's corner), a triangle counts as seen
/// edge-on and is missed.
pub const EDGE_ON: f32 = 1e-5;

/// Möller–Trumbore: `(t, b1, b2)` when the ray hits the triangle within `[tmin, tmax]`.
pub fn intersect(tri: &Tri, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> Option<(f32, Vec2)> {
    intersect_piece(&Piece::new(tri, 0), o, d, tmin, tmax)
}

/// [`intersect`] on a piece's precomputed edges.
#[inline(always)]
fn intersect_piece(t: &Piece, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> Option<(f32, Vec2)> {
    let (e1, e2) = (t.e1, t.e2);
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    // Seen edge-on (the ray within 1e-5 rad of the triangle's plane, or a degenerate
    // triangle), the determinant is rounding noise and so would be the barycentrics: such a
    // triangle covers no area, so it is missed.
    if det * det <= EDGE_ON * EDGE_ON * e1.length_squared() * e2.length_squared() {
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
    /// Build the BVH (in parallel) over the mesh's triangles, the alpha-tested ones cut to
    /// the opaque hull of their texture.
    pub fn new(mesh: &'a Mesh) -> Self {
        use rayon::prelude::*;
        // One hull per alpha source (texture, channel) that a material tests.
        let mut sources: Vec<(usize, bool)> =
            mesh.materials.iter().filter_map(|m| m.alpha).collect();
        sources.sort_unstable();
        sources.dedup();
        let hulls: Vec<((usize, bool), Option<crate::cutout::Polygon>)> = sources
            .into_par_iter()
            .map(|(t, c)| ((t, c), crate::cutout::opaque_hull(mesh, t, c)))
            .collect();
        let hull_of = |alpha: (usize, bool)| {
            hulls
                .iter()
                .find(|(k, _)| *k == alpha)
                .and_then(|(_, h)| h.as_ref())
        };
        let cut: Vec<(u32, [Vec2; 3])> = mesh
            .tris
            .par_iter()
            .enumerate()
            .flat_map_iter(|(i, t)| {
                let corners = match mesh.materials[t.material as usize].alpha {
                    Some(alpha) => crate::cutout::pieces(t, hull_of(alpha)),
                    None => vec![crate::cutout::WHOLE],
                };
                corners.into_iter().map(move |c| (i as u32, c))
            })
            .collect();
        let at = |t: &Tri, b: Vec2| t.p[0] + (t.p[1] - t.p[0]) * b.x + (t.p[2] - t.p[0]) * b.y;
        let bvh_tris: Vec<Triangle> = cut
            .iter()
            .map(|&(i, c)| {
                let t = &mesh.tris[i as usize];
                if c == crate::cutout::WHOLE {
                    return Triangle {
                        v0: Vec3A::from(t.p[0]),
                        v1: Vec3A::from(t.p[1]),
                        v2: Vec3A::from(t.p[2]),
                    };
                }
                Triangle {
                    v0: Vec3A::from(at(t, c[0])),
                    v1: Vec3A::from(at(t, c[1])),
                    v2: Vec3A::from(at(t, c[2])),
                }
            })
            .collect();
        let mut build_time = std::time::Duration::ZERO;
        let bvh = build_cwbvh_from_tris(&bvh_tris, BvhBuildParams::medium_build(), &mut build_time);
        let (pieces, corners) = bvh
            .primitive_indices
            .iter()
            .map(|&k| {
                let (i, c) = cut[k as usize];
                let b = &bvh_tris[k as usize];
                let (p0, p1, p2) = (Vec3::from(b.v0), Vec3::from(b.v1), Vec3::from(b.v2));
                let piece = Piece {
                    p0,
                    e1: p1 - p0,
                    e2: p2 - p0,
                    tri: i,
                };
                (piece, c)
            })
            .unzip();
        Self {
            mesh,
            tris: &mesh.tris,
            pieces,
            corners,
            bvh,
        }
    }

    /// Barycentrics of the triangle of piece `id` from barycentrics `b` of the piece.
    #[inline]
    fn triangle_bary(&self, id: usize, b: Vec2) -> Vec2 {
        let c = &self.corners[id];
        c[0] + (c[1] - c[0]) * b.x + (c[2] - c[0]) * b.y
    }

    /// Whether triangle `i` is solid at barycentrics `b` (alpha test).
    fn solid(&self, i: u32, b: Vec2) -> bool {
        let t = &self.tris[i as usize];
        if self.mesh.materials[t.material as usize].alpha.is_none() {
            return true;
        }
        let uv = t.uv[0] * (1.0 - b.x - b.y) + t.uv[1] * b.x + t.uv[2] * b.y;
        self.mesh.alpha(t.material, uv) >= ALPHA_CUTOFF
    }

    /// Number of pieces the BVH holds: what [`Self::piece_points`] and
    /// [`Self::piece_intersect`] index, in the BVH's leaf order (neighbours in space are
    /// near in this order).
    pub fn piece_count(&self) -> usize {
        self.pieces.len()
    }

    /// Object-space corners of piece `id` (`id < piece_count()`).
    pub fn piece_points(&self, id: usize) -> [Vec3; 3] {
        let p = &self.pieces[id];
        [p.p0, p.p0 + p.e1, p.p0 + p.e2]
    }

    /// The ray test of piece `id` alone, as [`Self::closest`] runs it: distance and the
    /// piece's barycentrics when `o + t·d` crosses it with `t ∈ [tmin, tmax]`, before the
    /// alpha test ([`Self::solid_hit`]).
    #[inline]
    pub fn piece_intersect(
        &self,
        id: usize,
        o: Vec3,
        d: Vec3,
        tmin: f32,
        tmax: f32,
    ) -> Option<(f32, Vec2)> {
        intersect_piece(&self.pieces[id], o, d, tmin, tmax)
    }

    /// The hit on piece `id` at distance `t` and piece barycentrics `b`
    /// ([`Self::piece_intersect`]) if its triangle is solid there (alpha test).
    #[inline]
    pub fn solid_hit(&self, id: usize, t: f32, b: Vec2) -> Option<Hit> {
        let tri = self.pieces[id].tri;
        let bary = self.triangle_bary(id, b);
        self.solid(tri, bary).then_some(Hit { t, tri, bary })
    }

    /// Closest alpha-tested hit along `o + t·d` (unit `d`) with `t ∈ [tmin, tmax]`.
    pub fn closest(&self, o: Vec3, d: Vec3, tmin: f32, tmax: f32) -> Option<Hit> {
        let ray = bvh_ray(o, d, tmin, tmax);
        let mut hit = RayHit::none();
        let mut last = (0u32, Vec2::ZERO);
        let found = self.bvh.ray_traverse(ray, &mut hit, |r, id| {
            match self.piece_intersect(id, o, d, r.tmin, r.tmax) {
                Some((t, b)) if t < r.tmax => match self.solid_hit(id, t, b) {
                    Some(h) => {
                        last = (h.tri, h.bary);
                        t
                    }
                    None => f32::INFINITY,
                },
                _ => f32::INFINITY,
            }
        });
        // `last` belongs to the last hit returned, which is the closest: the traversal accepts
        // every `t < tmax` and then lowers `tmax` to it.
        found.then_some(Hit {
            t: hit.t,
            tri: last.0,
            bary: last.1,
        })
    }

    /// Whether anything solid lies on `o + t·d`, `t ∈ [tmin, tmax]`, ignoring triangle `skip`.
    pub fn occluded(&self, o: Vec3, d: Vec3, tmin: f32, tmax: f32, skip: u32) -> bool {
        let ray = bvh_ray(o, d, tmin, tmax);
        !self.bvh.ray_traverse_miss(ray, |r, id| {
            let piece = &self.pieces[id];
            if piece.tri == skip {
                return f32::INFINITY;
            }
            match intersect_piece(piece, o, d, r.tmin, r.tmax) {
                Some((t, b)) if self.solid_hit(id, t, b).is_some() => t,
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
