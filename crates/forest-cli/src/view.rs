//! `forest view`: the walkthrough viewer. This part plays a recorded camera path back headless
//! to numbered PNGs (`--path FILE --frames DIR`) with any method; the interactive window
//! (winit + egui) is the open part of issue 6.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::Args;
use forest_format::camera_path::CameraPath;
use forest_render::methods::{ForestRenderer, Method};
use forest_render::renderer::{Background, RendererOptions};
use forest_render::target::{TARGET_FORMAT, Target};
use forest_render::{Camera, GpuContext, GpuScene, QuadStream};
use glam::Vec3;

use crate::render::{MethodArgs, load_scene, parse_size, prepare_models, write_png};

/// Arguments of `forest view`.
#[derive(Args, Debug)]
pub struct ViewArgs {
    /// Forest file (binary .forest or .json).
    pub forest: PathBuf,
    /// Camera path (JSON, see `forest_format::camera_path`) to play back.
    #[arg(long)]
    pub path: Option<PathBuf>,
    /// Render the path headless to DIR/frame-00000.png, … and exit.
    #[arg(long, requires = "path")]
    pub frames: Option<PathBuf>,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Refinement threshold ε in pixels (quad stream).
    #[arg(long, default_value_t = 4.0)]
    pub epsilon: f32,
    #[command(flatten)]
    pub m: MethodArgs,
}

/// Run `forest view`.
pub fn run(args: &ViewArgs) -> Result<()> {
    let Some(frames) = &args.frames else {
        bail!(
            "the interactive window is not built yet; play a camera path back headless with \
             --path FILE --frames DIR"
        );
    };
    let path_file = args
        .path
        .as_ref()
        .expect("clap requires --path with --frames");
    let path = CameraPath::load(path_file)?;
    if !frames.is_dir() {
        bail!("frames folder {} does not exist", frames.display());
    }
    let (forest, species) = load_scene(&args.forest)?;
    let mesh_method = args.m.checked_method(forest.species.len())?;
    let ctx = GpuContext::headless()?;
    let geometry = match mesh_method {
        Some(_) => Some(forest_render::geometry::GeometryRenderer::new(
            &ctx,
            &prepare_models(&args.m.models, &species)?,
            &forest,
            TARGET_FORMAT,
            Background::Sky,
        )?),
        None => None,
    };
    let opts = RendererOptions {
        format: TARGET_FORMAT,
        viewport: args.size,
        min_epsilon: args.epsilon,
        background: Background::Sky,
        ..Default::default()
    };
    let r = ForestRenderer::new(
        QuadStream::new(&ctx, GpuScene::new(&ctx, &species, &forest)?, &opts)?,
        geometry,
    );
    let method = match (args.m.method.as_str(), mesh_method) {
        (_, Some(m)) => Method::Mesh(m),
        ("impostor", None) => Method::Impostor,
        _ => Method::Quads,
    };
    r.set_method(&ctx, method)?;
    let target = Target::new(&ctx, args.size.0, args.size.1);
    let far = (forest.extent() * 3.0 + 100.0).max(1000.0);
    let mut total_ms = 0.0;
    for (i, key) in path.keys.iter().enumerate() {
        let cam = Camera {
            eye: Vec3::from_array(key.eye),
            target: Vec3::from_array(key.target),
            fov_y_deg: path.fov_deg,
            near: 0.1,
            far,
            viewport: args.size,
            epsilon: args.epsilon,
        };
        r.render_frame(&ctx, &cam, &target)
            .with_context(|| format!("{}: key {i}", path_file.display()))?;
        let stats = r.read_stats(&ctx);
        let errors = ctx.take_errors();
        if !errors.is_empty() {
            bail!("the GPU reported: {}", errors.join("; "));
        }
        let t = stats.times.unwrap_or_default();
        total_ms += t.cull_ms + t.refine_ms + t.draw_ms;
        write_png(
            &target.read(&ctx),
            &frames.join(format!("frame-{i:05}.png")),
        )?;
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
