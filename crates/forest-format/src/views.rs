//! Where a camera starts: the named views of a forest (`inside`, `hill`, `birds-eye`), which
//! `forest render`, the viewer's first frame and the Bevy example all take from here, so that
//! one placement rule serves them all.
//!
//! The rule: a view that stands in the forest keeps [`CLEARANCE`] metres from every tree's
//! bounding sphere ([`TreeShape`], the sphere the species' atlas frames, which holds its trunk
//! and crown), so no first frame starts inside a crown or against a trunk. [`Clearances`]
//! answers "how far is the nearest tree" through a grid over the trees, so a search over
//! thousands of spots in a forest of a million trees stays cheap.

use std::collections::HashMap;

use glam::{Quat, Vec3};

use crate::atlas::AtlasManifest;
use crate::forest::Forest;

/// Eye height above the ground of the views that stand on it (metres).
pub const EYE_HEIGHT: f32 = 1.7;

/// The least distance (metres) from a named view's eye to every tree's bounding sphere.
pub const CLEARANCE: f32 = 3.0;

/// The names [`named`] knows, in the order the help lists them.
pub const NAMES: [&str; 3] = ["inside", "hill", "birds-eye"];

/// Ring step (metres) of the search around the clump for a clear standing spot.
pub const RING_STEP: f32 = 2.0;

/// Spacing (metres) of the spots along one ring of that search (at least 16 per ring).
pub const SPOT_SPACING: f32 = 4.0;

/// A species' reach at scale 1: the sphere bounding its whole model, trunk and crown (object
/// space, metres), as its atlas records it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TreeShape {
    /// Centre in the model's frame (metres; the tree stands on y = 0).
    pub center: Vec3,
    /// Radius (metres, > 0).
    pub radius: f32,
}

impl TreeShape {
    /// The shape an atlas's manifest records.
    pub fn of(manifest: &AtlasManifest) -> Self {
        Self {
            center: manifest.bounding_sphere.center,
            radius: manifest.bounding_sphere.radius,
        }
    }
}

/// The world-space sphere of one tree: its species' [`TreeShape`] turned, scaled and placed.
fn world_sphere(forest: &Forest, shapes: &[TreeShape], i: usize) -> Option<(Vec3, f32)> {
    let t = &forest.instances[i];
    let s = shapes.get(t.species as usize)?;
    let c = Vec3::from_array(t.position) + Quat::from_rotation_y(t.rotation) * (s.center * t.scale);
    Some((c, s.radius * t.scale))
}

/// The trees' bounding spheres, bucketed on a square grid for distance queries.
pub struct Clearances<'a> {
    forest: &'a Forest,
    spheres: Vec<(Vec3, f32)>,
    /// Grid cell side (metres): the largest sphere radius plus [`CLEARANCE`].
    cell: f32,
    cells: HashMap<(i64, i64), Vec<u32>>,
}

impl<'a> Clearances<'a> {
    /// The trees of `forest`, each species shaped by `shapes` (in the forest's species order;
    /// a tree whose species has no shape, or whose sphere is not finite, is left out).
    pub fn new(forest: &'a Forest, shapes: &[TreeShape]) -> Self {
        let spheres: Vec<(Vec3, f32)> = (0..forest.instances.len())
            .filter_map(|i| world_sphere(forest, shapes, i))
            .filter(|(c, r)| c.is_finite() && r.is_finite())
            .collect();
        let cell = spheres.iter().map(|s| s.1).fold(0.0f32, f32::max) + CLEARANCE;
        let mut cells: HashMap<(i64, i64), Vec<u32>> = HashMap::new();
        for (k, (c, _)) in spheres.iter().enumerate() {
            cells.entry(Self::key(cell, *c)).or_default().push(k as u32);
        }
        Self {
            forest,
            spheres,
            cell,
            cells,
        }
    }

    fn key(cell: f32, p: Vec3) -> (i64, i64) {
        ((p.x / cell).floor() as i64, (p.z / cell).floor() as i64)
    }

    /// Distance (metres) from `p` to the nearest tree's bounding sphere, negative inside one.
    /// Exact where it is below [`CLEARANCE`]; elsewhere some value of at least that (a sphere
    /// outside the 3×3 grid cells around `p` lies farther). Infinite without a tree near.
    pub fn distance(&self, p: Vec3) -> f32 {
        let (x, z) = Self::key(self.cell, p);
        let mut d = f32::INFINITY;
        for dx in -1..=1 {
            for dz in -1..=1 {
                for &k in self.cells.get(&(x + dx, z + dz)).into_iter().flatten() {
                    let (c, r) = self.spheres[k as usize];
                    d = d.min(c.distance(p) - r);
                }
            }
        }
        d
    }

    /// Whether `p` keeps [`CLEARANCE`] from every tree's sphere.
    pub fn clear(&self, p: Vec3) -> bool {
        self.distance(p) >= CLEARANCE
    }

    /// A point `up` metres above the ground at (x, z).
    fn ground(&self, x: f32, z: f32, up: f32) -> Vec3 {
        Vec3::new(x, self.forest.ground_height(x, z) + up, z)
    }

    /// `eye` raised in steps of 5 m until it is clear of every tree (at most 400 m higher).
    fn raised(&self, eye: Vec3) -> Vec3 {
        (0..=80)
            .map(|k| eye + Vec3::Y * (5.0 * k as f32))
            .find(|&e| self.clear(e))
            .unwrap_or(eye + Vec3::Y * 400.0)
    }
}

/// The named view `name` of a forest (eye, target), standing on its ground, or None for a
/// name not in [`NAMES`]:
/// - `inside`: at eye height in a clump near the centre ([`inside`]);
/// - `hill`: 30 m above the highest ground among the trees, looking at the lowest ground
///   50 to 600 m away (on flat ground: 40 m up at the southern edge looking across);
/// - `birds-eye`: high above, looking down across the trees.
///
/// The two high views are raised until they too keep [`CLEARANCE`] from every tree.
pub fn named(name: &str, forest: &Forest, trees: &Clearances) -> Option<(Vec3, Vec3)> {
    Some(match name {
        "inside" => inside(forest, trees),
        "hill" => {
            let (e, t) = hill(forest);
            (trees.raised(e), t)
        }
        "birds-eye" => {
            let (e, t) = birds_eye(forest);
            (trees.raised(e), t)
        }
        _ => return None,
    })
}

/// The view a viewer or an example opens on: [`inside`].
pub fn start(forest: &Forest, trees: &Clearances) -> (Vec3, Vec3) {
    inside(forest, trees)
}

/// Inside the forest: near the tree with the most neighbours within 15 m among the 500
/// nearest the centre (a clump, not a clearing's edge), at the nearest spot to it, on rings
/// [`RING_STEP`] apart from 4 m out (south-south-east first on each ring, then round), whose
/// eye, [`EYE_HEIGHT`] above the ground, keeps [`CLEARANCE`] from every tree's sphere. The
/// rings reach past the forest's edge, so a forest too dense for a clear spot inside is seen
/// from its edge. It looks along the heading (of eight) that sees the most trees within
/// 80 m, at a point 3 m above the ground 60 m away.
pub fn inside(forest: &Forest, trees: &Clearances) -> (Vec3, Vec3) {
    let mut near: Vec<Vec3> = forest
        .instances
        .iter()
        .map(|i| Vec3::from_array(i.position))
        .collect();
    near.sort_by(|a, b| a.with_y(0.0).length().total_cmp(&b.with_y(0.0).length()));
    near.truncate(500);
    let flat = |a: Vec3, b: Vec3| (a - b).with_y(0.0).length();
    let Some(&c) = near
        .iter()
        .enumerate()
        .max_by_key(|&(k, &p)| {
            let n = near.iter().filter(|&&q| flat(p, q) < 15.0).count();
            // The most neighbours; the nearest the centre among equals.
            (n, std::cmp::Reverse(k))
        })
        .map(|(_, p)| p)
    else {
        return (
            trees.ground(3.0, 6.0, EYE_HEIGHT),
            trees.ground(-40.0, -60.0, 3.0),
        );
    };
    // Far enough to leave every tree behind: past the farthest sphere from the clump.
    let reach = trees
        .spheres
        .iter()
        .map(|(s, r)| flat(*s, c) + r)
        .fold(0.0f32, f32::max)
        + CLEARANCE
        + RING_STEP;
    let first = Vec3::new(3.0, 0.0, 6.0).normalize();
    let rings = (reach / RING_STEP).ceil().max(2.0) as u32;
    let eye = (2..=rings)
        .flat_map(|k| {
            let r = k as f32 * RING_STEP;
            let n = ((std::f32::consts::TAU * r / SPOT_SPACING).ceil() as u32).max(16);
            (0..n).map(move |j| {
                Quat::from_rotation_y(j as f32 * std::f32::consts::TAU / n as f32) * first * r
            })
        })
        .map(|o| trees.ground(c.x + o.x, c.z + o.z, EYE_HEIGHT))
        .find(|&e| trees.clear(e))
        .unwrap_or_else(|| trees.raised(trees.ground(c.x, c.z, EYE_HEIGHT)));
    let seen = |h: f32| {
        let d = Vec3::new(h.sin(), 0.0, -h.cos());
        near.iter()
            .filter(|&&q| {
                let v = (q - eye).with_y(0.0);
                let l = v.length();
                l > 1.0 && l < 80.0 && v.dot(d) > l * 0.8
            })
            .count()
    };
    // Headings from north-west round through north; the first of the most trees wins.
    let mut heading = -std::f32::consts::FRAC_PI_4;
    let mut best = seen(heading);
    for k in 1..8 {
        let h = -std::f32::consts::FRAC_PI_4 + k as f32 * std::f32::consts::FRAC_PI_4;
        let n = seen(h);
        if n > best {
            (heading, best) = (h, n);
        }
    }
    let d = Vec3::new(heading.sin(), 0.0, -heading.cos()) * 60.0;
    (eye, trees.ground(eye.x + d.x, eye.z + d.z, 3.0))
}

/// High above the trees' extent (the terrain may reach much farther), above the highest
/// ground, looking down across them.
fn birds_eye(forest: &Forest) -> (Vec3, Vec3) {
    let r = forest
        .instances
        .iter()
        .map(|i| Vec3::from_array(i.position).with_y(0.0).length())
        .fold(10.0, f32::max);
    let (_, top) = forest
        .terrain
        .as_ref()
        .map_or((0.0, 0.0), |t| t.height_range());
    (
        Vec3::new(0.0, top + r * 0.35, r * 0.55),
        Vec3::new(0.0, 0.0, -r * 0.1),
    )
}

/// On a lookout 30 m above the highest ground within the trees' square (above the canopy of
/// the trees around), looking at the lowest ground 50 to 600 m away; on flat ground, 40 m up
/// at the southern edge looking across.
fn hill(forest: &Forest) -> (Vec3, Vec3) {
    let half = forest
        .instances
        .iter()
        .map(|i| i.position[0].abs().max(i.position[2].abs()))
        .fold(10.0f32, f32::max);
    let Some(t) = &forest.terrain else {
        return (Vec3::new(0.0, 40.0, half), Vec3::new(0.0, 0.0, -half * 0.2));
    };
    let at = |k: usize| {
        let (i, j) = (k % t.size[0] as usize, k / t.size[0] as usize);
        Vec3::new(
            t.origin[0] + i as f32 * t.spacing,
            t.heights[k],
            t.origin[1] + j as f32 * t.spacing,
        )
    };
    let within = |p: Vec3, c: Vec3, r: f32| {
        p.x.abs() <= half && p.z.abs() <= half && (p - c).with_y(0.0).length() <= r
    };
    let all = || (0..t.heights.len()).map(at);
    let top = all()
        .filter(|p| within(*p, Vec3::ZERO, f32::INFINITY))
        .max_by(|a, b| a.y.total_cmp(&b.y))
        .unwrap_or(Vec3::ZERO);
    let low = all()
        .filter(|p| within(*p, top, 600.0) && (*p - top).with_y(0.0).length() > 50.0)
        .min_by(|a, b| a.y.total_cmp(&b.y))
        .unwrap_or(Vec3::new(0.0, 0.0, -half));
    (top + Vec3::Y * 30.0, low)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::{GenerateParams, generate};
    use crate::terrain::{Terrain, TerrainParams};
    use proptest::prelude::*;

    /// Two species of real size: a broad crown (14 m tall) and a tall narrow one (24 m).
    fn shapes() -> Vec<TreeShape> {
        vec![
            TreeShape {
                center: Vec3::new(0.3, 7.0, -0.2),
                radius: 7.5,
            },
            TreeShape {
                center: Vec3::new(0.0, 12.0, 0.0),
                radius: 12.5,
            },
        ]
    }

    fn forest(seed: u64, trees: u32, area_per_tree: f32, hills: bool) -> Forest {
        let side = (trees as f32 * area_per_tree).sqrt();
        let terrain = hills.then(|| {
            Terrain::generate(&TerrainParams {
                half_extent: side.max(200.0),
                relief: 60.0,
                hill_size: (side / 4.0).max(150.0),
                fade: 0.5,
                seed,
                ..TerrainParams::default()
            })
            .unwrap()
        });
        generate(&GenerateParams {
            trees,
            species: vec!["a.atlas".into(), "b.atlas".into()],
            area_per_tree,
            seed,
            terrain,
            ..GenerateParams::default()
        })
        .unwrap()
    }

    /// Every tree's distance from `p`, by brute force.
    fn nearest(f: &Forest, p: Vec3) -> f32 {
        (0..f.instances.len())
            .filter_map(|i| world_sphere(f, &shapes(), i))
            .map(|(c, r)| c.distance(p) - r)
            .fold(f32::INFINITY, f32::min)
    }

    #[test]
    fn the_grid_finds_the_nearest_tree_within_the_clearance() {
        let f = forest(3, 400, 20.0, true);
        let s = shapes();
        let trees = Clearances::new(&f, &s);
        let mut rng = crate::generate::SplitMix64(9);
        let mut r = |lo: f32, hi: f32| lo + (hi - lo) * rng.next_f32();
        let mut near = 0;
        for _ in 0..2000 {
            let (x, z) = (r(-60.0, 60.0), r(-60.0, 60.0));
            let p = Vec3::new(x, f.ground_height(x, z) + r(0.0, 30.0), z);
            let (grid, brute) = (trees.distance(p), nearest(&f, p));
            if brute < CLEARANCE {
                near += 1;
                assert!((grid - brute).abs() < 1e-4, "{p}: {grid} against {brute}");
            } else {
                assert!(grid >= CLEARANCE, "{p}: {grid} against {brute}");
            }
            assert_eq!(trees.clear(p), brute >= CLEARANCE, "{p}");
        }
        // Both sides of the bound were met.
        assert!(near > 100 && near < 1900, "{near}");
    }

    /// The views' eyes keep the clearance from every tree and the standing one stands at eye
    /// height on the ground, on flat ground, hills and in a dense forest.
    fn check_views(f: &Forest) -> Result<(), TestCaseError> {
        let s = shapes();
        let trees = Clearances::new(f, &s);
        for name in NAMES {
            let (eye, target) = named(name, f, &trees).unwrap();
            prop_assert!(
                eye.is_finite() && target.is_finite(),
                "{name}: {eye} {target}"
            );
            prop_assert!((target - eye).length() > 1.0, "{name}: {eye} {target}");
            let d = nearest(f, eye);
            prop_assert!(d >= CLEARANCE, "{name}: {eye} is {d} m from a tree");
        }
        let (eye, _) = start(f, &trees);
        prop_assert_eq!(start(f, &trees), named("inside", f, &trees).unwrap());
        let ground = f.ground_height(eye.x, eye.z);
        prop_assert!(
            (eye.y - ground - EYE_HEIGHT).abs() < 1e-3,
            "{eye} over {ground}"
        );
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(6))]
        #[test]
        fn views_keep_clear_of_every_tree_on_flat_ground(seed in 0u64..1000) {
            check_views(&forest(seed, 1500, 60.0, false))?;
        }

        #[test]
        fn views_keep_clear_of_every_tree_on_hills(seed in 0u64..1000) {
            check_views(&forest(seed, 1500, 60.0, true))?;
        }

        #[test]
        fn views_keep_clear_of_every_tree_in_a_dense_forest(seed in 0u64..1000) {
            check_views(&forest(seed, 1500, 6.0, seed % 2 == 0))?;
        }
    }

    #[test]
    fn the_inside_view_stands_among_the_trees_where_there_is_room() {
        // At the demo's density a clear spot is found inside the trees' square.
        for seed in 0..4 {
            let f = forest(seed, 1500, 60.0, seed % 2 == 1);
            let s = shapes();
            let (eye, _) = inside(&f, &Clearances::new(&f, &s));
            let half = f
                .instances
                .iter()
                .map(|i| i.position[0].abs().max(i.position[2].abs()))
                .fold(0.0f32, f32::max);
            // Inside the square, not at its edge, with trees around it.
            assert!(
                eye.x.abs() < half * 0.8 && eye.z.abs() < half * 0.8,
                "{eye}, half {half}"
            );
            let around = f
                .instances
                .iter()
                .filter(|i| {
                    Vec3::from_array(i.position)
                        .with_y(0.0)
                        .distance(eye.with_y(0.0))
                        < 30.0
                })
                .count();
            assert!(around >= 5, "{around} trees within 30 m of {eye}");
        }
    }

    #[test]
    fn a_forest_without_trees_or_shapes_still_has_views() {
        let f = Forest::new(vec!["a.atlas".into()], Vec::new(), 4);
        let trees = Clearances::new(&f, &[]);
        for name in NAMES {
            let (e, t) = named(name, &f, &trees).unwrap();
            assert!(e.is_finite() && t.is_finite() && e != t);
        }
        assert_eq!(named("nowhere", &f, &trees), None);
    }
}
