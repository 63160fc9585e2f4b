//! The full-geometry reference renders the forest, and the quad stream resembles it.

mod common;

use forest_baselines::geometry::{GeometryRenderer, downsample};
use forest_render::options::{Background, RendererOptions};
use forest_render::target::{TARGET_FORMAT, Target};
use forest_render::{GpuScene, QuadStream};

#[test]
fn quad_stream_resembles_the_supersampled_full_geometry() {
    let ctx = common::ctx();
    let forest = common::forest(300);
    let mut geo = GeometryRenderer::new(
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
    let mut stream = QuadStream::new(&ctx.device, scene, &opts).unwrap();
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

/// Sky visibility of the reference: per-vertex values traced by the bake's ray tracer, drawn
/// lit on the GPU, measured against the bake's own per-pixel images of the whole tree (one
/// slab, 16 samples per pixel, albedo and surface attributes lit on the CPU by the shading
/// model) from three elevations, next to no occlusion at all.
#[test]
#[ignore = "open defect: the GPU's per-vertex sky visibility darkens the pine more than the \
            bake's texels do (mean FLIP 0.057 against 0.035 with no occlusion; choosing the \
            side by the triangle's plane, as the bake does, changed nothing); the two must \
            agree, as both read the same traced values"]
fn per_vertex_sky_visibility_matches_the_bakes_texels_better_than_none() {
    use forest_bake::lod::{BILLBOARD_ELEVATIONS, billboard_images};
    use forest_format::shading::{Lighting, hemi_oct_decode, srgb_encode};
    let ctx = common::ctx();
    let forest = common::one_tree(1, 0.0);
    let mesh = forest_bake::Mesh::load(&common::root().join("assets/trees/pine/pine.obj")).unwrap();
    let lighting = Lighting::default();
    let res = 128;
    // Lit on the CPU and premultiplied (colour averaged with black where uncovered), as
    // `downsample` averages.
    let table = forest_format::shading::srgb_decode_table();
    let baked: Vec<image::RgbaImage> = billboard_images(&mesh, res, 16)
        .into_iter()
        .zip(BILLBOARD_ELEVATIONS)
        .map(|(b, e)| {
            let e = e.to_radians();
            let f =
                forest_format::slab::DirectionFrame::new(glam::Vec3::new(0.0, e.sin(), e.cos()));
            let mut img = b.albedo.clone();
            for (p, g) in img.pixels_mut().zip(b.surface.pixels()) {
                let a = f32::from(p[3]) / 255.0;
                let l = hemi_oct_decode(glam::Vec2::new(f32::from(g[0]), f32::from(g[1])) / 255.0);
                let n = (f.right * l.x + f.up * l.y + f.dir * l.z).normalize();
                let albedo = glam::Vec3::new(
                    table[p[0] as usize],
                    table[p[1] as usize],
                    table[p[2] as usize],
                );
                let c = lighting.shade(
                    albedo,
                    n,
                    1.0,
                    f32::from(g[2]) / 255.0,
                    f32::from(g[3]) / 255.0,
                );
                for k in 0..3 {
                    p[k] = (srgb_encode(c[k] * a) * 255.0).round() as u8;
                }
            }
            img
        })
        .collect();
    let sphere = forest_bake::bounding_sphere(&mesh);
    // The bake's images carry no sun visibility: neither do these (no self-shadowing).
    let traced = common::prepared().without_self_shadowing();
    let unshadowed = traced.map_sky_visibility(|_| 1.0);
    let mut flips = [0f32; 2];
    for (k, prepared) in [&traced, &unshadowed].into_iter().enumerate() {
        let mut geo = GeometryRenderer::new(
            &ctx,
            prepared,
            &forest,
            TARGET_FORMAT,
            Background::Transparent,
        )
        .unwrap();
        let big = Target::new(&ctx, res * 4, res * 4);
        for (e, image) in BILLBOARD_ELEVATIONS.iter().zip(&baked).take(3) {
            let e = e.to_radians();
            let dir = glam::Vec3::new(0.0, e.sin(), e.cos());
            let cam = common::along(sphere.center, sphere.radius, dir, res * 4, 1.0);
            geo.render_frame(&ctx, &cam, &big).unwrap();
            let img = downsample(&big.read(&ctx), 4);
            let m = forest_metrics::compare(image, &img).unwrap();
            let lum = |i: &image::RgbaImage| {
                let (s, n) = i
                    .pixels()
                    .filter(|p| p[3] > 200)
                    .fold((0u64, 0u64), |(s, n), p| (s + u64::from(p[1]), n + 1));
                s as f64 / n.max(1) as f64
            };
            eprintln!(
                "mean green: baked {:.1}, rendered {:.1}",
                lum(image),
                lum(&img)
            );
            eprintln!(
                "{} at {:.0}°: {m:?}",
                ["per-vertex sky visibility", "no occlusion"][k],
                e.to_degrees()
            );
            assert!(m.coverage_iou.unwrap() > 0.8, "silhouettes agree: {m:?}");
            flips[k] += m.flip_mean / 3.0;
            if k == 0 {
                let out = common::root().join("target/test-output");
                std::fs::create_dir_all(&out).unwrap();
                image
                    .save(out.join(format!("lighting-baked-{:.0}.png", e.to_degrees())))
                    .unwrap();
                img.save(out.join(format!("lighting-vertex-{:.0}.png", e.to_degrees())))
                    .unwrap();
            }
        }
    }
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    eprintln!(
        "mean FLIP vs the bake's texels: per-vertex {:.4}, none {:.4}",
        flips[0], flips[1]
    );
    assert!(
        flips[0] < flips[1],
        "per-vertex sky visibility ({:.4}) is closer to the bake's texels than none ({:.4})",
        flips[0],
        flips[1]
    );
}
