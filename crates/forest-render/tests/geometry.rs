//! The full-geometry reference renders the forest, and the quad stream resembles it.

mod common;

use forest_render::geometry::{GeometryRenderer, downsample};
use forest_render::renderer::{Background, RendererOptions};
use forest_render::target::{TARGET_FORMAT, Target};
use forest_render::{GpuScene, QuadStream};

#[test]
fn quad_stream_resembles_the_supersampled_full_geometry() {
    let ctx = common::ctx();
    let forest = common::forest(300);
    let geo = GeometryRenderer::new(
        &ctx,
        common::prepared(),
        &forest,
        TARGET_FORMAT,
        Background::Transparent,
    )
    .unwrap();
    assert_eq!(geo.figures.len(), 2);
    let scene = GpuScene::new(&ctx, &common::species(), &forest).unwrap();
    let opts = RendererOptions {
        viewport: (160, 120),
        min_epsilon: 1.0,
        background: Background::Transparent,
        ..Default::default()
    };
    let stream = QuadStream::new(&ctx, scene, &opts).unwrap();
    let (name, mut cam) = common::cameras(forest.extent()).remove(2);
    cam.epsilon = 1.0;
    let small = Target::new(&ctx, 160, 120);
    stream.render_frame(&ctx, &cam, &small).unwrap();
    let quads = small.read(&ctx);
    // Reference: 4×4 supersampled.
    let big = Target::new(&ctx, 640, 480);
    let mut big_cam = cam;
    big_cam.viewport = (640, 480);
    geo.render_frame(&ctx, &big_cam, &big).unwrap();
    let reference = downsample(&big.read(&ctx), 4);
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    let m = forest_metrics::compare(&reference, &quads).unwrap();
    eprintln!("{name}: quad stream vs full geometry: {m:?}");
    let covered = reference.pixels().filter(|p| p[3] > 0).count();
    assert!(
        covered > 160 * 120 / 20,
        "the reference shows trees ({covered} px)"
    );
    let iou = m.coverage_iou.unwrap();
    // A 64-pixel, 5-direction atlas is coarse; the silhouettes still mostly agree.
    assert!(iou > 0.5, "coverage IoU {iou:.3}");
    assert!(m.flip_mean < 0.5, "mean FLIP {:.3}", m.flip_mean);
    let out = common::root().join("target/test-output");
    std::fs::create_dir_all(&out).unwrap();
    reference
        .save(out.join(format!("{name}-geometry.png")))
        .unwrap();
    quads.save(out.join(format!("{name}-quads.png"))).unwrap();
}
