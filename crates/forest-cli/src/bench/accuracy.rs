//! Speed against accuracy: every setting of every method, mean FLIP against the 4×4
//! supersampled full-geometry reference versus GPU frame time, with each method's Pareto front,
//! at a close-up, a mid-range and a bird's-eye view, and over a walkthrough of seeded random
//! eye-height cameras inside the forest; then the same walkthrough through a forest at real
//! tree sizes and the demo's density (`walkthrough-real`).

use std::path::Path;

use anyhow::{Context, Result};
use forest_baselines::geometry::{Lods, MeshMethod, Stochastic, downsample};
use forest_baselines::hybrid::{Hybrid, Near};
use forest_baselines::methods::{ForestRenderer, Method};
use forest_format::forest::Forest;
use forest_format::noise::SplitMix64;
use forest_render::Camera;
use forest_render::ForestView;
use forest_render::options::Background;
use forest_render::target::Target;
use glam::Vec3;

use super::chart::{Chart, Series, pareto_front};
use super::report::Section;
use super::{Bench, Table, ms};

/// Supersampling of the reference (per axis).
pub const REFERENCE_SS: u32 = 4;

/// The accuracy forest: its size and viewport.
pub fn scene(b: &Bench) -> (u32, f32, (u32, u32)) {
    if b.quick {
        (150, 40.0, (160, 120))
    } else {
        (3000, 170.0, (400, 300))
    }
}

/// A 60° camera at `eye` looking at `target` over a forest of side `side` metres (near plane
/// 5 cm, far plane 3 sides), refining to `epsilon` pixels.
pub fn look_at(eye: Vec3, target: Vec3, side: f32, viewport: (u32, u32), epsilon: f32) -> Camera {
    Camera {
        eye,
        target,
        fov_y_deg: 60.0,
        near: 0.05,
        far: side * 3.0,
        viewport,
        epsilon,
    }
}

/// Base of the tree nearest `p` (ground level), and its scale.
pub fn nearest_tree(forest: &Forest, p: Vec3) -> (Vec3, f32) {
    forest
        .instances
        .iter()
        .map(|i| (Vec3::from_array(i.position), i.scale))
        .min_by(|a, b| a.0.distance(p).total_cmp(&b.0.distance(p)))
        .unwrap_or((Vec3::ZERO, 1.0))
}

/// A point at eye height near `start`, stepping towards the forest's centre, with no tree
/// base within `clearance` metres (so the camera is not inside a crown).
pub fn clear_eye(forest: &Forest, start: Vec3, clearance: f32) -> Vec3 {
    let step = -start.normalize_or_zero();
    (0..200)
        .map(|k| start + step * k as f32)
        .find(|p| {
            let (t, s) = nearest_tree(forest, *p);
            Vec3::new(t.x - p.x, 0.0, t.z - p.z).length() >= clearance * s
        })
        .unwrap_or(start)
}

/// The three views: close-up of the tree nearest the centre, mid-range inside the forest
/// (from a spot clear of crowns, `clearance` = the largest crown radius), bird's-eye over it.
pub fn views(
    forest: &Forest,
    side: f32,
    viewport: (u32, u32),
    clearance: f32,
) -> Vec<(&'static str, Camera)> {
    let (tree, scale) = nearest_tree(forest, Vec3::ZERO);
    let cam = |eye: Vec3, target: Vec3| Camera {
        eye,
        target,
        fov_y_deg: 60.0,
        near: 0.1,
        far: side * 3.0,
        viewport,
        epsilon: 16.0,
    };
    vec![
        (
            "close-up",
            cam(
                tree + Vec3::new(4.0 * scale, 1.7, 5.0 * scale),
                tree + Vec3::new(0.0, 2.5 * scale, 0.0),
            ),
        ),
        ("mid-range", {
            let eye = clear_eye(forest, Vec3::new(0.0, 1.7, side * 0.25), clearance);
            let eye = eye.with_y(forest.ground_height(eye.x, eye.z) + 1.7);
            let (tx, tz) = (eye.x - 5.0, eye.z - side * 0.25);
            cam(eye, Vec3::new(tx, forest.ground_height(tx, tz) + 3.0, tz))
        }),
        (
            "birds-eye",
            cam(Vec3::new(0.0, side * 0.35, side * 0.6), Vec3::ZERO),
        ),
    ]
}

use forest_format::results_csv::{ACCURACY_COLUMNS as COLUMNS, accuracy_columns as columns};

/// Seed of the walkthrough cameras.
pub const WALK_SEED: u64 = 0x3a1f_2c77;

/// `n` seeded random eye-height cameras inside the forest, as a walkthrough meets them: eyes
/// 1.7 m above the forest's ground anywhere in the inner half of the forest (inside crowns
/// too: none is rejected), any heading, pitched −10°…+30°.
pub fn walkthrough(forest: &Forest, side: f32, viewport: (u32, u32), n: usize) -> Vec<Camera> {
    let mut rng = SplitMix64(WALK_SEED);
    (0..n)
        .map(|_| {
            let x = (rng.next_f32() - 0.5) * side * 0.5;
            let z = (rng.next_f32() - 0.5) * side * 0.5;
            let heading = rng.next_f32() * std::f32::consts::TAU;
            let pitch = (-10.0 + 40.0 * rng.next_f32()).to_radians();
            let eye = Vec3::new(x, forest.ground_height(x, z) + 1.7, z);
            let dir = Vec3::new(
                heading.cos() * pitch.cos(),
                pitch.sin(),
                heading.sin() * pitch.cos(),
            );
            Camera {
                eye,
                target: eye + dir * 10.0,
                fov_y_deg: 60.0,
                near: 0.1,
                far: side * 3.0,
                viewport,
                epsilon: 16.0,
            }
        })
        .collect()
}

/// The 4×4 supersampled full-geometry reference of `cam`, downsampled.
pub fn reference(b: &Bench, r: &mut ForestRenderer, cam: &Camera) -> Result<image::RgbaImage> {
    let (w, h) = cam.viewport;
    let big = Target::new(&b.ctx, w * REFERENCE_SS, h * REFERENCE_SS);
    let mut c = *cam;
    c.viewport = (w * REFERENCE_SS, h * REFERENCE_SS);
    b.measure(r, Method::Mesh(MeshMethod::Reference), &c, &big, 0)?;
    Ok(downsample(&big.read(&b.ctx), REFERENCE_SS))
}

/// Every (method, parameter label) setting the suite sweeps.
pub fn settings(quick: bool) -> Vec<(Method, String)> {
    let mut s = Vec::new();
    let eps: &[f32] = if quick {
        &[4.0, 16.0]
    } else {
        &[1.0, 2.0, 4.0, 8.0, 16.0, 32.0]
    };
    for &e in eps {
        s.push((Method::Quads, format!("eps={e}")));
    }
    s.push((Method::Impostor, "level 0".into()));
    s.push((
        Method::Mesh(MeshMethod::Full { depth_sort: true }),
        "1x".into(),
    ));
    let st: &[(f32, f32)] = if quick {
        &[(5.0, 0.5)]
    } else {
        &[
            (2.0, 0.5),
            (5.0, 0.5),
            (15.0, 0.5),
            (40.0, 0.5),
            (5.0, 0.3),
            (5.0, 0.7),
        ]
    };
    for &(d0, h) in st {
        s.push((
            Method::Mesh(MeshMethod::Stochastic(Stochastic {
                d0,
                h,
                ..Default::default()
            })),
            format!("d0={d0} h={h}"),
        ));
    }
    for &e in eps {
        s.push((
            Method::Hybrid(Hybrid::default()),
            format!("eps={e} near=auto"),
        ));
    }
    if !quick {
        for near in [5.0, 10.0, 20.0] {
            s.push((
                Method::Hybrid(Hybrid {
                    near: Near::Metres(near),
                    ..Default::default()
                }),
                format!("eps=4 near={near}"),
            ));
        }
    }
    let lod: &[f32] = if quick {
        &[1.0]
    } else {
        &[0.25, 0.5, 1.0, 2.0]
    };
    for &k in lod {
        let d = Lods::default().distances.map(|x| x * k);
        s.push((
            Method::Mesh(MeshMethod::Lods(Lods { distances: d })),
            format!("distances={}/{}/{}", d[0], d[1], d[2]),
        ));
    }
    s
}

/// The ε a setting renders with (its label's, else 16).
fn epsilon_of(param: &str) -> f32 {
    param
        .strip_prefix("eps=")
        .and_then(|e| e.split(' ').next()?.parse().ok())
        .unwrap_or(16.0)
}

/// Trees of the real-size walkthrough's forest, and its ground per tree (m²): the demo's
/// density, species at their mature heights.
pub fn real_scene(b: &Bench) -> (u32, f32) {
    if b.quick { (150, 60.0) } else { (3000, 60.0) }
}

/// Run the suite.
pub fn run(b: &Bench) -> Result<Section> {
    let (trees, side, viewport) = scene(b);
    let forest = b.forest(trees, side, 7)?;
    let target = Target::new(&b.ctx, viewport.0, viewport.1);
    let mut table = Table::new(&columns());
    let walk = walk_cameras(b.quick);
    let mut groups: Vec<(&str, Vec<Camera>)> = views(&forest, side, viewport, b.clearance())
        .into_iter()
        .map(|(v, c)| (v, vec![c]))
        .collect();
    groups.push(("walkthrough", walkthrough(&forest, side, viewport, walk)));
    let chosen = |list: &[String], name: &str| list.is_empty() || list.iter().any(|v| v == name);
    groups.retain(|(view, _)| chosen(&b.views, view));
    let settings: Vec<_> = settings(b.quick)
        .into_iter()
        .filter(|(m, _)| chosen(&b.methods, m.name()))
        .collect();
    if !groups.is_empty() {
        let mut r = b.renderer(&forest, viewport, 1.0, true, Background::Transparent)?;
        measure_views(b, &mut r, &target, &groups, &settings, &mut table)?;
    }
    // The same walkthrough through a forest as users build it: real tree sizes at the
    // demo's density.
    if chosen(&b.views, "walkthrough-real") {
        let (real_trees, area) = real_scene(b);
        let (real, real_side) = b.real_size_forest(real_trees, area, 7)?;
        let mut r = b.renderer(&real, viewport, 1.0, true, Background::Transparent)?;
        let cams = walkthrough(&real, real_side, viewport, walk);
        measure_views(
            b,
            &mut r,
            &target,
            &[("walkthrough-real", cams)],
            &settings,
            &mut table,
        )?;
    }
    b.write("accuracy.csv", &table.csv())?;
    report(b, table)
}

/// Measure every setting over each group of cameras (a view, or a walkthrough's cameras)
/// with `r`, a row per setting and group: means over the group's cameras.
fn measure_views(
    b: &Bench,
    r: &mut ForestRenderer,
    target: &Target,
    groups: &[(&str, Vec<Camera>)],
    settings: &[(Method, String)],
    table: &mut Table,
) -> Result<()> {
    r.set_pipeline_statistics(true);
    for (view, cams) in groups {
        let references = cams
            .iter()
            .map(|c| reference(b, r, c))
            .collect::<Result<Vec<_>>>()?;
        for &(method, ref param) in settings {
            // Means over the view's cameras (one, or the walkthrough's).
            let (mut frame_ms, mut flip, mut ssim, mut psnr, mut prims) = (0.0, 0.0, 0.0, 0.0, 0);
            let mut work = Vec::new();
            for (cam, reference) in cams.iter().zip(&references) {
                let mut c = *cam;
                c.epsilon = epsilon_of(param);
                let (s, t) = b.measure(r, method, &c, target, b.frames_for(method))?;
                // The measured frames gathered statistics (set above); the background is
                // transparent, so the image's alpha is the coverage.
                let img = target.read(&b.ctx);
                let m = forest_metrics::compare(reference, &img)?;
                work.push(super::ViewWork {
                    work: s.work.clone(),
                    covered: super::covered(&img),
                    counts: b.count(r, &c, target)?,
                });
                frame_ms += t;
                flip += f64::from(m.flip_mean);
                ssim += m.ssim;
                psnr += m.psnr;
                prims += s.primitives;
            }
            let n = cams.len().max(1) as f64;
            let (frame_ms, flip) = (frame_ms / n, flip / n);
            println!(
                "{view} {} {param}: {frame_ms:.2} ms, FLIP {flip:.4}, {} primitives",
                method.name(),
                prims / cams.len().max(1) as u64
            );
            let mut row = vec![
                method.name().into(),
                param.clone(),
                view.to_string(),
                ms(frame_ms),
                format!("{flip:.5}"),
                format!("{:.4}", ssim / n),
                format!("{:.2}", psnr / n),
                (prims / cams.len().max(1) as u64).to_string(),
            ];
            row.extend(super::work_cells(&work));
            table.push(row);
        }
    }
    Ok(())
}

/// Cameras of the walkthrough view.
fn walk_cameras(quick: bool) -> usize {
    if quick { 2 } else { 6 }
}

/// Charts, readings and text of the suite from its table (as measured, or as read back from
/// `accuracy.csv` by [`redraw`]).
pub fn report(b: &Bench, table: Table) -> Result<Section> {
    let (trees, side, viewport) = scene(b);
    let walk = walk_cameras(b.quick);
    let cell = |row: &[String], k: usize| row[k].parse::<f64>().unwrap_or(f64::NAN);
    let mut view_names: Vec<String> = Vec::new();
    for row in &table.rows {
        if !view_names.contains(&row[2]) {
            view_names.push(row[2].clone());
        }
    }
    let mut charts = Vec::new();
    let mut summary = Vec::new();
    for view in &view_names {
        charts.extend(view_charts(b, &table, view, viewport, &mut summary)?);
    }
    // Per walkthrough (model sizes, real sizes): the fragments each method's default setting
    // shades per covered pixel, and the hybrid against the quad stream at the same ε.
    let walks: Vec<String> = ["walkthrough", "walkthrough-real"]
        .iter()
        .filter(|v| view_names.iter().any(|n| n == *v))
        .map(|&view| {
            let rows: Vec<&Vec<String>> = table.rows.iter().filter(|r| r[2] == view).collect();
            // A run without the hybrid or the quad stream (`--methods`) has no comparison.
            let against = hybrid_against_quads(&rows, &cell);
            let fragments = fragments_per_pixel(&rows);
            if against.is_empty() {
                format!(
                    "In `{view}`, fragments shaded per covered pixel, each method at its default \
                     setting: {fragments}."
                )
            } else {
                format!(
                    "In `{view}`, the hybrid with its automatic switch: {against}. Fragments \
                     shaded per covered pixel, each method at its default setting: {fragments}."
                )
            }
        })
        .collect();
    let (real_trees, area) = real_scene(b);
    let real = if view_names.iter().any(|v| v == "walkthrough-real") {
        format!(
            "; `walkthrough-real` is the same walk through a forest as users build it: \
             {real_trees} trees at their species' mature heights (oak and ash 15–25 m, pine \
             20–35 m, aspen 12–20 m, bush 1–3 m) at the demo's {area:.0} m² per tree"
        )
    } else {
        String::new()
    };
    let hybrid_sharpen = f64::from(forest_baselines::hybrid::HYBRID_SHARPEN_DEFAULT)
        / f64::from(forest_render::gpu_types::WEIGHT_ONE);
    let switches = b.switch_summary();
    let text = format!(
        "{trees} trees over {side:.0} m, {}x{}, transparent background (trees only). The \
         reference is full geometry supersampled 4×4; every other image is compared with it \
         (mean FLIP, lower is better). The quad stream sweeps ε, stochastic simplification d0 \
         and h, the discrete LODs their switch distances (×¼ to ×2 of 15/40/100 m); impostors \
         and full geometry at 1× are single points. Lines are each method's Pareto front \
         (nothing both faster and more accurate). On a CPU rasteriser full geometry and \
         stochastic simplification are timed over one frame. The hybrid draws trees nearer \
         than its switch distance as full geometry and the rest as the quad stream, its aspects \
         sharpened by {hybrid_sharpen:.1} (`near=auto`: per species, where its finest quads project to the \
         width at which its bake measured the stream against the triangles, at every ε: \
         {switches}). The walkthrough \
         view is the mean over {walk} seeded random eye-height cameras inside the forest (seed \
         {WALK_SEED:#x}; none rejected){real}.\n\nThe work charts put the same settings against the shader invocations a \
         frame asks of a GPU (pipeline-statistics queries), which a CPU rasteriser's times \
         distort: it charges triangles far more than a GPU does. Fragments are counted twice: \
         lavapipe's pipeline statistics count them per 4×4 stamp; the exact counts are tree \
         fragment invocations, helper lanes excluded, per pixel covered by a shown fragment \
         (1 is the limit of one shaded fragment per pixel), with the 2×2-quad lanes a GPU \
         would run and the shares that showed nothing (transparent) or were shown behind an \
         opaque fragment (hidden).\n\n{}\n\n{}",
        viewport.0,
        viewport.1,
        walks.join("\n\n"),
        summary
            .iter()
            .map(|s| format!("- {s}"))
            .collect::<Vec<_>>()
            .join("\n")
    );
    Ok(Section {
        title: "Accuracy against speed".into(),
        text,
        table,
        charts,
    })
}

/// The charts of one view of the table (speed and, where counted, work against accuracy),
/// each method's reading added to `summary`; the charts' names.
fn view_charts(
    b: &Bench,
    table: &Table,
    view: &str,
    viewport: (u32, u32),
    summary: &mut Vec<String>,
) -> Result<Vec<String>> {
    let cell = |row: &[String], k: usize| row[k].parse::<f64>().unwrap_or(f64::NAN);
    let mut charts = Vec::new();
    let series = per_method(table, view, |row| Some(cell(row, 3)));
    // The reading: each method's best FLIP and the fastest setting within 0.005 of the best
    // overall.
    let best = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1))
        .fold(f64::INFINITY, f64::min);
    for s in &series {
        let front = pareto_front(&s.points);
        let good = front.iter().find(|p| p.1 <= best + 0.005);
        summary.push(format!(
            "{view}, {}: best FLIP {:.4}{}",
            s.name,
            front.last().map(|p| p.1).unwrap_or(f64::NAN),
            good.map(|p| format!(", within 0.005 of the best at {:.2} ms", p.0))
                .unwrap_or_default()
        ));
    }
    let stem = format!("accuracy_{view}");
    b.chart(
        &stem,
        &Chart {
            title: format!(
                "Speed against accuracy: {view} ({}x{})",
                viewport.0, viewport.1
            ),
            x_label: "GPU ms per frame".into(),
            y_label: "mean FLIP against the reference".into(),
            log_x: true,
            series,
            ..Default::default()
        },
    )?;
    charts.push(stem);
    // The same settings by the work they ask of a GPU (shader invocations: vertex,
    // fragment and compute) instead of lavapipe's time, where the table has the counts.
    let invocations = |row: &[String]| {
        let k = COLUMNS.len();
        let v = [k + 2, k + 4, k + 5].map(|i| row.get(i).and_then(|c| c.parse::<f64>().ok()));
        Some(v[0]? + v[1]? + v[2]?)
    };
    let work_series = per_method(table, view, invocations);
    if !work_series.is_empty() {
        let stem = format!("accuracy_work_{view}");
        b.chart(
            &stem,
            &Chart {
                title: format!(
                    "Work against accuracy: {view} ({}x{})",
                    viewport.0, viewport.1
                ),
                x_label: "shader invocations per frame (vertex + fragment + compute)".into(),
                y_label: "mean FLIP against the reference".into(),
                log_x: true,
                series: work_series,
                ..Default::default()
            },
        )?;
        charts.push(stem);
    }
    Ok(charts)
}

/// One series per method (column 0) of `view`'s rows, each point `(x(row), FLIP)` (rows
/// without an `x` left out), drawn with its Pareto front.
fn per_method(table: &Table, view: &str, x: impl Fn(&[String]) -> Option<f64>) -> Vec<Series> {
    let mut series: Vec<Series> = Vec::new();
    for row in table.rows.iter().filter(|r| r[2] == view) {
        let Some(x) = x(row) else { continue };
        let point = (x, row[4].parse::<f64>().unwrap_or(f64::NAN));
        match series.iter_mut().find(|s| s.name == row[0]) {
            Some(s) => s.points.push(point),
            None => series.push(Series {
                name: row[0].clone(),
                points: vec![point],
                front: true,
                ..Default::default()
            }),
        }
    }
    series
}

/// The hybrid (`near=auto`) against the quad stream at the same ε, over `rows` of one view.
fn hybrid_against_quads(rows: &[&Vec<String>], cell: &dyn Fn(&[String], usize) -> f64) -> String {
    rows.iter()
        .filter(|r| r[0] == "hybrid" && r[1].ends_with("near=auto"))
        .filter_map(|h| {
            let eps = h[1].split(' ').next()?;
            let q = rows.iter().find(|r| r[0] == "quads" && r[1] == eps)?;
            Some(format!(
                "{eps}: {:.2}× the quad stream's frame time, FLIP {:.4} against {:.4}",
                cell(h, 3) / cell(q, 3),
                cell(h, 4),
                cell(q, 4)
            ))
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// The setting of each method the report quotes its work at: the defaults of `forest render`
/// (ε 16, the LODs' 15/40/100 m, stochastic d0 15 m).
const DEFAULT_PARAMS: [&str; 6] = [
    "eps=16",
    "eps=16 near=auto",
    "level 0",
    "1x",
    "d0=15 h=0.5",
    "distances=15/40/100",
];

/// Fragments per covered pixel of each method in `rows` at its default setting (else its
/// first): lavapipe's stamps and the exact counts, each where the table has them.
fn fragments_per_pixel(rows: &[&Vec<String>]) -> String {
    let k = COLUMNS.len();
    let num = |row: &[String], i: usize| row.get(k + i).and_then(|c| c.parse::<f64>().ok());
    let mut methods: Vec<&str> = Vec::new();
    for r in rows {
        if !methods.contains(&r[0].as_str()) {
            methods.push(&r[0]);
        }
    }
    let mut out: Vec<String> = Vec::new();
    for m in methods {
        let of_method = || rows.iter().filter(|r| r[0] == m);
        let Some(row) = of_method()
            .find(|r| DEFAULT_PARAMS.contains(&r[1].as_str()))
            .or_else(|| of_method().next())
        else {
            continue;
        };
        let mut parts = Vec::new();
        if let Some(stamps) = num(row, 8) {
            parts.push(format!("{stamps:.2} stamp fragments"));
        }
        if let (Some(f), Some(q), Some(t), Some(h)) =
            (num(row, 10), num(row, 13), num(row, 14), num(row, 15))
        {
            parts.push(format!(
                "exactly {f:.1} ({q:.1} 2×2-quad lanes, {:.0} % transparent, {:.0} % hidden)",
                100.0 * t,
                100.0 * h
            ));
        }
        if !parts.is_empty() {
            out.push(format!("{m} ({}) {}", row[1], parts.join("; ")));
        }
    }
    out.join("; ")
}

/// Rebuild the charts and the report section from `accuracy.csv` in the results folder,
/// without measuring (after a change to how results are drawn).
pub fn redraw(b: &Bench) -> Result<Section> {
    let path = b.out.join("accuracy.csv");
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("reading {} (run the accuracy suite first)", path.display()))?;
    report(b, read_table(&text, &path)?)
}

/// The table of an `accuracy.csv` (`text`, read from `path`, which errors name), each row
/// checked ([`forest_format::results_csv::read_accuracy`]).
fn read_table(text: &str, path: &Path) -> Result<Table> {
    let t = forest_format::results_csv::read_accuracy(text)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    Ok(Table {
        header: t.header,
        rows: t.rows,
    })
}
