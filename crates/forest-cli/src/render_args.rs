//! The options of `forest render` (shared by `view` and `bench`): the light, the shadows,
//! the method and its parameters, and their parsers.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use clap::Args;
use forest_baselines::geometry::{Lods, MeshMethod, Stochastic};
use forest_baselines::hybrid::{Hybrid, Near};
use forest_baselines::methods::Method;
use forest_format::forest::Forest;
use forest_render::gpu_types::WEIGHT_ONE;
use forest_render::options::{AspectBlend, Atmosphere, StreamOptions};
use forest_render::shadow::ShadowOptions;
use forest_scene::views;
use glam::Vec3;

/// Arguments of `forest render`.
#[derive(Args, Debug, Clone)]
pub struct RenderArgs {
    /// Forest file (binary .forest or .json).
    pub forest: PathBuf,
    /// Output PNG; with several views, `-VIEW` is inserted before the extension.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Named views: inside (eye height inside the forest), hill (on the highest ground among
    /// the trees, looking down over the lowest), birds-eye (above it); each keeps 3 m from
    /// every tree's trunk and crown. Repeatable.
    #[arg(long = "view", value_parser = views::NAMES)]
    pub views: Vec<String>,
    /// Eye position x,y,z in metres (with --target, instead of --view).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, requires = "target")]
    pub eye: Option<Vec3>,
    /// Point looked at, x,y,z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, requires = "eye")]
    pub target: Option<Vec3>,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "800x600", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Refinement threshold ε in pixels.
    #[arg(long, allow_negative_numbers = true, default_value_t = 16.0)]
    pub epsilon: f32,
    /// Vertical field of view in degrees.
    #[arg(long, allow_negative_numbers = true, default_value_t = 60.0)]
    pub fov: f32,
    /// Print one JSON line of figures per view.
    #[arg(long)]
    pub json: bool,
    /// Draw over a transparent background without ground (alpha = tree coverage, for metrics).
    #[arg(long)]
    pub transparent: bool,
    /// Distance haze, the same for every method: the visibility along the ground in metres
    /// (where 2 % of a surface's contrast is left), or `off`. Default: 2000 over the sky, off
    /// with --transparent.
    #[arg(long, allow_negative_numbers = true, value_parser = parse_haze)]
    pub haze: Option<f32>,
    /// Height in metres over which the haze thins by a factor e, or `off` for haze as thick
    /// at every height.
    #[arg(long, allow_negative_numbers = true, value_parser = parse_haze, default_value_t = Atmosphere::DEMO_HAZE_HEIGHT)]
    pub haze_height: f32,
    #[command(flatten)]
    pub m: MethodArgs,
    #[command(flatten)]
    pub light: LightArgs,
    #[command(flatten)]
    pub wind: WindArgs,
    #[command(flatten)]
    pub season: SeasonArgs,
    #[command(flatten)]
    pub shadow: ShadowArgs,
    /// Write an animation of the wind instead of a still: SECONDS of frames from
    /// --wind-time on, at --frame-rate, as an animated PNG (APNG) at the output path.
    #[arg(long, allow_negative_numbers = true)]
    pub animate: Option<f32>,
    /// Frames per second of --animate (1 to 60).
    #[arg(long, allow_negative_numbers = true, default_value_t = 15.0)]
    pub frame_rate: f32,
    /// Render at N×N times the size and box-filter down (the supersampled reference uses 4).
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    pub supersample: u32,
    /// Count every tree fragment exactly (each view is drawn twice more) and report the
    /// fragments per covered pixel, the 2×2-quad lanes and the hidden and transparent shares
    /// (not with --supersample). Tree fragments behind the ground count as shaded: the
    /// count's early depth test sees the trees' own depth, not the ground's.
    #[arg(long)]
    pub fragments: bool,
    /// What the PNG shows: the image (`off`), or `overdraw`, a heat map of the fragments
    /// shaded per pixel with a legend (implies --fragments; not with --supersample).
    #[arg(long, default_value = "off", value_parser = ["off", "overdraw"])]
    pub debug_view: String,
}

impl RenderArgs {
    /// Whether the views are counted.
    pub(crate) fn counts_fragments(&self) -> bool {
        self.fragments || self.overdraw()
    }

    /// The frames of --animate and the delay between them (seconds): none for a still.
    /// Checked: at most [`MAX_ANIMATION_FRAMES`], every instant within the wind's clock
    /// (`wind` is --wind's), and nothing asked of a still's counts.
    pub(crate) fn animation(&self, wind: &forest_format::wind::Wind) -> Result<Option<(u32, f32)>> {
        let Some(seconds) = self.animate else {
            return Ok(None);
        };
        if !(seconds.is_finite() && seconds > 0.0 && seconds <= MAX_ANIMATION_SECONDS) {
            anyhow::bail!(
                "--animate {seconds}: expected more than 0 and at most {MAX_ANIMATION_SECONDS} \
                 seconds"
            );
        }
        if !(self.frame_rate.is_finite() && (1.0..=60.0).contains(&self.frame_rate)) {
            anyhow::bail!(
                "--frame-rate {}: expected 1 to 60 frames per second",
                self.frame_rate
            );
        }
        let frames = (seconds * self.frame_rate).ceil().max(1.0) as u32;
        if frames > MAX_ANIMATION_FRAMES {
            anyhow::bail!(
                "--animate {seconds} at --frame-rate {}: {frames} frames, at most \
                 {MAX_ANIMATION_FRAMES}",
                self.frame_rate
            );
        }
        let step = 1.0 / self.frame_rate;
        forest_format::wind::Wind {
            time: wind.time + (frames - 1) as f32 * step,
            ..*wind
        }
        .validate()
        .map_err(|e| {
            anyhow::anyhow!(
                "--animate {seconds} from --wind-time {}: the last frame's {e}",
                wind.time
            )
        })?;
        if self.counts_fragments() {
            anyhow::bail!(
                "--animate draws frames in time: count fragments (--fragments, --debug-view \
                 overdraw) on a still"
            );
        }
        Ok(Some((frames, step)))
    }

    /// Whether the PNG is the overdraw view.
    pub(crate) fn overdraw(&self) -> bool {
        self.debug_view == "overdraw"
    }
}

/// The longest `--animate` (seconds).
pub const MAX_ANIMATION_SECONDS: f32 = 60.0;
/// The most frames `--animate` writes.
pub const MAX_ANIMATION_FRAMES: u32 = 3600;

/// The light every method shades with (shared by `forest render`, `forest view` and the
/// benches): the sun's direction and the exposure. Nothing of it is baked.
#[derive(clap::Args, Debug, Clone)]
pub struct LightArgs {
    /// Sun direction as AZIMUTH,ELEVATION in degrees (azimuth from +Z towards +X, elevation
    /// 0 to 90 above the horizon).
    #[arg(long, default_value = "30,55", value_parser = parse_sun, allow_hyphen_values = true)]
    pub sun: (f32, f32),
    /// Daylight at this local solar hour instead of --sun: 6 (sunrise, east) to 18 (sunset,
    /// west), 65° at noon; the sun reddens and the sky dims and warms as it sinks.
    #[arg(long, conflicts_with = "sun", allow_negative_numbers = true)]
    pub time: Option<f32>,
    /// Exposure: every radiance is scaled by it (above 0).
    #[arg(long, allow_negative_numbers = true, default_value_t = 1.0)]
    pub exposure: f32,
}

/// The wind every method and every shadow caster moves the trees by (shared by `forest
/// render`, `forest view` and the benches; see `forest_format::wind`).
#[derive(clap::Args, Debug, Clone)]
pub struct WindArgs {
    /// Wind as TOWARDS,SPEED: the azimuth it blows towards in degrees (from +Z towards +X, as
    /// --sun's azimuth) and its mean speed in m/s (0 to 50) [default: calm]
    #[arg(long, value_parser = forest_format::wind::parse_towards_speed, allow_hyphen_values = true)]
    pub wind: Option<(f32, f32)>,
    /// How much gusts vary the wind's speed: 0 (steady) to 1 (from calm to twice the mean).
    #[arg(long, allow_negative_numbers = true, default_value_t = forest_format::wind::DEFAULT_GUSTINESS)]
    pub wind_gustiness: f32,
    /// The instant drawn, in seconds of the wind's clock (within ±1e5; --time is the time of
    /// day).
    #[arg(long, allow_negative_numbers = true, default_value_t = 0.0)]
    pub wind_time: f32,
}

impl WindArgs {
    /// The wind asked for (calm without --wind), checked whether or not there is one: the
    /// error names the option and the bound.
    pub fn wind(&self) -> Result<forest_format::wind::Wind> {
        let (towards_deg, speed) = self.wind.unwrap_or((0.0, 0.0));
        let w = forest_format::wind::Wind {
            towards_deg,
            speed,
            gustiness: self.wind_gustiness,
            time: self.wind_time,
        };
        w.validate().map_err(|e| {
            let option = if e.contains("gustiness") {
                format!("--wind-gustiness {}", self.wind_gustiness)
            } else if e.contains("time") {
                format!("--wind-time {}", self.wind_time)
            } else {
                format!("--wind {towards_deg},{speed}")
            };
            anyhow::anyhow!("{option}: {e}")
        })?;
        Ok(w)
    }
}

/// The season every method colours the leaves in (shared by `forest render`, `forest view`
/// and the benches; see `forest_format::colour`).
#[derive(clap::Args, Debug, Clone)]
pub struct SeasonArgs {
    /// The season the leaves are drawn in: a number from 0 to 1 (spring 0, summer 0.33,
    /// autumn 0.67, late autumn 1) or a name (spring, summer, autumn, late-autumn); each tree
    /// of a varied forest is a little ahead or behind [default: none, the models' own colours]
    #[arg(long, value_parser = forest_format::colour::parse_season, allow_negative_numbers = true)]
    pub season: Option<f32>,
}

/// The sun's shadows (shared by `forest render` and `forest view`).
#[derive(clap::Args, Debug, Clone)]
pub struct ShadowArgs {
    /// The sun's shadows, cast by the trees onto the ground and each other through cascaded
    /// shadow maps, by every method [default: off in `render`, on in `view`]
    #[arg(long, value_parser = ["on", "off"])]
    pub shadows: Option<String>,
    /// Shadow cascades, 1 to 4.
    #[arg(long, default_value_t = ShadowOptions::default().cascades)]
    pub shadow_cascades: u32,
    /// Side of each cascade's map in texels (64 to 8192).
    #[arg(long, default_value_t = ShadowOptions::default().resolution)]
    pub shadow_resolution: u32,
    /// Shadows end this far along the view (metres).
    #[arg(long, allow_negative_numbers = true, default_value_t = ShadowOptions::default().distance)]
    pub shadow_distance: f32,
    /// The light views' refinement threshold ε, in shadow-map texels.
    #[arg(long, allow_negative_numbers = true, default_value_t = ShadowOptions::default().epsilon)]
    pub shadow_epsilon: f32,
}

impl ShadowArgs {
    /// The shadow options asked for (None: off; `on` when not given), checked whether the
    /// shadows are on or off (a bad value is never silently ignored): the error names it.
    pub fn options(&self, on: bool) -> Result<Option<ShadowOptions>> {
        let o = ShadowOptions {
            cascades: self.shadow_cascades,
            resolution: self.shadow_resolution,
            distance: self.shadow_distance,
            epsilon: self.shadow_epsilon,
            ..Default::default()
        };
        o.validate().map_err(|e| anyhow::anyhow!("{e}"))?;
        let off = self.shadows.as_deref().map_or(!on, |s| s == "off");
        Ok((!off).then_some(o))
    }
}

impl LightArgs {
    /// The light asked for, checked: the error names the bad value.
    pub fn lighting(&self) -> Result<forest_format::shading::Lighting> {
        let (az, el) = self.sun;
        if !(0.0..=90.0).contains(&el) {
            anyhow::bail!("--sun {az},{el}: the elevation must be 0 to 90 degrees");
        }
        let base = match self.time {
            Some(h) if !(6.0..=18.0).contains(&h) => {
                anyhow::bail!("--time {h}: the hour must be 6 (sunrise) to 18 (sunset)")
            }
            Some(h) => forest_format::shading::Lighting::at_hour(h, crate::window::NOON_ELEVATION),
            None => forest_format::shading::Lighting::with_sun(az, el),
        };
        let l = forest_format::shading::Lighting {
            exposure: self.exposure,
            ..base
        };
        l.validate()
            .map_err(|e| anyhow::anyhow!("--exposure {}: {e}", self.exposure))?;
        Ok(l)
    }
}

pub(crate) fn parse_sun(s: &str) -> Result<(f32, f32), String> {
    let parts: Vec<&str> = s.split(',').collect();
    let [az, el] = parts.as_slice() else {
        return Err(format!(
            "{s:?}: expected AZIMUTH,ELEVATION in degrees, e.g. 30,55"
        ));
    };
    let num = |x: &str| {
        x.trim()
            .parse::<f32>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("{x:?} is not a finite number of degrees"))
    };
    Ok((num(az)?, num(el)?))
}

/// The `--method` values.
pub const METHODS: [&str; 7] = [
    "quads",
    "impostor",
    "geometry",
    "reference",
    "stochastic",
    "lods",
    "hybrid",
];

/// The method and its parameters (shared by `forest render` and `forest view`).
#[derive(clap::Args, Debug, Clone)]
pub struct MethodArgs {
    /// Rendering method: the quad stream; static impostors (the stream without refinement);
    /// full geometry (the brute-force baseline); the reference (full geometry with every
    /// texture read at its finest level, for --supersample 4); stochastic simplification;
    /// discrete LODs + billboards; hybrid (trees nearer than --near as full geometry, the
    /// rest as the quad stream). The last five draw the models the bake stored in the atlases
    /// (model.bin), or --models. Default: hybrid, the most accurate for its time (the quad
    /// stream alone is poor within a few crown radii of the eye); quads where an atlas holds
    /// no model, said on stderr.
    #[arg(long, value_parser = METHODS)]
    pub method: Option<String>,
    /// Models (OBJ, or glTF 2.0 `.gltf`/`.glb`) of the forest's species, in its species order
    /// (geometry-based methods), instead of those stored in the atlases. Each must be the file its
    /// atlas was baked from (the same bytes, or else the same bounding sphere within 1 %)
    #[arg(long, value_delimiter = ',')]
    pub models: Vec<PathBuf>,
    /// Draw --models that are not the files their atlases were baked from (each is named on stderr)
    #[arg(long)]
    pub allow_other_models: bool,
    /// Full geometry: draw trees in submission order instead of nearest distance band first,
    /// and each tree's triangles in the model's order instead of front to back.
    #[arg(long)]
    pub unsorted: bool,
    /// Stochastic: distance (m, per unit tree scale) within which every leaf is drawn.
    #[arg(long, allow_negative_numbers = true, default_value_t = Stochastic::default().d0)]
    pub d0: f32,
    /// Stochastic: the d0²/d² at which half the leaves are drawn, in (0, 1).
    #[arg(long, allow_negative_numbers = true, default_value_t = Stochastic::default().h)]
    pub h: f32,
    /// Stochastic: fading band width as a fraction of λ.
    #[arg(long, allow_negative_numbers = true, default_value_t = Stochastic::default().fade)]
    pub fade: f32,
    /// Stochastic: no area preservation.
    #[arg(long)]
    pub no_area: bool,
    /// Stochastic: no contrast preservation.
    #[arg(long)]
    pub no_contrast: bool,
    /// LODs: distances (m, per unit tree scale) where LOD 1, LOD 2 and billboards start.
    #[arg(long, value_delimiter = ',', default_values_t = Lods::default().distances, allow_hyphen_values = true)]
    pub lod_distances: Vec<f32>,
    /// Quad stream: how a tree's 1–3 aspects combine: over (alpha-blended over each other,
    /// the paper's blend: coverage is their union), dither (each pixel shows one aspect,
    /// chosen by weight: coverage is the weighted mean), nearest (the largest weight alone).
    #[arg(long, default_value = "over", value_parser = clap::builder::PossibleValuesParser::new(AspectBlend::ALL.map(AspectBlend::name)))]
    pub blend: String,
    /// Quad stream: refine also by each quad's projected depth error, not only by its
    /// projected edge length (the paper's metric).
    #[arg(long)]
    pub depth_error: bool,
    /// Quad stream: draw every quad over its whole square, as the paper does, instead of its
    /// node's covered box (for comparison; the images agree, the fragments do not).
    #[arg(long)]
    pub untrimmed: bool,
    /// Quad stream: blend the aspects of every tree and refine every tree, as the paper does,
    /// also the far trees (see --far-span; drawn by default with their nearest aspect alone).
    #[arg(long)]
    pub far_blend: bool,
    /// Quad stream: a tree narrower than this many ε (pixels) across, whose nearest aspect's
    /// parallax stays within ε, is far: drawn with that aspect alone, its slabs composited
    /// into one quad, unrefined. 1 keeps only the trees narrower than ε far
    #[arg(long, default_value_t = forest_render::options::FAR_SPAN_DEFAULT,
          value_parser = clap::value_parser!(u32).range(1..=i64::from(forest_render::options::FAR_SPAN_MAX)))]
    pub far_span: u32,
    /// Quad stream: aspect sharpening, 0 to 0.333: each of a tree's 1–3 blend weights loses
    /// this share and the rest are scaled back to one, so aspects of small weight fade out
    /// (fewer layers of quads); 0 is the paper's blend. Default 0.1, and 0.2 for the
    /// hybrid's quads (the trees beyond its switch)
    #[arg(long, value_parser = parse_sharpen)]
    pub sharpen: Option<f64>,
    /// Quad stream: trees narrower than this many far spans (see --far-span) are sharpened
    /// more the narrower they are, up to 0.333 at the far span (1 to 15; 1: every tree
    /// keeps --sharpen; off with --far-blend)
    #[arg(long, default_value_t = forest_render::options::SHARPEN_REACH_DEFAULT,
          value_parser = clap::value_parser!(u32).range(1..=i64::from(forest_render::options::SHARPEN_REACH_MAX)))]
    pub sharpen_reach: u32,
    /// Quad stream: draw each slab of a far tree (see --far-span) as its own quad (by default
    /// its slabs are composited into one quad, sampled through their parallax).
    #[arg(long)]
    pub far_slabs: bool,
    /// Quad stream: without the opaque pass, which first draws each tree's opaque front with
    /// depth written a slab's thickness behind it, so that the depth test rejects what lies
    /// further behind (the same image, fewer fragments shaded).
    #[arg(long)]
    pub no_opaque_pass: bool,
    /// Hybrid: trees nearer than this (metres, eye to crown centre) are drawn as full
    /// geometry; `auto`: per species, where its quad stream becomes less accurate than its
    /// triangles, i.e. where its finest quads project wider than the crossover its bake
    /// measured (1.5 px for atlases baked without a GPU; it follows each tree's size and the
    /// view, not ε).
    #[arg(long, default_value = "auto", value_parser = parse_near, allow_hyphen_values = true)]
    pub near: Near,
    /// Hybrid: width of the transition band, as a fraction of the switch distance (a tree
    /// in it is drawn by both forms through complementary screen-door masks).
    #[arg(long, allow_negative_numbers = true, default_value_t = Hybrid::default().band)]
    pub band: f32,
}

fn parse_sharpen(s: &str) -> Result<f64, String> {
    let max = f64::from(forest_render::options::SHARPEN_MAX) / f64::from(WEIGHT_ONE);
    match s.parse::<f64>() {
        Ok(x) if (0.0..=max).contains(&x) => Ok(x),
        _ => Err(format!("{s:?}: expected a share from 0 to {max:.3}")),
    }
}

fn parse_near(s: &str) -> Result<Near, String> {
    if s == "auto" {
        return Ok(Near::Auto);
    }
    match s.parse::<f32>() {
        Ok(m) if m >= 0.0 => Ok(Near::Metres(m)),
        _ => Err(format!(
            "{s:?}: expected auto or a distance of 0 metres or more"
        )),
    }
}

/// The method drawn when `--method` is not given: the hybrid.
pub const DEFAULT_METHOD: &str = "hybrid";

impl MethodArgs {
    /// The method's name: `--method`, else [`DEFAULT_METHOD`] (see [`Self::settle`]).
    pub fn name(&self) -> &str {
        self.method.as_deref().unwrap_or(DEFAULT_METHOD)
    }

    /// Settle the method the user left to the program: the hybrid where `--models` are
    /// given or every atlas of `forest` (read from `forest_file`) holds a model, else the
    /// quad stream, with a line on stderr naming the atlas without one. A method given by
    /// name is kept (and fails later with the cause if it cannot be drawn).
    pub fn settle(&mut self, forest_file: &Path, forest: &Forest) {
        if self.method.is_some() {
            return;
        }
        let dir = forest_file.parent().unwrap_or(Path::new("."));
        let missing = forest
            .species
            .iter()
            .find(|s| !dir.join(s).join(forest_format::model::MODEL_FILE).exists());
        self.method = Some(match missing {
            Some(s) if self.models.is_empty() => {
                eprintln!(
                    "note: drawing the quad stream, not the hybrid: {} holds no model ({}); \
                     bake it without --no-model, give --models, or choose a --method",
                    dir.join(s).display(),
                    forest_format::model::MODEL_FILE
                );
                "quads".into()
            }
            _ => DEFAULT_METHOD.into(),
        });
    }

    /// The quad stream's run-time options.
    pub fn stream_options(&self) -> StreamOptions {
        StreamOptions {
            blend: AspectBlend::from_name(&self.blend).unwrap_or_default(),
            depth_error: self.depth_error,
            trim: !self.untrimmed,
            far_nearest: !self.far_blend,
            far_composite: !self.far_slabs,
            far_span: self.far_span,
            sharpen: self.sharpen_or(forest_render::options::SHARPEN_DEFAULT),
            sharpen_reach: self.sharpen_reach,
            opaque_first: !self.no_opaque_pass,
        }
    }

    /// The hybrid's aspect sharpening: `--sharpen` when given, else the hybrid's default.
    pub(crate) fn hybrid_sharpen(&self) -> u32 {
        self.sharpen_or(forest_baselines::hybrid::HYBRID_SHARPEN_DEFAULT)
    }

    /// `--sharpen` in units of 1/[`WEIGHT_ONE`], else `default`.
    fn sharpen_or(&self, default: u32) -> u32 {
        self.sharpen
            .map_or(default, |s| (s * f64::from(WEIGHT_ONE)).round() as u32)
    }

    /// The geometry method `name` names (for the hybrid: its near trees' form; None for the
    /// quad-stream methods).
    pub fn method(&self, name: &str) -> Result<Option<MeshMethod>> {
        let m = match name {
            "geometry" | "hybrid" => MeshMethod::Full {
                depth_sort: !self.unsorted,
            },
            "reference" => MeshMethod::Reference,
            "stochastic" => MeshMethod::Stochastic(Stochastic {
                d0: self.d0,
                h: self.h,
                fade: self.fade,
                area: !self.no_area,
                contrast: !self.no_contrast,
            }),
            "lods" => {
                let d: [f32; 3] = self.lod_distances.as_slice().try_into().map_err(|_| {
                    anyhow::anyhow!(
                        "--lod-distances needs three distances, got {}",
                        self.lod_distances.len()
                    )
                })?;
                MeshMethod::Lods(Lods { distances: d })
            }
            _ => return Ok(None),
        };
        m.validate()?;
        Ok(Some(m))
    }
}

impl MethodArgs {
    /// The method `--method` names, with `mesh` (from [`Self::checked_method`]) for the
    /// geometry-based ones and the hybrid's near trees.
    pub fn chosen(&self, mesh: Option<MeshMethod>) -> Result<Method> {
        Ok(match (self.name(), mesh) {
            ("hybrid", Some(near_form)) => {
                let h = Hybrid {
                    near: self.near,
                    band: self.band,
                    near_form,
                    sharpen: self.hybrid_sharpen(),
                    ..Default::default()
                };
                h.validate()?;
                Method::Hybrid(h)
            }
            (_, Some(x)) => Method::Mesh(x),
            ("impostor", None) => Method::Impostor,
            _ => Method::Quads,
        })
    }

    /// The geometry method chosen (None for the quad-stream methods), requiring one model per
    /// species for it when --models is given (else the atlases' stored models are drawn).
    pub fn checked_method(&self, species: usize) -> Result<Option<MeshMethod>> {
        let m = self.method(self.name())?;
        if m.is_some() && !self.models.is_empty() && self.models.len() != species {
            bail!(
                "--method {} needs --models with one model per species ({} given, the forest has {species})",
                self.name(),
                self.models.len()
            );
        }
        Ok(m)
    }
}

pub(crate) fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|x| {
            x.trim()
                .parse::<f32>()
                .map_err(|_| format!("{x:?} is not a number"))
        })
        .collect::<Result<_, _>>()?;
    if let Some(c) = v.iter().find(|c| !c.is_finite()) {
        return Err(format!("{s:?}: {c} is not a finite number"));
    }
    match v.as_slice() {
        [x, y, z] => Ok(Vec3::new(*x, *y, *z)),
        _ => Err(format!(
            "{s:?}: expected three numbers x,y,z, got {}",
            v.len()
        )),
    }
}

/// `off` (infinite) or a distance in metres, positive and finite.
pub(crate) fn parse_haze(s: &str) -> Result<f32, String> {
    if s == "off" {
        return Ok(f32::INFINITY);
    }
    match s.parse::<f32>() {
        Ok(v) if v > 0.0 && v.is_finite() => Ok(v),
        _ => Err(format!(
            "{s:?}: expected off or a distance in metres above 0"
        )),
    }
}

pub(crate) fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once('x')
        .ok_or_else(|| format!("{s:?}: expected WIDTHxHEIGHT"))?;
    let p = |x: &str| {
        x.parse::<u32>()
            .ok()
            .filter(|&v| (1..=16384).contains(&v))
            .ok_or_else(|| format!("{x:?} is not a size from 1 to 16384"))
    };
    Ok((p(w)?, p(h)?))
}
