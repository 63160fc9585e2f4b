//! Forest generation: trees in natural clumps, after "Seeing the Wood for the Trees" (2011).
//!
//! Candidate points are drawn uniformly over a square; each is kept with probability given by
//! an exponential turbulence map `t(p) = Σ_o |n(p·2^o/λ)|/2^o` (value noise `n ∈ [−1, 1]`,
//! 4 octaves, normalised to `[0,1]`), after `t` is raised to the power 3: low values leave gaps
//! between clumps, high values fill them, with organic, vein-like edges. Species come from a
//! second, coarser noise so that each species also grows in patches. Deterministic per seed.
//!
//! On a terrain ([`GenerateParams::terrain`]) every tree stands at the ground's height, and two
//! more rules thin the candidates ([`GroundRules`]): steep slopes carry no trees, nothing grows
//! above the treeline, and each species keeps to its altitude band
//! ([`species_altitude`]: pines on the hilltops, oaks and ashes in the valleys).

use forest_format::forest::{Forest, Instance};
use forest_format::terrain::Terrain;

pub use forest_format::noise::{SplitMix64, turbulence, value_noise};

/// Parameters of [`generate`].
#[derive(Clone, Debug, PartialEq)]
pub struct GenerateParams {
    /// Number of trees (≥ 1).
    pub trees: u32,
    /// Species names (atlas paths); at least one.
    pub species: Vec<String>,
    /// Mean ground area per tree over the whole square, m² (sets the square's side).
    pub area_per_tree: f32,
    /// Clump feature size λ in metres.
    pub clump_size: f32,
    /// Uniform scale range.
    pub scale: (f32, f32),
    /// Uniform scale range per species, in species order, instead of `scale` (empty: `scale`
    /// for every species). `forest scene` sets it from each species' height range
    /// ([`species_height`]) and its model's height.
    pub species_scale: Vec<(f32, f32)>,
    /// How far each species' foot reaches from its axis at scale 1, in species order
    /// ([`forest_format::model::footprint_radius`], metres; empty: 0 for every species). On a terrain
    /// a tree is lowered to the ground's lowest point under its foot scaled by its own scale
    /// ([`Terrain::lowest_under`]), so that its trunk's downhill side does not float.
    pub footprint: Vec<f32>,
    /// Random seed.
    pub seed: u64,
    /// Presort directions.
    pub presort_directions: u32,
    /// The ground: trees stand on it and follow [`Self::ground`]'s rules; the forest's square
    /// must lie on it. `None`: flat ground at y = 0.
    pub terrain: Option<Terrain>,
    /// Where trees grow on a terrain.
    pub ground: GroundRules,
}

/// Where trees grow on a terrain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroundRules {
    /// Steepest ground that carries trees, degrees; they thin out over the 10° below it.
    pub max_slope_deg: f32,
    /// Treeline, as a fraction of the way from the terrain's lowest to its highest sample;
    /// trees thin out over the tenth below it.
    pub treeline: f32,
    /// Width of a species' altitude band (same fraction): a tree of a species preferring
    /// altitude `a₀` is kept at altitude `a` with probability `exp(−((a − a₀)/width)²)`.
    pub band: f32,
}

impl Default for GroundRules {
    fn default() -> Self {
        Self {
            max_slope_deg: 35.0,
            treeline: 0.92,
            band: 0.45,
        }
    }
}

/// Preferred altitude of a species (fraction of the terrain's height range, 0 = valley floor)
/// by name: ash 0.2, oak 0.3, bush 0.35, aspen 0.55, pine 0.8; 0.5 for any other name.
pub fn species_altitude(name: &str) -> f32 {
    let stem = std::path::Path::new(name)
        .file_stem()
        .map(|s| s.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match stem.as_str() {
        "ash" => 0.2,
        "oak" => 0.3,
        "bush" => 0.35,
        "aspen" => 0.55,
        "pine" => 0.8,
        _ => 0.5,
    }
}

impl Default for GenerateParams {
    fn default() -> Self {
        Self {
            trees: 1000,
            species: Vec::new(),
            area_per_tree: 30.0,
            clump_size: 60.0,
            scale: (0.8, 1.25),
            species_scale: Vec::new(),
            footprint: Vec::new(),
            seed: 1,
            presort_directions: forest_format::forest::DEFAULT_PRESORT_DIRECTIONS,
            terrain: None,
            ground: GroundRules::default(),
        }
    }
}

/// Farthest a tree's foot may reach from its axis at its largest scale (metres): wider than
/// any tree's roots, small enough that planting it reads few of a terrain's samples.
pub const MAX_FOOT: f32 = 100.0;

/// Mature height ranges (metres) of common tree species, by name: what `forest scene` gives
/// the trees of a species of that name unless told otherwise (typical heights of grown trees
/// in a closed stand: oak and ash 15–25 m, Scots pine 20–35 m, aspen 12–20 m, shrubs 1–3 m).
pub const SPECIES_HEIGHTS: [(&str, f32, f32); 5] = [
    ("oak", 15.0, 25.0),
    ("ash", 15.0, 25.0),
    ("aspen", 12.0, 20.0),
    ("pine", 20.0, 35.0),
    ("bush", 1.0, 3.0),
];

/// The [`SPECIES_HEIGHTS`] range of a species name (case-insensitive), if listed.
pub fn species_height(name: &str) -> Option<(f32, f32)> {
    SPECIES_HEIGHTS
        .iter()
        .find(|(n, _, _)| n.eq_ignore_ascii_case(name))
        .map(|&(_, lo, hi)| (lo, hi))
}

/// The terrain's rules where a forest stands on one: the terrain, its rules, its lowest
/// height and height range, and each species' preferred altitude.
type Ground<'a> = (&'a Terrain, GroundRules, f32, f32, Vec<f32>);

/// Generate a forest; the error says which parameter is wrong.
pub fn generate(p: &GenerateParams) -> Result<Forest, String> {
    validate(p)?;
    let side = (p.trees as f32 * p.area_per_tree).sqrt();
    let ground = ground(p, side)?;
    let mut rng = SplitMix64(p.seed);
    let mut instances = Vec::with_capacity(p.trees as usize);
    let max_attempts = 1000u64 * u64::from(p.trees);
    let mut attempts = 0u64;
    // Candidates the clump map kept, and those of them the ground's rules then refused.
    let (mut clump_kept, mut refused_by_ground) = (0u64, 0u64);
    while instances.len() < p.trees as usize {
        attempts += 1;
        if attempts > max_attempts {
            return Err(if refused_by_ground * 10 > clump_kept * 9 {
                "the terrain's rules refuse too many places (steep slopes, ground above the \
                 treeline, altitudes far from the species' bands): raise --max-slope or \
                 --treeline, or lower the relief"
                    .into()
            } else {
                "the clump map accepts too few points; raise the clump size".into()
            });
        }
        let x = (rng.next_f32() - 0.5) * side;
        let z = (rng.next_f32() - 0.5) * side;
        let t = turbulence(x / p.clump_size, z / p.clump_size, p.seed).powi(3) * 8.0;
        if rng.next_f32() >= t.min(1.0) {
            continue;
        }
        let patch = value_noise(
            x / (p.clump_size * 3.0),
            z / (p.clump_size * 3.0),
            p.seed ^ 0xabc,
        );
        let pick = ((patch * 0.5 + 0.5) * p.species.len() as f32 + rng.next_f32() * 0.8 - 0.4)
            .floor()
            .clamp(0.0, (p.species.len() - 1) as f32) as u32;
        clump_kept += 1;
        let mut y = 0.0;
        if let Some((t, g, low, range, prefs)) = &ground {
            y = t.height(x, z);
            let slope = t.slope(x, z).atan().to_degrees();
            let mut keep = ((g.max_slope_deg - slope) / 10.0).clamp(0.0, 1.0);
            // Ground within a metre of level has no altitudes to speak of: no treeline, no
            // bands (every altitude would be 0, and the bands would thin some species only).
            if *range >= 1.0 {
                let alt = (y - low) / range;
                keep *= ((g.treeline - alt) / 0.1).clamp(0.0, 1.0)
                    * (-((alt - prefs[pick as usize]) / g.band).powi(2)).exp();
            }
            // (No draw where every rule keeps the place: level ground generates the same
            // forest as no terrain, raised to its height.)
            if keep < 1.0 && rng.next_f32() >= keep {
                refused_by_ground += 1;
                continue;
            }
        }
        let (lo, hi) = p
            .species_scale
            .get(pick as usize)
            .copied()
            .unwrap_or(p.scale);
        let rotation = rng.next_f32() * std::f32::consts::TAU;
        let scale = lo + (hi - lo) * rng.next_f32();
        if let (Some((t, ..)), Some(r)) = (&ground, p.footprint.get(pick as usize)) {
            y = t.lowest_under(x, z, r * scale);
        }
        instances.push(Instance {
            position: [x, y, z],
            rotation,
            scale,
            species: pick,
        });
    }
    let forest = Forest::new(p.species.clone(), instances, p.presort_directions);
    Ok(match &p.terrain {
        Some(t) => forest.with_terrain(t.clone()),
        None => forest,
    })
}

/// Refuse parameters out of range, naming the parameter.
fn validate(p: &GenerateParams) -> Result<(), String> {
    if p.trees == 0 || p.trees as usize > forest_format::forest::MAX_INSTANCES {
        return Err(format!(
            "trees = {}: must be 1 to {}",
            p.trees,
            forest_format::forest::MAX_INSTANCES
        ));
    }
    if p.species.is_empty() {
        return Err("at least one species (atlas) is needed".into());
    }
    if !(p.area_per_tree.is_finite() && p.area_per_tree > 0.0) {
        return Err(format!(
            "area per tree = {}: must be positive",
            p.area_per_tree
        ));
    }
    let side = (f64::from(p.trees) * f64::from(p.area_per_tree)).sqrt();
    if side > 2.0 * f64::from(forest_format::forest::MAX_COORDINATE) {
        return Err(format!(
            "area per tree = {}: {} trees would cover a square {side:.3e} m across, more than \
             the {:.0e} m a forest may span",
            p.area_per_tree,
            p.trees,
            2.0 * forest_format::forest::MAX_COORDINATE
        ));
    }
    if !(p.clump_size.is_finite() && p.clump_size > 0.0) {
        return Err(format!("clump size = {}: must be positive", p.clump_size));
    }
    use forest_format::forest::{MAX_SCALE, MIN_SCALE};
    let good = |(lo, hi): (f32, f32)| lo >= MIN_SCALE && hi >= lo && hi <= MAX_SCALE;
    if !good(p.scale) {
        return Err(format!(
            "scale range {:?}: must be {MIN_SCALE:e} ≤ min ≤ max ≤ {MAX_SCALE:e}",
            p.scale
        ));
    }
    if !p.species_scale.is_empty() && p.species_scale.len() != p.species.len() {
        return Err(format!(
            "{} per-species scale ranges for {} species",
            p.species_scale.len(),
            p.species.len()
        ));
    }
    if let Some((i, r)) = p.species_scale.iter().enumerate().find(|(_, r)| !good(**r)) {
        return Err(format!(
            "scale range {r:?} of species {}: must be {MIN_SCALE:e} ≤ min ≤ max ≤ {MAX_SCALE:e}",
            p.species[i]
        ));
    }
    if !p.footprint.is_empty() && p.footprint.len() != p.species.len() {
        return Err(format!(
            "{} footprint radii for {} species",
            p.footprint.len(),
            p.species.len()
        ));
    }
    for (i, &r) in p.footprint.iter().enumerate() {
        let largest = p.species_scale.get(i).map_or(p.scale.1, |s| s.1);
        if !(r.is_finite() && r >= 0.0 && r * largest <= MAX_FOOT) {
            return Err(format!(
                "species {}: its foot reaches {r} m from its axis, {} m at its largest scale \
                 ({largest}); a tree's foot must reach 0 to {MAX_FOOT} m",
                p.species[i],
                r * largest
            ));
        }
    }
    if !(1..=256).contains(&p.presort_directions) {
        return Err(format!(
            "presort directions = {}: must be 1 to 256",
            p.presort_directions
        ));
    }
    Ok(())
}

/// The ground the trees of a `side`-metre square stand on, with its rules checked (None
/// without terrain).
fn ground(p: &GenerateParams, side: f32) -> Result<Option<Ground<'_>>, String> {
    Ok(match &p.terrain {
        Some(t) => {
            t.check().map_err(|e| format!("terrain: {e}"))?;
            let half = side / 2.0;
            if !(t.contains(-half, -half) && t.contains(half, half)) {
                let ([x0, z0], [x1, z1]) = t.bounds();
                return Err(format!(
                    "the forest's square, {side:.0} m across and centred on the origin, does \
                     not lie on the terrain (x {x0:.0} to {x1:.0} m, z {z0:.0} to {z1:.0} m): \
                     fewer trees, a smaller area per tree, or a larger terrain spacing"
                ));
            }
            let g = p.ground;
            if !(g.max_slope_deg > 0.0 && g.max_slope_deg <= 90.0) {
                return Err(format!(
                    "steepest slope {}°: must be above 0 and at most 90",
                    g.max_slope_deg
                ));
            }
            if !(g.treeline > 0.0 && g.treeline <= 1.0 && g.band > 0.0 && g.band.is_finite()) {
                return Err(format!(
                    "treeline {} and altitude band {}: the treeline must be above 0 and at \
                     most 1, the band positive",
                    g.treeline, g.band
                ));
            }
            let (lo, hi) = t.height_range();
            let prefs: Vec<f32> = p.species.iter().map(|s| species_altitude(s)).collect();
            Some((t, g, lo, hi - lo, prefs))
        }
        None => None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(trees: u32, seed: u64) -> GenerateParams {
        GenerateParams {
            trees,
            species: vec!["a".into(), "b".into(), "c".into()],
            seed,
            ..GenerateParams::default()
        }
    }

    #[test]
    fn generation_is_deterministic_per_seed() {
        let a = generate(&params(500, 7)).unwrap();
        assert_eq!(a, generate(&params(500, 7)).unwrap());
        assert_ne!(a.instances, generate(&params(500, 8)).unwrap().instances);
        assert_eq!(a.instances.len(), 500);
        assert!(a.instances.iter().all(|i| i.species < 3));
        let used: std::collections::HashSet<u32> = a.instances.iter().map(|i| i.species).collect();
        assert!(used.len() >= 2, "several species: {used:?}");
    }

    #[test]
    fn trees_are_clumped() {
        // Count trees per 20 m cell: clumps make the variance well above Poisson's (= mean).
        let f = generate(&params(4000, 3)).unwrap();
        let side = (4000.0f32 * 30.0).sqrt();
        let cells = (side / 20.0).ceil() as usize;
        let mut counts = vec![0f64; cells * cells];
        for i in &f.instances {
            let cx = (((i.position[0] / side) + 0.5) * cells as f32) as usize;
            let cz = (((i.position[2] / side) + 0.5) * cells as f32) as usize;
            counts[cz.min(cells - 1) * cells + cx.min(cells - 1)] += 1.0;
        }
        let mean = counts.iter().sum::<f64>() / counts.len() as f64;
        let var = counts.iter().map(|c| (c - mean).powi(2)).sum::<f64>() / counts.len() as f64;
        assert!(var > 3.0 * mean, "variance {var:.1} vs mean {mean:.1}");
    }

    #[test]
    fn per_species_scales_apply_to_their_species_only() {
        let plain = generate(&params(400, 5)).unwrap();
        let mut p = params(400, 5);
        p.species_scale = vec![(3.0, 4.0), (0.5, 0.5), (1.0, 2.0)];
        let sized = generate(&p).unwrap();
        for (a, b) in plain.instances.iter().zip(&sized.instances) {
            // Same places, species and rotations: only the scales differ.
            assert_eq!(
                (a.position, a.species, a.rotation),
                (b.position, b.species, b.rotation)
            );
            let (lo, hi) = p.species_scale[b.species as usize];
            assert!(b.scale >= lo && b.scale <= hi, "{b:?}");
            // The same draw, mapped onto the species' range.
            let u = (a.scale - 0.8) / (1.25 - 0.8);
            assert!((b.scale - (lo + (hi - lo) * u)).abs() < 1e-4, "{a:?} {b:?}");
        }
        p.species_scale.pop();
        assert!(
            generate(&p)
                .unwrap_err()
                .contains("2 per-species scale ranges for 3")
        );
        p.species_scale = vec![(1.0, 2.0), (2.0, 1.0), (1.0, 1.0)];
        assert!(generate(&p).unwrap_err().contains("of species b"));
        assert_eq!(species_height("Pine"), Some((20.0, 35.0)));
        assert_eq!(species_height("baobab"), None);
    }

    #[test]
    fn feet_are_planted_on_slopes_and_nothing_else_moves() {
        use forest_format::terrain::TerrainParams;
        let terrain = Terrain::generate(&TerrainParams {
            half_extent: 300.0,
            spacing: 5.0,
            relief: 120.0,
            hill_size: 150.0,
            fade: 0.125,
            seed: 3,
        })
        .unwrap();
        let mut p = params(2000, 7);
        p.area_per_tree = 100.0;
        p.terrain = Some(terrain.clone());
        let standing = generate(&p).unwrap();
        p.footprint = vec![0.1, 0.0, 0.4];
        let planted = generate(&p).unwrap();
        assert_eq!(standing.instances.len(), planted.instances.len());
        let mut sunk = 0;
        for (a, b) in standing.instances.iter().zip(&planted.instances) {
            // The same tree, place, size and turn: only its height may change.
            assert_eq!(
                (a.position[0], a.position[2], a.species, a.rotation, a.scale),
                (b.position[0], b.position[2], b.species, b.rotation, b.scale)
            );
            let [x, y, z] = b.position;
            let r = p.footprint[b.species as usize] * b.scale;
            // No point of the foot's disk lies below the tree's base, and its base is no
            // lower than the ground's lowest point there (checked on a finer ring here).
            let (mut lowest, mut steepest) = (terrain.height(x, z), terrain.slope(x, z));
            for k in 0..1024 {
                let t = k as f32 * std::f32::consts::TAU / 1024.0;
                for f in [0.5, 1.0] {
                    let (px, pz) = (x + f * r * t.cos(), z + f * r * t.sin());
                    lowest = lowest.min(terrain.height(px, pz));
                    steepest = steepest.max(terrain.slope(px, pz));
                }
            }
            // What the 32 points between crossings may miss (Terrain::lowest_under).
            let slack = r * steepest * (1.0 - (std::f32::consts::PI / 32.0).cos()) + 1e-4;
            assert!(
                y <= lowest + slack && y >= lowest - slack,
                "{b:?}: {y} against {lowest}"
            );
            if r == 0.0 {
                assert_eq!(y, a.position[1]);
            } else if y < a.position[1] - 1e-3 {
                sunk += 1;
            }
        }
        assert!(sunk > 100, "{sunk} trees lowered");
        // Without a terrain a foot changes nothing.
        p.terrain = None;
        assert!(
            generate(&p)
                .unwrap()
                .instances
                .iter()
                .all(|i| i.position[1] == 0.0)
        );
        // Bad footprints are refused, naming the species.
        p.footprint = vec![0.1, f32::NAN, 0.4];
        assert!(generate(&p).unwrap_err().contains("species b"));
        // A foot wider than any tree's at the species' largest scale (1.25 by default).
        p.footprint = vec![0.1, 0.0, MAX_FOOT / 1.2];
        let e = generate(&p).unwrap_err();
        assert!(
            e.contains("species c") && e.contains("largest scale"),
            "{e}"
        );
        p.footprint = vec![0.1];
        assert!(generate(&p).unwrap_err().contains("footprint radii"));
    }

    #[test]
    fn trees_stand_on_the_terrain_and_keep_off_steep_ground_and_hilltops() {
        use forest_format::terrain::TerrainParams;
        let terrain = Terrain::generate(&TerrainParams {
            half_extent: 600.0,
            spacing: 10.0,
            relief: 150.0,
            hill_size: 400.0,
            fade: 0.125,
            seed: 9,
        })
        .unwrap();
        let mut p = params(3000, 4);
        p.species = vec!["x/oak.atlas".into(), "x/pine.atlas".into()];
        p.area_per_tree = 300.0;
        p.terrain = Some(terrain.clone());
        let f = generate(&p).unwrap();
        assert_eq!(f.terrain.as_ref(), Some(&terrain));
        let (lo, hi) = terrain.height_range();
        let g = GroundRules::default();
        let (mut oak, mut pine) = (Vec::new(), Vec::new());
        for i in &f.instances {
            let [x, y, z] = i.position;
            // Every base exactly on the drawn surface.
            assert_eq!(y, terrain.height(x, z), "{i:?}");
            assert!(terrain.slope(x, z).atan().to_degrees() < g.max_slope_deg);
            let alt = (y - lo) / (hi - lo);
            assert!(alt < g.treeline, "above the treeline: {alt}");
            [&mut oak, &mut pine][i.species as usize].push(alt);
        }
        let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len() as f32;
        assert!(
            mean(&pine) > mean(&oak) + 0.1,
            "pines higher up: {} against {}",
            mean(&pine),
            mean(&oak)
        );
        // The same forest without a terrain is the flat one of before.
        p.terrain = None;
        let flat = generate(&p).unwrap();
        assert!(flat.instances.iter().all(|i| i.position[1] == 0.0));
        assert!(flat.terrain.is_none());
        // Level ground keeps no bands: the same trees, species and places as without terrain.
        let level = Terrain {
            size: [3, 3],
            origin: [-600.0, -600.0],
            spacing: 600.0,
            heights: vec![5.0; 9],
        };
        p.terrain = Some(level);
        let on_level = generate(&p).unwrap();
        for (a, b) in on_level.instances.iter().zip(&flat.instances) {
            assert_eq!(
                (a.position[0], a.position[2], a.species),
                (b.position[0], b.position[2], b.species)
            );
            assert_eq!(a.position[1], 5.0);
        }
        // A wall everywhere: the ground's rules, not the clump map, are named.
        let wall = Terrain {
            size: [2, 2],
            origin: [-600.0, -600.0],
            spacing: 1200.0,
            heights: vec![0.0, 5000.0, 0.0, 5000.0],
        };
        p.terrain = Some(wall);
        let err = generate(&p).unwrap_err();
        assert!(err.contains("terrain's rules"), "{err}");
        // A square larger than the terrain is refused.
        p.terrain = Some(terrain);
        p.area_per_tree = 1000.0;
        let err = generate(&p).unwrap_err();
        assert!(err.contains("does not lie on the terrain"), "{err}");
    }

    #[test]
    fn bad_parameters_are_named() {
        assert!(generate(&params(0, 1)).unwrap_err().contains("trees = 0"));
        let mut p = params(10, 1);
        p.species.clear();
        assert!(generate(&p).unwrap_err().contains("species"));
    }
}
