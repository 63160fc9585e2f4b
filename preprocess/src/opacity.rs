//! The opacity volume of a model (see [`forest_format::opacity`]): its alpha-tested surface
//! area splatted into voxels, as optical depth per voxel length.
//!
//! Each triangle is covered by stratified points, about [`POINTS_PER_VOXEL_AREA`] per voxel
//! face of its area (at least one). A point on an opaque texel (alpha at least
//! [`crate::mesh::ALPHA_CUTOFF`], or any point of an untextured material) carries its share of
//! the triangle's area, splatted trilinearly onto the voxel centres around it. A voxel's area
//! `A` becomes the optical depth `G·A/h²` across one voxel length of side `h`, with `G =`
//! [`LEAF_PROJECTION`].

use glam::Vec3;
use rayon::prelude::*;

use forest_format::opacity::{LEAF_PROJECTION, OpacityVolume};
use forest_format::slab::Sphere;

use crate::mesh::Mesh;
use crate::sampling::stratified_barycentric;

/// Sample points per voxel face of triangle area.
pub const POINTS_PER_VOXEL_AREA: f32 = 16.0;

/// The opacity volume of `mesh` over the cube around `sphere`, `resolution` voxels a side.
pub fn opacity_volume(mesh: &Mesh, sphere: &Sphere, resolution: u32) -> OpacityVolume {
    let r = resolution as usize;
    let h = 2.0 * sphere.radius / resolution as f32;
    let lo = sphere.center - Vec3::splat(sphere.radius);
    // Grids of splatted area per fixed chunk of triangles, summed in chunk order: the same
    // sums whatever the threads, so a bake is byte-identical run to run.
    let chunk = mesh.tris.len().div_ceil(64).max(1024);
    let grids: Vec<Vec<f32>> = mesh
        .tris
        .par_chunks(chunk)
        .enumerate()
        .map(|(c, tris)| {
            let mut grid = vec![0f32; r * r * r];
            for (k, t) in tris.iter().enumerate() {
                let ti = c * chunk + k;
                let a = 0.5 * (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).length();
                if !(a > 0.0 && a.is_finite()) {
                    continue;
                }
                // side² stratified points in the triangle's unit square.
                let side = ((a / (h * h) * POINTS_PER_VOXEL_AREA).sqrt().ceil() as u32).max(1);
                let share = a / (side * side) as f32;
                for s in 0..side * side {
                    let b = stratified_barycentric(ti as u32, s, side, 0x3c6e_f372);
                    if !mesh.solid_at(t, b) {
                        continue;
                    }
                    let p = t.p[0] * b[0] + t.p[1] * b[1] + t.p[2] * b[2];
                    splat(&mut grid, resolution, (p - lo) / h - 0.5, share);
                }
            }
            grid
        })
        .collect();
    let mut area = vec![0f32; r * r * r];
    for g in &grids {
        area.iter_mut().zip(g).for_each(|(x, y)| *x += y);
    }
    let scale = LEAF_PROJECTION / (h * h);
    let depths: Vec<f32> = area.iter().map(|a| a * scale).collect();
    OpacityVolume::from_depths(resolution, &depths)
}

/// Add `w` to the grid at voxel coordinates `x` (voxel centres at integers), split
/// trilinearly over the 8 voxels around it; weight outside the grid is dropped.
fn splat(grid: &mut [f32], resolution: u32, x: Vec3, w: f32) {
    let r = resolution as i64;
    let i0 = x.floor();
    let f = x - i0;
    let (i, j, k) = (i0.x as i64, i0.y as i64, i0.z as i64);
    for (dk, wk) in [(k, 1.0 - f.z), (k + 1, f.z)] {
        for (dj, wj) in [(j, 1.0 - f.y), (j + 1, f.y)] {
            for (di, wi) in [(i, 1.0 - f.x), (i + 1, f.x)] {
                if (0..r).contains(&di) && (0..r).contains(&dj) && (0..r).contains(&dk) {
                    grid[(di + r * (dj + r * dk)) as usize] += w * wi * wj * wk;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{Material, Tri};
    use glam::Vec2;

    fn card(y: f32, half: f32) -> [Tri; 2] {
        let p = |x: f32, z: f32| Vec3::new(x, y, z);
        let tri = |a: Vec3, b: Vec3, c: Vec3| Tri {
            p: [a, b, c],
            uv: [Vec2::ZERO; 3],
            n: [Vec3::Y; 3],
            material: 0,
        };
        [
            tri(p(-half, -half), p(half, -half), p(half, half)),
            tri(p(-half, -half), p(half, half), p(-half, half)),
        ]
    }

    fn mesh(tris: Vec<Tri>) -> Mesh {
        Mesh {
            tris,
            materials: vec![Material {
                name: "m".into(),
                kd: Vec3::ONE,
                colour: None,
                alpha: None,
                translucency: 0.0,
            }],
            textures: vec![],
            degenerate: 0,
            hash: 0,
            notes: Vec::new(),
        }
    }

    #[test]
    fn a_card_deposits_its_area_as_optical_depth() {
        // A 1×1 card: the total optical depth times h² over G is its area.
        let sphere = Sphere {
            center: Vec3::ZERO,
            radius: 2.0,
        };
        let m = mesh(card(0.3, 0.5).to_vec());
        let res = 16;
        let v = opacity_volume(&m, &sphere, res);
        let h = 4.0 / res as f32;
        // Decoding loses at most half a code step of each square root.
        let total: f32 = v
            .codes
            .iter()
            .map(|&c| v.max_depth * (f32::from(c) / 255.0).powi(2))
            .sum();
        let area = total * h * h / LEAF_PROJECTION;
        assert!((area - 1.0).abs() < 0.02, "{area}");
        // A ray up through the card's centre is attenuated, one beside it is not.
        let below = Vec3::new(0.0, -0.5, 0.0);
        let t = v.transmittance(&sphere, below, Vec3::Y);
        assert!(t < 0.9, "{t}");
        let beside = Vec3::new(1.5, -0.5, 0.0);
        assert!((v.transmittance(&sphere, beside, Vec3::Y) - 1.0).abs() < 1e-3);
    }
}
