//! The full-geometry reference renders the forest, and the quad stream resembles it.

mod common;

use forest_baselines::geometry::{GeometryRenderer, downsample};
use forest_render::ForestView;
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
    assert_eq!(geo.figures().len(), 2);
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
    geo.set_method(&ctx, forest_baselines::geometry::MeshMethod::Reference)
        .unwrap();
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

/// Sky visibility of the reference: its per-vertex values, traced by the bake's ray tracer and
/// drawn lit on the GPU (4×4 supersampled), against the same tracer's own picture of the pine
/// (one ray per supersample, each hit lit on the CPU with `Lighting::shade` and its traced sky
/// visibility) from three elevations, next to the GPU without occlusion. The two paths read the
/// same traced values, so the GPU's brightness where both cover a pixel must be far closer to
/// the tracer's with them than without, and its coverage must be the tracer's (an alpha test
/// that thins leaves shows as lost coverage). FLIP is reported, but the silhouettes' aliasing
/// dominates it.
#[test]
fn per_vertex_sky_visibility_matches_the_ray_traced_pine() {
    use forest_bake::lod::BILLBOARD_ELEVATIONS;
    use forest_format::shading::{Lighting, srgb_decode_table, srgb_encode};
    let ctx = common::ctx();
    let forest = common::one_tree(1, 0.0);
    let mesh = forest_bake::Mesh::load(&common::root().join("assets/trees/pine/pine.obj")).unwrap();
    let lighting = Lighting::default();
    let (res, ss) = (128, 4);
    let sphere = forest_bake::bounding_sphere(&mesh);
    let scene = forest_bake::trace::Scene::new(&mesh);
    let sky = forest_bake::sky::triangle_sky(&scene);
    let table = srgb_decode_table();
    let frames: Vec<_> = BILLBOARD_ELEVATIONS[..3]
        .iter()
        .map(|e| {
            let e = e.to_radians();
            forest_format::slab::DirectionFrame::new(glam::Vec3::new(0.0, e.sin(), e.cos()))
        })
        .collect();
    // The tracer's picture: one ray through each supersample's centre, lit per hit.
    let traced: Vec<image::RgbaImage> = frames
        .iter()
        .map(|f| {
            let side = res * ss;
            let big = image::RgbaImage::from_fn(side, side, |x, y| {
                let (u, v) = (
                    (x as f32 + 0.5) / side as f32,
                    (y as f32 + 0.5) / side as f32,
                );
                let o = sphere.image_to_object(f, u, v, 0.0);
                match scene.closest(o, -f.dir, 0.0, 2.0 * sphere.radius) {
                    Some(hit) => {
                        let su = forest_bake::ldi::surface_at(&scene, &sky, &table, &hit, -f.dir);
                        let c = lighting.shade(
                            su.albedo,
                            su.normal,
                            1.0,
                            su.sky_visibility,
                            su.translucency,
                        );
                        let e = |v: f32| (srgb_encode(v.min(1.0)) * 255.0).round() as u8;
                        image::Rgba([e(c.x), e(c.y), e(c.z), 255])
                    }
                    None => image::Rgba([0; 4]),
                }
            });
            downsample(&big, ss)
        })
        .collect();
    // The tracer's samples carry no sun visibility: neither do these (no self-shadowing).
    let per_vertex = common::prepared().without_self_shadowing();
    let unoccluded = per_vertex.map_sky_visibility(|_| 1.0);
    // Mean linear luminance over the pixels both images cover fully.
    let luminance = |a: &image::RgbaImage, b: &image::RgbaImage| {
        let lum = |p: &image::Rgba<u8>| {
            0.2126 * table[p[0] as usize]
                + 0.7152 * table[p[1] as usize]
                + 0.0722 * table[p[2] as usize]
        };
        let (mut sa, mut sb) = (0f64, 0f64);
        for (p, q) in a.pixels().zip(b.pixels()) {
            if p[3] == 255 && q[3] == 255 {
                sa += f64::from(lum(p));
                sb += f64::from(lum(q));
            }
        }
        sb / sa
    };
    let mut flips = [0f32; 2];
    let mut ratios = [0f64; 2];
    for (k, prepared) in [&per_vertex, &unoccluded].into_iter().enumerate() {
        let mut geo = GeometryRenderer::new(
            &ctx,
            prepared,
            &forest,
            TARGET_FORMAT,
            Background::Transparent,
        )
        .unwrap();
        geo.set_method(&ctx, forest_baselines::geometry::MeshMethod::Reference)
            .unwrap();
        geo.set_light(lighting).unwrap();
        let big = Target::new(&ctx, res * ss, res * ss);
        for (f, want) in frames.iter().zip(&traced) {
            let cam = common::along(sphere.center, sphere.radius, f.dir, res * ss, 1.0);
            geo.render_frame(&ctx, &cam, &big).unwrap();
            let img = downsample(&big.read(&ctx), ss);
            let m = forest_metrics::compare(want, &img).unwrap();
            let name = ["per-vertex sky visibility", "no occlusion"][k];
            eprintln!(
                "{name} from elevation {:.0}°: {m:?}",
                f.dir.y.asin().to_degrees()
            );
            assert!(m.coverage_iou.unwrap() > 0.9, "silhouettes agree: {m:?}");
            flips[k] += m.flip_mean / frames.len() as f32;
            let ratio = luminance(want, &img);
            eprintln!("  luminance over the traced pine's: {ratio:.3}");
            ratios[k] += ratio / frames.len() as f64;
            if k == 0 {
                let out = common::root().join("target/test-output");
                std::fs::create_dir_all(&out).unwrap();
                let e = f.dir.y.asin().to_degrees();
                want.save(out.join(format!("sky-traced-{e:.0}.png")))
                    .unwrap();
                img.save(out.join(format!("sky-vertex-{e:.0}.png")))
                    .unwrap();
            }
        }
    }
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    eprintln!(
        "against the traced pine: mean FLIP per-vertex {:.4}, none {:.4}; luminance ratio \
         per-vertex {:.3}, none {:.3}",
        flips[0], flips[1], ratios[0], ratios[1]
    );
    assert!(
        (ratios[0] - 1.0).abs() < 0.25 * (ratios[1] - 1.0).abs(),
        "per-vertex sky visibility's brightness ({:.3} of the traced) is far closer to the \
         traced pine's than none's ({:.3})",
        ratios[0],
        ratios[1]
    );
}

/// A device too small for the models is refused before anything is allocated, by a message
/// naming the buffer and both sizes: checked on limits just below each buffer's size, and on
/// a real device opened with a storage-binding limit below the vertices' bytes, which reports
/// no validation error.
#[test]
fn models_beyond_the_device_limits_are_refused_by_name() {
    use forest_baselines::geometry::check_limits;
    use forest_render::context::RenderError;
    let prepared = common::prepared();
    let trees = 300;
    let vertex_bytes = prepared.vertex_bytes();
    let device_limits = common::ctx().device.limits();
    assert!(check_limits(&device_limits, prepared, trees).is_ok());
    let refused = |limits: &wgpu::Limits, trees: usize| match check_limits(limits, prepared, trees)
    {
        Err(e @ RenderError::DeviceLimit { .. }) => e.to_string(),
        other => panic!("not refused for the device's limit: {other:?}"),
    };
    let mut small = device_limits.clone();
    small.max_storage_buffer_binding_size = vertex_bytes - 1;
    let e = refused(&small, trees);
    assert!(
        e.contains("vertices") && e.contains(&vertex_bytes.to_string()) && e.contains("lighter"),
        "{e}"
    );
    // The largest buffer counts as well as the binding limit.
    let mut small = device_limits.clone();
    small.max_buffer_size = vertex_bytes - 1;
    assert!(refused(&small, trees).contains("vertices"));
    // Enough for the models, too little for 2^24 trees' instances.
    let mut small = device_limits.clone();
    small.max_storage_buffer_binding_size = vertex_bytes;
    let e = refused(&small, 1 << 24);
    assert!(e.contains("instances") && e.contains("fewer trees"), "{e}");
    // Texture arrays of too many layers, and opacity volumes stacked too deep.
    assert!(
        prepared.material_layers() > 0,
        "the test models have textures"
    );
    let mut small = device_limits.clone();
    small.max_texture_array_layers = prepared.material_layers() as u32 - 1;
    assert!(refused(&small, trees).contains("material texture layers"));
    let mut small = device_limits.clone();
    small.max_texture_dimension_3d = forest_format::opacity::VOLUME_RESOLUTION * 2 - 1;
    assert!(refused(&small, trees).contains("opacity volumes"));

    // A real device with that binding limit: refused by the renderer, with no wgpu error.
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle());
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        ..Default::default()
    }))
    .unwrap();
    let mut limits = adapter.limits();
    limits.max_storage_buffer_binding_size = vertex_bytes - 1;
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        required_features: adapter.features() & wgpu::Features::INDIRECT_FIRST_INSTANCE,
        required_limits: limits,
        ..Default::default()
    }))
    .unwrap();
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let ctx = forest_render::GpuContext::from_device(adapter.get_info(), device, queue);
    let made = GeometryRenderer::new(
        &ctx,
        prepared,
        &common::forest(trees as u32),
        TARGET_FORMAT,
        Background::Transparent,
    );
    match made {
        Err(e @ RenderError::DeviceLimit { .. }) => assert!(e.to_string().contains("vertices")),
        Err(e) => panic!("refused for another cause: {e}"),
        Ok(_) => panic!(
            "a device binding {} bytes took the models",
            vertex_bytes - 1
        ),
    }
    let error = pollster::block_on(scope.pop());
    assert!(error.is_none(), "wgpu error: {error:?}");
}
