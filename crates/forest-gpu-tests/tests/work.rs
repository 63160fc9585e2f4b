//! Work counters against analytic counts: a rectangle of known size shades its pixels and no
//! more; the quad stream's counts follow from its quads and its recorded passes.

mod common;

use forest_render::ForestView;
use forest_render::options::{AspectBlend, Background, RendererOptions};
use forest_render::target::{TARGET_FORMAT, Target};
use forest_render::work::{self, StatisticsQueries};
use forest_render::{GpuScene, QuadStream};
use glam::Vec3;

/// Pixels x 8..40, y 4..20 of a 64×32 target, edges on pixel boundaries.
const RECT_WGSL: &str = "
@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = select(-0.75, 0.25, (i & 1u) == 1u);
    let y = select(0.75, -0.25, (i & 2u) == 2u);
    return vec4<f32>(x, y, 0.5, 1.0);
}
@fragment fn fs() -> @location(0) vec4<f32> { return vec4<f32>(1.0); }
";

/// Pixels shaded in aligned `b`×`b` blocks by [`RECT_WGSL`]'s rectangle.
fn shaded_in_blocks(b: i32) -> u64 {
    common::rectangle_shaded_in_blocks([8, 4, 40, 20], (64, 32), b)
}

#[test]
fn a_rectangle_of_known_size_shades_its_pixels() {
    let ctx = common::ctx();
    let Some(queries) = StatisticsQueries::new(&ctx.device) else {
        eprintln!(
            "no pipeline-statistics queries on {}",
            ctx.adapter_info.name
        );
        return;
    };
    let module = ctx
        .device
        .create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("rectangle"),
            source: wgpu::ShaderSource::Wgsl(RECT_WGSL.into()),
        });
    let layout = ctx
        .device
        .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: None,
            bind_group_layouts: &[],
            immediate_size: 0,
        });
    let pipeline = common::strip_pipeline(&ctx, &module, &layout, None);
    let target = Target::new(&ctx, 64, 32);
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    for q in [work::CULL, work::REFINE] {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.begin_pipeline_statistics_query(&queries.set, q);
        pass.end_pipeline_statistics_query();
    }
    {
        let mut pass = common::cleared_pass(&mut enc, &target.colour_view);
        pass.set_pipeline(&pipeline);
        pass.begin_pipeline_statistics_query(&queries.set, work::DRAW);
        pass.draw(0..4, 0..1);
        pass.end_pipeline_statistics_query();
    }
    queries.resolve(&mut enc);
    ctx.queue.submit([enc.finish()]);
    let bytes = ctx.read_buffer(&queries.resolve, work::STATISTICS_BYTES);
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    let p = work::decode(&bytes).unwrap();
    let draw = p[work::DRAW as usize];
    let covered = target.read(&ctx).pixels().filter(|px| px[3] > 0).count() as u64;
    assert_eq!(covered, 32 * 16);
    assert_eq!(draw.vertex_invocations, 4, "{draw:?}");
    assert_eq!(draw.primitives, 2, "{draw:?}");
    // Fragments are counted per pixel, or per aligned block a triangle touches (2×2 quads
    // with their helper invocations on most GPUs; lavapipe counts its 4×4 stamps): each
    // answer is analytic, and the count must be one of them.
    let answers: Vec<u64> = [1, 2, 4].map(shaded_in_blocks).to_vec();
    assert_eq!(answers[0], covered);
    assert!(
        answers.contains(&draw.fragment_invocations),
        "{draw:?}: per pixel, 2×2 and 4×4 blocks give {answers:?}"
    );
    assert_eq!(draw.compute_invocations, 0);
    assert_eq!(p[work::CULL as usize], work::PassWork::default());
}

/// A quad stream over `species`' trees of `forest`, 160×120 over a transparent background,
/// sized for ε down to `min_epsilon`, and its target.
fn small_stream(
    ctx: &forest_render::GpuContext,
    species: &[forest_render::SpeciesData],
    forest: &forest_format::forest::Forest,
    min_epsilon: f32,
) -> (QuadStream, Target) {
    let scene = GpuScene::new(ctx, species, forest).unwrap();
    let opts = RendererOptions {
        viewport: (160, 120),
        min_epsilon,
        background: Background::Transparent,
        ..Default::default()
    };
    (
        QuadStream::new(&ctx.device, scene, &opts).unwrap(),
        Target::new(ctx, 160, 120),
    )
}

#[test]
fn the_stream_counts_its_work() {
    let ctx = common::ctx();
    let forest = common::forest(6);
    let (mut stream, target) = small_stream(&ctx, &common::species(), &forest, 2.0);
    let side = forest.extent();
    let cam = common::camera(Vec3::new(0.0, 2.0, side * 1.5), Vec3::ZERO, 2.0);
    // Off by default: no statistics, the recorded counts all the same.
    stream.render_frame(&ctx, &cam, &target).unwrap();
    let off = stream.read_stats(&ctx);
    assert_eq!(off.work.passes, None);
    assert!(off.work.dispatches > 0 && off.work.draws == 3);
    stream.set_pipeline_statistics(true);
    stream.render_frame(&ctx, &cam, &target).unwrap();
    let stats = stream.read_stats(&ctx);
    assert_eq!(
        (stats.work.dispatches, stats.work.draws, stats.work.bytes),
        (off.work.dispatches, off.work.draws, off.work.bytes)
    );
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    let w = &stats.work;
    assert!(stats.quads > 0, "the camera sees trees");
    // Cull: setup, count, top, down, emit. Refine: per iteration top, down, emit; then the
    // final length.
    let iterations = stream.scene.tables.max_levels - 1;
    assert_eq!(w.dispatches, 5 + 3 * iterations + 1);
    // The stream's three draws (the opaque pass, far trees' composited quads, then the
    // others), no ground over a transparent background.
    assert_eq!(w.draws, 3, "quads only over a transparent background");
    assert!(w.bytes >= stream.scene.bytes + stream.capacity.bytes());
    let Some(p) = w.passes else {
        eprintln!(
            "no pipeline-statistics queries on {}",
            ctx.adapter_info.name
        );
        return;
    };
    let (cull, refine, draw) = (
        p[work::CULL as usize],
        p[work::REFINE as usize],
        p[work::DRAW as usize],
    );
    // Every quad is a four-vertex strip in one of the two blended draws (its list's), and
    // every plain quad once more in the opaque pass: two triangles unless clipped.
    let strips = u64::from(stats.quads) + u64::from(stats.quads - stats.composites);
    assert_eq!(draw.vertex_invocations, 4 * strips);
    assert!(draw.primitives > 0 && draw.primitives <= 2 * strips);
    // Every covered pixel was shaded at least once.
    let covered = target.read(&ctx).pixels().filter(|px| px[3] > 0).count() as u64;
    assert!(
        covered > 0 && draw.fragment_invocations >= covered,
        "{draw:?} {covered}"
    );
    // Compute work in the compute passes only; the cull visits every tree at least once.
    assert!(cull.compute_invocations >= forest.instances.len() as u64);
    // Refinement visits every plain quad (the composited ones, never refined, it skips).
    assert!(refine.compute_invocations >= u64::from(stats.quads - stats.composites));
    assert_eq!(draw.compute_invocations, 0);
    assert_eq!(cull.fragment_invocations + refine.fragment_invocations, 0);
    // The frame loop's read-back (a few frames late) brings the same counts.
    let polled = (0..20).find_map(|_| {
        stream.render_frame(&ctx, &cam, &target).unwrap();
        stream.poll_stats(&ctx.device, &ctx.queue)
    });
    let polled = polled.expect("statistics arrive within 20 frames");
    assert_eq!(polled.work, stats.work);
}

#[test]
fn every_method_counts_its_work() {
    use forest_baselines::geometry::{GeometryRenderer, MeshMethod};
    use forest_baselines::hybrid::{Hybrid, Near};
    use forest_baselines::methods::{ForestRenderer, Method};

    let ctx = common::ctx();
    let forest = common::forest(6);
    let scene = GpuScene::new(&ctx, &common::species(), &forest).unwrap();
    let opts = RendererOptions {
        viewport: (160, 120),
        background: Background::Transparent,
        ..Default::default()
    };
    let geometry = GeometryRenderer::new(
        &ctx,
        common::prepared(),
        &forest,
        TARGET_FORMAT,
        Background::Transparent,
    )
    .unwrap();
    let gpu_bytes = geometry.gpu_bytes;
    let mut r = ForestRenderer::new(
        QuadStream::new(&ctx.device, scene, &opts).unwrap(),
        Some(geometry),
    );
    r.set_pipeline_statistics(true);
    let side = forest.extent();
    let cam = common::camera(Vec3::new(0.0, 2.0, side * 1.5), Vec3::ZERO, 2.0);
    let target = Target::new(&ctx, 160, 120);
    let segments = forest_bake::lod::BANDS * forest.species.len() as u32;
    let mut run = |method: Method| {
        r.set_method(&ctx, method).unwrap();
        r.render_frame(&ctx, &cam, &target).unwrap();
        let s = r.read_stats(&ctx);
        assert_eq!(ctx.take_errors(), Vec::<String>::new(), "{method:?}");
        let covered = target.read(&ctx).pixels().filter(|px| px[3] > 0).count() as u64;
        (s, covered)
    };
    let (full, covered) = run(Method::Mesh(MeshMethod::Full { depth_sort: false }));
    let w = &full.work;
    // Reset, classify, arguments, scatter; one indirect draw per band and species.
    assert_eq!((w.dispatches, w.draws, w.bytes), (4, segments, gpu_bytes));
    if let Some(p) = w.passes {
        let draw = p[work::DRAW as usize];
        // Indexed triangles: at most three vertices each, at least one (shared vertices).
        assert!(draw.vertex_invocations <= 3 * full.primitives, "{draw:?}");
        assert!(draw.vertex_invocations >= full.primitives / 3, "{draw:?}");
        assert!(
            draw.fragment_invocations >= covered && covered > 0,
            "{draw:?}"
        );
        assert_eq!(p[work::REFINE as usize], work::PassWork::default());
        assert!(p[work::CULL as usize].compute_invocations >= forest.instances.len() as u64);
    }
    let (quads, _) = run(Method::Quads);
    let (hybrid, _) = run(Method::Hybrid(Hybrid {
        near: Near::Metres(side * 0.4),
        ..Default::default()
    }));
    // The hybrid's work is both forms' work in one frame: the stream's dispatches and its
    // two draws (its quads run without the opaque pass), the geometry's four dispatches and
    // its draws, both renderers' memory.
    let h = &hybrid.work;
    assert_eq!(h.dispatches, quads.work.dispatches + 4);
    assert_eq!(h.draws, 2 + segments);
    assert_eq!(h.bytes, quads.work.bytes + gpu_bytes);
    if let (Some(t), Some(_)) = (h.total(), quads.work.passes) {
        assert!(t.compute_invocations > 0 && t.vertex_invocations > 0);
    }
}

#[test]
fn trimmed_quads_draw_the_same_image_with_fewer_fragments() {
    use forest_render::options::StreamOptions;

    let ctx = common::ctx();
    let forest = common::forest(40);
    let scene = GpuScene::new(&ctx, &common::species(), &forest).unwrap();
    let opts = RendererOptions {
        viewport: (160, 120),
        min_epsilon: 1.0,
        background: Background::Transparent,
        ..Default::default()
    };
    let mut stream = QuadStream::new(&ctx.device, scene, &opts).unwrap();
    stream.set_pipeline_statistics(true);
    let target = Target::new(&ctx, 160, 120);
    let mut frame = |trim: bool, cam: &forest_render::Camera| {
        stream
            .set_options(StreamOptions {
                trim,
                ..Default::default()
            })
            .unwrap();
        stream.render_frame(&ctx, cam, &target).unwrap();
        let s = stream.read_stats(&ctx);
        assert_eq!(ctx.take_errors(), Vec::<String>::new());
        let fragments = s
            .work
            .passes
            .map(|p| p[work::DRAW as usize].fragment_invocations);
        (target.read(&ctx), fragments, s.quads)
    };
    let side = forest.extent();
    let mut cams = common::cameras(side);
    cams.push((
        "close_up",
        common::camera(Vec3::new(3.0, 1.5, 3.0), Vec3::new(0.0, 1.5, 0.0), 1.0),
    ));
    for (name, cam) in cams {
        let (whole, whole_fragments, whole_quads) = frame(false, &cam);
        let (trimmed, trimmed_fragments, quads) = frame(true, &cam);
        assert_eq!(quads, whole_quads, "{name}: trimming changes no quad");
        let m = forest_metrics::compare(&whole, &trimmed).unwrap();
        if m.flip_mean > 0.01 {
            let out = common::failure_images(&format!("trim-{name}"), &whole, &trimmed);
            panic!(
                "{name}: trimmed against untrimmed FLIP {} (images in {})",
                m.flip_mean,
                out.display()
            );
        }
        if let (Some(t), Some(w)) = (trimmed_fragments, whole_fragments)
            && quads > 0
        {
            eprintln!(
                "{name}: {quads} quads, fragments {w} untrimmed, {t} trimmed, FLIP {}",
                m.flip_mean
            );
            assert!(t <= w, "{name}: {t} fragments trimmed, {w} untrimmed");
        }
    }
}

#[test]
fn every_covered_texel_lies_in_its_nodes_box() {
    use forest_format::trim;
    for s in common::species() {
        let m = &s.atlas.manifest;
        let t = trim::node_trims(&s.atlas.nodes, &m.layer_roots, &s.layers, m.levels);
        let res = s.layers.resolution;
        let (mut nodes, mut texels) = (0, 0);
        for (l, root) in m.layer_roots.iter().enumerate() {
            let Some(root) = root else { continue };
            let rgba = s.layers.layer(l as u32);
            let mut stack = vec![(*root, 0u32, 0u32, 0u32)];
            while let Some((n, level, x, y)) = stack.pop() {
                let side = res >> level;
                let (lo, hi) = trim::unpack(t[n as usize][0]);
                for py in y * side..(y + 1) * side {
                    for px in x * side..(x + 1) * side {
                        if rgba[((py * res + px) * 4 + 3) as usize] == 0 {
                            continue;
                        }
                        let fx = (px - x * side) as f32 / side as f32;
                        let fy = (py - y * side) as f32 / side as f32;
                        let inv = 1.0 / side as f32;
                        assert!(
                            fx >= lo[0] - 1e-6
                                && fy >= lo[1] - 1e-6
                                && fx + inv <= hi[0] + 1e-6
                                && fy + inv <= hi[1] + 1e-6,
                            "layer {l} node {n} (level {level}): texel ({px}, {py}) outside \
                             {lo:?}..{hi:?}"
                        );
                        texels += 1;
                    }
                }
                nodes += 1;
                let node = s.atlas.nodes[n as usize];
                for c in 0..4 {
                    if let Some(k) = node.child_index(c) {
                        stack.push((k, level + 1, x * 2 + (c & 1), y * 2 + (c >> 1)));
                    }
                }
            }
        }
        assert!(nodes > 0 && texels > 0);
        // The boxes trim: on average a node's box is well under its square.
        let area: f32 = t
            .iter()
            .map(|&b| {
                let (lo, hi) = trim::unpack(b[0]);
                (hi[0] - lo[0]).max(0.0) * (hi[1] - lo[1]).max(0.0)
            })
            .sum::<f32>()
            / t.len() as f32;
        eprintln!("{nodes} nodes, {texels} covered texel visits, mean box area {area:.3}");
        assert!(area < 0.9, "mean box area {area}");
    }
}

/// A frame of `stream` with `options`: its counters, its final quads (checked equal to the
/// CPU reference's for the same flags) and its image.
fn checked_frame(
    ctx: &forest_render::GpuContext,
    stream: &mut QuadStream,
    cam: &forest_render::Camera,
    target: &Target,
    options: forest_render::options::StreamOptions,
) -> (
    forest_render::stats::FrameStats,
    Vec<forest_render::gpu_types::Quad>,
    image::RgbaImage,
) {
    stream.set_options(options).unwrap();
    stream.render_frame(ctx, cam, target).unwrap();
    let s = stream.read_stats(ctx);
    let quads = stream.read_quads(ctx);
    let mut g = cam.to_gpu();
    options.apply(&mut g);
    let cpu = forest_render::reference::run(&stream.scene.tables, &g, stream.capacity.quads);
    assert_eq!(quads, cpu.quads, "{options:?}: GPU and CPU agree");
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    (s, quads, target.read(ctx))
}

/// A frame of a bird's-eye view at ε 16 over 300 small trees (most under ε pixels), over a
/// transparent background with pipeline statistics, for each of two option sets.
fn far_view(
    options: [forest_render::options::StreamOptions; 2],
    shadowed: bool,
) -> [(
    forest_render::stats::FrameStats,
    Vec<forest_render::gpu_types::Quad>,
    image::RgbaImage,
); 2] {
    let ctx = common::ctx();
    let forest = common::forest(300);
    let mut species = common::species();
    if !shadowed {
        for s in &mut species {
            s.opacity = forest_format::opacity::OpacityVolume::empty(s.opacity.resolution);
        }
    }
    let (mut stream, target) = small_stream(&ctx, &species, &forest, 4.0);
    stream.set_pipeline_statistics(true);
    let cam = far_camera(&forest);
    options.map(|o| checked_frame(&ctx, &mut stream, &cam, &target, o))
}

/// The camera of [`far_view`].
fn far_camera(forest: &forest_format::forest::Forest) -> forest_render::Camera {
    let side = forest.extent();
    common::camera(Vec3::new(0.0, side, side * 0.6), Vec3::ZERO, 16.0)
}

/// [`far_view`]'s 4×4 supersampled full-geometry reference.
fn far_reference() -> image::RgbaImage {
    let forest = common::forest(300);
    reference_of(&forest, &far_camera(&forest))
}

/// The 4×4 supersampled full-geometry reference of `cam` (160×120) over `forest`.
fn reference_of(
    forest: &forest_format::forest::Forest,
    cam: &forest_render::Camera,
) -> image::RgbaImage {
    let ctx = common::ctx();
    let mut geo = forest_baselines::geometry::GeometryRenderer::with_targets(
        &ctx,
        common::prepared(),
        forest,
        &RendererOptions {
            format: TARGET_FORMAT,
            background: Background::Transparent,
            ..Default::default()
        },
    )
    .unwrap();
    let big = Target::new(&ctx, 640, 480);
    let mut cam = *cam;
    cam.viewport = (640, 480);
    geo.set_method(&ctx, forest_baselines::geometry::MeshMethod::Reference)
        .unwrap();
    geo.render_frame(&ctx, &cam, &big).unwrap();
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    forest_baselines::geometry::downsample(&big.read(&ctx), 4)
}

/// Far trees' slabs drawn as one composited quad: one quad per far tree instead of at least
/// one per slab, nearly the same image (FLIP ≤ 0.03), fewer fragments; GPU and CPU reference
/// agree either way.
#[test]
fn far_trees_composite_their_slabs_into_one_quad() {
    use forest_render::options::StreamOptions;

    // Far span 1: only trees narrower than ε are far, so that drawn per slab their quads
    // are hardly ever refined either.
    let both = [
        StreamOptions {
            far_composite: false,
            far_span: 1,
            ..Default::default()
        },
        StreamOptions {
            far_span: 1,
            ..Default::default()
        },
    ];
    // Without self-shadowing the two draw the same texels; with it they differ in where
    // they march (see below).
    let [(slabs, slab_quads, slab_img), (comp, comp_quads, comp_img)] = far_view(both, false);
    let composited: std::collections::BTreeSet<u32> = comp_quads
        .iter()
        .filter(|q| q.composite())
        .map(|q| q.instance)
        .collect();
    assert!(!composited.is_empty(), "far trees are composited");
    // Their own draw only while the options can make composited quads.
    assert_eq!((slabs.work.draws, comp.work.draws), (2, 3));
    assert!(slab_quads.iter().all(|q| !q.composite()));
    for &tree in &composited {
        let of = |qs: &[forest_render::gpu_types::Quad]| {
            qs.iter().filter(|q| q.instance == tree).count()
        };
        assert_eq!(of(&comp_quads), 1, "tree {tree}: one quad");
        // At least one per slab (a level-0 quad's nearest corner can project longer than ε
        // and be refined, which a composited quad never is).
        assert!(of(&slab_quads) >= 2, "tree {tree}: one quad per slab");
    }
    assert_eq!(comp.composites as usize, composited.len());
    assert_eq!(slabs.composites, 0);
    assert!(
        comp.quads as usize + composited.len() <= slabs.quads as usize,
        "{} quads composited, {} not",
        comp.quads,
        slabs.quads
    );
    let m = forest_metrics::compare(&slab_img, &comp_img).unwrap();
    // Self-shadowed, a composited quad marches towards the sun per fragment and a level-0
    // slab quad at its corners (interpolated over the whole tree): judged against the 4×4
    // reference, the composite must be no worse (measured 0.125 against 0.164).
    let [(_, _, slab_lit), (_, _, comp_lit)] = far_view(both, true);
    let reference = far_reference();
    let to_ref = |img| forest_metrics::compare(&reference, img).unwrap().flip_mean;
    let (per_slab, composited_flip) = (to_ref(&slab_lit), to_ref(&comp_lit));
    eprintln!("against the reference: per slab {per_slab:.4}, composited {composited_flip:.4}");
    assert!(
        composited_flip <= per_slab + 0.005,
        "self-shadowed: composited FLIP {composited_flip:.4} against the reference, per slab \
         {per_slab:.4}"
    );
    let work = |s: &forest_render::stats::FrameStats| {
        s.work
            .total()
            .map(|p| (p.vertex_invocations, p.fragment_invocations))
    };
    eprintln!(
        "{} composited trees; quads {} -> {}; (vertices, fragments) {:?} -> {:?}; FLIP {}",
        composited.len(),
        slabs.quads,
        comp.quads,
        work(&slabs),
        work(&comp),
        m.flip_mean
    );
    // Measured 0.025 on this view, where every far tree is composited (each slab sampled at
    // its root plane's depth through the parallax; the rest is filtering and the few far
    // trees whose level-0 corners project just past ε and are refined when drawn per slab);
    // slab samples repeating the image's edge texels gave 0.043 with visible streaks.
    if m.flip_mean > 0.03 {
        let out = common::failure_images("composite", &slab_img, &comp_img);
        panic!(
            "FLIP {} against one quad per slab (images in {})",
            m.flip_mean,
            out.display()
        );
    }
    if let (Some(a), Some(b)) = (work(&slabs), work(&comp)) {
        // Fewer fragments; each quad's four vertices run once in its own list's draw, and a
        // plain quad's once more in the opaque pass.
        assert!(b.1 < a.1, "{a:?} -> {b:?}");
        let strips = |s: &forest_render::stats::FrameStats| {
            u64::from(s.quads) + u64::from(s.quads - s.composites)
        };
        assert_eq!(a.0, 4 * strips(&slabs));
        assert_eq!(b.0, 4 * strips(&comp));
    }
}

#[test]
fn trees_narrower_than_epsilon_draw_their_nearest_aspect_alone() {
    use forest_render::options::StreamOptions;

    let [
        (blended, blended_quads, blended_img),
        (nearest, quads, nearest_img),
    ] = far_view(
        [
            StreamOptions {
                far_nearest: false,
                sharpen_reach: 1,
                ..Default::default()
            },
            StreamOptions {
                sharpen_reach: 1,
                ..Default::default()
            },
        ],
        true,
    );
    assert_eq!(nearest.visible_trees, blended.visible_trees);
    assert!(nearest.visible_trees > 0);
    // Trees drawn at level 0 alone, with one aspect: the far ones join them, with at most
    // one quad per slab.
    let level0_single = |quads: &[forest_render::gpu_types::Quad]| {
        let mut per_tree = std::collections::BTreeMap::<u32, Vec<(u32, u32)>>::new();
        for q in quads {
            per_tree
                .entry(q.instance)
                .or_default()
                .push((q.level(), q.dir()));
        }
        per_tree
            .values()
            .filter(|v| v.iter().all(|&(l, d)| l == 0 && d == v[0].1))
            .map(|v| v.len())
            .collect::<Vec<_>>()
    };
    let (before, after) = (level0_single(&blended_quads), level0_single(&quads));
    assert!(
        after.len() > before.len(),
        "{} vs {}",
        after.len(),
        before.len()
    );
    assert!(
        after.iter().all(|&n| n <= 2),
        "one quad per slab (two slabs) or one composited quad"
    );
    assert!(
        nearest.quads < blended.quads,
        "{} vs {}",
        nearest.quads,
        blended.quads
    );
    let single = after.len();
    let m = forest_metrics::compare(&blended_img, &nearest_img).unwrap();
    eprintln!(
        "{} visible trees: {} quads blended, {} nearest ({single} single-aspect trees), FLIP {}",
        nearest.visible_trees, blended.quads, nearest.quads, m.flip_mean
    );
    // The images differ (one aspect instead of a blend, for trees under ε pixels); how much
    // that costs against the reference is the accuracy suite's to say.
    assert!(m.flip_mean < 0.15, "FLIP {}", m.flip_mean);
}

/// What [`sweep`] measured of its three option sets: exact fragments and FLIP against the 4×4
/// reference, each summed over the six views.
struct Sweep {
    fragments: [u64; 3],
    flips: [f32; 3],
}

/// Three option sets on the six test cameras (the five named ones at ε 4 and the far view at
/// ε 16): each frame checked against the CPU reference (`checked_frame`), counted exactly,
/// and compared with the 4×4 reference; no view may be more than FLIP 0.01 less accurate
/// with the second set than with the first, and the second must shade fewer fragments than
/// the first, the third no more than the second. `between(name, a, b)` checks each view's
/// consecutive frame statistics.
fn sweep(
    label: &str,
    options: [forest_render::options::StreamOptions; 3],
    between: impl Fn(&str, &forest_render::stats::FrameStats, &forest_render::stats::FrameStats),
) -> Sweep {
    use forest_render::fragments::{FragmentCounter, count_fragments};

    let ctx = common::ctx();
    let forest = common::forest(300);
    let (mut stream, target) = small_stream(&ctx, &common::species(), &forest, 4.0);
    let counter = FragmentCounter::new(&ctx.device, 160, 120, false).unwrap();
    let mut views = common::cameras(forest.extent());
    views.push(("far", far_camera(&forest)));
    assert_eq!(views.len(), 6);
    let mut out = Sweep {
        fragments: [0; 3],
        flips: [0.0; 3],
    };
    for (name, cam) in views {
        let reference = reference_of(&forest, &cam);
        let mut last = None;
        let mut images = Vec::new();
        for (k, o) in options.into_iter().enumerate() {
            let (s, _, img) = checked_frame(&ctx, &mut stream, &cam, &target, o);
            if let Some(before) = &last {
                between(name, before, &s);
            }
            last = Some(s);
            let counts = count_fragments(
                &ctx,
                &counter,
                &mut stream,
                QuadStream::set_fragment_counter,
                |st| st.render_frame(&ctx, &cam, &target),
            )
            .unwrap();
            assert!(
                target.read(&ctx) == img,
                "{name}: counting changed the frame"
            );
            out.fragments[k] += counts.summary().fragments;
            let flip = forest_metrics::compare(&reference, &img).unwrap().flip_mean;
            out.flips[k] += flip;
            images.push((img, flip));
        }
        let (base, def) = (images[0].1, images[1].1);
        eprintln!(
            "{label} {name}: FLIP against the reference {base:.4} -> {def:.4}; between them {:.4}",
            forest_metrics::compare(&images[0].0, &images[1].0)
                .unwrap()
                .flip_mean
        );
        if def > base + 0.01 {
            let dir =
                common::failure_images(&format!("{label}-{name}"), &images[0].0, &images[1].0);
            panic!(
                "{label} {name}: FLIP against the reference {def} at the default, {base} without \
                 (images in {})",
                dir.display()
            );
        }
    }
    eprintln!(
        "{label}: fragments {:?}, FLIP sums {:?}",
        out.fragments, out.flips
    );
    assert!(
        out.fragments[1] < out.fragments[0] && out.fragments[2] <= out.fragments[1],
        "{label}: fragments {:?}",
        out.fragments
    );
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    out
}

/// A wider far span makes more trees far (one aspect, slabs composited, unrefined): on each of
/// the six test cameras, GPU and CPU reference agree at spans 1, the default and 16; the far
/// trees only grow and the quads only shrink with the span; against the 4×4 reference the
/// default is nowhere more than FLIP 0.01 less accurate than span 1, and within 3 % over the
/// six views; and over them it shades fewer fragments, counted exactly. (The default's image
/// is not span 1's: it draws a blend of three aspects as one, FLIP 0.017 apart in the far
/// view.)
#[test]
fn a_wider_far_span_shades_fewer_fragments_at_the_same_accuracy() {
    use forest_render::options::{FAR_SPAN_DEFAULT, StreamOptions};

    let with = |far_span| StreamOptions {
        far_span,
        sharpen: 0,
        sharpen_reach: 1,
        ..Default::default()
    };
    let s = sweep(
        "far-span",
        [with(1), with(FAR_SPAN_DEFAULT), with(16)],
        |name, a, b| {
            assert!(b.composites >= a.composites, "{name}");
            assert!(b.quads + b.composites <= a.quads + a.composites, "{name}");
        },
    );
    // Measured 1.020× on these views (far view +0.0031, bird's-eye +0.0016: with these
    // atlases' 5 directions the nearest aspect lies up to 45° off).
    assert!(s.flips[1] <= s.flips[0] * 1.03, "{:?}", s.flips);
}

/// Sharpened aspect weights drop the faint aspects' quads: on the six test cameras, GPU and CPU
/// reference agree at sharpening 0, the default and the largest; the quads only shrink; the
/// default shades fewer fragments, nowhere more than FLIP 0.01 less accurate against the
/// reference and within 3 % over the six views.
#[test]
fn sharpened_aspects_shade_fewer_fragments_at_the_same_accuracy() {
    use forest_render::options::{SHARPEN_DEFAULT, SHARPEN_MAX, StreamOptions};

    // The reach off, so that sharpening 0 is the unsharpened blend.
    let with = |sharpen| StreamOptions {
        sharpen,
        sharpen_reach: 1,
        ..Default::default()
    };
    fewer_quads_sweep(
        "sharpen",
        [with(0), with(SHARPEN_DEFAULT), with(SHARPEN_MAX)],
    );
}

/// [`sweep`] over three option sets that only drop aspects: the same trees visible, the quads
/// only shrinking, and the second set within 3 % of the first's FLIP over the six views.
fn fewer_quads_sweep(label: &str, options: [forest_render::options::StreamOptions; 3]) {
    let s = sweep(label, options, |name, a, b| {
        assert_eq!(b.visible_trees, a.visible_trees, "{name}");
        assert!(b.quads <= a.quads, "{name}");
    });
    assert!(s.flips[1] <= s.flips[0] * 1.03, "{label}: {:?}", s.flips);
}

/// The sharpening's reach raises a narrow tree's sharpening towards the largest as it nears
/// the far span: on the six test cameras, GPU and CPU reference agree at reach 1 (off), the
/// default and the largest; the quads only shrink as the reach grows; the default shades
/// fewer fragments, nowhere more than FLIP 0.01 less accurate against the reference and
/// within 3 % over the six views.
#[test]
fn the_sharpening_reach_shades_fewer_fragments_at_the_same_accuracy() {
    use forest_render::options::{SHARPEN_REACH_DEFAULT, SHARPEN_REACH_MAX, StreamOptions};

    let with = |sharpen_reach| StreamOptions {
        sharpen_reach,
        ..Default::default()
    };
    fewer_quads_sweep(
        "reach",
        [
            with(1),
            with(SHARPEN_REACH_DEFAULT),
            with(SHARPEN_REACH_MAX),
        ],
    );
}

/// The opaque pass draws the image the blended quads alone draw (within FLIP 0.001, the
/// rounding of a blend at alpha 1 − 0.5/255, on the six test cameras and a close-up). It
/// shades its own fragments twice, so in this sparse forest, where little lies more than a
/// slab's thickness behind an opaque front, it shades a few per cent more; the benchmarks
/// report the walkthroughs.
#[test]
fn opaque_pass_draws_the_same_image() {
    let forest = common::forest(40);
    let side = forest.extent();
    let mut cams = common::cameras(side);
    cams.push((
        "close_up",
        common::camera(Vec3::new(3.0, 1.5, 3.0), Vec3::new(0.0, 1.5, 0.0), 1.0),
    ));
    let (blended, opaque) =
        opaque_pass_fragments(&common::species(), &forest, &cams, AspectBlend::Over, 0.001);
    eprintln!("all: {opaque} fragments with the opaque pass, {blended} without");
}

/// The opaque pass serves the "over" blend alone (`StreamOptions::opaque_pass`): under the
/// dither and nearest blends, whose aspects do not blend over each other, asking for it
/// changes nothing, the same fragments shaded and the same image, on the six test cameras.
#[test]
fn opaque_pass_is_off_under_the_other_blends() {
    let forest = common::forest(40);
    let cams = common::cameras(forest.extent());
    // Under the over blend the pass changes what is shaded in this scene, so equal counts
    // below mean it did not run.
    let (blended, opaque) =
        opaque_pass_fragments(&common::species(), &forest, &cams, AspectBlend::Over, 0.001);
    assert_ne!(
        blended, opaque,
        "the over blend's pass changed nothing here"
    );
    for blend in [AspectBlend::Dither, AspectBlend::Nearest] {
        let (blended, opaque) =
            opaque_pass_fragments(&common::species(), &forest, &cams, blend, 0.0);
        assert!(blended > 0, "{blend:?}: nothing drawn");
        assert_eq!(
            blended, opaque,
            "{blend:?}: fragments without and with the pass"
        );
    }
}

/// The opaque pass rejects what lies more than a slab's thickness behind a tree's opaque
/// front: in a thicket (200 trees at 4 m² each, atlases of 256 px whose leaves have opaque
/// texels), seen from inside and along the horizon, it shades at most 0.95 of the fragments
/// shaded without it (0.89 when written). The images stay within FLIP 0.01 (0.004 from
/// inside when written): where crowns interpenetrate, the trees' presorted order is wrong at
/// some pixels and the pass's depth test corrects it.
#[test]
fn opaque_pass_rejects_the_trees_behind() {
    use forest_format::generate::{GenerateParams, generate};
    let forest = generate(&GenerateParams {
        trees: 200,
        species: vec!["bush".into(), "pine".into()],
        area_per_tree: 4.0,
        seed: 5,
        ..GenerateParams::default()
    })
    .unwrap();
    let species = common::species_with(&forest_format::BakeParams {
        directions: 5,
        resolution: 256,
        min_quad: 4,
        spp: 4,
        ..forest_format::BakeParams::default()
    });
    let cams = common::cameras(forest.extent());
    let cams: Vec<_> = cams
        .into_iter()
        .filter(|(name, _)| ["inside", "horizon"].contains(name))
        .collect();
    let (blended, opaque) =
        opaque_pass_fragments(&species, &forest, &cams, AspectBlend::Over, 0.01);
    assert!(
        (opaque as f64) < 0.95 * blended as f64,
        "{opaque} fragments with the opaque pass, {blended} without"
    );
}

/// Fragments over `cams` without and with the opaque pass under aspect blend `blend`, each
/// camera's two images within FLIP `max_flip` (written on failure), counting leaving each
/// image unchanged.
fn opaque_pass_fragments(
    species: &[forest_render::SpeciesData],
    forest: &forest_format::forest::Forest,
    cams: &[(&str, forest_render::Camera)],
    blend: AspectBlend,
    max_flip: f32,
) -> (u64, u64) {
    use forest_render::fragments::{FragmentCounter, count_fragments};
    use forest_render::options::StreamOptions;

    let ctx = common::ctx();
    let scene = GpuScene::new(&ctx, species, forest).unwrap();
    let size = (160, 120);
    let opts = RendererOptions {
        viewport: size,
        min_epsilon: 1.0,
        background: Background::Transparent,
        ..Default::default()
    };
    let mut stream = QuadStream::new(&ctx.device, scene, &opts).unwrap();
    let target = Target::new(&ctx, size.0, size.1);
    let counter = FragmentCounter::new(&ctx.device, size.0, size.1, false).unwrap();
    let mut frame = |opaque_first: bool, cam: &forest_render::Camera| {
        stream
            .set_options(StreamOptions {
                opaque_first,
                blend,
                ..Default::default()
            })
            .unwrap();
        stream.render_frame(&ctx, cam, &target).unwrap();
        let image = target.read(&ctx);
        let counts = count_fragments(
            &ctx,
            &counter,
            &mut stream,
            QuadStream::set_fragment_counter,
            |s| s.render_frame(&ctx, cam, &target),
        )
        .unwrap();
        assert_eq!(ctx.take_errors(), Vec::<String>::new());
        assert!(image == target.read(&ctx), "counting changed the image");
        (image, counts.summary())
    };
    let (mut blended_all, mut opaque_all) = (0u64, 0u64);
    for (name, cam) in cams {
        let (blended, b) = frame(false, cam);
        let (opaque, o) = frame(true, cam);
        let m = forest_metrics::compare(&blended, &opaque).unwrap();
        eprintln!(
            "{name}: fragments {} blended, {} with the opaque pass; FLIP {:.5}",
            b.fragments, o.fragments, m.flip_mean
        );
        if m.flip_mean > max_flip {
            let out =
                common::failure_images(&format!("opaque-{blend:?}-{name}"), &blended, &opaque);
            panic!(
                "{name}: opaque pass against blended FLIP {} (images in {})",
                m.flip_mean,
                out.display()
            );
        }
        blended_all += b.fragments;
        opaque_all += o.fragments;
    }
    (blended_all, opaque_all)
}
