//! Alpha-tested triangles cut to the opaque part of their texture, for the ray tracer only.
//!
//! Leaf cards are mostly transparent (a quarter of the bundled oak's leaf texture passes the
//! alpha test), and every ray through a crown tests, and rejects, the transparent part of
//! many cards. Cutting each card to the convex hull of its texture's opaque texels, as
//! engines cut billboards to their silhouette, halves its area and tightens its BVH box.
//! The cut is exact for the tracer: every point of an opaque texel lies inside the hull, so
//! every hit that passes the alpha test is still found, and each piece keeps its triangle's
//! barycentric frame, so what a hit reads (texture, normal, sky visibility) is unchanged.
//!
//! Pure functions over texture-space polygons; [`crate::trace::Scene`] uses them.

use glam::Vec2;

use crate::mesh::{ALPHA_CUTOFF, Mesh, Tri, texel_alpha};

/// Most vertices a hull keeps: a triangle cut by it is at most `MAX_HULL_VERTICES + 1`
/// pieces. Fewer vertices add area (measured on the bundled leaf textures: a few per cent).
pub const MAX_HULL_VERTICES: usize = 6;

/// A convex polygon in texture space (`uv`, OBJ convention), counter-clockwise.
pub type Polygon = Vec<Vec2>;

/// A whole triangle as barycentric corners `(b1, b2)`: the one piece of an uncut triangle.
pub const WHOLE: [Vec2; 3] = [Vec2::ZERO, Vec2::X, Vec2::Y];

/// The convex hull, simplified outward to at most [`MAX_HULL_VERTICES`] vertices, of the
/// texels of texture `t` of `mesh` that pass the alpha test as [`Mesh::alpha`] reads them
/// (its alpha channel when `channel`, else its grey), each texel taken whole and grown by a
/// quarter texel. `None` when no texel passes (every triangle on it is transparent).
pub fn opaque_hull(mesh: &Mesh, t: usize, channel: bool) -> Option<Polygon> {
    let tex = &mesh.textures[t];
    let (w, h) = (tex.width as usize, tex.height as usize);
    let pass = |x: usize, y: usize| {
        let i = (y * w + x) * 4;
        let texel = [
            tex.rgba[i],
            tex.rgba[i + 1],
            tex.rgba[i + 2],
            tex.rgba[i + 3],
        ];
        f32::from(texel_alpha(texel, channel)) / 255.0 >= ALPHA_CUTOFF
    };
    // Texel (x, y) covers u ∈ [x/w, (x+1)/w] and v ∈ [1 − (y+1)/h, 1 − y/h] (row 0 on top;
    // `Texture::texel`): the corners of each row's outermost passing texels, grown by a
    // quarter texel.
    let grow = 0.25;
    let mut points = Vec::new();
    for y in 0..h {
        let first = (0..w).find(|&x| pass(x, y));
        let Some(first) = first else { continue };
        let last = (first..w).rev().find(|&x| pass(x, y)).unwrap_or(first);
        for x in [first as f32 - grow, last as f32 + 1.0 + grow] {
            for yy in [y as f32 - grow, y as f32 + 1.0 + grow] {
                points.push(Vec2::new(x / w as f32, 1.0 - yy / h as f32));
            }
        }
    }
    if points.is_empty() {
        return None;
    }
    Some(simplify_outward(convex_hull(points), MAX_HULL_VERTICES))
}

/// Andrew's monotone chain: the convex hull of `points`, counter-clockwise, without
/// collinear vertices.
pub fn convex_hull(mut points: Vec<Vec2>) -> Polygon {
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    points.dedup();
    if points.len() < 3 {
        return points;
    }
    let cross = |o: Vec2, a: Vec2, b: Vec2| (a - o).perp_dot(b - o);
    let mut hull: Vec<Vec2> = Vec::with_capacity(2 * points.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &Vec2>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// Shrink convex polygon `poly` (counter-clockwise) to at most `max` vertices (at least 3)
/// by removing, one at a time, the edge whose removal adds the least area: its two
/// neighbouring edges are extended to meet. The result contains `poly`.
pub fn simplify_outward(mut poly: Polygon, max: usize) -> Polygon {
    let max = max.max(3);
    while poly.len() > max {
        let n = poly.len();
        let mut best: Option<(f32, usize, Vec2)> = None;
        for i in 0..n {
            // Remove edge (a, b): extend (prev, a) and (b, next) to their intersection.
            let (prev, a, b, next) = (
                poly[(i + n - 1) % n],
                poly[i],
                poly[(i + 1) % n],
                poly[(i + 2) % n],
            );
            let (d1, d2) = (a - prev, next - b);
            let denom = d1.perp_dot(d2);
            // The two edges must turn towards each other (less than 180° in all).
            if denom <= 1e-12 {
                continue;
            }
            let s = (b - a).perp_dot(d2) / denom;
            if s < 0.0 {
                continue;
            }
            let x = a + d1 * s;
            let added = 0.5 * (b - a).perp_dot(x - a).abs();
            if best.is_none_or(|(area, _, _)| added < area) {
                best = Some((added, i, x));
            }
        }
        // A polygon with no removable edge (a triangle-like shape) stays as it is.
        let Some((_, i, x)) = best else { break };
        poly[i] = x;
        poly.remove((i + 1) % n);
    }
    poly
}

/// Convex polygon `subject` clipped by convex polygon `clip` (both counter-clockwise):
/// Sutherland–Hodgman. Empty when they do not overlap.
pub fn clip_convex(subject: &[Vec2], clip: &[Vec2]) -> Polygon {
    let mut out: Polygon = subject.to_vec();
    for i in 0..clip.len() {
        if out.is_empty() {
            break;
        }
        let (a, b) = (clip[i], clip[(i + 1) % clip.len()]);
        let side = |p: Vec2| (b - a).perp_dot(p - a);
        let input = std::mem::take(&mut out);
        for j in 0..input.len() {
            let (p, q) = (input[j], input[(j + 1) % input.len()]);
            let (sp, sq) = (side(p), side(q));
            if sp >= 0.0 {
                out.push(p);
            }
            if (sp >= 0.0) != (sq >= 0.0) {
                out.push(p + (q - p) * (sp / (sp - sq)));
            }
        }
    }
    out
}

/// The pieces of triangle `t` that may pass the alpha test, as barycentric corners
/// `[(b1, b2); 3]` of `t` (the whole triangle is `[(0,0), (1,0), (0,1)]`): `t` cut by the
/// hull of its texture. A triangle whose texture coordinates leave `[0,1]²` (a repeating
/// texture) or are degenerate is kept whole; one outside the hull gives no piece.
pub fn pieces(t: &Tri, hull: Option<&Polygon>) -> Vec<[Vec2; 3]> {
    let Some(hull) = hull else {
        return Vec::new();
    };
    let inside = |uv: Vec2| (0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y);
    if !t.uv.iter().all(|&uv| inside(uv)) {
        return vec![WHOLE];
    }
    let (e1, e2) = (t.uv[1] - t.uv[0], t.uv[2] - t.uv[0]);
    let det = e1.perp_dot(e2);
    if det.abs() < 1e-12 {
        return vec![WHOLE];
    }
    // Counter-clockwise in texture space, as the hull.
    let tri: Vec<Vec2> = if det > 0.0 {
        t.uv.to_vec()
    } else {
        vec![t.uv[0], t.uv[2], t.uv[1]]
    };
    let poly = clip_convex(&tri, hull);
    if poly.len() < 3 {
        return Vec::new();
    }
    // Texture point -> barycentrics (b1, b2) of `t`.
    let bary = |p: Vec2| {
        let d = p - t.uv[0];
        Vec2::new(d.perp_dot(e2) / det, e1.perp_dot(d) / det)
    };
    let b: Vec<Vec2> = poly.iter().map(|&p| bary(p)).collect();
    (1..b.len() - 1).map(|k| [b[0], b[k], b[k + 1]]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(p: &[Vec2]) -> f32 {
        (0..p.len())
            .map(|i| p[i].perp_dot(p[(i + 1) % p.len()]))
            .sum::<f32>()
            * 0.5
    }

    fn contains(poly: &[Vec2], q: Vec2) -> bool {
        (0..poly.len())
            .all(|i| (poly[(i + 1) % poly.len()] - poly[i]).perp_dot(q - poly[i]) >= -1e-5)
    }

    #[test]
    fn the_hull_of_a_square_grid_is_its_square() {
        let pts: Vec<Vec2> = (0..25)
            .map(|i| Vec2::new((i % 5) as f32, (i / 5) as f32))
            .collect();
        let h = convex_hull(pts);
        assert_eq!(h.len(), 4);
        assert!((area(&h) - 16.0).abs() < 1e-5, "counter-clockwise, area 16");
    }

    #[test]
    fn simplification_only_grows_the_polygon() {
        // A regular 32-gon, simplified to 8 vertices, contains the original and is larger.
        let poly: Polygon = (0..32)
            .map(|i| {
                let a = i as f32 / 32.0 * std::f32::consts::TAU;
                Vec2::new(a.cos(), a.sin())
            })
            .collect();
        let s = simplify_outward(poly.clone(), 8);
        assert_eq!(s.len(), 8);
        assert!(poly.iter().all(|&p| contains(&s, p)));
        let (a0, a1) = (area(&poly), area(&s));
        assert!(a1 >= a0 && a1 < a0 * 1.1, "{a0} -> {a1}");
    }

    #[test]
    fn clipping_has_analytic_answers() {
        let square = [
            Vec2::ZERO,
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ];
        let shifted: Vec<Vec2> = square.iter().map(|p| *p + Vec2::splat(0.5)).collect();
        assert!((area(&clip_convex(&square, &shifted)) - 0.25).abs() < 1e-6);
        let far: Vec<Vec2> = square.iter().map(|p| *p + Vec2::splat(3.0)).collect();
        assert!(clip_convex(&square, &far).is_empty());
    }

    fn card(uv: [Vec2; 3]) -> Tri {
        Tri {
            p: [glam::Vec3::ZERO, glam::Vec3::X, glam::Vec3::Y],
            uv,
            n: [glam::Vec3::Z; 3],
            material: 0,
        }
    }

    #[test]
    fn pieces_cover_the_hull_within_the_triangle_in_its_barycentric_frame() {
        let hull = vec![
            Vec2::new(0.25, 0.25),
            Vec2::new(0.75, 0.25),
            Vec2::new(0.75, 0.75),
            Vec2::new(0.25, 0.75),
        ];
        // Texture coordinates equal to the barycentrics: the pieces are the hull's part
        // of the lower-left half of the unit square.
        for uv in [
            [Vec2::ZERO, Vec2::X, Vec2::Y],
            [Vec2::ZERO, Vec2::Y, Vec2::X], // the other winding
        ] {
            let p = pieces(&card(uv), Some(&hull));
            let total: f32 = p
                .iter()
                .map(|c| 0.5 * (c[1] - c[0]).perp_dot(c[2] - c[0]).abs())
                .sum();
            // The diagonal u + v = 1 halves the square (0.25).
            assert!((total - 0.125).abs() < 1e-5, "{total}");
            for c in p.iter().flatten() {
                assert!(c.x >= -1e-6 && c.y >= -1e-6 && c.x + c.y <= 1.0 + 1e-6);
            }
        }
        // Outside the hull: nothing; repeating coordinates: the whole triangle.
        let off = [
            Vec2::new(0.9, 0.9),
            Vec2::new(1.0, 0.9),
            Vec2::new(0.9, 1.0),
        ];
        assert!(pieces(&card(off), Some(&hull)).is_empty());
        let wrap = [Vec2::ZERO, Vec2::new(2.0, 0.0), Vec2::Y];
        assert_eq!(pieces(&card(wrap), Some(&hull)).len(), 1);
        assert!(pieces(&card([Vec2::ZERO, Vec2::X, Vec2::Y]), None).is_empty());
    }
}
