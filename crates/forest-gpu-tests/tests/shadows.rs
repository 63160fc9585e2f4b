//! The sun's shadows: the light views' streams against the CPU reference, and where a tree's
//! shadow falls on flat ground against the analytic projection of its top.

mod common;

use forest_format::wind::{SwayedTree, Wind};
use forest_render::ForestView;
use forest_render::options::{Background, RendererOptions};
use forest_render::shadow::{ShadowOptions, cameras};
use forest_render::{GpuScene, QuadStream, reference};
use glam::Vec3;

/// Small maps for small test views.
fn small_shadows() -> ShadowOptions {
    ShadowOptions {
        resolution: 256,
        epsilon: 8.0,
        ..Default::default()
    }
}

#[test]
fn light_view_streams_equal_the_cpu_reference() {
    let ctx = common::ctx();
    let forest = common::forest(300);
    let scene = GpuScene::new(&ctx, &common::species(), &forest).unwrap();
    let (mut stream, target) = common::small_stream(&ctx, scene, None);
    let opts = small_shadows();
    stream.set_shadows(&ctx.device, Some(opts)).unwrap();
    let (mut compared, mut composites) = (0, 0);
    for (name, cam) in common::cameras(forest.extent()) {
        stream.render_frame(&ctx, &cam, &target).unwrap();
        let light = cameras(
            &cam.to_gpu(),
            &stream.light(),
            &opts,
            stream.options(),
            stream.scene.band,
        );
        assert_eq!(light.len(), 1 + opts.cascades as usize);
        let sh = stream.shadows().unwrap();
        for (k, s) in sh.streams().iter().enumerate() {
            let gpu = s.read_quads(&ctx);
            let stats = s.read_stats(&ctx);
            let cpu = reference::run_with(
                &s.scene.tables,
                &light[k + 1],
                s.capacity.quads,
                s.iterations(),
            );
            assert_eq!(
                stats.visible_trees, cpu.visible,
                "{name} cascade {k}: visible trees"
            );
            assert_eq!(
                stats.overflow_refine, cpu.overflow_refine,
                "{name} cascade {k}"
            );
            if let Some(i) = gpu.iter().zip(&cpu.quads).position(|(a, b)| a != b) {
                panic!(
                    "{name} cascade {k}: quad {i} differs: GPU {:?} CPU {:?}",
                    gpu[i], cpu.quads[i]
                );
            }
            assert_eq!(
                gpu.len(),
                cpu.quads.len(),
                "{name} cascade {k}: stream length"
            );
            assert_eq!(
                stats.composites,
                cpu.kept_composites(),
                "{name} cascade {k}"
            );
            compared += gpu.len();
            composites += stats.composites;
        }
    }
    assert!(
        compared > 1000,
        "the light views drew {compared} quads in all"
    );
    assert!(composites > 0, "no far tree was composited in a light view");
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
}

/// Ground points (x, z) the shadow of one tree (`atlas`) covers under a sun in direction
/// `sun`: pixels darker with shadows than without, seen by a camera high above the origin;
/// one screen pixel's width on the ground and the ground's shadow-map texel (metres).
fn shadow_points(
    atlas: &forest_format::Atlas,
    sun: Vec3,
    wind: Wind,
) -> (Vec<(f32, f32)>, f32, f32) {
    let ctx = common::ctx();
    let forest = forest_format::forest::Forest::new(
        vec!["pine".into()],
        vec![forest_format::forest::Instance {
            position: [0.0; 3],
            rotation: 0.0,
            scale: 1.0,
            species: 0,
        }],
        15,
    );
    let species =
        forest_render::SpeciesData::decode(atlas.clone(), std::path::Path::new("pine")).unwrap();
    let scene = GpuScene::new(&ctx, &[species], &forest).unwrap();
    let band = scene.band;
    let size = 320;
    let opts = RendererOptions {
        viewport: (size, size),
        background: Background::Sky,
        lighting: forest_format::shading::Lighting {
            sun_dir: sun,
            ..Default::default()
        },
        atmosphere: forest_render::options::Atmosphere::CLEAR,
        ..Default::default()
    };
    let mut stream = QuadStream::new(&ctx.device, scene, &opts).unwrap();
    stream.set_wind(wind).unwrap();
    let target = forest_render::target::Target::new(&ctx, size, size);
    let mut cam = common::camera(Vec3::new(0.0, 60.0, 0.01), Vec3::ZERO, 2.0);
    cam.viewport = (size, size);
    cam.fov_y_deg = 30.0;
    let mut shot = |shadows: Option<ShadowOptions>| {
        stream.set_shadows(&ctx.device, shadows).unwrap();
        stream.render_fitted(&ctx, &cam, &target).unwrap();
        target.read(&ctx)
    };
    let shadows = ShadowOptions {
        resolution: 1024,
        epsilon: 4.0,
        ..Default::default()
    };
    let off = shot(None);
    let on = shot(Some(shadows));
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    // The texel of the cascade the ground (60 m down) falls in.
    let view = forest_render::shadow::ViewSlice {
        view_proj: cam.view_proj(),
        eye: cam.eye,
        forward: cam.forward(),
    };
    let texel = forest_render::shadow::fit_cascades(&view, sun, &shadows, band)
        .iter()
        .find(|c| c.split.1 >= 59.0)
        .map_or(f32::MAX, |c| c.texel);
    let inv = cam.view_proj().inverse();
    let lum = |c: &image::Rgba<u8>| u32::from(c[0]) + u32::from(c[1]) + u32::from(c[2]);
    let mut pts = Vec::new();
    for (x, y, p) in on.enumerate_pixels() {
        if lum(p) * 10 < lum(off.get_pixel(x, y)) * 9 {
            // The pixel's ray down to y = 0.
            let ndc = |z: f32| {
                inv.project_point3(Vec3::new(
                    (x as f32 + 0.5) / size as f32 * 2.0 - 1.0,
                    1.0 - (y as f32 + 0.5) / size as f32 * 2.0,
                    z,
                ))
            };
            let (a, b) = (ndc(0.0), ndc(1.0));
            let g = a + (b - a) * (a.y / (a.y - b.y));
            pts.push((g.x, g.z));
        }
    }
    (
        pts,
        2.0 * 60.0 * 15f32.to_radians().tan() / size as f32,
        texel,
    )
}

/// `obj` baked small with 15 sampling directions (a ring of them at 45°), and one of the
/// atlas's texels across the model (metres).
fn bake_15(obj: &std::path::Path) -> (forest_format::Atlas, f32) {
    let params = forest_format::BakeParams {
        directions: 15,
        resolution: 64,
        min_quad: 4,
        spp: 2,
        ..Default::default()
    };
    let atlas = forest_bake::bake_file(obj, &params, &|_, _| {})
        .unwrap()
        .atlas;
    let texel =
        2.0 * atlas.manifest.bounding_sphere.radius / atlas.manifest.params.resolution as f32;
    (atlas, texel)
}

/// The card of the card tests: one opaque square, 2 m across, lying 3 m above the foot, baked
/// as [`bake_15`] does.
fn card() -> (forest_format::Atlas, f32) {
    let dir = common::root().join("target/test-output/card");
    std::fs::create_dir_all(&dir).unwrap();
    let obj = dir.join("card.obj");
    std::fs::write(
        &obj,
        "v -1 3 -1\nv 1 3 -1\nv 1 3 1\nv -1 3 1\nf 1 2 3\nf 1 3 4\nf 3 2 1\nf 4 3 1\n",
    )
    .unwrap();
    bake_15(&obj)
}

/// The bounds (x min, x max, z min, z max) of ground points, metres.
fn bounds(pts: &[(f32, f32)]) -> [f32; 4] {
    pts.iter().fold(
        [f32::MAX, f32::MIN, f32::MAX, f32::MIN],
        |[x0, x1, z0, z1], p| [x0.min(p.0), x1.max(p.0), z0.min(p.1), z1.max(p.1)],
    )
}

/// The card in a storm, at two instants: its shadow's edges lie where the card's corners,
/// moved by the wind's CPU model (the tree as every method sees the instance: its foot, the
/// top and radius of the baked bounding sphere, instance 0), project along the sun, within
/// the calm test's tolerance and the wind's bending of the card's inside between its corners;
/// the two instants (the card bent least and most in 20 s of a gusty storm) give shadows
/// measurably apart, and the drawn shadow follows.
#[test]
fn a_swaying_cards_shadow_lands_where_the_moved_card_projects() {
    let (atlas, atlas_texel) = card();
    let sphere = atlas.manifest.bounding_sphere;
    let tree = SwayedTree::from_sphere(Vec3::ZERO, 1.0, sphere.center.y, sphere.radius, 0);
    let sun = forest_format::shading::Lighting::with_sun(35.0, 50.0).sun_dir;
    let storm = Wind {
        gustiness: 1.0,
        ..Wind::new(75.0, 35.0)
    };
    // The instants of the first 20 s (every 0.1 s) when the card's middle is bent least and
    // most along the wind, by the CPU model.
    let along = |t: f32| {
        let w = storm.at(t);
        let d = w.direction();
        let moved = w.swayed(Vec3::new(0.0, 3.0, 0.0), &tree);
        moved.x * d.x + moved.z * d.y
    };
    let instants: Vec<f32> = (0..200).map(|i| i as f32 * 0.1).collect();
    let least = instants
        .iter()
        .copied()
        .min_by(|a, b| along(*a).total_cmp(&along(*b)));
    let most = instants
        .iter()
        .copied()
        .max_by(|a, b| along(*a).total_cmp(&along(*b)));
    let mut seen = Vec::new();
    for time in [least.unwrap(), most.unwrap()] {
        let wind = storm.at(time);
        // The moved corners' projections along the sun onto the ground.
        let projected: Vec<(f32, f32)> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .iter()
            .map(|&(x, z)| {
                let p = wind.swayed(Vec3::new(x, 3.0, z), &tree);
                let g = p - sun * (p.y / sun.y);
                (g.x, g.z)
            })
            .collect();
        let want = bounds(&projected);
        let (pts, pixel, texel) = shadow_points(&atlas, sun, wind);
        assert!(pts.len() > 50, "t {time} s: {} shadowed pixels", pts.len());
        let got = bounds(&pts);
        // The card's middle, moved, against the mean of its corners: how far the wind bends
        // the inside away from the corners' straight lines (quads follow their corners).
        let middle = wind.swayed(Vec3::new(0.0, 3.0, 0.0), &tree);
        let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .iter()
            .map(|&(x, z)| wind.swayed(Vec3::new(x, 3.0, z), &tree))
            .sum::<Vec3>()
            / 4.0;
        let bend = (middle - corners).length() / sun.y;
        let tolerance = texel + atlas_texel + pixel + bend;
        for (i, what) in ["x min", "x max", "z min", "z max"].iter().enumerate() {
            assert!(
                (got[i] - want[i]).abs() <= tolerance,
                "t {time} s: the shadow's {what} edge at {:.3} m, the moved card's projects to \
                 {:.3} m (± {tolerance:.3})",
                got[i],
                want[i]
            );
        }
        seen.push((want, got, tolerance));
    }
    // The wind moved the card's shadow between the instants by more than the two
    // tolerances together: each drawn shadow is its own instant's and not the other's.
    let (a, b) = (&seen[0], &seen[1]);
    let moved = (0..4).map(|i| (a.0[i] - b.0[i]).abs()).fold(0.0, f32::max);
    assert!(
        moved > a.2 + b.2,
        "the storm moved the card's shadow only {moved:.3} m between the instants"
    );
    let followed = (0..4).map(|i| (a.1[i] - b.1[i]).abs()).fold(0.0, f32::max);
    assert!(
        followed > moved * 0.5,
        "drawn {followed:.3} m, moved {moved:.3} m"
    );
}

/// One opaque square card, 2 m across, lying 3 m above flat ground: under a low and a high
/// sun its shadow's edges lie where the card's edges project along the sun, within a texel of
/// the shadow map, a texel of the atlas and a pixel of the image that measures them.
#[test]
fn a_cards_shadow_lands_where_the_sun_projects_it() {
    let (atlas, atlas_texel) = card();
    let atlas = &atlas;
    for (az, el) in [(35.0f32, 30.0f32), (200.0, 65.0)] {
        let sun = forest_format::shading::Lighting::with_sun(az, el).sun_dir;
        let (pts, pixel, texel) = shadow_points(atlas, sun, Wind::CALM);
        assert!(pts.len() > 50, "sun {sun}: {} shadowed pixels", pts.len());
        // The card's shadow: the square moved 3 m along the sun's ray down to the ground.
        let shift = -3.0 * Vec3::new(sun.x, 0.0, sun.z) / sun.y;
        let [x0, x1, z0, z1] = bounds(&pts);
        let tolerance = texel + atlas_texel + pixel;
        for (what, got, want) in [
            ("x min", x0, shift.x - 1.0),
            ("x max", x1, shift.x + 1.0),
            ("z min", z0, shift.z - 1.0),
            ("z max", z1, shift.z + 1.0),
        ] {
            assert!(
                (got - want).abs() <= tolerance,
                "sun {az}°, {el}°: the shadow's {what} edge at {got:.3} m, the card's projects \
                 to {want:.3} m (± {tolerance:.3}: map texel {texel:.3}, atlas texel \
                 {atlas_texel:.3}, pixel {pixel:.3})"
            );
        }
    }
}

#[test]
fn a_trees_shadow_falls_where_its_silhouette_projects_along_the_sun() {
    // The sun along sampling directions of the pine's atlas (one aspect draws the light view,
    // so the caster is the baked silhouette itself), low and high: 15 directions have a ring
    // at 45°.
    let pine = common::root().join("assets/trees/pine/pine.obj");
    let (atlas, texel) = bake_15(&pine);
    let atlas = &atlas;
    let mut dirs: Vec<Vec3> = atlas
        .manifest
        .directions
        .iter()
        .map(|f| f.dir)
        .filter(|d| (0.3..0.95).contains(&d.y))
        .collect();
    dirs.sort_by(|a, b| a.y.total_cmp(&b.y));
    assert!(
        !dirs.is_empty(),
        "no sampling direction between 17° and 72°: {dirs:?}"
    );
    let mesh = forest_bake::Mesh::load(&pine).unwrap();
    for sun in [dirs[0], dirs[dirs.len() - 1]] {
        let (pts, pixel, _) = shadow_points(atlas, sun, Wind::CALM);
        assert!(
            pts.len() > 50,
            "sun {sun}: only {} shadowed pixels",
            pts.len()
        );
        // Every vertex's shadow on y = 0, measured along the ground away from the sun.
        let away = -Vec3::new(sun.x, 0.0, sun.z).normalize();
        let along = |p: Vec3| (p - sun * (p.y / sun.y)).dot(away);
        let (lo, hi) = mesh
            .tris
            .iter()
            .flat_map(|t| t.p)
            .fold((f32::MAX, f32::MIN), |(lo, hi), p| {
                (lo.min(along(p)), hi.max(along(p)))
            });
        let (got_lo, got_hi) = pts
            .iter()
            .map(|&(x, z)| Vec3::new(x, 0.0, z).dot(away))
            .fold((f32::MAX, f32::MIN), |(lo, hi), d| (lo.min(d), hi.max(d)));
        // The bound: two of the atlas's texels (its silhouette), stretched along the ground
        // by the sun's slant, and two screen pixels.
        let tolerance = 2.0 * texel / sun.y + 2.0 * pixel;
        // Nothing is shadowed beyond where the silhouette projects (no misplaced or detached
        // shadow) ...
        assert!(
            got_hi < hi + tolerance && got_lo > lo - tolerance,
            "sun {sun}: the shadow spans {got_lo:.2} to {got_hi:.2} m along the ground, the \
             silhouette projects to {lo:.2} to {hi:.2} m (± {tolerance:.2})"
        );
        // ... and the shadow reaches most of the way: the crown's top is sparse needles that
        // cover a small share of their texels and cast a shadow too faint for the mask (10 %
        // darker) at the very tip (measured: 4.47 of 5.37 m and 4.89 of 4.89 m).
        assert!(
            got_hi > 0.75 * hi,
            "sun {sun}: the shadow reaches {got_hi:.2} m, the silhouette projects to {hi:.2} m"
        );
        // It runs away from the sun: the shadowed points' centre lies on the sun's azimuth.
        let side = Vec3::Y.cross(away);
        let n = pts.len() as f32;
        let (a, l) = pts.iter().fold((0.0, 0.0), |(a, l), &(x, z)| {
            let p = Vec3::new(x, 0.0, z);
            (a + p.dot(away) / n, l + p.dot(side) / n)
        });
        assert!(
            a > 0.0 && l.abs() < 0.1 * a + 2.0 * pixel,
            "sun {sun}: the shadow's centre lies {a:.2} m along the sun's azimuth and {l:.2} m \
             aside"
        );
    }
}

/// Pixels of flat ground a method's shadows darken (by 10 % or more) in a view from above,
/// and the image with shadows.
fn shadow_mask(
    ctx: &forest_render::GpuContext,
    r: &mut forest_baselines::methods::ForestRenderer,
    method: forest_baselines::methods::Method,
    cam: &forest_render::Camera,
) -> (Vec<bool>, image::RgbaImage) {
    r.set_method(ctx, method).unwrap();
    let target = forest_render::target::Target::new(ctx, cam.viewport.0, cam.viewport.1);
    let shot = |r: &mut forest_baselines::methods::ForestRenderer, on: bool| {
        let o = ShadowOptions {
            resolution: 1024,
            epsilon: 4.0,
            ..Default::default()
        };
        r.set_shadows(&ctx.device, on.then_some(o)).unwrap();
        r.render_fitted(ctx, cam, &target).unwrap();
        target.read(ctx)
    };
    let off = shot(r, false);
    let on = shot(r, true);
    let lum = |c: &image::Rgba<u8>| u32::from(c[0]) + u32::from(c[1]) + u32::from(c[2]);
    let mask = on
        .pixels()
        .zip(off.pixels())
        .map(|(a, b)| lum(a) * 10 < lum(b) * 9)
        .collect();
    (mask, on)
}

#[test]
fn the_quad_stream_casts_the_shadow_full_geometry_casts() {
    let ctx = common::ctx();
    let forest = common::one_tree(1, 0.3);
    let size = 256;
    // The bundled atlases' 20 directions (the tests' usual 5 have none between the horizon
    // and the zenith, so a 40° sun blends two aspects unlike its view).
    let atlases = common::atlases_with(&forest_format::BakeParams {
        directions: 20,
        resolution: 64,
        min_quad: 4,
        spp: 2,
        ..Default::default()
    });
    let mut r = common::forest_renderer(
        &ctx,
        &common::species_of(&atlases),
        &common::prepared_for(&atlases),
        &forest,
        (size, size),
        Background::Sky,
        forest_render::options::Atmosphere::CLEAR,
    );
    r.set_light(forest_format::shading::Lighting::with_sun(120.0, 40.0))
        .unwrap();
    let mut cam = common::camera(Vec3::new(0.0, 60.0, 0.01), Vec3::ZERO, 2.0);
    cam.viewport = (size, size);
    cam.fov_y_deg = 30.0;
    use forest_baselines::methods::Method;
    let (geometry, geometry_image) = shadow_mask(
        &ctx,
        &mut r,
        Method::Mesh(forest_baselines::geometry::MeshMethod::Full { depth_sort: true }),
        &cam,
    );
    let (quads, quads_image) = shadow_mask(&ctx, &mut r, Method::Quads, &cam);
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    let both = geometry
        .iter()
        .zip(&quads)
        .filter(|(a, b)| **a && **b)
        .count();
    let either = geometry
        .iter()
        .zip(&quads)
        .filter(|(a, b)| **a || **b)
        .count();
    let (g, q) = (
        geometry.iter().filter(|x| **x).count(),
        quads.iter().filter(|x| **x).count(),
    );
    let iou = both as f64 / either.max(1) as f64;
    // Measured: 394 and 501 pixels, IoU 0.728 (the shadow is small: its rim is most of it).
    // The cascades cover only the depths where the tree and ground are, so the ground's
    // texels are finer than the view's whole depth range gave (501 and 497 pixels, IoU 0.742
    // then): the alpha-tested leaves leave gaps of full sun, while the quads' coverage, from
    // a 64-texel test atlas, spreads a partial shadow over them.
    if !(g > 100 && q > 100 && iou > 0.65 && q.abs_diff(g) * 10 < g * 3) {
        let out = common::root().join("target/test-output");
        std::fs::create_dir_all(&out).unwrap();
        geometry_image
            .save(out.join("shadow-cast-geometry.png"))
            .unwrap();
        quads_image.save(out.join("shadow-cast-quads.png")).unwrap();
        panic!(
            "ground shadows: geometry {g} pixels, quads {q}, IoU {iou:.3} (at least 0.65, areas \
             within 30 %); images in {}",
            out.display()
        );
    }
}

#[test]
fn a_hosts_reverse_z_shadow_map_gives_the_forests_own_shadows() {
    let ctx = common::ctx();
    let forest = common::forest(300);
    let scene = std::sync::Arc::new(GpuScene::new(&ctx, &common::species(), &forest).unwrap());
    let (w, h) = (160, 120);
    let view_opts = RendererOptions {
        viewport: (w, h),
        min_epsilon: 4.0,
        ..Default::default()
    };
    let cam = common::cameras(forest.extent())[0].1;
    let shadows = small_shadows();
    let target = forest_render::target::Target::new(&ctx, w, h);
    // The forest's own maps.
    let mut own = QuadStream::new(&ctx.device, scene.clone(), &view_opts).unwrap();
    own.set_shadows(&ctx.device, Some(shadows)).unwrap();
    own.render_fitted(&ctx, &cam, &target).unwrap();
    let expected = target.read(&ctx);
    let mut plain = QuadStream::new(&ctx.device, scene.clone(), &view_opts).unwrap();
    plain.render_fitted(&ctx, &cam, &target).unwrap();
    let unshadowed = target.read(&ctx);

    // The host's: the same cascades, in reverse-Z (depth 1 − z), in its own depth array.
    let sun = own.light().sun_dir;
    let g = cam.to_gpu();
    let view = forest_render::shadow::ViewSlice {
        view_proj: glam::Mat4::from_cols_array_2d(&g.view_proj),
        eye: cam.eye,
        forward: cam.forward(),
    };
    let flip = glam::Mat4::from_cols(
        glam::Vec4::X,
        glam::Vec4::Y,
        glam::Vec4::new(0.0, 0.0, -1.0, 0.0),
        glam::Vec4::new(0.0, 0.0, 1.0, 1.0),
    );
    let cascades: Vec<_> =
        forest_render::shadow::fit_cascades(&view, sun, &shadows, own.scene.band)
            .into_iter()
            .map(|c| forest_render::shadow::Cascade {
                view_proj: flip * c.view_proj,
                ..c
            })
            .collect();
    let res = shadows.resolution;
    let maps = ctx.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("host shadow maps"),
        size: wgpu::Extent3d {
            width: res,
            height: res,
            depth_or_array_layers: cascades.len() as u32,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Depth32Float,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    });
    let caster_opts = RendererOptions {
        viewport: (res, res),
        min_epsilon: shadows.epsilon,
        depth_format: wgpu::TextureFormat::Depth32Float,
        reverse_z: true,
        ..Default::default()
    };
    let mut casters: Vec<QuadStream> = cascades
        .iter()
        .map(|_| QuadStream::new(&ctx.device, scene.clone(), &caster_opts).unwrap())
        .collect();
    let mut encoder = ctx.device.create_command_encoder(&Default::default());
    for (k, (c, caster)) in cascades.iter().zip(&mut casters).enumerate() {
        let light = forest_render::shadow::LightParams {
            view_proj: c.view_proj,
            to_light: sun,
            resolution: (res, res),
            epsilon: shadows.epsilon,
            view_eye: cam.eye,
        };
        caster
            .prepare_light(&ctx.device, &ctx.queue, &light)
            .unwrap();
        caster.encode_compute(&mut encoder);
        let layer = maps.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2),
            base_array_layer: k as u32,
            array_layer_count: Some(1),
            ..Default::default()
        });
        let mut pass = forest_render::extend::depth_pass(&mut encoder, &layer, 0.0, None);
        caster.render_depth(&mut pass);
    }
    ctx.queue.submit([encoder.finish()]);
    let array = maps.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    let mut host = QuadStream::new(&ctx.device, scene, &view_opts).unwrap();
    host.receive_host_shadows(&ctx.device, Some((&array, res, true)));
    host.set_host_cascades(&cascades).unwrap();
    host.render_fitted(&ctx, &cam, &target).unwrap();
    let got = target.read(&ctx);
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    let differ = |a: &image::RgbaImage, b: &image::RgbaImage| {
        a.pixels()
            .zip(b.pixels())
            .filter(|(p, q)| p.0.iter().zip(q.0).any(|(x, y)| x.abs_diff(y) > 2))
            .count()
    };
    let (shadowed, mismatched) = (differ(&expected, &unshadowed), differ(&got, &expected));
    // Only the rare texel where the two depth conventions round apart may differ.
    if shadowed < 500 || mismatched * 200 > (w * h) as usize {
        let out = common::root().join("target/test-output");
        std::fs::create_dir_all(&out).unwrap();
        expected.save(out.join("shadow-host-own.png")).unwrap();
        got.save(out.join("shadow-host-reverse-z.png")).unwrap();
        panic!(
            "{shadowed} pixels shadowed by the forest's own maps; the host's reverse-Z maps \
             differ from them in {mismatched} (images in {})",
            out.display()
        );
    }
}
