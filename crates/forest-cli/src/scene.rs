//! `forest scene`: generate a forest file.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use clap::Args;
use forest_format::generate::{GenerateParams, generate};

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
    Ok(())
}
