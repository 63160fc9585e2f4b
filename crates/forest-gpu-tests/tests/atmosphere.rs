//! The environment and the haze: the sky, the endless ground and the sun's disc have analytic
//! colours; haze mixes every method's trees towards the horizon colour by exp(−σ·distance);
//! full geometry and the quad stream draw the same sky and ground and the same hazed tree. The
//! terrain: a planar height field is drawn where the analytic plane is, in the shading model's
//! colour for its normal, the flat ground continuing around it; both methods draw the same
//! hills pixel for pixel, in haze too.

mod common;

use forest_baselines::geometry::{GeometryRenderer, MeshMethod};
use forest_format::forest::Forest;
use forest_format::shading::srgb_decode_table;
use forest_format::terrain::Terrain;
use forest_render::ForestView;
use forest_render::options::{
    Atmosphere, Background, KOSCHMIEDER, RendererOptions, SUN_DISC_DEGREES, ground_albedo,
};
use forest_render::target::{TARGET_FORMAT, Target};
use forest_render::{Camera, GpuContext, GpuScene, QuadStream};
use glam::{Vec3, Vec4};

const SIZE: (u32, u32) = (160, 120);

fn options(background: Background, atmosphere: Atmosphere) -> RendererOptions {
    RendererOptions {
        format: TARGET_FORMAT,
        viewport: SIZE,
        min_epsilon: 1.0,
        background,
        atmosphere,
        ..Default::default()
    }
}

fn quads(ctx: &GpuContext, forest: &Forest, opts: &RendererOptions, cam: &Camera) -> Image {
    let scene = GpuScene::new(ctx, &common::species(), forest).unwrap();
    let mut stream = QuadStream::new(&ctx.device, scene, opts).unwrap();
    let target = Target::new(ctx, SIZE.0, SIZE.1);
    stream.render_frame(ctx, cam, &target).unwrap();
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    Image(target.read(ctx))
}

fn geometry(ctx: &GpuContext, forest: &Forest, opts: &RendererOptions, cam: &Camera) -> Image {
    let mut geo = GeometryRenderer::with_targets(ctx, common::prepared(), forest, opts).unwrap();
    geo.set_method(ctx, MeshMethod::default()).unwrap();
    let target = Target::new(ctx, SIZE.0, SIZE.1);
    geo.render_frame(ctx, cam, &target).unwrap();
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    Image(target.read(ctx))
}

/// A read-back frame, with its pixels decoded to linear premultiplied RGBA.
struct Image(image::RgbaImage);

impl Image {
    fn linear(&self, x: u32, y: u32) -> Vec4 {
        let t = srgb_decode_table();
        let p = self.0.get_pixel(x, y);
        Vec4::new(
            t[p[0] as usize],
            t[p[1] as usize],
            t[p[2] as usize],
            f32::from(p[3]) / 255.0,
        )
    }

    fn save(&self, name: &str) {
        let out = common::root().join("target/test-output");
        std::fs::create_dir_all(&out).unwrap();
        self.0
            .save(out.join(format!("atmosphere-{name}.png")))
            .unwrap();
    }
}

/// The unit direction through the centre of pixel (x, y), by inverting the view-projection
/// (the shader finds it another way).
fn pixel_ray(cam: &Camera, x: u32, y: u32) -> Vec3 {
    let ndc_x = 2.0 * (x as f32 + 0.5) / SIZE.0 as f32 - 1.0;
    let ndc_y = 1.0 - 2.0 * (y as f32 + 0.5) / SIZE.1 as f32;
    let p = cam
        .view_proj()
        .inverse()
        .project_point3(Vec3::new(ndc_x, ndc_y, 0.5));
    (p - cam.eye).normalize()
}

fn camera(eye: Vec3, target: Vec3) -> Camera {
    Camera {
        viewport: SIZE,
        far: 5000.0,
        ..common::camera(eye, target, 1.0)
    }
}

/// σ₀·exp(−y / haze_height) integrated from `a` to `b` by the midpoint rule.
fn numeric_optical_depth(atmosphere: &Atmosphere, a: Vec3, b: Vec3) -> f32 {
    let n = 4000;
    let step = a.distance(b) / n as f32;
    let sigma = KOSCHMIEDER / atmosphere.visibility;
    (0..n)
        .map(|i| {
            let p = a.lerp(b, (i as f32 + 0.5) / n as f32);
            sigma * (-p.y / atmosphere.haze_height).exp() * step
        })
        .sum()
}

#[test]
fn the_optical_depth_integrates_the_height_fog() {
    let a = Atmosphere {
        haze_height: 50.0,
        ..Atmosphere::hazy(800.0)
    };
    for (eye, p) in [
        (Vec3::new(0.0, 2.0, 0.0), Vec3::new(300.0, 0.0, 40.0)),
        (Vec3::new(0.0, 400.0, 0.0), Vec3::new(900.0, 3.0, -200.0)),
        (Vec3::new(5.0, 30.0, 0.0), Vec3::new(-60.0, 30.0, 10.0)),
        (Vec3::new(5.0, 30.0, 0.0), Vec3::new(-60.0, 30.02, 10.0)),
        (Vec3::new(0.0, 1.7, 0.0), Vec3::new(10.0, 25.0, 10.0)),
    ] {
        let (got, want) = (a.optical_depth(eye, p), numeric_optical_depth(&a, eye, p));
        assert!(
            (got - want).abs() <= 1e-3 * want.max(1.0),
            "{eye} → {p}: {got} vs {want}"
        );
        assert!((a.optical_depth(p, eye) - want).abs() <= 1e-3 * want.max(1.0));
    }
    // Homogeneous haze: σ₀·distance; no overflow from a very high eye.
    let h = Atmosphere {
        haze_height: f32::INFINITY,
        ..a
    };
    let (e, p) = (Vec3::new(0.0, 3.0, 0.0), Vec3::new(30.0, 3.0, 40.0));
    assert!((h.optical_depth(e, p) - KOSCHMIEDER / 800.0 * 50.0).abs() < 1e-5);
    let high = a.optical_depth(Vec3::new(0.0, 30_000.0, 0.0), Vec3::ZERO);
    assert!(high.is_finite() && high > 0.0, "{high}");
}

/// Within one step of 8-bit sRGB around `want` (linear RGB).
fn close(got: Vec4, want: Vec3, what: &str) {
    let d = (got.truncate() - want).abs().max_element();
    assert!(
        d <= 0.01 + 0.02 * want.max_element(),
        "{what}: got {got}, want {want}"
    );
}

#[test]
fn sky_ground_and_sun_have_their_analytic_colours() {
    let ctx = common::ctx();
    let empty = Forest::new(vec!["bush".into(), "pine".into()], Vec::new(), 15);
    // Haze thinning with height, with a low eye in it.
    let atmosphere = Atmosphere {
        haze_height: 3.0,
        ..Atmosphere::hazy(400.0)
    };
    let opts = options(Background::Sky, atmosphere);
    let horizon = Vec3::from_array(atmosphere.horizon);
    let zenith = Vec3::from_array(atmosphere.zenith);
    let ground = |p: Vec3| {
        opts.lighting
            .shade(ground_albedo(p.x, p.z), Vec3::Y, 1.0, 1.0, 0.0)
    };
    // Looking north, a little up: the ground in the lower rows, the sky above.
    let cam = camera(Vec3::new(3.0, 2.0, -4.0), Vec3::new(3.0, 2.5, 20.0));
    for img in [
        quads(&ctx, &empty, &opts, &cam),
        geometry(&ctx, &empty, &opts, &cam),
    ] {
        let mut checked = [0; 2];
        for y in (0..SIZE.1).step_by(7) {
            for x in (0..SIZE.0).step_by(13) {
                let d = pixel_ray(&cam, x, y);
                // Skip the rows that straddle the horizon.
                if d.y.abs() < 0.02 {
                    continue;
                }
                let want = if d.y < 0.0 {
                    let hit = cam.eye + d * (cam.eye.y / -d.y);
                    let t = (-numeric_optical_depth(&atmosphere, cam.eye, hit)).exp();
                    checked[0] += 1;
                    ground(hit) * t + horizon * (1.0 - t)
                } else {
                    checked[1] += 1;
                    let glow = opts.lighting.sun
                        * (0.25 * d.dot(opts.lighting.sun_dir).max(0.0).powf(256.0));
                    horizon.lerp(zenith, d.y.sqrt()) + glow
                };
                let got = img.linear(x, y);
                if (got.truncate() - want).abs().max_element() > 0.01 + 0.02 * want.max_element() {
                    img.save("analytic");
                }
                close(got, want, &format!("pixel ({x}, {y}), ray {d}"));
            }
        }
        assert!(checked[0] > 20 && checked[1] > 20, "{checked:?}");
    }
    // Looking at the sun: its disc, in the sun's colour.
    let sun = opts.lighting.sun_dir;
    let cam = camera(
        Vec3::new(0.0, 2.0, 0.0),
        Vec3::new(0.0, 2.0, 0.0) + sun * 100.0,
    );
    let img = quads(&ctx, &empty, &opts, &cam);
    let (cx, cy) = (SIZE.0 / 2, SIZE.1 / 2);
    assert!(pixel_ray(&cam, cx, cy).dot(sun) > SUN_DISC_DEGREES.to_radians().cos());
    close(
        img.linear(cx, cy),
        (opts.lighting.sun * 1.5).min(Vec3::ONE),
        "the sun's disc",
    );
    // Without the disc (and its glow), the sky there is the gradient alone.
    let no_disc = Atmosphere {
        sun_disc: false,
        ..atmosphere
    };
    let img = quads(&ctx, &empty, &options(Background::Sky, no_disc), &cam);
    let d = pixel_ray(&cam, cx, cy);
    close(
        img.linear(cx, cy),
        horizon.lerp(zenith, d.y.sqrt()),
        "the sky without the disc",
    );
}

#[test]
fn exposure_scales_the_sky_the_ground_the_haze_and_the_trees_alike() {
    let ctx = common::ctx();
    let forest = common::one_tree(1, 0.4);
    let centre = common::atlases()[1].manifest.bounding_sphere.center;
    // A far tree in thick haze, the ground below it and the sky with the sun's glow above.
    let atmosphere = Atmosphere {
        haze_height: 3.0,
        ..Atmosphere::hazy(60.0)
    };
    let cam = camera(centre + Vec3::new(2.0, 1.0, -12.0), centre);
    let bright = options(Background::Sky, atmosphere);
    let exposure = 0.25;
    let mut dim = bright.clone();
    dim.lighting.exposure = exposure;
    for (name, draw) in [
        ("quads", quads as fn(&_, &_, &_, &_) -> Image),
        ("geometry", geometry),
    ] {
        let (full, scaled) = (
            draw(&ctx, &forest, &bright, &cam),
            draw(&ctx, &forest, &dim, &cam),
        );
        let mut checked = 0;
        for y in (0..SIZE.1).step_by(3) {
            for x in (0..SIZE.0).step_by(3) {
                let (a, b) = (full.linear(x, y), scaled.linear(x, y));
                // Saturated pixels say nothing of the scale.
                if a.truncate().max_element() >= 0.99 {
                    continue;
                }
                let want = a.truncate() * exposure;
                if (b.truncate() - want).abs().max_element() > 0.01 + 0.02 * want.max_element() {
                    full.save(&format!("exposure_{name}_1"));
                    scaled.save(&format!("exposure_{name}_{exposure}"));
                }
                close(
                    b,
                    want,
                    &format!("{name}: pixel ({x}, {y}) at exposure {exposure}"),
                );
                checked += 1;
            }
        }
        assert!(checked > 1000, "{name}: only {checked} pixels checked");
    }
}

#[test]
fn haze_mixes_every_methods_tree_towards_the_horizon_by_its_distance() {
    let ctx = common::ctx();
    let forest = common::one_tree(1, 0.4);
    let sphere = common::atlases()[1].manifest.bounding_sphere;
    let centre = sphere.center;
    let r = sphere.radius;
    // About 25 crown radii away, where the stream at ε = 1 is close to the geometry.
    let distance = 25.0 * r;
    // A narrow field of view, so that the far tree still covers some 50 pixels across.
    let cam = Camera {
        fov_y_deg: 12.0,
        ..camera(
            centre + Vec3::new(0.3, 0.1, -1.0).normalize() * distance,
            centre,
        )
    };
    // Half the colour left at the tree's centre.
    let visibility = KOSCHMIEDER * distance / std::f32::consts::LN_2;
    // Homogeneous, so that a fragment's transmittance is bounded by the tree's nearest and
    // farthest points'.
    let hazy = Atmosphere {
        haze_height: f32::INFINITY,
        ..Atmosphere::hazy(visibility)
    };
    let clear = Atmosphere::CLEAR;
    let horizon = Vec3::from_array(hazy.horizon);
    let sigma = hazy.haze_density();
    let (t_near, t_far) = (
        (-sigma * (distance - r)).exp(),
        (-sigma * (distance + r)).exp(),
    );
    let render = [quads, geometry];
    let mut hazed_images = Vec::new();
    for (name, draw) in ["quads", "geometry"].into_iter().zip(render) {
        let plain = draw(
            &ctx,
            &forest,
            &options(Background::Transparent, clear),
            &cam,
        );
        let hazed = draw(&ctx, &forest, &options(Background::Transparent, hazy), &cam);
        let (mut n, mut err_sum, mut moved) = (0u32, 0.0f32, 0.0f32);
        let mut worst = 0.0f32;
        for y in 0..SIZE.1 {
            for x in 0..SIZE.0 {
                let (u, h) = (plain.linear(x, y), hazed.linear(x, y));
                // The haze never changes coverage.
                assert!(
                    (u.w - h.w).abs() <= 1.0 / 255.0,
                    "{name}: alpha at ({x}, {y})"
                );
                if u.w < 0.5 {
                    continue;
                }
                // Each fragment keeps T of its colour, T between the tree's nearest and
                // farthest points' transmittance, and takes 1 − T of the horizon colour.
                let at = |t: f32| u.truncate() * t + horizon * (u.w * (1.0 - t));
                let (a, b) = (at(t_near), at(t_far));
                let lo = a.min(b) - Vec3::splat(0.01);
                let hi = a.max(b) + Vec3::splat(0.01);
                let c = h.truncate();
                let out = (lo - c).max(c - hi).max(Vec3::ZERO).max_element();
                worst = worst.max(out);
                err_sum += (c - at(0.5)).abs().max_element();
                moved += (c - u.truncate()).abs().max_element();
                n += 1;
            }
        }
        assert!(n > 50, "{name}: {n} covered pixels");
        if worst > 0.01 || err_sum / n as f32 > 0.01 {
            plain.save(&format!("{name}-clear"));
            hazed.save(&format!("{name}-hazed"));
        }
        eprintln!(
            "{name}: {n} pixels, worst {worst:.4} outside the bounds, mean error {:.4}, moved {:.3}",
            err_sum / n as f32,
            moved / n as f32
        );
        assert!(
            worst <= 0.01,
            "{name}: a pixel {worst} outside its haze bounds"
        );
        assert!(
            err_sum / n as f32 <= 0.01,
            "{name}: mean error {} against T = 0.5 at the centre",
            err_sum / n as f32
        );
        // The haze did something a missing haze would fail.
        assert!(
            moved / n as f32 > 0.05,
            "{name}: haze moved colours by {moved}"
        );
        hazed_images.push(draw(&ctx, &forest, &options(Background::Sky, hazy), &cam));
    }
    // Over the sky, both methods draw the same environment: wherever neither draws the tree,
    // their pixels are identical, and the hazed trees agree as closely as the methods do.
    let (q, g) = (&hazed_images[0], &hazed_images[1]);
    let plain_q = quads(
        &ctx,
        &forest,
        &options(Background::Transparent, clear),
        &cam,
    );
    let plain_g = geometry(
        &ctx,
        &forest,
        &options(Background::Transparent, clear),
        &cam,
    );
    let mut background = 0;
    for (x, y, p) in q.0.enumerate_pixels() {
        if plain_q.0.get_pixel(x, y)[3] == 0 && plain_g.0.get_pixel(x, y)[3] == 0 {
            assert_eq!(p, g.0.get_pixel(x, y), "environment at ({x}, {y})");
            background += 1;
        }
    }
    assert!(background > 1000, "{background} background pixels");
    let (hazed_flip, _) = forest_metrics::flip(&g.0, &q.0).unwrap();
    let (clear_flip, _) = forest_metrics::flip(
        &geometry(&ctx, &forest, &options(Background::Sky, clear), &cam).0,
        &quads(&ctx, &forest, &options(Background::Sky, clear), &cam).0,
    )
    .unwrap();
    eprintln!("FLIP between the methods: {hazed_flip:.4} hazed, {clear_flip:.4} clear");
    if hazed_flip > clear_flip + 0.002 {
        q.save("quads-sky");
        g.save("geometry-sky");
    }
    assert!(
        hazed_flip <= clear_flip + 0.002,
        "FLIP between the methods: {hazed_flip} hazed, {clear_flip} clear"
    );
}

#[test]
fn bad_atmospheres_are_refused_with_their_cause() {
    let ctx = common::ctx();
    let forest = common::one_tree(0, 0.0);
    let scene = std::sync::Arc::new(GpuScene::new(&ctx, &common::species(), &forest).unwrap());
    for (atmosphere, cause) in [
        (Atmosphere::hazy(0.0), "visibility"),
        (Atmosphere::hazy(-5.0), "visibility"),
        (Atmosphere::hazy(f32::NAN), "visibility"),
        (
            Atmosphere {
                zenith: [0.2, f32::INFINITY, 0.1],
                ..Atmosphere::CLEAR
            },
            "zenith",
        ),
        (
            Atmosphere {
                horizon: [-0.1, 0.5, 0.5],
                ..Atmosphere::CLEAR
            },
            "horizon",
        ),
    ] {
        let opts = options(Background::Sky, atmosphere);
        let Err(e) = QuadStream::new(&ctx.device, scene.clone(), &opts) else {
            panic!("{atmosphere:?} accepted");
        };
        assert!(e.to_string().contains(cause), "{e}");
        let Err(e) = GeometryRenderer::with_targets(&ctx, common::prepared(), &forest, &opts)
        else {
            panic!("{atmosphere:?} accepted by the geometry renderer");
        };
        assert!(e.to_string().contains(cause), "{e}");
    }
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
}

#[test]
fn the_hybrid_refuses_forms_in_different_atmospheres() {
    use forest_baselines::hybrid::Hybrid;
    use forest_baselines::methods::{ForestRenderer, Method};
    let ctx = common::ctx();
    let forest = common::one_tree(0, 0.0);
    let build = |stream_haze: Atmosphere| {
        let scene = GpuScene::new(&ctx, &common::species(), &forest).unwrap();
        let stream =
            QuadStream::new(&ctx.device, scene, &options(Background::Sky, stream_haze)).unwrap();
        let geo = GeometryRenderer::with_targets(
            &ctx,
            common::prepared(),
            &forest,
            &options(Background::Sky, Atmosphere::hazy(900.0)),
        )
        .unwrap();
        ForestRenderer::new(stream, Some(geo))
    };
    let mut same = build(Atmosphere::hazy(900.0));
    same.set_method(&ctx, Method::Hybrid(Hybrid::default()))
        .unwrap();
    let mut different = build(Atmosphere::CLEAR);
    let e = different
        .set_method(&ctx, Method::Hybrid(Hybrid::default()))
        .unwrap_err();
    assert!(e.to_string().contains("atmosphere"), "{e}");
    // The single-form methods draw alone and take either.
    different
        .set_method(&ctx, Method::Mesh(MeshMethod::default()))
        .unwrap();
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
}

/// Heights `a·x + b·z + c` on a 41 × 41 grid 5 m apart, centred on the origin.
fn planar(a: f32, b: f32, c: f32) -> Terrain {
    let (n, s) = (41u32, 5.0f32);
    let o = -s * (n - 1) as f32 / 2.0;
    let heights = (0..n)
        .flat_map(|j| (0..n).map(move |i| a * (o + i as f32 * s) + b * (o + j as f32 * s) + c))
        .collect();
    Terrain {
        size: [n, n],
        origin: [o, o],
        spacing: s,
        heights,
    }
}

#[test]
fn a_planar_terrain_is_drawn_where_and_as_the_plane_is() {
    let ctx = common::ctx();
    // Rising to the east and the north: 50 m at the centre, 10 m to 90 m along x.
    let (a, b, c) = (0.4, 0.1, 50.0);
    let terrain = planar(a, b, c);
    let forest = Forest::new(vec!["bush".into(), "pine".into()], Vec::new(), 15)
        .with_terrain(terrain.clone());
    let opts = options(Background::Sky, Atmosphere::CLEAR);
    let normal = Vec3::new(-a, 1.0, -b).normalize();
    let slope = |p: Vec3| {
        opts.lighting
            .shade(ground_albedo(p.x, p.z), normal, 1.0, 1.0, 0.0)
    };
    let flat = |p: Vec3| {
        opts.lighting
            .shade(ground_albedo(p.x, p.z), Vec3::Y, 1.0, 1.0, 0.0)
    };
    // From the south-west, above the slope, looking at its middle and past its east edge.
    let cam = Camera {
        viewport: SIZE,
        far: 5000.0,
        ..common::camera(
            Vec3::new(-60.0, 140.0, -160.0),
            Vec3::new(40.0, 50.0, 20.0),
            1.0,
        )
    };
    let q = quads(&ctx, &forest, &opts, &cam);
    let g = geometry(&ctx, &forest, &opts, &cam);
    if q.0 != g.0 {
        q.save("terrain-quads");
        g.save("terrain-geometry");
    }
    assert!(q.0 == g.0, "both methods draw the same terrain");
    let ([x0, z0], [x1, z1]) = terrain.bounds();
    let (mut on, mut off) = (0, 0);
    for y in (0..SIZE.1).step_by(5) {
        for x in (0..SIZE.0).step_by(7) {
            let d = pixel_ray(&cam, x, y);
            // The ray against the plane y = a·x + b·z + c, kept where it is on the grid.
            let n = Vec3::new(-a, 1.0, -b);
            let t = (c - n.dot(cam.eye)) / n.dot(d);
            let p = cam.eye + d * t;
            let margin = 2.0;
            let inside =
                |p: Vec3, m: f32| p.x > x0 + m && p.x < x1 - m && p.z > z0 + m && p.z < z1 - m;
            let want = if t > 0.0 && inside(p, margin) {
                on += 1;
                slope(p)
            } else if t > 0.0 && inside(p, -margin) {
                continue; // near the border or its skirt
            } else if d.y < -0.05 {
                // Past the grid the ray meets the flat ground, unless it passes over the
                // grid below its highest point first (then a skirt or the slope is in front).
                let hit = cam.eye + d * (cam.eye.y / -d.y);
                let crosses = (0..=400).any(|k| {
                    let p = cam.eye.lerp(hit, k as f32 / 400.0);
                    p.y <= 95.0 && inside(p, -3.0 * margin)
                });
                // Far away a pixel spans metres of the ground's 6 m noise: not compared.
                if crosses || hit.distance(cam.eye) > 500.0 {
                    continue;
                }
                off += 1;
                flat(hit)
            } else {
                continue;
            };
            let got = q.linear(x, y).truncate();
            if (got - want).abs().max_element() > 0.01 + 0.02 * want.max_element() {
                q.save("terrain-planar");
                panic!("pixel ({x}, {y}), ray {d}: got {got}, want {want}");
            }
        }
    }
    assert!(on > 100 && off > 10, "{on} on the slope, {off} beyond");
    assert!(
        (slope(Vec3::ZERO) - flat(Vec3::ZERO)).abs().max_element() > 0.02,
        "a slope is shaded"
    );
}

#[test]
fn hills_in_haze_are_the_same_for_every_method_and_hide_the_plane() {
    let ctx = common::ctx();
    let forest = common::hilly_forest(60);
    let t = forest.terrain.as_ref().unwrap();
    let (lo, hi) = t.height_range();
    let opts = options(Background::Sky, Atmosphere::hazy(600.0));
    let empty = Forest::new(forest.species.clone(), Vec::new(), 15).with_terrain(t.clone());
    // Standing on the ground, looking across the hills; and from high above.
    let low = Vec3::new(-10.0, forest.ground_height(-10.0, 5.0) + 1.7, 5.0);
    for (name, eye, target) in [
        ("ground", low, Vec3::new(30.0, (lo + hi) / 2.0, -30.0)),
        (
            "above",
            Vec3::new(0.0, hi + 150.0, 120.0),
            Vec3::new(0.0, lo, 0.0),
        ),
    ] {
        let cam = Camera {
            viewport: SIZE,
            far: 5000.0,
            ..common::camera(eye, target, 1.0)
        };
        let q = quads(&ctx, &empty, &opts, &cam);
        let g = geometry(&ctx, &empty, &opts, &cam);
        if q.0 != g.0 {
            q.save(&format!("terrain-{name}-quads"));
            g.save(&format!("terrain-{name}-geometry"));
        }
        assert!(q.0 == g.0, "{name}: both methods draw the same hills");
        // No sky shows through the hills: every pixel whose ray points down hits ground.
        let sky = |p: &image::Rgba<u8>| p[2] > p[0] + 30;
        let holes = (0..SIZE.1)
            .flat_map(|y| (0..SIZE.0).map(move |x| (x, y)))
            .filter(|&(x, y)| pixel_ray(&cam, x, y).y < -0.02 && sky(q.0.get_pixel(x, y)))
            .count();
        if holes > 0 {
            q.save(&format!("terrain-{name}-holes"));
        }
        assert_eq!(holes, 0, "{name}: sky through the ground");
        // The trees standing on the hills are drawn over them.
        let trees = quads(&ctx, &forest, &opts, &cam);
        let differ = (trees.0.pixels().zip(q.0.pixels()))
            .filter(|(a, b)| a != b)
            .count();
        assert!(differ > 20, "{name}: {differ} pixels of trees");
    }
}
