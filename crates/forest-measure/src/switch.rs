//! The hybrid's switch of one model, measured at bake: where its quad stream becomes as
//! accurate as its own triangles, within a tolerance.
//!
//! One tree (scale 1, unrotated) is seen from seeded random cameras at a ladder of distances
//! from its crown's centre (in crown radii; azimuth uniform, elevation −20° to 40°, eyes kept
//! 0.3 m above the ground, looking at the centre; 400×300, 60°, transparent background).
//! Each view is drawn as full geometry at 1×, as the quad stream at ε 2 and as the
//! discrete-LOD baseline's mesh LODs 1 and 2, and each is compared (mean FLIP) with the 4×4
//! supersampled reference ([`MeshMethod::Reference`]). The crossover is where the stream's
//! mean error first reaches `1 + tolerance` times the geometry's (linear between the two
//! distances around it), found by bisection over the ladder (4 or 5 of its 9 rungs: the
//! excess falls with distance); it is recorded as the width the finest quads project to
//! there ([`HybridSwitch::finest_quad_pixels`]), which carries over to any view and tree
//! size. The LODs' errors say whether they could draw the hybrid's near trees instead of the
//! full model: from where each is as accurate as the full model (within the same tolerance),
//! up to the switch, the hybrid draws its near trees in it ([`lod_from`],
//! [`HybridSwitch::lod_from`]; on the bundled species they never come within 1.7× of it).

use anyhow::Result;
use forest_baselines::geometry::{GeometryRenderer, GeometrySpecies, MeshMethod, PreparedGeometry};
use forest_baselines::hybrid::auto_radii;
use forest_baselines::methods::{ForestRenderer, Method};
use forest_format::atlas::HybridSwitch;
use forest_format::forest::{Forest, Instance};
use forest_format::model::PreparedModel;
use forest_format::noise::SplitMix64;
use forest_render::options::{Background, RendererOptions};
use forest_render::scene::SpeciesData;
use forest_render::target::{TARGET_FORMAT, Target};
use forest_render::{Camera, GpuContext, GpuScene, QuadStream};
use glam::Vec3;

/// Distances of the ladder, crown radii from the crown's centre.
pub const DISTANCES: [f32; 9] = [1.25, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 5.0, 6.0];
/// Seeded cameras per distance (the same directions at every distance).
pub const CAMERAS: u32 = 6;
/// Viewport of the measurement (pixels).
pub const VIEWPORT: (u32, u32) = (400, 300);
/// Vertical field of view (degrees).
pub const FOV_Y_DEG: f32 = 60.0;
/// The quad stream's ε (pixels).
pub const EPSILON: f32 = 2.0;
/// Supersampling of the reference, per axis.
const REFERENCE_SS: u32 = 4;
/// Seed of the camera directions.
const SEED: u64 = 0x5717_c400;

/// Distances of the discrete-LOD baseline that draw every tree nearer than 10⁶ m in mesh
/// LOD `lod` (1 or 2).
fn whole_lod(lod: usize) -> forest_baselines::geometry::Lods {
    let distances = if lod == 1 {
        [1e-6, 1e6, 2e6]
    } else {
        [1e-6, 2e-6, 1e6]
    };
    forest_baselines::geometry::Lods { distances }
}

/// The mean FLIP of both forms at one distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rung {
    /// Crown radii from the crown's centre.
    pub radii: f32,
    /// Full geometry at 1×.
    pub geometry: f32,
    /// The quad stream at [`EPSILON`].
    pub quads: f32,
    /// The discrete-LOD baseline's mesh LODs 1 and 2 at 1× (the whole tree in that LOD).
    pub lods: [f32; 2],
}

impl Rung {
    /// The stream's error beyond what `tolerance` allows it over the triangles':
    /// `quads − (1 + tolerance) · geometry`; the switch lies where it reaches 0.
    pub fn excess(&self, tolerance: f32) -> f32 {
        self.quads - (1.0 + tolerance) * self.geometry
    }

    /// Mesh LOD `k`'s (1 or 2) error as a multiple of the full model's.
    pub fn lod_ratio(&self, k: usize) -> f32 {
        self.lods[k - 1] / self.geometry.max(f32::MIN_POSITIVE)
    }
}

/// The default [`HybridSwitch::tolerance`]: none, the stream must be as accurate as the
/// triangles. Measured in the real-size walkthrough (3 000 trees, 6 seeded eye-height
/// cameras, 400×300): a 25 % tolerance moves the bundled species' switches from 2.1–6 to
/// 1.3–3.5 crown radii and the hybrid to the cheap end of the front (ε 16: 0.30× the time,
/// 0.18× the vertices, 1.6× the fragments, FLIP 0.0577 → 0.0664), but at the accurate end
/// it loses (ε 1–4: FLIP +10 %, no faster), so it is a choice, not the default.
pub const DEFAULT_TOLERANCE: f32 = 0.0;

/// Rungs a bisection of [`DISTANCES`] measures at most: ⌈log₂ 9⌉ + 1 for the rung before the
/// crossing (what the progress bar counts).
pub const SEARCHED_RUNGS: usize = 5;

/// The first index in `0..n` at which `crossed` holds, by bisection, assuming that once it
/// holds it holds for every later index; `None` when it holds nowhere. `crossed` is asked at
/// most ⌈log₂(n + 1)⌉ times.
pub fn first_crossing(
    n: usize,
    mut crossed: impl FnMut(usize) -> Result<bool>,
) -> Result<Option<usize>> {
    let (mut lo, mut hi) = (0, n);
    while lo < hi {
        let mid = (lo + hi) / 2;
        if crossed(mid)? {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    Ok((lo < n).then_some(lo))
}

/// Where a ladder's crossover lies ([`crossover`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Crossing {
    /// Between two measured rungs.
    Between,
    /// At the nearest rung: the stream was already within the tolerance there.
    Nearest,
    /// Nowhere: the stream stayed outside the tolerance at every rung; the switch is put at
    /// the farthest ([`HybridSwitch::never_reached`]). Also an empty ladder (distance 0).
    Never,
}

/// The crossover of a ladder (crown radii): where `quads − (1 + tolerance) · geometry` first
/// reaches zero, linear between the rungs around it; the first rung when the stream is
/// already within the tolerance there, the last when it never is, which [`Crossing`] tells.
pub fn crossover(ladder: &[Rung], tolerance: f32) -> (f32, Crossing) {
    let Some(first) = ladder.first() else {
        return (0.0, Crossing::Never);
    };
    let diff = |r: &Rung| r.excess(tolerance);
    if diff(first) <= 0.0 {
        return (first.radii, Crossing::Nearest);
    }
    for w in ladder.windows(2) {
        let (a, b) = (diff(&w[0]), diff(&w[1]));
        if b <= 0.0 {
            let t = a / (a - b);
            return (
                w[0].radii + t * (w[1].radii - w[0].radii),
                Crossing::Between,
            );
        }
    }
    (ladder[ladder.len() - 1].radii, Crossing::Never)
}

/// Where mesh LOD `k` (1 or 2) becomes as accurate as the full model (its error within
/// `1 + tolerance` times the model's) and stays so up to the switch at `switch_radii`, in
/// crown radii, over a `ladder` of increasing distance: after the last measured rung nearer
/// than the switch where it was not, linear between that rung and the next (which may lie
/// past the switch); the first rung when it was at every rung nearer than the switch. `None`
/// when no rung lies nearer than the switch, when the rung after the last failing one fails
/// too or is missing, or when the crossing lies at or past the switch.
pub fn lod_crossover(ladder: &[Rung], switch_radii: f32, tolerance: f32, k: usize) -> Option<f32> {
    let excess = |r: &Rung| r.lods[k - 1] - (1.0 + tolerance) * r.geometry;
    let near = ladder.iter().filter(|r| r.radii < switch_radii).count();
    if near == 0 {
        return None;
    }
    let Some(last_bad) = (0..near).rev().find(|&i| excess(&ladder[i]) > 0.0) else {
        return Some(ladder[0].radii);
    };
    let (a, b) = (&ladder[last_bad], ladder.get(last_bad + 1)?);
    let (ea, eb) = (excess(a), excess(b));
    if eb > 0.0 {
        return None;
    }
    let at = a.radii + ea / (ea - eb) * (b.radii - a.radii);
    (at < switch_radii).then_some(at)
}

/// The hybrid's mesh-LOD starts of a measured ladder ([`HybridSwitch::lod_from`]): each
/// LOD's [`lod_crossover`] as a fraction of the switch. A LOD 2 that is as accurate from as
/// near as LOD 1 replaces it (LOD 1 would draw no tree).
pub fn lod_from(ladder: &[Rung], switch_radii: f32, tolerance: f32) -> [Option<f32>; 2] {
    let frac = |k| {
        lod_crossover(ladder, switch_radii, tolerance, k)
            .map(|r| r / switch_radii)
            .filter(|f| *f > 0.0 && *f < 1.0)
    };
    match [frac(1), frac(2)] {
        [Some(a), Some(b)] if b <= a => [None, Some(b)],
        f => f,
    }
}

/// The finest quads' projected width (pixels) at `radii` crown radii, for a hierarchy of
/// `levels` levels at the measurement's view: `2 · focal / (2^(levels−1) · radii)`, the
/// relation [`auto_radii`] solves for the radii (crown radii × pixels is fixed).
pub fn finest_quad_pixels(levels: u32, radii: f32) -> f32 {
    let view = Camera {
        eye: Vec3::ZERO,
        target: Vec3::NEG_Z,
        fov_y_deg: FOV_Y_DEG,
        near: 0.05,
        far: 1.0,
        viewport: VIEWPORT,
        epsilon: EPSILON,
    };
    auto_radii(&view, levels, radii)
}

/// How accurate the switch lets the quad stream be, in words: "as accurate as the triangles"
/// at tolerance 0, else within that share of their error.
pub fn accuracy_words(tolerance: f32) -> String {
    if tolerance == 0.0 {
        "as accurate as the triangles".into()
    } else {
        format!("within {:.0} % of the triangles' error", tolerance * 100.0)
    }
}

/// The hybrid's automatic switch of an atlas in words: the finest quads' width there and,
/// where the bake measured it, the crossover in crown radii at the measurement's view, or
/// that the stream never reached the accuracy asked and the switch is the farthest distance
/// measured.
pub fn describe(m: &forest_format::AtlasManifest) -> String {
    match &m.hybrid_switch {
        Some(h) => describe_switch(h),
        None => format!(
            "finest quads {} px (not measured: the default)",
            forest_render::DEFAULT_SWITCH_PIXELS
        ),
    }
}

/// A measured switch in words (see [`describe`]).
pub fn describe_switch(h: &HybridSwitch) -> String {
    format!(
        "finest quads {:.2} px ({:.2} crown radii at {}x{}, {}°, {}){}",
        h.finest_quad_pixels,
        h.crown_radii,
        h.viewport[0],
        h.viewport[1],
        h.fov_y_deg,
        if h.never_reached {
            format!(
                "the farthest measured: the stream was never {}",
                accuracy_words(h.tolerance)
            )
        } else {
            format!("stream {}", accuracy_words(h.tolerance))
        },
        describe_lod_from(&h.lod_from)
    )
}

/// What [`measure`] found: the record the manifest keeps, where on the ladder its crossover
/// lies, and the rungs it measured (increasing distance; the rest were not needed).
pub struct Measured {
    /// The switch as the manifest records it.
    pub switch: HybridSwitch,
    /// Where [`crossover`] put it.
    pub crossing: Crossing,
    /// The measured rungs.
    pub ladder: Vec<Rung>,
}

/// A fresh measurement in words, for `forest bake`: [`describe_switch`]'s facts with the
/// ladder's own, which the manifest does not keep (whether the crossover lay between rungs
/// or at the nearest, and the stream's error ratio at the farthest rung when it never
/// reached the accuracy asked).
pub fn describe_measured(m: &Measured) -> String {
    let h = &m.switch;
    let (first, last) = (DISTANCES[0], DISTANCES[DISTANCES.len() - 1]);
    let words = accuracy_words(h.tolerance);
    let r = h.crown_radii;
    let place = match m.crossing {
        Crossing::Between => format!("is {words} from {r:.2} crown radii"),
        Crossing::Nearest => {
            format!("is {words} already at {r:.2} crown radii, the nearest measured")
        }
        Crossing::Never => {
            let ratio = m
                .ladder
                .last()
                .map_or(f32::NAN, |g| g.quads / g.geometry.max(f32::MIN_POSITIVE));
            format!(
                "was never {words} from {first} to {last} crown radii ({ratio:.2}x the \
                 triangles' error at {last}): switched at the farthest, {r:.2}"
            )
        }
    };
    format!(
        "the quad stream (ε {}) {place} (finest quads {:.2} px at {}x{}, {}°){}",
        h.epsilon,
        h.finest_quad_pixels,
        h.viewport[0],
        h.viewport[1],
        h.fov_y_deg,
        describe_lod_from(&h.lod_from)
    )
}

/// The hybrid's mesh-LOD starts in words: empty when the near trees are always the full
/// model, else where each LOD takes over.
pub fn describe_lod_from(lod_from: &[Option<f32>; 2]) -> String {
    let parts: Vec<String> = lod_from
        .iter()
        .enumerate()
        .filter_map(|(k, f)| f.map(|f| format!("mesh LOD {} from {:.2}", k + 1, f)))
        .collect();
    if parts.is_empty() {
        String::new()
    } else {
        format!(
            "; near trees in {} of the switch distance",
            parts.join(", ")
        )
    }
}

/// The mesh LODs' accuracy on a measured ladder, in words: per LOD, its smallest error as a
/// multiple of the full model's over the rungs nearer than the switch (all rungs when none
/// is), which says whether the LOD could draw the hybrid's near trees.
pub fn describe_lods(ladder: &[Rung], switch_radii: f32) -> String {
    let near: Vec<&Rung> = ladder.iter().filter(|r| r.radii < switch_radii).collect();
    let rungs: Vec<&Rung> = if near.is_empty() {
        ladder.iter().collect()
    } else {
        near
    };
    let best = |k: usize| {
        rungs
            .iter()
            .map(|r| r.lod_ratio(k))
            .fold(f32::INFINITY, f32::min)
    };
    format!(
        "mesh LODs 1 / 2: at best {:.2}x / {:.2}x the full model's error on {} measured \
         rung{} nearer than the switch",
        best(1),
        best(2),
        rungs.len(),
        if rungs.len() == 1 { "" } else { "s" }
    )
}

/// An upper estimate of the memory (bytes) [`measure`] adds to a bake's peak for a model of
/// `model_bytes` bytes of OBJ text: the device and its compiled pipelines on lavapipe, the
/// render targets (the 4×4 reference among them), and the full-detail geometry with its LODs,
/// about 9 B per byte of OBJ. Measured as the peak with the measurement less the peak without
/// it: 165 MiB for the bundled oak (1.3 MB of OBJ), 399 MiB for oak-dense (30 MB).
pub fn peak_bytes_estimate(model_bytes: u64) -> u64 {
    (160 << 20) + 9 * model_bytes
}

/// Measure the switch of the prepared model `model` of the species baked into `species` at
/// `tolerance` (see [`HybridSwitch::tolerance`]), its colour layers stored as `colour`;
/// `progress(done, total)` counts the views. Each
/// rung also measures the discrete-LOD baseline's mesh LODs 1 and 2 ([`Rung::lods`]), which says
/// whether they could draw the hybrid's near trees.
pub fn measure(
    ctx: &GpuContext,
    species: SpeciesData,
    model: std::sync::Arc<PreparedModel>,
    tolerance: f32,
    colour: forest_render::ColourFormat,
    progress: &dyn Fn(u64, u64),
) -> Result<Measured> {
    let manifest = species.atlas.manifest.clone();
    let sphere = manifest.bounding_sphere;
    let forest = Forest::new(
        vec!["measured".into()],
        vec![Instance {
            position: [0.0; 3],
            rotation: 0.0,
            scale: 1.0,
            species: 0,
        }],
        1,
    );
    let prepared = PreparedGeometry::new(&[GeometrySpecies::new(model, &manifest)]);
    let opts = RendererOptions {
        format: TARGET_FORMAT,
        viewport: VIEWPORT,
        min_epsilon: EPSILON,
        background: Background::Transparent,
        ..Default::default()
    };
    let scene = GpuScene::with_format(ctx, &[species], &forest, colour)?;
    let stream = QuadStream::new(&ctx.device, scene, &opts)?;
    let geometry = GeometryRenderer::with_targets(ctx, &prepared, &forest, &opts)?;
    let mut r = ForestRenderer::new(stream, Some(geometry));
    let small = Target::new(ctx, VIEWPORT.0, VIEWPORT.1);
    let big = Target::new(ctx, VIEWPORT.0 * REFERENCE_SS, VIEWPORT.1 * REFERENCE_SS);
    let full = Method::Mesh(MeshMethod::Full { depth_sort: true });

    let mut rng = SplitMix64(SEED);
    let directions: Vec<(f32, f32)> = (0..CAMERAS)
        .map(|_| {
            let azimuth = rng.next_f32() * std::f32::consts::TAU;
            let elevation = (-20.0 + 60.0 * rng.next_f32()).to_radians();
            (azimuth, elevation)
        })
        .collect();
    // The rungs are measured lazily, in the order a bisection for the crossover asks for
    // them: the difference `quads − geometry` falls with distance on every model measured
    // (the full ladders of the bundled trees each cross once), so the first rung where it
    // reaches zero is found with 4 or 5 rungs instead of 9, and the crossover is then
    // interpolated between it and the rung before, as over the full ladder.
    let mut measured: Vec<Option<Rung>> = vec![None; DISTANCES.len()];
    let total = (SEARCHED_RUNGS * directions.len()) as u64;
    let mut views = 0u64;
    let mut rung = |i: usize, measured: &mut Vec<Option<Rung>>| -> Result<Rung> {
        if let Some(r) = measured[i] {
            return Ok(r);
        }
        let radii = DISTANCES[i];
        let (mut g_sum, mut q_sum) = (0.0f32, 0.0f32);
        let mut lod_sums = [0.0f32; 2];
        for &(azimuth, elevation) in &directions {
            let d = radii * sphere.radius;
            let offset = Vec3::new(
                elevation.cos() * azimuth.cos(),
                elevation.sin(),
                elevation.cos() * azimuth.sin(),
            ) * d;
            let mut eye = sphere.center + offset;
            eye.y = eye.y.max(0.3);
            let cam = Camera {
                eye,
                target: sphere.center,
                fov_y_deg: FOV_Y_DEG,
                near: 0.05,
                far: d + 4.0 * sphere.radius,
                viewport: VIEWPORT,
                epsilon: EPSILON,
            };
            let mut cam_big = cam;
            cam_big.viewport = (VIEWPORT.0 * REFERENCE_SS, VIEWPORT.1 * REFERENCE_SS);
            r.set_method(ctx, Method::Mesh(MeshMethod::Reference))?;
            r.render_fitted(ctx, &cam_big, &big)?;
            let reference = forest_baselines::geometry::downsample(&big.read(ctx), REFERENCE_SS);
            r.set_method(ctx, full)?;
            r.render_fitted(ctx, &cam, &small)?;
            let geometry = small.read(ctx);
            r.set_method(ctx, Method::Quads)?;
            r.render_fitted(ctx, &cam, &small)?;
            let quads = small.read(ctx);
            for (k, sum) in lod_sums.iter_mut().enumerate() {
                r.set_method(ctx, Method::Mesh(MeshMethod::Lods(whole_lod(k + 1))))?;
                r.render_fitted(ctx, &cam, &small)?;
                *sum += forest_metrics::flip(&reference, &small.read(ctx))?.0;
            }
            ctx.check_errors()?;
            g_sum += forest_metrics::flip(&reference, &geometry)?.0;
            q_sum += forest_metrics::flip(&reference, &quads)?.0;
            views += 1;
            progress(views.min(total), total);
        }
        let n = directions.len() as f32;
        let out = Rung {
            radii,
            geometry: g_sum / n,
            quads: q_sum / n,
            lods: lod_sums.map(|s| s / n),
        };
        measured[i] = Some(out);
        Ok(out)
    };
    let first = first_crossing(DISTANCES.len(), |i| {
        rung(i, &mut measured).map(|r| r.excess(tolerance) <= 0.0)
    })?;
    if let Some(i) = first.filter(|&i| i > 0) {
        rung(i - 1, &mut measured)?;
    }
    progress(total, total);
    let ladder: Vec<Rung> = measured.into_iter().flatten().collect();
    let (radii, crossing) = crossover(&ladder, tolerance);
    let lod_from = lod_from(&ladder, radii, tolerance);
    let pixels = finest_quad_pixels(manifest.levels, radii)
        .clamp(HybridSwitch::MIN_PIXELS, HybridSwitch::MAX_PIXELS);
    Ok(Measured {
        switch: HybridSwitch {
            finest_quad_pixels: pixels,
            crown_radii: radii,
            viewport: [VIEWPORT.0, VIEWPORT.1],
            fov_y_deg: FOV_Y_DEG,
            epsilon: EPSILON,
            cameras: CAMERAS,
            tolerance,
            lod_from,
            never_reached: crossing == Crossing::Never,
        },
        crossing,
        ladder,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_strict_switch_reads_as_accurate_and_a_tolerance_as_its_share() {
        assert_eq!(accuracy_words(0.0), "as accurate as the triangles");
        assert_eq!(accuracy_words(0.25), "within 25 % of the triangles' error");
    }

    /// A strict switch at `radii` crown radii measured at the bake's view.
    fn strict_switch(radii: f32, never_reached: bool) -> HybridSwitch {
        HybridSwitch {
            finest_quad_pixels: finest_quad_pixels(8, radii),
            crown_radii: radii,
            viewport: [VIEWPORT.0, VIEWPORT.1],
            fov_y_deg: FOV_Y_DEG,
            epsilon: EPSILON,
            cameras: CAMERAS,
            tolerance: 0.0,
            lod_from: [None; 2],
            never_reached,
        }
    }

    #[test]
    fn a_switch_the_stream_never_reached_says_so() {
        let mut h = strict_switch(6.0, false);
        let reached = describe_switch(&h);
        assert!(reached.contains("6.00 crown radii"), "{reached}");
        assert!(
            reached.contains("stream as accurate as the triangles"),
            "{reached}"
        );
        h.never_reached = true;
        let text = describe_switch(&h);
        assert!(
            text.contains("the farthest measured: the stream was never as accurate"),
            "{text}"
        );
    }

    #[test]
    fn a_fresh_measurement_says_where_its_crossover_lay() {
        let rung = |radii, geometry, quads| Rung {
            radii,
            geometry,
            quads,
            lods: [1.0; 2],
        };
        let switch_at = |ladder: Vec<Rung>| {
            let (radii, crossing) = crossover(&ladder, 0.0);
            describe_measured(&Measured {
                switch: strict_switch(radii, crossing == Crossing::Never),
                crossing,
                ladder,
            })
        };
        // quads − geometry: 0.02 at 2, −0.02 at 3: crossing halfway.
        let between = switch_at(vec![rung(2.0, 0.1, 0.12), rung(3.0, 0.1, 0.08)]);
        assert!(
            between.contains("is as accurate as the triangles from 2.50 crown radii"),
            "{between}"
        );
        let nearest = switch_at(vec![rung(1.25, 0.1, 0.09)]);
        assert!(
            nearest.contains("already at 1.25 crown radii, the nearest"),
            "{nearest}"
        );
        // Still 1.5× the triangles' error at the last rung measured.
        let never = switch_at(vec![rung(5.0, 0.1, 0.2), rung(6.0, 0.1, 0.15)]);
        assert!(never.contains("was never as accurate"), "{never}");
        assert!(
            never.contains("(1.50x the triangles' error at 6)"),
            "{never}"
        );
        assert!(never.contains("switched at the farthest, 6.00"), "{never}");
    }

    #[test]
    fn bisection_finds_the_first_crossing_in_few_questions() {
        for n in [1usize, 2, 5, 9] {
            for first in 0..=n {
                let mut asked = Vec::new();
                let found = first_crossing(n, |i| {
                    asked.push(i);
                    Ok(i >= first)
                })
                .unwrap();
                assert_eq!(found, (first < n).then_some(first), "n {n}, first {first}");
                let bound = (n as f32 + 1.0).log2().ceil() as usize;
                assert!(asked.len() <= bound, "n {n}: asked {asked:?}");
                if n == DISTANCES.len() {
                    assert!(asked.len() < SEARCHED_RUNGS);
                }
            }
        }
    }

    fn rung(radii: f32, geometry: f32, quads: f32) -> Rung {
        Rung {
            radii,
            geometry,
            quads,
            lods: [0.0; 2],
        }
    }

    #[test]
    fn the_crossover_is_where_the_stream_first_catches_up() {
        // 0.02 worse at 2, 0.01 better at 3: a third of the way.
        let ladder = [
            rung(1.0, 0.10, 0.20),
            rung(2.0, 0.05, 0.07),
            rung(3.0, 0.03, 0.02),
            rung(4.0, 0.01, 0.02),
        ];
        let (k, crossing) = crossover(&ladder, 0.0);
        assert!((k - (2.0 + 2.0 / 3.0)).abs() < 1e-5, "{k}");
        assert_eq!(crossing, Crossing::Between);
        // Allowed 50 % more error than the triangles: the excess falls from 0.20 − 0.15 = 0.05
        // at 1 to 0.07 − 0.075 = −0.005 at 2.
        let (k, crossing) = crossover(&ladder, 0.5);
        assert!((k - (1.0 + 0.05 / 0.055)).abs() < 1e-5, "{k}");
        assert_eq!(crossing, Crossing::Between);
        // Better from the first rung, or never: the ladder's ends, told apart.
        assert_eq!(
            crossover(&[rung(1.0, 0.2, 0.1), rung(2.0, 0.1, 0.2)], 0.0),
            (1.0, Crossing::Nearest)
        );
        assert_eq!(
            crossover(&[rung(1.0, 0.1, 0.2), rung(2.0, 0.1, 0.2)], 0.0),
            (2.0, Crossing::Never)
        );
        // Twice the triangles' error is within a tolerance of 1 from the first rung.
        assert_eq!(
            crossover(&[rung(1.0, 0.1, 0.2), rung(2.0, 0.1, 0.2)], 1.0),
            (1.0, Crossing::Nearest)
        );
        assert_eq!(crossover(&[], 0.0), (0.0, Crossing::Never));
    }

    #[test]
    fn lods_are_described_by_their_best_ratio_nearer_than_the_switch() {
        let mut a = rung(1.0, 0.10, 0.20);
        a.lods = [0.30, 0.40];
        let mut b = rung(2.0, 0.05, 0.07);
        b.lods = [0.10, 0.20];
        let mut far = rung(4.0, 0.01, 0.01);
        far.lods = [0.01, 0.01];
        let text = describe_lods(&[a, b, far], 3.0);
        assert!(text.contains("2.00x / 4.00x"), "{text}");
        assert!(text.contains("on 2 measured rungs"), "{text}");
        // No rung nearer than the switch: every rung counts.
        assert!(describe_lods(&[far], 1.0).contains("1.00x / 1.00x"));
    }

    fn lod_rung(radii: f32, geometry: f32, lods: [f32; 2]) -> Rung {
        Rung {
            radii,
            geometry,
            quads: 1.0,
            lods,
        }
    }

    #[test]
    fn mesh_lods_start_where_they_stay_as_accurate_up_to_the_switch() {
        // LOD 1: twice the model's error at 1, 0.05 over at 2, 0.05 under at 3: as accurate
        // from 2.5. LOD 2: over at every rung nearer than the switch at 4, under at 4: from
        // 3.8, between the last rung before the switch and the first past it.
        let ladder = [
            lod_rung(1.0, 0.1, [0.2, 0.5]),
            lod_rung(2.0, 0.1, [0.15, 0.4]),
            lod_rung(3.0, 0.1, [0.05, 0.3]),
            lod_rung(4.0, 0.1, [0.05, 0.05]),
        ];
        let c = lod_crossover(&ladder, 4.0, 0.0, 1).unwrap();
        assert!((c - 2.5).abs() < 1e-5, "{c}");
        let c = lod_crossover(&ladder, 4.0, 0.0, 2).unwrap();
        assert!((c - 3.8).abs() < 1e-5, "{c}");
        let f = lod_from(&ladder, 4.0, 0.0);
        assert!((f[0].unwrap() - 2.5 / 4.0).abs() < 1e-5, "{f:?}");
        assert!((f[1].unwrap() - 3.8 / 4.0).abs() < 1e-5, "{f:?}");
        // The crossing at 3.8 lies past a switch at 3.5: never.
        assert_eq!(lod_crossover(&ladder, 3.5, 0.0, 2), None);
        // A tolerance of 1.5: LOD 1 is within it everywhere, from the first rung; LOD 2 from
        // 3.2 (excess 0.05 at 3, −0.2 at 4).
        let f = lod_from(&ladder, 4.0, 1.5);
        assert_eq!(f[0], Some(0.25));
        assert!((f[1].unwrap() - 3.2 / 4.0).abs() < 1e-5, "{f:?}");
        // A LOD that is worse again at a later rung starts after it; none before the switch,
        // or no rung nearer than it: never.
        let bumpy = [
            lod_rung(1.0, 0.1, [0.05, 0.5]),
            lod_rung(2.0, 0.1, [0.2, 0.5]),
            lod_rung(3.0, 0.1, [0.1, 0.5]),
        ];
        assert_eq!(lod_crossover(&bumpy, 4.0, 0.0, 1), Some(3.0));
        assert_eq!(lod_crossover(&bumpy, 2.5, 0.0, 1), None);
        assert_eq!(lod_from(&bumpy, 2.5, 0.0), [None; 2]);
        assert_eq!(lod_crossover(&bumpy, 1.0, 0.0, 1), None);
        // LOD 2 as accurate as near as LOD 1 replaces it.
        let coarse = [
            lod_rung(1.0, 0.1, [0.2, 0.2]),
            lod_rung(2.0, 0.1, [0.1, 0.1]),
        ];
        assert_eq!(lod_from(&coarse, 4.0, 0.0), [None, Some(0.5)]);
        assert_eq!(describe_lod_from(&[None; 2]), "");
        assert_eq!(
            describe_lod_from(&[Some(0.25), Some(0.5)]),
            "; near trees in mesh LOD 1 from 0.25, mesh LOD 2 from 0.50 of the switch distance"
        );
    }

    #[test]
    fn finest_quads_at_the_crossover_follow_the_view_formula() {
        // 400×300 at 60°: focal 259.81 px; 8 levels: finest quads 2R/128 wide.
        let p = finest_quad_pixels(8, 2.0);
        assert!((p - 2.0 * 259.8076 / (128.0 * 2.0)).abs() < 1e-3, "{p}");
        assert!((finest_quad_pixels(9, 2.0) - p / 2.0).abs() < 1e-5);
        assert!((finest_quad_pixels(8, 4.0) - p / 2.0).abs() < 1e-5);
    }
}
