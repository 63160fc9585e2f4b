//! `forest bench all --quick`: every suite runs on tiny atlases and writes its CSV (with the
//! stable columns), its charts and REPORT.md. Figures are not asserted, only produced.

mod cli;

use std::path::{Path, PathBuf};

use cli::{bake_small, forest, model};

#[test]
fn quick_benchmarks_write_every_table_chart_and_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let results = run_quick_benchmarks(dir.path());
    every_table_has_its_columns(&results);
    every_method_is_in_the_tables(&results);
    the_work_columns_count_alike(&results);
    the_walkthroughs_charts_and_report(&results);
}

/// `forest bench all --quick` on two species baked small into `d`; its results folder.
fn run_quick_benchmarks(d: &Path) -> PathBuf {
    let mut atlases = Vec::new();
    for s in ["bush", "pine"] {
        let atlas = d.join(format!("{s}.atlas"));
        bake_small(s, &atlas, 32, 5);
        atlases.push(atlas.display().to_string());
    }
    let results = d.join("results");
    let out = forest(&[
        "bench",
        "all",
        "--quick",
        "--species",
        &atlases.join(","),
        "--models",
        &format!("{},{}", model("bush"), model("pine")),
        "--out",
        results.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    results
}

/// A table's header line.
fn header(results: &Path, f: &str) -> String {
    std::fs::read_to_string(results.join(f))
        .unwrap_or_else(|e| panic!("{f}: {e}"))
        .lines()
        .next()
        .unwrap()
        .to_string()
}

/// Every table's stable columns, the walk at real tree sizes and the fidelity variants.
fn every_table_has_its_columns(results: &Path) {
    let header = |f: &str| header(results, f);
    assert!(
        header("table1.csv")
            .starts_with("trees,view,visible_trees,quads,cull_ms,refine_ms,draw_ms,total_ms")
    );
    assert!(header("accuracy.csv").starts_with("method,param,view,frame_ms,flip_mean,ssim,psnr"));
    assert!(header("stability.csv").starts_with("case,method,flip_mean,flicker,pops"));
    assert!(header("storage.csv").starts_with("method,species,disk_bytes,gpu_bytes"));
    assert_eq!(
        header("wind.csv"),
        "case,distance_m,method,flip_static,flip_wind,wind_over_static,motion_step,motion_px,\
         motion_over_reference,motion_1_over_reference,change_over_reference,flicker_frames,\
         frame_ms_calm,frame_ms_wind,time_ratio"
    );
    assert_eq!(
        header("wind_switch.csv"),
        "species,switch_m,crown_motion_px,worst_disagreement_px"
    );
    assert_eq!(
        header("colour.csv"),
        "case,method,trees,mean_delta_e,worst_delta_e,within_2,mean_delta_l"
    );
    assert_eq!(
        header("colour_trees.csv"),
        "view,case,instance,species,distance_m,radius_px,method,delta_e,delta_l"
    );
    assert_eq!(
        header("colour_cost.csv"),
        "method,frame_ms_plain,frame_ms_varied,time_ratio"
    );
    let colour = std::fs::read_to_string(results.join("colour.csv")).unwrap();
    for m in [
        "quads",
        "impostor",
        "geometry",
        "stochastic",
        "lods",
        "hybrid",
    ] {
        for case in ["own colours", "\"varied, autumn\""] {
            assert!(
                colour
                    .lines()
                    .any(|l| l.starts_with(&format!("{case},{m},"))),
                "{case} {m}"
            );
        }
    }
    assert_eq!(
        header("fidelity.csv"),
        "variant,species,camera,distance_radii,elevation_deg,azimuth_deg,between_directions,\
         epsilon,quads,flip_mean,iou,frame_ms"
    );
    // The walk through the model-size forest and through one at real tree sizes: the same
    // columns, every method.
    assert_eq!(header("path.csv"), header("path_real.csv"));
    let path_real = std::fs::read_to_string(results.join("path_real.csv")).unwrap();
    for m in ["quads", "impostor", "lods", "hybrid"] {
        assert!(
            path_real.lines().any(|l| l.contains(&format!(",{m},"))),
            "{m}"
        );
    }
    assert!(results.join("path_real.png").is_file());
    for f in [
        "path.csv",
        "budget.csv",
        "storage_forest.csv",
        "storage_stream.csv",
        "fidelity_summary.csv",
    ] {
        assert!(!header(f).is_empty(), "{f}");
    }
    // Quick mode's fidelity variants: the baseline, one run-time swap, the paper's method and
    // the yardstick (full geometry at 1x).
    let fidelity = std::fs::read_to_string(results.join("fidelity.csv")).unwrap();
    for v in ["baseline", "blend=dither", "paper", "full geometry 1x"] {
        assert!(
            fidelity.lines().any(|l| l.starts_with(&format!("{v},"))),
            "{v}"
        );
    }
    for c in [
        "fidelity-distance",
        "fidelity-elevation",
        "colour_own",
        "colour_autumn",
    ] {
        assert!(results.join(format!("{c}.png")).is_file(), "{c}.png");
        assert!(results.join(format!("{c}.svg")).is_file(), "{c}.svg");
    }
    // Each method's worst tree beside the reference.
    assert!(results.join("colour_worst_quads.png").is_file());
}

/// Every method appears in the accuracy and stability tables.
fn every_method_is_in_the_tables(results: &Path) {
    let accuracy = std::fs::read_to_string(results.join("accuracy.csv")).unwrap();
    let stability = std::fs::read_to_string(results.join("stability.csv")).unwrap();
    let wind = std::fs::read_to_string(results.join("wind.csv")).unwrap();
    for m in [
        "quads",
        "impostor",
        "geometry",
        "stochastic",
        "lods",
        "hybrid",
    ] {
        assert!(
            accuracy.lines().any(|l| l.starts_with(&format!("{m},"))),
            "{m}"
        );
        assert!(
            stability.lines().any(|l| l.contains(&format!(",{m},"))),
            "{m}"
        );
        // In wind, on each of the four seeded cameras.
        for case in ["near", "mid", "far", "switch"] {
            assert!(
                wind.lines()
                    .any(|l| l.starts_with(&format!("{case},")) && l.contains(&format!(",{m},"))),
                "wind: {m} at {case}"
            );
        }
    }
}

/// The work columns, appended to Table 1, the path and the accuracy tables, with counts
/// wherever the adapter has pipeline statistics, and the exact fragment counts of every row.
fn the_work_columns_count_alike(results: &Path) {
    let work = "dispatches,draws,vertex_invocations,primitives_rasterised,fragment_invocations,\
                compute_invocations,gpu_mb,covered_pixels,fragments_per_covered_pixel,work_source,\
                exact_fragments_per_covered_pixel,exact_median,exact_p95,\
                quad_lanes_per_covered_pixel,transparent_share,hidden_share";
    for f in ["table1.csv", "path.csv", "path_real.csv", "accuracy.csv"] {
        let text = std::fs::read_to_string(results.join(f)).unwrap();
        let head = text.lines().next().unwrap();
        assert!(head.ends_with(work), "{f}: {head}");
        for row in text.lines().skip(1) {
            // The work cells are the last 16 (earlier cells may hold quoted commas).
            let cells: Vec<&str> = row.split(',').collect();
            let k = cells.len() - 16;
            let dispatches: u32 = cells[k].parse().unwrap_or_else(|_| panic!("{f}: {row}"));
            assert!(dispatches > 0, "{f}: {row}");
            let covered: u64 = cells[k + 7].parse().unwrap();
            if cells[k + 9] == "pipeline statistics" {
                let per_pixel = cells[k + 8];
                assert!(
                    covered == 0 || per_pixel.parse::<f64>().unwrap() >= 1.0,
                    "{f}: a covered pixel is shaded at least once: {row}"
                );
            }
            let exact: Vec<f64> = cells[k + 10..]
                .iter()
                .map(|c| c.parse().unwrap_or_else(|_| panic!("{f}: {row}")))
                .collect();
            let [mean, median, p95, lanes, transparent, hidden] = exact[..] else {
                unreachable!()
            };
            if covered > 0 {
                assert!(mean >= 1.0 && median >= 1.0 && p95 >= median, "{f}: {row}");
                assert!(lanes >= mean, "{f}: a GPU runs whole 2×2 quads: {row}");
            }
            assert!(
                (0.0..=1.0).contains(&transparent) && (0.0..=1.0).contains(&hidden),
                "{f}: {row}"
            );
            assert!(transparent + hidden <= 1.0 + 1e-3, "{f}: {row}");
        }
    }
    // Every table counts the same way: the adapter has pipeline statistics for all or none.
    let sources: std::collections::BTreeSet<String> =
        ["table1.csv", "path.csv", "path_real.csv", "accuracy.csv"]
            .iter()
            .flat_map(|f| {
                let text = std::fs::read_to_string(results.join(f)).unwrap();
                text.lines()
                    .skip(1)
                    .map(|l| l.split(',').rev().nth(6).unwrap().to_string())
                    .collect::<Vec<_>>()
            })
            .collect();
    assert_eq!(sources.len(), 1, "{sources:?}");
}

/// The work-against-accuracy charts, the walkthroughs, the budget, and the report's charts;
/// no scratch bake is left behind.
fn the_walkthroughs_charts_and_report(results: &Path) {
    let accuracy = std::fs::read_to_string(results.join("accuracy.csv")).unwrap();
    assert!(results.join("accuracy_work_walkthrough.png").is_file());
    // The walkthrough of random eye-height cameras, and the hybrid's switch choices.
    assert!(accuracy.lines().any(|l| l.contains(",walkthrough,")));
    // And the same walk through a forest at real tree sizes, every method.
    for m in ["quads", "impostor", "lods", "hybrid"] {
        assert!(
            accuracy
                .lines()
                .any(|l| l.starts_with(&format!("{m},")) && l.contains(",walkthrough-real,")),
            "{m}"
        );
    }
    assert!(results.join("accuracy_walkthrough-real.png").is_file());
    let budget = std::fs::read_to_string(results.join("budget.csv")).unwrap();
    assert!(budget.lines().any(|l| l.starts_with("hybrid near=auto,")));
    let report = std::fs::read_to_string(results.join("REPORT.md")).unwrap();
    let mut charts = 0;
    for line in report.lines().filter(|l| l.starts_with("![")) {
        let png = line.split("](").nth(1).unwrap().split(')').next().unwrap();
        let img = image::open(results.join(png)).unwrap_or_else(|e| panic!("{png}: {e}"));
        assert!(img.width() > 100);
        assert!(results.join(png.replace(".png", ".svg")).is_file());
        charts += 1;
    }
    assert!(charts >= 10, "{charts} charts in the report");
    for scratch in [".budget-atlases", ".fidelity-atlases"] {
        assert!(
            !results.join(scratch).exists(),
            "scratch bakes removed: {scratch}"
        );
    }
}
