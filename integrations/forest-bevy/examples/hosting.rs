//! The cost of hosting the forest in Bevy: frame times of a forest view drawn by the plugin
//! inside a headless Bevy app (the whole `App::update` plus waiting for the GPU) against the
//! same view drawn by `forest-render` alone (write the camera, cull, refine, draw, wait), in
//! one run, interleaved, medians of the frames.
//!
//! ```sh
//! cargo run --release --ignore-rust-version --example hosting -- FOREST [--size WxH] [--frames N] [--no-depth] [--method quads|hybrid|lods]
//! ```
//! `--no-depth` draws without `ForestCamera::write_depth`. `--method` draws the hybrid
//! (default), the quad stream or the discrete LODs (the hybrid and the LODs from the models
//! the atlases hold).
//! Bevy's camera draws one sample per pixel, as `forest-render`'s frame does.

use forest_render::ForestView;
use std::path::PathBuf;
use std::time::Instant;

use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::prelude::*;
use bevy::render::RenderApp;
use bevy::render::renderer::RenderDevice;
use bevy::window::{ExitCondition, WindowPlugin};
use forest_baselines::{ForestRenderer, GeometryRenderer};
use forest_bevy::{ForestCamera, ForestMethod, ForestPlugin, ForestScene, ForestStats};
use forest_render::{FrameParams, GpuContext, GpuScene, QuadStream, RendererOptions, Targets};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

type Error = Box<dyn std::error::Error>;

/// The command line.
struct Args {
    forest: PathBuf,
    size: (u32, u32),
    frames: usize,
    settings: ForestCamera,
}

impl Args {
    fn parse() -> Result<Self, Error> {
        let args: Vec<String> = std::env::args().skip(1).collect();
        let value = |flag: &str| {
            args.iter()
                .position(|a| a == flag)
                .and_then(|i| args.get(i + 1))
        };
        let forest = PathBuf::from(
            args.first()
                .ok_or("usage: hosting FOREST [--size WxH] [--frames N]")?,
        );
        let size = match value("--size") {
            Some(s) => {
                let (a, b) = s.split_once('x').ok_or("--size WxH")?;
                (a.parse()?, b.parse()?)
            }
            None => (400u32, 300u32),
        };
        let frames: usize = value("--frames").map_or(Ok(7), |s| s.parse())?;
        let method = match value("--method").map(String::as_str) {
            Some("quads") => ForestMethod::QuadStream,
            None | Some("hybrid") => ForestMethod::Hybrid,
            Some("lods") => ForestMethod::DiscreteLods,
            Some(m) => return Err(format!("--method {m}: quads, hybrid or lods").into()),
        };
        let settings = ForestCamera {
            method,
            epsilon: 4.0,
            write_depth: !args.iter().any(|a| a == "--no-depth"),
        };
        Ok(Args {
            forest,
            size,
            frames,
            settings,
        })
    }
}

/// forest-render alone: the method's renderer of the forest (the model methods draw the
/// models the atlases hold).
fn renderer_alone(
    ctx: &GpuContext,
    args: &Args,
    forest: &forest_format::forest::Forest,
    species: &[forest_render::SpeciesData],
) -> Result<ForestRenderer, Error> {
    let (w, h) = args.size;
    let opts = RendererOptions {
        reverse_z: true,
        viewport: (w, h),
        min_epsilon: args.settings.epsilon,
        atmosphere: forest_bevy::light::atmosphere(None, Vec3::ZERO, 1.0),
        ..Default::default()
    };
    let scene = std::sync::Arc::new(GpuScene::new(ctx, species, forest)?);
    let stream = QuadStream::new(&ctx.device, scene, &opts)?;
    let method = args.settings.method;
    let geometry = if method.needs_models() {
        let prepared =
            forest_baselines::geometry::models_for(&[], &args.forest, forest, species, false)?;
        Some(GeometryRenderer::with_targets(
            ctx,
            &prepared.geometry,
            forest,
            &opts,
        )?)
    } else {
        None
    };
    let mut renderer = ForestRenderer::new(stream, geometry);
    renderer.set_method(ctx, method.method())?;
    Ok(renderer)
}

/// A headless Bevy app drawing the forest file (in `folder`) with the plugin into an image
/// of `size`: the app, its camera and the forest's entity.
fn bevy_app(folder: &std::path::Path, args: &Args) -> Result<(App, Entity, Entity), Error> {
    let mut app = App::new();
    app.add_plugins(
        DefaultPlugins
            .set(AssetPlugin {
                file_path: folder.to_string_lossy().into_owned(),
                ..default()
            })
            .set(WindowPlugin {
                primary_window: None,
                exit_condition: ExitCondition::DontExit,
                ..default()
            })
            .disable::<bevy::winit::WinitPlugin>()
            .disable::<bevy::render::pipelined_rendering::PipelinedRenderingPlugin>(),
    )
    .add_plugins(ForestPlugin);
    while app.plugins_state() == bevy::app::PluginsState::Adding {
        bevy::tasks::tick_global_task_pools_on_main_thread();
    }
    app.finish();
    app.cleanup();
    let name = args
        .forest
        .file_name()
        .ok_or("no file name")?
        .to_string_lossy()
        .into_owned();
    let handle = app
        .world()
        .resource::<AssetServer>()
        .load::<forest_bevy::ForestAsset>(name);
    let forest_entity = app.world_mut().spawn(ForestScene(handle)).id();
    let (w, h) = args.size;
    let image = Image::new_target_texture(w, h, wgpu::TextureFormat::Rgba8UnormSrgb, None);
    let image = app.world_mut().resource_mut::<Assets<Image>>().add(image);
    let camera = app
        .world_mut()
        .spawn((
            Camera3d::default(),
            RenderTarget::Image(image.into()),
            Tonemapping::None,
            // One sample per pixel, as forest-render's own frame draws (Bevy's default is 4).
            bevy::render::view::Msaa::Off,
            args.settings,
        ))
        .id();
    Ok((app, camera, forest_entity))
}

/// One frame of forest-render alone: the camera, then cull, refine and draw, submitted.
fn draw_alone(
    ctx: &GpuContext,
    target: &forest_render::target::Target,
    stream: &mut ForestRenderer,
    frame: &FrameParams,
) -> Result<(), forest_render::RenderError> {
    stream.prepare(&ctx.queue, frame)?;
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    let clear = wgpu::Color::BLACK;
    let targets = Targets::cleared(&target.colour_view, &target.depth_view, clear, 0.0);
    stream.encode_compute(&mut enc);
    {
        let mut pass = targets.begin(&mut enc, "forest", stream.draw_timestamps());
        stream.render(&mut pass);
    }
    stream.resolve_times(&mut enc);
    ctx.queue.submit([enc.finish()]);
    Ok(())
}

/// Waits for Bevy's GPU work.
fn wait(app: &App) {
    let device = app.sub_app(RenderApp).world().resource::<RenderDevice>();
    let _ = device
        .wgpu_device()
        .poll(wgpu::PollType::wait_indefinitely());
}

/// The frame parameters of forest-render alone for a camera at `eye` looking at `at`, as
/// Bevy's default perspective projects it.
fn frame_at(eye: Vec3, at: Vec3, args: &Args) -> FrameParams {
    let (w, h) = args.size;
    let world_from_view = Transform::from_translation(eye)
        .looking_at(at, Vec3::Y)
        .to_matrix();
    let proj = bevy::camera::CameraProjection::get_clip_from_view(&PerspectiveProjection {
        aspect_ratio: w as f32 / h as f32,
        ..default()
    });
    let g = |m: Mat4| glam::Mat4::from_cols_array(&m.to_cols_array());
    FrameParams {
        view: g(world_from_view.inverse()),
        proj: g(proj),
        viewport: (w, h),
        epsilon: args.settings.epsilon,
        light: Default::default(),
        wind: forest_format::wind::Wind::CALM,
        season: None,
    }
}

/// Bevy and forest-render alone measured on one view, interleaved; its table row.
struct Hosting<'a> {
    app: App,
    camera: Entity,
    forest: Entity,
    ctx: &'a GpuContext,
    target: forest_render::target::Target,
    stream: ForestRenderer,
}

impl Hosting<'_> {
    fn row(&mut self, label: &str, eye: Vec3, at: Vec3, args: &Args) -> Result<String, Error> {
        let (app, camera) = (&mut self.app, self.camera);
        *app.world_mut()
            .get_mut::<Transform>(camera)
            .ok_or("camera")? = Transform::from_translation(eye).looking_at(at, Vec3::Y);
        let frame = frame_at(eye, at, args);
        // Warm both up until the streams hold the view.
        for _ in 0..200 {
            app.update();
            wait(app);
            if app
                .world()
                .resource::<ForestStats>()
                .get(camera, self.forest)
                .is_some_and(|s| s.quads > 0 || s.triangles > 0)
            {
                break;
            }
        }
        for _ in 0..4 {
            app.update();
            wait(app);
            draw_alone(self.ctx, &self.target, &mut self.stream, &frame)?;
            let stats = self.stream.read_stats(self.ctx);
            self.stream.fit(&self.ctx.device, &stats)?;
        }
        let (mut bevy, mut alone) = (Vec::new(), Vec::new());
        for _ in 0..args.frames {
            let t = Instant::now();
            app.update();
            wait(app);
            bevy.push(t.elapsed().as_secs_f64() * 1e3);
            let t = Instant::now();
            draw_alone(self.ctx, &self.target, &mut self.stream, &frame)?;
            let _ = self.ctx.device.poll(wgpu::PollType::wait_indefinitely());
            alone.push(t.elapsed().as_secs_f64() * 1e3);
        }
        let stats = app.world().resource::<ForestStats>();
        let quads = stats.quads(camera);
        let hosted = stats.get(camera, self.forest);
        let triangles = hosted.map_or(0, |s| s.triangles);
        let hosted_gpu = hosted.and_then(|s| s.gpu_ms).unwrap_or(f64::NAN);
        let alone_gpu = self
            .stream
            .read_stats(self.ctx)
            .times
            .map_or(f64::NAN, |t| t.total_ms());
        // Bevy's own frame: the same camera without the forest.
        app.world_mut().entity_mut(camera).remove::<ForestCamera>();
        let mut empty = Vec::new();
        for k in 0..args.frames + 2 {
            let t = Instant::now();
            app.update();
            wait(app);
            if k >= 2 {
                empty.push(t.elapsed().as_secs_f64() * 1e3);
            }
        }
        app.world_mut().entity_mut(camera).insert(args.settings);
        let (b, a, e) = (median(bevy), median(alone), median(empty));
        Ok(format!(
            "| {label} | {quads} | {triangles} | {b:.1} | {e:.1} | {a:.1} | {:.2} | {hosted_gpu:.1} | {alone_gpu:.1} |",
            b / a
        ))
    }
}

fn main() -> Result<(), Error> {
    let args = Args::parse()?;
    let folder = args
        .forest
        .parent()
        .unwrap_or(std::path::Path::new("."))
        .canonicalize()?;
    let ctx = GpuContext::headless()?;
    let (forest, species) = forest_render::load_scene(&args.forest, |_| {})?;
    // The viewer's opening view (clear of every tree), and one from 60 m above.
    let (eye, target) = forest_render::start_view(&forest, &species);
    let ground = forest.ground_height(0.0, 0.0);
    let views = [
        // forest-format's glam is not Bevy's: the points cross as arrays.
        (
            "inside",
            Vec3::from_array(eye.to_array()),
            Vec3::from_array(target.to_array()),
        ),
        (
            "above",
            Vec3::new(-60.0, ground + 60.0, -60.0),
            Vec3::new(0.0, ground, 0.0),
        ),
    ];
    let stream = renderer_alone(&ctx, &args, &forest, &species)?;
    let (app, camera, forest_entity) = bevy_app(&folder, &args)?;
    let (w, h) = args.size;
    let mut hosting = Hosting {
        app,
        camera,
        forest: forest_entity,
        ctx: &ctx,
        target: forest_render::target::Target::new(&ctx, w, h),
        stream,
    };
    println!(
        "| view | quads (Bevy) | triangles (Bevy) | Bevy frame, ms | Bevy frame without the forest, ms | \
         forest-render frame, ms | ratio | forest GPU passes in Bevy, ms | alone, ms |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for (label, eye, at) in views {
        println!("{}", hosting.row(label, eye, at, &args)?);
    }
    Ok(())
}
