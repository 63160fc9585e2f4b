//! The GPU's quad stream equals the CPU reference, quad for quad and in order.

mod common;

use forest_format::wind::Wind;
use forest_render::ForestView;
use forest_render::options::RendererOptions;
use forest_render::reference;
use forest_render::scene::SpeciesData;
use forest_render::target::Target;
use forest_render::{Camera, GpuContext, GpuScene, QuadStream};

/// What one compared view drew.
#[derive(Clone, Debug)]
struct Summary {
    name: String,
    quads: usize,
    visible: u32,
    /// Level-0 quads dropped plus quads left unrefined.
    overflow: u32,
    overflow_cull: u32,
    /// Far trees' composited quads at level 0, before any were dropped.
    composites_all: u32,
    /// Composited quads drawn (leading the stream).
    composites: u32,
    /// Quads below level 0.
    refined: u32,
}

/// Along the ground at a coarse ε: the far trees are composited, the near ones refined.
fn coarse_view(side: f32) -> Camera {
    common::camera(
        glam::Vec3::new(-side * 0.7, 0.5, 0.0),
        glam::Vec3::new(0.0, 0.6, 0.0),
        16.0,
    )
}

/// Render one view and require the GPU's stream and counters to equal the reference's, run
/// with the stream's capacity and iterations.
fn compare(
    ctx: &GpuContext,
    stream: &mut QuadStream,
    target: &Target,
    name: &str,
    cam: &Camera,
) -> Summary {
    stream.render_frame(ctx, cam, target).unwrap();
    let gpu = stream.read_quads(ctx);
    let stats = stream.read_stats(ctx);
    // The camera uniform as the stream fills it: the reference's culls grow each sphere by
    // the wind's reach as the GPU's do.
    let mut uniform = cam.to_gpu();
    uniform.set_wind(&stream.wind());
    let cpu = reference::run_with(
        &stream.scene.tables,
        &uniform,
        stream.capacity.quads,
        stream.iterations(),
    );
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
    let kept = cpu.kept_composites();
    assert_eq!(stats.composites, kept, "{name}: composited quads");
    assert!(
        cpu.quads
            .iter()
            .enumerate()
            .all(|(i, q)| q.composite() == (i < kept as usize)),
        "{name}: composited quads lead the reference's stream"
    );
    assert_eq!(stats.per_level, cpu.per_level, "{name}: quads per level");
    assert_eq!(stats.quads as usize, gpu.len(), "{name}: quads counted");
    assert!(gpu.len() <= stream.capacity.quads as usize);
    Summary {
        name: name.to_string(),
        quads: gpu.len(),
        visible: stats.visible_trees,
        overflow: stats.overflow_refine + stats.overflow_cull,
        overflow_cull: stats.overflow_cull,
        composites_all: cpu.composites,
        composites: stats.composites,
        refined: stats.per_level.iter().skip(1).sum(),
    }
}

/// The shared cameras and the coarse view over a forest of `trees` of `species`.
fn check_species(species: &[SpeciesData], trees: u32, max_quads: Option<u32>) -> Vec<Summary> {
    check_in_wind(species, trees, max_quads, Wind::CALM)
}

/// [`check_species`] in `wind`.
fn check_in_wind(
    species: &[SpeciesData],
    trees: u32,
    max_quads: Option<u32>,
    wind: Wind,
) -> Vec<Summary> {
    let ctx = common::ctx();
    let forest = common::forest(trees);
    let scene = GpuScene::new(&ctx, species, &forest).unwrap();
    let (mut stream, target) = common::small_stream(&ctx, scene, max_quads);
    stream.set_wind(wind).unwrap();
    let side = forest.extent();
    let mut views = common::cameras(side);
    views.push(("horizon_coarse", coarse_view(side)));
    views
        .iter()
        .map(|(name, cam)| compare(&ctx, &mut stream, &target, name, cam))
        .collect()
}

fn check(trees: u32, max_quads: Option<u32>) -> Vec<Summary> {
    check_species(&common::species(), trees, max_quads)
}

fn find<'a>(s: &'a [Summary], name: &str) -> &'a Summary {
    s.iter().find(|x| x.name == name).unwrap()
}

#[test]
fn gpu_stream_equals_the_cpu_reference() {
    let s = check(300, None);
    eprintln!("{s:?}");
    let get = |n: &str| find(&s, n);
    assert!(get("inside").quads > 0 && get("birds_eye").quads > 0 && get("horizon").quads > 0);
    assert_eq!(get("culled").quads, 0, "nothing visible");
    assert_eq!(get("culled").visible, 0);
    assert!(
        get("birds_eye").visible > get("inside").visible,
        "a bird's eye sees more trees"
    );
    assert!(
        s.iter().all(|x| x.overflow == 0),
        "no overflow at the formula's capacity"
    );
    // A view that composites far trees and refines near ones: refinement runs over the
    // plain quads behind the composited ones.
    let coarse = get("horizon_coarse");
    assert!(coarse.composites > 0 && coarse.refined > 0, "{coarse:?}");
}

/// In a storm the culls grow every sphere by the wind's reach, on the GPU as in the reference:
/// the streams still equal quad for quad, and the grown spheres keep trees the calm culls
/// drop (trees swayed into view).
#[test]
fn in_a_storm_the_gpu_stream_equals_the_cpu_reference() {
    let storm = Wind {
        gustiness: 1.0,
        ..Wind::new(130.0, 35.0).at(7.25)
    };
    let calm = check(300, None);
    let windy = check_in_wind(&common::species(), 300, None, storm);
    eprintln!("{windy:?}");
    assert!(windy.iter().all(|x| x.overflow == 0));
    let visible = |s: &[Summary]| s.iter().map(|x| x.visible).sum::<u32>();
    assert!(
        visible(&windy) > visible(&calm),
        "the storm's reach kept no more trees: {} against {} calm",
        visible(&windy),
        visible(&calm)
    );
}

/// Trees standing on hills: the cull's bounding spheres, the presorts and the refinement
/// still give the reference's stream, from eyes standing on the ground in a valley and on a
/// hilltop, looking up and down the slopes, and from above.
#[test]
fn on_hilly_ground_the_gpu_stream_equals_the_cpu_reference() {
    use glam::Vec3;
    let ctx = common::ctx();
    let forest = common::hilly_forest(300);
    let terrain = forest.terrain.as_ref().unwrap();
    let (lo, hi) = terrain.height_range();
    assert!(hi - lo > 8.0, "hills: {lo}..{hi}");
    let scene = GpuScene::new(&ctx, &common::species(), &forest).unwrap();
    let (mut stream, target) = common::small_stream(&ctx, scene, None);
    let on_ground = |x: f32, z: f32, up: f32| Vec3::new(x, forest.ground_height(x, z) + up, z);
    // The lowest and highest trees' places.
    let by_height = |f: fn(f32, f32) -> bool| {
        forest
            .instances
            .iter()
            .map(|i| Vec3::from_array(i.position))
            .reduce(|a, b| if f(a.y, b.y) { a } else { b })
            .unwrap()
    };
    let (low, high) = (by_height(|a, b| a < b), by_height(|a, b| a > b));
    let side = forest.extent();
    let views = [
        (
            "valley, up the slope",
            common::camera(on_ground(low.x + 2.0, low.z, 1.7), high, 2.0),
        ),
        (
            "hilltop, down the slope",
            common::camera(on_ground(high.x + 2.0, high.z, 1.7), low, 2.0),
        ),
        (
            "above",
            common::camera(
                Vec3::new(0.0, hi + side * 0.8, side * 0.6),
                Vec3::new(0.0, lo, 0.0),
                2.0,
            ),
        ),
    ];
    for (name, cam) in &views {
        let s = compare(&ctx, &mut stream, &target, name, cam);
        assert!(s.visible > 0 && s.quads > 0, "{s:?}");
    }
    // Every tree stands on the drawn surface.
    for i in &forest.instances {
        assert_eq!(i.position[1], terrain.height(i.position[0], i.position[2]));
    }
}

/// Refinement alternates the stream buffers, so the final stream lies in the second buffer
/// after an odd number of steps: the composited quads, which no step writes, must be there
/// too (the test atlases' 5 levels give an even 4 steps; 64 px with 8-px finest quads give 4
/// levels, 3 steps).
#[test]
fn an_odd_number_of_refinement_steps_keeps_the_composited_quads() {
    let species = common::species_with(&forest_format::BakeParams {
        directions: 5,
        resolution: 64,
        min_quad: 8,
        spp: 2,
        ..forest_format::BakeParams::default()
    });
    let s = check_species(&species, 300, None);
    eprintln!("{s:?}");
    let coarse = find(&s, "horizon_coarse");
    assert!(coarse.composites > 0 && coarse.refined > 0, "{coarse:?}");
}

#[test]
fn overflow_keeps_to_the_capacity_and_matches_the_reference() {
    let s = check(300, Some(700));
    eprintln!("{s:?}");
    assert!(
        s.iter().any(|x| x.overflow > 0),
        "a small stream overflows somewhere"
    );
    // Also where composited quads lead the stream and refinement runs behind them.
    assert!(
        s.iter()
            .any(|x| x.overflow > 0 && x.composites > 0 && x.refined > 0),
        "{s:?}"
    );
    assert!(s.iter().all(|x| x.quads <= 700));
}

/// A level-0 stream longer than the capacity loses its first quads: the composited ones, then
/// the farthest trees' plain quads. Capacities chosen from the view's level-0 counts drop
/// part of the composited list, then all of it and some plain quads.
#[test]
fn cull_overflow_drops_the_composited_quads_first() {
    let ctx = common::ctx();
    let forest = common::forest(300);
    let cam = coarse_view(forest.extent());
    let species = common::species();
    let level0 = {
        let scene = GpuScene::new(&ctx, &species, &forest).unwrap();
        reference::run_with(&scene.tables, &cam.to_gpu(), u32::MAX, 0)
    };
    let (total, all) = (level0.quads.len() as u32, level0.composites);
    assert!(
        all > 4 && total > all + 4,
        "{total} level-0 quads, {all} composited"
    );
    for (capacity, kept) in [(total - all / 2, all - all / 2), (total - all - 4, 0)] {
        let scene = GpuScene::new(&ctx, &species, &forest).unwrap();
        let (mut stream, target) = common::small_stream(&ctx, scene, Some(capacity));
        let s = compare(&ctx, &mut stream, &target, "horizon_coarse", &cam);
        assert_eq!(
            (s.overflow_cull, s.composites_all, s.composites),
            (total - capacity, all, kept),
            "capacity {capacity}"
        );
    }
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
    let mut views = common::cameras(forest.extent());
    views.push(("horizon_coarse", coarse_view(forest.extent())));
    let mut composited = 0;
    for (name, cam) in views {
        let s = compare(&ctx, &mut stream, &target, name, &cam);
        assert_eq!(s.refined, 0, "{name}: only level-0 quads");
        composited += s.composites;
        let _ = target.read(&ctx);
        assert_eq!(ctx.take_errors(), Vec::<String>::new());
    }
    assert!(composited > 0, "some view composites far trees");
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
