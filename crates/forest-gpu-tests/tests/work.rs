//! Work counters against analytic counts: a rectangle of known size shades its pixels and no
//! more; the quad stream's counts follow from its quads and its recorded passes.

mod common;

use forest_render::ForestView;
use forest_render::options::{Background, RendererOptions};
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

#[test]
fn the_stream_counts_its_work() {
    let ctx = common::ctx();
    let forest = common::forest(6);
    let (mut stream, target) = common::transparent_stream(&ctx, &common::species(), &forest, 2.0);
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
