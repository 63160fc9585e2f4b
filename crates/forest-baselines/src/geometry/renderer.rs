//! The geometry-based renderer of one forest: per frame, classify every tree into a distance
//! band on the GPU, write indirect arguments per band × species, scatter, and draw the bands
//! nearest first.

use forest_format::forest::Forest;
use forest_format::model::BANDS;
use forest_render::context::{GpuContext, RenderError};
use forest_render::extend::draw_pipeline;
use forest_render::extend::{Caster, ShadowTargets};
use forest_render::gpu_types::GpuCamera;
use forest_render::options::RendererOptions;
use forest_render::options::{Atmosphere, Background};
use forest_render::stats::PassTimes;
use forest_render::work::{self, FrameWork, StatisticsQueries};
use forest_render::{Form, FrameInputs};
use std::sync::atomic::AtomicU32;
use wgpu::util::DeviceExt;

use super::layout::{compute_entries, draw_entries};
use super::models::GpuModels;
use super::models::require_indirect_first_instance;
use super::params::{GeometryStats, MeshMethod, SpeciesFigures};
use super::prepare::PreparedGeometry;
use super::views::Shared;
use std::sync::Arc;

/// Workgroup size of `geo_reset` (one invocation per segment); the other per-tree entry
/// points use the runtime's `WG` (a test checks both against the WGSL).
pub const RESET_WG: u32 = 64;

/// The geometry-based renderer of one forest.
pub struct GeometryRenderer {
    inputs: FrameInputs,
    method_buf: wgpu::Buffer,
    method: MeshMethod,
    ring: forest_render::stats::StatsRing,
    reset: wgpu::ComputePipeline,
    classify: wgpu::ComputePipeline,
    args_pipeline: wgpu::ComputePipeline,
    scatter: wgpu::ComputePipeline,
    draw: wgpu::RenderPipeline,
    billboard: wgpu::RenderPipeline,
    environment: wgpu::RenderPipeline,
    terrain_pipeline: wgpu::RenderPipeline,
    /// The layout of the draw's group 0 and the targets' options, for the counting
    /// pipelines built on demand ([`Self::set_fragment_counter`]).
    draw_layout: wgpu::BindGroupLayout,
    targets: RendererOptions,
    /// The counting geometry and billboard pipelines, built at the first attached counter
    /// and kept.
    counting_draw: Option<[wgpu::RenderPipeline; 2]>,
    atmosphere: Atmosphere,
    compute_bg: wgpu::BindGroup,
    draw_bg: wgpu::BindGroup,
    args: wgpu::Buffer,
    queries: Option<(wgpu::QuerySet, wgpu::Buffer, f64)>,
    statistics: Option<StatisticsQueries>,
    /// Draws recorded by the last [`Self::record_draw`].
    draws: AtomicU32,
    /// Bytes of GPU memory the renderer allocated (buffers and textures), the models it
    /// shares included.
    pub gpu_bytes: u64,
    /// Layout of the draw's group 2, the sun's shadow maps.
    shadow_layout: wgpu::BindGroupLayout,
    /// The light views and the maps' receivers' group while shadows are on.
    shadows: Option<super::light::LightViews>,
    /// The last light views switched off, kept for switching them on again.
    parked: Option<super::light::LightViews>,
    /// What every view of the renderer binds (its own lists aside).
    shared: Shared,
}

impl GeometryRenderer {
    /// Upload prepared species with the forest's instances (their species order must match),
    /// for `format` colour targets with the crate's own depth target (Depth32Float, standard
    /// depth, one sample). The method starts as [`MeshMethod::default`].
    pub fn new(
        ctx: &GpuContext,
        prepared: &PreparedGeometry,
        forest: &Forest,
        format: wgpu::TextureFormat,
        background: Background,
    ) -> Result<Self, RenderError> {
        let opts = RendererOptions {
            format,
            background,
            ..Default::default()
        };
        Self::with_targets(ctx, prepared, forest, &opts)
    }

    /// [`Self::new`] for the host's targets: colour and depth formats, sample count, depth
    /// convention and background from `opts` (the same options a quad stream takes, so that
    /// the hybrid can draw both forms into one pass).
    pub fn with_targets(
        ctx: &GpuContext,
        prepared: &PreparedGeometry,
        forest: &Forest,
        opts: &RendererOptions,
    ) -> Result<Self, RenderError> {
        opts.atmosphere.validate().map_err(RenderError::Parameter)?;
        Self::with_models(ctx, Arc::new(GpuModels::new(ctx, prepared, forest)?), opts)
    }

    /// [`Self::with_targets`] over models already on the device, which this renderer shares
    /// with every other built from them (a view per camera uploads the models once).
    pub fn with_models(
        ctx: &GpuContext,
        models: Arc<GpuModels>,
        opts: &RendererOptions,
    ) -> Result<Self, RenderError> {
        opts.atmosphere.validate().map_err(RenderError::Parameter)?;
        require_indirect_first_instance(ctx)?;
        let device = &ctx.device;
        let cap = models.capacity;
        // This renderer's own allocations; the shared models' are added at the end.
        let gpu_bytes = std::cell::Cell::new(0u64);
        use wgpu::BufferUsages as U;
        let init = |label: &str, bytes: &[u8], usage: U| {
            gpu_bytes.set(gpu_bytes.get() + bytes.len() as u64);
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytes,
                usage,
            })
        };
        let zeros = |label: &str, bytes: usize, usage: U| init(label, &vec![0u8; bytes], usage);
        let method = MeshMethod::default();
        let method_buf = init(
            "geometry method",
            bytemuck::bytes_of(&method.to_gpu()),
            U::UNIFORM | U::COPY_DST,
        );

        let draw_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("geometry draw"),
            source: wgpu::ShaderSource::Wgsl(crate::shaders::draw_source().into()),
        });
        let (compute_layout, [reset, classify, args_pipeline, scatter]) = compute_pipelines(device);
        let draw_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("geometry draw"),
            entries: &draw_entries(),
        });
        let shadow_layout = forest_render::extend::receiver_layout(device);
        let draw_pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("geometry draw"),
            bind_group_layouts: &[Some(&draw_layout), None, Some(&shadow_layout)],
            immediate_size: 0,
        });
        let render_pipeline = |vs: &str, fs: &str, topology, layout: &wgpu::PipelineLayout| {
            draw_pipeline(
                device,
                opts,
                layout,
                &draw_module,
                topology,
                [vs, fs],
                None,
                true,
            )
        };
        use wgpu::PrimitiveTopology as T;
        let draw = render_pipeline("vs_geo", "fs_geo", T::TriangleList, &draw_pl);
        let billboard = render_pipeline("vs_billboard", "fs_billboard", T::TriangleList, &draw_pl);
        let environment = render_pipeline(
            "vs_environment",
            "fs_environment",
            T::TriangleList,
            &draw_pl,
        );
        let terrain_pipeline =
            render_pipeline("vs_terrain", "fs_terrain", T::TriangleList, &draw_pl);
        let environment_buf = init(
            "geometry environment",
            bytemuck::bytes_of(&forest_render::extend::environment_uniform(
                &opts.atmosphere,
                &models.terrain.grid,
            )),
            U::UNIFORM,
        );
        let shared = Shared {
            models: models.clone(),
            method: method_buf.clone(),
            environment: environment_buf,
            compute_layout,
            draw_layout: draw_layout.clone(),
        };
        let view = shared.view(device, "geometry");
        gpu_bytes.set(gpu_bytes.get() + view.bytes);
        let queries = device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY)
            .then(|| {
                let set = device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("geometry pass times"),
                    ty: wgpu::QueryType::Timestamp,
                    count: 4,
                });
                let resolve = zeros("geometry timestamps", 32, U::QUERY_RESOLVE | U::COPY_SRC);
                (set, resolve, f64::from(ctx.queue.get_timestamp_period()))
            });
        let statistics = StatisticsQueries::new(device);
        let mut sources = vec![(view.args.clone(), u64::from(cap.segments) * 16)];
        if let Some((_, resolve, _)) = &queries {
            sources.push((resolve.clone(), 32));
        }
        if let Some(q) = &statistics {
            sources.push((q.resolve.clone(), work::STATISTICS_BYTES));
        }
        let ring = forest_render::stats::StatsRing::new(device, sources);
        let inputs = FrameInputs::new(
            device,
            view.camera,
            shadow_layout.clone(),
            forest_render::extend::FORMS_GEOMETRY,
            opts,
        );
        Ok(Self {
            inputs,
            method_buf,
            method,
            ring,
            reset,
            classify,
            args_pipeline,
            scatter,
            draw,
            billboard,
            environment,
            terrain_pipeline,
            draw_layout,
            targets: opts.clone(),
            counting_draw: None,
            atmosphere: opts.atmosphere,
            compute_bg: view.compute_bg,
            draw_bg: view.draw_bg,
            args: view.args,
            shadow_layout,
            shadows: None,
            parked: None,
            shared,
            queries,
            statistics,
            draws: AtomicU32::new(0),
            gpu_bytes: gpu_bytes.get() + models.bytes(),
        })
    }

    /// Per-species figures of the models drawn, in the forest's species order.
    pub fn figures(&self) -> &[SpeciesFigures] {
        self.shared.models.figures()
    }

    /// Switch the method (a uniform write; nothing is rebuilt).
    pub fn set_method(&mut self, ctx: &GpuContext, method: MeshMethod) -> Result<(), RenderError> {
        method.validate()?;
        ctx.queue
            .write_buffer(&self.method_buf, 0, bytemuck::bytes_of(&method.to_gpu()));
        self.method = method;
        Ok(())
    }

    /// The current method.
    pub fn method(&self) -> MeshMethod {
        self.method
    }

    /// The statistics queries when frames gather them.
    fn counting(&self) -> Option<&StatisticsQueries> {
        self.statistics
            .as_ref()
            .filter(|_| self.inputs.gathers_statistics())
    }

    /// The sky and haze, fixed when the renderer was built.
    pub fn atmosphere(&self) -> Atmosphere {
        self.atmosphere
    }

    /// Write a camera uniform with the renderer's own fields (none: its inputs and its light
    /// views' cameras while shadows are on).
    fn write_camera(&mut self, queue: &wgpu::Queue, g: GpuCamera) {
        let own = self
            .shadows
            .as_ref()
            .map(|lv| (lv.targets.options(), Default::default(), lv.targets.band()));
        self.inputs.upload(queue, g, own);
    }

    /// Cast and receive the sun's shadows with `opts` from the next frame on, in maps of the
    /// renderer's own, or not (`None`); refused, with nothing changed, when the options are
    /// out of range or the device cannot hold the maps.
    pub fn set_shadows(
        &mut self,
        device: &wgpu::Device,
        opts: Option<forest_render::shadow::ShadowOptions>,
    ) -> Result<(), RenderError> {
        let same =
            |s: &Option<super::light::LightViews>| s.as_ref().map(|s| *s.targets.options()) == opts;
        let targets = match opts {
            Some(_) if same(&self.shadows) => return Ok(()),
            Some(_) if same(&self.parked) => self.parked.as_ref().map(|p| p.targets.clone()),
            Some(o) => Some(std::sync::Arc::new(ShadowTargets::new(
                device,
                &o,
                &self.shadow_layout,
                self.shared.models.band,
            )?)),
            None => None,
        };
        self.share_shadows(device, targets);
        Ok(())
    }

    /// Cast into and read `targets`, maps another renderer made (the quad stream's, so that
    /// the hybrid's two forms share them), or stop (`None`). Only the quad stream's passes
    /// then draw into them: see [`forest_render::extend::Caster`].
    pub fn share_shadows(
        &mut self,
        device: &wgpu::Device,
        targets: Option<std::sync::Arc<ShadowTargets>>,
    ) {
        let same = |s: &Option<super::light::LightViews>, t: &std::sync::Arc<ShadowTargets>| {
            s.as_ref()
                .is_some_and(|s| std::sync::Arc::ptr_eq(&s.targets, t))
        };
        if targets.is_some() {
            self.inputs.drop_host_shadows();
        }
        match targets {
            None => {
                if let Some(s) = self.shadows.take() {
                    self.parked = Some(s);
                }
            }
            Some(t) if same(&self.shadows, &t) => {}
            Some(t) if same(&self.parked, &t) => {
                std::mem::swap(&mut self.shadows, &mut self.parked);
            }
            Some(t) => {
                self.parked = self.shadows.take();
                self.shadows = Some(super::light::LightViews::new(device, &self.shared, t));
            }
        }
    }

    /// Whether shadows are on.
    pub fn shadows(&self) -> bool {
        self.shadows.is_some()
    }

    /// The shadow maps' passes of a frame when shadows are on: each cascade's cull, then its
    /// trees drawn depth-only into its layer (after [`ForestView::set_camera`](forest_render::ForestView::set_camera)).
    pub fn encode_shadows(&self, encoder: &mut wgpu::CommandEncoder) {
        if let Some(lv) = &self.shadows {
            for k in 0..lv.views.len() {
                self.encode_light(encoder, k);
                let mut pass = lv.targets.begin_cascade(encoder, k, None);
                self.record_light(&mut pass, k);
            }
        }
    }

    /// The view's compute pass alone: classify, arguments, scatter (after a camera was
    /// written), without the shadow maps' passes (the hybrid's stream casts for both forms).
    pub fn encode_view_compute(&self, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("geometry cull"),
            timestamp_writes: self.queries.as_ref().map(|(query_set, _, _)| {
                wgpu::ComputePassTimestampWrites {
                    query_set,
                    beginning_of_pass_write_index: Some(0),
                    end_of_pass_write_index: Some(1),
                }
            }),
        });
        if let Some(q) = self.counting() {
            pass.begin_pipeline_statistics_query(&q.set, work::CULL);
        }
        self.record_cull(&mut pass, &self.compute_bg);
        if let Some(q) = self.counting() {
            pass.end_pipeline_statistics_query();
            // No refine pass: its query is written empty, so every query is resolved.
            pass.begin_pipeline_statistics_query(&q.set, work::REFINE);
            pass.end_pipeline_statistics_query();
        }
    }

    /// The four cull dispatches of a view (its compute group `group`).
    fn record_cull(&self, pass: &mut wgpu::ComputePass, group: &wgpu::BindGroup) {
        pass.set_bind_group(0, group, &[]);
        let segments = BANDS * self.shared.models.species_count;
        pass.set_pipeline(&self.reset);
        pass.dispatch_workgroups(segments.div_ceil(RESET_WG).max(1), 1, 1);
        pass.set_pipeline(&self.classify);
        pass.dispatch_workgroups(
            self.shared
                .models
                .instance_count
                .div_ceil(forest_render::extend::WG)
                .max(1),
            1,
            1,
        );
        pass.set_pipeline(&self.args_pipeline);
        pass.dispatch_workgroups(1, 1, 1);
        pass.set_pipeline(&self.scatter);
        pass.dispatch_workgroups(
            self.shared
                .models
                .instance_count
                .div_ceil(forest_render::extend::WG)
                .max(1),
            1,
            1,
        );
    }

    /// Draw every band × species segment of a view's `args`, nearest band first, meshes with
    /// `pipelines[0]` and billboards with `pipelines[1]`.
    fn record_bands(
        &self,
        pass: &mut wgpu::RenderPass,
        args: &wgpu::Buffer,
        [draw, billboard]: [&wgpu::RenderPipeline; 2],
    ) {
        let first_billboard = self.method.first_billboard_band();
        for band in 0..BANDS {
            if band == 0 {
                pass.set_pipeline(draw);
            }
            if band == first_billboard {
                pass.set_pipeline(billboard);
            }
            for s in 0..self.shared.models.species_count {
                pass.draw_indirect(
                    args,
                    u64::from(band * self.shared.models.species_count + s) * 16,
                );
            }
        }
    }

    /// Visible trees per segment (`band · species + s`) of the last submitted frame; waits.
    pub fn read_segment_counts(&self, ctx: &GpuContext) -> Vec<u32> {
        let n = (BANDS * self.shared.models.species_count) as usize;
        let args: Vec<[u32; 4]> =
            bytemuck::pod_collect_to_vec(&ctx.read_buffer(&self.args, (n * 16) as u64)[..n * 16]);
        args.iter().map(|a| a[1]).collect()
    }

    /// Counters and pass times of the last submitted frame; waits for the GPU.
    pub fn read_stats(&self, ctx: &GpuContext) -> GeometryStats {
        let n = (BANDS * self.shared.models.species_count) as usize;
        let args = ctx.read_buffer(&self.args, (n * 16) as u64);
        let times = self
            .queries
            .as_ref()
            .map(|(_, resolve, _)| ctx.read_buffer(resolve, 32));
        let statistics = self
            .statistics
            .as_ref()
            .map(|q| ctx.read_buffer(&q.resolve, work::STATISTICS_BYTES));
        self.decode(&args, times.as_deref(), statistics.as_deref())
    }

    /// Counters of a recent frame without waiting (a few frames late; `None` until one has
    /// arrived): see [`forest_render::stats::StatsRing`].
    pub fn poll_stats(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Option<GeometryStats> {
        let parts = self.ring.poll(device, queue)?;
        let (times, statistics) = forest_render::stats::query_parts(
            &parts,
            self.queries.is_some(),
            self.statistics.is_some(),
        );
        Some(self.decode(&parts[0], times, statistics))
    }

    fn decode(
        &self,
        args: &[u8],
        times: Option<&[u8]>,
        statistics: Option<&[u8]>,
    ) -> GeometryStats {
        let n = ((BANDS * self.shared.models.species_count) as usize).min(args.len() / 16);
        let args: Vec<[u32; 4]> = bytemuck::pod_collect_to_vec(&args[..n * 16]);
        let first_billboard = self.method.first_billboard_band();
        let mut stats = GeometryStats {
            per_band: vec![0; BANDS as usize],
            ..Default::default()
        };
        for (seg, a) in args.iter().enumerate() {
            let band = seg as u32 / self.shared.models.species_count.max(1);
            stats.visible_trees += a[1];
            stats.per_band[band as usize] += a[1];
            stats.triangles += u64::from(a[0] / 3) * u64::from(a[1]);
            if band >= first_billboard {
                stats.billboards += a[1];
            }
        }
        let period = self.queries.as_ref().map_or(1.0, |q| q.2);
        stats.times = times.filter(|t| t.len() >= 32).map(|t| {
            let t: Vec<u64> = bytemuck::pod_collect_to_vec(&t[..32]);
            let ms = |a: usize| t[a + 1].saturating_sub(t[a]) as f64 * period / 1e6;
            PassTimes {
                cull_ms: ms(0),
                refine_ms: 0.0,
                draw_ms: ms(2),
            }
        });
        stats.work = FrameWork {
            dispatches: 4,
            draws: self.draws.load(std::sync::atomic::Ordering::Relaxed),
            passes: statistics
                .filter(|_| self.inputs.gathers_statistics())
                .and_then(work::decode),
            bytes: self.gpu_bytes + self.shadows.as_ref().map_or(0, |s| s.bytes()),
        };
        stats
    }
}

impl forest_render::extend::Caster for GeometryRenderer {
    /// Copy cascade `k`'s light camera into its light view and classify its trees.
    fn encode_light(&self, encoder: &mut wgpu::CommandEncoder, k: usize) {
        let Some(lv) = &self.shadows else { return };
        let size = std::mem::size_of::<GpuCamera>() as u64;
        let view = &lv.views[k];
        encoder.copy_buffer_to_buffer(
            self.inputs.camera(),
            size * (k as u64 + 1),
            &view.camera,
            0,
            size,
        );
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("geometry light view"),
            timestamp_writes: None,
        });
        self.record_cull(&mut pass, &view.compute_bg);
    }

    /// Draw cascade `k`'s trees depth-only.
    fn record_light(&self, pass: &mut wgpu::RenderPass, k: usize) {
        let Some(lv) = &self.shadows else { return };
        let view = &lv.views[k];
        pass.set_bind_group(0, &view.draw_bg, &[]);
        let [a, b] = &lv.cast;
        self.record_bands(pass, &view.args, [a, b]);
    }
}

/// The geometry methods' compute layout and its four entry points, in order: reset,
/// classify, arguments, scatter (one module, one bind group).
fn compute_pipelines(device: &wgpu::Device) -> (wgpu::BindGroupLayout, [wgpu::ComputePipeline; 4]) {
    let compute = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("geometry cull"),
        source: wgpu::ShaderSource::Wgsl(crate::shaders::cull_source().into()),
    });
    // One explicit layout shared by the four compute entry points (one bind group).
    let entries = compute_entries();
    let compute_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("geometry cull"),
        entries: &entries,
    });
    let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("geometry cull"),
        bind_group_layouts: &[Some(&compute_layout)],
        immediate_size: 0,
    });
    let cpl = |entry: &str| {
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout: Some(&pl),
            module: &compute,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        })
    };
    let pipelines = ["geo_reset", "geo_classify", "geo_args", "geo_scatter"].map(cpl);
    (compute_layout, pipelines)
}

/// The geometry renderer's passes behind the frame API ([`forest_render::ForestView`]).
impl Form for GeometryRenderer {
    fn inputs(&self) -> &FrameInputs {
        &self.inputs
    }

    fn inputs_mut(&mut self) -> &mut FrameInputs {
        &mut self.inputs
    }

    fn write_frame(&mut self, queue: &wgpu::Queue, g: GpuCamera) {
        self.write_camera(queue, g);
    }

    fn park_own_shadows(&mut self, device: &wgpu::Device) {
        self.share_shadows(device, None);
    }

    /// The shadow maps' passes when the renderer casts its own (or shares the stream's and
    /// draws a method alone), then classify, arguments, scatter.
    fn encode_compute(&self, encoder: &mut wgpu::CommandEncoder) {
        self.encode_shadows(encoder);
        self.encode_view_compute(encoder);
    }

    fn draw_timestamps(&self) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        self.queries
            .as_ref()
            .map(|(query_set, _, _)| wgpu::RenderPassTimestampWrites {
                query_set,
                beginning_of_pass_write_index: Some(2),
                end_of_pass_write_index: Some(3),
            })
    }

    /// The counting pipelines, built at the first counter and kept; the frame's own
    /// pipelines are untouched.
    fn build_counting(&mut self, device: &wgpu::Device) {
        if self.counting_draw.is_none() {
            let counts = forest_render::fragments::bind_layout(device);
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("counted geometry draw"),
                bind_group_layouts: &[
                    Some(&self.draw_layout),
                    Some(&counts),
                    Some(&self.shadow_layout),
                ],
                immediate_size: 0,
            });
            let source = crate::shaders::counting_draw_source();
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("counted geometry draw"),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            });
            let pipeline = |entries| {
                draw_pipeline(
                    device,
                    &self.targets,
                    &layout,
                    &module,
                    wgpu::PrimitiveTopology::TriangleList,
                    entries,
                    None,
                    true,
                )
            };
            self.counting_draw = Some([
                pipeline(["vs_geo", "fs_geo"]),
                pipeline(["vs_billboard", "fs_billboard"]),
            ]);
        }
    }

    /// Record the draw into a render pass after [`Self::encode_compute`]: the environment (sky
    /// and ground, when `ground` and the background is the sky), then the bands nearest first.
    fn record_draw(&self, pass: &mut wgpu::RenderPass, ground: bool) {
        let ground = ground && self.inputs.background() == Background::Sky;
        pass.set_bind_group(0, &self.draw_bg, &[]);
        let receivers = self
            .inputs
            .receivers(self.shadows.as_ref().map(|s| s.targets.receivers()));
        pass.set_bind_group(2, receivers, &[]);
        let environment = if ground {
            self.shared.models.terrain.record_ground(
                pass,
                &self.environment,
                &self.terrain_pipeline,
            )
        } else {
            0
        };
        // The statistics are the trees' alone (the environment is outside the query).
        if let Some(q) = self.counting() {
            pass.begin_pipeline_statistics_query(&q.set, work::DRAW);
        }
        let [draw, billboard] = match (&self.counting_draw, self.inputs.fragment_counts()) {
            (Some([draw, billboard]), Some(counts)) => {
                pass.set_bind_group(1, counts, &[]);
                [draw, billboard]
            }
            _ => [&self.draw, &self.billboard],
        };
        self.record_bands(pass, &self.args, [draw, billboard]);
        if self.counting().is_some() {
            pass.end_pipeline_statistics_query();
        }
        self.draws.store(
            BANDS * self.shared.models.species_count + environment,
            std::sync::atomic::Ordering::Relaxed,
        );
    }

    /// Resolve the frame's pass times: the cull pass's, and the draw pass's when `draw` (the
    /// render pass carried this renderer's timestamps).
    fn resolve_queries(&self, encoder: &mut wgpu::CommandEncoder, draw: bool) {
        if let Some((set, resolve, _)) = &self.queries {
            encoder.resolve_query_set(set, 0..if draw { 4 } else { 2 }, resolve, 0);
        }
        if let Some(q) = self.counting() {
            q.resolve(encoder);
        }
    }
}
