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
    /// The section's Markdown, with `run` (the line naming its run) under the heading.
    pub fn markdown(&self, run: &str) -> String {
        let mut s = format!("## {}\n\n{run}\n\n{}\n\n", self.title, self.text.trim());
        for c in &self.charts {
            let _ = write!(s, "![{c}]({c}.png) ([SVG]({c}.svg))\n\n");
        }
        s + &self.table.markdown()
    }
}

/// REPORT.md: the header and every suite's section that has been run into this results folder
/// (kept in `sections/SUITE.md`), in suite order, so re-running one suite updates the report
/// without re-running the others. Each section carries the line naming its run ([`run_line`]),
/// so that sections measured at different times, or by different builds, can be told apart.
/// `measured`: false when the section was redrawn from an earlier run's CSV, which keeps that
/// run's line.
pub fn write(b: &Bench, suite: &str, section: &Section, measured: bool) -> anyhow::Result<()> {
    let dir = b.out.join("sections");
    std::fs::create_dir_all(&dir)?;
    let file = dir.join(format!("{suite}.md"));
    let run = if measured {
        run_line(b, &today())
    } else {
        std::fs::read_to_string(&file)
            .ok()
            .and_then(|t| {
                t.lines()
                    .find(|l| l.starts_with(RUN_PREFIX))
                    .map(str::to_string)
            })
            .unwrap_or_else(|| format!("{RUN_PREFIX} earlier; redrawn on {}.*", today()))
    };
    b.write(&format!("sections/{suite}.md"), &section.markdown(&run))?;
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

/// How each section's run line starts.
const RUN_PREFIX: &str = "*Measured";

/// The line under a section's heading that names its run: the date (UTC), the device, the
/// species, the frames per setting and the shadows.
fn run_line(b: &Bench, date: &str) -> String {
    format!(
        "{RUN_PREFIX} on {date} on {}: species {}; medians of {} frame(s) after one warm-up \
         frame{}; {}*",
        b.device,
        b.species_paths
            .iter()
            .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
            .collect::<Vec<_>>()
            .join(", "),
        b.frames,
        if b.quick {
            "; QUICK MODE: tiny scenes, the figures only prove the suites run"
        } else {
            ""
        },
        match b.shadows {
            Some(o) => format!(
                "the sun's shadows on: {} cascades of {}² texels over {} m, light views at ε {} \
                 texels (the reference's maps {}²).",
                o.cascades,
                o.resolution,
                o.distance,
                o.epsilon,
                forest_baselines::methods::REFERENCE_SHADOW_RESOLUTION
            ),
            None => "the sun's shadows off.".to_string(),
        }
    )
}

/// Today's date (UTC) as YYYY-MM-DD.
fn today() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (y, m, d) = civil_from_days((secs / 86_400) as i64);
    format!("{y:04}-{m:02}-{d:02}")
}

/// The proleptic Gregorian date (year, month 1–12, day 1–31) `days` days after 1970-01-01
/// (Howard Hinnant's `civil_from_days`).
fn civil_from_days(days: i64) -> (i64, u32, u32) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1_460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    (yoe + era * 400 + i64::from(m <= 2), m, d)
}

fn header(b: &Bench) -> String {
    format!(
        "# forest bench report\n\nEach section is one run of `forest bench SUITE`; the line \
         under its heading names the run (date, device, species, frames, shadows). Times are \
         GPU timestamps (cull + refine + draw){}.\n\n",
        if b.cpu {
            "; on a CPU rasteriser such as lavapipe absolute times are a CPU emulating a GPU: \
             compare methods by their ratios within one section"
        } else {
            ""
        },
    )
}

#[cfg(test)]
mod tests {
    use super::civil_from_days;

    #[test]
    fn dates_from_days_since_1970() {
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(-1), (1969, 12, 31));
        // 2000 is a leap year (divisible by 400): 11 016 days to 2000-02-29.
        assert_eq!(civil_from_days(11_016), (2000, 2, 29));
        assert_eq!(civil_from_days(11_017), (2000, 3, 1));
        // 2100 is not (divisible by 100 only): February ends on the 28th.
        assert_eq!(civil_from_days(47_540), (2100, 2, 28));
        assert_eq!(civil_from_days(47_541), (2100, 3, 1));
        assert_eq!(civil_from_days(20_792), (2026, 12, 5));
    }
}
