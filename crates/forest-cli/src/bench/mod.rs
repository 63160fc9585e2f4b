//! `forest bench`: benchmark suites. Each writes CSV (stable columns, header row) and charts
//! (PNG + SVG) into the results folder and updates REPORT.md; `all` runs every suite. Figures
//! are printed and written, never asserted.

mod accuracy;
mod budget;
pub mod chart;
pub mod colour;
mod fidelity;
mod fidelity_variants;
mod lighting;
mod path;
mod report;
mod shadowing;
mod shadows;
mod stability;
mod storage;
mod table1;
mod wind;

use forest_render::ForestView;
use std::cell::OnceCell;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::Args;
use forest_baselines::geometry::{GeometryRenderer, PreparedGeometry};
use forest_baselines::methods::{ForestRenderer, Method, MethodStats};
use forest_format::forest::Forest;
use forest_render::fragments::{FragmentCounts, FragmentSummary};
use forest_render::options::{Background, RendererOptions};
use forest_render::scene::SpeciesData;
use forest_render::stats::PassTimes;
use forest_render::target::{TARGET_FORMAT, Target};
use forest_render::work::FrameWork;
use forest_render::{Camera, GpuContext, GpuScene, QuadStream};
use forest_scene::generate::{GenerateParams, generate};

/// The suites, in the order `all` runs them.
pub const SUITES: [&str; 12] = [
    "storage",
    "shadowing",
    "lighting",
    "shadows",
    "table1",
    "path",
    "accuracy",
    "stability",
    "budget",
    "fidelity",
    "wind",
    "colour",
];

/// Arguments of `forest bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Suite: storage, shadowing, lighting, shadows, table1, path, accuracy, stability,
    /// budget, fidelity, wind, colour, or all. Every run
    /// updates REPORT.md with the sections of all suites run into the results folder so far.
    #[arg(value_parser = [
        "storage", "shadowing", "lighting", "shadows", "table1", "path", "accuracy", "stability",
        "budget", "fidelity", "wind", "colour", "all",
    ])]
    pub suite: String,
    /// Species atlases (comma-separated).
    #[arg(long, value_delimiter = ',', required = true)]
    pub species: Vec<PathBuf>,
    /// OBJ models of the species, same order (for the geometry-based methods and the
    /// reference). Default: `assets/trees/NAME/FILE` for an atlas `NAME.atlas` baked from FILE.
    #[arg(long, value_delimiter = ',')]
    pub models: Vec<PathBuf>,
    /// Use --models that are not the files their atlases were baked from (each is named on
    /// stderr).
    #[arg(long)]
    pub allow_other_models: bool,
    /// Results folder.
    #[arg(long, default_value = "results")]
    pub out: PathBuf,
    /// Quick mode: tiny forests, small viewports, few frames and settings (for CI: proves the
    /// suites run; the figures mean little).
    #[arg(long)]
    pub quick: bool,
    /// Accuracy suite: redraw its charts and report section from the `accuracy.csv` already
    /// in the results folder, measuring nothing.
    #[arg(long)]
    pub redraw: bool,
    /// Frames measured per setting (the median is reported).
    #[arg(long, default_value_t = 3, allow_negative_numbers = true)]
    pub frames: u32,
    /// Accuracy suite: measure only these views (comma-separated; default: all). Use with
    /// its own --out: the CSV, charts and report then hold these views alone.
    #[arg(long, value_delimiter = ',', value_parser = ["close-up", "mid-range", "birds-eye", "walkthrough", "walkthrough-real"])]
    pub views: Vec<String>,
    /// Accuracy suite: measure only these methods (comma-separated; default: all).
    #[arg(long, value_delimiter = ',', value_parser = ["quads", "impostor", "geometry", "stochastic", "lods", "hybrid"])]
    pub methods: Vec<String>,
    /// The sun's shadows in every suite's frames (off unless `--shadows on`; the shadows
    /// suite draws frames with and without them whatever this says).
    #[command(flatten)]
    pub shadow: crate::render::ShadowArgs,
    /// The wind every suite's frames are drawn in (calm unless `--wind`).
    #[command(flatten)]
    pub wind: crate::render::WindArgs,
    /// The season every suite's frames are drawn in (the models' own colours unless
    /// `--season`).
    #[command(flatten)]
    pub season: crate::render::SeasonArgs,
    /// How much each tree of the suites' generated forests differs in colour from the others
    /// of its species (0 to 3; 1 is natural, as `forest scene` gives by default): 0, the
    /// default, draws every tree of a species alike, as the suites measured before variation.
    #[arg(long, allow_negative_numbers = true, default_value_t = 0.0)]
    pub variation: f32,
}

/// What every suite works with.
pub struct Bench {
    /// The GPU.
    pub ctx: GpuContext,
    /// Adapter name and backend, for the tables.
    pub device: String,
    /// Whether the adapter is a CPU rasteriser (lavapipe): the slowest settings are sampled.
    pub cpu: bool,
    /// Atlas paths.
    pub species_paths: Vec<PathBuf>,
    /// Loaded atlases.
    pub species: Vec<SpeciesData>,
    /// OBJ models (empty when none could be found).
    pub models: Vec<PathBuf>,
    /// `--allow-other-models`.
    allow_other_models: bool,
    prepared: OnceCell<PreparedGeometry>,
    /// Results folder.
    pub out: PathBuf,
    /// Quick mode.
    pub quick: bool,
    /// Frames measured per setting.
    pub frames: u32,
    /// Accuracy suite: the views to measure (empty: all).
    pub views: Vec<String>,
    /// Accuracy suite: the methods to measure (empty: all).
    pub methods: Vec<String>,
    /// The sun's shadows every suite's renderers draw (`--shadows`), or none.
    pub shadows: Option<forest_render::shadow::ShadowOptions>,
    /// The wind every suite's renderers draw in (`--wind`).
    pub wind: forest_format::wind::Wind,
    /// The season of every frame (`None`: the models' own colours).
    pub season: Option<f32>,
    /// The colour variation of the generated forests (0: none).
    pub variation: f32,
}

/// Every method at its default parameters, in the order the suites report them.
pub fn every_method() -> [Method; 6] {
    use forest_baselines::geometry::{MeshMethod, Stochastic};
    [
        Method::Quads,
        Method::Impostor,
        Method::Mesh(MeshMethod::Full { depth_sort: true }),
        Method::Mesh(MeshMethod::Stochastic(Stochastic::default())),
        Method::Mesh(MeshMethod::Lods(Default::default())),
        Method::Hybrid(forest_baselines::hybrid::Hybrid::default()),
    ]
}

/// The median (the lower middle for even counts); 0 for none.
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        0.0
    } else {
        v[(v.len() - 1) / 2]
    }
}

/// Default model of an atlas: `assets/trees/NAME/FILE` (NAME from `NAME.atlas`, FILE the OBJ
/// the manifest names).
fn default_model(atlas_path: &Path, data: &SpeciesData) -> Option<PathBuf> {
    let name = atlas_path.file_stem()?.to_str()?;
    let p = Path::new("assets/trees")
        .join(name)
        .join(&data.atlas.manifest.source.file);
    p.is_file().then_some(p)
}

impl Bench {
    fn new(args: &BenchArgs) -> Result<Self> {
        if args.frames == 0 {
            bail!("--frames 0: measure at least 1 frame per setting");
        }
        if !(0.0..=forest_format::colour::MAX_AMOUNT).contains(&args.variation) {
            bail!(
                "--variation {}: expected 0 (none) to {} (1 is natural)",
                args.variation,
                forest_format::colour::MAX_AMOUNT
            );
        }
        // The results never land inside an input: an atlas, a model (given, or found beside
        // the assets), a model's material library or texture, or a folder holding one.
        let inputs: Vec<PathBuf> = args.species.iter().chain(&args.models).cloned().collect();
        crate::guard::output(&args.out, "--out results folder", &inputs)?;
        let species = args
            .species
            .iter()
            .map(|p| SpeciesData::load(p).map_err(anyhow::Error::from))
            .collect::<Result<Vec<_>>>()?;
        let models = if args.models.is_empty() {
            args.species
                .iter()
                .zip(&species)
                .map(|(p, s)| default_model(p, s))
                .collect::<Option<Vec<_>>>()
                .unwrap_or_default()
        } else if args.models.len() != species.len() {
            bail!(
                "--models names {} OBJ files for {} species",
                args.models.len(),
                species.len()
            );
        } else {
            args.models.clone()
        };
        let mut inputs = inputs;
        for m in &models {
            inputs.extend(forest_bake::source_files(m).unwrap_or_else(|_| vec![m.clone()]));
        }
        crate::guard::output(&args.out, "--out results folder", &inputs)?;
        std::fs::create_dir_all(&args.out)
            .with_context(|| format!("creating {}", args.out.display()))?;
        let ctx = crate::gpu_context()?;
        if !ctx
            .device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY)
        {
            bail!(
                "the adapter {} has no timestamp queries: no pass times to report",
                ctx.adapter_info.name
            );
        }
        let device = format!("{} ({:?})", ctx.adapter_info.name, ctx.adapter_info.backend);
        let cpu = ctx.adapter_info.device_type == wgpu::DeviceType::Cpu;
        Ok(Self {
            ctx,
            device,
            cpu,
            species_paths: args.species.clone(),
            species,
            models,
            allow_other_models: args.allow_other_models,
            prepared: OnceCell::new(),
            out: args.out.clone(),
            quick: args.quick,
            frames: if args.quick { 1 } else { args.frames },
            views: args.views.clone(),
            methods: args.methods.clone(),
            shadows: args.shadow.options(false)?,
            wind: args.wind.wind()?,
            season: args.season.season,
            variation: args.variation,
        })
    }

    /// The largest crown (bounding-sphere) radius of the species, metres at scale 1.
    pub fn clearance(&self) -> f32 {
        self.species
            .iter()
            .map(|s| s.atlas.manifest.bounding_sphere.radius)
            .fold(1.0, f32::max)
    }

    /// The hybrid's automatic switch of each species, for the reports: the finest quads'
    /// projected width there and, where the bake measured it, the crossover in crown radii
    /// at the measurement's view.
    pub fn switch_summary(&self) -> String {
        self.species_paths
            .iter()
            .zip(&self.species)
            .map(|(p, s)| {
                let name = p.file_stem().map_or_else(String::new, |n| {
                    n.to_string_lossy().trim_end_matches(".atlas").to_string()
                });
                format!(
                    "{name}: {}",
                    forest_measure::switch::describe(&s.atlas.manifest)
                )
            })
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The geometry methods' preparation of the species (once).
    pub fn prepared(&self) -> Result<&PreparedGeometry> {
        if let Some(p) = self.prepared.get() {
            return Ok(p);
        }
        if self.models.is_empty() {
            bail!(
                "this suite draws the full-geometry reference and needs the species' OBJ models: \
                 pass --models (none found under assets/trees/)"
            );
        }
        let p = crate::render::noted(forest_baselines::geometry::prepare_models(
            &self.models,
            &self.species,
            self.allow_other_models,
        )?);
        Ok(self.prepared.get_or_init(|| p))
    }

    /// A generated forest of the bench species: `trees` over a `side`-metre square, checked
    /// with its species as `render` checks a forest file.
    pub fn forest(&self, trees: u32, side: f32, seed: u64) -> Result<Forest> {
        self.generated(GenerateParams {
            trees,
            area_per_tree: side * side / trees.max(1) as f32,
            clump_size: (side / 15.0).max(5.0),
            seed,
            ..GenerateParams::default()
        })
    }

    /// The forest of `params` over the bench species (`params.species` is set here), checked
    /// with its species as `render` checks a forest file.
    fn generated(&self, params: GenerateParams) -> Result<Forest> {
        let forest = generate(&GenerateParams {
            species: self
                .species_paths
                .iter()
                .map(|p| p.display().to_string())
                .collect(),
            ..params
        })
        .map_err(anyhow::Error::msg)?;
        let forest = if self.variation > 0.0 {
            let species = forest
                .species
                .iter()
                .map(|s| forest_format::colour::SpeciesColour::by_name(s))
                .collect();
            forest.with_colouring(forest_format::colour::Colouring::new(
                self.variation,
                species,
            ))
        } else {
            forest
        };
        let manifests: Vec<_> = self.species.iter().map(|s| &s.atlas.manifest).collect();
        forest_format::species::check(&forest, &manifests, Path::new("the bench's forest"))?;
        Ok(forest)
    }

    /// A forest of `trees` trees at real sizes: each species at its mature heights
    /// ([`forest_scene::generate::species_height`], by the atlas folder's name; a species
    /// not in that table keeps its model's size ×0.8–1.25, as `forest scene` sizes trees by
    /// default), `area_per_tree` m² of ground per tree. Returns the forest and its side
    /// (metres).
    pub fn real_size_forest(
        &self,
        trees: u32,
        area_per_tree: f32,
        seed: u64,
    ) -> Result<(Forest, f32)> {
        let side = (trees as f32 * area_per_tree).sqrt();
        let species_scale = self
            .species_paths
            .iter()
            .zip(&self.species)
            .map(|(path, s)| {
                let name = path
                    .file_stem()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default();
                match forest_scene::generate::species_height(&name) {
                    Some((lo, hi)) => {
                        let top = s.atlas.manifest.model_top();
                        (lo / top, hi / top)
                    }
                    None => GenerateParams::default().scale,
                }
            })
            .collect();
        let forest = self.generated(GenerateParams {
            trees,
            area_per_tree,
            species_scale,
            seed,
            ..GenerateParams::default()
        })?;
        Ok((forest, side))
    }

    /// Every method's renderer for `forest` (the geometry ones when `geometry`).
    pub fn renderer(
        &self,
        forest: &Forest,
        viewport: (u32, u32),
        min_epsilon: f32,
        geometry: bool,
        background: Background,
    ) -> Result<ForestRenderer> {
        let scene =
            GpuScene::with_format(&self.ctx, &self.species, forest, crate::colour_format())?;
        let opts = RendererOptions {
            format: TARGET_FORMAT,
            viewport,
            min_epsilon,
            background,
            ..Default::default()
        };
        let stream = QuadStream::new(&self.ctx.device, scene, &opts)?;
        let geo = if geometry {
            Some(GeometryRenderer::new(
                &self.ctx,
                self.prepared()?,
                forest,
                TARGET_FORMAT,
                background,
            )?)
        } else {
            None
        };
        self.shadowed(ForestRenderer::new(stream, geo))
    }

    /// `r` drawing the shadows the suites were asked for (`--shadows`), in their wind
    /// (`--wind`).
    pub fn shadowed(&self, mut r: ForestRenderer) -> Result<ForestRenderer> {
        r.set_shadows(&self.ctx.device, self.shadows)?;
        r.set_wind(self.wind)?;
        r.set_season(self.season)?;
        Ok(r)
    }

    /// Render `frames` + 1 frames of `method` (the first unmeasured: pipelines may compile
    /// then, and the stream grows to fit the view; with `frames` = 0 that one frame is
    /// measured); the last frame's counters and the median GPU frame time (cull + refine +
    /// draw).
    pub fn measure(
        &self,
        r: &mut ForestRenderer,
        method: Method,
        cam: &Camera,
        target: &Target,
        frames: u32,
    ) -> Result<(MethodStats, f64)> {
        let (stats, _, total) = self.measure_passes(r, method, cam, target, frames)?;
        Ok((stats, total))
    }

    /// [`Self::measure`] with the median of each pass too: (counters, per-pass medians,
    /// median frame total).
    pub fn measure_passes(
        &self,
        r: &mut ForestRenderer,
        method: Method,
        cam: &Camera,
        target: &Target,
        frames: u32,
    ) -> Result<(MethodStats, PassTimes, f64)> {
        r.set_method(&self.ctx, method)?;
        let mut times = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut stats = MethodStats::default();
        for f in 0..=frames {
            stats = if f == 0 {
                r.render_fitted(&self.ctx, cam, target)?
            } else {
                r.render_frame(&self.ctx, cam, target)?;
                r.read_stats(&self.ctx)
            };
            if f > 0 || frames == 0 {
                let t = stats.times.unwrap_or_default();
                times.0.push(t.cull_ms);
                times.1.push(t.refine_ms);
                times.2.push(t.draw_ms);
                times.3.push(t.total_ms());
            }
        }
        self.ctx.check_errors()?;
        Ok((
            stats,
            PassTimes {
                cull_ms: median(times.0),
                refine_ms: median(times.1),
                draw_ms: median(times.2),
            },
            median(times.3),
        ))
    }

    /// The work `method` asks of the GPU for `cam`, the pixels it covers and its exact
    /// fragment counts: one more frame, over a transparent background (its alpha is the
    /// coverage) and with pipeline statistics on, then that frame counted
    /// ([`ForestRenderer::count_fragments`]: two more); the renderer's background and
    /// statistics are restored after. Timed frames ([`Self::measure`]) run as the renderer is
    /// set (statistics off unless a suite turned them on).
    pub fn work(
        &self,
        r: &mut ForestRenderer,
        method: Method,
        cam: &Camera,
        target: &Target,
    ) -> Result<ViewWork> {
        let (background, counting) = (r.background(), r.pipeline_statistics());
        r.set_method(&self.ctx, method)?;
        r.set_background(Background::Transparent);
        r.set_pipeline_statistics(true);
        let drawn = r.render_fitted(&self.ctx, cam, target).and_then(|stats| {
            let covered = covered(&target.read(&self.ctx));
            let counts = r.count_fragments(&self.ctx, cam, target)?;
            Ok((stats, covered, counts))
        });
        r.set_background(background);
        r.set_pipeline_statistics(counting);
        let (stats, covered, counts) = drawn?;
        self.ctx.check_errors()?;
        Ok(ViewWork {
            work: stats.work,
            covered,
            counts,
        })
    }

    /// The exact fragment counts of `r`'s current method for `cam`, drawn as the renderer is
    /// set (two frames; see [`ForestRenderer::count_fragments`]).
    pub fn count(
        &self,
        r: &mut ForestRenderer,
        cam: &Camera,
        target: &Target,
    ) -> Result<FragmentCounts> {
        let counts = r.count_fragments(&self.ctx, cam, target)?;
        self.ctx.check_errors()?;
        Ok(counts)
    }

    /// Frames to measure for a method: one for full geometry and stochastic simplification on
    /// a CPU rasteriser (seconds per frame there), else the configured count.
    pub fn frames_for(&self, method: Method) -> u32 {
        let slow = matches!(
            method,
            Method::Mesh(
                forest_baselines::geometry::MeshMethod::Full { .. }
                    | forest_baselines::geometry::MeshMethod::Reference
                    | forest_baselines::geometry::MeshMethod::Stochastic(_)
            )
        );
        if self.cpu && slow { 1 } else { self.frames }
    }

    /// Write `name` in the results folder atomically.
    pub fn write(&self, name: &str, contents: &str) -> Result<PathBuf> {
        let path = self.out.join(name);
        forest_format::atomic::write_bytes(&path, contents.as_bytes())?;
        println!("wrote {}", path.display());
        Ok(path)
    }

    /// Save a chart as `stem.png` and `stem.svg` in the results folder.
    pub fn chart(&self, stem: &str, c: &chart::Chart) -> Result<()> {
        chart::save(c, &self.out.join(stem))?;
        println!("wrote {}.png, .svg", self.out.join(stem).display());
        Ok(())
    }
}

/// What one view's frame asked of the GPU ([`Bench::work`]).
pub struct ViewWork {
    /// Recorded commands and pipeline statistics.
    pub work: FrameWork,
    /// Pixels the trees cover (alpha of the method's transparent render).
    pub covered: u64,
    /// Exact per-pixel fragment counts ([`forest_render::fragments`]).
    pub counts: FragmentCounts,
}

pub use forest_format::results_csv::WORK_COLUMNS;

/// The [`WORK_COLUMNS`] cells of views' work: means over the views (one view: its counts),
/// fragments per covered pixel as a ratio of sums, the exact counts of all views' pixels
/// pooled ([`FragmentSummary::pooled`]).
pub fn work_cells(views: &[ViewWork]) -> Vec<String> {
    let n = views.len().max(1) as u64;
    let mean = |f: &dyn Fn(&FrameWork) -> u64| views.iter().map(|v| f(&v.work)).sum::<u64>() / n;
    let stats: Option<Vec<_>> = views.iter().map(|v| v.work.total()).collect();
    let stat = |f: fn(&forest_render::work::PassWork) -> u64| {
        stats.as_ref().map_or(String::new(), |t| {
            (t.iter().map(f).sum::<u64>() / n).to_string()
        })
    };
    let covered: u64 = views.iter().map(|v| v.covered).sum();
    let per_pixel = stats
        .as_ref()
        .filter(|_| covered > 0)
        .map_or(String::new(), |t| {
            let fragments: u64 = t.iter().map(|t| t.fragment_invocations).sum();
            format!("{:.3}", fragments as f64 / covered as f64)
        });
    let counts: Vec<FragmentCounts> = views.iter().map(|v| v.counts.clone()).collect();
    let exact = FragmentSummary::pooled(&counts);
    vec![
        mean(&|w| u64::from(w.dispatches)).to_string(),
        mean(&|w| u64::from(w.draws)).to_string(),
        stat(|t| t.vertex_invocations),
        stat(|t| t.primitives),
        stat(|t| t.fragment_invocations),
        stat(|t| t.compute_invocations),
        format!("{:.2}", mean(&|w| w.bytes) as f64 / 1e6),
        (covered / n).to_string(),
        per_pixel,
        if stats.is_some() {
            "pipeline statistics".into()
        } else {
            "recorded commands".into()
        },
        format!("{:.3}", exact.per_covered_mean),
        exact.per_covered_median.to_string(),
        exact.per_covered_p95.to_string(),
        format!("{:.3}", exact.quad_lanes_per_covered),
        format!("{:.4}", exact.transparent_share),
        format!("{:.4}", exact.hidden_share),
    ]
}

/// Pixels of `img` with non-zero alpha (a transparent render's coverage).
pub fn covered(img: &image::RgbaImage) -> u64 {
    img.pixels().filter(|p| p[3] > 0).count() as u64
}

/// A CSV table: header and rows of already-formatted cells.
#[derive(Clone, Debug, Default)]
pub struct Table {
    /// Column names.
    pub header: Vec<&'static str>,
    /// Rows.
    pub rows: Vec<Vec<String>>,
}

impl Table {
    /// An empty table with these columns.
    pub fn new(header: &[&'static str]) -> Self {
        Self {
            header: header.to_vec(),
            rows: Vec::new(),
        }
    }

    /// Add a row (one cell per column).
    pub fn push(&mut self, row: Vec<String>) {
        debug_assert_eq!(row.len(), self.header.len());
        self.rows.push(row);
    }

    /// CSV text; cells with commas or quotes are quoted.
    pub fn csv(&self) -> String {
        let cell = |c: &str| {
            if c.contains([',', '"']) {
                format!("\"{}\"", c.replace('"', "\"\""))
            } else {
                c.to_string()
            }
        };
        let mut s = self.header.join(",") + "\n";
        for r in &self.rows {
            s += &(r.iter().map(|c| cell(c)).collect::<Vec<_>>().join(",") + "\n");
        }
        s
    }

    /// A Markdown table.
    pub fn markdown(&self) -> String {
        let mut s = format!("| {} |\n|", self.header.join(" | "));
        for _ in &self.header {
            s += "---|";
        }
        s += "\n";
        for r in &self.rows {
            let _ = writeln!(s, "| {} |", r.join(" | "));
        }
        s
    }
}

/// Format milliseconds.
pub fn ms(v: f64) -> String {
    format!("{v:.3}")
}

/// Run `forest bench`.
pub fn run(args: &BenchArgs) -> Result<()> {
    let b = Bench::new(args)?;
    println!("forest bench {} on {}", args.suite, b.device);
    let suites: Vec<&str> = if args.suite == "all" {
        SUITES.to_vec()
    } else {
        vec![args.suite.as_str()]
    };
    for s in suites {
        let section = match s {
            "storage" => storage::run(&b)?,
            "shadowing" => shadowing::run(&b)?,
            "lighting" => lighting::run(&b)?,
            "shadows" => shadows::run(&b)?,
            "table1" => table1::run(&b)?,
            "path" => path::run(&b)?,
            "accuracy" if args.redraw => accuracy::redraw(&b)?,
            "accuracy" => accuracy::run(&b)?,
            "stability" => stability::run(&b)?,
            "budget" => budget::run(&b)?,
            "fidelity" => fidelity::run(&b)?,
            "wind" => wind::run(&b)?,
            "colour" => colour::run(&b)?,
            _ => unreachable!("clap checks the suite"),
        };
        report::write(&b, s, &section, !(s == "accuracy" && args.redraw))?;
    }
    Ok(())
}
