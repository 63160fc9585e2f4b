//! The paper's Table 1: forests of 20k–120k trees over the same square kilometre, viewed from
//! inside and from above; visible trees, quads and the time of each pass of the quad stream.

use anyhow::Result;
use forest_baselines::methods::Method;
use forest_render::Camera;
use forest_render::options::Background;
use forest_render::target::Target;
use glam::Vec3;

use super::chart::{Chart, Series};
use super::report::Section;
use super::{Bench, Table, WORK_COLUMNS, ms, work_cells};

/// Side of the square every Table 1 forest covers (metres): forests differ in density.
const SIDE: f32 = 1000.0;

/// The two views of a forest of side `side`: inside at eye height, and from above.
pub fn views(side: f32) -> [(&'static str, Vec3, Vec3); 2] {
    [
        (
            "inside",
            Vec3::new(0.0, 1.7, 0.0),
            Vec3::new(-30.0, 4.0, -100.0),
        ),
        (
            "birds-eye",
            Vec3::new(0.0, side * 0.15, side * 0.5),
            Vec3::ZERO,
        ),
    ]
}

/// Run the suite.
pub fn run(b: &Bench) -> Result<Section> {
    let (sizes, viewport, side): (Vec<u32>, (u32, u32), f32) = if b.quick {
        (vec![500, 1000], (200, 150), 100.0)
    } else {
        (
            vec![20_000, 40_000, 60_000, 80_000, 100_000, 120_000],
            (800, 600),
            SIDE,
        )
    };
    let mut columns = vec![
        "trees",
        "view",
        "visible_trees",
        "quads",
        "cull_ms",
        "refine_ms",
        "draw_ms",
        "total_ms",
        "overflow",
        "device",
    ];
    columns.extend(WORK_COLUMNS);
    let mut table = Table::new(&columns);
    let target = Target::new(&b.ctx, viewport.0, viewport.1);
    let mut series: Vec<Series> = views(side)
        .iter()
        .map(|(v, _, _)| Series {
            name: format!("{v}: total"),
            line: true,
            ..Default::default()
        })
        .collect();
    for &trees in &sizes {
        let forest = b.forest(trees, side, 1)?;
        let mut r = b.renderer(&forest, viewport, 16.0, false, Background::Sky)?;
        for (k, (view, eye, target_pt)) in views(side).into_iter().enumerate() {
            let cam = Camera {
                eye,
                target: target_pt,
                fov_y_deg: 60.0,
                near: 0.1,
                far: side * 3.0,
                viewport,
                epsilon: 16.0,
            };
            let (s, p, _) = b.measure_passes(&mut r, Method::Quads, &cam, &target, b.frames)?;
            let work = b.work(&mut r, Method::Quads, &cam, &target)?;
            let (c, rf, d) = (p.cull_ms, p.refine_ms, p.draw_ms);
            series[k].points.push((f64::from(trees), c + rf + d));
            let mut row = vec![
                trees.to_string(),
                view.into(),
                s.visible_trees.to_string(),
                s.primitives.to_string(),
                ms(c),
                ms(rf),
                ms(d),
                ms(c + rf + d),
                s.overflow.to_string(),
                b.device.clone(),
            ];
            row.extend(work_cells(&[work]));
            table.push(row);
            println!(
                "{trees} trees, {view}: {} visible, {} quads, cull {c:.1} refine {rf:.1} draw {d:.1} ms",
                s.visible_trees, s.primitives
            );
        }
    }
    b.write("table1.csv", &table.csv())?;
    b.chart(
        "table1",
        &Chart {
            title: format!(
                "Table 1: quad stream frame time, {}x{}, ε 16",
                viewport.0, viewport.1
            ),
            x_label: "trees in the forest".into(),
            y_label: "GPU ms per frame".into(),
            series,
            ..Default::default()
        },
    )?;
    let rows = &table.rows;
    let total = |r: &Vec<String>| r[7].parse::<f64>().unwrap_or(0.0);
    // The work of each view of the largest forest (work columns follow the first ten).
    let work = rows
        .iter()
        .rev()
        .take(2)
        .rev()
        .map(|r| {
            let c = |k: usize| r.get(10 + k).map_or("", String::as_str);
            let pct = |k: usize| {
                c(k).parse::<f64>()
                    .map_or(String::new(), |v| format!("{:.0} %", 100.0 * v))
            };
            let stamps = if c(8).is_empty() {
                String::new()
            } else {
                format!("{} stamp fragments per covered pixel; ", c(8))
            };
            format!(
                "{} trees, {}: {} dispatches, {} vertex and {} fragment invocations for {} \
                 covered pixels ({stamps}exactly {} fragment invocations per covered pixel, \
                 median {}, 95th percentile {}, and {} 2×2-quad lanes; {} of them \
                 transparent and {} hidden), {} compute invocations, {} MB",
                r[0],
                r[1],
                c(0),
                c(2),
                c(4),
                c(7),
                c(10),
                c(11),
                c(12),
                c(13),
                pct(14),
                pct(15),
                c(5),
                c(6)
            )
        })
        .collect::<Vec<_>>()
        .join("; ");
    let text = format!(
        "The paper's Table 1: forests of {}–{} trees over the same {side:.0} m square (density \
         grows with the count), at {}x{} and ε = 16, from inside the forest and from above. \
         Frame time grows linearly with the visible trees and quads, as in the paper: from \
         {:.1} ms ({} trees, inside) to {:.1} ms ({} trees, bird's-eye). The overflow column \
         counts quads dropped for lack of buffer room (0 means the capacity formula held). \
         The work each frame asks of a GPU (pipeline statistics; lavapipe counts fragments per \
         4×4 stamp): {work}.",
        sizes.first().unwrap_or(&0),
        sizes.last().unwrap_or(&0),
        viewport.0,
        viewport.1,
        rows.first().map(total).unwrap_or(0.0),
        sizes.first().unwrap_or(&0),
        rows.last().map(total).unwrap_or(0.0),
        sizes.last().unwrap_or(&0),
    );
    Ok(Section {
        title: "Table 1: frame time against forest size".into(),
        text,
        table,
        charts: vec!["table1".into()],
    })
}
