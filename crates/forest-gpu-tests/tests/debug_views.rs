//! The viewer's debug views of the draw pass: quads coloured by level, by sampling direction
//! (blend weights), and outlined (wireframe). Colours are checked against the CPU mirrors of
//! the palette and the counts of the stream.

mod common;

use forest_format::shading::srgb_decode_table;
use forest_render::ForestView;
use forest_render::options::{
    Background, DebugView, LEVEL_COLOURS, RendererOptions, direction_colour,
};
use forest_render::target::Target;
use forest_render::{Camera, GpuScene, QuadStream};
use glam::Vec3;

const SIZE: u32 = 128;

fn stream(refine: bool) -> (forest_render::GpuContext, QuadStream, Target) {
    let ctx = common::ctx();
    let scene = GpuScene::with_format(
        &ctx,
        &common::species(),
        &common::one_tree(0, 0.0),
        forest_render::ColourFormat::Rgba8,
    )
    .unwrap();
    let opts = RendererOptions {
        viewport: (SIZE, SIZE),
        min_epsilon: 0.5,
        background: Background::Transparent,
        refine,
        ..Default::default()
    };
    let s = QuadStream::new(&ctx.device, scene, &opts).unwrap();
    let t = Target::new(&ctx, SIZE, SIZE);
    (ctx, s, t)
}

fn render(
    ctx: &forest_render::GpuContext,
    s: &mut QuadStream,
    t: &Target,
    cam: &Camera,
    view: DebugView,
) -> image::RgbaImage {
    s.set_debug_view(view);
    s.render_frame(ctx, cam, t).unwrap();
    let img = t.read(ctx);
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    img
}

/// Linear, un-premultiplied colours of the pixels at least 90 % covered.
fn covered_colours(img: &image::RgbaImage) -> Vec<[f32; 3]> {
    let table = srgb_decode_table();
    img.pixels()
        .filter(|p| p[3] >= 230)
        .map(|p| {
            let a = f32::from(p[3]) / 255.0;
            [0, 1, 2].map(|c| table[p[c] as usize] / a)
        })
        .collect()
}

fn near(a: [f32; 3], b: [f32; 3], tol: f32) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
}

fn close_camera(epsilon: f32) -> Camera {
    let sphere = common::atlases()[0].manifest.bounding_sphere;
    Camera {
        eye: sphere.center + Vec3::new(0.3, 0.2, 1.0).normalize() * sphere.radius * 2.2,
        target: sphere.center,
        fov_y_deg: 60.0,
        near: 0.05,
        far: 100.0,
        viewport: (SIZE, SIZE),
        epsilon,
    }
}

#[test]
fn levels_view_colours_impostors_as_level_zero() {
    let (ctx, mut s, t) = stream(false);
    let img = render(&ctx, &mut s, &t, &close_camera(0.5), DebugView::Levels);
    let colours = covered_colours(&img);
    assert!(colours.len() > 200, "only {} covered pixels", colours.len());
    let off: Vec<_> = colours
        .iter()
        .filter(|c| !near(**c, LEVEL_COLOURS[0], 0.03))
        .collect();
    assert!(
        off.is_empty(),
        "{} of {} pixels are not level 0's colour, e.g. {:?}",
        off.len(),
        colours.len(),
        off.first()
    );
}

#[test]
fn levels_view_shows_exactly_the_levels_in_the_stream() {
    let (ctx, mut s, t) = stream(true);
    // One aspect per tree, so that no pixel mixes two levels' colours.
    s.set_options(forest_render::options::StreamOptions {
        blend: forest_render::options::AspectBlend::Nearest,
        ..Default::default()
    })
    .unwrap();
    // ε large enough that the tree is a mix of levels.
    let img = render(&ctx, &mut s, &t, &close_camera(24.0), DebugView::Levels);
    let stats = s.read_stats(&ctx);
    let colours = covered_colours(&img);
    let present: Vec<usize> = (0..LEVEL_COLOURS.len())
        .filter(|&l| {
            colours
                .iter()
                .filter(|c| near(**c, LEVEL_COLOURS[l], 0.03))
                .count()
                >= 20
        })
        .collect();
    let in_stream: Vec<usize> = (0..stats.per_level.len())
        .filter(|&l| stats.per_level[l] > 0)
        .collect();
    assert!(
        present.len() >= 2,
        "levels seen {present:?}, stream {:?}",
        stats.per_level
    );
    for l in &present {
        assert!(
            in_stream.contains(l),
            "level {l}'s colour is drawn but the stream has no level-{l} quads: {:?}",
            stats.per_level
        );
    }
}

#[test]
fn weights_view_shows_the_one_direction_seen_exactly_along() {
    let (ctx, mut s, t) = stream(false);
    let atlas = &common::atlases()[0];
    let sphere = atlas.manifest.bounding_sphere;
    let mut checked = 0;
    for (d, frame) in atlas.manifest.directions.iter().enumerate() {
        if frame.dir.y.abs() > 0.99 {
            continue; // the zenith: a look-at camera has no up vector there
        }
        let cam = common::along(sphere.center, sphere.radius, frame.dir, SIZE, 0.5);
        let colours = covered_colours(&render(&ctx, &mut s, &t, &cam, DebugView::Weights));
        assert!(
            colours.len() > 100,
            "direction {d}: {} covered pixels",
            colours.len()
        );
        let want = direction_colour(d as u32);
        let off = colours.iter().filter(|c| !near(**c, want, 0.03)).count();
        assert_eq!(
            off, 0,
            "direction {d}: {off} pixels not in its colour {want:?}"
        );
        checked += 1;
    }
    assert!(checked >= 3);
}

#[test]
fn wireframe_view_outlines_quads_over_the_textured_image() {
    let (ctx, mut s, t) = stream(true);
    let cam = close_camera(2.0);
    let plain = render(&ctx, &mut s, &t, &cam, DebugView::Off);
    let wire = render(&ctx, &mut s, &t, &cam, DebugView::Wireframe);
    let line = |p: &image::Rgba<u8>| p[0] > 240 && p[1] > 230 && p[2] < 140 && p[3] == 255;
    let lines = wire.pixels().filter(|p| line(p)).count();
    let plain_lines = plain.pixels().filter(|p| line(p)).count();
    let same = plain
        .pixels()
        .zip(wire.pixels())
        .filter(|(a, b)| a == b)
        .count();
    let n = (SIZE * SIZE) as usize;
    assert!(lines > n / 50, "{lines} outline pixels of {n}");
    assert!(
        lines > 10 * plain_lines.max(1),
        "{lines} vs {plain_lines} without outlines"
    );
    assert!(
        same > n / 2,
        "only {same} of {n} pixels unchanged off the outlines"
    );
    // Switching back restores the plain image exactly.
    assert_eq!(render(&ctx, &mut s, &t, &cam, DebugView::Off), plain);
}
