//! Sampling directions over the upper hemisphere, their triangulation, and view blending.
//!
//! Directions lie on rings of constant elevation, the first ring on the horizon and the last
//! point at the zenith, with points per ring proportional to the ring's circumference, so the
//! set covers the whole hemisphere (views from below the horizon are clamped onto it). They
//! are triangulated (Delaunay) in the octahedral projection `p = (x, z)/(|x| + max(y,0) + |z|)`
//! (the zenith at the centre, the horizon on the diamond `|p.x| + |p.y| = 1`); the blend of a
//! view direction is its barycentric coordinates in the triangle that contains its projection.
//! The projection needs no trigonometry and is scale-invariant, so the GPU computes exactly the
//! same weights as this CPU code from an unnormalised view vector.

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
            for j in 0..n {
                let phi = 2.0 * std::f64::consts::PI * (f64::from(j) + 0.5 * (i % 2) as f64)
                    / f64::from(n);
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
    }
    dirs.push(Vec3::Y);
    dirs
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

/// The 1–3 directions blended for a view, with weights summing to 1 (unused slots weigh 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blend {
    /// Direction indices.
    pub index: [u32; 3],
    /// Barycentric weights, each in `[0,1]`.
    pub weight: [f32; 3],
}

/// Blend of the sampling directions for a view direction `view` (unit, from the model towards
/// the viewer, in the model's object space).
///
/// Inside the triangulation: the barycentric coordinates of the containing triangle. Outside
/// its hull (between horizon points): the nearest hull edge, weighted by the projection onto
/// it. Without triangles (fewer than 3 directions): the nearest direction alone.
pub fn blend(dirs: &[Vec3], triangles: &[[u32; 3]], view: Vec3) -> Blend {
    let p = disk_point(view);
    let pts: Vec<Vec2> = dirs.iter().map(|&d| disk_point(d)).collect();
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
            let b = blend(&d, &t, v);
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
            let b = blend(&d, &t, view.normalize());
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
        let b = blend(&d, &[], Vec3::new(0.0, 0.9, 0.1).normalize());
        assert_eq!(b.index[0], 1);
        assert_eq!(b.weight, [1.0, 0.0, 0.0]);
    }
}
