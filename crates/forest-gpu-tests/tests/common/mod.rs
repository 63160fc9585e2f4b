//! Shared fixtures of the GPU tests: small atlases baked once, a small forest, cameras.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use forest_format::{Atlas, BakeParams, forest::Forest};
use forest_render::scene::SpeciesData;
use forest_render::{Camera, GpuContext};
use forest_scene::generate::{GenerateParams, generate};
use glam::Vec3;

/// Small atlases (64 px, 5 directions, 2 slabs): bush and pine.
pub fn atlases() -> &'static [Atlas] {
    static A: OnceLock<Vec<Atlas>> = OnceLock::new();
    A.get_or_init(|| bake(&small_params()))
}

/// The bake parameters of [`atlases`]: 64 px, 5 directions, 2 slabs, 2 samples per pixel.
pub fn small_params() -> BakeParams {
    BakeParams {
        directions: 5,
        resolution: 64,
        min_quad: 4,
        spp: 2,
        ..BakeParams::default()
    }
}

/// Bush and pine baked with `params` (not cached); [`species_of`] decodes them.
pub fn atlases_with(params: &BakeParams) -> Vec<Atlas> {
    bake(params)
}

/// Decoded atlases, ready to upload.
pub fn species_of(atlases: &[Atlas]) -> Vec<SpeciesData> {
    atlases.iter().map(species_data).collect()
}

/// Bush and pine baked with `params`.
fn bake(params: &BakeParams) -> Vec<Atlas> {
    ["bush", "pine"]
        .iter()
        .map(|s| {
            let p = root().join(format!("assets/trees/{s}/{s}.obj"));
            forest_bake::bake_file(&p, params, &|_, _| {})
                .unwrap()
                .atlas
        })
        .collect()
}

pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

pub fn species() -> Vec<SpeciesData> {
    atlases().iter().map(species_data).collect()
}

fn species_data(a: &Atlas) -> SpeciesData {
    SpeciesData::decode(a.clone(), Path::new("test")).unwrap()
}

/// Bush and pine baked with `params` (not cached).
pub fn species_with(params: &BakeParams) -> Vec<SpeciesData> {
    bake(params).iter().map(species_data).collect()
}

pub fn forest(trees: u32) -> Forest {
    forest_on(trees, None)
}

/// [`forest`]'s trees on `terrain` (flat ground without one).
fn forest_on(trees: u32, terrain: Option<forest_format::terrain::Terrain>) -> Forest {
    generate(&GenerateParams {
        trees,
        species: vec!["bush".into(), "pine".into()],
        area_per_tree: 12.0,
        clump_size: 15.0,
        seed: 5,
        terrain,
        ..GenerateParams::default()
    })
    .unwrap()
}

/// [`forest`]'s trees on seeded hills of 25 m relief, the hills reaching past the trees.
pub fn hilly_forest(trees: u32) -> Forest {
    let side = (trees as f32 * 12.0).sqrt();
    let terrain =
        forest_format::terrain::Terrain::generate(&forest_format::terrain::TerrainParams {
            half_extent: side * 0.75,
            spacing: 2.0,
            relief: 25.0,
            hill_size: side / 2.0,
            fade: 0.125,
            seed: 5,
        })
        .unwrap();
    forest_on(trees, Some(terrain))
}

/// The bad-size forests every method must render without validation errors: empty and
/// 1M trees (bush and pine, 12 m² per tree).
pub fn empty_and_million() -> (Forest, Forest) {
    let empty = Forest::new(vec!["bush".into(), "pine".into()], Vec::new(), 15);
    let million = generate(&GenerateParams {
        trees: 1_000_000,
        species: vec!["bush".into(), "pine".into()],
        area_per_tree: 12.0,
        seed: 9,
        ..Default::default()
    })
    .unwrap();
    (empty, million)
}

/// One unit-scale tree of test species `species` (0 bush, 1 pine) at the origin, turned by
/// `rotation` radians.
pub fn one_tree(species: u32, rotation: f32) -> Forest {
    Forest::new(
        vec!["bush".into(), "pine".into()],
        vec![forest_format::forest::Instance {
            position: [0.0; 3],
            rotation,
            scale: 1.0,
            species,
        }],
        15,
    )
}

pub fn ctx() -> GpuContext {
    GpuContext::headless().expect("a GPU adapter (install mesa-vulkan-drivers)")
}

pub fn camera(eye: Vec3, target: Vec3, epsilon: f32) -> Camera {
    Camera {
        eye,
        target,
        fov_y_deg: 60.0,
        near: 0.1,
        far: 2000.0,
        viewport: (160, 120),
        epsilon,
    }
}

/// A nearly orthographic camera looking along `-dir` at the sphere (`center`, `radius`) from
/// 1000 radii away, framing it in a square `size`-pixel viewport: the view of a bake
/// direction. `dir` must not be vertical (a look-at camera has no up vector there).
pub fn along(center: Vec3, radius: f32, dir: Vec3, size: u32, epsilon: f32) -> Camera {
    let dist = radius * 1000.0;
    Camera {
        eye: center + dir * dist,
        target: center,
        fov_y_deg: (2.0 * (radius / dist).atan()).to_degrees(),
        near: dist - 2.0 * radius,
        far: dist + 2.0 * radius,
        viewport: (size, size),
        epsilon,
    }
}

/// The named test cameras over a forest of extent ~`side` metres around the origin.
pub fn cameras(side: f32) -> Vec<(&'static str, Camera)> {
    vec![
        (
            "inside",
            camera(Vec3::new(2.0, 1.7, 3.0), Vec3::new(-10.0, 2.0, -20.0), 4.0),
        ),
        (
            "birds_eye",
            camera(Vec3::new(0.0, side, side * 0.6), Vec3::ZERO, 4.0),
        ),
        (
            "horizon",
            camera(
                Vec3::new(-side * 0.7, 0.5, 0.0),
                Vec3::new(0.0, 0.6, 0.0),
                4.0,
            ),
        ),
        (
            "under_canopy",
            camera(Vec3::new(0.5, 0.3, 0.5), Vec3::new(1.0, 8.0, 2.0), 4.0),
        ),
        (
            "culled",
            camera(
                Vec3::new(0.0, 5.0, side * 5.0),
                Vec3::new(0.0, 5.0, side * 10.0),
                4.0,
            ),
        ),
    ]
}

/// The geometry methods' CPU preparation of bush and pine, lit as their test atlases.
pub fn prepared() -> &'static forest_baselines::geometry::PreparedGeometry {
    static P: OnceLock<forest_baselines::geometry::PreparedGeometry> = OnceLock::new();
    P.get_or_init(|| prepared_for(atlases()))
}

/// The geometry methods' CPU preparation of bush and pine for `atlases` (their lighting and
/// hybrid switch), not cached.
pub fn prepared_for(atlases: &[Atlas]) -> forest_baselines::geometry::PreparedGeometry {
    prepared_with(atlases, forest_baselines::geometry::Cards::Cut)
}

/// As [`prepared_for`], with the leaf cards `cards`.
pub fn prepared_with(
    atlases: &[Atlas],
    cards: forest_baselines::geometry::Cards,
) -> forest_baselines::geometry::PreparedGeometry {
    let species: Vec<forest_baselines::geometry::GeometrySpecies> = ["bush", "pine"]
        .iter()
        .zip(atlases)
        .map(|(s, a)| {
            let mesh =
                forest_bake::Mesh::load(&root().join(format!("assets/trees/{s}/{s}.obj"))).unwrap();
            forest_baselines::geometry::GeometrySpecies::new(
                forest_bake::model::prepare(&mesh, None).into(),
                &a.manifest,
            )
        })
        .collect();
    forest_baselines::geometry::PreparedGeometry::with_cards(&species, cards)
}

/// The tests' small view: a quad stream over `scene` for a 160×120 target refined down to
/// ε = 4, with `max_quads` overriding the capacity formula, and the target.
pub fn small_stream(
    ctx: &GpuContext,
    scene: forest_render::GpuScene,
    max_quads: Option<u32>,
) -> (forest_render::QuadStream, forest_render::target::Target) {
    let opts = forest_render::options::RendererOptions {
        viewport: (160, 120),
        min_epsilon: 4.0,
        max_quads,
        ..Default::default()
    };
    let stream = forest_render::QuadStream::new(&ctx.device, scene, &opts).unwrap();
    (stream, forest_render::target::Target::new(ctx, 160, 120))
}

/// Pixels shaded when fragments are shaded in aligned `b`×`b` blocks, for a rectangle of
/// pixels `[x0, y0, x1, y1)` (edges on pixel boundaries, 2:1 aspect so that no pixel centre
/// lies on its diagonal) drawn as a triangle strip from its top-left corner in a `size`
/// target: the blocks that each of its two triangles ((x0,y0) (x1,y0) (x0,y1), then (x1,y0)
/// (x0,y1) (x1,y1)) covers with a pixel centre, summed over the triangles, times `b²`.
pub fn rectangle_shaded_in_blocks(rect: [i32; 4], size: (i32, i32), b: i32) -> u64 {
    let [x0, y0, x1, y1] = rect;
    assert_eq!(
        x1 - x0,
        2 * (y1 - y0),
        "the diagonal must miss every pixel centre"
    );
    let inside = |p: [f32; 2], t: [[f32; 2]; 3]| {
        let e = |a: [f32; 2], b: [f32; 2]| {
            (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
        };
        let (d0, d1, d2) = (e(t[0], t[1]), e(t[1], t[2]), e(t[2], t[0]));
        (d0 >= 0.0 && d1 >= 0.0 && d2 >= 0.0) || (d0 <= 0.0 && d1 <= 0.0 && d2 <= 0.0)
    };
    let [fx0, fy0, fx1, fy1] = rect.map(|v| v as f32);
    let tris = [
        [[fx0, fy0], [fx1, fy0], [fx0, fy1]],
        [[fx1, fy0], [fx0, fy1], [fx1, fy1]],
    ];
    let mut blocks = 0;
    for t in tris {
        for qy in 0..size.1 / b {
            for qx in 0..size.0 / b {
                let hit = (0..b * b).any(|k| {
                    let (x, y) = (qx * b + k % b, qy * b + k / b);
                    // Strictly inside the rectangle's pixel range, then the triangle.
                    (x0..x1).contains(&x)
                        && (y0..y1).contains(&y)
                        && inside([x as f32 + 0.5, y as f32 + 0.5], t)
                });
                blocks += u64::from(hit);
            }
        }
    }
    blocks * (b * b) as u64
}

/// A triangle-strip pipeline of `module`'s `vs` and `fs` into one target of
/// `forest_render::target::TARGET_FORMAT`, no depth, with `blend`.
pub fn strip_pipeline(
    ctx: &GpuContext,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    blend: Option<wgpu::BlendState>,
) -> wgpu::RenderPipeline {
    ctx.device
        .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("strip"),
            layout: Some(layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleStrip,
                ..Default::default()
            },
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some("fs"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: forest_render::target::TARGET_FORMAT,
                    blend,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        })
}

/// A render pass into `view` alone, cleared to transparent black.
pub fn cleared_pass<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    view: &wgpu::TextureView,
) -> wgpu::RenderPass<'e> {
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: None,
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// Both forms of `species` (and their geometry, `prepared`) for `forest`: the quad stream and
/// the geometry renderer behind one `ForestRenderer`, drawing `viewport` over `background`.
pub fn forest_renderer(
    ctx: &GpuContext,
    species: &[SpeciesData],
    prepared: &forest_baselines::geometry::PreparedGeometry,
    forest: &Forest,
    viewport: (u32, u32),
    background: forest_render::options::Background,
    atmosphere: forest_render::options::Atmosphere,
) -> forest_baselines::methods::ForestRenderer {
    let scene = forest_render::GpuScene::new(ctx, species, forest).unwrap();
    let opts = forest_render::options::RendererOptions {
        format: forest_render::target::TARGET_FORMAT,
        viewport,
        background,
        atmosphere,
        ..Default::default()
    };
    let geometry =
        forest_baselines::geometry::GeometryRenderer::with_targets(ctx, prepared, forest, &opts)
            .unwrap();
    forest_baselines::methods::ForestRenderer::new(
        forest_render::QuadStream::new(&ctx.device, scene, &opts).unwrap(),
        Some(geometry),
    )
}

/// Writes `NAME-expected.png`, `NAME-actual.png` and the FLIP map `NAME-difference.png` to
/// target/test-output; returns the folder.
pub fn failure_images(
    name: &str,
    expected: &image::RgbaImage,
    actual: &image::RgbaImage,
) -> std::path::PathBuf {
    let out = root().join("target/test-output");
    std::fs::create_dir_all(&out).unwrap();
    expected
        .save(out.join(format!("{name}-expected.png")))
        .unwrap();
    actual.save(out.join(format!("{name}-actual.png"))).unwrap();
    let (_, map) = forest_metrics::flip(expected, actual).unwrap();
    map.save(out.join(format!("{name}-difference.png")))
        .unwrap();
    out
}

/// A quad stream over `species`' trees of `forest`, 160×120 over a transparent background,
/// sized for ε down to `min_epsilon`, and its target.
pub fn transparent_stream(
    ctx: &forest_render::GpuContext,
    species: &[forest_render::SpeciesData],
    forest: &forest_format::forest::Forest,
    min_epsilon: f32,
) -> (forest_render::QuadStream, forest_render::target::Target) {
    let scene = forest_render::GpuScene::new(ctx, species, forest).unwrap();
    let opts = forest_render::options::RendererOptions {
        viewport: (160, 120),
        min_epsilon,
        background: forest_render::options::Background::Transparent,
        ..Default::default()
    };
    (
        forest_render::QuadStream::new(&ctx.device, scene, &opts).unwrap(),
        forest_render::target::Target::new(ctx, 160, 120),
    )
}

/// Run the compute entry point `main` of the runtime's modules with `harness` added (its
/// bindings in group 0: the uniform `uniform` at 0, the storage buffers `inputs` at 1, 2, …,
/// and after them the output array of `count` `vec4<f32>`) over `count` invocations
/// (workgroups of 64), and read the output back. Any wgpu error fails the test.
pub fn run_harness(
    ctx: &GpuContext,
    harness: &str,
    uniform: &[u8],
    inputs: &[&[u8]],
    count: usize,
) -> Vec<[f32; 4]> {
    use wgpu::BufferUsages as U;
    use wgpu::util::DeviceExt;
    let src = forest_render::shaders::Composer::runtime()
        .with_module("harness", harness)
        .compose(&["harness"])
        .unwrap();
    let d = &ctx.device;
    let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("harness"),
        source: wgpu::ShaderSource::Wgsl(src.into()),
    });
    let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("harness"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let init = |bytes: &[u8], usage| {
        d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: None,
            contents: bytes,
            usage,
        })
    };
    let mut buffers = vec![init(uniform, U::UNIFORM)];
    buffers.extend(inputs.iter().map(|b| init(b, U::STORAGE)));
    let size = (count * 16) as u64;
    buffers.push(d.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size,
        usage: U::STORAGE | U::COPY_SRC,
        mapped_at_creation: false,
    }));
    let read = d.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size,
        usage: U::MAP_READ | U::COPY_DST,
        mapped_at_creation: false,
    });
    let entries: Vec<wgpu::BindGroupEntry> = buffers
        .iter()
        .enumerate()
        .map(|(k, b)| wgpu::BindGroupEntry {
            binding: k as u32,
            resource: b.as_entire_binding(),
        })
        .collect();
    let group = d.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    });
    let mut enc = d.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups((count as u32).div_ceil(64), 1, 1);
    }
    enc.copy_buffer_to_buffer(buffers.last().unwrap(), 0, &read, 0, size);
    ctx.queue.submit([enc.finish()]);
    read.slice(..)
        .map_async(wgpu::MapMode::Read, |r| r.unwrap());
    d.poll(wgpu::PollType::wait_indefinitely()).unwrap();
    let out = bytemuck::cast_slice(&read.slice(..).get_mapped_range().unwrap()).to_vec();
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    out
}

/// Every method by name, full geometry's reference and the hybrid at its switch among them.
pub fn every_method() -> Vec<(&'static str, forest_baselines::methods::Method)> {
    every_method_switching_at(0.0)
}

/// [`every_method`], the hybrid at its switch drawing geometry nearer than `switch` metres.
pub fn every_method_switching_at(
    switch: f32,
) -> Vec<(&'static str, forest_baselines::methods::Method)> {
    use forest_baselines::geometry::{Lods, MeshMethod, Stochastic};
    use forest_baselines::methods::Method;
    use forest_baselines::{Hybrid, Near};
    vec![
        ("quads", Method::Quads),
        ("impostor", Method::Impostor),
        (
            "geometry",
            Method::Mesh(MeshMethod::Full { depth_sort: true }),
        ),
        ("reference", Method::Mesh(MeshMethod::Reference)),
        (
            "stochastic",
            Method::Mesh(MeshMethod::Stochastic(Stochastic::default())),
        ),
        ("lods", Method::Mesh(MeshMethod::Lods(Lods::default()))),
        ("hybrid", Method::Hybrid(Hybrid::default())),
        (
            "hybrid-at-switch",
            Method::Hybrid(Hybrid {
                near: Near::Metres(switch),
                ..Default::default()
            }),
        ),
    ]
}
