//! Image tests against stored references (NVIDIA FLIP), and the per-frame upload contract.

mod common;

use forest_render::ForestView;
use std::path::PathBuf;

use forest_render::options::RendererOptions;
use forest_render::target::Target;
use forest_render::{GpuScene, QuadStream};

fn refs() -> PathBuf {
    common::root().join("tests/images")
}

fn out_dir() -> PathBuf {
    let d = common::root().join("target/test-output");
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn flip(reference: &image::RgbaImage, test: &image::RgbaImage) -> (f32, image::RgbImage) {
    forest_metrics::flip(reference, test).unwrap()
}

#[test]
fn renders_match_the_stored_references() {
    let ctx = common::ctx();
    let forest = common::forest(300);
    let scene = GpuScene::new(&ctx, &common::species(), &forest).unwrap();
    let (mut stream, target) = common::small_stream(&ctx, scene, None);
    let mut failures = Vec::new();
    for (name, cam) in common::cameras(forest.extent()) {
        if name == "culled" || name == "under_canopy" {
            continue;
        }
        stream.render_frame(&ctx, &cam, &target).unwrap();
        let img = target.read(&ctx);
        assert_eq!(ctx.take_errors(), Vec::<String>::new());
        let path = refs().join(format!("{name}.png"));
        let Ok(reference) = image::open(&path) else {
            img.save(&path).unwrap();
            failures.push(format!(
                "{name}: no reference; wrote {} (inspect and commit it)",
                path.display()
            ));
            continue;
        };
        let (mean, map) = flip(&reference.to_rgba8(), &img);
        // Different drivers rasterise a little differently; a broken pass changes far more.
        if mean > 0.05 {
            img.save(out_dir().join(format!("{name}-actual.png")))
                .unwrap();
            map.save(out_dir().join(format!("{name}-flip.png")))
                .unwrap();
            failures.push(format!(
                "{name}: mean FLIP {mean:.4} > 0.05 (see target/test-output/)"
            ));
        }
        // The image is not just sky and ground: trees cover a good part of it.
        let sky_or_ground = img
            .pixels()
            .filter(|p| p[2] > p[1] + 40 || (p[0] as i32 - 0x6f).abs() < 8)
            .count();
        assert!(
            sky_or_ground < img.pixels().count() * 95 / 100,
            "{name}: no trees drawn"
        );
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn a_frame_writes_only_the_camera() {
    let ctx = common::ctx();
    let forest = common::forest(100);
    let scene = GpuScene::new(&ctx, &common::species(), &forest).unwrap();
    let mut stream = QuadStream::new(
        &ctx.device,
        scene,
        &RendererOptions {
            viewport: (64, 48),
            ..Default::default()
        },
    )
    .unwrap();
    // Nothing but the camera can be written after load: no other buffer accepts copies.
    assert_eq!(stream.writable_buffers(), vec!["camera"]);
    let target = Target::new(&ctx, 64, 48);
    let cams = common::cameras(forest.extent());
    let mut streams = Vec::new();
    for (_, cam) in cams.iter().take(3) {
        stream.render_frame(&ctx, cam, &target).unwrap();
        streams.push(stream.read_quads(&ctx));
    }
    assert_eq!(
        stream.uploads(),
        (
            3,
            3 * std::mem::size_of::<forest_render::gpu_types::GpuCamera>() as u64
        ),
        "one camera write (the camera uniform, its light included) per frame"
    );
    assert_ne!(
        streams[0], streams[1],
        "the GPU rebuilt the stream from the camera alone"
    );
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
}

#[test]
fn an_empty_forest_and_bad_cameras_are_handled() {
    let ctx = common::ctx();
    let mut forest = common::forest(10);
    forest.instances.clear();
    forest.presort = forest_format::forest::Presort::new(&[], 15);
    let scene = GpuScene::new(&ctx, &common::species(), &forest).unwrap();
    let mut stream = QuadStream::new(
        &ctx.device,
        scene,
        &RendererOptions {
            viewport: (32, 32),
            ..Default::default()
        },
    )
    .unwrap();
    let target = Target::new(&ctx, 32, 32);
    let (_, mut cam) = common::cameras(10.0).remove(0);
    cam.viewport = (32, 32);
    stream.render_frame(&ctx, &cam, &target).unwrap();
    assert_eq!(stream.read_stats(&ctx).quads, 0);
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    let mut bad = cam;
    bad.target = bad.eye;
    assert!(stream.set_camera(&ctx, &bad).is_err());
    assert_eq!(stream.uploads().0, 1, "a refused camera is not written");
}

#[test]
fn bc7_colour_renders_like_rgba8() {
    let ctx = common::ctx();
    if !ctx.has_bc() {
        eprintln!("skipped: the adapter has no BC textures");
        return;
    }
    let forest = common::forest(300);
    let (name, cam) = common::cameras(forest.extent()).remove(2);
    let mut images = Vec::new();
    for format in [
        forest_render::ColourFormat::Rgba8,
        forest_render::ColourFormat::Bc7,
    ] {
        let scene = GpuScene::with_format(&ctx, &common::species(), &forest, format).unwrap();
        assert_eq!(scene.bc7, format == forest_render::ColourFormat::Bc7);
        let (mut stream, target) = common::small_stream(&ctx, scene, None);
        stream.render_frame(&ctx, &cam, &target).unwrap();
        images.push(target.read(&ctx));
        assert_eq!(ctx.take_errors(), Vec::<String>::new());
    }
    let (mean, map) = flip(&images[0], &images[1]);
    if mean > 0.05 {
        images[1]
            .save(out_dir().join(format!("{name}-bc7.png")))
            .unwrap();
        map.save(out_dir().join(format!("{name}-bc7-flip.png")))
            .unwrap();
    }
    assert!(mean <= 0.05, "BC7 vs RGBA8: mean FLIP {mean:.4}");
    assert!(mean > 0.0, "BC7 is lossy: the images cannot be identical");
}

#[test]
fn a_bgra_target_reads_back_like_an_rgba_one() {
    // Window surfaces are often BGRA: the viewer's screenshots render into a target of the
    // surface's format with the surface's pipelines and read it back as RGBA.
    let ctx = common::ctx();
    let forest = common::forest(50);
    let (name, cam) = common::cameras(forest.extent()).remove(0);
    let mut images = Vec::new();
    for format in [
        wgpu::TextureFormat::Rgba8UnormSrgb,
        wgpu::TextureFormat::Bgra8UnormSrgb,
    ] {
        let scene = GpuScene::new(&ctx, &common::species(), &forest).unwrap();
        let opts = RendererOptions {
            viewport: (160, 120),
            format,
            ..Default::default()
        };
        let mut stream = QuadStream::new(&ctx.device, scene, &opts).unwrap();
        let target = Target::with_format(&ctx, 160, 120, format).unwrap();
        stream.render_frame(&ctx, &cam, &target).unwrap();
        images.push(target.read(&ctx));
        assert_eq!(ctx.take_errors(), Vec::<String>::new());
    }
    assert!(
        images[0] == images[1],
        "{name}: BGRA read-back differs from RGBA"
    );
    assert!(
        Target::with_format(&ctx, 4, 4, wgpu::TextureFormat::Rgba16Float).is_err(),
        "an unreadable format is refused"
    );
}
