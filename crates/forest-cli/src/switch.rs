//! The hybrid's switch of one model, measured at bake: where its quad stream becomes as
//! accurate as its own triangles.
//!
//! One tree (scale 1, unrotated) is seen from seeded random cameras at a ladder of distances
//! from its crown's centre (in crown radii; azimuth uniform, elevation −20° to 40°, eyes kept
//! 0.3 m above the ground, looking at the centre; 400×300, 60°, transparent background).
//! Each view is drawn as full geometry at 1× and as the quad stream at ε 2, and both are
//! compared (mean FLIP) with the 4×4 supersampled reference ([`MeshMethod::Reference`]). The crossover is where the
//! stream's mean error, minus the geometry's, first reaches zero (linear between the two
//! distances around it), found by bisection over the ladder (4 or 5 of its 9 rungs: the
//! difference falls with distance); it is recorded as the width the finest quads project to there
//! ([`HybridSwitch::finest_quad_pixels`]), which carries over to any view and tree size.

use std::path::Path;

use anyhow::{Context, Result};
use forest_baselines::geometry::{GeometryRenderer, GeometrySpecies, MeshMethod, PreparedGeometry};
use forest_baselines::hybrid::auto_radii;
use forest_baselines::methods::{ForestRenderer, Method};
use forest_format::atlas::HybridSwitch;
use forest_format::forest::{Forest, Instance};
use forest_format::generate::SplitMix64;
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

/// The mean FLIP of both forms at one distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rung {
    /// Crown radii from the crown's centre.
    pub radii: f32,
    /// Full geometry at 1×.
    pub geometry: f32,
    /// The quad stream at [`EPSILON`].
    pub quads: f32,
}

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

/// The crossover of a ladder (crown radii): where `quads − geometry` first reaches zero,
/// linear between the rungs around it; the first rung when the stream is already the more
/// accurate there, the last when it never is. The flag tells whether it lies inside the
/// ladder.
pub fn crossover(ladder: &[Rung]) -> (f32, bool) {
    let Some(first) = ladder.first() else {
        return (0.0, false);
    };
    let diff = |r: &Rung| r.quads - r.geometry;
    if diff(first) <= 0.0 {
        return (first.radii, false);
    }
    for w in ladder.windows(2) {
        let (a, b) = (diff(&w[0]), diff(&w[1]));
        if b <= 0.0 {
            let t = a / (a - b);
            return (w[0].radii + t * (w[1].radii - w[0].radii), true);
        }
    }
    (ladder[ladder.len() - 1].radii, false)
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

/// The hybrid's automatic switch of an atlas in words: the finest quads' width there and,
/// where the bake measured it, the crossover in crown radii at the measurement's view.
pub fn describe(m: &forest_format::AtlasManifest) -> String {
    match &m.hybrid_switch {
        Some(h) => format!(
            "finest quads {:.2} px ({:.2} crown radii at {}x{}, {}°)",
            h.finest_quad_pixels, h.crown_radii, h.viewport[0], h.viewport[1], h.fov_y_deg
        ),
        None => format!(
            "finest quads {} px (not measured: the default)",
            forest_render::forms::DEFAULT_SWITCH_PIXELS
        ),
    }
}

/// An upper estimate of the memory (bytes) [`measure`] adds to a bake's peak for a model of
/// `model_bytes` bytes of OBJ text: the device and its compiled pipelines on lavapipe, the
/// render targets (the 4×4 reference among them), and the full-detail geometry with its LODs,
/// about 9 B per byte of OBJ. Measured as the peak with the measurement less the peak without
/// it: 165 MiB for the bundled oak (1.3 MB of OBJ), 399 MiB for oak-dense (30 MB).
pub fn peak_bytes_estimate(model_bytes: u64) -> u64 {
    (160 << 20) + 9 * model_bytes
}

/// Measure the switch of the model `model` baked into `species`, reusing `sky`, the bake's
/// traced sky visibility of its triangles, when the model is the one the atlas was baked
/// from; `progress(done, total)` counts the views. Returns the record and the ladder it came from.
pub fn measure(
    ctx: &GpuContext,
    species: SpeciesData,
    model: &Path,
    sky: Option<Vec<forest_bake::sky::TriangleSky>>,
    progress: &dyn Fn(u64, u64),
) -> Result<(HybridSwitch, Vec<Rung>)> {
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
    let mesh = forest_bake::Mesh::load(model)
        .with_context(|| format!("loading {} for the geometry", model.display()))?;
    // The bake's traced sky visibility, when it traced this very model.
    let same_model = manifest.source.hash == format!("{:016x}", mesh.hash);
    let mut geometry_species = GeometrySpecies::new(mesh, &manifest);
    if let Some(sky) = sky.filter(|_| same_model) {
        geometry_species = geometry_species.with_sky(sky);
    }
    let prepared = PreparedGeometry::new(&[geometry_species]);
    let opts = RendererOptions {
        format: TARGET_FORMAT,
        viewport: VIEWPORT,
        min_epsilon: EPSILON,
        background: Background::Transparent,
        ..Default::default()
    };
    let scene = GpuScene::with_format(ctx, &[species], &forest, crate::colour_format())?;
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
        };
        measured[i] = Some(out);
        Ok(out)
    };
    let first = first_crossing(DISTANCES.len(), |i| {
        rung(i, &mut measured).map(|r| r.quads - r.geometry <= 0.0)
    })?;
    if let Some(i) = first.filter(|&i| i > 0) {
        rung(i - 1, &mut measured)?;
    }
    progress(total, total);
    let ladder: Vec<Rung> = measured.into_iter().flatten().collect();
    let (radii, _) = crossover(&ladder);
    let pixels = finest_quad_pixels(manifest.levels, radii)
        .clamp(HybridSwitch::MIN_PIXELS, HybridSwitch::MAX_PIXELS);
    Ok((
        HybridSwitch {
            finest_quad_pixels: pixels,
            crown_radii: radii,
            viewport: [VIEWPORT.0, VIEWPORT.1],
            fov_y_deg: FOV_Y_DEG,
            epsilon: EPSILON,
            cameras: CAMERAS,
        },
        ladder,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let (k, inside) = crossover(&ladder);
        assert!((k - (2.0 + 2.0 / 3.0)).abs() < 1e-5, "{k}");
        assert!(inside);
        // Better from the first rung, or never: the ladder's ends, flagged.
        assert_eq!(
            crossover(&[rung(1.0, 0.2, 0.1), rung(2.0, 0.1, 0.2)]),
            (1.0, false)
        );
        assert_eq!(
            crossover(&[rung(1.0, 0.1, 0.2), rung(2.0, 0.1, 0.2)]),
            (2.0, false)
        );
        assert_eq!(crossover(&[]), (0.0, false));
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
