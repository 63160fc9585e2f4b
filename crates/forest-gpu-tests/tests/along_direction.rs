//! Viewed exactly along a sampling direction from far away (nearly orthographic), with a tiny
//! ε, the quad stream reproduces the bake's own slab images (front slab over back slab), each
//! texel lit on the CPU by the shading model under the stream's light. The opacity volume is
//! left empty here (no self-shadowing): the slab texels do not record where along the ray
//! they lie, and the march is checked on its own (tests/opacity.rs, tests/lighting.rs).

mod common;

use forest_format::shading::{srgb_decode_table, srgb_encode};
use forest_render::ForestView;
use forest_render::options::{Background, RendererOptions};
use forest_render::target::Target;
use forest_render::{GpuScene, QuadStream};

#[test]
fn a_tree_seen_along_a_sampling_direction_matches_its_slab_images() {
    let ctx = common::ctx();
    let mut species = common::species();
    for s in &mut species {
        s.opacity = forest_format::opacity::OpacityVolume::empty(s.opacity.resolution);
    }
    let atlas = &species[0].atlas; // bush, 64 px, 5 directions, 2 slabs
    let forest = common::one_tree(0, 0.0);
    let res = atlas.manifest.params.resolution;
    let scene =
        GpuScene::with_format(&ctx, &species, &forest, forest_render::ColourFormat::Rgba8).unwrap();
    let opts = RendererOptions {
        viewport: (res, res),
        min_epsilon: 0.5,
        background: Background::Transparent,
        ..Default::default()
    };
    let mut stream = QuadStream::new(&ctx.device, scene, &opts).unwrap();
    let target = Target::new(&ctx, res, res);
    let sphere = atlas.manifest.bounding_sphere;
    let table = srgb_decode_table();
    let layers = &species[0].layers;
    let surface = &species[0].surface;
    let light = forest_format::shading::Lighting::default();
    // Texel `i` of layer `l` lit under `light` in the direction's frame `f`: premultiplied,
    // linear RGB and alpha.
    let lit = |l: u32, i: usize, f: &forest_format::slab::DirectionFrame| {
        let (c, g) = (layers.layer(l), surface.layer(l));
        let a = f32::from(c[i + 3]) / 255.0;
        if a == 0.0 {
            return [0.0; 4];
        }
        let g = [0, 1, 2, 3].map(|k| f32::from(g[i + k]) / 255.0 / a);
        let local = forest_format::shading::hemi_oct_decode(glam::Vec2::new(g[0], g[1]));
        let n = (f.right * local.x + f.up * local.y + f.dir * local.z).normalize();
        let albedo = glam::Vec3::new(
            table[c[i] as usize],
            table[c[i + 1] as usize],
            table[c[i + 2] as usize],
        ) / a;
        let r = light.shade(albedo, n, 1.0, g[2].min(1.0), g[3].min(1.0)) * a;
        [r.x, r.y, r.z, a]
    };
    let mut checked = 0;
    for (d, frame) in atlas.manifest.directions.iter().enumerate() {
        if frame.dir.y.abs() > 0.99 {
            continue; // the zenith and nadir: a look-at camera has no up vector there
        }
        let cam = common::along(sphere.center, sphere.radius, frame.dir, res, 0.5);
        stream.render_frame(&ctx, &cam, &target).unwrap();
        let img = target.read(&ctx);
        assert_eq!(ctx.take_errors(), Vec::<String>::new());
        // Expected: front slab over back slab, in linear premultiplied space.
        let slabs = atlas.manifest.params.slabs;
        let expected = image::RgbaImage::from_fn(res, res, |x, y| {
            let i = ((y * res + x) * 4) as usize;
            let front = lit(d as u32 * slabs, i, frame);
            let back = lit(d as u32 * slabs + 1, i, frame);
            let fa = front[3];
            let mut px = [0u8; 4];
            for c in 0..3 {
                let v = front[c] + back[c] * (1.0 - fa);
                px[c] = (srgb_encode(v) * 255.0).round() as u8;
            }
            let a = fa + back[3] * (1.0 - fa);
            px[3] = (a * 255.0).round() as u8;
            image::Rgba(px)
        });
        let m = forest_metrics::compare(&expected, &img).unwrap();
        let out = common::root().join("target/test-output");
        std::fs::create_dir_all(&out).unwrap();
        if m.flip_mean > 0.05 || m.coverage_iou.unwrap_or(0.0) < 0.9 {
            expected
                .save(out.join(format!("along-{d}-expected.png")))
                .unwrap();
            img.save(out.join(format!("along-{d}-actual.png"))).unwrap();
        }
        assert!(
            m.flip_mean <= 0.05,
            "direction {d}: FLIP {:.4} ({m:?})",
            m.flip_mean
        );
        assert!(m.coverage_iou.unwrap() >= 0.9, "direction {d}: {m:?}");
        checked += 1;
    }
    // 4 above the horizon and 4 below it: every direction but the zenith and the nadir.
    assert_eq!(checked, 8, "every direction but the zenith and the nadir");
}
