//! Fidelity where a walkthrough looks: a close-up of one tree and a view from under its crown,
//! the quad stream against the 4×4 supersampled full geometry. The thresholds sit between what
//! the gap-aware bake with directions below the horizon reaches and what the paper's bake
//! (least-squares planes bridging depth gaps, views from below clamped onto the horizon)
//! gives, whose streaks fail them: the test checks both sides.

mod common;

use forest_render::ForestView;
use std::sync::OnceLock;

use forest_baselines::geometry::{GeometryRenderer, GeometrySpecies, PreparedGeometry, downsample};
use forest_format::forest::{Forest, Instance};
use forest_format::{Atlas, BakeParams, PlaneFit};
use forest_render::Camera;
use forest_render::options::{AspectBlend, Background, RendererOptions, StreamOptions};
use forest_render::scene::SpeciesData;
use forest_render::target::{TARGET_FORMAT, Target};
use forest_render::{GpuContext, GpuScene, QuadStream};
use glam::Vec3;

const SIZE: (u32, u32) = (160, 120);
const SS: u32 = 4;

fn model() -> std::path::PathBuf {
    common::root().join("assets/trees/pine/pine.obj")
}

/// Pine at 256 px: the defaults (gap-aware, 5 directions below), and the paper's bake.
fn atlases() -> &'static (Atlas, Atlas) {
    static A: OnceLock<(Atlas, Atlas)> = OnceLock::new();
    A.get_or_init(|| {
        let now = BakeParams {
            resolution: 256,
            spp: 2,
            ..BakeParams::default()
        };
        let paper = BakeParams {
            below: 0,
            plane_fit: PlaneFit::LeastSquares,
            ..now
        };
        let bake = |p: &BakeParams| {
            forest_bake::bake_file(&model(), p, &|_, _| {})
                .unwrap()
                .atlas
        };
        (bake(&now), bake(&paper))
    })
}

fn prepared() -> &'static PreparedGeometry {
    static P: OnceLock<PreparedGeometry> = OnceLock::new();
    P.get_or_init(|| {
        let mesh = forest_bake::Mesh::load(&model()).unwrap();
        PreparedGeometry::new(&[GeometrySpecies::new(
            forest_bake::model::prepare(&mesh, None).into(),
            &atlases().0.manifest,
        )])
    })
}

fn one_pine() -> Forest {
    Forest::new(
        vec!["pine".into()],
        vec![Instance {
            position: [0.0; 3],
            rotation: 0.0,
            scale: 1.0,
            species: 0,
        }],
        15,
    )
}

fn camera(eye: Vec3, target: Vec3, viewport: (u32, u32)) -> Camera {
    Camera {
        eye,
        target,
        fov_y_deg: 60.0,
        near: 0.05,
        far: 200.0,
        viewport,
        epsilon: 2.0,
    }
}

/// The close-up and the view from under the crown, from the atlas's bounding sphere.
fn cameras(atlas: &Atlas) -> [(&'static str, Camera); 2] {
    let s = atlas.manifest.bounding_sphere;
    let (c, r) = (s.center, s.radius);
    [
        (
            "close-up",
            camera(
                Vec3::new(c.x + 0.35 * r, 1.7, c.z + 0.75 * r),
                Vec3::new(c.x, c.y, c.z),
                SIZE,
            ),
        ),
        (
            "from-below",
            camera(
                Vec3::new(c.x + 0.45 * r, 1.2, c.z + 0.3 * r),
                Vec3::new(c.x + 0.1 * r, c.y + 0.8 * r, c.z),
                SIZE,
            ),
        ),
    ]
}

fn render_quads(
    ctx: &GpuContext,
    atlas: &Atlas,
    options: StreamOptions,
    cam: &Camera,
) -> image::RgbaImage {
    let forest = one_pine();
    let species = vec![SpeciesData::decode(atlas.clone(), std::path::Path::new("test")).unwrap()];
    let scene = GpuScene::new(ctx, &species, &forest).unwrap();
    let opts = RendererOptions {
        viewport: SIZE,
        min_epsilon: 2.0,
        background: Background::Transparent,
        ..Default::default()
    };
    let mut stream = QuadStream::new(&ctx.device, scene, &opts).unwrap();
    stream.set_options(options).unwrap();
    let target = Target::new(ctx, SIZE.0, SIZE.1);
    stream.render_frame(ctx, cam, &target).unwrap();
    let img = target.read(ctx);
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    img
}

fn reference(ctx: &GpuContext, cam: &Camera) -> image::RgbaImage {
    let mut geo = GeometryRenderer::new(
        ctx,
        prepared(),
        &one_pine(),
        TARGET_FORMAT,
        Background::Transparent,
    )
    .unwrap();
    let big = Target::new(ctx, SIZE.0 * SS, SIZE.1 * SS);
    let mut c = *cam;
    c.viewport = (SIZE.0 * SS, SIZE.1 * SS);
    geo.set_method(ctx, forest_baselines::geometry::MeshMethod::Reference)
        .unwrap();
    geo.render_frame(ctx, &c, &big).unwrap();
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    downsample(&big.read(ctx), SS)
}

#[test]
fn close_up_and_from_below_beat_the_papers_bake() {
    let ctx = common::ctx();
    let (now, paper) = atlases();
    let out = common::root().join("target/test-output");
    std::fs::create_dir_all(&out).unwrap();
    let paper_options = StreamOptions {
        blend: AspectBlend::Over,
        depth_error: false,
        trim: false,
        far_nearest: false,
        far_composite: false,
        far_span: 1,
        sharpen: 0,
        sharpen_reach: 1,
        opaque_first: false,
    };
    // Mean FLIP ceilings: what the defaults must reach and the paper's bake does not (measured
    // on lavapipe: close-up 0.120 against 0.189, from below 0.289 against 0.324).
    let ceilings = [("close-up", 0.155), ("from-below", 0.306)];
    let mut failures = Vec::new();
    for ((name, cam), (_, ceiling)) in cameras(now).into_iter().zip(ceilings) {
        let want = reference(&ctx, &cam);
        let covered = want.pixels().filter(|p| p[3] >= 128).count();
        assert!(
            covered > (SIZE.0 * SIZE.1 / 4) as usize,
            "{name}: the tree fills the view ({covered} px)"
        );
        let mut results = Vec::new();
        for (label, atlas, options) in [
            ("defaults", now, StreamOptions::default()),
            ("paper", paper, paper_options),
        ] {
            let got = render_quads(&ctx, atlas, options, &cam);
            let (flip, map) = forest_metrics::flip(&want, &got).unwrap();
            eprintln!("{name}, {label}: mean FLIP {flip:.4}");
            let ok = if label == "defaults" {
                flip <= ceiling
            } else {
                flip > ceiling
            };
            // Written every run, for a look; the FLIP map too when the check fails.
            want.save(out.join(format!("fidelity-{name}-reference.png")))
                .unwrap();
            got.save(out.join(format!("fidelity-{name}-{label}-actual.png")))
                .unwrap();
            if !ok {
                map.save(out.join(format!("fidelity-{name}-{label}-flip.png")))
                    .unwrap();
                failures.push(format!(
                    "{name}, {label}: mean FLIP {flip:.4} against the ceiling {ceiling} (images in target/test-output/)"
                ));
            }
            results.push(flip);
        }
        assert!(results[0] < results[1], "{name}: {results:?}");
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
