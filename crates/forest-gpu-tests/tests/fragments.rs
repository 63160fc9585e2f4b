//! Exact fragment counts (`forest_render::fragments`) against analytic scenes: an opaque
//! rectangle of known size counts one fragment per pixel it covers and its 2×2 quads; where
//! two rectangles overlap each pixel counts two, and the one behind an opaque one is hidden.
//! Then every method's counted frame: the same image as the uncounted one, covered pixels
//! equal to the image's, and counts bounded by the pipeline statistics.

mod common;

use forest_baselines::geometry::{GeometryRenderer, Lods, MeshMethod, Stochastic};
use forest_baselines::hybrid::{Hybrid, Near};
use forest_baselines::methods::{ForestRenderer, Method};
use forest_render::ForestView;
use forest_render::fragments::{FragmentCounter, FragmentCounts, PixelCounts};
use forest_render::options::{Background, RendererOptions};
use forest_render::target::{TARGET_FORMAT, Target};
use forest_render::work;
use forest_render::{GpuContext, GpuScene, QuadStream};
use glam::Vec3;

const SIZE: (u32, u32) = (64, 32);

/// Rectangle 0 covers pixels x 8..40, y 4..20 at depth 0.5; rectangle 1 covers x 24..56,
/// y 12..28 at depth `DEPTH_1`, of alpha `ALPHA_1`. Each is a triangle strip from its
/// top-left corner; instance i draws rectangle i. The fragment stage calls the counting hooks
/// as every tree fragment stage does, and as a depth-writing stage when `WRITES_DEPTH`.
const RECTS_WGSL: &str = "
struct Out {
    @builtin(position) pos: vec4<f32>,
    @location(0) @interpolate(flat) alpha: f32,
}
@vertex fn vs(@builtin(vertex_index) i: u32, @builtin(instance_index) r: u32) -> Out {
    let x = select(-0.75, 0.25, (i & 1u) == 1u) + 0.5 * f32(r);
    let y = select(0.75, -0.25, (i & 2u) == 2u) - 0.5 * f32(r);
    return Out(vec4<f32>(x, y, select(0.5, DEPTH_1, r == 1u), 1.0), select(1.0, ALPHA_1, r == 1u));
}
@fragment fn fs(in: Out) -> @location(0) vec4<f32> {
    count_enter(in.pos);
    count_shown(in.pos, in.alpha);
    if (WRITES_DEPTH) { count_depth(in.pos); }
    return vec4<f32>(in.alpha);
}
";

const RECT_0: [i32; 4] = [8, 4, 40, 20];
const RECT_1: [i32; 4] = [24, 12, 56, 28];

fn in_rect(r: [i32; 4], x: i32, y: i32) -> bool {
    (r[0]..r[2]).contains(&x) && (r[1]..r[3]).contains(&y)
}

/// Count `instances` of [`RECTS_WGSL`]'s rectangles, rectangle 1 of alpha `alpha_1`, drawn
/// with no depth test in instance order.
fn count_rectangles(ctx: &GpuContext, instances: u32, alpha_1: f32) -> FragmentCounts {
    counted_rectangles(ctx, instances, alpha_1, None).1
}

/// [`count_rectangles`], with the counter that holds the counts.
/// With `depth_1`, rectangle 1 lies at that depth and both write depth (0.25 otherwise, no
/// depth written).
fn counted_rectangles(
    ctx: &GpuContext,
    instances: u32,
    alpha_1: f32,
    depth_1: Option<f32>,
) -> (FragmentCounter, FragmentCounts) {
    let device = &ctx.device;
    let source = format!(
        "const ALPHA_1: f32 = {alpha_1:?};\nconst DEPTH_1: f32 = {:?};\nconst WRITES_DEPTH: bool = {};\n{}{RECTS_WGSL}",
        depth_1.unwrap_or(0.25),
        depth_1.is_some(),
        forest_render::shaders::COUNT_ON_WGSL
    );
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("counted rectangles"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let empty = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: None,
        entries: &[],
    });
    let counts_layout = forest_render::fragments::bind_layout(device);
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: None,
        bind_group_layouts: &[Some(&empty), Some(&counts_layout)],
        immediate_size: 0,
    });
    let blend = Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING);
    let pipeline = common::strip_pipeline(ctx, &module, &layout, blend);
    let empty_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &empty,
        entries: &[],
    });
    let target = Target::new(ctx, SIZE.0, SIZE.1);
    let counter = FragmentCounter::new(device, SIZE.0, SIZE.1, false).unwrap();
    let counts = counter
        .count_frame(ctx, || {
            let mut enc = device.create_command_encoder(&Default::default());
            {
                let mut pass = common::cleared_pass(&mut enc, &target.colour_view);
                pass.set_pipeline(&pipeline);
                pass.set_bind_group(0, &empty_group, &[]);
                pass.set_bind_group(1, counter.bind_group(), &[]);
                pass.draw(0..4, 0..instances);
            }
            ctx.queue.submit([enc.finish()]);
            Ok::<(), ()>(())
        })
        .unwrap();
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    (counter, counts)
}

fn at(c: &FragmentCounts, x: i32, y: i32) -> PixelCounts {
    c.pixels[(y as u32 * c.width + x as u32) as usize]
}

#[test]
fn an_opaque_rectangle_counts_its_pixels_and_quads() {
    let ctx = common::ctx();
    let c = count_rectangles(&ctx, 1, 1.0);
    assert_eq!((c.width, c.height), SIZE);
    for y in 0..SIZE.1 as i32 {
        for x in 0..SIZE.0 as i32 {
            let n = u32::from(in_rect(RECT_0, x, y));
            let p = at(&c, x, y);
            assert_eq!(
                (p.invocations, p.shown, p.hidden),
                (n, n, 0),
                "pixel ({x}, {y}): helper lanes must not count"
            );
        }
    }
    let size = (SIZE.0 as i32, SIZE.1 as i32);
    let lanes: u64 = c.pixels.iter().map(|p| u64::from(p.quad_lanes)).sum();
    // The rectangle is 2-aligned, but each of its triangles shades the 2×2 quads it touches:
    // the ones along the diagonal twice.
    let quads = common::rectangle_shaded_in_blocks(RECT_0, size, 2);
    assert_eq!(lanes, quads);
    assert!(quads > 32 * 16, "the diagonal's quads are shaded twice");
    let s = c.summary();
    assert_eq!(s.covered_pixels, 32 * 16);
    assert_eq!(s.fragments, 32 * 16);
    assert_eq!(
        (s.per_covered_mean, s.per_covered_median, s.per_covered_p95),
        (1.0, 1, 1)
    );
    assert_eq!(s.quad_lanes_per_covered, quads as f64 / (32.0 * 16.0));
    assert_eq!((s.transparent_share, s.hidden_share), (0.0, 0.0));
}

#[test]
fn overlapping_rectangles_count_two_and_hide_what_is_behind() {
    let ctx = common::ctx();
    // Rectangle 1 is nearer: opaque, it hides rectangle 0 where they overlap; of alpha 0.5
    // it hides nothing; of alpha below 0.5/255 it shows nothing.
    for (alpha, hides, shows) in [(1.0, true, true), (0.5, false, true), (0.001, false, false)] {
        let c = count_rectangles(&ctx, 2, alpha);
        for y in 0..SIZE.1 as i32 {
            for x in 0..SIZE.0 as i32 {
                let (a, b) = (in_rect(RECT_0, x, y), in_rect(RECT_1, x, y));
                let want = PixelCounts {
                    invocations: u32::from(a) + u32::from(b),
                    quad_lanes: at(&c, x, y).quad_lanes,
                    shown: u32::from(a) + u32::from(b && shows),
                    hidden: u32::from(a && b && hides),
                };
                assert_eq!(at(&c, x, y), want, "alpha {alpha}, pixel ({x}, {y})");
            }
        }
        let s = c.summary();
        let (area, overlap) = (32 * 16, 16 * 8);
        let covered = if shows { 2 * area - overlap } else { area };
        assert_eq!(s.covered_pixels, covered, "alpha {alpha}");
        assert_eq!(s.fragments, 2 * area, "alpha {alpha}");
        assert_eq!(s.per_covered_median, 1);
        // A quarter of rectangle 0 and a seventh of the union count two.
        assert_eq!(s.per_covered_p95, 2);
        let hidden = if hides { overlap } else { 0 };
        assert_eq!(s.hidden_share, hidden as f64 / (2 * area) as f64);
        let transparent = if shows { 0 } else { area };
        assert_eq!(s.transparent_share, transparent as f64 / (2 * area) as f64);
    }
}

#[test]
fn a_fragment_behind_written_depth_is_not_shaded() {
    // Depth-writing stages (the geometry's) test depth late while they count: the counts
    // emulate the early test. Rectangle 1, drawn second, lies behind rectangle 0 at 0.75, or
    // in front at 0.25.
    let ctx = common::ctx();
    for (depth, rejected) in [(0.75, true), (0.25, false)] {
        let (_, c) = counted_rectangles(&ctx, 2, 1.0, Some(depth));
        for y in 0..SIZE.1 as i32 {
            for x in 0..SIZE.0 as i32 {
                let (a, b) = (in_rect(RECT_0, x, y), in_rect(RECT_1, x, y));
                let shaded_b = b && !(a && rejected);
                let p = at(&c, x, y);
                let want = (
                    u32::from(a) + u32::from(shaded_b),
                    u32::from(a) + u32::from(shaded_b),
                    u32::from(a && b && !rejected),
                );
                assert_eq!(
                    (p.invocations, p.shown, p.hidden),
                    want,
                    "depth {depth}, pixel ({x}, {y})"
                );
            }
        }
    }
}

/// sRGB bytes of a linear colour, as an sRGB target stores it.
fn srgb(c: [f32; 3]) -> [u8; 3] {
    c.map(|v| (forest_format::shading::srgb_encode(v) * 255.0).round() as u8)
}

#[test]
fn the_overdraw_view_shows_each_pixels_band() {
    use forest_render::fragments::{OVERDRAW_COLOURS, OverdrawPass, band, legend_side};
    let ctx = common::ctx();
    let (counter, counts) = counted_rectangles(&ctx, 2, 0.5, None);
    let view = OverdrawPass::new(&ctx.device, TARGET_FORMAT);
    let draw = |legend: bool| {
        let binding = view.bind(&ctx.device, &counter, legend);
        let target = Target::new(&ctx, SIZE.0, SIZE.1);
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        view.record(
            &mut common::cleared_pass(&mut enc, &target.colour_view),
            &binding,
        );
        ctx.queue.submit([enc.finish()]);
        let img = target.read(&ctx);
        assert_eq!(ctx.take_errors(), Vec::<String>::new());
        img
    };
    let plain = draw(false);
    for (x, y, p) in plain.enumerate_pixels() {
        let n = at(&counts, x as i32, y as i32).invocations;
        let want = srgb(OVERDRAW_COLOURS[band(n)]);
        let got = [p[0], p[1], p[2]];
        assert!(
            got.iter().zip(want).all(|(a, b)| a.abs_diff(b) <= 1) && p[3] == 255,
            "pixel ({x}, {y}), {n} fragments: {got:?}, want {want:?}"
        );
    }
    // The legend: swatch b's top row in band b's colour along the bottom edge; the rest
    // of the image as without it.
    let legend = draw(true);
    let s = legend_side(SIZE.0);
    let top = SIZE.1 - 2 * s;
    for (x, y, p) in legend.enumerate_pixels() {
        let swatch = x < 9 * s && y >= top;
        if !swatch {
            assert_eq!(p, plain.get_pixel(x, y), "({x}, {y}) outside the legend");
        } else if y == top && x % s != s - 1 {
            let want = srgb(OVERDRAW_COLOURS[(x / s) as usize]);
            assert!(
                [p[0], p[1], p[2]]
                    .iter()
                    .zip(want)
                    .all(|(a, b)| a.abs_diff(b) <= 1),
                "legend ({x}, {y}): {p:?}, want {want:?}"
            );
        }
    }
}

fn renderer(ctx: &GpuContext, reverse_z: bool) -> (ForestRenderer, forest_render::Camera) {
    let forest = common::forest(40);
    let scene = GpuScene::new(ctx, &common::species(), &forest).unwrap();
    let opts = RendererOptions {
        format: TARGET_FORMAT,
        viewport: (160, 120),
        min_epsilon: 2.0,
        background: Background::Transparent,
        reverse_z,
        ..Default::default()
    };
    let geometry = GeometryRenderer::with_targets(ctx, common::prepared(), &forest, &opts).unwrap();
    let mut r = ForestRenderer::new(
        QuadStream::new(&ctx.device, scene, &opts).unwrap(),
        Some(geometry),
    );
    r.set_pipeline_statistics(true);
    let side = forest.extent();
    let cam = common::camera(Vec3::new(0.0, 2.0, side * 0.8), Vec3::ZERO, 2.0);
    (r, cam)
}

fn methods() -> [Method; 7] {
    [
        Method::Quads,
        Method::Impostor,
        Method::Mesh(MeshMethod::Full { depth_sort: true }),
        Method::Mesh(MeshMethod::Stochastic(Stochastic::default())),
        Method::Mesh(MeshMethod::Lods(Lods::default())),
        Method::Mesh(MeshMethod::Lods(Lods {
            distances: [0.5, 1.0, 1.5],
        })),
        Method::Hybrid(Hybrid {
            near: Near::Metres(3.0),
            ..Default::default()
        }),
    ]
}

#[test]
fn every_method_counts_its_frame_without_changing_it() {
    let ctx = common::ctx();
    for reverse_z in [false, true] {
        let (mut r, cam) = renderer(&ctx, reverse_z);
        let target = Target::new(&ctx, 160, 120);
        for method in methods() {
            let name = format!("{} {method:?} reverse_z {reverse_z}", method.name());
            r.set_method(&ctx, method).unwrap();
            r.render_frame(&ctx, &cam, &target).unwrap();
            let plain = target.read(&ctx);
            let stats = r.read_stats(&ctx);
            let counts = r.count_fragments(&ctx, &cam, &target).unwrap();
            let counted = target.read(&ctx);
            assert_eq!(ctx.take_errors(), Vec::<String>::new(), "{name}");
            assert!(plain == counted, "{name}: counting changed the image");
            // A pixel is covered when a fragment showed there: exactly the pixels the
            // image's alpha covers (an 8-bit target rounds a lesser alpha to 0).
            let image_covered = plain.pixels().filter(|p| p[3] > 0).count() as u64;
            let s = counts.summary();
            assert!(image_covered > 200, "{name}: trees in view");
            assert_eq!(s.covered_pixels, image_covered, "{name}");
            assert!(s.per_covered_mean >= 1.0, "{name}: {s:?}");
            assert!(
                s.quad_lanes_per_covered >= s.per_covered_mean,
                "{name}: {s:?}"
            );
            for p in &counts.pixels {
                assert!(
                    p.shown <= p.invocations && p.hidden <= p.shown,
                    "{name}: {p:?}"
                );
                assert_eq!(p.quad_lanes % 4, 0, "{name}: {p:?}");
            }
            // Lavapipe's statistics count whole stamps, helpers and all: never fewer.
            if let Some(p) = stats.work.passes {
                let stamps = p[work::DRAW as usize].fragment_invocations;
                assert!(s.fragments <= stamps, "{name}: {} > {stamps}", s.fragments);
            }
        }
    }
}

/// Leaf cards cut to their texture's visible quadrilateral (`geometry::Cards::Cut`, the
/// default) against whole cards, judged against the 4×4 supersampled reference of whole
/// cards, on the six test cameras and a close-up, for every method that draws the models: the
/// cut shades fewer fragments, counted exactly, and is as accurate (mean FLIP over the views
/// no higher; no view more than 0.01 worse). The two differ where cards are under about 8
/// pixels across, where the cut trims the coverage that coarse mips spread past the leaves
/// (closer to the reference, which reads the finest level), and in the per-vertex
/// self-shadowing, sampled at the cut's new corners.
#[test]
fn cut_cards_shade_fewer_fragments_at_the_same_accuracy() {
    use forest_baselines::geometry::{Cards, downsample};
    let ctx = common::ctx();
    let forest = common::forest(40);
    let side = forest.extent();
    let whole_models = common::prepared_with(common::atlases(), Cards::Whole);
    let renderer = |cards: Cards| {
        common::forest_renderer(
            &ctx,
            &common::species(),
            &common::prepared_with(common::atlases(), cards),
            &forest,
            (160, 120),
            Background::Transparent,
            Default::default(),
        )
    };
    let (mut cut, mut whole) = (renderer(Cards::Cut), renderer(Cards::Whole));
    let mut reference = GeometryRenderer::new(
        &ctx,
        &whole_models,
        &forest,
        TARGET_FORMAT,
        Background::Transparent,
    )
    .unwrap();
    reference.set_method(&ctx, MeshMethod::Reference).unwrap();
    let target = Target::new(&ctx, 160, 120);
    let big = Target::new(&ctx, 640, 480);
    let mut cams = common::cameras(side);
    cams.push((
        "close_up",
        common::camera(Vec3::new(2.0, 1.0, 2.0), Vec3::new(0.0, 1.2, 0.0), 2.0),
    ));
    let methods = [
        Method::Mesh(MeshMethod::Full { depth_sort: true }),
        Method::Mesh(MeshMethod::Lods(Lods::default())),
        Method::Hybrid(Hybrid {
            near: Near::Metres(side),
            ..Default::default()
        }),
    ];
    let (mut fragments, mut flip) = ([0u64; 2], [0f64; 2]);
    for (view, cam) in &cams {
        let mut big_cam = *cam;
        big_cam.viewport = (640, 480);
        reference.render_frame(&ctx, &big_cam, &big).unwrap();
        let truth = downsample(&big.read(&ctx), 4);
        for method in methods {
            let name = format!("{} {view}", method.name());
            let frame = |r: &mut ForestRenderer| {
                r.set_method(&ctx, method).unwrap();
                let counts = r.count_fragments(&ctx, cam, &target).unwrap();
                assert_eq!(ctx.take_errors(), Vec::<String>::new(), "{name}");
                let image = target.read(&ctx);
                let m = forest_metrics::compare(&truth, &image).unwrap();
                (image, counts.summary().fragments, f64::from(m.flip_mean))
            };
            let (a, fa, ea) = frame(&mut whole);
            let (b, fb, eb) = frame(&mut cut);
            eprintln!("{name}: fragments {fa} whole, {fb} cut; FLIP {ea:.4} whole, {eb:.4} cut");
            if eb > ea + 0.01 {
                let out = common::failure_images(&format!("cards-{view}"), &a, &b);
                panic!(
                    "{name}: FLIP {eb} cut against {ea} whole (images in {})",
                    out.display()
                );
            }
            assert!(fb <= fa, "{name}: {fb} fragments cut, {fa} whole");
            fragments[0] += fa;
            fragments[1] += fb;
            flip[0] += ea;
            flip[1] += eb;
        }
    }
    eprintln!("fragments {fragments:?}, summed FLIP {flip:?} (whole, cut)");
    assert!(flip[1] <= flip[0], "summed FLIP {flip:?} (whole, cut)");
    assert!(
        (fragments[1] as f64) < 0.9 * fragments[0] as f64,
        "cut cards shade {} fragments against {}",
        fragments[1],
        fragments[0]
    );
}

/// Each tree's triangles drawn in the presorted order of its view direction
/// (`geometry::draw_orders`, on with depth sorting) against the model's own order: the same
/// image, fewer fragments shaded. One pine, rotated so that its bins are not the world's,
/// seen at 2.5 crown radii from 8 azimuths, level with its centre and from 50° above and
/// below, by full geometry and by the LODs at LOD 0. A vertex stage that picked its bin by
/// another convention than `order_bin`'s would draw back to front from some of them.
#[test]
fn presorted_triangles_shade_fewer_fragments_for_the_same_image() {
    let ctx = common::ctx();
    let forest = common::one_tree(1, 0.7);
    let sphere = common::atlases()[1].manifest.bounding_sphere;
    let mut r = common::forest_renderer(
        &ctx,
        &common::species(),
        common::prepared(),
        &forest,
        (160, 120),
        Background::Transparent,
        Default::default(),
    );
    let target = Target::new(&ctx, 160, 120);
    let mut totals = [0u64; 2];
    for k in 0..24 {
        let azimuth = (k % 8) as f32 * std::f32::consts::FRAC_PI_4 + 0.2;
        let elevation = [-50f32, 0.0, 50.0][k / 8].to_radians();
        let dir = Vec3::new(
            elevation.cos() * azimuth.cos(),
            elevation.sin(),
            elevation.cos() * azimuth.sin(),
        );
        let cam = common::camera(
            sphere.center + dir * 2.5 * sphere.radius,
            sphere.center,
            2.0,
        );
        for (unsorted, sorted) in [
            (
                MeshMethod::Full { depth_sort: false },
                MeshMethod::Full { depth_sort: true },
            ),
            (
                MeshMethod::Stochastic(Stochastic {
                    d0: 1e6,
                    ..Default::default()
                }),
                MeshMethod::Lods(Lods {
                    distances: [1e5, 2e5, 3e5],
                }),
            ),
        ] {
            let mut frame = |method: MeshMethod| {
                r.set_method(&ctx, Method::Mesh(method)).unwrap();
                let counts = r.count_fragments(&ctx, &cam, &target).unwrap();
                assert_eq!(ctx.take_errors(), Vec::<String>::new(), "{method:?}");
                (target.read(&ctx), counts.summary().fragments)
            };
            let (a, fa) = frame(unsorted);
            let (b, fb) = frame(sorted);
            let name = format!("{sorted:?} view {k}");
            assert!(
                a.pixels().filter(|p| p[3] > 0).count() > 300,
                "{name}: tree in view"
            );
            let flip = forest_metrics::compare(&a, &b).unwrap().flip_mean;
            if flip > 0.001 {
                let out = common::failure_images(&format!("presorted-{k}"), &a, &b);
                panic!(
                    "{name}: FLIP {flip} against the model's order (images in {})",
                    out.display()
                );
            }
            assert!(
                fb < fa,
                "{name}: {fb} fragments presorted, {fa} in the model's order"
            );
            totals[0] += fa;
            totals[1] += fb;
        }
    }
    eprintln!(
        "fragments in the model's order {}, presorted {}",
        totals[0], totals[1]
    );
    assert!(
        (totals[1] as f64) < 0.85 * totals[0] as f64,
        "presorted {} fragments against {}",
        totals[1],
        totals[0]
    );
}

#[test]
fn a_counter_too_large_for_the_device_is_refused_before_allocating() {
    let ctx = common::ctx();
    let err = FragmentCounter::new(&ctx.device, 1 << 16, 1 << 16, false)
        .err()
        .expect("a 65536² counter exceeds every device's storage binding");
    assert!(err.to_string().contains("fragment counts"), "{err}");
    assert!(FragmentCounter::new(&ctx.device, 0, 4, false).is_err());
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
}
