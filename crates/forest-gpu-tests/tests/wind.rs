//! Wind: the GPU moves every point as the CPU mirror (`forest_format::wind`) does; every
//! method moves a tree downwind, alike; shadows move with their trees; and a tree whose sway
//! carries it into view is not culled.

mod common;

use forest_baselines::Hybrid;
use forest_baselines::geometry::MeshMethod;
use forest_baselines::methods::{ForestRenderer, Method};
use forest_format::forest::{Forest, Instance};
use forest_format::noise::SplitMix64;
use forest_format::wind::{SwayedTree, Wind};
use forest_render::gpu_types::GpuCamera;
use forest_render::options::{Atmosphere, Background};
use forest_render::target::Target;
use forest_render::{Camera, ForestView, GpuContext};
use glam::Vec3;

/// A compute module evaluating `swayed` and `wind_reach_now` for each input.
const HARNESS: &str = r#"
#import wind
@group(0) @binding(0) var<uniform> camera: Camera;
// Per sample: the point (xyz) and the seed (w, bits); the foot (xyz) and height (w); the
// radius (x).
@group(0) @binding(1) var<storage, read> samples: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> out: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (3u * i + 2u >= arrayLength(&samples)) { return; }
    let a = samples[3u * i];
    let b = samples[3u * i + 1u];
    let c = samples[3u * i + 2u];
    let p = swayed(a.xyz, b.xyz, b.w, c.x, bitcast<u32>(a.w));
    out[i] = vec4<f32>(p, wind_reach_now(b.xyz, b.w, bitcast<u32>(a.w)));
}
"#;

/// The GPU's `swayed` point and `wind_reach_now` for each tree and point under `wind`.
fn gpu_swayed(ctx: &GpuContext, wind: &Wind, samples: &[(Vec3, SwayedTree)]) -> Vec<[f32; 4]> {
    let mut cam = GpuCamera::default();
    cam.set_wind(wind);
    let data: Vec<[f32; 4]> = samples
        .iter()
        .flat_map(|(p, t)| {
            [
                [p.x, p.y, p.z, f32::from_bits(t.seed)],
                [t.foot.x, t.foot.y, t.foot.z, t.height],
                [t.radius, 0.0, 0.0, 0.0],
            ]
        })
        .collect();
    common::run_harness(
        ctx,
        HARNESS,
        bytemuck::bytes_of(&cam),
        &[bytemuck::cast_slice(&data)],
        samples.len(),
    )
}

#[test]
fn the_gpu_moves_every_point_as_the_cpu_mirror() {
    let ctx = common::ctx();
    let mut rng = SplitMix64(11);
    let mut u = |lo: f32, hi: f32| lo + (hi - lo) * rng.next_f32();
    let mut worst = 0.0f32;
    for k in 0..6 {
        let wind = Wind {
            towards_deg: u(-400.0, 400.0),
            speed: [0.0, 2.0, 8.0, 15.0, 30.0, 50.0][k],
            gustiness: u(0.0, 1.0),
            time: u(0.0, 600.0),
        };
        wind.validate().unwrap();
        let samples: Vec<(Vec3, SwayedTree)> = (0..512)
            .map(|i| {
                let tree = SwayedTree::from_sphere(
                    Vec3::new(u(-500.0, 500.0), u(-20.0, 40.0), u(-500.0, 500.0)),
                    u(0.5, 2.0),
                    u(1.0, 8.0),
                    u(1.0, 7.0),
                    i * 7919 + k as u32,
                );
                let p =
                    tree.foot + Vec3::new(u(-1.0, 1.0), u(-0.1, 1.6), u(-1.0, 1.0)) * tree.height;
                (p, tree)
            })
            .collect();
        let gpu = gpu_swayed(&ctx, &wind, &samples);
        for ((p, tree), g) in samples.iter().zip(&gpu) {
            let cpu = wind.swayed(*p, tree);
            let got = Vec3::new(g[0], g[1], g[2]);
            // Within a few micrometres per metre of the point's distance from the foot, and
            // the rounding of its world coordinates.
            let tol = 4e-6 * (1.0 + (*p - tree.foot).length()) + 4e-7 * p.abs().max_element();
            let err = (got - cpu).length();
            worst = worst.max(err / tol);
            assert!(
                err <= tol,
                "wind {wind:?}, tree {tree:?}, point {p}: GPU {got}, CPU {cpu}"
            );
            // The reach takes the sway's sines at the instant, rounded alike within a few
            // parts in 1e5 (its own margin is a hundredth).
            let reach = wind.reach_now(tree);
            assert!(
                (g[3] - reach).abs() <= 4e-5 * (1.0 + reach),
                "{} {reach}",
                g[3]
            );
            assert!(
                (cpu - *p).length() <= reach + 1e-5,
                "{wind:?}: beyond the reach"
            );
        }
    }
    eprintln!("worst GPU/CPU difference: {worst:.2} of the tolerance");
}

const SIZE: (u32, u32) = (128, 96);

/// One bush standing at the origin, unturned (its bounding sphere where the atlas says).
fn bush() -> Forest {
    Forest::new(
        vec!["bush".into(), "pine".into()],
        vec![Instance {
            position: [0.0, 0.0, 0.0],
            rotation: 0.0,
            scale: 1.0,
            species: 0,
        }],
        15,
    )
}

fn renderer(ctx: &GpuContext, forest: &Forest, background: Background) -> ForestRenderer {
    common::forest_renderer(
        ctx,
        &common::species(),
        common::prepared(),
        forest,
        SIZE,
        background,
        Atmosphere::CLEAR,
    )
}

/// The frame `r` draws of `cam` in `wind`.
fn frame(ctx: &GpuContext, r: &mut ForestRenderer, cam: &Camera, wind: Wind) -> image::RgbaImage {
    r.set_wind(wind).unwrap();
    let target = Target::new(ctx, SIZE.0, SIZE.1);
    r.render_fitted(ctx, cam, &target).unwrap();
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    target.read(ctx)
}

/// The covered pixels' mean column and count.
fn coverage(img: &image::RgbaImage) -> (f32, usize) {
    let (mut sum, mut n) = (0.0, 0);
    for (x, _, p) in img.enumerate_pixels() {
        if p[3] > 128 {
            sum += x as f32;
            n += 1;
        }
    }
    (sum / n.max(1) as f32, n)
}

#[test]
fn every_method_moves_the_tree_downwind_alike() {
    let ctx = common::ctx();
    let forest = bush();
    let sphere = common::atlases()[0].manifest.bounding_sphere;
    // Seen from the south (−Z) looking north, the wind blowing east (+X, to the left on
    // screen: right-handed, y up).
    let cam = Camera {
        viewport: SIZE,
        ..common::camera(
            sphere.center + Vec3::new(0.0, 0.0, -4.0 * sphere.radius),
            sphere.center,
            1.0,
        )
    };
    // A storm without gusts, at an instant of its sway; and the same wind blowing west.
    let east = Wind {
        gustiness: 0.0,
        ..Wind::new(90.0, 30.0).at(2.0)
    };
    let west = Wind {
        towards_deg: 270.0,
        ..east
    };
    let mut shifts = Vec::new();
    for (name, method) in common::every_method() {
        let mut r = renderer(&ctx, &forest, Background::Transparent);
        r.set_method(&ctx, method).unwrap();
        let calm = frame(&ctx, &mut r, &cam, Wind::CALM);
        let blown = frame(&ctx, &mut r, &cam, east);
        let back = frame(&ctx, &mut r, &cam, west);
        let (c0, n0) = coverage(&calm);
        let (c1, n1) = coverage(&blown);
        let (c2, _) = coverage(&back);
        if !(c1 < c0 - 0.5 && c2 > c0 + 0.5) {
            common::failure_images(&format!("wind-{name}"), &calm, &blown);
        }
        assert!(n0 > 200 && n1 > 200, "{name}: {n0} and {n1} pixels covered");
        assert!(
            c1 < c0 - 0.5 && c2 > c0 + 0.5,
            "{name}: the crown's mean column {c0:.2} calm, {c1:.2} blown east, {c2:.2} west"
        );
        shifts.push((name, c0 - c1));
    }
    // Every form moves the same points alike: the shifts agree within a third.
    let reference = shifts.iter().find(|(n, _)| *n == "reference").unwrap().1;
    for (name, s) in &shifts {
        assert!(
            (s - reference).abs() <= 0.35 * reference,
            "{name} shifts {s:.2} px, the reference {reference:.2} px: {shifts:?}"
        );
    }
    eprintln!("shifts in pixels: {shifts:?}");
}

#[test]
fn a_tree_swayed_towards_the_view_is_not_culled_and_its_shadow_moves() {
    let ctx = common::ctx();
    let forest = bush();
    let sphere = common::atlases()[0].manifest.bounding_sphere;
    let r = sphere.radius;
    // Looking north at the crown's height from east of the tree (+X is on the screen's left,
    // so the tree lies past the view's right edge): the right frustum plane 2 % of the radius
    // beyond the bounding sphere. A storm blowing east bends the crown towards the view.
    let look = |x: f32| {
        let eye = Vec3::new(x, sphere.center.y, -3.0 * r);
        Camera {
            viewport: SIZE,
            fov_y_deg: 30.0,
            ..common::camera(eye, eye + Vec3::Z * 10.0, 1.0)
        }
    };
    let right = |x: f32| {
        let pl =
            glam::Vec4::from_array(forest_render::camera::frustum_planes(look(x).view_proj())[1]);
        pl.truncate().dot(sphere.center) + pl.w
    };
    // The plane's distance is linear in the eye's x.
    let (d0, d1) = (right(0.0), right(1.0));
    let x = (-1.02 * r - d0) / (d1 - d0);
    let cam = look(x);
    assert!((right(x) + 1.02 * r).abs() < 1e-3 * r, "{}", right(x));
    let storm = Wind {
        gustiness: 0.0,
        ..Wind::new(90.0, 45.0).at(1.0)
    };
    for (name, method) in [
        ("quads", Method::Quads),
        (
            "geometry",
            Method::Mesh(MeshMethod::Full { depth_sort: true }),
        ),
        ("hybrid", Method::Hybrid(Hybrid::default())),
    ] {
        let mut rd = renderer(&ctx, &forest, Background::Transparent);
        rd.set_method(&ctx, method).unwrap();
        let target = Target::new(&ctx, SIZE.0, SIZE.1);
        let mut visible = |wind: Wind| {
            rd.set_wind(wind).unwrap();
            let stats = rd.render_fitted(&ctx, &cam, &target).unwrap();
            stats.visible_trees
        };
        assert_eq!(
            visible(Wind::CALM),
            0,
            "{name}: the calm tree lies out of view"
        );
        assert_eq!(
            visible(storm),
            1,
            "{name}: the tree the storm bends towards the view was culled"
        );
    }
    // Shadows move with their trees: under a low sun behind the tree (north of it), its
    // shadow falls towards the camera, on the ground in the image's lower third, and moves.
    let cam = Camera {
        viewport: SIZE,
        ..common::camera(
            sphere.center + Vec3::new(6.0, 6.0, -10.0),
            sphere.center * Vec3::new(1.0, 0.0, 1.0),
            1.0,
        )
    };
    for (name, method) in [
        ("quads", Method::Quads),
        (
            "geometry",
            Method::Mesh(MeshMethod::Full { depth_sort: true }),
        ),
    ] {
        let mut rd = renderer(&ctx, &forest, Background::Sky);
        rd.set_method(&ctx, method).unwrap();
        rd.set_light(forest_format::shading::Lighting::with_sun(10.0, 30.0))
            .unwrap();
        rd.set_shadows(&ctx.device, Some(Default::default()))
            .unwrap();
        let calm = frame(&ctx, &mut rd, &cam, Wind::CALM);
        let blown = frame(&ctx, &mut rd, &cam, storm);
        // Ground pixels (the image's lower third) that change.
        let changed = calm
            .enumerate_pixels()
            .zip(blown.pixels())
            .filter(|((_, y, a), b)| *y > SIZE.1 * 2 / 3 && a.0 != b.0)
            .count();
        if changed <= 20 {
            common::failure_images(&format!("wind-shadow-{name}"), &calm, &blown);
        }
        assert!(changed > 20, "{name}: {changed} ground pixels changed");
    }
}
