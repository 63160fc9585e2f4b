//! Where a camera starts: the named views of a forest (`inside`, `hill`, `birds-eye`), which
//! `forest render`, the viewer's first frame and the Bevy example all take from here, so that
//! one placement rule serves them all.
//!
//! The rule: a view that stands in the forest keeps [`CLEARANCE`] metres from every tree's
//! trunk and crown ([`TreeShape`]: per height band, the reach from the trunk's axis of every
//! voxel of the species' opacity volume that holds leaf or wood area; the bounding sphere
//! the atlas frames where the volume is not known), so no first frame starts inside a crown or
//! against a trunk. [`Clearances`] answers "how far is the nearest tree" through a grid over
//! the trees, so a search over thousands of spots in a forest of a million trees stays cheap.

use std::collections::HashMap;

use glam::{Quat, Vec3};

use forest_format::atlas::AtlasManifest;
use forest_format::forest::{Forest, Instance};
use forest_format::opacity::OpacityVolume;

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

/// Part of a tree between two heights: everything of it within `y0..y1` lies within
/// `radius` of its vertical axis (the model's y axis, about which instances turn).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Band {
    /// Bottom (metres, model space).
    pub y0: f32,
    /// Top (metres, model space, ≥ `y0`).
    pub y1: f32,
    /// Reach from the axis (metres, ≥ 0).
    pub radius: f32,
}

/// A species' reach at scale 1 (model space, metres; the tree stands on y = 0 around its y
/// axis): the sphere bounding its whole model, trunk and crown, as its atlas records it,
/// and where known the bands it fills.
#[derive(Clone, Debug, PartialEq)]
pub struct TreeShape {
    /// Centre of the bounding sphere in the model's frame.
    pub center: Vec3,
    /// Radius of the bounding sphere (> 0).
    pub radius: f32,
    /// The occupied bands, bottom up, all within the bounding cube; empty where only the
    /// sphere is known (then the sphere is the tree's shape).
    pub bands: Vec<Band>,
}

impl TreeShape {
    /// The bounding sphere an atlas's manifest records, as the whole shape.
    pub fn of(manifest: &AtlasManifest) -> Self {
        Self {
            center: manifest.bounding_sphere.center,
            radius: manifest.bounding_sphere.radius,
            bands: Vec::new(),
        }
    }

    /// The shape of a species whose opacity volume is known: [`Self::of`] its manifest,
    /// [`Self::banded`] by its volume.
    pub fn with_volume(manifest: &AtlasManifest, volume: &OpacityVolume) -> Self {
        Self::of(manifest).banded(volume)
    }

    /// This shape's bands taken from `volume`, the opacity volume on the cube around its
    /// sphere: one band per voxel layer holding any leaf or wood area (a code above 0),
    /// reaching to the farthest corner of its occupied voxels. An empty volume leaves the
    /// sphere alone.
    pub fn banded(self, volume: &OpacityVolume) -> Self {
        let mut shape = Self {
            bands: Vec::new(),
            ..self
        };
        let n = volume.resolution as usize;
        if n == 0 || volume.codes.len() != n * n * n || volume.max_depth <= 0.0 {
            return shape;
        }
        let h = 2.0 * shape.radius / n as f32;
        let lo = shape.center - Vec3::splat(shape.radius);
        for j in 0..n {
            let mut reach = None;
            for k in 0..n {
                for i in 0..n {
                    if volume.codes[i + n * (j + n * k)] == 0 {
                        continue;
                    }
                    let x = (lo.x + (i as f32 + 0.5) * h).abs() + 0.5 * h;
                    let z = (lo.z + (k as f32 + 0.5) * h).abs() + 0.5 * h;
                    let r = x.hypot(z);
                    reach = Some(reach.map_or(r, |m: f32| m.max(r)));
                }
            }
            if let Some(radius) = reach {
                let y0 = lo.y + j as f32 * h;
                shape.bands.push(Band {
                    y0,
                    y1: y0 + h,
                    radius,
                });
            }
        }
        shape
    }

    /// Radius (metres, model space) of a sphere about [`Self::center`] holding every band.
    fn bound(&self) -> f32 {
        let axis = self.center.with_y(0.0).length();
        self.bands
            .iter()
            .map(|b| {
                let up = (b.y0 - self.center.y)
                    .abs()
                    .max((b.y1 - self.center.y).abs());
                (axis + b.radius).hypot(up)
            })
            .fold(self.radius, f32::max)
    }

    /// Distance (metres, model space) from `q` to the shape: to the union of its bands'
    /// cylinders, or to its sphere (negative inside) where it has none.
    fn distance(&self, q: Vec3) -> f32 {
        if self.bands.is_empty() {
            return q.distance(self.center) - self.radius;
        }
        let across = q.with_y(0.0).length();
        self.bands
            .iter()
            .map(|b| {
                let dh = (across - b.radius).max(0.0);
                let dv = (b.y0 - q.y).max(q.y - b.y1).max(0.0);
                dh.hypot(dv)
            })
            .fold(f32::INFINITY, f32::min)
    }
}

/// One tree of the forest with a world sphere holding its whole shape.
#[derive(Clone, Copy)]
struct Placed {
    /// Its index in the forest's instances.
    index: u32,
    center: Vec3,
    bound: f32,
}

/// Distance (metres) from world point `p` to the shape of tree `t`, of species shape `s`.
fn tree_distance(s: &TreeShape, t: &Instance, p: Vec3) -> f32 {
    let q = Quat::from_rotation_y(-t.rotation) * (p - Vec3::from_array(t.position));
    s.distance(q / t.scale) * t.scale
}

/// The trees' shapes, bucketed on a square grid by the spheres holding them, for distance
/// queries.
pub struct Clearances<'a> {
    forest: &'a Forest,
    shapes: &'a [TreeShape],
    trees: Vec<Placed>,
    /// Grid cell side (metres): the largest holding sphere's radius plus [`CLEARANCE`].
    cell: f32,
    cells: HashMap<(i64, i64), Vec<u32>>,
}

impl<'a> Clearances<'a> {
    /// The trees of `forest`, each species shaped by `shapes` (in the forest's species order;
    /// a tree whose species has no shape, or whose sphere is not finite, is left out).
    pub fn new(forest: &'a Forest, shapes: &'a [TreeShape]) -> Self {
        let bounds: Vec<f32> = shapes.iter().map(TreeShape::bound).collect();
        let trees: Vec<Placed> = (forest.instances.iter().enumerate())
            .filter_map(|(i, t)| {
                let s = shapes.get(t.species as usize)?;
                let center = Vec3::from_array(t.position)
                    + Quat::from_rotation_y(t.rotation) * (s.center * t.scale);
                let bound = bounds[t.species as usize] * t.scale;
                (center.is_finite() && bound.is_finite() && t.scale > 0.0).then_some(Placed {
                    index: i as u32,
                    center,
                    bound,
                })
            })
            .collect();
        let cell = trees.iter().map(|t| t.bound).fold(0.0f32, f32::max) + CLEARANCE;
        let mut cells: HashMap<(i64, i64), Vec<u32>> = HashMap::new();
        for (k, t) in trees.iter().enumerate() {
            cells
                .entry(Self::key(cell, t.center))
                .or_default()
                .push(k as u32);
        }
        Self {
            forest,
            shapes,
            trees,
            cell,
            cells,
        }
    }

    fn key(cell: f32, p: Vec3) -> (i64, i64) {
        ((p.x / cell).floor() as i64, (p.z / cell).floor() as i64)
    }

    /// Distance (metres) from `p` to the nearest tree's shape (0 or negative inside one).
    /// Exact where it is below [`CLEARANCE`]; elsewhere some value of at least that (a tree
    /// outside the 3×3 grid cells around `p`, or whose holding sphere keeps that far, lies
    /// farther). Infinite without a tree near.
    pub fn distance(&self, p: Vec3) -> f32 {
        let (x, z) = Self::key(self.cell, p);
        let mut d = f32::INFINITY;
        for dx in -1..=1 {
            for dz in -1..=1 {
                for &k in self.cells.get(&(x + dx, z + dz)).into_iter().flatten() {
                    let t = &self.trees[k as usize];
                    let far = t.center.distance(p) - t.bound;
                    d = d.min(if far >= CLEARANCE {
                        far
                    } else {
                        let tree = &self.forest.instances[t.index as usize];
                        tree_distance(&self.shapes[tree.species as usize], tree, p)
                    });
                }
            }
        }
        d
    }

    /// Whether `p` keeps [`CLEARANCE`] from every tree's shape.
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
        .trees
        .iter()
        .map(|t| flat(t.center, c) + t.bound)
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
    use forest_format::terrain::{Terrain, TerrainParams};
    use proptest::prelude::*;

    /// Two species of real size as spheres alone: a broad crown (14 m tall) and a tall
    /// narrow one (24 m).
    fn shapes() -> Vec<TreeShape> {
        vec![
            TreeShape {
                center: Vec3::new(0.3, 7.0, -0.2),
                radius: 7.5,
                bands: Vec::new(),
            },
            TreeShape {
                center: Vec3::new(0.0, 12.0, 0.0),
                radius: 12.5,
                bands: Vec::new(),
            },
        ]
    }

    /// The same two with their trunks and crowns as bands.
    fn banded_shapes() -> Vec<TreeShape> {
        let band = |y0, y1, radius| Band { y0, y1, radius };
        let mut s = shapes();
        s[0].bands = vec![
            band(0.0, 3.0, 0.3),
            band(3.0, 6.0, 4.0),
            band(6.0, 11.0, 6.5),
            band(11.0, 14.0, 3.0),
        ];
        s[1].bands = vec![
            band(0.0, 8.0, 0.4),
            band(8.0, 16.0, 4.0),
            band(16.0, 24.0, 2.5),
        ];
        s
    }

    fn both() -> [Vec<TreeShape>; 2] {
        [shapes(), banded_shapes()]
    }

    /// A seeded forest, on hills of 60 m relief when `hills` (halved until the generator's
    /// slope rules accept the trees: a dense forest covers little ground; flat ground when no
    /// relief down to 3.75 m does).
    fn forest(seed: u64, trees: u32, area_per_tree: f32, hills: bool) -> Forest {
        let side = (trees as f32 * area_per_tree).sqrt();
        let make = |relief: Option<f32>| {
            let terrain = relief.map(|relief| {
                Terrain::generate(&TerrainParams {
                    half_extent: side.max(200.0),
                    relief,
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
        };
        if !hills {
            return make(None).unwrap();
        }
        [60.0, 30.0, 15.0, 7.5, 3.75]
            .into_iter()
            .find_map(|relief| make(Some(relief)).ok())
            // A seed whose crowded trees fit no hills of these reliefs stands on flat ground.
            .unwrap_or_else(|| make(None).unwrap())
    }

    /// Every tree's distance from `p`, by brute force.
    fn nearest_to(f: &Forest, shapes: &[TreeShape], p: Vec3) -> f32 {
        f.instances
            .iter()
            .map(|t| tree_distance(&shapes[t.species as usize], t, p))
            .fold(f32::INFINITY, f32::min)
    }

    #[test]
    fn the_grid_finds_the_nearest_tree_within_the_clearance() {
        for s in both() {
            grid_against_brute_force(&s);
        }
    }

    fn grid_against_brute_force(s: &[TreeShape]) {
        let f = forest(3, 400, 20.0, true);
        let trees = Clearances::new(&f, s);
        let mut rng = crate::generate::SplitMix64(9);
        let mut r = |lo: f32, hi: f32| lo + (hi - lo) * rng.next_f32();
        let mut near = 0;
        for _ in 0..2000 {
            let (x, z) = (r(-60.0, 60.0), r(-60.0, 60.0));
            let p = Vec3::new(x, f.ground_height(x, z) + r(0.0, 30.0), z);
            let (grid, brute) = (trees.distance(p), nearest_to(&f, s, p));
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
        for s in both() {
            check_views_of(f, &s)?;
        }
        Ok(())
    }

    fn check_views_of(f: &Forest, s: &[TreeShape]) -> Result<(), TestCaseError> {
        let trees = Clearances::new(f, s);
        for name in NAMES {
            let (eye, target) = named(name, f, &trees).unwrap();
            prop_assert!(
                eye.is_finite() && target.is_finite(),
                "{name}: {eye} {target}"
            );
            prop_assert!((target - eye).length() > 1.0, "{name}: {eye} {target}");
            let d = nearest_to(f, s, eye);
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
        for (seed, s) in (0..4).zip(both().into_iter().cycle()) {
            let f = forest(seed, 1500, 60.0, seed % 2 == 1);
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

    /// A volume holding a trunk (the four central columns of voxels, lower half) and a ball
    /// of crown: the bands hold every occupied voxel, the trunk's band reaches to its
    /// voxels' far corners (√2 voxel sides), and a point beside the trunk under the crown
    /// is as far from the shape as from that band.
    #[test]
    fn bands_hold_the_volume_and_measure_the_trunk() {
        let n = 32usize;
        let (center, radius) = (Vec3::new(0.0, 5.0, 0.0), 5.0);
        let h = 2.0 * radius / n as f32;
        let at = |i: usize, j: usize, k: usize| {
            center - Vec3::splat(radius) + (Vec3::new(i as f32, j as f32, k as f32) + 0.5) * h
        };
        let crown = Vec3::new(0.0, 7.0, 0.0);
        let mut depths = vec![0.0f32; n * n * n];
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let trunk = (15..=16).contains(&i) && (15..=16).contains(&k) && j < n / 2;
                    let leaf = j >= n / 2 && at(i, j, k).distance(crown) < 4.0;
                    if trunk || leaf {
                        depths[i + n * (j + n * k)] = 1.0;
                    }
                }
            }
        }
        let volume = OpacityVolume::from_depths(n as u32, &depths);
        let shape = TreeShape {
            center,
            radius,
            bands: Vec::new(),
        }
        .banded(&volume);
        assert_eq!(shape.bands.len(), n);
        assert!(
            (shape.bands[0].radius - h * 2f32.sqrt()).abs() < 1e-5,
            "{:?}",
            shape.bands[0]
        );
        for (k, d) in depths.iter().enumerate() {
            if *d > 0.0 {
                let p = at(k % n, k / n % n, k / (n * n));
                assert_eq!(shape.distance(p), 0.0, "{p}");
            }
        }
        let beside = Vec3::new(2.0, 1.7, 0.0);
        let want = 2.0 - h * 2f32.sqrt();
        assert!(
            (shape.distance(beside) - want).abs() < 1e-5,
            "{}",
            shape.distance(beside)
        );
        // The sphere alone puts that point inside the tree.
        assert!(
            TreeShape {
                bands: Vec::new(),
                ..shape.clone()
            }
            .distance(beside)
                < 0.0
        );
        // An empty volume leaves the sphere alone.
        assert!(shape.banded(&OpacityVolume::empty(8)).bands.is_empty());
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
