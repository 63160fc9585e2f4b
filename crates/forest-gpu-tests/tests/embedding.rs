//! The runtime as middleware in a host's frame: drawing over the host's pixels without
//! clearing them, nothing drawn before the first `prepare`, a resize that keeps the scene, the
//! host's MSAA and reverse-Z targets, statistics read back without waiting, typed errors, and
//! renderers that can be shared between threads.

mod common;

use forest_render::ForestView;
use std::sync::Arc;

use forest_baselines::{ForestRenderer, GeometryRenderer};
use forest_render::options::Background;
use forest_render::target::{TARGET_FORMAT, Target};
use forest_render::{
    FrameParams, GpuContext, GpuScene, QuadStream, RenderError, RendererOptions, Targets,
};
use glam::Vec3;

const SIZE: (u32, u32) = (160, 120);
const MAGENTA: wgpu::Color = wgpu::Color {
    r: 1.0,
    g: 0.0,
    b: 1.0,
    a: 1.0,
};

fn scene(ctx: &GpuContext) -> Arc<GpuScene> {
    Arc::new(GpuScene::new(ctx, &common::species(), &common::forest(300)).unwrap())
}

fn opts(background: Background) -> RendererOptions {
    RendererOptions {
        viewport: SIZE,
        min_epsilon: 4.0,
        background,
        ..Default::default()
    }
}

fn inside() -> forest_render::Camera {
    common::camera(Vec3::new(2.0, 1.7, 3.0), Vec3::new(-10.0, 2.0, -20.0), 4.0)
}

/// Clear `target` to `colour` and depth 1 in a pass of the host's own.
fn host_clear(ctx: &GpuContext, target: &Target, colour: wgpu::Color) {
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    drop(
        Targets::cleared(&target.colour_view, &target.depth_view, colour, 1.0)
            .begin(&mut enc, "host", None),
    );
    ctx.queue.submit([enc.finish()]);
}

/// A host's multisampled colour and depth targets of `samples` samples, and the readable
/// target the colour resolves to.
fn msaa_targets(ctx: &GpuContext, samples: u32) -> (wgpu::TextureView, wgpu::TextureView, Target) {
    let make = |format, label| {
        ctx.device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width: SIZE.0,
                    height: SIZE.1,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: samples,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            })
            .create_view(&Default::default())
    };
    (
        make(TARGET_FORMAT, "msaa colour"),
        make(wgpu::TextureFormat::Depth32Float, "msaa depth"),
        Target::new(ctx, SIZE.0, SIZE.1),
    )
}

/// `cam` seen through a reverse-Z projection with an infinite far plane (same field of view).
fn reverse_z_frame(cam: &forest_render::Camera) -> FrameParams {
    FrameParams {
        proj: glam::camera::rh::proj::directx::perspective_infinite_reverse(
            cam.fov_y_deg.to_radians(),
            cam.viewport.0 as f32 / cam.viewport.1 as f32,
            cam.near,
        ),
        ..FrameParams::from(cam)
    }
}

#[test]
fn drawing_over_a_host_frame_keeps_its_pixels_where_no_tree_is() {
    let ctx = common::ctx();
    let scene = scene(&ctx);
    let cam = inside();
    // Coverage: the same view on transparent black.
    let mut alone =
        QuadStream::new(&ctx.device, scene.clone(), &opts(Background::Transparent)).unwrap();
    let coverage_target = Target::new(&ctx, SIZE.0, SIZE.1);
    alone.render_frame(&ctx, &cam, &coverage_target).unwrap();
    let coverage = coverage_target.read(&ctx);

    let mut stream = QuadStream::new(&ctx.device, scene, &opts(Background::Sky)).unwrap();
    let target = Target::new(&ctx, SIZE.0, SIZE.1);
    host_clear(&ctx, &target, MAGENTA);
    stream
        .prepare(&ctx.queue, &FrameParams::from(&cam))
        .unwrap();
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    stream.encode_into(
        &mut enc,
        &Targets::over(&target.colour_view, &target.depth_view),
    );
    ctx.queue.submit([enc.finish()]);
    let over = target.read(&ctx);
    assert_eq!(ctx.take_errors(), Vec::<String>::new());

    let (mut empty, mut full, mut diff) = (0, 0, 0.0);
    for (c, o) in coverage.pixels().zip(over.pixels()) {
        match c.0[3] {
            // Nothing drawn at all (colour and alpha 0: sRGB makes a faint texel visible in the
            // colour before the alpha).
            0 if c.0 == [0; 4] => {
                assert_eq!(
                    o.0,
                    [255, 0, 255, 255],
                    "a host pixel no tree covers changed"
                );
                empty += 1;
            }
            255 => {
                // Covered: the tree's colour, whatever the host had. Over black and over
                // magenta the 8-bit target rounds differently after every blended layer (and
                // alpha 255 may still let ~1 % through after many layers), so the colours
                // are compared on average.
                assert_ne!(o.0, [255, 0, 255, 255]);
                diff += (0..3)
                    .map(|k| f64::from(c.0[k].abs_diff(o.0[k])))
                    .sum::<f64>()
                    / 3.0;
                full += 1;
            }
            _ => {}
        }
    }
    assert!(
        empty > 500 && full > 500,
        "{empty} empty, {full} covered pixels"
    );
    let mean = diff / f64::from(full);
    assert!(
        mean < 1.5,
        "covered pixels differ by {mean} sRGB steps on average"
    );
}

#[test]
fn a_frame_before_the_first_prepare_draws_nothing() {
    let ctx = common::ctx();
    let stream = QuadStream::new(&ctx.device, scene(&ctx), &opts(Background::Transparent)).unwrap();
    assert!(!forest_render::Form::inputs(&stream).is_prepared());
    let target = Target::new(&ctx, SIZE.0, SIZE.1);
    host_clear(&ctx, &target, MAGENTA);
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    stream.encode_into(
        &mut enc,
        &Targets::over(&target.colour_view, &target.depth_view),
    );
    ctx.queue.submit([enc.finish()]);
    let img = target.read(&ctx);
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    assert!(img.pixels().all(|p| p.0 == [255, 0, 255, 255]));
    let s = stream.read_stats(&ctx);
    assert_eq!((s.visible_trees, s.quads), (0, 0));
}

#[test]
fn a_resize_keeps_the_scene_and_matches_a_fresh_stream() {
    let ctx = common::ctx();
    let scene = scene(&ctx);
    let small = RendererOptions {
        viewport: (80, 60),
        ..opts(Background::Sky)
    };
    let mut stream = QuadStream::new(&ctx.device, scene.clone(), &small).unwrap();
    let before = stream.capacity;
    stream.resize(&ctx.device, SIZE).unwrap();
    assert!(
        stream.capacity.quads > before.quads,
        "the stream grew for the larger view"
    );
    assert!(
        Arc::ptr_eq(&stream.scene, &scene),
        "the scene was kept, not rebuilt"
    );
    assert_eq!(stream.uploads(), (0, 0), "a resize uploads nothing");
    // The scene's buffers accept no writes at all: nothing can re-upload into them.
    assert_eq!(stream.writable_buffers(), vec!["camera"]);
    let cam = inside();
    let target = Target::new(&ctx, SIZE.0, SIZE.1);
    stream.render_frame(&ctx, &cam, &target).unwrap();
    let resized = target.read(&ctx);
    let mut fresh = QuadStream::new(&ctx.device, scene, &opts(Background::Sky)).unwrap();
    fresh.render_frame(&ctx, &cam, &target).unwrap();
    assert_eq!(fresh.capacity, stream.capacity);
    assert!(
        resized == target.read(&ctx),
        "resized and fresh streams draw the same image"
    );
    assert_eq!(stream.uploads().0, 1, "one camera write per frame");
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
}

#[test]
fn reverse_z_and_msaa_targets_of_the_host() {
    let ctx = common::ctx();
    let scene = scene(&ctx);
    let cam = inside();
    let reference = {
        let mut s = QuadStream::new(&ctx.device, scene.clone(), &opts(Background::Sky)).unwrap();
        let t = Target::new(&ctx, SIZE.0, SIZE.1);
        s.render_frame(&ctx, &cam, &t).unwrap();
        t.read(&ctx)
    };
    // Reverse-Z with an infinite far plane, 4× MSAA resolved into the readable target.
    let samples = 4;
    let host = RendererOptions {
        reverse_z: true,
        sample_count: samples,
        ..opts(Background::Sky)
    };
    let mut s = QuadStream::new(&ctx.device, scene, &host).unwrap();
    let (msaa, depth, resolved) = msaa_targets(&ctx, samples);
    let frame = reverse_z_frame(&cam);
    s.prepare(&ctx.queue, &frame).unwrap();
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    let targets = Targets {
        resolve: Some(&resolved.colour_view),
        ..Targets::cleared(&msaa, &depth, forest_render::options::SKY, 0.0)
    };
    s.encode_compute(&mut enc);
    {
        let mut pass = targets.begin(&mut enc, "host msaa", None);
        forest_render::Form::record_draw(&s, &mut pass, true);
    }
    ctx.queue.submit([enc.finish()]);
    let img = resolved.read(&ctx);
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    let (flip, _) = forest_metrics::flip(&reference, &img).unwrap();
    // The same trees, edges antialiased: close to the 1× standard-depth image.
    eprintln!("FLIP against 1x standard depth: {flip:.4}");
    assert!(flip < 0.05, "FLIP {flip}");
    assert!(img != reference, "4× MSAA changed the edges");
}

#[test]
fn statistics_arrive_without_waiting_and_equal_the_blocking_read() {
    let ctx = common::ctx();
    let mut stream = QuadStream::new(&ctx.device, scene(&ctx), &opts(Background::Sky)).unwrap();
    let target = Target::new(&ctx, SIZE.0, SIZE.1);
    stream.render_frame(&ctx, &inside(), &target).unwrap();
    let mut polled = None;
    for _ in 0..20 {
        polled = stream.poll_stats(&ctx.device, &ctx.queue);
        if polled.is_some() {
            break;
        }
        ctx.device
            .poll(wgpu::PollType::wait_indefinitely())
            .unwrap();
    }
    let polled = polled.expect("statistics arrived");
    let blocking = stream.read_stats(&ctx);
    assert!(blocking.quads > 0);
    assert_eq!(
        (polled.visible_trees, polled.quads, &polled.per_level),
        (blocking.visible_trees, blocking.quads, &blocking.per_level)
    );
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
}

#[test]
fn errors_are_typed_and_renderers_can_be_shared() {
    fn shareable<T: Send + Sync>() {}
    shareable::<QuadStream>();
    shareable::<GpuScene>();
    shareable::<GeometryRenderer>();
    shareable::<ForestRenderer>();

    let ctx = common::ctx();
    let one_species = &common::species()[..1];
    match GpuScene::new(&ctx, one_species, &common::forest(10)) {
        Err(RenderError::SpeciesCount {
            forest: 2,
            given: 1,
            what: "atlases",
        }) => {}
        Err(e) => panic!("wrong error: {e}"),
        Ok(_) => panic!("a forest of two species loaded with one atlas"),
    }
    let bad = RendererOptions {
        sample_count: 3,
        ..opts(Background::Sky)
    };
    assert!(matches!(
        QuadStream::new(&ctx.device, scene(&ctx), &bad),
        Err(RenderError::Parameter(m)) if m.contains("sample count")
    ));
    let mut frame = FrameParams::from(&inside());
    frame.proj = glam::Mat4::ZERO;
    let mut s = QuadStream::new(&ctx.device, scene(&ctx), &opts(Background::Sky)).unwrap();
    assert!(matches!(
        s.prepare(&ctx.queue, &frame),
        Err(RenderError::Camera(_))
    ));
}

#[test]
fn the_geometry_renderer_draws_into_reverse_z_msaa_targets() {
    use forest_baselines::geometry::MeshMethod;
    let ctx = common::ctx();
    let forest = common::forest(300);
    let cam = inside();
    let mut standard = GeometryRenderer::new(
        &ctx,
        common::prepared(),
        &forest,
        TARGET_FORMAT,
        Background::Sky,
    )
    .unwrap();
    let t = Target::new(&ctx, SIZE.0, SIZE.1);
    standard.render_frame(&ctx, &cam, &t).unwrap();
    let reference = t.read(&ctx);
    let samples = 4;
    let host = RendererOptions {
        reverse_z: true,
        sample_count: samples,
        ..opts(Background::Sky)
    };
    let mut geo = GeometryRenderer::with_targets(&ctx, common::prepared(), &forest, &host).unwrap();
    geo.set_method(&ctx, MeshMethod::Full { depth_sort: true })
        .unwrap();
    let (msaa, depth, resolved) = msaa_targets(&ctx, samples);
    let frame = reverse_z_frame(&cam);
    geo.prepare(&ctx.queue, &frame).unwrap();
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    geo.encode_compute(&mut enc);
    {
        let targets = Targets {
            resolve: Some(&resolved.colour_view),
            ..Targets::cleared(&msaa, &depth, forest_render::options::SKY, 0.0)
        };
        let mut pass = targets.begin(&mut enc, "host msaa", None);
        forest_render::Form::record_draw(&geo, &mut pass, true);
    }
    ctx.queue.submit([enc.finish()]);
    let img = resolved.read(&ctx);
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    let (flip, _) = forest_metrics::flip(&reference, &img).unwrap();
    eprintln!("FLIP against 1x standard depth: {flip:.4}");
    assert!(flip < 0.05, "FLIP {flip}");
    assert!(img != reference, "4x MSAA changed the edges");
}

/// With `write_depth`, the quads leave the host their depth where they are opaque and nothing
/// where no tree is, and the colour is the same as without it; without it, the opaque pass
/// writes depth only where the image is opaque, and behind the quads' own depth there, and
/// without both no depth is written at all (reverse-Z, cleared to 0).
#[test]
fn write_depth_leaves_the_trees_opaque_depth_to_the_host() {
    let ctx = common::ctx();
    let scene = scene(&ctx);
    let cam = inside();
    let frame = reverse_z_frame(&cam);
    let draw = |write_depth: bool, opaque_first: bool| {
        let opts = RendererOptions {
            reverse_z: true,
            write_depth,
            ..opts(Background::Transparent)
        };
        let mut stream = QuadStream::new(&ctx.device, scene.clone(), &opts).unwrap();
        stream
            .set_options(forest_render::options::StreamOptions {
                opaque_first,
                ..Default::default()
            })
            .unwrap();
        let target = Target::new(&ctx, SIZE.0, SIZE.1);
        stream.prepare(&ctx.queue, &frame).unwrap();
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        stream.encode_into(
            &mut enc,
            &Targets::cleared(
                &target.colour_view,
                &target.depth_view,
                wgpu::Color::TRANSPARENT,
                0.0,
            ),
        );
        ctx.queue.submit([enc.finish()]);
        (target.read(&ctx), target.read_depth(&ctx))
    };
    let (blended, no_depth) = draw(false, false);
    let (plain, opaque_front) = draw(false, true);
    let (with, depth) = draw(true, true);
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    assert!(plain == with, "writing depth changed the colour");
    assert!(
        no_depth.iter().all(|&d| d == 0.0),
        "depth written without write_depth and the opaque pass"
    );
    // The opaque pass writes where the image is opaque, and nowhere else.
    let mut fronts = 0;
    for ((p, &d), &b) in plain.pixels().zip(&opaque_front).zip(&depth) {
        if d != 0.0 {
            assert_eq!(
                p.0[3], 255,
                "the opaque pass wrote depth at a pixel of alpha {}",
                p.0[3]
            );
            // With write_depth the same pass runs, and the quads' depth is written over it
            // where they are nearer (larger in reverse-Z): everywhere it wrote, since it writes
            // a slab's thickness behind them.
            assert!(d < b, "opaque pass depth {d} not behind write_depth's {b}");
            fronts += 1;
        }
    }
    // Few in this small forest (59 pixels when written): its nodes are seldom half opaque.
    assert!(fronts > 0, "the opaque pass wrote no depth");
    let m = forest_metrics::compare(&blended, &plain).unwrap();
    assert!(
        m.flip_mean < 0.001,
        "opaque pass against blended: FLIP {}",
        m.flip_mean
    );
    let (mut empty, mut opaque, mut opaque_written) = (0, 0, 0);
    for (p, &d) in with.pixels().zip(&depth) {
        if p.0 == [0; 4] {
            assert_eq!(d, 0.0, "depth written where no tree is");
            empty += 1;
        } else if p.0[3] == 255 {
            opaque += 1;
            opaque_written += usize::from(d > 0.0 && d <= 1.0);
        }
    }
    assert!(
        empty > 500 && opaque > 500,
        "{empty} empty, {opaque} opaque pixels"
    );
    let share = opaque_written as f32 / opaque as f32;
    assert!(
        share > 0.9,
        "only {share} of the opaque pixels have the trees' depth"
    );
}
