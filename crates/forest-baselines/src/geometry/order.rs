//! Presorted triangle orders: each model's triangles sorted front to back for a few fixed view
//! directions, so that a tree's nearest leaves are drawn first and the depth test rejects
//! the leaves they hide before they are shaded (seed 003 sorts trees; this sorts within a
//! tree). Nothing here depends on the camera: the orders are built once; per tree and frame
//! the cull pass's scatter picks the bin of the direction from the eye to the tree
//! (`order_bin` in `shaders/geometry_types.wgsl`, mirrored by [`order_bin`]) and stores it
//! in the tree's visible-list entry, and the vertex stage draws that bin's order
//! (`draw_vertex` in `shaders/geometry_draw.wgsl`). Any order draws the same image (the
//! leaves are alpha-tested and opaque); only the fragments shaded and rejected change.

use forest_format::model::RefVertex;
use glam::Vec3;

/// View-direction bins: 8 azimuths × 3 elevation bands.
pub const ORDER_BINS: u32 = 24;

/// Bits of a visible-list entry that hold the instance's index; the tree's order bin, chosen
/// once per tree and frame by the cull pass's scatter, is stored above them
/// (`VISIBLE_ID_BITS` in `shaders/geometry_types.wgsl`).
pub const VISIBLE_ID_BITS: u32 = 24;
const _: () = assert!(
    forest_format::forest::MAX_INSTANCES <= 1 << VISIBLE_ID_BITS
        && ORDER_BINS <= 1 << (32 - VISIBLE_ID_BITS)
);

/// Distance of each bin's virtual eye from the tree's centre, in bounding radii: the near
/// trees the geometry methods draw lie a few radii away, so a perspective sort from there
/// puts their front leaves first better than a plane sort does.
pub const VIRTUAL_EYE_RADII: f32 = 3.0;

/// The bin of the object-space direction `v` from the eye towards the tree (any length; a
/// zero vector falls in bin 8, level and at azimuth 0): azimuth `atan2(z, x)` rounded to the
/// nearest of 8, elevation band 0 below −30°, 1 within ±30°, 2 above.
pub fn order_bin(v: Vec3) -> u32 {
    let len = v.length();
    let u = if len > 1e-12 { v / len } else { Vec3::X };
    let turns = u.z.atan2(u.x) / std::f32::consts::TAU;
    let azimuth = ((turns * 8.0 + 8.5).floor() as i64).rem_euclid(8) as u32;
    let band = if u.y < -0.5 {
        0
    } else if u.y > 0.5 {
        2
    } else {
        1
    };
    band * 8 + azimuth
}

/// The unit direction at the centre of bin `k` (< [`ORDER_BINS`]): azimuth `(k mod 8) · 45°`,
/// elevation −60°, 0° or 60°.
pub fn bin_direction(k: u32) -> Vec3 {
    let azimuth = (k % 8) as f32 * std::f32::consts::FRAC_PI_4;
    let elevation = [-60f32, 0.0, 60.0][(k / 8).min(2) as usize].to_radians();
    Vec3::new(
        elevation.cos() * azimuth.cos(),
        elevation.sin(),
        elevation.cos() * azimuth.sin(),
    )
}

/// The draw orders of `vertices` (whole triangles, 3 vertices each): for every bin `k`,
/// entry `k · T + t` (T = `vertices.len() / 3`) is the triangle drawn `t`-th. Each range of
/// `ranges` (vertex ranges `[start, end)` on triangle boundaries, disjoint: a species' LOD)
/// is sorted within itself by distance from the bin's virtual eye, `VIRTUAL_EYE_RADII`
/// radii from `sphere`'s centre against the bin's direction; triangles outside every range
/// keep their place. Ties keep the model's order.
pub fn draw_orders(
    vertices: &[RefVertex],
    ranges: &[([f32; 4], std::ops::Range<usize>)],
) -> Vec<u32> {
    let triangles = vertices.len() / 3;
    let mut out = Vec::with_capacity(triangles * ORDER_BINS as usize);
    let centroid = |t: usize| {
        let p = |i: usize| Vec3::from(vertices[3 * t + i].pos);
        (p(0) + p(1) + p(2)) / 3.0
    };
    let centroids: Vec<Vec3> = (0..triangles).map(centroid).collect();
    for k in 0..ORDER_BINS {
        let base = out.len();
        out.extend(0..triangles as u32);
        let d = bin_direction(k);
        for (sphere, range) in ranges {
            let (a, b) = (range.start / 3, (range.end / 3).min(triangles));
            if a >= b {
                continue;
            }
            let eye =
                Vec3::new(sphere[0], sphere[1], sphere[2]) - d * (VIRTUAL_EYE_RADII * sphere[3]);
            let mut keyed: Vec<(f32, u32)> = (a..b)
                .map(|t| (centroids[t].distance_squared(eye), t as u32))
                .collect();
            keyed.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
            for (slot, (_, t)) in out[base + a..base + b].iter_mut().zip(keyed) {
                *slot = t;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(z: f32) -> [RefVertex; 3] {
        let v = |x: f32, y: f32| RefVertex {
            pos: [x, y, z],
            sky_front: 1.0,
            normal: [0.0, 0.0, 1.0],
            material: 0,
            uv: [0.0, 0.0],
            element: forest_format::model::NONE,
            sky_back: 1.0,
        };
        [v(0.0, 0.0), v(0.1, 0.0), v(0.0, 0.1)]
    }

    #[test]
    fn each_bin_holds_its_own_direction() {
        for k in 0..ORDER_BINS {
            assert_eq!(order_bin(bin_direction(k)), k);
            assert_eq!(order_bin(bin_direction(k) * 7.0), k);
        }
        // Straight up and down fall in the polar bands; the zero vector is bin 8 (azimuth 0).
        assert_eq!(order_bin(Vec3::Y) / 8, 2);
        assert_eq!(order_bin(-Vec3::Y) / 8, 0);
        assert_eq!(order_bin(Vec3::ZERO), 8);
        // Azimuths round to the nearest of eight: 22° to 0°, 23° to 45°.
        let at = |deg: f32| {
            order_bin(Vec3::new(
                deg.to_radians().cos(),
                0.0,
                deg.to_radians().sin(),
            ))
        };
        assert_eq!(
            (at(22.0), at(23.0), at(-22.0), at(-23.0), at(180.0)),
            (8, 9, 8, 15, 12)
        );
    }

    #[test]
    fn orders_put_the_eyes_side_first_within_each_range() {
        // Five triangles at z = -2..2, then one outside every range.
        let zs = [0.0, -2.0, 2.0, 1.0, -1.0, 5.0];
        let vertices: Vec<RefVertex> = zs.iter().flat_map(|&z| tri(z)).collect();
        let sphere = [0.0, 0.0, 0.0, 2.0];
        let orders = draw_orders(&vertices, &[(sphere, 0..15)]);
        let t = vertices.len() / 3;
        assert_eq!(orders.len(), t * ORDER_BINS as usize);
        for k in 0..ORDER_BINS {
            let o = &orders[k as usize * t..(k as usize + 1) * t];
            // A permutation of the range, the triangle outside it in place.
            let mut sorted = o[..5].to_vec();
            sorted.sort();
            assert_eq!(sorted, [0, 1, 2, 3, 4]);
            assert_eq!(o[5], 5);
        }
        // Looking along +z (azimuth 90°, bin 8 + 2) the eye is at z = -6: nearest z first.
        let o = &orders[10 * t..11 * t];
        assert_eq!(&o[..5], &[1, 4, 0, 3, 2]);
        // Along -z (bin 8 + 6) the other way round.
        let o = &orders[14 * t..15 * t];
        assert_eq!(&o[..5], &[2, 3, 0, 4, 1]);
    }
}
