//! The GPU's marches through the opacity volumes (`sun_transmittance`,
//! `sun_transmittance_coarse`, and `opacity_march` at each quad level's `quad_march` in
//! common.wgsl) and a billboard's `median_depth_point` against their CPU mirrors
//! (`forest_format::opacity::OpacityVolume::transmittance`, `coarse_transmittance`,
//! `level_transmittance` at `quad_march` and `median_depth_point`, through
//! the volumes' mip levels as `OpacityVolume::mips` makes them), on two stacked
//! species, from points (inside the volumes' cubes and outside them) and towards suns drawn by
//! a seeded hash.

mod common;

use forest_format::opacity::{COARSE_LEVEL, OpacityVolume, VOLUME_RESOLUTION, quad_march};
use forest_format::slab::Sphere;
use glam::Vec3;
use wgpu::util::DeviceExt;

const POINTS: usize = 256;

fn hash(mut x: u32) -> f32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    (x >> 8) as f32 / (1u32 << 24) as f32
}

/// A volume with structure on every axis: a dense ball off centre in a thin haze, scaled
/// by `k` so that the two species differ.
fn volume(k: f32) -> OpacityVolume {
    let r = VOLUME_RESOLUTION;
    let depths: Vec<f32> = (0..r.pow(3))
        .map(|i| {
            let p = Vec3::new((i % r) as f32, (i / r % r) as f32, (i / (r * r)) as f32) / r as f32;
            let ball = (0.3 - p.distance(Vec3::new(0.55, 0.6, 0.45 + 0.1 * k))).max(0.0);
            k * (0.02 + 4.0 * ball)
        })
        .collect();
    OpacityVolume::from_depths(r, &depths)
}

#[test]
fn the_gpu_march_matches_the_cpu_mirror() {
    let ctx = common::ctx();
    let volumes = [volume(1.0), volume(2.5)];
    let spheres = [
        Sphere {
            center: Vec3::new(0.0, 3.0, 0.0),
            radius: 3.0,
        },
        Sphere {
            center: Vec3::new(1.0, 8.0, -2.0),
            radius: 8.0,
        },
    ];
    let (input, expected) = cpu_marches(&volumes, &spheres);
    let got = gpu_marches(&ctx, &volumes, &spheres, &input);
    compare_marches(&got, &expected, &input, &spheres);
}

/// Per point: its shader input (point, species, direction towards the sun, the volume's
/// largest depth) and the CPU mirror's six answers (the full, coarse and quad level's
/// marches, and a billboard's median depth point).
fn cpu_marches(volumes: &[OpacityVolume; 2], spheres: &[Sphere; 2]) -> (Vec<[f32; 8]>, Vec<f32>) {
    let mips = [volumes[0].mips(COARSE_LEVEL), volumes[1].mips(COARSE_LEVEL)];
    // Per point: species, point in its sphere's cube, direction with y > 0.05.
    let mut input: Vec<[f32; 8]> = Vec::new();
    let mut expected = Vec::new();
    for i in 0..POINTS {
        let k = i % 2;
        let s = &spheres[k];
        let h = |j: u32| hash(i as u32 * 8 + j);
        let u = Vec3::new(h(0), h(1), h(2));
        // One point in five lies outside the volume's cube (billboard corners do): its march
        // starts where the ray enters.
        let reach = if i % 5 == 0 { 1.4 } else { 0.95 };
        let p = s.center + (u * 2.0 - 1.0) * s.radius * reach;
        let az = std::f32::consts::TAU * h(3);
        let el = (0.05 + 0.95 * h(4)).asin();
        let d = Vec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
        expected.push(volumes[k].transmittance(s, p, d));
        let coarse = &mips[k][COARSE_LEVEL as usize];
        expected.push(OpacityVolume::coarse_transmittance(coarse, s, p, d));
        // A plain quad's march, at hierarchy level i mod 8.
        let (level, steps) = quad_march(i as u32 % 8);
        let mip = &mips[k][level as usize];
        expected.push(OpacityVolume::level_transmittance(
            mip, level, steps, s, p, d,
        ));
        // A billboard's view ray through the point, down against the sun.
        let m = OpacityVolume::median_depth_point(coarse, s, p, -d);
        expected.extend([m.x, m.y, m.z]);
        input.push([
            p.x,
            p.y,
            p.z,
            f32::from_bits(k as u32),
            d.x,
            d.y,
            d.z,
            volumes[k].max_depth,
        ]);
    }
    (input, expected)
}

/// The same six answers per point, marched by the runtime's WGSL.
fn gpu_marches(
    ctx: &forest_render::GpuContext,
    volumes: &[OpacityVolume; 2],
    spheres: &[Sphere; 2],
    input: &[[f32; 8]],
) -> Vec<f32> {
    let (texture, _) = forest_render::extend::opacity_texture(
        &ctx.device,
        &ctx.queue,
        &[&volumes[0], &volumes[1]],
    )
    .unwrap();
    let view = texture.create_view(&Default::default());
    let sampler = ctx.device.create_sampler(&wgpu::SamplerDescriptor {
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        ..Default::default()
    });
    let sphere_data: Vec<[f32; 4]> = spheres
        .iter()
        .map(|s| s.center.extend(s.radius).to_array())
        .collect();
    let src = forest_render::shaders::Composer::runtime()
        .with_module(
            "march",
            r#"
#import common

// Declared for common.wgsl's shading, unused here (so not in the derived layout).
@group(0) @binding(0) var<uniform> camera: Camera;
@group(0) @binding(1) var vol: texture_3d<f32>;
@group(0) @binding(2) var samp: sampler;
@group(0) @binding(3) var<storage, read> points: array<array<vec4<f32>, 2>>;
@group(0) @binding(4) var<storage, read> spheres: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> out: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (6u * id.x >= arrayLength(&out)) { return; }
    let a = points[id.x][0];
    let b = points[id.x][1];
    let k = bitcast<u32>(a.w);
    let o = 6u * id.x;
    out[o] = sun_transmittance(vol, samp, k, spheres[k], b.w, a.xyz, b.xyz);
    out[o + 1u] = sun_transmittance_coarse(vol, samp, k, spheres[k], b.w, a.xyz, b.xyz);
    let m = quad_march(id.x % 8u);
    out[o + 2u] = opacity_march(vol, samp, k, spheres[k], b.w, a.xyz, b.xyz, m.x, m.y);
    let v = median_depth_point(vol, samp, k, spheres[k], b.w, a.xyz, -b.xyz);
    out[o + 3u] = v.x;
    out[o + 4u] = v.y;
    out[o + 5u] = v.z;
}
"#,
        )
        .compose(&["march"])
        .unwrap();
    let module = ctx
        .device
        .create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("opacity march"),
            source: wgpu::ShaderSource::Wgsl(src.into()),
        });
    let pipeline = ctx
        .device
        .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("opacity march"),
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
    let buffer = |contents: &[u8], usage| {
        ctx.device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: None,
                contents,
                usage,
            })
    };
    let points = buffer(bytemuck::cast_slice(input), wgpu::BufferUsages::STORAGE);
    let spheres_buf = buffer(
        bytemuck::cast_slice(&sphere_data),
        wgpu::BufferUsages::STORAGE,
    );
    let out = buffer(
        &vec![0u8; POINTS * 24],
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
    );
    let group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(&view),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::Sampler(&sampler),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: points.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 4,
                resource: spheres_buf.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 5,
                resource: out.as_entire_binding(),
            },
        ],
    });
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups((POINTS as u32).div_ceil(64), 1, 1);
    }
    ctx.queue.submit([enc.finish()]);
    let got: Vec<f32> = bytemuck::cast_slice(&ctx.read_buffer(&out, (POINTS * 24) as u64)).to_vec();
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    got
}

/// The GPU's answers are the CPU's, and the case is not trivial: the volumes shadow and the
/// rays meet the crowns.
fn compare_marches(got: &[f32], expected: &[f32], input: &[[f32; 8]], spheres: &[Sphere; 2]) {
    let mut worst = 0f32;
    let mut worst_point = 0f32;
    for (i, (g, e)) in got.iter().zip(expected).enumerate() {
        let (point, j) = (i / 6, i % 6);
        if j < 3 {
            // The rasteriser filters with 8-bit weights: a small tolerance.
            let march = ["full", "coarse", "quad level's"][j];
            assert!(
                (g - e).abs() < 0.02,
                "point {point}, {march} march: GPU {g}, CPU {e}"
            );
            worst = worst.max((g - e).abs());
        } else {
            // The median depth's coordinates, within 5 % of the sphere's radius (a sixth of a
            // step of the march across the diameter: where a step stops little light, the
            // filter's 8-bit weights move the point within it).
            let r = spheres[point % 2].radius;
            worst_point = worst_point.max((g - e).abs() / r);
            assert!(
                (g - e).abs() < 0.05 * r,
                "point {point}, median depth along axis {}: GPU {g}, CPU {e}",
                j - 3
            );
        }
    }
    // The volumes shadow, every march: not every answer is 1; and the median depth lies off
    // the point itself for many rays.
    for m in 0..3 {
        let shadowed = expected
            .iter()
            .skip(m)
            .step_by(6)
            .filter(|&&t| t < 0.5)
            .count();
        assert!(
            shadowed > POINTS / 10,
            "march {m}: {shadowed} of {POINTS} points shadowed"
        );
    }
    let moved = input
        .iter()
        .enumerate()
        .filter(|(k, row)| {
            let e = &expected[6 * k + 3..6 * k + 6];
            (Vec3::new(row[0], row[1], row[2]) - Vec3::from_slice(e)).length() > 1e-3
        })
        .count();
    assert!(
        moved > POINTS / 10,
        "{moved} of {POINTS} rays met the crown"
    );
    let shadowed = expected.iter().step_by(6).filter(|&&t| t < 0.5).count();
    eprintln!(
        "worst |GPU − CPU| {worst:.5}, {shadowed} of {POINTS} points below 0.5, {moved} rays \
         meeting the crown, median depths within {worst_point:.4} radii"
    );
}
