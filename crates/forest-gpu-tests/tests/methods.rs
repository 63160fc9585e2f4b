//! The rival methods in the geometry renderer: at maximum detail they draw exactly the full
//! geometry's image; the GPU's per-band classification equals the CPU's; every method renders
//! an empty scene, a single tree and a 1M-tree forest without validation errors.

mod common;

use forest_bake::lod::BANDS;
use forest_baselines::geometry::{GeometryRenderer, Lods, MeshMethod, Stochastic};
use forest_format::forest::Forest;
use forest_render::ForestView;
use forest_render::options::{Background, RendererOptions};
use forest_render::target::{TARGET_FORMAT, Target};
use forest_render::{Camera, GpuContext, GpuScene, QuadStream};
use glam::Vec3;

fn geometry(ctx: &GpuContext, forest: &Forest) -> GeometryRenderer {
    GeometryRenderer::new(
        ctx,
        common::prepared(),
        forest,
        TARGET_FORMAT,
        Background::Transparent,
    )
    .unwrap()
}

fn draw(
    ctx: &GpuContext,
    geo: &mut GeometryRenderer,
    method: MeshMethod,
    cam: &Camera,
) -> image::RgbaImage {
    geo.set_method(ctx, method).unwrap();
    let target = Target::new(ctx, cam.viewport.0, cam.viewport.1);
    geo.render_frame(ctx, cam, &target).unwrap();
    target.read(ctx)
}

fn covered(img: &image::RgbaImage) -> usize {
    img.pixels().filter(|p| p[3] > 0).count()
}

fn save_on_failure(name: &str, images: &[(&str, &image::RgbaImage)]) {
    let out = common::root().join("target/test-output");
    std::fs::create_dir_all(&out).unwrap();
    for (n, img) in images {
        img.save(out.join(format!("{name}-{n}.png"))).unwrap();
    }
}

/// Two renderers built over one upload of the models (as each camera's view in a host is)
/// draw exactly what a renderer with its own upload draws, and each counts the shared models
/// in its memory once; models for another number of species are refused.
#[test]
fn renderers_share_one_upload_of_the_models() {
    use forest_baselines::geometry::GpuModels;
    use std::sync::Arc;
    let ctx = common::ctx();
    let forest = common::forest(300);
    let (_, cam) = common::cameras(forest.extent()).remove(0);
    let lods = MeshMethod::Lods(Default::default());
    let mut own = geometry(&ctx, &forest);
    let alone = draw(&ctx, &mut own, lods, &cam);
    let models = Arc::new(GpuModels::new(&ctx, common::prepared(), &forest).unwrap());
    let opts = RendererOptions {
        format: TARGET_FORMAT,
        background: Background::Transparent,
        ..Default::default()
    };
    let mut a = GeometryRenderer::with_models(&ctx, models.clone(), &opts).unwrap();
    let mut b = GeometryRenderer::with_models(&ctx, models.clone(), &opts).unwrap();
    assert_eq!(Arc::strong_count(&models), 3);
    let (img_a, img_b) = (
        draw(&ctx, &mut a, lods, &cam),
        draw(&ctx, &mut b, lods, &cam),
    );
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    assert!(covered(&alone) > 160 * 120 / 10, "trees in view");
    for (name, img) in [("first", &img_a), ("second", &img_b)] {
        if img != &alone {
            save_on_failure("shared-models", &[("own", &alone), (name, img)]);
            panic!("the {name} renderer over shared models differs from one with its own");
        }
    }
    assert_eq!(a.gpu_bytes, own.gpu_bytes);
    assert!(models.bytes() > 0 && models.bytes() < a.gpu_bytes);
    let mut extra_species = common::forest(10);
    extra_species.species.push("another".into());
    let Err(e) = GpuModels::new(&ctx, common::prepared(), &extra_species) else {
        panic!("models of another species count accepted");
    };
    assert!(e.to_string().contains("models"), "{e}");
}

#[test]
fn maximum_detail_draws_exactly_the_full_geometry() {
    let ctx = common::ctx();
    let forest = common::forest(300);
    let mut geo = geometry(&ctx, &forest);
    let (_, cam) = common::cameras(forest.extent()).remove(0);
    let full = draw(&ctx, &mut geo, MeshMethod::Full { depth_sort: false }, &cam);
    assert!(covered(&full) > 160 * 120 / 10, "trees in view");
    let sorted = draw(&ctx, &mut geo, MeshMethod::Full { depth_sort: true }, &cam);
    let stochastic = MeshMethod::Stochastic(Stochastic {
        d0: 1e6,
        ..Default::default()
    });
    let lambda_one = draw(&ctx, &mut geo, stochastic, &cam);
    let lod0 = MeshMethod::Lods(Lods {
        distances: [1e5, 2e5, 3e5],
    });
    let lod_zero = draw(&ctx, &mut geo, lod0, &cam);
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    // Stochastic simplification keeps the model's triangle order; LOD 0 draws each tree's
    // triangles in their presorted order, as depth-sorted full geometry does.
    for (name, img, against) in [
        ("stochastic λ=1", &lambda_one, &full),
        ("LOD 0", &lod_zero, &sorted),
    ] {
        if img != against {
            save_on_failure("max-detail", &[("full", against), (name, img)]);
            panic!("{name} differs from the full geometry");
        }
    }
    // Another triangle order changes only where two surfaces meet at the same depth, which
    // the first drawn wins.
    let differing = full
        .pixels()
        .zip(sorted.pixels())
        .filter(|(a, b)| a != b)
        .count();
    if differing * 1000 > covered(&full) {
        save_on_failure("max-detail", &[("full", &full), ("depth-sorted", &sorted)]);
        panic!("depth-sorted full geometry differs in {differing} pixels");
    }

    // Controls: real simplification changes the image and draws fewer triangles, yet stays
    // close to it.
    geo.set_method(&ctx, MeshMethod::Full { depth_sort: false })
        .unwrap();
    let target = Target::new(&ctx, 160, 120);
    geo.render_frame(&ctx, &cam, &target).unwrap();
    let full_tris = geo.read_stats(&ctx).triangles;
    for (name, method) in [
        (
            "stochastic",
            MeshMethod::Stochastic(Stochastic {
                d0: 3.0,
                ..Default::default()
            }),
        ),
        (
            "lods",
            MeshMethod::Lods(Lods {
                distances: [4.0, 8.0, 16.0],
            }),
        ),
    ] {
        let img = draw(&ctx, &mut geo, method, &cam);
        let stats = geo.read_stats(&ctx);
        let m = forest_metrics::compare(&full, &img).unwrap();
        eprintln!(
            "{name}: {} of {full_tris} triangles, {} billboards, {m:?}",
            stats.triangles, stats.billboards
        );
        assert_ne!(img, full, "{name} simplifies");
        // Branches stay whole under stochastic simplification (half the pine's triangles).
        assert!(
            stats.triangles < full_tris * 3 / 4,
            "{name} draws fewer triangles"
        );
        if name == "lods" {
            assert!(stats.billboards > 0, "far trees are billboards");
        }
        if m.flip_mean > 0.25 || m.coverage_iou.unwrap() < 0.5 {
            save_on_failure(name, &[("full", &full), (name, &img)]);
            panic!("{name} strays from the full geometry: {m:?}");
        }
    }
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
}

/// The CPU's segment (band · species + s) of every instance, or None when culled; and whether
/// the instance lies within rounding of a frustum plane or a band boundary.
fn cpu_segments(
    forest: &Forest,
    cam: &Camera,
    method: &MeshMethod,
    spheres: &[(Vec3, f32)],
) -> (Vec<u32>, usize) {
    let planes = cam.to_gpu().planes;
    let s = forest.species.len() as u32;
    let mut counts = vec![0u32; (BANDS * s) as usize];
    let mut ambiguous = 0;
    for inst in &forest.instances {
        let (c0, r0) = spheres[inst.species as usize];
        let (sin, cos) = inst.rotation.sin_cos();
        let p = c0 * inst.scale;
        let c = Vec3::new(cos * p.x + sin * p.z, p.y, -sin * p.x + cos * p.z)
            + Vec3::from_array(inst.position);
        let r = r0 * inst.scale;
        let margins: Vec<f32> = planes
            .iter()
            .map(|pl| pl[0] * c.x + pl[1] * c.y + pl[2] * c.z + pl[3] + r)
            .collect();
        if margins.iter().any(|m| m.abs() < 1e-3 * r.max(1.0)) {
            ambiguous += 1;
        }
        if margins.iter().any(|m| *m < 0.0) {
            continue;
        }
        let d = c.distance(cam.eye) / inst.scale;
        let band = method.band(d);
        if method.band(d * 1.0001) != band || method.band(d * 0.9999) != band {
            ambiguous += 1;
        }
        counts[(band * s + inst.species) as usize] += 1;
    }
    (counts, ambiguous)
}

#[test]
fn gpu_bands_match_the_cpu_classification() {
    let ctx = common::ctx();
    let forest = common::forest(2000);
    let mut geo = geometry(&ctx, &forest);
    let spheres: Vec<(Vec3, f32)> = ["bush", "pine"]
        .iter()
        .map(|s| {
            let m =
                forest_bake::Mesh::load(&common::root().join(format!("assets/trees/{s}/{s}.obj")))
                    .unwrap();
            let b = forest_bake::bounding_sphere(&m);
            (b.center, b.radius)
        })
        .collect();
    let methods = [
        MeshMethod::Full { depth_sort: true },
        MeshMethod::Stochastic(Stochastic {
            d0: 5.0,
            h: 0.7,
            ..Default::default()
        }),
        MeshMethod::Lods(Lods {
            distances: [6.0, 15.0, 40.0],
        }),
    ];
    let target = Target::new(&ctx, 160, 120);
    let mut checked = 0;
    for method in methods {
        geo.set_method(&ctx, method).unwrap();
        for (name, cam) in common::cameras(forest.extent()) {
            geo.render_frame(&ctx, &cam, &target).unwrap();
            let gpu = geo.read_segment_counts(&ctx);
            let (cpu, ambiguous) = cpu_segments(&forest, &cam, &method, &spheres);
            let diff: u32 = gpu.iter().zip(&cpu).map(|(a, b)| a.abs_diff(*b)).sum();
            assert!(
                diff as usize <= 2 * ambiguous,
                "{method:?} {name}: GPU {gpu:?} vs CPU {cpu:?} ({ambiguous} within rounding)"
            );
            let used = cpu.iter().filter(|c| **c > 0).count();
            checked += used;
        }
    }
    assert!(
        checked > 20,
        "the cameras exercise many segments ({checked})"
    );
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
}

#[test]
fn every_method_renders_empty_single_and_million_tree_forests() {
    let ctx = common::ctx();
    let (empty, million) = common::empty_and_million();
    let methods = [
        ("geometry", MeshMethod::Full { depth_sort: false }),
        ("geometry-sorted", MeshMethod::Full { depth_sort: true }),
        ("stochastic", MeshMethod::Stochastic(Stochastic::default())),
        ("lods", MeshMethod::Lods(Lods::default())),
    ];
    for (forest_name, forest) in [
        ("empty", &empty),
        ("single", &common::one_tree(1, 0.3)),
        ("million", &million),
    ] {
        // Single tree: 12 m away, in full view. Otherwise from inside, with a far plane that
        // keeps the 1M-tree frame affordable on a software rasteriser.
        let mut cam = if forest_name == "single" {
            common::camera(Vec3::new(0.0, 3.0, 12.0), Vec3::new(0.0, 2.5, 0.0), 4.0)
        } else {
            common::cameras(forest.extent().max(10.0)).remove(0).1
        };
        cam.far = 40.0;
        let mut geo = geometry(&ctx, forest);
        let mut images = Vec::new();
        for (name, method) in methods {
            images.push((name, draw(&ctx, &mut geo, method, &cam)));
            assert_eq!(
                ctx.take_errors(),
                Vec::<String>::new(),
                "{name}, {forest_name}"
            );
        }
        for (name, refine) in [("quads", true), ("impostor", false)] {
            let scene = GpuScene::new(&ctx, &common::species(), forest).unwrap();
            let opts = RendererOptions {
                viewport: cam.viewport,
                background: Background::Transparent,
                refine,
                ..Default::default()
            };
            let mut stream = QuadStream::new(&ctx.device, scene, &opts).unwrap();
            let target = Target::new(&ctx, cam.viewport.0, cam.viewport.1);
            stream.render_frame(&ctx, &cam, &target).unwrap();
            images.push((name, target.read(&ctx)));
            assert_eq!(
                ctx.take_errors(),
                Vec::<String>::new(),
                "{name}, {forest_name}"
            );
        }
        for (name, img) in &images {
            let c = covered(img);
            match forest_name {
                "empty" => assert_eq!(c, 0, "{name}: an empty forest draws nothing"),
                _ => assert!(c > 100, "{name}, {forest_name}: trees drawn ({c} px)"),
            }
        }
    }
}

#[test]
fn switching_methods_at_run_time_reproduces_each_methods_own_frame() {
    use forest_baselines::methods::{ForestRenderer, Method};
    let ctx = common::ctx();
    let forest = common::forest(300);
    let (_, cam) = common::cameras(forest.extent()).remove(0);
    let opts = |refine| RendererOptions {
        viewport: cam.viewport,
        background: Background::Transparent,
        refine,
        ..Default::default()
    };
    let stream = || GpuScene::new(&ctx, &common::species(), &forest).unwrap();
    let alone = |refine| {
        let mut s = QuadStream::new(&ctx.device, stream(), &opts(refine)).unwrap();
        let t = Target::new(&ctx, cam.viewport.0, cam.viewport.1);
        s.render_frame(&ctx, &cam, &t).unwrap();
        t.read(&ctx)
    };
    let (quads, impostor) = (alone(true), alone(false));
    assert_ne!(quads, impostor, "refinement changes the image");
    let lods = MeshMethod::Lods(Lods {
        distances: [4.0, 8.0, 16.0],
    });
    let mut geo = geometry(&ctx, &forest);
    let lods_alone = draw(&ctx, &mut geo, lods, &cam);

    let mut without = ForestRenderer::new(
        QuadStream::new(&ctx.device, stream(), &opts(true)).unwrap(),
        None,
    );
    let err = without
        .set_method(&ctx, Method::Mesh(lods))
        .unwrap_err()
        .to_string();
    assert!(err.contains("OBJ models"), "{err}");
    assert_eq!(
        without.method(),
        Method::Quads,
        "a refused switch changes nothing"
    );

    let mut all = ForestRenderer::new(
        QuadStream::new(&ctx.device, stream(), &opts(false)).unwrap(),
        Some(geometry(&ctx, &forest)),
    );
    let target = Target::new(&ctx, cam.viewport.0, cam.viewport.1);
    for (method, expected) in [
        (Method::Impostor, &impostor),
        (Method::Mesh(lods), &lods_alone),
        (Method::Quads, &quads),
        (Method::Impostor, &impostor),
        (Method::Quads, &quads),
    ] {
        all.set_method(&ctx, method).unwrap();
        all.render_frame(&ctx, &cam, &target).unwrap();
        let stats = all.read_stats(&ctx);
        assert!(stats.visible_trees > 0 && stats.primitives > 0, "{stats:?}");
        assert!(
            &target.read(&ctx) == expected,
            "{} after switching differs from its own renderer",
            method.name()
        );
    }
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
}
