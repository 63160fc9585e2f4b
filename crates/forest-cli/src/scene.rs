//! `forest scene`: generate a forest file.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::Args;
use forest_format::AtlasManifest;
use forest_format::colour::{Colouring, SpeciesColour};
use forest_format::terrain::{Terrain, TerrainParams};
use forest_scene::generate::{GenerateParams, GroundRules, generate, species_height};

/// Arguments of `forest scene`.
#[derive(Args, Debug)]
pub struct SceneArgs {
    /// Number of trees.
    #[arg(long, default_value_t = 10_000, allow_negative_numbers = true)]
    pub trees: u32,
    /// Species atlases (comma-separated or repeated); each must be a baked atlas folder.
    #[arg(long, value_delimiter = ',', required = true)]
    pub species: Vec<PathBuf>,
    /// Random seed.
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    pub seed: u64,
    /// Mean ground area per tree in m² (sets the forest's size).
    #[arg(long, allow_negative_numbers = true, default_value_t = 30.0)]
    pub area_per_tree: f32,
    /// Clump size in metres.
    #[arg(long, allow_negative_numbers = true, default_value_t = 60.0)]
    pub clump_size: f32,
    /// Presort directions.
    #[arg(long, default_value_t = 15, allow_negative_numbers = true)]
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
    /// The ground: `flat` (y = 0), `hills` (seeded rolling hills reaching past the forest and
    /// fading into the plain), or a height field: a 16-bit greyscale PNG (0-65535 map to 0 to
    /// --relief metres) or an OpenEXR file of heights in metres, centred on the forest, row 0
    /// at the smallest z. Trees stand on it, keep off slopes over --max-slope and off ground
    /// above the treeline, and each species keeps to its altitude band.
    #[arg(long, default_value = "flat")]
    pub terrain: String,
    /// Relief in metres: the highest hilltop of `hills`, or the height of a PNG's value 65535
    /// [default: 100].
    #[arg(long, allow_negative_numbers = true)]
    pub relief: Option<f32>,
    /// Metres between height samples (a height field's pixels, or the generated hills')
    /// [default: 8].
    #[arg(long, allow_negative_numbers = true)]
    pub terrain_spacing: Option<f32>,
    /// Steepest ground that carries trees, degrees [default: 35].
    #[arg(long, allow_negative_numbers = true)]
    pub max_slope: Option<f32>,
    /// Treeline: the fraction of the way from the lowest to the highest ground above which no
    /// tree grows [default: 0.92].
    #[arg(long, allow_negative_numbers = true)]
    pub treeline: Option<f32>,
    /// How much each tree's colour varies from the others of its species: 0 (every tree of a
    /// species alike, as before variation) to 3; 1 is natural. The variation comes from a
    /// hash of each tree, so it costs no byte per tree.
    #[arg(long, allow_negative_numbers = true, default_value_t = 1.0)]
    pub variation: f32,
    /// Species whose leaves stay green through the seasons and vary less (comma-separated
    /// atlas names without `.atlas`, or `auto`: every species whose name holds pine, spruce,
    /// fir, cedar, cypress, juniper or yew).
    #[arg(long, value_delimiter = ',', default_value = "auto")]
    pub evergreen: Vec<String>,
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

/// A species' name: its atlas folder's, without the extension.
fn species_name(atlas: &Path) -> String {
    atlas
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Each species' scale range, and a line per species saying what was chosen; `manifests` are
/// the species' atlases' manifests, in `args.species` order.
fn species_scales(
    args: &SceneArgs,
    manifests: &[AtlasManifest],
) -> Result<(ScaleRanges, Vec<String>)> {
    let names: Vec<String> = args.species.iter().map(|p| species_name(p)).collect();
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
    for (manifest, name) in manifests.iter().zip(&names) {
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
        let top = manifest.model_top();
        scales.push((lo / top, hi / top));
        lines.push(format!(
            "  {name}: {lo}-{hi} m tall (model {top:.2} m: scale {:.2}-{:.2})",
            lo / top,
            hi / top
        ));
    }
    Ok((scales, lines))
}

/// Relief of `--terrain hills` and of a PNG's full range when `--relief` is not given, metres.
pub const DEFAULT_RELIEF: f32 = 100.0;

/// Metres between height samples when `--terrain-spacing` is not given.
pub const DEFAULT_TERRAIN_SPACING: f32 = 8.0;

/// The terrain `--terrain` asks for (`None`: flat), for a forest `side` metres across.
fn terrain(args: &SceneArgs, side: f32) -> Result<Option<Terrain>> {
    let relief = args.relief.unwrap_or(DEFAULT_RELIEF);
    let spacing = args.terrain_spacing.unwrap_or(DEFAULT_TERRAIN_SPACING);
    match args.terrain.as_str() {
        "flat" => {
            let given: Vec<&str> = [
                ("--relief", args.relief.is_some()),
                ("--terrain-spacing", args.terrain_spacing.is_some()),
                ("--max-slope", args.max_slope.is_some()),
                ("--treeline", args.treeline.is_some()),
            ]
            .iter()
            .filter(|(_, g)| *g)
            .map(|(n, _)| *n)
            .collect();
            if !given.is_empty() {
                bail!(
                    "{} need(s) a --terrain (hills, or a height field): flat ground has none",
                    given.join(", ")
                );
            }
            Ok(None)
        }
        "hills" => {
            // Hills reach half the forest's width past each edge, falling gently to the plain
            // from the forest's edge on, so the forest's edge is not the world's; a hill is
            // about a quarter of the forest across.
            let half = side.max(200.0);
            Terrain::generate(&TerrainParams {
                half_extent: half,
                spacing,
                relief,
                hill_size: (side / 4.0).max(150.0),
                fade: 0.5,
                seed: args.seed,
            })
            .map(Some)
            .map_err(|e| anyhow::anyhow!("--terrain hills: {e}"))
        }
        file => {
            let path = Path::new(file);
            let exr = path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
            if exr && args.relief.is_some() {
                bail!("--relief scales 16-bit PNG height fields; an EXR holds heights in metres");
            }
            if path.extension().is_none() {
                bail!("--terrain '{file}': give flat, hills, or a height field (.png or .exr)");
            }
            Ok(Some(Terrain::from_image(path, spacing, relief)?))
        }
    }
}

/// Run `forest scene`.
pub fn run(args: &SceneArgs) -> Result<()> {
    let mut inputs = args.species.clone();
    if !matches!(args.terrain.as_str(), "flat" | "hills") {
        inputs.push(PathBuf::from(&args.terrain));
    }
    crate::guard::output(&args.output, "output", &inputs)?;
    let mut species = Vec::new();
    // Every atlas loaded whole, as render loads it: a forest is not written over atlases
    // that render would refuse.
    let mut manifests = Vec::new();
    for s in &args.species {
        if !s.join(forest_format::atlas::MANIFEST_FILE).is_file() {
            bail!(
                "species {} is not an atlas folder (bake it with forest bake)",
                s.display()
            );
        }
        let atlas =
            forest_format::Atlas::load(s).with_context(|| format!("species {}", s.display()))?;
        manifests.push(atlas.manifest);
        species.push(stored_path(s, &args.output)?);
    }
    let (species_scale, size_lines) = species_scales(args, &manifests)?;
    let colouring = colouring(args)?;
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
    let side = (f64::from(args.trees) * f64::from(args.area_per_tree)).sqrt() as f32;
    let terrain = if side.is_finite() && side > 0.0 {
        terrain(args, side)?
    } else {
        None
    };
    let (footprint, foot_lines) = match &terrain {
        Some(_) => footprints(&args.species),
        None => (Vec::new(), Vec::new()),
    };
    let forest = generate(&GenerateParams {
        terrain,
        footprint,
        ground: GroundRules {
            max_slope_deg: args
                .max_slope
                .unwrap_or(GroundRules::default().max_slope_deg),
            treeline: args.treeline.unwrap_or(GroundRules::default().treeline),
            ..GroundRules::default()
        },
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
    let forest = forest.with_colouring(colouring);
    // What `render` would refuse is refused here, before anything is written.
    forest.check(&args.output)?;
    forest_format::species::check(&forest, &manifests.iter().collect::<Vec<_>>(), &args.output)?;
    spinner.set_message(format!("writing {}", args.output.display()));
    forest.save(&args.output)?;
    spinner.finish_and_clear();
    println!(
        "{} trees of {} species, {:.0} m across, {} presort directions -> {}",
        forest.instances.len(),
        forest.species.len(),
        side,
        forest.presort.directions.len(),
        args.output.display()
    );
    if let Some(c) = &forest.colouring {
        let evergreen: Vec<&str> = args
            .species
            .iter()
            .zip(&c.species)
            .filter(|(_, s)| **s == SpeciesColour::EVERGREEN)
            .map(|(p, _)| p.to_str().unwrap_or("?"))
            .collect();
        println!(
            "  colour variation {} (evergreen: {})",
            c.amount,
            if evergreen.is_empty() {
                "none".to_string()
            } else {
                evergreen.join(", ")
            }
        );
    }
    if let Some(t) = &forest.terrain {
        let (lo, hi) = t.height_range();
        let ([x0, _], [x1, _]) = t.bounds();
        println!(
            "  terrain: {}×{} samples, {:.1} m apart, {:.0} m across, ground {lo:.1} to {hi:.1} m",
            t.size[0],
            t.size[1],
            t.spacing,
            x1 - x0
        );
    }
    for l in size_lines.iter().chain(&foot_lines) {
        println!("{l}");
    }
    Ok(())
}

/// The forest's colouring from `--variation` and `--evergreen`; the error names the option
/// and the bound.
fn colouring(args: &SceneArgs) -> Result<Colouring> {
    let amount = args.variation;
    if !(0.0..=forest_format::colour::MAX_AMOUNT).contains(&amount) {
        bail!(
            "--variation {amount}: expected 0 (none) to {} (1 is natural)",
            forest_format::colour::MAX_AMOUNT
        );
    }
    let names: Vec<String> = args.species.iter().map(|p| species_name(p)).collect();
    let auto = args.evergreen.iter().any(|e| e == "auto");
    for e in args
        .evergreen
        .iter()
        .filter(|e| *e != "auto" && !e.is_empty())
    {
        if !names.contains(e) {
            bail!(
                "--evergreen {e}: no species of that name (the species are {})",
                names.join(", ")
            );
        }
    }
    let species = names
        .iter()
        .map(|n| {
            if args.evergreen.contains(n) {
                SpeciesColour::EVERGREEN
            } else if auto {
                SpeciesColour::by_name(n)
            } else {
                SpeciesColour::DECIDUOUS
            }
        })
        .collect();
    Ok(Colouring::new(amount, species))
}

/// Each species' foot ([`forest_format::model::footprint_radius`] of its model, recorded in
/// its atlas's manifest at bake, else computed from the model the atlas stores), so that
/// trees on a slope are planted on the ground's lowest point under their trunk; and a line
/// per species saying what was found. An older atlas without a readable model gives 0 (its trees
/// stand on the ground at their axis, as before feet were measured) and says why: the forest needs
/// no model, only the geometry methods do.
fn footprints(atlases: &[PathBuf]) -> (Vec<f32>, Vec<String>) {
    let mut radii = Vec::new();
    let mut lines = Vec::new();
    for a in atlases {
        let name = species_name(a);
        // Recorded at bake; atlases baked before it was recorded compute it from their model.
        let recorded = forest_format::Atlas::load_manifest(a)
            .ok()
            .and_then(|m| m.source.foot);
        let found = match recorded {
            Some(r) => Ok(Some(r)),
            None => forest_format::model::PreparedModel::load(a)
                .map(|m| m.map(|m| m.footprint_radius())),
        };
        let (r, line) = match found {
            Ok(Some(r)) => {
                let line = format!(
                    "  {name}: foot {r:.3} m from its axis at scale 1; on slopes lowered to the \
                     lowest ground under it"
                );
                (r, line)
            }
            Ok(None) => (
                0.0,
                format!(
                    "  {name}: its atlas stores no model (bake it again to store one), so its \
                     trees stand at their axis and may float on steep slopes"
                ),
            ),
            Err(e) => (
                0.0,
                format!(
                    "  {name}: its model could not be read ({e}), so its trees stand at their \
                     axis and may float on steep slopes"
                ),
            ),
        };
        radii.push(r);
        lines.push(line);
    }
    (radii, lines)
}
