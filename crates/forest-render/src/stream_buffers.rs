//! The per-view buffers of a quad stream, sized by its capacity (the stream, scan and counter
//! buffers and their bind groups), and the frame counters read back from them.

use wgpu::util::DeviceExt;

use crate::capacity::{Capacity, CapacityInput};
use crate::context::RenderError;
use crate::gpu_types::{GpuArgs, GpuCamera, GpuState, Quad, SceneConsts};
use crate::options::RendererOptions;
use crate::passes::ComputeShared;
use crate::passes::cull::CullPass;
use crate::passes::draw::DrawPass;
use crate::passes::refine::RefinePass;
use crate::scene::GpuScene;
use crate::stats::{FrameStats, PassTimes, StatsRing};
use crate::work::{FrameWork, StatisticsQueries};

/// Bytes of the resolved timestamps (six queries).
pub(crate) const TIMESTAMP_BYTES: u64 = 48;

/// The pipelines (built once per stream).
pub(crate) struct Passes {
    pub(crate) shared: ComputeShared,
    pub(crate) cull: CullPass,
    pub(crate) refine: RefinePass,
    pub(crate) draw: DrawPass,
}

/// Everything whose size follows the capacity: rebuilt by [`QuadStream::resize`].
pub(crate) struct Sized {
    pub(crate) state: wgpu::Buffer,
    pub(crate) args: wgpu::Buffer,
    pub(crate) quads: [wgpu::Buffer; 2],
    pub(crate) bg_cull: wgpu::BindGroup,
    pub(crate) bg_ab: wgpu::BindGroup,
    pub(crate) bg_ba: wgpu::BindGroup,
    pub(crate) bg_draw: [wgpu::BindGroup; 2],
    pub(crate) args_group: wgpu::BindGroup,
    pub(crate) ring: StatsRing,
    pub(crate) owned: Vec<(&'static str, wgpu::Buffer)>,
    /// Bytes of the view's own buffers (the scene's are in `GpuScene::bytes`).
    pub(crate) view_bytes: u64,
}

/// The query results read back with the counters, in this order: timestamps, then pipeline
/// statistics, each where the device has them.
pub(crate) fn readback<'a>(
    times: Option<&'a (wgpu::QuerySet, wgpu::Buffer)>,
    statistics: Option<&'a StatisticsQueries>,
) -> Vec<(&'a wgpu::Buffer, u64)> {
    let mut out = Vec::new();
    if let Some((_, b)) = times {
        out.push((b, TIMESTAMP_BYTES));
    }
    if let Some(q) = statistics {
        out.push((&q.resolve, crate::work::STATISTICS_BYTES));
    }
    out
}

/// Bytes of the camera buffer: the view's camera, then a light-view camera per cascade
/// (written together, the frame's one upload; see [`crate::shadow_maps`]).
pub(crate) const CAMERA_BYTES: usize =
    std::mem::size_of::<GpuCamera>() * (1 + crate::shadow::MAX_CASCADES as usize);

pub(crate) fn buffer(
    device: &wgpu::Device,
    label: &str,
    size: u64,
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(16),
        usage,
        mapped_at_creation: false,
    })
}

/// The capacity of `opts`, and at least `grown` quads (what [`QuadStream::fit`] found frames
/// need) unless the options fix it.
pub(crate) fn capacity(scene: &GpuScene, opts: &RendererOptions, grown: u32) -> Capacity {
    let t = &scene.tables;
    Capacity::new(&CapacityInput {
        instances: t.instances.len() as u32,
        quads_per_tree: t.quads_per_tree.max(1),
        viewport: opts.viewport,
        min_epsilon: opts.min_epsilon,
        overdraw: opts.overdraw,
        max_quads: opts.max_quads,
        grown,
    })
}

/// The per-view buffers and bind groups for `capacity`, checked against the device's
/// limits before anything is allocated.
pub(crate) fn build_sized(
    device: &wgpu::Device,
    scene: &GpuScene,
    passes: &Passes,
    camera: &wgpu::Buffer,
    environment: &wgpu::Buffer,
    capacity: &Capacity,
    readback: &[(&wgpu::Buffer, u64)],
) -> Result<Sized, RenderError> {
    let limit = crate::error::storage_limit(&device.limits());
    let quad_bytes = u64::from(capacity.quads) * std::mem::size_of::<Quad>() as u64;
    crate::error::within_limit(
        || format!("a stream of {} quads (bytes per buffer)", capacity.quads),
        quad_bytes,
        limit,
        ": lower the viewport or raise the minimum epsilon",
    )?;
    let t = &scene.tables;
    use wgpu::BufferUsages as U;
    let consts = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("scene constants"),
        contents: bytemuck::bytes_of(&SceneConsts {
            instances: t.instances.len() as u32,
            presort_dirs: t.presort_dirs.len() as u32,
            capacity: capacity.quads,
            species: t.species.len() as u32,
        }),
        usage: U::UNIFORM,
    });
    let state = buffer(
        device,
        "state",
        std::mem::size_of::<GpuState>() as u64,
        U::STORAGE | U::COPY_SRC,
    );
    let args = buffer(
        device,
        "args",
        std::mem::size_of::<GpuArgs>() as u64,
        U::STORAGE | U::INDIRECT,
    );
    let args_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("indirect arguments"),
        layout: &passes.shared.args_layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: args.as_entire_binding(),
        }],
    });
    // Scan data of the current step and the next one: `data[0]` holds the cull's tree
    // counts (instances) and the wishes of every other step, `data[1]` the others'.
    let data = [
        buffer(
            device,
            "scan data A",
            u64::from(capacity.items) * 4,
            U::STORAGE,
        ),
        buffer(
            device,
            "scan data B",
            u64::from(capacity.quads) * 4,
            U::STORAGE,
        ),
    ];
    let sums = buffer(
        device,
        "block sums",
        u64::from(capacity.sums) * 4,
        U::STORAGE,
    );
    let quads = [0, 1].map(|k| {
        buffer(
            device,
            if k == 0 { "stream A" } else { "stream B" },
            quad_bytes,
            U::STORAGE | U::COPY_SRC,
        )
    });
    let presort_view = scene.presort.create_view(&Default::default());
    let nodes_view = scene.nodes.create_view(&Default::default());
    let compute_bg = |label: &str, (d_in, d_out): (usize, usize), q: (usize, usize)| {
        let res: [wgpu::BindingResource; 16] = [
            camera.as_entire_binding(),
            consts.as_entire_binding(),
            scene.instances.as_entire_binding(),
            scene.species.as_entire_binding(),
            scene.frames.as_entire_binding(),
            scene.tris.as_entire_binding(),
            scene.roots.as_entire_binding(),
            scene.presort_dirs.as_entire_binding(),
            wgpu::BindingResource::TextureView(&presort_view),
            wgpu::BindingResource::TextureView(&nodes_view),
            state.as_entire_binding(),
            data[d_out].as_entire_binding(),
            data[d_in].as_entire_binding(),
            sums.as_entire_binding(),
            quads[q.0].as_entire_binding(),
            quads[q.1].as_entire_binding(),
        ];
        let entries = crate::passes::numbered(res.into());
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout: &passes.shared.bind_layout,
            entries: &entries,
        })
    };
    // (data in, data out), (quads in, quads out): the cull reads tree counts from data A
    // and writes stream A with its wishes in data B; the steps then alternate.
    let bg_cull = compute_bg("cull", (0, 1), (1, 0));
    let bg_ab = compute_bg("refine A->B", (1, 0), (0, 1));
    let bg_ba = compute_bg("refine B->A", (0, 1), (1, 0));
    let bg_draw = draw_groups(device, scene, passes, [camera, environment, &state], &quads);
    let mut sources = vec![(state.clone(), std::mem::size_of::<GpuState>() as u64)];
    sources.extend(readback.iter().map(|(b, n)| ((*b).clone(), *n)));
    let ring = StatsRing::new(device, sources);
    let (view_bytes, owned) = view_buffers(
        scene,
        [camera, &consts, environment, &state, &args],
        [&data[0], &data[1], &sums, &quads[0], &quads[1]],
    );
    Ok(Sized {
        state,
        args,
        quads,
        bg_cull,
        bg_ab,
        bg_ba,
        bg_draw,
        args_group,
        ring,
        owned,
        view_bytes,
    })
}

/// The bytes of a view's own buffers, and every buffer its passes bind with its label (the
/// scene's too): `[camera, scene constants, environment, state, args]` and `[scan data A,
/// scan data B, block sums, stream A, stream B]`.
fn view_buffers(
    scene: &GpuScene,
    [camera, consts, environment, state, args]: [&wgpu::Buffer; 5],
    [data_a, data_b, sums, quads_a, quads_b]: [&wgpu::Buffer; 5],
) -> (u64, Vec<(&'static str, wgpu::Buffer)>) {
    let view_bytes = [
        camera,
        consts,
        environment,
        state,
        args,
        data_a,
        data_b,
        sums,
        quads_a,
        quads_b,
    ]
    .iter()
    .map(|b| b.size())
    .sum::<u64>();
    let owned: Vec<(&'static str, wgpu::Buffer)> = [
        ("camera", camera),
        ("scene constants", consts),
        ("environment", environment),
        ("state", state),
        ("args", args),
        ("scan data A", data_a),
        ("scan data B", data_b),
        ("block sums", sums),
        ("stream A", quads_a),
        ("stream B", quads_b),
        ("instances", &scene.instances),
        ("species", &scene.species),
        ("frames", &scene.frames),
        ("direction triangles", &scene.tris),
        ("roots", &scene.roots),
        ("presort directions", &scene.presort_dirs),
    ]
    .into_iter()
    .map(|(l, b)| (l, b.clone()))
    .collect();
    (view_bytes, owned)
}

/// One draw group per stream buffer: the final stream is A after an even number of
/// refinement iterations, B after an odd one (refinement can be switched at run time).
/// `[camera, environment, state]` are the view's buffers.
fn draw_groups(
    device: &wgpu::Device,
    scene: &GpuScene,
    passes: &Passes,
    [camera, environment, state]: [&wgpu::Buffer; 3],
    quads: &[wgpu::Buffer; 2],
) -> [wgpu::BindGroup; 2] {
    let nodes_view = scene.nodes.create_view(&Default::default());
    let colour_view = scene.colour.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    let surface_view = scene.surface.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    let opacity_view = scene.opacity.create_view(&Default::default());
    let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("colour"),
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        ..Default::default()
    });
    [&quads[0], &quads[1]].map(|final_quads| {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("draw"),
            layout: &passes.draw.bind_layout,
            entries: &[
                crate::passes::numbered(vec![
                    camera.as_entire_binding(),
                    scene.instances.as_entire_binding(),
                    scene.species.as_entire_binding(),
                    scene.frames.as_entire_binding(),
                    final_quads.as_entire_binding(),
                    wgpu::BindingResource::TextureView(&nodes_view),
                    wgpu::BindingResource::TextureView(&colour_view),
                    wgpu::BindingResource::Sampler(&sampler),
                    environment.as_entire_binding(),
                    scene.roots.as_entire_binding(),
                    state.as_entire_binding(),
                    wgpu::BindingResource::TextureView(&surface_view),
                ]),
                vec![
                    wgpu::BindGroupEntry {
                        binding: crate::terrain::HEIGHTS_BINDING,
                        resource: scene.terrain.heights.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: crate::passes::draw::OPACITY_BINDING,
                        resource: wgpu::BindingResource::TextureView(&opacity_view),
                    },
                ],
            ]
            .concat(),
        })
    })
}

/// A frame's counters from its read-back state and timestamps (`levels`: the scene's
/// deepest hierarchy), with the work the frame recorded.
pub(crate) fn frame_stats(
    state: &[u8],
    times: Option<&[u8]>,
    levels: u32,
    period: f32,
    work: FrameWork,
) -> FrameStats {
    let mut s = GpuState::default();
    let n = state.len().min(std::mem::size_of::<GpuState>());
    bytemuck::bytes_of_mut(&mut s)[..n].copy_from_slice(&state[..n]);
    let levels = levels.clamp(1, s.per_level.len() as u32) as usize;
    let times = times
        .filter(|t| t.len() >= TIMESTAMP_BYTES as usize)
        .map(|t| {
            let t: Vec<u64> = bytemuck::pod_collect_to_vec(&t[..TIMESTAMP_BYTES as usize]);
            let ms = |a: usize| t[a + 1].saturating_sub(t[a]) as f64 * f64::from(period) / 1e6;
            PassTimes {
                cull_ms: ms(0),
                refine_ms: ms(2),
                draw_ms: ms(4),
            }
        });
    FrameStats {
        presort: s.presort,
        visible_trees: s.visible,
        quads: s.quads,
        composites: crate::gpu_types::kept_composites(s.composites, s.overflow_cull),
        per_level: s.per_level[..levels].to_vec(),
        overflow_cull: s.overflow_cull,
        overflow_refine: s.overflow_refine,
        times,
        work,
    }
}
