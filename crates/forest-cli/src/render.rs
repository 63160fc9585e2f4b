//! `forest render`: headless rendering of camera views of a forest to PNG.

use forest_render::ForestView;
use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use forest_baselines::geometry::{self, GeometryRenderer, PreparedGeometry};
use forest_baselines::methods::{ForestRenderer, MethodStats};
use forest_format::forest::Forest;
use forest_render::fragments::OverdrawPass;
use forest_render::fragments::{FragmentCounter, FragmentCounts, FragmentSummary};
use forest_render::options::{Atmosphere, RendererOptions};
use forest_render::scene::SpeciesData;
use forest_render::target::{TARGET_FORMAT, Target};
use forest_render::{Camera, GpuContext, QuadStream};
use glam::Vec3;

pub use crate::render_args::{LightArgs, MethodArgs, RenderArgs, SeasonArgs, ShadowArgs, WindArgs};

/// Load a forest and its species' atlases ([`forest_render::load_scene`]), with a spinner.
pub fn load_scene(path: &Path) -> Result<(Forest, Vec<SpeciesData>)> {
    let spinner = crate::progress::spinner(format!("loading {}", path.display()));
    let scene = forest_render::load_scene(path, |n| {
        spinner.set_message(format!("loading the {n} atlases of {}", path.display()))
    })?;
    spinner.finish_and_clear();
    Ok(scene)
}

/// The species' models for the geometry-based methods ([`geometry::models_for`]), their notes
/// said on stderr.
pub fn models_for(
    models: &[PathBuf],
    forest_file: &Path,
    forest: &Forest,
    species: &[SpeciesData],
    allow_other: bool,
) -> Result<PreparedGeometry> {
    let sourced = geometry::models_for(models, forest_file, forest, species, allow_other)?;
    Ok(noted(sourced))
}

/// The models prepared, their notes (a model drawn though its bytes differ from the baked
/// one's) said on stderr.
pub fn noted(sourced: geometry::SourcedModels) -> PreparedGeometry {
    for note in &sourced.notes {
        eprintln!("forest: note: {note}");
    }
    sourced.geometry
}

/// Run `forest render`.
pub fn run(args: &RenderArgs) -> Result<()> {
    args.light.lighting()?;
    let wind = args.wind.wind()?;
    let animation = args.animation(&wind)?;
    let mut views: Vec<(String, Vec3, Vec3)> = Vec::new();
    let (forest, species) = load_scene(&args.forest)?;
    let mut settled = args.clone();
    settled.m.settle(&args.forest, &forest);
    let args = &settled;
    for v in &args.views {
        let (e, t) = forest_render::named_view(v, &forest, &species)?;
        views.push((v.clone(), e, t));
    }
    if let (Some(e), Some(t)) = (args.eye, args.target) {
        views.push(("camera".into(), e, t));
    }
    if views.is_empty() {
        bail!("give a --view (inside, hill, birds-eye) or --eye and --target");
    }
    let cameras: Vec<(String, Camera)> = views
        .into_iter()
        .map(|(name, eye, target)| {
            let far = forest.far_plane(eye);
            let cam = Camera {
                eye,
                target,
                fov_y_deg: args.fov,
                near: 0.1,
                far,
                viewport: args.size,
                epsilon: args.epsilon,
            };
            cam.validate().map(|()| (name, cam))
        })
        .collect::<Result<_, _>>()?;
    // Nothing the command reads may be overwritten: the forest, its atlases, the models.
    let dir = args.forest.parent().unwrap_or(Path::new("."));
    let mut inputs = vec![args.forest.clone()];
    inputs.extend(forest.species.iter().map(|s| dir.join(s)));
    for m in &args.m.models {
        inputs.extend(forest_bake::source_files(m).unwrap_or_else(|_| vec![m.clone()]));
    }
    for (name, _) in &cameras {
        let out = output_for(&args.output, name, cameras.len());
        crate::guard::output(&out, "output", &inputs)?;
        crate::guard::extension(&out, "output", "PNG", &["png"])?;
        let parent = out.parent().filter(|p| !p.as_os_str().is_empty());
        if let Some(p) = parent
            && !p.is_dir()
        {
            bail!("output folder {} does not exist", p.display());
        }
    }
    if !(1..=8).contains(&args.supersample) {
        bail!("supersample = {}: must be 1 to 8", args.supersample);
    }
    if args.overdraw() && args.supersample > 1 {
        bail!("--debug-view overdraw counts the pixels it shows: render it without --supersample");
    }
    if args.fragments && args.supersample > 1 {
        bail!(
            "--fragments counts the pixels of the image as rendered: count it without \
             --supersample (it would count the {0}×{0} larger image)",
            args.supersample
        );
    }
    let mesh_method = args.m.checked_method(forest.species.len())?;
    args.shadow.options(false)?;
    let method = args.m.chosen(mesh_method)?;
    let ctx = crate::gpu_context()?;
    if args.counts_fragments() {
        // Refused before the frames are drawn, not after.
        FragmentCounter::check_size(&ctx.device, args.size.0, args.size.1)?;
    }
    let geometry = if method.needs_models() {
        let prepared = args_models(args, &forest, &species)?;
        let opts = target_options(args);
        Some(GeometryRenderer::with_targets(
            &ctx, &prepared, &forest, &opts,
        )?)
    } else {
        None
    };
    let stream = stream_for(args, &ctx, &species, &forest, method.draws_quads())?;
    let mut r = ForestRenderer::new(stream, geometry);
    r.set_method(&ctx, method)?;
    r.set_shadows(&ctx.device, args.shadow.options(false)?)?;
    r.set_wind(wind)?;
    r.set_season(args.season.season)?;
    r.set_pipeline_statistics(args.json);
    render_views(args, &ctx, &cameras, animation, |cam, target, instant| {
        if let Some(t) = instant {
            r.set_wind(forest_format::wind::Wind { time: t, ..wind })?;
        }
        let stats = r.render_fitted(&ctx, cam, target)?;
        let (json, line) = report(args, &ctx, &r, &stats);
        let counted = count(
            args,
            &ctx,
            target,
            &mut r,
            |r, device, counter| r.set_fragment_counter(device, counter),
            |r| r.render_frame(&ctx, cam, target),
        )?;
        Ok(ViewReport {
            counted,
            json,
            line,
        })
    })
}

/// A frame's figures for `--json` and its line of text: the counters every method shares,
/// then those of the quad stream and of the geometry where the method drew them.
fn report(
    args: &RenderArgs,
    ctx: &GpuContext,
    r: &ForestRenderer,
    s: &MethodStats,
) -> (serde_json::Value, String) {
    let t = s.times.unwrap_or_default();
    let quads = u64::from(s.stream.quads);
    let triangles = s.primitives - quads;
    let mut json = serde_json::json!({
        "method": args.m.name(),
        "visible_trees": s.visible_trees, "geometry_trees": s.geometry_trees,
        "quads": quads, "triangles": triangles, "billboards": s.billboards,
        "per_level": s.per_level, "overflow": s.overflow,
        "cull_ms": t.cull_ms, "refine_ms": t.refine_ms, "draw_ms": t.draw_ms,
        "work": work_json(&s.work),
    });
    let o = json.as_object_mut().expect("an object");
    if r.method().draws_quads() {
        let stream = &r.stream;
        let cascades = stream.shadows().map(|sh| {
            sh.stats(ctx)
                .iter()
                .map(|c| {
                    let ct = c.times.unwrap_or_default();
                    serde_json::json!({"visible_trees": c.visible_trees, "quads": c.quads,
                        "cull_ms": ct.cull_ms, "refine_ms": ct.refine_ms, "draw_ms": ct.draw_ms,
                        "overflow_cull": c.overflow_cull, "overflow_refine": c.overflow_refine})
                })
                .collect::<Vec<_>>()
        });
        o.extend([
            ("composited_quads".into(), s.stream.composites.into()),
            ("overflow_cull".into(), s.stream.overflow_cull.into()),
            ("overflow_refine".into(), s.stream.overflow_refine.into()),
            ("capacity_quads".into(), stream.capacity.quads.into()),
            ("stream_bytes".into(), stream.capacity.bytes().into()),
            ("shadow_cascades".into(), serde_json::json!(cascades)),
        ]);
    }
    if let Some(g) = r.geometry.as_ref().filter(|_| r.method().needs_models()) {
        o.insert(
            "per_band".into(),
            serde_json::json!(g.read_stats(ctx).per_band),
        );
    }
    let line = format!(
        "{} ({}x supersampled): {} visible trees, {} as geometry, {quads} quads ({} composited) \
         {:?}, {triangles} triangles, {} billboards, overflow {}, cull {:.1} ms, refine {:.1} ms, \
         draw {:.1} ms",
        args.m.name(),
        args.supersample,
        s.visible_trees,
        s.geometry_trees,
        s.stream.composites,
        s.per_level,
        s.billboards,
        s.overflow,
        t.cull_ms,
        t.refine_ms,
        t.draw_ms,
    );
    (json, line)
}

/// What one rendered view reports: its figures for `--json` (merged with the view's name,
/// output, camera and adapter) and, without it, the middle of its line of text; with
/// `--fragments`, its exact counts and the counter that holds them.
struct ViewReport {
    json: serde_json::Value,
    line: String,
    counted: Option<(FragmentCounter, FragmentCounts)>,
}

/// With `--fragments` (or the overdraw view), the exact fragment counts of the view's frame:
/// `renderer` attached to a counter of the target's size by `attach` and drawn twice more by
/// `draw`.
fn count<R, E>(
    args: &RenderArgs,
    ctx: &GpuContext,
    target: &Target,
    renderer: &mut R,
    attach: fn(&mut R, &wgpu::Device, Option<&FragmentCounter>),
    draw: impl FnMut(&mut R) -> Result<(), E>,
) -> Result<Option<(FragmentCounter, FragmentCounts)>>
where
    anyhow::Error: From<E>,
{
    if !args.counts_fragments() {
        return Ok(None);
    }
    let (w, h) = target.size;
    let counter = FragmentCounter::new(&ctx.device, w, h, target_options(args).reverse_z)?;
    let counts = forest_render::fragments::count_fragments(ctx, &counter, renderer, attach, draw)?;
    Ok(Some((counter, counts)))
}

/// A counted frame's figures for `--json`.
fn fragments_json(s: &FragmentSummary) -> serde_json::Value {
    serde_json::json!({
        "covered_pixels": s.covered_pixels, "fragments": s.fragments,
        "per_covered_mean": s.per_covered_mean, "per_covered_median": s.per_covered_median,
        "per_covered_p95": s.per_covered_p95,
        "quad_lanes_per_covered": s.quad_lanes_per_covered,
        "transparent_share": s.transparent_share, "hidden_share": s.hidden_share,
    })
}

/// A counted frame's figures in words.
fn fragments_line(s: &FragmentSummary) -> String {
    format!(
        "; {:.1} fragments per covered pixel (median {}, 95th percentile {}), {:.1} 2×2-quad lanes, {:.0} % transparent, {:.0} % hidden, over {} covered pixels",
        s.per_covered_mean,
        s.per_covered_median,
        s.per_covered_p95,
        s.quad_lanes_per_covered,
        100.0 * s.transparent_share,
        100.0 * s.hidden_share,
        s.covered_pixels,
    )
}

/// Render every camera through `frame` into one target of the rendered viewport (the
/// output size times the supersampling), fail on any GPU error, save each view's PNG and
/// print its report: one JSON line with `--json`, else `NAME: LINE (ADAPTER) -> OUTPUT`.
fn render_views(
    args: &RenderArgs,
    ctx: &GpuContext,
    cameras: &[(String, Camera)],
    animation: Option<(u32, f32)>,
    mut frame: impl FnMut(&Camera, &Target, Option<f32>) -> Result<ViewReport>,
) -> Result<()> {
    let (sw, sh) = rendered_viewport(args);
    let target = Target::new(ctx, sw, sh);
    for (name, cam) in cameras {
        let mut cam = *cam;
        cam.viewport = (sw, sh);
        if let Some((frames, step)) = animation {
            // The wind's frames, one after another into one animated PNG.
            let out = output_for(&args.output, name, cameras.len());
            let start = args.wind.wind_time;
            let mut line = String::new();
            crate::animation::write_apng(&out, args.size, frames, step, |i| {
                let report = frame(&cam, &target, Some(start + i as f32 * step))?;
                ctx.check_errors()?;
                line = report.line;
                Ok(read_downsampled(&target, ctx, args.supersample))
            })?;
            println!(
                "{name}: {frames} frames at {} Hz, the last {line} ({}) -> {}",
                args.frame_rate,
                ctx.adapter_info.name,
                out.display()
            );
            continue;
        }
        let mut report = frame(&cam, &target, None)?;
        if let Some((counter, counts)) = &report.counted {
            if args.overdraw() {
                overdraw_view(ctx, &target, counter);
            }
            let s = counts.summary();
            report.line += &fragments_line(&s);
            if let serde_json::Value::Object(o) = &mut report.json {
                o.insert("fragments".into(), fragments_json(&s));
            }
        }
        let out = finish_view(ctx, &target, args, name, cameras.len())?;
        if args.json {
            let mut json = serde_json::json!({
                "view": name, "output": out.display().to_string(),
                "eye": cam.eye.to_array(), "target": cam.target.to_array(),
                "adapter": ctx.adapter_info.name,
            });
            if let (Some(all), serde_json::Value::Object(figures)) =
                (json.as_object_mut(), report.json)
            {
                all.extend(figures);
            }
            println!("{json}");
        } else {
            println!(
                "{name}: {} ({}) -> {}",
                report.line,
                ctx.adapter_info.name,
                out.display()
            );
        }
    }
    Ok(())
}

/// Draw the overdraw view of `counter`'s counts over `target`, with its legend.
pub(crate) fn overdraw_view(ctx: &GpuContext, target: &Target, counter: &FragmentCounter) {
    let view = OverdrawPass::new(&ctx.device, target.format);
    let binding = view.bind(&ctx.device, counter, true);
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    view.encode(&mut enc, &target.colour_view, &binding);
    ctx.queue.submit([enc.finish()]);
}

/// A frame's work for `--json`: dispatches, draws and bytes as recorded; the pipeline
/// statistics summed over the passes where the device counts them (null otherwise).
fn work_json(w: &forest_render::work::FrameWork) -> serde_json::Value {
    let total = w.total();
    serde_json::json!({
        "dispatches": w.dispatches, "draws": w.draws, "bytes": w.bytes,
        "vertex_invocations": total.map(|p| p.vertex_invocations),
        "primitives_rasterised": total.map(|p| p.primitives),
        "fragment_invocations": total.map(|p| p.fragment_invocations),
        "compute_invocations": total.map(|p| p.compute_invocations),
    })
}

/// The viewport every method renders at (the image size times the supersampling).
fn rendered_viewport(args: &RenderArgs) -> (u32, u32) {
    (
        args.size.0 * args.supersample,
        args.size.1 * args.supersample,
    )
}

/// The quad stream of the scene, sized for the rendered viewport and ε.
fn stream_for(
    args: &RenderArgs,
    ctx: &GpuContext,
    species: &[SpeciesData],
    forest: &Forest,
    draws: bool,
) -> Result<QuadStream> {
    let scene = crate::progress::upload(ctx, species, forest)?;
    let opts = RendererOptions {
        min_epsilon: args.epsilon.min(8.0),
        // A method that draws no quads keeps the stream at the image's own size: its
        // supersampled target would size the stream for nothing.
        viewport: if draws {
            rendered_viewport(args)
        } else {
            args.size
        },
        refine: args.m.name() != "impostor",
        ..target_options(args)
    };
    let mut stream = QuadStream::new(&ctx.device, scene, &opts)?;
    stream.set_options(args.m.stream_options())?;
    Ok(stream)
}

/// What both forms draw into and over: the crate's own targets, the background and the
/// atmosphere (one source, so that the hybrid's two forms always agree).
fn target_options(args: &RenderArgs) -> RendererOptions {
    RendererOptions {
        format: TARGET_FORMAT,
        background: background(args),
        atmosphere: atmosphere(args),
        // Checked in `run` before anything is loaded.
        lighting: args.light.lighting().unwrap_or_default(),
        ..Default::default()
    }
}

/// The haze asked for, or by default the demo's over the sky and none over transparent.
fn atmosphere(args: &RenderArgs) -> Atmosphere {
    let default = if args.transparent {
        f32::INFINITY
    } else {
        Atmosphere::DEMO_VISIBILITY
    };
    Atmosphere {
        haze_height: args.haze_height,
        ..Atmosphere::hazy(args.haze.unwrap_or(default))
    }
}

fn background(args: &RenderArgs) -> forest_render::options::Background {
    if args.transparent {
        forest_render::options::Background::Transparent
    } else {
        forest_render::options::Background::Sky
    }
}

/// Fail on any GPU error, then save the view's image; returns its path.
fn finish_view(
    ctx: &GpuContext,
    target: &Target,
    args: &RenderArgs,
    name: &str,
    views: usize,
) -> Result<PathBuf> {
    ctx.check_errors()?;
    let out = output_for(&args.output, name, views);
    save(target, ctx, args.supersample, &out)?;
    Ok(out)
}

/// Read the target back, box-filter it down by `supersample`, and write a PNG atomically.
fn save(target: &Target, ctx: &GpuContext, supersample: u32, out: &Path) -> Result<()> {
    write_png(&read_downsampled(target, ctx, supersample), out)
}

/// The target read back and box-filtered down by `supersample` (the image a view writes).
fn read_downsampled(target: &Target, ctx: &GpuContext, supersample: u32) -> image::RgbaImage {
    let img = target.read(ctx);
    if supersample > 1 {
        forest_baselines::geometry::downsample(&img, supersample)
    } else {
        img
    }
}

/// Write a PNG atomically (temporary name, then rename).
pub fn write_png(img: &image::RgbaImage, out: &Path) -> Result<()> {
    forest_format::atomic::write_with(out, |tmp| {
        img.save_with_format(tmp, image::ImageFormat::Png)
    })?;
    Ok(())
}

/// [`models_for`] the forest and the options of `render`.
fn args_models(
    args: &RenderArgs,
    forest: &Forest,
    species: &[SpeciesData],
) -> Result<PreparedGeometry> {
    models_for(
        &args.m.models,
        &args.forest,
        forest,
        species,
        args.m.allow_other_models,
    )
}

fn output_for(base: &Path, view: &str, views: usize) -> PathBuf {
    if views == 1 {
        return base.to_path_buf();
    }
    let stem = base
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ext = base
        .extension()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or("png".into());
    base.with_file_name(format!("{stem}-{view}.{ext}"))
}
