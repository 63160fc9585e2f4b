//! Fidelity: the quad stream's accuracy around single trees where people look — close up,
//! under the crown, between sampling directions, far away — and the error split by swapping
//! one factor of the bake or the runtime at a time (and the paper's method in one row), beside
//! full geometry drawn at 1×, the yardstick of the stream's accuracy targets.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result};
use forest_baselines::geometry::MeshMethod;
use forest_baselines::methods::{ForestRenderer, Method};
use forest_format::forest::{DEFAULT_PRESORT_DIRECTIONS, Forest, Instance};
use forest_format::noise::SplitMix64;
use forest_render::options::{Background, StreamOptions};
use forest_render::scene::SpeciesData;
use forest_render::target::{TARGET_FORMAT, Target};
use forest_render::{Camera, GpuScene, QuadStream, RendererOptions};
use glam::Vec3;

use super::accuracy::reference;
use super::chart::{Chart, Series};
pub use super::fidelity_variants::{EPS, EPS_EXACT};
use super::fidelity_variants::{GEOMETRY, Variant, variants};
use super::report::Section;
use super::{Bench, Table, ms};

/// Seed of the camera draw.
pub const SEED: u64 = 0x5eed;
/// Lowest eye height (metres): eyes drawn below it slide along their ray towards the crown.
pub const MIN_EYE_HEIGHT: f32 = 0.3;
/// Highest elevation drawn (degrees): straight down has no up vector.
const MAX_ELEVATION: f32 = 89.5;
/// Largest scratch-bake resolution in quick mode.
const QUICK_RESOLUTION: u32 = 128;
/// Scratch folder of the re-baked atlases, inside the results folder (removed afterwards).
pub const SCRATCH: &str = ".fidelity-atlases";

/// A drawn camera and what the table records of it.
struct View {
    cam: Camera,
    /// Distance from the crown centre in crown radii (after any move above the ground).
    distance_radii: f32,
    elevation_deg: f32,
    azimuth_deg: f32,
    /// Azimuth halfway between two adjacent horizon sampling directions (else on one).
    between: bool,
}

/// `n` cameras around a tree at the origin (scale 1, rotation 0) of `data`, drawn from `seed`:
/// distance 1–100 crown radii (log-uniform) from the crown centre, elevation −60°..90°,
/// azimuth on a horizon sampling direction (even indices) or halfway between two (odd).
fn views(data: &SpeciesData, n: usize, viewport: (u32, u32), seed: u64) -> Vec<View> {
    let m = &data.atlas.manifest;
    let (c, r) = (m.bounding_sphere.center, m.bounding_sphere.radius);
    let tau = std::f32::consts::TAU;
    let mut horizon: Vec<f32> = m
        .directions
        .iter()
        .filter(|f| f.dir.y.abs() < 1e-3)
        .map(|f| f.dir.x.atan2(f.dir.z).rem_euclid(tau))
        .collect();
    horizon.sort_by(f32::total_cmp);
    let mut rng = SplitMix64(seed);
    (0..n)
        .map(|i| {
            // Always the same four draws per camera, whatever the branch.
            let u = rng.next_f32();
            let e = rng.next_f32();
            let pick = rng.next_u64();
            let free = rng.next_f32() * tau;
            let (az, between) = if horizon.is_empty() {
                (free, false)
            } else {
                let k = (pick % horizon.len() as u64) as usize;
                if i % 2 == 0 {
                    (horizon[k], false)
                } else {
                    let next = horizon.get(k + 1).copied().unwrap_or(horizon[0] + tau);
                    (((horizon[k] + next) / 2.0).rem_euclid(tau), true)
                }
            };
            let el = (-60.0 + 150.0 * e).min(MAX_ELEVATION).to_radians();
            let dir = Vec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
            let mut d = r * 10f32.powf(2.0 * u);
            if (c + dir * d).y < MIN_EYE_HEIGHT {
                // Below ground: slide towards the crown centre (under the crown).
                d = ((MIN_EYE_HEIGHT - c.y) / dir.y).clamp(0.05, d);
            }
            View {
                cam: Camera {
                    eye: c + dir * d,
                    target: c,
                    fov_y_deg: 60.0,
                    near: 0.05,
                    far: d + 4.0 * r + 10.0,
                    viewport,
                    epsilon: EPS,
                },
                distance_radii: d / r,
                elevation_deg: el.to_degrees(),
                azimuth_deg: az.to_degrees(),
                between,
            }
        })
        .collect()
}

/// Relative change of the mean FLIP from the baseline's from which a variant is charted.
const CHART_SHARE: f64 = 0.05;
/// Bin edges of the distance chart (crown radii).
const DISTANCE_BINS: [f64; 9] = [0.0, 1.0, 1.5, 2.0, 3.0, 5.0, 10.0, 30.0, f64::INFINITY];
/// Bin edges of the elevation chart (degrees).
const ELEVATION_BINS: [f64; 11] = [
    -90.0, -60.0, -45.0, -30.0, -15.0, 0.0, 15.0, 30.0, 45.0, 60.0, 90.0,
];

/// Points (x, y) averaged per bin `[edges[i], edges[i + 1])`: (mean x, mean y) of every bin
/// that holds a point, in the edges' order.
fn binned(points: impl Iterator<Item = (f64, f64)>, edges: &[f64]) -> Vec<(f64, f64)> {
    let bins = edges.len().saturating_sub(1);
    let mut sum = vec![(0.0, 0.0, 0u32); bins];
    for (x, y) in points {
        if let Some(i) = (0..bins).find(|&i| x >= edges[i] && x < edges[i + 1]) {
            sum[i] = (sum[i].0 + x, sum[i].1 + y, sum[i].2 + 1);
        }
    }
    sum.into_iter()
        .filter(|s| s.2 > 0)
        .map(|(x, y, n)| (x / f64::from(n), y / f64::from(n)))
        .collect()
}

/// One measured (variant, species, camera).
struct Row {
    variant: usize,
    distance_radii: f32,
    elevation_deg: f32,
    flip: f32,
    iou: Option<f64>,
    frame_ms: f64,
}

/// The single-tree forest of species `k` among `species` names.
fn one_tree(species: Vec<String>, k: u32) -> Forest {
    Forest::new(
        species,
        vec![Instance {
            position: [0.0; 3],
            rotation: 0.0,
            scale: 1.0,
            species: k,
        }],
        DEFAULT_PRESORT_DIRECTIONS,
    )
}

/// The quad stream alone of one scratch atlas at `path` (a single-species forest).
fn scratch_renderer(
    b: &Bench,
    path: &Path,
    viewport: (u32, u32),
    min_epsilon: f32,
) -> Result<(ForestRenderer, u64)> {
    let species = vec![SpeciesData::load(path)?];
    let gpu = species[0].atlas.manifest.gpu_bytes();
    let forest = one_tree(vec![path.display().to_string()], 0);
    let scene = GpuScene::with_format(&b.ctx, &species, &forest, crate::colour_format())?;
    let opts = RendererOptions {
        format: TARGET_FORMAT,
        viewport,
        min_epsilon,
        background: Background::Transparent,
        ..Default::default()
    };
    let stream = QuadStream::new(&b.ctx.device, scene, &opts)?;
    Ok((b.shadowed(ForestRenderer::new(stream, None))?, gpu))
}

fn mean(v: impl Iterator<Item = f64>) -> Option<f64> {
    let (s, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    (n > 0).then(|| s / n as f64)
}

fn cell(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "-".into(), |x| format!("{x:.digits$}"))
}

/// What the variants measured over every species: a row per camera, the atlas GPU bytes per
/// variant, the variants that could not run, and the resolutions the re-bakes used.
#[derive(Default)]
struct Measured {
    rows: Vec<Row>,
    gpu_bytes: Vec<u64>,
    failed: Vec<String>,
    bake_resolutions: Vec<u32>,
}

/// Run the suite.
pub fn run(b: &Bench) -> Result<Section> {
    // The reference needs the models: fail before any work without them.
    b.prepared()?;
    let quick = b.quick;
    let viewport = if quick { (160, 120) } else { (400, 300) };
    let n = if quick { 4 } else { 24 };
    let count = if quick { 1 } else { b.species.len() };
    let variants = variants(quick);
    let scratch = b.out.join(SCRATCH);
    std::fs::create_dir_all(&scratch).with_context(|| format!("creating {}", scratch.display()))?;
    let target = Target::new(&b.ctx, viewport.0, viewport.1);
    let mut table = Table::new(&[
        "variant",
        "species",
        "camera",
        "distance_radii",
        "elevation_deg",
        "azimuth_deg",
        "between_directions",
        "epsilon",
        "quads",
        "flip_mean",
        "iou",
        "frame_ms",
    ]);
    let mut m = Measured {
        gpu_bytes: vec![0u64; variants.len()],
        ..Default::default()
    };
    let result = (|| -> Result<()> {
        for k in 0..count {
            measure_species(b, k, n, viewport, &variants, &target, &mut table, &mut m)?;
        }
        Ok(())
    })();
    let _ = std::fs::remove_dir_all(&scratch);
    result?;
    b.write("fidelity.csv", &table.csv())?;
    let Measured {
        rows,
        gpu_bytes,
        failed,
        bake_resolutions,
    } = m;
    let (summary, ratios) = summarise(&variants, &rows, &gpu_bytes);
    b.write("fidelity_summary.csv", &summary.csv())?;
    println!("{}", summary.markdown());
    let what = format!(
        "{} species, {n} cameras each, {}x{}",
        count, viewport.0, viewport.1
    );
    charts(b, &variants, &rows, &ratios, &what)?;
    let text = paragraph(
        b,
        &variants,
        &ratios,
        &summary,
        &failed,
        &bake_resolutions,
        &what,
    );
    Ok(Section {
        title: "Fidelity around single trees".into(),
        text,
        table: summary,
        charts: vec!["fidelity-distance".into(), "fidelity-elevation".into()],
    })
}

/// Species `k` seen from `n` seeded cameras by every variant: the references once, then each
/// variant's frames (a re-baked variant in its scratch atlas), into `table` and `m`.
#[allow(clippy::too_many_arguments)]
fn measure_species(
    b: &Bench,
    k: usize,
    n: usize,
    viewport: (u32, u32),
    variants: &[Variant],
    target: &Target,
    table: &mut Table,
    m: &mut Measured,
) -> Result<()> {
    let quick = b.quick;
    let scratch = b.out.join(SCRATCH);
    let names: Vec<String> = b
        .species_paths
        .iter()
        .map(|p| p.display().to_string())
        .collect();
    let data = &b.species[k];
    let species = b.species_paths[k]
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| format!("species{k}"));
    let views = views(data, n, viewport, SEED.wrapping_add(k as u64));
    let forest = one_tree(names, k as u32);
    let mut r0 = b.renderer(&forest, viewport, EPS, true, Background::Transparent)?;
    eprintln!("fidelity: {species}: {n} references (4x4 supersampled full geometry)");
    let refs = views
        .iter()
        .map(|v| reference(b, &mut r0, &v.cam))
        .collect::<Result<Vec<_>>>()?;
    let mut base = data.atlas.manifest.params;
    if quick {
        base.resolution = base.resolution.min(QUICK_RESOLUTION);
        base.min_quad = base.min_quad.min(base.resolution / 2).max(1);
    }
    for (vi, v) in variants.iter().enumerate() {
        let start = std::time::Instant::now();
        // The renderer of this variant: the one given, or a scratch re-bake.
        let mut scratch_r;
        let r = match v.bake {
            None => {
                if !v.geometry {
                    m.gpu_bytes[vi] += data.atlas.manifest.gpu_bytes();
                }
                &mut r0
            }
            Some(change) => {
                let params = change(base);
                eprintln!(
                    "fidelity: {species} {}: baking ({} px, {} + {} directions, {} \
                     slabs, min quad {}, {} fit)",
                    v.name,
                    params.resolution,
                    params.directions,
                    params.below,
                    params.slabs,
                    params.min_quad,
                    params.plane_fit.name()
                );
                let path = scratch.join(format!("{k}-{vi}.atlas"));
                let baked = forest_bake::bake_file(&b.models[k], &params, &|_, _| {})
                    .map_err(anyhow::Error::from)
                    .and_then(|out| {
                        out.atlas.save(&path)?;
                        scratch_renderer(b, &path, viewport, v.epsilon)
                    });
                match baked {
                    Ok((r, gpu)) => {
                        // Rows that do not swap the resolution itself: bake at the
                        // base's (below the given atlases' in quick mode).
                        if params.resolution == base.resolution {
                            m.bake_resolutions.push(params.resolution);
                        }
                        m.gpu_bytes[vi] += gpu;
                        scratch_r = r;
                        &mut scratch_r
                    }
                    Err(e) => {
                        eprintln!("fidelity: {species} {}: FAILED: {e:#}", v.name);
                        m.failed.push(format!("{} ({species}): {e:#}", v.name));
                        let _ = std::fs::remove_dir_all(&path);
                        continue;
                    }
                }
            }
        };
        r.stream.set_options(v.options)?;
        let flips = measure_views(b, r, (vi, v), &species, &views, &refs, target, table, m)?;
        r.stream.set_options(StreamOptions::default())?;
        eprintln!(
            "fidelity: {species} {}: mean FLIP {:.4} ({:.1} s)",
            v.name,
            mean(flips.into_iter()).unwrap_or(f64::NAN),
            start.elapsed().as_secs_f64()
        );
        if v.bake.is_some() {
            let _ = std::fs::remove_dir_all(scratch.join(format!("{k}-{vi}.atlas")));
        }
    }
    Ok(())
}

/// Variant `v` (number `vi`) drawn by `r` from every view, each frame compared with its
/// reference: a table row and a [`Row`] each; the views' FLIP.
#[allow(clippy::too_many_arguments)]
fn measure_views(
    b: &Bench,
    r: &mut ForestRenderer,
    (vi, v): (usize, &Variant),
    species: &str,
    views: &[View],
    refs: &[image::RgbaImage],
    target: &Target,
    table: &mut Table,
    out: &mut Measured,
) -> Result<Vec<f64>> {
    let mut flips = Vec::new();
    for (ci, (view, rf)) in views.iter().zip(refs).enumerate() {
        let mut cam = view.cam;
        cam.epsilon = v.epsilon;
        let method = if v.geometry {
            Method::Mesh(MeshMethod::Full { depth_sort: true })
        } else {
            Method::Quads
        };
        let (s, frame_ms) = b.measure(r, method, &cam, target, b.frames)?;
        if s.overflow > 0 {
            eprintln!(
                "fidelity: {species} {} camera {ci}: {} quads overflowed",
                v.name, s.overflow
            );
        }
        let m = forest_metrics::compare(rf, &target.read(&b.ctx))?;
        flips.push(f64::from(m.flip_mean));
        table.push(vec![
            v.name.into(),
            species.to_owned(),
            ci.to_string(),
            format!("{:.3}", view.distance_radii),
            format!("{:.2}", view.elevation_deg),
            format!("{:.2}", view.azimuth_deg),
            view.between.to_string(),
            v.epsilon.to_string(),
            s.primitives.to_string(),
            format!("{:.5}", m.flip_mean),
            cell(m.coverage_iou, 4),
            ms(frame_ms),
        ]);
        out.rows.push(Row {
            variant: vi,
            distance_radii: view.distance_radii,
            elevation_deg: view.elevation_deg,
            flip: m.flip_mean,
            iou: m.coverage_iou,
            frame_ms,
        });
    }
    Ok(flips)
}

/// The summary per variant (rows, mean FLIP overall and per bucket of distance and elevation,
/// the ratio to the baseline, frame time, atlas bytes), and each variant's (name, FLIP, ratio).
fn summarise<'a>(
    variants: &'a [Variant],
    rows: &[Row],
    gpu_bytes: &[u64],
) -> (Table, Vec<(&'a str, f64, f64)>) {
    let stats = |vi: usize, f: &dyn Fn(&Row) -> bool| {
        mean(
            rows.iter()
                .filter(|r| r.variant == vi && f(r))
                .map(|r| f64::from(r.flip)),
        )
    };
    let all = |_: &Row| true;
    let base_flip = stats(0, &all);
    let mut summary = Table::new(&[
        "variant",
        "rows",
        "flip_mean",
        "iou_mean",
        "flip_under_2r",
        "flip_2r_to_10r",
        "flip_over_10r",
        "flip_from_below",
        "flip_ratio_to_baseline",
        "frame_ms_mean",
        "atlas_gpu_mib",
    ]);
    let mut ratios: Vec<(&str, f64, f64)> = Vec::new();
    for (vi, v) in variants.iter().enumerate() {
        let mine: Vec<&Row> = rows.iter().filter(|r| r.variant == vi).collect();
        if mine.is_empty() {
            continue;
        }
        let flip = stats(vi, &all);
        let ratio = flip.zip(base_flip).map(|(f, b)| f / b);
        if let (Some(f), Some(q)) = (flip, ratio) {
            ratios.push((v.name, f, q));
        }
        summary.push(vec![
            v.name.into(),
            mine.len().to_string(),
            cell(flip, 5),
            cell(mean(mine.iter().filter_map(|r| r.iou)), 4),
            cell(stats(vi, &|r| r.distance_radii < 2.0), 5),
            cell(stats(vi, &|r| (2.0..=10.0).contains(&r.distance_radii)), 5),
            cell(stats(vi, &|r| r.distance_radii > 10.0), 5),
            cell(stats(vi, &|r| r.elevation_deg < 0.0), 5),
            cell(ratio, 3),
            cell(mean(mine.iter().map(|r| r.frame_ms)), 3),
            if v.geometry {
                "-".into()
            } else {
                format!("{:.2}", gpu_bytes[vi] as f64 / 1048576.0)
            },
        ]);
    }
    (summary, ratios)
}

/// The charts: mean FLIP per bin of distance and of elevation, one line per variant drawn
/// (the baseline, the paper's method, the yardstick, and every row [`CHART_SHARE`] or more
/// away from the baseline; the table has them all).
fn charts(
    b: &Bench,
    variants: &[Variant],
    rows: &[Row],
    ratios: &[(&str, f64, f64)],
    what: &str,
) -> Result<()> {
    let drawn = |v: &Variant| {
        matches!(v.name, "baseline" | "paper" | GEOMETRY)
            || ratios
                .iter()
                .any(|r| r.0 == v.name && (r.2 - 1.0).abs() >= CHART_SHARE)
    };
    let series = |x: &dyn Fn(&Row) -> f64, edges: &[f64]| -> Vec<Series> {
        variants
            .iter()
            .enumerate()
            .filter(|&(vi, v)| drawn(v) && rows.iter().any(|r| r.variant == vi))
            .map(|(vi, v)| Series {
                name: v.name.into(),
                points: binned(
                    rows.iter()
                        .filter(|r| r.variant == vi)
                        .map(|r| (x(r), f64::from(r.flip))),
                    edges,
                ),
                line: true,
                ..Default::default()
            })
            .collect()
    };
    b.chart(
        "fidelity-distance",
        &Chart {
            title: format!("Single-tree fidelity against distance ({what}; binned)"),
            x_label: "distance from the crown centre (crown radii)".into(),
            y_label: "mean FLIP against the reference".into(),
            log_x: true,
            series: series(&|r| f64::from(r.distance_radii), &DISTANCE_BINS),
            ..Default::default()
        },
    )?;
    b.chart(
        "fidelity-elevation",
        &Chart {
            title: format!("Single-tree fidelity against elevation ({what}; binned)"),
            x_label: "camera elevation seen from the crown centre (degrees)".into(),
            y_label: "mean FLIP against the reference".into(),
            series: series(&|r| f64::from(r.elevation_deg), &ELEVATION_BINS),
            ..Default::default()
        },
    )?;
    Ok(())
}

/// Summary rows `a` and `b` compared per bucket of cameras ("LABEL A against B", with the
/// ratio A / B when `ratio`; over all cameras first when `ratio`); empty when either is missing.
fn buckets(summary: &Table, a: &str, b: &str, ratio: bool) -> Vec<String> {
    let row = |name: &str| summary.rows.iter().find(|r| r[0] == name);
    let (Some(ra), Some(rb)) = (row(a), row(b)) else {
        return Vec::new();
    };
    let all = [
        (2, "over all cameras"),
        (4, "under 2 radii"),
        (5, "2–10 radii"),
        (6, "beyond 10 radii"),
        (7, "from below"),
    ];
    all.iter()
        .skip(usize::from(!ratio))
        .filter_map(|&(c, label)| {
            let (x, y) = (ra[c].parse::<f64>().ok()?, rb[c].parse::<f64>().ok()?);
            (y > 0.0).then(|| {
                if ratio {
                    format!("{label} {x:.4} against {y:.4} ({:.2}×)", x / y)
                } else {
                    format!("{label} {x:.4} against {y:.4}")
                }
            })
        })
        .collect()
}

/// The report's reading, from the measured figures.
fn paragraph(
    b: &Bench,
    variants: &[Variant],
    ratios: &[(&str, f64, f64)],
    summary: &Table,
    failed: &[String],
    bake_resolutions: &[u32],
    what: &str,
) -> String {
    let mut s = format!(
        "One tree at the origin per species ({what}; transparent background, so coverage IoU \
         is the silhouette's overlap), seen from seeded random cameras (seed {SEED:#x}): \
         distance 1–100 crown radii from the crown centre (log-uniform), elevation −60° to \
         90°, azimuth exactly on a horizon sampling direction (even cameras) or halfway \
         between two (odd); eyes drawn below {MIN_EYE_HEIGHT} m slide along their ray towards \
         the crown centre and stand under the crown; cameras inside a crown are kept. Every \
         image is compared with the 4×4 supersampled full-geometry reference (mean FLIP, lower \
         is better). The baseline is the atlases given with the default run-time options \
         (\"over\" aspect blend, refinement by projected edge length) on the default bake \
         (gap-aware planes, 5 directions below the horizon) at ε = {EPS}; every other row swaps \
         one factor: a run-time option, or a re-bake of the model with the given atlas's \
         parameters but that one changed (`min-quad=1` at ε = {EPS_EXACT}); `paper` is the \
         original method in one row (no directions below the horizon, least-squares plane \
         fit, \"over\" blending, projected edge length alone).\n\n"
    );
    if let Some(res) = bake_resolutions.iter().max() {
        let given: Vec<u32> = b
            .species
            .iter()
            .map(|d| d.atlas.manifest.params.resolution)
            .collect();
        if given.iter().any(|g| g != res) {
            let _ = write!(
                s,
                "Re-bakes here are at {res} px while the atlases given are at {} px, so the \
                 bake rows also differ by resolution. ",
                given
                    .iter()
                    .map(u32::to_string)
                    .collect::<Vec<_>>()
                    .join("/")
            );
        }
    }
    let base = ratios.iter().find(|r| r.0 == "baseline");
    match base {
        Some(&(_, flip, _)) => {
            let _ = write!(s, "Baseline mean FLIP {flip:.4}. ");
            let mut others: Vec<&(&str, f64, f64)> =
                ratios.iter().filter(|r| r.0 != "baseline").collect();
            others.sort_by(|a, b| b.2.total_cmp(&a.2));
            let factors: Vec<String> = others
                .iter()
                .filter(|r| r.0 != "paper" && r.0 != GEOMETRY)
                .map(|&&(name, f, q)| {
                    let verdict = if q > 1.0 {
                        format!("{:.0} % more error than the baseline", (q - 1.0) * 100.0)
                    } else {
                        format!("{:.0} % less error than the baseline", (1.0 - q) * 100.0)
                    };
                    format!("`{name}` {f:.4} ({q:.2}×, {verdict})")
                })
                .collect();
            if !factors.is_empty() {
                let _ = write!(
                    s,
                    "Swapping one factor, from the most error to the least: {}. ",
                    factors.join("; ")
                );
            }
            if let Some(&&(_, f, q)) = others.iter().find(|r| r.0 == "paper") {
                let _ = write!(
                    s,
                    "The paper's method together: mean FLIP {f:.4}, {q:.2}× the baseline's \
                     (the baseline has {:.0} % {} error)",
                    (1.0 - 1.0 / q).abs() * 100.0,
                    if q >= 1.0 { "less" } else { "more" }
                );
                // Where the two differ most: the buckets' ratios.
                let parts = buckets(summary, "paper", "baseline", false);
                if !parts.is_empty() {
                    let _ = write!(s, ": {}", parts.join(", "));
                }
                s += ". ";
            }
            // The yardstick: how far the stream is from the triangles drawn at 1×, per bucket.
            let row = |name: &str| summary.rows.iter().find(|r| r[0] == name);
            let parts = buckets(summary, "baseline", GEOMETRY, true);
            if let (Some(g), Some(bl), false) = (row(GEOMETRY), row("baseline"), parts.is_empty()) {
                let _ = write!(
                    s,
                    "Against full geometry drawn at 1× (the same triangles as the reference, \
                     without its supersampling), the baseline's mean FLIP is {}; coverage IoU \
                     {} against {}. ",
                    parts.join(", "),
                    bl[3],
                    g[3]
                );
            }
        }
        None => s += "The baseline was not measured. ",
    }
    let _ = write!(
        s,
        "The distance buckets and the from-below column are the mean FLIP of the cameras \
         in them; `atlas_gpu_mib` is the atlas memory each row needs (the cost of the \
         larger bakes). Variants measured: {}.",
        variants
            .iter()
            .map(|v| format!("`{}`", v.name))
            .collect::<Vec<_>>()
            .join(", ")
    );
    if !failed.is_empty() {
        let _ = write!(s, "\n\nNot measured (failed): {}.", failed.join("; "));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn binned_averages_each_occupied_bin_and_drops_points_outside() {
        let pts = [
            (0.5, 1.0),
            (0.7, 3.0),
            (2.5, 5.0),
            (9.0, 7.0),
            (-1.0, 100.0),
        ];
        let got = binned(pts.into_iter(), &[0.0, 1.0, 2.0, 3.0, 10.0]);
        // [0, 1): two points; [1, 2): empty, left out; [2, 3): one; [3, 10): one; −1 is outside.
        assert_eq!(got, vec![(0.6, 2.0), (2.5, 5.0), (9.0, 7.0)]);
        assert!(binned(pts.into_iter(), &[0.0]).is_empty());
    }
}
