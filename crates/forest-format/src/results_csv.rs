//! The results files the bench writes and `bench accuracy --redraw` reads back:
//! `accuracy.csv`'s columns and its checked reader. A file may come from anywhere, so every
//! row is checked whole: names usable in file names (views and methods name chart files),
//! every figure empty (not measured) or a finite number in its column's range.

/// The first columns of `accuracy.csv`: what was drawn, and its time and accuracy.
pub const ACCURACY_COLUMNS: [&str; 8] = [
    "method",
    "param",
    "view",
    "frame_ms",
    "flip_mean",
    "ssim",
    "psnr",
    "primitives",
];

/// The work columns the benches' tables end with: dispatches and draws, the pipeline
/// statistics' invocations, GPU megabytes, covered pixels and fragments per covered pixel,
/// where the counts came from, the exact fragment counts (mean, median, 95th percentile) and
/// 2×2-quad lanes per covered pixel, and the shares of invocations that showed nothing
/// (transparent) or were shown behind an opaque fragment (hidden).
pub const WORK_COLUMNS: [&str; 16] = [
    "dispatches",
    "draws",
    "vertex_invocations",
    "primitives_rasterised",
    "fragment_invocations",
    "compute_invocations",
    "gpu_mb",
    "covered_pixels",
    "fragments_per_covered_pixel",
    "work_source",
    "exact_fragments_per_covered_pixel",
    "exact_median",
    "exact_p95",
    "quad_lanes_per_covered_pixel",
    "transparent_share",
    "hidden_share",
];

/// Every column of `accuracy.csv`: [`ACCURACY_COLUMNS`], then [`WORK_COLUMNS`].
pub fn accuracy_columns() -> Vec<&'static str> {
    ACCURACY_COLUMNS
        .iter()
        .copied()
        .chain(WORK_COLUMNS)
        .collect()
}

/// A results table as read: its columns (one of the layouts [`read_accuracy`] knows) and
/// rows of exactly as many cells.
#[derive(Debug, Clone, PartialEq)]
pub struct ResultsTable {
    /// Column names.
    pub header: Vec<&'static str>,
    /// Rows, each checked by [`check_row`].
    pub rows: Vec<Vec<String>>,
}

/// The table of an `accuracy.csv`'s `text`, each row checked by [`check_row`]. Files written
/// before the work columns, or before the exact fragment counts (the first ten work
/// columns), are read as they are. Errors name the line (1 is the header).
pub fn read_accuracy(text: &str) -> Result<ResultsTable, String> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let all = accuracy_columns();
    let layouts = [
        &all[..],
        &all[..ACCURACY_COLUMNS.len() + 10],
        &ACCURACY_COLUMNS[..],
    ];
    let Some(layout) = layouts.into_iter().find(|l| **l == header[..]) else {
        return Err(format!(
            "unexpected columns {header:?}: expected those `bench accuracy` writes"
        ));
    };
    let mut table = ResultsTable {
        header: layout.to_vec(),
        rows: Vec::new(),
    };
    for (i, l) in lines.enumerate().filter(|(_, l)| !l.is_empty()) {
        let row: Vec<String> = l.split(',').map(str::to_string).collect();
        if row.len() != table.header.len() {
            return Err(format!(
                "line {}: a row of {} cells, expected {}",
                i + 2,
                row.len(),
                table.header.len()
            ));
        }
        check_row(&table.header, &row).map_err(|e| format!("line {}: {e}", i + 2))?;
        table.rows.push(row);
    }
    Ok(table)
}

/// A row of a results table as `--redraw` takes it: its names usable in file names (views
/// and methods name the charts), every figure empty (not measured) or a finite number in its
/// range: shares and FLIP in 0 to 1, SSIM in −1 to 1, the rest 0 or more.
pub fn check_row(header: &[&str], row: &[String]) -> Result<(), String> {
    for (name, cell) in header.iter().zip(row) {
        match *name {
            "method" | "param" | "view" => check_name(name, cell)?,
            "work_source" => {}
            _ if cell.is_empty() => {}
            _ => {
                let v: f64 = cell
                    .trim()
                    .parse()
                    .map_err(|_| format!("{name} is {cell:?}, not a number"))?;
                let (lo, hi) = match *name {
                    "flip_mean" | "transparent_share" | "hidden_share" => (0.0, 1.0),
                    "ssim" => (-1.0, 1.0),
                    _ => (0.0, f64::INFINITY),
                };
                if !v.is_finite() || v < lo || v > hi {
                    let range = if hi.is_finite() {
                        format!("{lo} to {hi}")
                    } else {
                        format!("a finite {lo} or more")
                    };
                    return Err(format!("{name} is {cell}: expected {range}"));
                }
            }
        }
    }
    Ok(())
}

/// A name from a results file that becomes part of a chart's file name: not empty (but a
/// method's parameter may be), no path separator, control character or leading dot.
pub fn check_name(what: &str, name: &str) -> Result<(), String> {
    let bad = name.starts_with('.')
        || name
            .chars()
            .any(|c| c == '/' || c == '\\' || c.is_control())
        || (name.is_empty() && what != "param");
    if bad {
        return Err(format!(
            "{what} {name:?} cannot name a chart file: no '/', '\\', control characters or \
             leading '.'"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(view: &str, frame_ms: &str, flip: &str) -> Vec<String> {
        let mut r: Vec<String> = accuracy_columns().iter().map(|_| String::new()).collect();
        r[0] = "quads".into();
        r[2] = view.into();
        r[3] = frame_ms.into();
        r[4] = flip.into();
        r
    }

    /// `--redraw` takes finite figures in their ranges and names the cell otherwise; names
    /// that would leave the results folder as chart paths are refused.
    #[test]
    fn redrawn_rows_are_checked_cell_by_cell() {
        let header = accuracy_columns();
        assert!(check_row(&header, &row("inside", "1.5", "0.2")).is_ok());
        assert!(check_row(&header, &row("inside", "1e308", "0")).is_ok());
        for (view, ms, flip, cause) in [
            ("inside", "NaN", "0.2", "frame_ms is NaN"),
            ("inside", "abc", "0.2", "not a number"),
            ("inside", "-5", "0.2", "frame_ms is -5"),
            ("inside", "inf", "0.2", "frame_ms is inf"),
            ("inside", "1", "1.5", "flip_mean is 1.5: expected 0 to 1"),
            ("x/y", "1", "0.2", "cannot name a chart file"),
            ("../../escaped", "1", "0.2", "cannot name a chart file"),
            ("", "1", "0.2", "cannot name a chart file"),
        ] {
            let e = check_row(&header, &row(view, ms, flip)).unwrap_err();
            assert!(e.contains(cause), "{view} {ms} {flip}: {e}");
        }
    }

    /// A cell as a hostile results file may hold it: any float as Rust prints it (NaN,
    /// infinities, subnormals, ±1e308), its spellings, words, empty, separators.
    fn cell() -> impl proptest::strategy::Strategy<Value = String> {
        use proptest::prelude::*;
        prop_oneof![
            any::<f64>().prop_map(|v| v.to_string()),
            any::<f64>().prop_map(|v| format!("{v:e}")),
            (0.0f64..1.0).prop_map(|v| v.to_string()),
            prop::sample::select(vec![
                "", "NaN", "inf", "-inf", "abc", "1e999", "-0", " 1", "."
            ])
            .prop_map(String::from),
            r"[a-z./\\\x00-\x1f]{0,6}",
        ]
    }

    proptest::proptest! {
        #![proptest_config(proptest::test_runner::Config::with_cases(256))]

        /// Any table of hostile cells is read or refused, never with a panic; what is read
        /// holds finite figures in their ranges and names usable as file names.
        #[test]
        fn any_csv_is_read_checked_or_refused(
            rows in proptest::collection::vec(proptest::collection::vec(cell(), accuracy_columns().len()), 0..5),
            short in proptest::bool::ANY,
        ) {
            let header = accuracy_columns();
            let mut text = header.join(",") + "\n";
            for r in &rows {
                let cells = if short { &r[..r.len() - 1] } else { &r[..] };
                text += &(cells.join(",") + "\n");
            }
            if let Ok(table) = read_accuracy(&text) {
                for row in &table.rows {
                    for (name, c) in header.iter().zip(row) {
                        if matches!(*name, "method" | "param" | "view") {
                            proptest::prop_assert!(!c.contains('/') && !c.starts_with('.'));
                        } else if *name != "work_source" && !c.is_empty() {
                            let v: f64 = c.trim().parse().unwrap();
                            proptest::prop_assert!(v.is_finite(), "{name} = {c}");
                        }
                    }
                }
            }
        }
    }
}
