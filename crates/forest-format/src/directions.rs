//! Sampling directions over the sphere, their triangulation, and view blending.
//!
//! Upper directions lie on rings of constant elevation, the first ring on the horizon and the
//! last point at the zenith, with points per ring proportional to the ring's circumference, so
//! the set covers the whole upper hemisphere. Optional lower directions (rings below the
//! horizon and the nadir) follow them, for trees seen from below. Each hemisphere is
//! triangulated (Delaunay) in its own octahedral projection: above,
//! `p = (x, z)/(|x| + max(y,0) + |z|)` (the zenith at the centre), below,
//! `p = (x, z)/(|x| + max(−y,0) + |z|)` (the nadir at the centre); both put the horizon on the
//! diamond `|p.x| + |p.y| = 1`, and both triangulations include the horizon ring, so blends
//! agree across the horizon. The blend of a view direction is its barycentric coordinates in
//! the triangle of its hemisphere that contains its projection. Without lower directions, views
//! from below are clamped onto the horizon. The projections need no trigonometry and are
//! scale-invariant, so the GPU computes exactly the same weights as this CPU code from an
//! unnormalised view vector.

use glam::{Vec2, Vec3};

/// The `count` sampling directions (unit vectors, `y ≥ 0`), deterministic.
///
/// `count = 1` gives the zenith alone; otherwise `n = max(1, round((π/2)/√(2π/count)))` rings
/// at elevations `90°·i/n`, `i < n`, share `count − 1` points in proportion to `cos(elevation)`
/// (largest remainders, at least one per ring while points last), plus the zenith. Odd rings are
/// rotated by half a step. At `count = 15`: 8 on the horizon, 6 at 45°, the zenith.
pub fn hemisphere_directions(count: u32) -> Vec<Vec3> {
    if count == 0 {
        return Vec::new();
    }
    let mut dirs = Vec::with_capacity(count as usize);
    let rest = count - 1;
    if rest > 0 {
        let spacing = (2.0 * std::f64::consts::PI / f64::from(count)).sqrt();
        let rings = ((std::f64::consts::FRAC_PI_2 / spacing).round() as u32).clamp(1, rest);
        let elev: Vec<f64> = (0..rings)
            .map(|i| std::f64::consts::FRAC_PI_2 * f64::from(i) / f64::from(rings))
            .collect();
        let total: f64 = elev.iter().map(|e| e.cos()).sum();
        let exact: Vec<f64> = elev
            .iter()
            .map(|e| f64::from(rest) * e.cos() / total)
            .collect();
        let mut counts: Vec<u32> = exact.iter().map(|x| (x.floor() as u32).max(1)).collect();
        // Largest remainder until the counts add up (ties broken by lower ring).
        while counts.iter().sum::<u32>() < rest {
            let (i, _) = exact
                .iter()
                .zip(&counts)
                .enumerate()
                .map(|(i, (x, &c))| (i, x - f64::from(c)))
                .fold((0, f64::NEG_INFINITY), |best, cur| {
                    if cur.1 > best.1 { cur } else { best }
                });
            counts[i] += 1;
        }
        while counts.iter().sum::<u32>() > rest {
            let i = counts
                .iter()
                .rposition(|&c| c > 1)
                .unwrap_or(counts.len() - 1);
            counts[i] -= 1;
        }
        for (i, (&e, &n)) in elev.iter().zip(&counts).enumerate() {
            push_ring(&mut dirs, e, n, i % 2 == 1);
        }
    }
    dirs.push(Vec3::Y);
    dirs
}

/// Push `n` unit directions at elevation `e` (radians), evenly spaced in azimuth from +Z
/// towards +X, rotated by half a step when `half_step`.
fn push_ring(dirs: &mut Vec<Vec3>, e: f64, n: u32, half_step: bool) {
    let offset = if half_step { 0.5 } else { 0.0 };
    for j in 0..n {
        let phi = 2.0 * std::f64::consts::PI * (f64::from(j) + offset) / f64::from(n);
        dirs.push(
            Vec3::new(
                (e.cos() * phi.sin()) as f32,
                e.sin() as f32,
                (e.cos() * phi.cos()) as f32,
            )
            .normalize(),
        );
    }
}

/// The sampling directions: `upper` over the upper hemisphere ([`hemisphere_directions`]),
/// then `below` under the horizon ([`lower_directions`]).
pub fn sampling_directions(upper: u32, below: u32) -> Vec<Vec3> {
    let mut d = hemisphere_directions(upper);
    d.extend(lower_directions(below));
    d
}

/// `count` directions strictly below the horizon, deterministic: the nadir last, and before it
/// `R = max(1, round(√(count − 1) / 2))` rings at elevations `−90°·i/(R + 1)`, `i = 1..=R`,
/// sharing `count − 1` points in proportion to `cos(elevation)` (at least one each while
/// points last). At `count = 5`: four at −45° (azimuths 45°, 135°, …) and the nadir.
pub fn lower_directions(count: u32) -> Vec<Vec3> {
    if count == 0 {
        return Vec::new();
    }
    let rest = count - 1;
    let mut dirs = Vec::with_capacity(count as usize);
    if rest > 0 {
        let rings = ((f64::from(rest).sqrt() / 2.0).round() as u32).clamp(1, rest);
        let elev: Vec<f64> = (1..=rings)
            .map(|i| -std::f64::consts::FRAC_PI_2 * f64::from(i) / f64::from(rings + 1))
            .collect();
        let total: f64 = elev.iter().map(|e| e.cos()).sum();
        let mut counts: Vec<u32> = elev
            .iter()
            .map(|e| ((f64::from(rest) * e.cos() / total).round() as u32).max(1))
            .collect();
        while counts.iter().sum::<u32>() > rest {
            let i = counts.iter().rposition(|&c| c > 1).unwrap_or(0);
            counts[i] -= 1;
        }
        while counts.iter().sum::<u32>() < rest {
            counts[0] += 1;
        }
        for (i, (&e, &n)) in elev.iter().zip(&counts).enumerate() {
            push_ring(&mut dirs, e, n, i % 2 == 0);
        }
    }
    dirs.push(Vec3::NEG_Y);
    dirs
}

/// Octahedral projection of a direction for views from below (the nadir at the centre);
/// above-horizon directions land on the horizon's diamond.
pub fn disk_point_lower(dir: Vec3) -> Vec2 {
    disk_point(Vec3::new(dir.x, -dir.y, dir.z))
}

/// Octahedral projection of a direction (any length); below-horizon directions are clamped
/// onto the horizon, and straight down (or zero) maps to the zenith's point.
pub fn disk_point(dir: Vec3) -> Vec2 {
    let den = dir.x.abs() + dir.y.max(0.0) + dir.z.abs();
    if den > 0.0 {
        Vec2::new(dir.x / den, dir.z / den)
    } else {
        Vec2::ZERO
    }
}

/// Delaunay triangles (counter-clockwise index triples) of the directions' disk projections.
/// Empty when fewer than 3 directions or all collinear.
pub fn triangulate(dirs: &[Vec3]) -> Vec<[u32; 3]> {
    let points: Vec<delaunator::Point> = dirs
        .iter()
        .map(|&d| {
            let p = disk_point(d);
            delaunator::Point {
                x: f64::from(p.x),
                y: f64::from(p.y),
            }
        })
        .collect();
    let t = delaunator::triangulate(&points);
    t.triangles
        .chunks_exact(3)
        .map(|c| [c[0] as u32, c[1] as u32, c[2] as u32])
        .collect()
}

/// Triangulations for views from above and from below: `(upper, lower)`. The upper one covers
/// the directions with `y ≥ 0` ([`triangulate`]); the lower one (empty without directions
/// below the horizon) covers the horizon ring and the directions below it, in
/// [`disk_point_lower`]. Indices refer to `dirs`.
pub fn triangulate_sphere(dirs: &[Vec3]) -> (Vec<[u32; 3]>, Vec<[u32; 3]>) {
    let subset = |keep: &dyn Fn(Vec3) -> bool, flip: bool| {
        let idx: Vec<u32> = (0..dirs.len() as u32)
            .filter(|&i| keep(dirs[i as usize]))
            .collect();
        let pts: Vec<Vec3> = idx
            .iter()
            .map(|&i| {
                let d = dirs[i as usize];
                if flip { Vec3::new(d.x, -d.y, d.z) } else { d }
            })
            .collect();
        triangulate(&pts)
            .into_iter()
            .map(|t| t.map(|k| idx[k as usize]))
            .collect::<Vec<_>>()
    };
    let upper = subset(&|d| d.y >= 0.0, false);
    let lower = if dirs.iter().any(|d| d.y < 0.0) {
        subset(&|d| d.y <= 0.0, true)
    } else {
        Vec::new()
    };
    (upper, lower)
}

/// Check that `tris` triangulate one half of `dirs` as [`triangulate_sphere`] makes them: the
/// directions with `y ≥ 0` in [`disk_point`] (`lower` false) or those with `y ≤ 0` in
/// [`disk_point_lower`]. Every triangle names three distinct directions of that half and
/// all turn the same way (or have no area: nearly collinear directions); each directed edge is used once, an inner edge by two triangles
/// in opposite senses; the edges used once bound the half's convex hull; and every direction
/// of the half is a corner. Any Delaunay tie the bake broke either way passes; a changed
/// index does not. The error names the first triangle or direction at fault.
pub fn check_triangulation(dirs: &[Vec3], tris: &[[u32; 3]], lower: bool) -> Result<(), String> {
    let n = dirs.len() as u32;
    let half = |i: u32| {
        i < n && {
            let d = dirs[i as usize];
            if lower { d.y <= 0.0 } else { d.y >= 0.0 }
        }
    };
    let at = |i: u32| {
        let d = dirs[i as usize];
        let p = if lower {
            disk_point_lower(d)
        } else {
            disk_point(d)
        };
        (f64::from(p.x), f64::from(p.y))
    };
    let cross = |a: u32, b: u32, c: u32| {
        let (pa, pb, pc) = (at(a), at(b), at(c));
        (pb.0 - pa.0) * (pc.1 - pa.1) - (pb.1 - pa.1) * (pc.0 - pa.0)
    };
    let members: Vec<u32> = (0..n).filter(|&i| half(i)).collect();
    // Rounding leaves some triangles of (nearly) collinear directions with no area; the
    // others all turn the first one's way (delaunator's is clockwise here).
    const FLAT: f64 = 1e-9;
    let sense = tris
        .iter()
        .filter(|t| t.iter().all(|&i| half(i)))
        .map(|&[a, b, c]| cross(a, b, c))
        .find(|x| x.abs() > FLAT)
        .map_or(1.0, f64::signum);
    let mut edges = std::collections::HashSet::new();
    for t in tris {
        let [a, b, c] = *t;
        if !(half(a) && half(b) && half(c)) || a == b || b == c || a == c {
            return Err(format!(
                "triangle {t:?} does not name three directions of its half"
            ));
        }
        if sense * cross(a, b, c) < -FLAT {
            return Err(format!("triangle {t:?} turns against the others"));
        }
        for e in [(a, b), (b, c), (c, a)] {
            if !edges.insert(e) {
                return Err(format!("triangle {t:?} overlaps another along {e:?}"));
            }
        }
    }
    for &(a, b) in &edges {
        if !edges.contains(&(b, a))
            && let Some(&p) = members.iter().find(|&&p| sense * cross(a, b, p) < -1e-6)
        {
            return Err(format!(
                "edge ({a}, {b}) bounds the triangles, but direction {p} lies beyond it"
            ));
        }
    }
    if !tris.is_empty()
        && let Some(p) = members
            .iter()
            .find(|&&p| !edges.iter().any(|&(a, _)| a == p))
    {
        return Err(format!("direction {p} is no triangle's corner"));
    }
    Ok(())
}

/// The 1–3 directions blended for a view, with weights summing to 1 (unused slots weigh 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blend {
    /// Direction indices.
    pub index: [u32; 3],
    /// Barycentric weights, each in `[0,1]`.
    pub weight: [f32; 3],
}

/// Blend of the sampling directions for a view direction `view` (from the model towards the
/// viewer, in the model's object space; any length).
///
/// Views from below (`view.y < 0`) use the `lower` triangles in [`disk_point_lower`] when
/// there are any; every other view uses the `upper` triangles in [`disk_point`]. Inside the
/// triangulation: the barycentric coordinates of the containing triangle. Outside its hull
/// (between horizon points): the nearest hull edge, weighted by the projection onto it.
/// Without triangles (fewer than 3 directions): the nearest direction alone.
pub fn blend(dirs: &[Vec3], upper: &[[u32; 3]], lower: &[[u32; 3]], view: Vec3) -> Blend {
    let below = view.y < 0.0 && !lower.is_empty();
    let proj = if below { disk_point_lower } else { disk_point };
    let triangles = if below { lower } else { upper };
    let p = proj(view);
    let pts: Vec<Vec2> = dirs.iter().map(|&d| proj(d)).collect();
    let mut best_edge: Option<(f32, Blend)> = None;
    for t in triangles {
        let [a, b, c] = t.map(|i| pts[i as usize]);
        let den = (b - a).perp_dot(c - a);
        if den.abs() < 1e-12 {
            continue;
        }
        let wb = (p - a).perp_dot(c - a) / den;
        let wc = (b - a).perp_dot(p - a) / den;
        let wa = 1.0 - wb - wc;
        const TOL: f32 = -1e-6;
        if wa >= TOL && wb >= TOL && wc >= TOL {
            let w = [wa.max(0.0), wb.max(0.0), wc.max(0.0)];
            let s = w[0] + w[1] + w[2];
            return Blend {
                index: *t,
                weight: w.map(|x| x / s),
            };
        }
        for (i, j) in [(0, 1), (1, 2), (2, 0)] {
            let (e0, e1) = (t[i], t[j]);
            let (q0, q1) = (pts[e0 as usize], pts[e1 as usize]);
            let e = q1 - q0;
            let s = ((p - q0).dot(e) / e.length_squared()).clamp(0.0, 1.0);
            let dist = (q0 + e * s - p).length_squared();
            if best_edge.as_ref().is_none_or(|(d, _)| dist < *d) {
                best_edge = Some((
                    dist,
                    Blend {
                        index: [e0, e1, e0],
                        weight: [1.0 - s, s, 0.0],
                    },
                ));
            }
        }
    }
    if let Some((_, b)) = best_edge {
        return b;
    }
    let nearest = dirs
        .iter()
        .enumerate()
        .fold((0u32, f32::NEG_INFINITY), |best, (i, d)| {
            let c = d.dot(view);
            if c > best.1 { (i as u32, c) } else { best }
        })
        .0;
    Blend {
        index: [nearest; 3],
        weight: [1.0, 0.0, 0.0],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bakes_triangulations_pass_their_check_and_a_changed_index_does_not() {
        let mut changed = 0;
        for upper in 1..=40 {
            for below in [0, 1, 2, 5, 12] {
                let dirs = sampling_directions(upper, below);
                let (up, lo) = triangulate_sphere(&dirs);
                for (tris, lower) in [(&up, false), (&lo, true)] {
                    check_triangulation(&dirs, tris, lower)
                        .unwrap_or_else(|e| panic!("{upper} + {below}: {e}"));
                    // Every corner of every triangle moved to every other direction.
                    for t in 0..tris.len() {
                        for corner in 0..3 {
                            for to in 0..dirs.len() as u32 {
                                let mut bad = tris.clone();
                                if bad[t][corner] == to {
                                    continue;
                                }
                                bad[t][corner] = to;
                                assert!(
                                    check_triangulation(&dirs, &bad, lower).is_err(),
                                    "{upper} + {below}: {bad:?} passed"
                                );
                                changed += 1;
                            }
                        }
                    }
                }
            }
        }
        assert!(changed > 10_000, "{changed}");
    }

    #[test]
    fn default_set_has_15_unit_upper_directions() {
        let d = hemisphere_directions(15);
        assert_eq!(d.len(), 15);
        assert!(
            d.iter()
                .all(|v| (v.length() - 1.0).abs() < 1e-6 && v.y >= 0.0)
        );
        assert_eq!(d.iter().filter(|v| v.y.abs() < 1e-6).count(), 8);
        assert_eq!(*d.last().unwrap(), Vec3::Y);
        for n in 1..=64 {
            assert_eq!(hemisphere_directions(n).len(), n as usize, "count {n}");
        }
    }

    #[test]
    fn triangulation_covers_disk_area_of_the_hull() {
        let d = hemisphere_directions(15);
        let t = triangulate(&d);
        assert!(!t.is_empty());
        let pts: Vec<Vec2> = d.iter().map(|&v| disk_point(v)).collect();
        let area: f32 = t
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| pts[i as usize]);
                0.5 * (b - a).perp_dot(c - a).abs()
            })
            .sum();
        // The 8 horizon points span the whole diamond |x| + |y| ≤ 1, of area 2.
        assert!((area - 2.0).abs() < 1e-4, "area {area}");
    }

    #[test]
    fn blend_at_a_sampling_direction_is_that_direction() {
        let d = hemisphere_directions(15);
        let t = triangulate(&d);
        for (i, &v) in d.iter().enumerate() {
            let b = blend(&d, &t, &[], v);
            let w: f32 = (0..3)
                .filter(|&k| b.index[k] == i as u32)
                .map(|k| b.weight[k])
                .sum();
            assert!((w - 1.0).abs() < 1e-5, "direction {i}: {b:?}");
        }
    }

    #[test]
    fn blend_weights_reproduce_the_view_point() {
        let d = hemisphere_directions(15);
        let t = triangulate(&d);
        for view in [
            Vec3::new(0.3, 0.6, 0.2),
            Vec3::new(-0.7, 0.2, 0.1),
            Vec3::new(0.1, -0.5, -0.9), // below the horizon: clamped
            Vec3::new(0.0, 0.0, 1.0),
        ] {
            let b = blend(&d, &t, &[], view.normalize());
            let s: f32 = b.weight.iter().sum();
            assert!((s - 1.0).abs() < 1e-5);
            let p: Vec2 = (0..3)
                .map(|k| disk_point(d[b.index[k] as usize]) * b.weight[k])
                .sum();
            let target = disk_point(view.normalize());
            // The hull is the whole diamond: barycentric weights reproduce the point.
            assert!((p - target).length() < 1e-5, "{view}: {p} vs {target}");
        }
    }

    #[test]
    fn fewer_than_three_directions_pick_the_nearest() {
        let d = hemisphere_directions(2);
        assert!(triangulate(&d).is_empty());
        let b = blend(&d, &[], &[], Vec3::new(0.0, 0.9, 0.1).normalize());
        assert_eq!(b.index[0], 1);
        assert_eq!(b.weight, [1.0, 0.0, 0.0]);
    }

    #[test]
    fn lower_directions_are_below_and_end_at_the_nadir() {
        let d = lower_directions(5);
        assert_eq!(d.len(), 5);
        assert_eq!(*d.last().unwrap(), Vec3::NEG_Y);
        for v in &d[..4] {
            assert!((v.y + std::f32::consts::FRAC_1_SQRT_2).abs() < 1e-6, "{v}");
        }
        for n in 0..=40 {
            let d = lower_directions(n);
            assert_eq!(d.len(), n as usize, "count {n}");
            assert!(
                d.iter()
                    .all(|v| v.y < 0.0 && (v.length() - 1.0).abs() < 1e-6)
            );
        }
    }

    #[test]
    fn views_from_below_blend_lower_directions_and_agree_at_the_horizon() {
        let d = sampling_directions(15, 5);
        let (up, low) = triangulate_sphere(&d);
        assert!(!low.is_empty());
        // Every lower triangle uses the horizon ring or directions below it.
        assert!(low.iter().flatten().all(|&i| d[i as usize].y <= 0.0));
        // At each sampling direction, the blend is that direction alone.
        for (i, &v) in d.iter().enumerate() {
            let b = blend(&d, &up, &low, v);
            let w: f32 = (0..3)
                .filter(|&k| b.index[k] == i as u32)
                .map(|k| b.weight[k])
                .sum();
            assert!((w - 1.0).abs() < 1e-5, "direction {i} ({v}): {b:?}");
        }
        // Straight down is the nadir alone.
        let b = blend(&d, &up, &low, Vec3::new(0.0, -3.0, 0.0));
        let nadir: f32 = (0..3)
            .filter(|&k| b.index[k] == 19)
            .map(|k| b.weight[k])
            .sum();
        assert!((nadir - 1.0).abs() < 1e-5, "{b:?}");
        // Just above and just below the horizon give the same weights on the same directions.
        for az in [0.1f32, 0.7, 2.0, 4.0] {
            let above = blend(&d, &up, &low, Vec3::new(az.sin(), 1e-4, az.cos()));
            let under = blend(&d, &up, &low, Vec3::new(az.sin(), -1e-4, az.cos()));
            let weights = |b: &Blend| {
                let mut w = vec![0.0f32; d.len()];
                for k in 0..3 {
                    w[b.index[k] as usize] += b.weight[k];
                }
                w
            };
            let (a, u) = (weights(&above), weights(&under));
            let diff: f32 = a.iter().zip(&u).map(|(x, y)| (x - y).abs()).sum();
            assert!(diff < 1e-3, "azimuth {az}: {above:?} vs {under:?}");
        }
        // Without lower directions a view from below is clamped onto the horizon.
        let d15 = sampling_directions(15, 0);
        let (up15, low15) = triangulate_sphere(&d15);
        assert!(low15.is_empty());
        let b = blend(&d15, &up15, &low15, Vec3::new(0.0, -1.0, 1.0));
        assert!(
            b.index
                .iter()
                .zip(b.weight)
                .all(|(&i, w)| w == 0.0 || d15[i as usize].y.abs() < 1e-6)
        );
    }
}
