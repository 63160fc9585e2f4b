//! REPORT.md: every suite's table, charts and a reading of them.

use std::fmt::Write as _;

use super::{Bench, Table};

/// One suite's part of the report.
#[derive(Clone, Debug, Default)]
pub struct Section {
    /// Heading.
    pub title: String,
    /// What was measured and what it means (Markdown, written from the measured figures).
    pub text: String,
    /// The suite's main table.
    pub table: Table,
    /// Chart stems (PNG and SVG next to the report).
    pub charts: Vec<String>,
}

/// The whole report.
#[derive(Clone, Debug, Default)]
pub struct Report {
    /// Sections in suite order.
    pub sections: Vec<Section>,
}

impl Report {
    /// The Markdown text.
    pub fn markdown(&self, b: &Bench) -> String {
        let mut s = format!(
            "# forest bench report\n\nDevice: {}{}. Species: {}. Times are GPU timestamps \
             (cull + refine + draw), medians of {} frame(s) after one warm-up frame{}.\n\n",
            b.device,
            if b.cpu {
                " — a CPU rasteriser: absolute times are a CPU emulating a GPU; compare \
                 methods by their ratios"
            } else {
                ""
            },
            b.species_paths
                .iter()
                .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
                .collect::<Vec<_>>()
                .join(", "),
            b.frames,
            if b.quick {
                ". QUICK MODE: tiny scenes, the figures only prove the suites run"
            } else {
                ""
            }
        );
        for sec in &self.sections {
            let _ = write!(s, "## {}\n\n{}\n\n", sec.title, sec.text.trim());
            for c in &sec.charts {
                let _ = write!(s, "![{c}]({c}.png) ([SVG]({c}.svg))\n\n");
            }
            s += &sec.table.markdown();
            s += "\n";
        }
        s
    }
}
