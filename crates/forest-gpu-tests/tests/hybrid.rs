//! The hybrid method: at a switch distance of 0 it is the quad stream (at the hybrid's aspect
//! sharpening) and at infinity the full geometry, byte for byte; a tree in the transition
//! band is drawn by both forms through complementary masks (every pixel from exactly one of them);
//! the GPU's classification equals the CPU mirror; a frame writes only the camera; empty,
//! single-tree and 1M-tree forests render without validation errors.

mod common;

use forest_baselines::geometry::{MeshMethod, PreparedGeometry};
use forest_baselines::hybrid::{HYBRID_SHARPEN_DEFAULT, Hybrid, Near};
use forest_baselines::methods::{ForestRenderer, Method};
use forest_format::atlas::HybridSwitch;
use forest_format::forest::Forest;
use forest_render::ForestView;
use forest_render::extend as hybrid;
use forest_render::options::{Atmosphere, Background, StreamOptions};
use forest_render::target::Target;
use forest_render::{Camera, GpuContext, SpeciesData, reference};
use glam::Vec3;

const WEIGHT_ONE: u32 = forest_render::gpu_types::WEIGHT_ONE;

fn renderer(
    ctx: &GpuContext,
    forest: &Forest,
    viewport: (u32, u32),
    background: Background,
) -> ForestRenderer {
    renderer_in(ctx, forest, viewport, background, Atmosphere::CLEAR)
}

/// Both forms over `background` in `atmosphere`.
fn renderer_in(
    ctx: &GpuContext,
    forest: &Forest,
    viewport: (u32, u32),
    background: Background,
    atmosphere: Atmosphere,
) -> ForestRenderer {
    let species = common::species();
    common::forest_renderer(
        ctx,
        &species,
        common::prepared(),
        forest,
        viewport,
        background,
        atmosphere,
    )
}

fn frame(
    ctx: &GpuContext,
    r: &mut ForestRenderer,
    method: Method,
    cam: &Camera,
) -> image::RgbaImage {
    r.set_method(ctx, method).unwrap();
    let target = Target::new(ctx, cam.viewport.0, cam.viewport.1);
    r.render_frame(ctx, cam, &target).unwrap();
    target.read(ctx)
}

fn hybrid_at(near: f32) -> Method {
    Method::Hybrid(Hybrid {
        near: Near::Metres(near),
        ..Default::default()
    })
}

fn save(name: &str, images: &[(&str, &image::RgbaImage)]) {
    let out = common::root().join("target/test-output");
    std::fs::create_dir_all(&out).unwrap();
    for (n, img) in images {
        img.save(out.join(format!("{name}-{n}.png"))).unwrap();
    }
}

#[test]
fn switch_at_zero_is_the_quad_stream_and_at_infinity_the_full_geometry() {
    let ctx = common::ctx();
    let forest = common::forest(300);
    // In haze too: both forms go through the same haze, so the ends still match exactly; and
    // with the sun's shadows, which both forms cast into one set of maps.
    let shadows = forest_render::shadow::ShadowOptions {
        resolution: 256,
        epsilon: 8.0,
        ..Default::default()
    };
    for (background, atmosphere, shadows) in [
        (Background::Transparent, Atmosphere::CLEAR, None),
        (Background::Sky, Atmosphere::CLEAR, None),
        (Background::Sky, Atmosphere::hazy(300.0), None),
        (Background::Sky, Atmosphere::CLEAR, Some(shadows)),
    ] {
        let mut r = renderer_in(&ctx, &forest, (160, 120), background, atmosphere);
        r.set_shadows(&ctx.device, shadows).unwrap();
        let mut sharpened = 0;
        for (name, cam) in common::cameras(forest.extent()).into_iter().take(4) {
            // The hybrid's quads draw with its own aspect sharpening and without the opaque
            // pass: the stream's options set so draw the same quads.
            let own = frame(&ctx, &mut r, Method::Quads, &cam);
            let options = r.stream.options();
            r.stream
                .set_options(StreamOptions {
                    sharpen: HYBRID_SHARPEN_DEFAULT,
                    opaque_first: false,
                    ..options
                })
                .unwrap();
            let quads = frame(&ctx, &mut r, Method::Quads, &cam);
            r.stream.set_options(options).unwrap();
            sharpened += usize::from(quads != own);
            let zero = frame(&ctx, &mut r, hybrid_at(0.0), &cam);
            let geometry = frame(
                &ctx,
                &mut r,
                Method::Mesh(MeshMethod::Full { depth_sort: true }),
                &cam,
            );
            let infinity = frame(&ctx, &mut r, hybrid_at(f32::INFINITY), &cam);
            // Switched back, the stream draws with its own options again.
            assert!(
                frame(&ctx, &mut r, Method::Quads, &cam) == own,
                "{name}: the quad stream after the hybrid kept the hybrid's options"
            );
            assert_ne!(quads, geometry, "{name}: the two forms differ");
            for (what, got, want) in [
                ("at 0", &zero, &quads),
                ("at infinity", &infinity, &geometry),
            ] {
                if got != want {
                    save(
                        &format!(
                            "hybrid-{name}-{background:?}-{}-{}",
                            atmosphere.visibility,
                            shadows.is_some()
                        ),
                        &[("expected", want), ("hybrid", got)],
                    );
                    panic!(
                        "{name} {background:?} shadows {}: the hybrid {what} differs",
                        shadows.is_some()
                    );
                }
            }
        }
        assert!(
            sharpened > 0,
            "{background:?}: the hybrid's sharpening changed no camera's quads"
        );
    }
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
}

/// Casting into each cascade only the trees whose shadow can reach its slice of the view
/// changes no pixel, for the quad stream, the hybrid and full geometry, and drops casters.
#[test]
fn culling_casters_by_their_receivers_changes_no_shadow() {
    let ctx = common::ctx();
    let forest = common::forest(300);
    let mut r = renderer_in(
        &ctx,
        &forest,
        (160, 120),
        Background::Sky,
        Atmosphere::CLEAR,
    );
    let (mut with, mut without) = (0, 0);
    for method in [
        Method::Quads,
        hybrid_at(8.0),
        Method::Mesh(MeshMethod::Full { depth_sort: true }),
    ] {
        for (name, cam) in common::cameras(forest.extent()).into_iter().take(4) {
            let mut shot = |cull: bool, trees: &mut u32| {
                let opts = forest_render::shadow::ShadowOptions {
                    resolution: 256,
                    epsilon: 8.0,
                    cull_casters: cull,
                    ..Default::default()
                };
                r.set_shadows(&ctx.device, Some(opts)).unwrap();
                r.set_method(&ctx, method).unwrap();
                // Fitted: the light views grow to hold every caster, culled or not.
                let target = Target::new(&ctx, cam.viewport.0, cam.viewport.1);
                r.render_fitted(&ctx, &cam, &target).unwrap();
                let img = target.read(&ctx);
                let stats = r.stream.shadows().unwrap().stats(&ctx);
                *trees += stats.iter().map(|s| s.visible_trees).sum::<u32>();
                img
            };
            let culled = shot(true, &mut with);
            let all = shot(false, &mut without);
            if culled != all {
                save(
                    &format!("cull-casters-{name}"),
                    &[("all", &all), ("culled", &culled)],
                );
                panic!("{name} {method:?}: culling casters changed the image");
            }
        }
    }
    assert!(
        with < without,
        "the cull kept {with} of {without} light-view trees"
    );
    // The reference casts into finer maps, and the others go back to theirs.
    let side = |r: &ForestRenderer| r.stream.shadows().unwrap().options().resolution;
    r.set_method(&ctx, Method::Mesh(MeshMethod::Reference))
        .unwrap();
    assert_eq!(
        side(&r),
        forest_baselines::methods::REFERENCE_SHADOW_RESOLUTION
    );
    r.set_method(&ctx, Method::Quads).unwrap();
    assert_eq!(side(&r), 256);
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
}

/// The tree's bounding sphere in the world (centre, crown radius) and its switch unit (times
/// its scale), as the GPU computes them.
fn tree_sphere(r: &ForestRenderer, instance: usize) -> (Vec3, f32, f32) {
    let t = &r.stream.scene.tables;
    let inst = &t.instances[instance];
    let sp = &t.species[inst.species as usize];
    let c = Vec3::from_slice(&sp.sphere[..3]) * inst.scale;
    let c = Vec3::new(
        inst.cos_rot * c.x + inst.sin_rot * c.z,
        c.y,
        -inst.sin_rot * c.x + inst.cos_rot * c.z,
    ) + Vec3::from_array(inst.position);
    (c, sp.sphere[3] * inst.scale, sp.switch_unit * inst.scale)
}

/// The tree's distance from the eye and switch unit, as the GPU computes them.
fn tree_distance(r: &ForestRenderer, cam: &Camera, instance: usize) -> (f32, f32) {
    let (c, _, unit) = tree_sphere(r, instance);
    (cam.eye.distance(c), unit)
}

#[test]
fn a_tree_in_the_band_is_drawn_by_both_forms_with_weights_summing_to_one() {
    let ctx = common::ctx();
    for species in [0, 1] {
        let forest = common::one_tree(species, 0.4);
        let mut r = renderer(&ctx, &forest, (160, 120), Background::Transparent);
        let cam = common::camera(Vec3::new(2.0, 2.0, 9.0), Vec3::new(0.0, 2.0, 0.0), 2.0);
        let (d, unit) = tree_distance(&r, &cam, 0);
        let quads = frame(&ctx, &mut r, hybrid_at(0.0), &cam);
        let geometry = frame(&ctx, &mut r, hybrid_at(f32::INFINITY), &cam);
        // The band [d/1.4, d/1.4 · 1.8] puts the tree half-way through.
        let method = Method::Hybrid(Hybrid {
            near: Near::Metres(d / 1.4),
            band: 0.8,
            jitter: 0.0,
            ..Default::default()
        });
        let mixed = frame(&ctx, &mut r, method, &cam);
        let Method::Hybrid(h) = method else {
            unreachable!()
        };
        let share = hybrid::quad_share(h.forms(&cam), d, unit, 0);
        assert!(
            (1500..2600).contains(&share),
            "the tree is inside the band: share {share}"
        );
        let stats = r.read_stats(&ctx);
        assert_eq!(stats.geometry_trees, 1, "drawn as geometry: {stats:?}");
        assert!(stats.primitives > stats.per_level.iter().sum::<u32>() as u64);
        // Every pixel from exactly one form: the quads' where the mask is below the share.
        let expected = image::RgbaImage::from_fn(160, 120, |x, y| {
            if hybrid::form_threshold(x, y, 0) < share {
                *quads.get_pixel(x, y)
            } else {
                *geometry.get_pixel(x, y)
            }
        });
        let wrong = mixed
            .pixels()
            .zip(expected.pixels())
            .filter(|(a, b)| a != b)
            .count();
        let from_quads = (0..120)
            .flat_map(|y| (0..160).map(move |x| (x, y)))
            .filter(|&(x, y)| {
                quads.get_pixel(x, y) != geometry.get_pixel(x, y)
                    && mixed.get_pixel(x, y) == quads.get_pixel(x, y)
            })
            .count();
        let differ = quads
            .pixels()
            .zip(geometry.pixels())
            .filter(|(a, b)| a != b)
            .count();
        eprintln!(
            "species {species}: share {share}, {from_quads} of {differ} differing pixels \
             from the quads, {wrong} unexpected"
        );
        if wrong != 0 {
            save(
                &format!("hybrid-band-{species}"),
                &[("mixed", &mixed), ("expected", &expected)],
            );
            panic!("{wrong} pixels are not from the form their mask gives");
        }
        let f = from_quads as f32 / differ as f32;
        let want = share as f32 / WEIGHT_ONE as f32;
        assert!(
            (f - want).abs() < 0.1,
            "quads draw {f} of the tree, want {want}"
        );
    }
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
}

/// One tree nearer than the hybrid's switch, drawn with mesh-LOD starts `lod_from` for its
/// species: the image and the frame's counters.
fn near_tree_in_lods(
    ctx: &GpuContext,
    species: u32,
    lod_from: [f32; 2],
    cam: &Camera,
) -> (
    image::RgbaImage,
    forest_baselines::methods::MethodStats,
    [u32; 2],
) {
    let forest = common::one_tree(species, 0.4);
    let mut prepared = common::prepared().clone();
    prepared.set_lod_from(species as usize, lod_from).unwrap();
    let mut r = common::forest_renderer(
        ctx,
        &common::species(),
        &prepared,
        &forest,
        cam.viewport,
        Background::Transparent,
        Atmosphere::CLEAR,
    );
    let (d, unit) = tree_distance(&r, cam, 0);
    // The switch at twice the tree's distance: the tree is geometry alone.
    let h = Hybrid {
        near: Near::Metres(2.0 * d),
        band: 0.5,
        jitter: 0.0,
        ..Default::default()
    };
    assert_eq!(hybrid::quad_share(h.forms(cam), d, unit, 0), 0);
    let image = frame(ctx, &mut r, Method::Hybrid(h), cam);
    let shares = hybrid::lod_shares(h.forms(cam), d, unit, 0, lod_from);
    (image, r.read_stats(ctx), shares)
}

#[test]
fn a_near_tree_in_a_crossfade_between_mesh_lods_is_split_pixel_for_pixel() {
    let ctx = common::ctx();
    let cam = common::camera(Vec3::new(2.0, 2.0, 9.0), Vec3::new(0.0, 2.0, 0.0), 2.0);
    let mut cam = cam;
    cam.viewport = (160, 120);
    for species in [0, 1] {
        // Without starts the full model; starts at a tenth of the switch put the whole tree
        // (at half of it) in that LOD.
        let (lod0, full, _) = near_tree_in_lods(&ctx, species, [0.0, 0.0], &cam);
        let (lod1, one, _) = near_tree_in_lods(&ctx, species, [0.1, 0.0], &cam);
        let (lod2, two, _) = near_tree_in_lods(&ctx, species, [0.0, 0.1], &cam);
        let lods = [&lod0, &lod1, &lod2];
        let tris = common::prepared().figures[species as usize].lod_triangles;
        for (stats, t) in [(&full, tris[0]), (&one, tris[1]), (&two, tris[2])] {
            assert_eq!(
                (stats.geometry_trees, stats.primitives),
                (1, t),
                "{stats:?}"
            );
        }
        assert!(
            lod0 != lod1 && lod1 != lod2,
            "the LODs draw different images"
        );
        // LOD 1 from 0.4 and LOD 2 from 0.45 of the switch (band 0.5): the tree, at 0.5, is
        // half-way through LOD 1's crossfade and a fifth of the way through LOD 2's.
        let (mixed, stats, [c1, c2]) = near_tree_in_lods(&ctx, species, [0.4, 0.45], &cam);
        assert!(
            (1900..2200).contains(&c1) && (700..1000).contains(&c2),
            "shares {c1} {c2}"
        );
        assert_eq!(stats.geometry_trees, 3, "listed once per LOD: {stats:?}");
        let expected = image::RgbaImage::from_fn(160, 120, |x, y| {
            let t = hybrid::lod_threshold(x, y, 0);
            let k = 2 - usize::from(t >= c2) - usize::from(t >= c1);
            *lods[k].get_pixel(x, y)
        });
        let wrong = mixed
            .pixels()
            .zip(expected.pixels())
            .filter(|(a, b)| a != b)
            .count();
        if wrong != 0 {
            save(
                &format!("hybrid-lods-{species}"),
                &[("mixed", &mixed), ("expected", &expected)],
            );
            panic!("{wrong} pixels are not from the LOD their mask gives");
        }
    }
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
}

#[test]
fn gpu_classification_equals_the_cpu_mirror_and_a_frame_writes_only_the_camera() {
    let ctx = common::ctx();
    let forest = common::forest(2000);
    // A switch in metres for every tree; then the automatic switch, per species, where the
    // pine's atlas records a measured switch at finest quads of 0.8 px (farther than the
    // default 1.5 px the bush keeps).
    let mut species = common::species();
    species[1].atlas.manifest.hybrid_switch = Some(HybridSwitch {
        finest_quad_pixels: 0.8,
        crown_radii: 0.0,
        viewport: [160, 120],
        fov_y_deg: 60.0,
        epsilon: 2.0,
        cameras: 1,
        tolerance: 0.0,
        lod_from: [None; 2],
        never_reached: false,
    });
    let atlases: Vec<_> = species.iter().map(|s| s.atlas.clone()).collect();
    let measured = common::prepared_for(&atlases);
    let default = hybrid::switch_unit(&common::atlases()[1].manifest);
    let unit = hybrid::switch_unit(&species[1].atlas.manifest);
    assert!((unit / default - hybrid::DEFAULT_SWITCH_PIXELS / 0.8).abs() < 1e-5);
    // And with the pine's near trees in mesh LOD 1 from 0.3 and LOD 2 from 0.6 of its
    // switch: a tree is listed once per LOD its crossfades give pixels.
    let mut lods = measured.clone();
    // Starts the manifest would refuse are refused by the same rule, naming the value; 0 is
    // "never".
    for (bad, cause) in [
        ([0.6, 0.3], "LOD 2 starts before LOD 1"),
        ([1.0, 0.0], "lod_from[0] = 1"),
        ([0.0, -0.5], "lod_from[1] = -0.5"),
    ] {
        let e = lods.set_lod_from(1, bad).unwrap_err().to_string();
        assert!(e.contains(cause) && e.contains("species 1"), "{e}");
    }
    assert!(lods.set_lod_from(9, [0.3, 0.6]).is_err());
    lods.set_lod_from(1, [0.0, 0.6]).unwrap();
    assert_eq!(lods.lod_from()[1], [0.0, 0.6]);
    lods.set_lod_from(1, [0.3, 0.6]).unwrap();
    for (near, species, prepared) in [
        (Near::Metres(10.0), common::species(), common::prepared()),
        (Near::Auto, species.clone(), &measured),
        (Near::Auto, species, &lods),
    ] {
        classification_matches(&ctx, &forest, &species, prepared, near);
    }
}

/// The GPU's classification of `forest` under the hybrid with switch `near` equals the CPU
/// mirror's, and a frame writes only the camera.
fn classification_matches(
    ctx: &GpuContext,
    forest: &Forest,
    species: &[SpeciesData],
    prepared: &PreparedGeometry,
    near: Near,
) {
    let mut r = common::forest_renderer(
        ctx,
        species,
        prepared,
        forest,
        (160, 120),
        Background::Transparent,
        Atmosphere::CLEAR,
    );
    let target = Target::new(ctx, 160, 120);
    let h = Hybrid {
        near,
        band: 0.5,
        jitter: 0.3,
        ..Default::default()
    };
    r.set_method(ctx, Method::Hybrid(h)).unwrap();
    let before = r.uploads();
    let (mut both, mut frames, mut crossfades) = (0, 0, 0);
    let lod_from = prepared.lod_from();
    for (name, cam) in common::cameras(forest.extent()) {
        r.render_frame(ctx, &cam, &target).unwrap();
        frames += 1;
        let forms = h.forms(&cam);
        let mut g = cam.to_gpu();
        g.forms = forms;
        // The stream's options with the hybrid's own sharpening.
        StreamOptions {
            sharpen: h.sharpen,
            ..r.stream.options()
        }
        .apply(&mut g);
        // Quads: the CPU reference skips the trees drawn as geometry alone.
        let cpu = reference::run(&r.stream.scene.tables, &g, r.stream.capacity.quads);
        assert!(
            r.stream.read_quads(ctx) == cpu.quads,
            "{name}: the GPU stream differs from the reference"
        );
        // Geometry: the visible trees whose quad share is below one.
        let mut near = 0;
        let planes = g.planes;
        for i in 0..r.stream.scene.tables.instances.len() {
            let (c, radius, unit) = tree_sphere(&r, i);
            let d = cam.eye.distance(c);
            let visible = planes
                .iter()
                .all(|p| p[0] * c.x + p[1] * c.y + p[2] * c.z + p[3] >= -radius);
            let share = hybrid::quad_share(forms, d, unit, i as u32);
            if visible && share < WEIGHT_ONE {
                // Once per mesh LOD with pixels: [c(k+1), c(k)) not empty.
                let sp = r.stream.scene.tables.instances[i].species as usize;
                let [c1, c2] = hybrid::lod_shares(forms, d, unit, i as u32, lod_from[sp]);
                let listed = [WEIGHT_ONE, c1, c2, 0]
                    .windows(2)
                    .filter(|w| w[1] < w[0])
                    .count() as u32;
                near += listed;
                crossfades += u32::from(listed > 1);
                both += u32::from(share > 0);
            }
        }
        let stats = r.read_stats(ctx);
        assert_eq!(
            stats.geometry_trees, near,
            "{name}: trees drawn as geometry"
        );
    }
    assert!(both > 0, "some trees were in the band");
    if lod_from.iter().flatten().any(|&f| f > 0.0) {
        assert!(
            crossfades > 0,
            "some trees were in a crossfade between mesh LODs"
        );
    }
    let (n, bytes) = r.uploads();
    let size = std::mem::size_of::<forest_render::gpu_types::GpuCamera>() as u64;
    assert_eq!(
        (n - before.0, bytes - before.1),
        (2 * frames, 2 * frames * size),
        "a hybrid frame writes the camera once per form and nothing else"
    );
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
}

#[test]
fn empty_single_and_million_tree_forests_render_without_errors() {
    let ctx = common::ctx();
    let (empty, million) = common::empty_and_million();
    for (name, forest) in [
        ("empty", &empty),
        ("single", &common::one_tree(1, 0.3)),
        ("million", &million),
    ] {
        let mut cam = if name == "single" {
            common::camera(Vec3::new(0.0, 3.0, 6.0), Vec3::new(0.0, 2.5, 0.0), 1.0)
        } else {
            common::cameras(forest.extent().max(10.0)).remove(0).1
        };
        cam.far = 40.0;
        let mut r = renderer(&ctx, forest, cam.viewport, Background::Transparent);
        let img = frame(&ctx, &mut r, Method::Hybrid(Hybrid::default()), &cam);
        let stats = r.read_stats(&ctx);
        assert_eq!(ctx.take_errors(), Vec::<String>::new(), "{name}");
        let covered = img.pixels().filter(|p| p[3] > 0).count();
        match name {
            "empty" => assert_eq!(covered, 0),
            _ => {
                assert!(covered > 100, "{name}: trees drawn");
                assert!(stats.geometry_trees > 0, "{name}: near trees as geometry");
            }
        }
        if name == "million" {
            assert!(
                stats.per_level.iter().sum::<u32>() > 0,
                "{name}: far trees as quads"
            );
        }
    }
}
