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

impl Section {
    /// The section's Markdown.
    pub fn markdown(&self) -> String {
        let mut s = format!("## {}\n\n{}\n\n", self.title, self.text.trim());
        for c in &self.charts {
            let _ = write!(s, "![{c}]({c}.png) ([SVG]({c}.svg))\n\n");
        }
        s + &self.table.markdown()
    }
}

/// REPORT.md: the header (device, species, frames) and every suite's section that has been
/// run into this results folder (kept in `sections/SUITE.md`), in suite order, so re-running
/// one suite updates the report without re-running the others.
pub fn write(b: &Bench, suite: &str, section: &Section) -> anyhow::Result<()> {
    let dir = b.out.join("sections");
    std::fs::create_dir_all(&dir)?;
    b.write(&format!("sections/{suite}.md"), &section.markdown())?;
    let mut s = header(b);
    for name in super::SUITES {
        if let Ok(text) = std::fs::read_to_string(dir.join(format!("{name}.md"))) {
            s += &text;
            s += "\n";
        }
    }
    b.write("REPORT.md", &s)?;
    Ok(())
}

fn header(b: &Bench) -> String {
    format!(
        "# forest bench report\n\nDevice: {}{}. Species: {}. Times are GPU timestamps \
             (cull + refine + draw), medians of {} frame(s) after one warm-up frame{}. {}\n\n",
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
        },
        match b.shadows {
            Some(o) => format!(
                "The sun's shadows are on in every suite: {} cascades of {}² texels over {} m, \
                 light views at ε {} texels (the reference's maps {}²).",
                o.cascades,
                o.resolution,
                o.distance,
                o.epsilon,
                forest_baselines::methods::REFERENCE_SHADOW_RESOLUTION
            ),
            None => "The sun's shadows are off (but in the shadows suite).".to_string(),
        }
    )
}
