//! The GPU's quad stream equals the CPU reference, quad for quad and in order.

mod common;

use forest_render::options::RendererOptions;
use forest_render::reference;
use forest_render::target::Target;
use forest_render::{GpuScene, QuadStream};

/// Per view: (name, quads, visible trees, overflow, composited quads, refined quads).
type Summary = (String, usize, u32, u32, u32, u32);

fn check(trees: u32, max_quads: Option<u32>) -> Vec<Summary> {
    let ctx = common::ctx();
    let forest = common::forest(trees);
    let scene = GpuScene::new(&ctx, &common::species(), &forest).unwrap();
    let (mut stream, target) = common::small_stream(&ctx, scene, max_quads);
    let side = forest.extent();
    let mut summary = Vec::new();
    let mut views = common::cameras(side);
    // Along the ground at a coarse ε: the far trees are composited, the near ones refined.
    views.push((
        "horizon_coarse",
        common::camera(
            glam::Vec3::new(-side * 0.7, 0.5, 0.0),
            glam::Vec3::new(0.0, 0.6, 0.0),
            16.0,
        ),
    ));
    for (name, cam) in views {
        stream.render_frame(&ctx, &cam, &target).unwrap();
        let gpu = stream.read_quads(&ctx);
        let stats = stream.read_stats(&ctx);
        let cpu = reference::run(&stream.scene.tables, &cam.to_gpu(), stream.capacity.quads);
        assert_eq!(
            ctx.take_errors(),
            Vec::<String>::new(),
            "{name}: wgpu errors"
        );
        assert_eq!(stats.presort, cpu.presort, "{name}: presort direction");
        assert_eq!(stats.visible_trees, cpu.visible, "{name}: visible trees");
        assert_eq!(
            stats.overflow_cull, cpu.overflow_cull,
            "{name}: cull overflow"
        );
        assert_eq!(
            stats.overflow_refine, cpu.overflow_refine,
            "{name}: refine overflow"
        );
        if let Some(i) = gpu.iter().zip(&cpu.quads).position(|(a, b)| a != b) {
            panic!(
                "{name}: quad {i} of {}/{} differs: GPU {:?} CPU {:?}",
                gpu.len(),
                cpu.quads.len(),
                gpu[i],
                cpu.quads[i]
            );
        }
        assert_eq!(gpu.len(), cpu.quads.len(), "{name}: stream length");
        // Two lists: the kept composited quads lead the stream, and only they.
        let kept = cpu.composites.saturating_sub(cpu.overflow_cull);
        assert_eq!(stats.composites, kept, "{name}: composited quads");
        assert!(
            cpu.quads
                .iter()
                .enumerate()
                .all(|(i, q)| q.composite() == (i < kept as usize)),
            "{name}: composited quads lead the reference's stream"
        );
        assert_eq!(stats.per_level, cpu.per_level, "{name}: quads per level");
        assert!(gpu.len() <= stream.capacity.quads as usize);
        summary.push((
            name.to_string(),
            gpu.len(),
            stats.visible_trees,
            stats.overflow_refine + stats.overflow_cull,
            stats.composites,
            stats.per_level.iter().skip(1).sum(),
        ));
    }
    summary
}

#[test]
fn gpu_stream_equals_the_cpu_reference() {
    let s = check(300, None);
    eprintln!("{s:?}");
    let get = |n: &str| s.iter().find(|x| x.0 == n).unwrap().clone();
    assert!(get("inside").1 > 0 && get("birds_eye").1 > 0 && get("horizon").1 > 0);
    assert_eq!(get("culled").1, 0, "nothing visible");
    assert_eq!(get("culled").2, 0);
    assert!(
        get("birds_eye").2 > get("inside").2,
        "a bird's eye sees more trees"
    );
    assert!(
        s.iter().all(|x| x.3 == 0),
        "no overflow at the formula's capacity"
    );
    // A view that composites far trees and refines near ones: refinement runs over the
    // plain quads behind the composited ones.
    let coarse = get("horizon_coarse");
    assert!(coarse.4 > 0 && coarse.5 > 0, "{coarse:?}");
}

#[test]
fn overflow_keeps_to_the_capacity_and_matches_the_reference() {
    let s = check(300, Some(700));
    eprintln!("{s:?}");
    assert!(
        s.iter().any(|x| x.3 > 0),
        "a small stream overflows somewhere"
    );
    // Also where composited quads lead the stream and refinement runs behind them.
    assert!(s.iter().any(|x| x.3 > 0 && x.4 > 0 && x.5 > 0), "{s:?}");
    assert!(s.iter().all(|x| x.1 <= 700));
}

#[test]
fn static_impostors_are_the_level0_stream() {
    let ctx = common::ctx();
    let forest = common::forest(300);
    let scene = GpuScene::new(&ctx, &common::species(), &forest).unwrap();
    let opts = RendererOptions {
        viewport: (160, 120),
        refine: false,
        ..Default::default()
    };
    let mut stream = QuadStream::new(&ctx.device, scene, &opts).unwrap();
    assert_eq!(stream.iterations(), 0);
    let target = Target::new(&ctx, 160, 120);
    for (name, cam) in common::cameras(forest.extent()) {
        stream.render_frame(&ctx, &cam, &target).unwrap();
        let gpu = stream.read_quads(&ctx);
        let cpu = reference::run_with(
            &stream.scene.tables,
            &cam.to_gpu(),
            stream.capacity.quads,
            0,
        );
        assert_eq!(gpu, cpu.quads, "{name}");
        assert!(
            gpu.iter().all(|q| q.level() == 0),
            "{name}: only level-0 quads"
        );
        let _ = target.read(&ctx);
        assert_eq!(ctx.take_errors(), Vec::<String>::new());
    }
}

/// Long streams: the block sums of 1M trees (1954 blocks) and of their level-0 quads take the
/// one-workgroup scan through several chunks of 512 with its carry, and an emitting
/// workgroup's output crosses block boundaries. The first sizing cannot hold a bird's-eye view
/// of every tree: the first frame overflows safely (and still equals the reference at that
/// capacity), `fit` grows the stream, and the grown stream holds the whole view.
#[test]
fn a_million_trees_grow_the_stream_and_equal_the_cpu_reference() {
    let ctx = common::ctx();
    let (_, forest) = common::empty_and_million();
    let scene = GpuScene::new(&ctx, &common::species(), &forest).unwrap();
    let (mut stream, target) = common::small_stream(&ctx, scene, None);
    let side = forest.extent();
    let cam = common::camera(
        glam::Vec3::new(0.0, side * 0.6, side * 0.4),
        glam::Vec3::ZERO,
        4.0,
    );
    let first = stream.capacity.quads;
    let mut rebuilt = 0;
    loop {
        stream.render_frame(&ctx, &cam, &target).unwrap();
        let gpu = stream.read_quads(&ctx);
        let stats = stream.read_stats(&ctx);
        assert_eq!(ctx.take_errors(), Vec::<String>::new());
        let cpu = reference::run(&stream.scene.tables, &cam.to_gpu(), stream.capacity.quads);
        assert_eq!(stats.visible_trees, cpu.visible);
        assert_eq!(
            (stats.overflow_cull, stats.overflow_refine),
            (cpu.overflow_cull, cpu.overflow_refine)
        );
        assert_eq!(stats.per_level, cpu.per_level);
        assert_eq!(gpu.len(), cpu.quads.len(), "stream length");
        if let Some(i) = gpu.iter().zip(&cpu.quads).position(|(a, b)| a != b) {
            panic!("quad {i} differs: GPU {:?} CPU {:?}", gpu[i], cpu.quads[i]);
        }
        assert!(gpu.len() <= stream.capacity.quads as usize);
        if rebuilt == 0 {
            assert!(stats.overflow_cull > 0, "the first sizing overflows");
        }
        if !stream.fit(&ctx.device, &stats).unwrap() {
            assert_eq!(stats.overflow_cull + stats.overflow_refine, 0);
            assert!(
                gpu.len() > 512 * 512,
                "{} quads: too few for several chunks of block sums",
                gpu.len()
            );
            break;
        }
        rebuilt += 1;
        assert!(rebuilt <= 4, "fit settles in a few steps");
    }
    assert!(stream.capacity.quads > first);
}
