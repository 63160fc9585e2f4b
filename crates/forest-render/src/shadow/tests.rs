//! Tests of `shadow.rs`.

use super::*;

fn view(eye: Vec3, target: Vec3) -> ViewSlice {
    let cam = crate::Camera {
        eye,
        target,
        fov_y_deg: 60.0,
        near: 0.5,
        far: 2000.0,
        viewport: (1600, 900),
        epsilon: 4.0,
    };
    ViewSlice {
        view_proj: cam.view_proj(),
        eye: cam.eye,
        forward: cam.forward(),
    }
}

#[test]
fn splits_run_from_near_to_the_shadow_distance() {
    let s = split_depths(1.0, 100.0, 2, 1.0);
    assert_eq!(s.len(), 3);
    assert!((s[1] - 10.0).abs() < 1e-4, "logarithmic middle {}", s[1]);
    let s = split_depths(1.0, 101.0, 2, 0.0);
    assert!((s[1] - 51.0).abs() < 1e-4, "uniform middle {}", s[1]);
}

#[test]
fn a_slice_sphere_touches_its_farthest_corners() {
    // A slice from 10 to 20 m whose edges spread 0.5 m per metre.
    let (z, r) = slice_sphere(10.0, 20.0, 0.5);
    assert!((10.0..=20.0).contains(&z));
    let near = ((z - 10.0).powi(2) + 25.0).sqrt();
    let far = ((20.0 - z).powi(2) + 100.0).sqrt();
    assert!((r - near.max(far)).abs() < 1e-4);
    // Interior centre: both ends touch the sphere.
    assert!((near - far).abs() < 1e-3, "{near} {far}");
}

#[test]
fn every_point_of_a_slice_lands_inside_its_cascade() {
    let v = view(Vec3::new(3.0, 1.7, -4.0), Vec3::new(40.0, 4.0, 30.0));
    let sun = Vec3::new(0.4, 0.5, 0.3).normalize();
    let opts = ShadowOptions::default();
    let cascades = fit_cascades(&v, sun, &opts, ReceiverBand::ANY);
    assert_eq!(cascades.len(), 3);
    let inv = v.view_proj.inverse();
    for c in &cascades {
        for (x, y) in [
            (-1.0, -1.0),
            (1.0, -1.0),
            (-1.0, 1.0),
            (1.0, 1.0),
            (0.0, 0.0),
        ] {
            // The corner ray's points at the slice's two depths.
            let p = inv.project_point3(Vec3::new(x, y, 0.5));
            let r = p - v.eye;
            let r = r / r.dot(v.forward);
            for d in [c.split.0, c.split.1] {
                let s = c.view_proj.project_point3(v.eye + r * d);
                assert!(
                    s.x.abs() <= 1.0 + 1e-4 && s.y.abs() <= 1.0 + 1e-4,
                    "{s} outside cascade {c:?}"
                );
                assert!((0.0..=1.0).contains(&s.z), "depth {}", s.z);
            }
        }
        // A point `reach` towards the sun from the far edge of the sphere is still in
        // the box; beyond that it is not.
        let top = c.centre + sun * (c.radius + opts.reach * 0.99);
        assert!(c.view_proj.project_point3(top).z >= 0.0);
        let beyond = c.centre + sun * (c.radius + opts.reach * 1.01);
        assert!(c.view_proj.project_point3(beyond).z < 0.0);
    }
}

/// A caster culled from a cascade has no point of its swept sphere over any receiver
/// of the cascade's slice (sampled: points of the slice above the floor, the sweep down
/// to the floor), for seeded random views, suns and casters; and the cull drops some.
#[test]
fn culled_casters_cannot_shadow_the_slice() {
    let mut seed = 0x9e37_79b9_u32;
    let mut rnd = move || {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed as f32 / u32::MAX as f32
    };
    let opts = ShadowOptions::default();
    let floor = -2.0;
    let (mut culled, mut kept) = (0, 0);
    for _ in 0..12 {
        let eye = Vec3::new(rnd() * 40.0 - 20.0, 1.0 + rnd() * 60.0, rnd() * 40.0 - 20.0);
        let look = Vec3::new(rnd() * 2.0 - 1.0, -rnd() * 0.8, rnd() * 2.0 - 1.0);
        let cam = crate::Camera {
            eye,
            target: eye + look,
            fov_y_deg: 50.0,
            near: 0.5,
            far: 2000.0,
            viewport: (160, 90),
            epsilon: 4.0,
        };
        let light = forest_format::shading::Lighting::with_sun(rnd() * 360.0, 8.0 + rnd() * 80.0);
        let g = cam.to_gpu();
        let band = ReceiverBand {
            floor,
            top: f32::MAX,
        };
        let all = cameras(&g, &light, &opts, Default::default(), band);
        let inv = cam.view_proj().inverse();
        let forward = cam.forward();
        for (k, l) in all[1..].iter().enumerate() {
            let split = (
                if k == 0 {
                    0.0
                } else {
                    all[0].shadow_splits[k - 1]
                },
                all[0].shadow_splits[k],
            );
            // Receivers: points of the view slice above the floor.
            let mut receivers = Vec::new();
            for _ in 0..3000 {
                let ray =
                    inv.project_point3(Vec3::new(rnd() * 2.0 - 1.0, rnd() * 2.0 - 1.0, 0.5)) - eye;
                let d = split.0 + rnd() * (split.1 - split.0);
                let p = eye + ray * (d / ray.dot(forward));
                if p.y >= floor {
                    receivers.push(p);
                }
            }
            for _ in 0..200 {
                let c = eye
                    + Vec3::new(rnd() - 0.5, rnd() * 0.5 - 0.2, rnd() - 0.5)
                        * (2.0 * split.1 + 40.0);
                let c = Vec3::new(c.x, c.y.max(floor), c.z);
                let r = 1.0 + rnd() * 8.0;
                if casts_into(l, c, r) {
                    kept += 1;
                    continue;
                }
                culled += 1;
                let sun = light.sun_dir;
                let len = l.caster_floor[1].min((c.y + r - floor).max(0.0) / sun.y);
                for p in &receivers {
                    // Distance from p to the segment c → c − len·sun.
                    let t = (c - *p).dot(sun).clamp(0.0, len);
                    let q = c - sun * t;
                    assert!(
                        q.distance(*p) > r,
                        "cascade {k}: culled caster {c} r {r} shadows {p}"
                    );
                }
            }
        }
    }
    assert!(culled > 500 && kept > 500, "culled {culled}, kept {kept}");
}

/// Cascades cover only the depths where the view meets the receivers' heights: looking
/// straight down from 50 m on trees up to 20 m, the depths 29.3 to 50.5 m; a walker's
/// view meets them everywhere and keeps the cascades it has without a band.
#[test]
fn cascades_cover_only_the_depths_where_receivers_can_be() {
    let opts = ShadowOptions::default();
    let sun = Vec3::new(0.3, 0.8, 0.2).normalize();
    let band = ReceiverBand {
        floor: 0.0,
        top: 20.0,
    };
    let down = view(Vec3::new(0.0, 50.0, 0.0), Vec3::new(0.0, 0.0, 0.01));
    let c = fit_cascades(&down, sun, &opts, band);
    let (pad_top, pad_floor) = (0.5 + 0.2, 0.5);
    assert!(
        (c[0].split.0 - (30.0 - pad_top)).abs() < 0.05,
        "{:?}",
        c[0].split
    );
    let last = c.last().unwrap().split.1;
    assert!((last - (50.0 + pad_floor)).abs() < 0.05, "ends at {last}");
    // The ground's cascade, 49 m down, is finer than without the band, and its sphere is
    // within 10 % of the view's cross-section there (half its diagonal: no fit is smaller).
    let all = fit_cascades(&down, sun, &opts, ReceiverBand::ANY);
    let ground = |cs: &[Cascade]| *cs.iter().find(|c| c.split.1 >= 49.0).unwrap();
    assert!(ground(&c).texel < 0.8 * ground(&all).texel);
    let t = 30f32.to_radians().tan();
    let half_diagonal = 50.5 * (t * t + (t * 16.0 / 9.0).powi(2)).sqrt();
    assert!(
        ground(&c).radius < 1.1 * half_diagonal,
        "{} vs {half_diagonal}",
        ground(&c).radius
    );
    let walk = view(Vec3::new(3.0, 1.7, 2.0), Vec3::new(40.0, 3.0, 60.0));
    assert_eq!(
        fit_cascades(&walk, sun, &opts, band),
        fit_cascades(&walk, sun, &opts, ReceiverBand::ANY)
    );
}

#[test]
fn turning_or_moving_the_camera_moves_cascades_by_whole_texels() {
    let sun = Vec3::new(-0.3, 0.6, 0.5).normalize();
    let opts = ShadowOptions::default();
    let a = fit_cascades(
        &view(Vec3::new(0.0, 2.0, 0.0), Vec3::new(10.0, 2.0, 30.0)),
        sun,
        &opts,
        ReceiverBand::ANY,
    );
    let b = fit_cascades(
        &view(Vec3::new(0.37, 2.0, 0.11), Vec3::new(-20.0, 3.0, 25.0)),
        sun,
        &opts,
        ReceiverBand::ANY,
    );
    let rot = light_rotation(sun);
    for (a, b) in a.iter().zip(&b) {
        assert_eq!(a.radius, b.radius, "the map's scale does not change");
        // A fixed world point's texel position differs by a whole number of texels.
        let p = Vec3::new(5.0, 0.0, 12.0);
        let ta = a.view_proj.project_point3(p) * 0.5 * opts.resolution as f32;
        let tb = b.view_proj.project_point3(p) * 0.5 * opts.resolution as f32;
        for d in [(ta.x - tb.x), (ta.y - tb.y)] {
            assert!((d - d.round()).abs() < 2e-2, "shift {d} texels");
        }
        let ca = rot.transform_point3(a.centre) / a.texel;
        assert!((ca.x - ca.x.round()).abs() < 1e-2);
    }
}

#[test]
fn a_light_camera_looks_down_the_sun_from_afar() {
    let sun = Vec3::new(0.2, 0.9, 0.1).normalize();
    let opts = ShadowOptions::default();
    let cascades = fit_cascades(
        &view(Vec3::ZERO + Vec3::Y, Vec3::new(0.0, 1.0, 10.0)),
        sun,
        &opts,
        ReceiverBand::ANY,
    );
    let g = light_camera(&cascades[0], sun, &opts, Default::default());
    let eye = Vec3::from_slice(&g.eye[..]);
    assert!((eye - cascades[0].centre).normalize().dot(sun) > 0.999_999);
    assert_eq!(g.viewport[0], opts.resolution as f32);
    assert_eq!(g.epsilon, opts.epsilon);
    assert_eq!(
        g.stream_flags as u32,
        crate::options::StreamOptions::default().flags()
    );
}

#[test]
fn bad_options_are_named() {
    let bad = [
        ShadowOptions {
            cascades: 0,
            ..Default::default()
        },
        ShadowOptions {
            cascades: 5,
            ..Default::default()
        },
        ShadowOptions {
            resolution: 16,
            ..Default::default()
        },
        ShadowOptions {
            distance: f32::NAN,
            ..Default::default()
        },
        ShadowOptions {
            split_lambda: 1.5,
            ..Default::default()
        },
        ShadowOptions {
            reach: -1.0,
            ..Default::default()
        },
    ];
    for o in bad {
        assert!(o.validate().is_err(), "{o:?}");
    }
    assert!(ShadowOptions::default().validate().is_ok());
}
