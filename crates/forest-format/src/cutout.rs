//! Convex polygons in texture space, and triangles cut by them: how alpha-tested cards are
//! trimmed to the part of their texture that can pass the alpha test.
//!
//! Leaf cards are mostly transparent (a sixth to a quarter of the bundled leaf textures pass
//! the alpha test), and both a ray tracer and a rasteriser pay for the transparent part: a ray
//! tests and rejects it, a rasteriser shades and discards it. Cutting each triangle to the
//! convex hull of what can pass, as engines cut particles and billboards to their silhouette,
//! removes most of it. Each piece is given in its triangle's barycentric frame, so whatever is
//! interpolated over the triangle (texture coordinates, normals, occlusion) is unchanged on it.
//!
//! Pure functions; the bake's tracer (`preprocess::cutout`) and the geometry renderer's card
//! trimming (`forest_baselines`) use them.

use glam::Vec2;

/// A convex polygon in texture space (`uv`), counter-clockwise.
pub type Polygon = Vec<Vec2>;

/// A whole triangle as barycentric corners `(b1, b2)`: the one piece of an uncut triangle.
pub const WHOLE: [Vec2; 3] = [Vec2::ZERO, Vec2::X, Vec2::Y];

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

/// The pieces of the triangle with texture coordinates `uv` that lie inside convex polygon
/// `hull`, as barycentric corners `[(b1, b2); 3]` of the triangle (the whole triangle is
/// [`WHOLE`]), a fan of the clipped polygon. A triangle whose texture coordinates leave
/// `[0,1]²` (a repeating texture) or are degenerate is kept whole; one outside the hull gives
/// no piece. The pieces tile `triangle ∩ hull` exactly: they share their inner edges' corners.
pub fn pieces_in(uv: [Vec2; 3], hull: &[Vec2]) -> Vec<[Vec2; 3]> {
    let inside = |uv: Vec2| (0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y);
    if !uv.iter().all(|&p| inside(p)) {
        return vec![WHOLE];
    }
    let (e1, e2) = (uv[1] - uv[0], uv[2] - uv[0]);
    let det = e1.perp_dot(e2);
    if det.abs() < 1e-12 {
        return vec![WHOLE];
    }
    // Counter-clockwise in texture space, as the hull.
    let tri: Vec<Vec2> = if det > 0.0 {
        uv.to_vec()
    } else {
        vec![uv[0], uv[2], uv[1]]
    };
    let poly = clip_convex(&tri, hull);
    if poly.len() < 3 {
        return Vec::new();
    }
    // Texture point -> barycentrics (b1, b2) of the triangle.
    let bary = |p: Vec2| {
        let d = p - uv[0];
        Vec2::new(d.perp_dot(e2) / det, e1.perp_dot(d) / det)
    };
    let b: Vec<Vec2> = poly.iter().map(|&p| bary(p)).collect();
    (1..b.len() - 1).map(|k| [b[0], b[k], b[k + 1]]).collect()
}

/// Directions, evenly spaced over the full turn, of the supporting lines
/// [`enclosing_quad`] chooses its sides among (besides the hull's own edges and the unit
/// square's).
pub const QUAD_DIRECTIONS: usize = 32;

/// The smallest-area quadrilateral, among those whose four sides each lie on a supporting
/// line of convex polygon `hull` (counter-clockwise), that contains `hull` and lies in the unit
/// square `[0,1]²`: its corners counter-clockwise. The candidate lines are the hull's edges,
/// the square's sides and the hull's supporting lines at [`QUAD_DIRECTIONS`] outward normals;
/// every quadrilateral they bound contains `hull`, since `hull` lies on the inner side of each.
/// A card cut to it keeps its two triangles. `None` when `hull` has fewer than three corners
/// or leaves the square (beyond 1e-6).
pub fn enclosing_quad(hull: &[Vec2]) -> Option<[Vec2; 4]> {
    const EPS: f32 = 1e-6;
    if hull.len() < 3
        || hull
            .iter()
            .any(|p| p.min_element() < -EPS || p.max_element() > 1.0 + EPS)
    {
        return None;
    }
    // Half-planes n · p ≤ h (n unit, outward), by the angle of n.
    let support = |n: Vec2| (n, hull.iter().map(|&p| n.dot(p)).fold(f32::MIN, f32::max));
    let mut lines: Vec<(f32, Vec2, f32)> = Vec::new();
    let mut add = |(n, h): (Vec2, f32)| lines.push((n.y.atan2(n.x), n, h));
    for i in 0..hull.len() {
        let e = hull[(i + 1) % hull.len()] - hull[i];
        if e.length() > EPS {
            // Counter-clockwise: the outward normal is the edge turned clockwise.
            add(support(Vec2::new(e.y, -e.x).normalize()));
        }
    }
    for k in 0..QUAD_DIRECTIONS {
        let a = k as f32 / QUAD_DIRECTIONS as f32 * std::f32::consts::TAU;
        add(support(Vec2::new(a.cos(), a.sin())));
    }
    for (n, h) in [
        (Vec2::X, 1.0),
        (Vec2::Y, 1.0),
        (Vec2::NEG_X, 0.0),
        (Vec2::NEG_Y, 0.0),
    ] {
        add((n, h));
    }
    lines.sort_by(|a, b| a.0.total_cmp(&b.0));
    let meet = |(n1, h1): (Vec2, f32), (n2, h2): (Vec2, f32)| {
        let det = n1.perp_dot(n2);
        (det.abs() > 1e-9).then(|| Vec2::new(h1 * n2.y - h2 * n1.y, n1.x * h2 - n2.x * h1) / det)
    };
    let area = |q: &[Vec2; 4]| (0..4).map(|i| q[i].perp_dot(q[(i + 1) % 4])).sum::<f32>() * 0.5;
    let n = lines.len();
    let mut best: Option<(f32, [Vec2; 4])> = None;
    for a in 0..n {
        for b in a + 1..n {
            for c in b + 1..n {
                for d in c + 1..n {
                    let l = [lines[a], lines[b], lines[c], lines[d]];
                    // Bounded only if no turn between consecutive normals reaches half a turn.
                    let turn = |i: usize| {
                        let t = l[(i + 1) % 4].0 - l[i].0;
                        if t < 0.0 {
                            t + std::f32::consts::TAU
                        } else {
                            t
                        }
                    };
                    if (0..4).any(|i| turn(i) >= std::f32::consts::PI - 1e-4) {
                        continue;
                    }
                    let mut q = [Vec2::ZERO; 4];
                    let mut ok = true;
                    for i in 0..4 {
                        match meet((l[i].1, l[i].2), (l[(i + 1) % 4].1, l[(i + 1) % 4].2)) {
                            Some(p) => q[i] = p,
                            None => ok = false,
                        }
                    }
                    // Every corner within every side's half-plane (a true quadrilateral) and
                    // within the square.
                    ok = ok
                        && q.iter().all(|p| {
                            l.iter().all(|&(_, nn, h)| nn.dot(*p) <= h + 1e-5)
                                && p.min_element() >= -1e-5
                                && p.max_element() <= 1.0 + 1e-5
                        });
                    if !ok {
                        continue;
                    }
                    let ar = area(&q);
                    if ar > 0.0 && best.is_none_or(|(b, _)| ar < b) {
                        best = Some((ar, q));
                    }
                }
            }
        }
    }
    best.map(|(_, q)| q.map(|p| p.clamp(Vec2::ZERO, Vec2::ONE)))
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

    /// The axis-aligned rectangle from `min` to `max`, counter-clockwise.
    fn rect(min: Vec2, max: Vec2) -> Polygon {
        vec![min, Vec2::new(max.x, min.y), max, Vec2::new(min.x, max.y)]
    }

    /// `n` points evenly spaced in angle on the ellipse of `centre` and `radii`,
    /// counter-clockwise.
    fn ellipse(n: usize, centre: Vec2, radii: Vec2) -> Polygon {
        (0..n)
            .map(|i| {
                let a = i as f32 / n as f32 * std::f32::consts::TAU;
                centre + radii * Vec2::new(a.cos(), a.sin())
            })
            .collect()
    }

    #[test]
    fn simplification_only_grows_the_polygon() {
        // A regular 32-gon, simplified to 8 vertices, contains the original and is larger.
        let poly = ellipse(32, Vec2::ZERO, Vec2::ONE);
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

    #[test]
    fn pieces_cover_the_hull_within_the_triangle_in_its_barycentric_frame() {
        let hull = rect(Vec2::splat(0.25), Vec2::splat(0.75));
        // Texture coordinates equal to the barycentrics: the pieces are the hull's part
        // of the lower-left half of the unit square.
        for uv in [
            [Vec2::ZERO, Vec2::X, Vec2::Y],
            [Vec2::ZERO, Vec2::Y, Vec2::X], // the other winding
        ] {
            let p = pieces_in(uv, &hull);
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
        assert!(pieces_in(off, &hull).is_empty());
        let wrap = [Vec2::ZERO, Vec2::new(2.0, 0.0), Vec2::Y];
        assert_eq!(pieces_in(wrap, &hull).len(), 1);
    }

    #[test]
    fn the_enclosing_quad_of_a_rectangle_or_a_diamond_is_itself() {
        let rect = rect(Vec2::new(0.2, 0.1), Vec2::new(0.7, 0.9));
        let diamond = ellipse(4, Vec2::splat(0.5), Vec2::splat(0.4));
        for (hull, want) in [(rect, 0.4), (diamond, 0.32)] {
            let q = enclosing_quad(&hull).unwrap();
            assert!((area(&q) - want).abs() < 1e-5, "{q:?}");
        }
    }

    #[test]
    fn the_enclosing_quad_contains_its_hull_within_the_square() {
        // A regular 12-gon touching the square's left side and a triangle in a corner.
        let gon = ellipse(12, Vec2::new(0.4, 0.5), Vec2::new(0.4, 0.3));
        let tri = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(0.6, 0.0),
            Vec2::new(0.0, 0.6),
        ];
        for hull in [&gon, &tri] {
            let q = enclosing_quad(hull).unwrap();
            assert!(hull.iter().all(|&p| contains(&q, p)), "{q:?}");
            assert!(
                q.iter()
                    .all(|p| p.min_element() >= 0.0 && p.max_element() <= 1.0)
            );
            // Counter-clockwise, at least the hull's area, at most the square's.
            let (a, h) = (area(&q), area(hull));
            assert!(a >= h - 1e-5 && a <= 1.0, "{a} for a hull of {h}");
        }
        // The 12-gon's quad is its bounding box or tighter.
        assert!(area(&enclosing_quad(&gon).unwrap()) <= 0.8 * 0.6 + 1e-4);
        assert!(enclosing_quad(&[Vec2::ZERO, Vec2::X]).is_none());
        assert!(enclosing_quad(&[Vec2::ZERO, Vec2::new(1.5, 0.0), Vec2::Y]).is_none());
    }
}
