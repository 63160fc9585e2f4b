//! `forest view`: the walkthrough viewer — a window (see [`crate::window`]), or, with
//! `--path FILE --frames DIR`, a recorded camera path played back headless to numbered PNGs.
//! Without a forest file it opens the bundled demo forest ([`crate::demo`]).

use forest_format::shading::Lighting;
use std::path::{Path, PathBuf};
use std::rc::Rc;

use anyhow::{Context, Result, bail};
use clap::Args;
use forest_baselines::geometry::{GeometryRenderer, PreparedGeometry};
use forest_baselines::methods::ForestRenderer;
use forest_format::camera_path::CameraPath;
use forest_format::forest::Forest;
use forest_render::fragments::FragmentCounter;
use forest_render::options::{Atmosphere, Background, DebugView, RendererOptions};
use forest_render::scene::SpeciesData;
use forest_render::target::{TARGET_FORMAT, Target};
use forest_render::{Camera, ForestView, GpuContext, QuadStream};
use glam::Vec3;

use crate::render::{MethodArgs, load_scene, models_for, overdraw_view, write_png};
use crate::render_args::parse_size;

/// Arguments of `forest view`.
#[derive(Args, Debug)]
pub struct ViewArgs {
    /// Forest file (binary .forest or .json); without it, the bundled demo forest (its trees
    /// baked on first use and cached in out/, run from the repository's folder).
    pub forest: Option<PathBuf>,
    /// Camera path (JSON, see `forest_format::camera_path`) to play back: in the window from
    /// its first key (P replays it), or headless with --frames.
    #[arg(long)]
    pub path: Option<PathBuf>,
    /// Render the path headless to DIR/frame-00000.png, … and exit.
    #[arg(long, requires = "path")]
    pub frames: Option<PathBuf>,
    /// Keys per second of the headless frames (--frames): key i is drawn at the wind's
    /// instant --wind-time + i / RATE, so the frames are an animation of the wind.
    #[arg(long, allow_negative_numbers = true, default_value_t = 30.0)]
    pub frame_rate: f32,
    /// Where R saves a recorded camera path (interactive mode).
    #[arg(long, default_value = "camera-path.json")]
    pub record: PathBuf,
    /// Folder F12 screenshots go to (screenshot-NNN.png, with its camera as a one-key path
    /// screenshot-NNN.json).
    #[arg(long, default_value = ".")]
    pub screenshots: PathBuf,
    /// Debug view: off; of the quad-stream methods levels (quads coloured by level), weights
    /// (by sampling direction, blended by aspect weight), wireframe (quad outlines); of every
    /// method overdraw (a heat map of the fragments shaded per pixel, counted exactly).
    #[arg(long, default_value = "off", value_parser = parse_debug_view)]
    pub debug_view: DebugView,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Refinement threshold ε in pixels (quad stream).
    #[arg(long, allow_negative_numbers = true, default_value_t = 4.0)]
    pub epsilon: f32,
    #[command(flatten)]
    pub m: MethodArgs,
    #[command(flatten)]
    pub light: crate::render::LightArgs,
    #[command(flatten)]
    pub wind: crate::render::WindArgs,
    #[command(flatten)]
    pub season: crate::render::SeasonArgs,
    #[command(flatten)]
    pub shadow: crate::render::ShadowArgs,
}

fn parse_debug_view(s: &str) -> Result<DebugView, String> {
    DebugView::ALL
        .into_iter()
        .find(|v| v.name().split(' ').next() == Some(s))
        .ok_or_else(|| format!("{s:?}: expected off, levels, weights, wireframe or overdraw"))
}

/// The quad stream of `forest` for a colour format, sized for `viewport` and ε `min_epsilon`
/// (pixels), over the sky and ground, in the demo's haze.
fn quad_stream(
    ctx: &GpuContext,
    species: &[SpeciesData],
    forest: &Forest,
    format: wgpu::TextureFormat,
    viewport: (u32, u32),
    min_epsilon: f32,
    light: Lighting,
) -> Result<QuadStream> {
    let opts = RendererOptions {
        viewport,
        min_epsilon,
        ..viewer_options(format, light)
    };
    Ok(QuadStream::new(
        &ctx.device,
        crate::progress::upload(ctx, species, forest)?,
        &opts,
    )?)
}

/// The geometry renderer of `forest` for a colour format, over the sky and ground, in the
/// demo's haze.
fn geometry(
    ctx: &GpuContext,
    prepared: &PreparedGeometry,
    forest: &Forest,
    format: wgpu::TextureFormat,
    light: Lighting,
) -> Result<GeometryRenderer> {
    Ok(GeometryRenderer::with_targets(
        ctx,
        prepared,
        forest,
        &viewer_options(format, light),
    )?)
}

/// What both forms draw into and over in the viewer: `format` targets, the sky and ground, the
/// demo's haze, under `light` (one source, so that the hybrid's two forms always agree).
fn viewer_options(format: wgpu::TextureFormat, light: Lighting) -> RendererOptions {
    RendererOptions {
        format,
        background: Background::Sky,
        atmosphere: Atmosphere::hazy(Atmosphere::DEMO_VISIBILITY),
        lighting: light,
        ..Default::default()
    }
}

/// Far plane (metres): beyond the farthest tree from anywhere in the forest.
/// Run `forest view`.
pub fn run(args: &ViewArgs) -> Result<()> {
    let light = args.light.lighting()?;
    let wind = args.wind.wind()?;
    if !(args.frame_rate.is_finite() && (1.0..=1000.0).contains(&args.frame_rate)) {
        anyhow::bail!(
            "--frame-rate {}: expected 1 to 1000 keys per second",
            args.frame_rate
        );
    }
    let mut args_models = args.m.clone();
    let forest_file = match &args.forest {
        Some(f) => f.clone(),
        None => {
            let demo = crate::demo::prepare()?;
            if args_models.models.is_empty() {
                args_models.models = demo.models;
            }
            demo.forest
        }
    };
    if !args.screenshots.is_dir() {
        bail!(
            "screenshot folder {} does not exist",
            args.screenshots.display()
        );
    }
    if let Some(dir) = args.record.parent().filter(|p| !p.as_os_str().is_empty())
        && !dir.is_dir()
    {
        bail!(
            "--record {}: folder {} does not exist",
            args.record.display(),
            dir.display()
        );
    }
    // Nothing the viewer reads may be written over: the forest, the path, the models, and
    // no atlas at all (the forest's atlases are checked once it is loaded).
    let mut inputs = vec![forest_file.clone()];
    inputs.extend(args.path.iter().cloned());
    for m in &args_models.models {
        inputs.extend(forest_bake::source_files(m).unwrap_or_else(|_| vec![m.clone()]));
    }
    crate::guard::output(&args.record, "--record", &inputs)?;
    crate::guard::extension(&args.record, "--record", "a camera path (JSON)", &["json"])?;
    crate::guard::not_in_atlas(&args.screenshots, "screenshot folder")?;
    let Some(frames) = &args.frames else {
        return interactive(args, &forest_file, &args_models, light, wind);
    };
    let path_file = args
        .path
        .as_ref()
        .expect("clap requires --path with --frames");
    let path = CameraPath::load(path_file)?;
    // The wind's instant of the last key, checked before any frame is drawn.
    let last = path.keys.len().saturating_sub(1);
    forest_format::wind::Wind {
        time: wind.time + last as f32 / args.frame_rate,
        ..wind
    }
    .validate()
    .map_err(|e| {
        anyhow::anyhow!(
            "--wind-time {} with {} keys at --frame-rate {}: the last key's {e}",
            wind.time,
            path.keys.len(),
            args.frame_rate
        )
    })?;
    if frames.exists() && !frames.is_dir() {
        bail!(
            "frames folder {} is a file, not a folder: name a folder for the frames",
            frames.display()
        );
    }
    if !frames.is_dir() {
        bail!(
            "frames folder {} does not exist: create it first",
            frames.display()
        );
    }
    crate::guard::not_in_atlas(frames, "frames folder")?;
    let (forest, species) = load_scene(&forest_file)?;
    args_models.settle(&forest_file, &forest);
    let dir = forest_file.parent().unwrap_or(Path::new("."));
    inputs.extend(forest.species.iter().map(|s| dir.join(s)));
    let frame_file = |i: usize| frames.join(format!("frame-{i:05}.png"));
    for i in 0..path.keys.len() {
        crate::guard::output(&frame_file(i), "frame", &inputs)?;
    }
    let mesh_method = args_models.checked_method(forest.species.len())?;
    let ctx = crate::gpu_context()?;
    let geometry = match mesh_method {
        Some(_) => Some(geometry(
            &ctx,
            &models_for(
                &args_models.models,
                &forest_file,
                &forest,
                &species,
                args_models.allow_other_models,
            )?,
            &forest,
            TARGET_FORMAT,
            light,
        )?),
        None => None,
    };
    let mut r = ForestRenderer::new(
        quad_stream(
            &ctx,
            &species,
            &forest,
            TARGET_FORMAT,
            args.size,
            args.epsilon,
            light,
        )?,
        geometry,
    );
    r.stream.set_debug_view(args.debug_view);
    r.stream.set_options(args_models.stream_options())?;
    let method = args_models.chosen(mesh_method)?;
    r.set_method(&ctx, method)?;
    r.set_shadows(&ctx.device, args.shadow.options(true)?)?;
    r.set_wind(wind)?;
    r.set_season(args.season.season)?;
    let target = Target::new(&ctx, args.size.0, args.size.1);
    // The overdraw view: each frame counted (drawn twice more) and its heat map drawn over it.
    let counter = match args.debug_view {
        DebugView::Overdraw => Some(FragmentCounter::new(
            &ctx.device,
            args.size.0,
            args.size.1,
            r.stream.options_built().reverse_z,
        )?),
        _ => None,
    };
    let mut total_ms = 0.0;
    for (i, key) in path.keys.iter().enumerate() {
        // The wind's instant of this key (checked: a long path may run past the clock's bound).
        r.set_wind(forest_format::wind::Wind {
            time: wind.time + i as f32 / args.frame_rate,
            ..wind
        })?;
        let cam = Camera {
            eye: Vec3::from_array(key.eye),
            target: Vec3::from_array(key.target),
            fov_y_deg: path.fov_deg,
            near: 0.1,
            far: forest.far_plane(Vec3::from_array(key.eye)),
            viewport: args.size,
            epsilon: args.epsilon,
        };
        let stats = r
            .render_fitted(&ctx, &cam, &target)
            .with_context(|| format!("{}: key {i}", path_file.display()))?;
        if let Some(counter) = &counter {
            forest_render::fragments::count_fragments(
                &ctx,
                counter,
                &mut r,
                |r, device, counter| r.set_fragment_counter(device, counter),
                |r| r.render_frame(&ctx, &cam, &target),
            )?;
            overdraw_view(&ctx, &target, counter);
        }
        ctx.check_errors()?;
        let t = stats.times.unwrap_or_default();
        total_ms += t.total_ms();
        write_png(&target.read(&ctx), &frame_file(i))?;
    }
    println!(
        "{} frames of {} -> {} (mean GPU {:.1} ms/frame, {})",
        path.keys.len(),
        method.name(),
        frames.display(),
        total_ms / path.keys.len() as f64,
        ctx.adapter_info.name
    );
    Ok(())
}

/// The window: walk through the forest with every method at hand.
fn interactive(
    args: &ViewArgs,
    forest_file: &Path,
    m: &MethodArgs,
    light: Lighting,
    wind: forest_format::wind::Wind,
) -> Result<()> {
    let (forest, species) = load_scene(forest_file)?;
    let mut m = m.clone();
    m.settle(forest_file, &forest);
    let m = &m;
    let mesh_method = m.checked_method(forest.species.len())?;
    // The models: --models, else those stored in the atlases (the geometry methods are
    // offered when every atlas holds one).
    let prepared = if m.models.is_empty() {
        match models_for(&[], forest_file, &forest, &species, false) {
            Ok(p) => Some(p),
            Err(e) if mesh_method.is_some() => return Err(e),
            Err(_) => None,
        }
    } else {
        Some(models_for(
            &m.models,
            forest_file,
            &forest,
            &species,
            m.allow_other_models,
        )?)
    };
    let path = args.path.as_deref().map(CameraPath::load).transpose()?;
    let chosen = m.chosen(mesh_method)?;
    // The hybrid offered beside another method takes --sharpen too, when given.
    let hybrid = forest_baselines::hybrid::Hybrid {
        sharpen: m.hybrid_sharpen(),
        ..Default::default()
    };
    let methods = crate::window::offered(chosen, prepared.is_some(), hybrid);
    let start = methods.iter().position(|x| *x == chosen).unwrap_or(0);
    let (size, epsilon) = (args.size, args.epsilon);
    // Both builders hold the forest (the window calls them once, when it has a device).
    let extent = forest.extent();
    let terrain = forest.terrain.clone();
    // Start inside the forest, standing on its ground.
    let start_view = Some(forest_render::named_view("inside", &forest, &species)?);
    let forest = Rc::new(forest);
    let f = forest.clone();
    // The stream's run-time options from the command line (--blend, --far-span, --sharpen…).
    let stream_options = m.stream_options();
    let build_stream: crate::window::BuildStream = Box::new(move |ctx, format, viewport, eps| {
        let mut s = quad_stream(ctx, &species, &f, format, viewport, eps, light)?;
        s.set_options(stream_options)?;
        Ok(s)
    });
    let build_geometry: crate::window::BuildGeometry = Box::new(move |ctx, format| {
        prepared
            .as_ref()
            .map(|p| geometry(ctx, p, &forest, format, light))
            .transpose()
    });
    crate::window::Viewer::new(crate::window::Settings {
        build_stream,
        build_geometry,
        size,
        epsilon,
        extent,
        terrain,
        start: start_view,
        methods,
        method: start,
        debug_view: args.debug_view,
        hour: args.light.time.unwrap_or(12.0),
        shadows: args.shadow.options(true)?,
        wind,
        season: args.season.season,
        path,
        record_to: args.record.clone(),
        screenshots: args.screenshots.clone(),
    })
    .run()
}
