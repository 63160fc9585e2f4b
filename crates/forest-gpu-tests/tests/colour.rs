//! Every tree its own colour: the GPU colours every point as the CPU mirror
//! (`forest_format::colour`) does, wood keeps its colour through the seasons (in the model
//! and, with a bark-only bush and pine, in every method's images), every method
//! gives the same tree the same colour, and a forest without variation and without a season
//! draws today's images bit for bit.

mod common;

use forest_baselines::methods::ForestRenderer;
use forest_format::colour::{self, Colouring, SpeciesColour, TreeColour};
use forest_format::forest::{Forest, Instance};
use forest_render::gpu_types::GpuCamera;
use forest_render::options::{Atmosphere, Background};
use forest_render::target::Target;
use forest_render::{Camera, ForestView, GpuContext};
use glam::Vec3;

/// A compute module evaluating `tree_albedo` for each input.
const HARNESS: &str = r#"
#import common
#import tint
@group(0) @binding(0) var<uniform> camera: Camera;
@group(0) @binding(1) var<storage, read> colours: array<TreeColour>;
// Per sample: the albedo (xyz) and translucency (w); x: the key's bits, y: the colour.
@group(0) @binding(2) var<storage, read> samples: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> out: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (2u * i + 1u >= arrayLength(&samples)) { return; }
    let a = samples[2u * i];
    let b = samples[2u * i + 1u];
    let key = bitcast<u32>(b.x);
    out[i] = vec4<f32>(tree_albedo(a.xyz, a.w, key, colours[bitcast<u32>(b.y)]),
                       tree_randoms(key).w);
}
"#;

/// One sample: albedo, translucency, key, index of its colour.
type Sample = (Vec3, f32, u32, u32);

/// The GPU's `tree_albedo` (xyz) and the season phase's random (w) of each sample.
fn gpu_albedo(
    ctx: &GpuContext,
    season: Option<f32>,
    colours: &[TreeColour],
    samples: &[Sample],
) -> Vec<[f32; 4]> {
    let mut cam = GpuCamera::default();
    cam.set_season(season);
    let data: Vec<[f32; 4]> = samples
        .iter()
        .flat_map(|(a, tau, key, c)| {
            [
                [a.x, a.y, a.z, *tau],
                [f32::from_bits(*key), f32::from_bits(*c), 0.0, 0.0],
            ]
        })
        .collect();
    common::run_harness(
        ctx,
        HARNESS,
        bytemuck::bytes_of(&cam),
        &[bytemuck::cast_slice(colours), bytemuck::cast_slice(&data)],
        samples.len(),
    )
}

#[test]
fn the_gpu_colours_every_tree_as_the_cpu_mirror_and_leaves_wood_alone() {
    let ctx = common::ctx();
    let colours = [
        TreeColour::NONE,
        SpeciesColour::DECIDUOUS.gpu(1.0),
        SpeciesColour::EVERGREEN.gpu(0.5),
        SpeciesColour::DECIDUOUS.gpu(colour::MAX_AMOUNT),
    ];
    let mut rng = forest_format::noise::SplitMix64(66);
    let mut samples: Vec<Sample> = Vec::new();
    for k in 0..512u32 {
        let a = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 0.6;
        // Leaves, wood and the mixes coarse texels hold; hashed and explicit keys.
        let tau = [0.35, 0.0, 0.35 * rng.next_f32(), 0.5][k as usize % 4];
        let key = if k % 3 == 0 {
            colour::explicit_code(rng.next_f32())
        } else {
            rng.next_u64() as u32
        };
        samples.push((a, tau, key, k % colours.len() as u32));
    }
    let mut calm_bark = None;
    for season in [None, Some(0.0), Some(0.3), Some(2.0 / 3.0), Some(1.0)] {
        let gpu = gpu_albedo(&ctx, season, &colours, &samples);
        let s = season.unwrap_or(-1.0);
        let mut worst = 0.0f32;
        for ((a, tau, key, c), g) in samples.iter().zip(&gpu) {
            let cpu = colour::tree_albedo(*a, *tau, *key, &colours[*c as usize], s);
            let got = Vec3::new(g[0], g[1], g[2]);
            worst = worst.max((cpu - got).abs().max_element());
            // The hash is exact on both sides.
            assert_eq!(g[3], colour::randoms(*key)[3], "key {key}");
            if *c == 0 && season.is_none() {
                // No colouring and no season: the albedo itself, bit for bit.
                assert_eq!(
                    got.to_array().map(f32::to_bits),
                    a.to_array().map(f32::to_bits)
                );
            }
        }
        assert!(
            worst < 2e-6,
            "season {season:?}: GPU and CPU differ by {worst}"
        );
        // Wood (translucency 0) keeps one colour through every season, on the GPU.
        let bark: Vec<[f32; 4]> = samples
            .iter()
            .zip(&gpu)
            .filter(|((_, tau, _, _), _)| *tau == 0.0)
            .map(|(_, g)| *g)
            .collect();
        assert!(!bark.is_empty());
        match &calm_bark {
            None => calm_bark = Some(bark),
            Some(b) => assert_eq!(b, &bark, "season {season:?} changed the bark"),
        }
    }
}

const SIZE: (u32, u32) = (160, 80);

/// Two bushes side by side, 2.4 crown radii apart along x, each given its own explicit value.
fn pair(colouring: Option<Colouring>) -> Forest {
    let r = common::atlases()[0].manifest.bounding_sphere.radius;
    let tree = |x: f32| Instance {
        position: [x, 0.0, 0.0],
        rotation: 0.0,
        scale: 1.0,
        species: 0,
    };
    let f = Forest::new(
        vec!["bush".into(), "pine".into()],
        vec![tree(-1.2 * r), tree(1.2 * r)],
        15,
    );
    match colouring {
        Some(c) => f.with_colouring(c),
        None => f,
    }
}

fn view() -> Camera {
    let s = common::atlases()[0].manifest.bounding_sphere;
    Camera {
        viewport: SIZE,
        ..common::camera(
            s.center + Vec3::new(0.0, 0.0, -4.0 * s.radius),
            s.center,
            1.0,
        )
    }
}

/// Every method's frame of `forest` in `season`.
fn frames(ctx: &GpuContext, forest: &Forest, season: Option<f32>) -> Vec<image::RgbaImage> {
    let mut r: ForestRenderer = common::forest_renderer(
        ctx,
        &common::species(),
        common::prepared(),
        forest,
        SIZE,
        Background::Transparent,
        Atmosphere::CLEAR,
    );
    r.set_season(season).unwrap();
    common::every_method()
        .into_iter()
        .map(|(_, m)| {
            r.set_method(ctx, m).unwrap();
            let target = Target::new(ctx, SIZE.0, SIZE.1);
            r.render_fitted(ctx, &view(), &target).unwrap();
            assert_eq!(ctx.take_errors(), Vec::<String>::new());
            target.read(ctx)
        })
        .collect()
}

/// The mean colour (linear RGB) of the covered pixels of the left and right halves.
fn halves(img: &image::RgbaImage) -> [Vec3; 2] {
    let decode = |v: u8| forest_format::shading::srgb_decode(f32::from(v) / 255.0);
    let mut sum = [Vec3::ZERO; 2];
    let mut n = [0usize; 2];
    for (x, _, p) in img.enumerate_pixels() {
        if p[3] > 128 {
            let h = usize::from(x >= img.width() / 2);
            // Premultiplied over transparent black: undo the coverage.
            let a = f32::from(p[3]) / 255.0;
            sum[h] += Vec3::new(decode(p[0]), decode(p[1]), decode(p[2])) / a;
            n[h] += 1;
        }
    }
    assert!(n.iter().all(|&n| n > 100), "covered pixels {n:?}");
    [sum[0] / n[0] as f32, sum[1] / n[1] as f32]
}

#[test]
fn every_method_gives_each_tree_the_same_colour() {
    let ctx = common::ctx();
    let mut colouring = Colouring::new(
        colour::MAX_AMOUNT,
        vec![SpeciesColour::DECIDUOUS, SpeciesColour::EVERGREEN],
    );
    // Two values whose hue turns lie far apart.
    let (v0, v1) = (0..200)
        .flat_map(|i| (0..200).map(move |j| (i as f32 / 200.0, j as f32 / 200.0)))
        .max_by(|a, b| {
            let d = |(x, y): (f32, f32)| {
                (colour::randoms(colour::explicit_code(x))[0]
                    - colour::randoms(colour::explicit_code(y))[0])
                    .abs()
            };
            d(*a).total_cmp(&d(*b))
        })
        .unwrap();
    colouring.explicit = vec![v0, v1];
    let forest = pair(Some(colouring.clone()));
    let names: Vec<&str> = common::every_method().iter().map(|(n, _)| *n).collect();
    let r = names.iter().position(|n| *n == "reference").unwrap();
    let summer = frames(&ctx, &forest, None);
    let reference = halves(&summer[r]);
    let apart = colour::delta_e(reference[0], reference[1]);
    assert!(apart > 10.0, "the two trees differ by ΔE {apart} only");
    for (name, img) in names.iter().zip(&summer) {
        let m = halves(img);
        eprintln!(
            "{name}: ΔE to the reference's trees {:.2} {:.2}, the trees ΔE {apart:.2} apart",
            colour::delta_e(m[0], reference[0]),
            colour::delta_e(m[1], reference[1])
        );
        for t in 0..2 {
            let own = colour::delta_e(m[t], reference[t]);
            let other = colour::delta_e(m[t], reference[1 - t]);
            if own >= 0.5 * other {
                common::failure_images(&format!("colour-{name}"), &summer[r], img);
            }
            assert!(
                own < 0.5 * other,
                "{name}: tree {t} lies ΔE {own:.2} from its reference colour and {other:.2} \
                 from the other tree's"
            );
        }
    }
    // In autumn every method turns both trees' leaves from green towards red (CIELAB a*) by
    // about as much as the reference does (at the natural amount, where the season outweighs
    // a tree's own hue).
    let natural = pair(Some(Colouring {
        amount: 1.0,
        ..colouring
    }));
    let summer = frames(&ctx, &natural, None);
    let autumn = frames(&ctx, &natural, Some(2.0 / 3.0));
    let turn = |k: usize, t: usize| {
        colour::lab(halves(&autumn[k])[t]).y - colour::lab(halves(&summer[k])[t]).y
    };
    for (k, name) in names.iter().enumerate() {
        for t in 0..2 {
            let (own, want) = (turn(k, t), turn(r, t));
            eprintln!("{name}: tree {t}'s a* rises by {own:.2} in autumn (reference {want:.2})");
            assert!(want > 8.0, "the reference's tree {t} turns by {want} only");
            assert!(
                (own - want).abs() < 0.3 * want,
                "{name}: tree {t}'s a* rises by {own:.2} in autumn, the reference's by {want:.2}"
            );
        }
    }
}

#[test]
fn without_variation_or_a_season_every_method_draws_todays_images() {
    let ctx = common::ctx();
    let plain = frames(&ctx, &pair(None), None);
    let zero = Colouring {
        explicit: vec![0.2, 0.9],
        ..Colouring::new(0.0, vec![SpeciesColour::DECIDUOUS; 2])
    };
    let still = frames(&ctx, &pair(Some(zero)), None);
    let varied = frames(
        &ctx,
        &pair(Some(Colouring::new(1.0, vec![SpeciesColour::DECIDUOUS; 2]))),
        None,
    );
    for (((name, _), a), (b, c)) in common::every_method()
        .iter()
        .zip(&plain)
        .zip(still.iter().zip(&varied))
    {
        assert!(
            a.as_raw() == b.as_raw(),
            "{name}: amount 0 changed the image"
        );
        assert!(
            a.as_raw() != c.as_raw(),
            "{name}: amount 1 left the image as it was"
        );
    }
}

/// Bush and pine without their leaves: every triangle of a translucent (leaf) material
/// dropped. Returns the decoded atlases and the geometry methods' preparation of them.
fn bark_only() -> (
    Vec<forest_render::scene::SpeciesData>,
    forest_baselines::geometry::PreparedGeometry,
) {
    let mut atlases = Vec::new();
    let mut geometry = Vec::new();
    for s in ["bush", "pine"] {
        let mut mesh =
            forest_bake::Mesh::load(&common::root().join(format!("assets/trees/{s}/{s}.obj")))
                .unwrap();
        let all = mesh.tris.len();
        let materials = mesh.materials.clone();
        mesh.tris
            .retain(|t| materials[t.material as usize].translucency == 0.0);
        assert!(
            mesh.tris.len() > 100 && mesh.tris.len() < all,
            "{s}: {} of {all} triangles are wood",
            mesh.tris.len()
        );
        let atlas = forest_bake::bake_mesh(&mesh, s, &common::small_params(), &|_, _| {})
            .unwrap()
            .atlas;
        geometry.push(forest_baselines::geometry::GeometrySpecies::new(
            forest_bake::model::prepare(&mesh, None).into(),
            &atlas.manifest,
        ));
        atlases.push(atlas);
    }
    (
        common::species_of(&atlases),
        forest_baselines::geometry::PreparedGeometry::with_cards(
            &geometry,
            forest_baselines::geometry::Cards::Cut,
        ),
    )
}

#[test]
fn a_bark_only_model_keeps_its_colour_through_every_season() {
    let ctx = common::ctx();
    let (species, prepared) = bark_only();
    // The bush (deciduous by its name) beside the pine (evergreen), without a colouring and
    // with one at the natural amount (whose bark shifts per tree, but never with the season).
    let pine = species[1].atlas.manifest.bounding_sphere;
    let trees = |colouring: Option<Colouring>| {
        let tree = |x: f32, species: u32| Instance {
            position: [x, 0.0, 0.0],
            rotation: 0.0,
            scale: 1.0,
            species,
        };
        let f = Forest::new(
            vec!["bush".into(), "pine".into()],
            vec![tree(-pine.radius, 0), tree(pine.radius, 1)],
            15,
        );
        match colouring {
            Some(c) => f.with_colouring(c),
            None => f,
        }
    };
    let view = Camera {
        viewport: SIZE,
        ..common::camera(
            pine.center + Vec3::new(0.0, 0.0, -3.0 * pine.radius),
            pine.center,
            1.0,
        )
    };
    let varied = Colouring::new(
        1.0,
        vec![SpeciesColour::DECIDUOUS, SpeciesColour::EVERGREEN],
    );
    for forest in [trees(None), trees(Some(varied))] {
        let mut r: ForestRenderer = common::forest_renderer(
            &ctx,
            &species,
            &prepared,
            &forest,
            SIZE,
            Background::Transparent,
            Atmosphere::CLEAR,
        );
        for (name, m) in common::every_method() {
            r.set_method(&ctx, m).unwrap();
            let mut draw = |season: Option<f32>| {
                r.set_season(season).unwrap();
                let target = Target::new(&ctx, SIZE.0, SIZE.1);
                r.render_fitted(&ctx, &view, &target).unwrap();
                assert_eq!(ctx.take_errors(), Vec::<String>::new());
                target.read(&ctx)
            };
            let plain = draw(None);
            let covered = plain.pixels().filter(|p| p[3] > 0).count();
            assert!(covered > 100, "{name}: the wood covers {covered} pixels");
            for season in [0.0, 1.0 / 3.0, 0.5, 2.0 / 3.0, 1.0] {
                let img = draw(Some(season));
                if img.as_raw() != plain.as_raw() {
                    common::failure_images(&format!("bark-{name}-{season}"), &plain, &img);
                }
                assert!(
                    img.as_raw() == plain.as_raw(),
                    "{name}: the wood changed colour in season {season}"
                );
            }
        }
    }
}
