//! `forest scene`: generate a forest file.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use clap::Args;
use forest_format::generate::{GenerateParams, generate, species_height};

/// Arguments of `forest scene`.
#[derive(Args, Debug)]
pub struct SceneArgs {
    /// Number of trees.
    #[arg(long, default_value_t = 10_000)]
    pub trees: u32,
    /// Species atlases (comma-separated or repeated); each must be a baked atlas folder.
    #[arg(long, value_delimiter = ',', required = true)]
    pub species: Vec<PathBuf>,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Mean ground area per tree in m² (sets the forest's size).
    #[arg(long, allow_negative_numbers = true, default_value_t = 30.0)]
    pub area_per_tree: f32,
    /// Clump size in metres.
    #[arg(long, allow_negative_numbers = true, default_value_t = 60.0)]
    pub clump_size: f32,
    /// Presort directions.
    #[arg(long, default_value_t = 15)]
    pub presort_directions: u32,
    /// Tree heights per species, `NAME=MIN-MAX` in metres (comma-separated; NAME is the
    /// atlas folder's name without `.atlas`), drawn uniformly per tree. They override the
    /// built-in table (oak and ash 15-25, pine 20-35, aspen 12-20, bush 1-3); a species in
    /// neither keeps its model's size, varied ×0.8-1.25.
    #[arg(long, value_delimiter = ',', value_parser = parse_height)]
    pub heights: Vec<(String, f32, f32)>,
    /// Keep every model's own size, varied ×0.8-1.25, instead of the species' heights.
    #[arg(long, conflicts_with = "heights")]
    pub model_sizes: bool,
    /// Output: binary forest, or JSON when the name ends in .json.
    #[arg(short, long)]
    pub output: PathBuf,
}

/// A species path as stored in a forest: relative to the forest's folder when inside it.
fn stored_path(atlas: &Path, forest: &Path) -> Result<String> {
    let abs = std::fs::canonicalize(atlas)
        .map_err(|e| anyhow::anyhow!("species atlas {}: {e}", atlas.display()))?;
    let dir = forest
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let dir = std::fs::canonicalize(dir)
        .map_err(|e| anyhow::anyhow!("output folder {}: {e}", dir.display()))?;
    Ok(abs
        .strip_prefix(&dir)
        .map(|p| p.display().to_string())
        .unwrap_or_else(|_| abs.display().to_string()))
}

/// `NAME=MIN-MAX` (metres) of `--heights`.
fn parse_height(s: &str) -> Result<(String, f32, f32), String> {
    let usage = || format!("'{s}': expected NAME=MIN-MAX in metres, for example oak=15-25");
    let (name, range) = s.split_once('=').ok_or_else(usage)?;
    let (lo, hi) = range.split_once('-').ok_or_else(usage)?;
    let (lo, hi): (f32, f32) = (
        lo.trim().parse().map_err(|_| usage())?,
        hi.trim().parse().map_err(|_| usage())?,
    );
    if name.trim().is_empty() || !(lo > 0.0 && hi >= lo && hi <= 1000.0) {
        return Err(format!(
            "'{s}': a species name and heights with 0 < MIN <= MAX <= 1000 m"
        ));
    }
    Ok((name.trim().to_string(), lo, hi))
}

/// Scale ranges, one per species (empty: every model at its own size, ×0.8–1.25).
type ScaleRanges = Vec<(f32, f32)>;

/// Each species' scale range, and a line per species saying what was chosen.
fn species_scales(args: &SceneArgs) -> Result<(ScaleRanges, Vec<String>)> {
    let names: Vec<String> = args
        .species
        .iter()
        .map(|p| {
            p.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        })
        .collect();
    if let Some((n, _, _)) = args
        .heights
        .iter()
        .find(|(n, _, _)| !names.iter().any(|m| m.eq_ignore_ascii_case(n)))
    {
        bail!(
            "--heights names '{n}', which is none of the species ({})",
            names.join(", ")
        );
    }
    if args.model_sizes {
        return Ok((Vec::new(), Vec::new()));
    }
    let mut scales = Vec::new();
    let mut lines = Vec::new();
    for (path, name) in args.species.iter().zip(&names) {
        let given = args
            .heights
            .iter()
            .rev()
            .find(|(n, _, _)| n.eq_ignore_ascii_case(name))
            .map(|&(_, lo, hi)| (lo, hi));
        let Some((lo, hi)) = given.or_else(|| species_height(name)) else {
            scales.push(GenerateParams::default().scale);
            lines.push(format!(
                "  {name}: not in the height table, its model's own size ×0.8-1.25 (--heights {name}=MIN-MAX sets one)"
            ));
            continue;
        };
        let top = forest_format::atlas::Atlas::load_manifest(path)?.model_top();
        scales.push((lo / top, hi / top));
        lines.push(format!(
            "  {name}: {lo}-{hi} m tall (model {top:.2} m: scale {:.2}-{:.2})",
            lo / top,
            hi / top
        ));
    }
    Ok((scales, lines))
}

/// Run `forest scene`.
pub fn run(args: &SceneArgs) -> Result<()> {
    crate::guard::not_an_input(&args.output, "output", &args.species)?;
    let mut species = Vec::new();
    for s in &args.species {
        if !s.join(forest_format::atlas::MANIFEST_FILE).is_file() {
            bail!(
                "species {} is not an atlas folder (bake it with forest bake)",
                s.display()
            );
        }
        species.push(stored_path(s, &args.output)?);
    }
    let (species_scale, size_lines) = species_scales(args)?;
    // Millions of trees take seconds to place and sort: say so while it runs.
    let spinner = indicatif::ProgressBar::new_spinner();
    if args.trees >= 100_000 {
        spinner.set_message(format!(
            "placing {} trees and sorting them along {} directions",
            args.trees, args.presort_directions
        ));
        spinner.enable_steady_tick(std::time::Duration::from_millis(200));
    } else {
        spinner.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let forest = generate(&GenerateParams {
        trees: args.trees,
        species,
        area_per_tree: args.area_per_tree,
        clump_size: args.clump_size,
        seed: args.seed,
        presort_directions: args.presort_directions,
        species_scale,
        ..GenerateParams::default()
    })
    .map_err(anyhow::Error::msg)?;
    // What `render` would refuse is refused here, before anything is written.
    forest.check(&args.output)?;
    spinner.set_message(format!("writing {}", args.output.display()));
    forest.save(&args.output)?;
    spinner.finish_and_clear();
    println!(
        "{} trees of {} species, {:.0} m across, {} presort directions -> {}",
        forest.instances.len(),
        forest.species.len(),
        2.0 * forest.extent(),
        forest.presort.directions.len(),
        args.output.display()
    );
    for l in size_lines {
        println!("{l}");
    }
    Ok(())
}
