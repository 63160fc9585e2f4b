//! A walkthrough of 100 views through the forest (the paper's Figure 7): frame time and
//! primitives per view for every method, through a forest at the models' sizes and through
//! one at real tree sizes.

use anyhow::Result;
use forest_baselines::geometry::{Lods, MeshMethod, Stochastic};
use forest_baselines::methods::Method;
use forest_render::Camera;
use forest_render::options::Background;
use forest_render::target::Target;
use glam::Vec3;

use super::chart::{Chart, Series};
use super::report::Section;
use super::{Bench, Table, WORK_COLUMNS, ms, work_cells};

/// View `i` of `n` along the walkthrough of a forest of side `side`: eye height 1.7 m above
/// the ground `ground(x, z)`, across the forest on a gentle S-curve, looking ahead (level)
/// and swinging left and right.
pub fn view(
    i: u32,
    n: u32,
    side: f32,
    viewport: (u32, u32),
    ground: impl Fn(f32, f32) -> f32,
) -> Camera {
    let t = i as f32 / (n.max(2) - 1) as f32;
    let x = (t - 0.5) * side * 0.7;
    let z = (t * std::f32::consts::TAU).sin() * side * 0.1;
    let yaw = (t * 3.0 * std::f32::consts::TAU).sin() * 0.6;
    let eye = Vec3::new(x, ground(x, z) + 1.7, z);
    Camera {
        eye,
        target: eye + Vec3::new(yaw.cos(), 0.05, yaw.sin()) * 50.0,
        fov_y_deg: 60.0,
        near: 0.1,
        far: side * 3.0,
        viewport,
        epsilon: 16.0,
    }
}

/// One walk's forest: its CSV and chart stem, how the report names it, and its forest.
struct Walk {
    stem: &'static str,
    label: String,
    forest: forest_format::forest::Forest,
    side: f32,
}

/// Run the suite: the walk through the model-size forest (`path.csv`), then the same walk
/// through a forest at real tree sizes and the demo's density (`path_real.csv`).
pub fn run(b: &Bench) -> Result<Section> {
    let (trees, side, viewport, views) = if b.quick {
        (300, 60.0, (160, 120), 4)
    } else {
        (10_000, 320.0, (400, 300), 100)
    };
    // As many trees at real sizes, at the demo's density.
    let area = super::accuracy::real_scene(b).1;
    let (real, real_side) = b.real_size_forest(trees, area, 11)?;
    let walks = [
        Walk {
            stem: "path",
            label: format!("{trees} trees at their models' sizes over {side:.0} m"),
            forest: b.forest(trees, side, 11)?,
            side,
        },
        Walk {
            stem: "path_real",
            label: format!(
                "{} trees at their species' mature heights, {area:.0} m² per tree, over \
                 {real_side:.0} m",
                real.instances.len()
            ),
            forest: real,
            side: real_side,
        },
    ];
    let mut texts = Vec::new();
    let mut summary = Table::new(&["forest", "method", "mean_ms", "worst_ms", "views_measured"]);
    for w in &walks {
        let (text, means) = walk(b, w, viewport, views)?;
        texts.push(text);
        for (m, mean, worst, stride) in &means {
            summary.push(vec![
                w.stem.to_string(),
                m.to_string(),
                ms(*mean),
                ms(*worst),
                views.div_ceil(*stride as u32).to_string(),
            ]);
        }
    }
    Ok(Section {
        title: "Walkthrough (Figure 7)".into(),
        text: texts.join("\n\n"),
        table: summary,
        charts: walks.iter().map(|w| w.stem.to_string()).collect(),
    })
}

/// A method's mean and worst frame time (ms) over a walk, and the stride of views measured.
type Means = Vec<(&'static str, f64, f64, usize)>;

/// Measure every method over `views` views of `w`'s walk; write its CSV and chart. Returns
/// the report's paragraph and each method's means.
fn walk(b: &Bench, w: &Walk, viewport: (u32, u32), views: u32) -> Result<(String, Means)> {
    let (forest, side) = (&w.forest, w.side);
    let geometry = !b.models.is_empty();
    let mut r = b.renderer(forest, viewport, 16.0, geometry, Background::Sky)?;
    let target = Target::new(&b.ctx, viewport.0, viewport.1);
    let mut methods = vec![(Method::Quads, 1), (Method::Impostor, 1)];
    if geometry {
        // On a CPU rasteriser full geometry and stochastic simplification take seconds per
        // frame: every 10th view is measured (said in the report), the rest every view.
        let stride = if b.cpu && !b.quick { 10 } else { 1 };
        methods.push((Method::Mesh(MeshMethod::Lods(Lods::default())), 1));
        methods.push((
            Method::Mesh(MeshMethod::Stochastic(Stochastic::default())),
            stride,
        ));
        methods.push((Method::Mesh(MeshMethod::Full { depth_sort: true }), stride));
        methods.push((
            Method::Hybrid(forest_baselines::hybrid::Hybrid::default()),
            1,
        ));
    }
    let mut columns = vec!["view", "method", "frame_ms", "primitives", "visible_trees"];
    columns.extend(WORK_COLUMNS);
    let mut table = Table::new(&columns);
    let mut series = Vec::new();
    let mut means = Vec::new();
    for (method, stride) in methods {
        let mut s = Series {
            name: method.name().into(),
            line: true,
            ..Default::default()
        };
        for i in (0..views).step_by(stride) {
            let cam = view(i, views, side, viewport, |x, z| forest.ground_height(x, z));
            // One measured frame per view: the hundred views are the samples.
            let (st, t) = b.measure(&mut r, method, &cam, &target, 1)?;
            let work = b.work(&mut r, method, &cam, &target)?;
            s.points.push((f64::from(i), t));
            let mut row = vec![
                i.to_string(),
                method.name().into(),
                ms(t),
                st.primitives.to_string(),
                st.visible_trees.to_string(),
            ];
            row.extend(work_cells(&[work]));
            table.push(row);
        }
        let mean = s.points.iter().map(|p| p.1).sum::<f64>() / s.points.len().max(1) as f64;
        let worst = s.points.iter().map(|p| p.1).fold(0.0, f64::max);
        println!(
            "{}, {}: mean {mean:.2} ms, worst {worst:.2} ms",
            w.stem,
            method.name()
        );
        means.push((method.name(), mean, worst, stride));
        series.push(s);
    }
    b.write(&format!("{}.csv", w.stem), &table.csv())?;
    b.chart(
        w.stem,
        &Chart {
            title: format!(
                "Walkthrough: {}, {views} views, {}x{}",
                w.label, viewport.0, viewport.1
            ),
            x_label: "view along the path".into(),
            y_label: "GPU ms per frame".into(),
            log_y: true,
            series,
            ..Default::default()
        },
    )?;
    let quads = means.first().map(|m| m.1).unwrap_or(f64::NAN);
    let text = format!(
        "{views} views along an S-shaped walk at eye height through {} (the paper's Figure \
         7; `{}.csv`), {}x{}, ε 16, default parameters.\n\n{}",
        w.label,
        w.stem,
        viewport.0,
        viewport.1,
        means
            .iter()
            .map(|(m, mean, worst, stride)| format!(
                "- {m}: mean {mean:.2} ms, worst {worst:.2} ms ({:.1}× the quad stream's mean){}",
                mean / quads,
                if *stride > 1 {
                    format!(", every {stride}th view measured")
                } else {
                    String::new()
                }
            ))
            .collect::<Vec<_>>()
            .join("\n")
    );
    Ok((text, means))
}
