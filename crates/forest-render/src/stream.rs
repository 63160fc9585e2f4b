//! The quad stream of one view: the per-view buffers (camera, stream, scan, counters), the
//! bind groups over a shared scene, and the frame function that records the three passes.
//!
//! The shape is that of wgpu middleware: build once from the device and the host's target
//! formats; per frame, [`ForestView::prepare`] writes the one camera buffer (the only upload),
//! then [`QuadStream::encode_compute`] records cull and refine and [`ForestView::render`] draws
//! into the host's render pass, or [`QuadStream::encode_into`] does both into targets with the
//! host's load operations. The scene is shared ([`Arc<GpuScene>`]): several views (split
//! screen, shadow maps) are several streams over one upload, and [`QuadStream::resize`]
//! rebuilds only the view's own buffers.

use std::sync::Arc;
use std::sync::atomic::{AtomicU32, Ordering};

use wgpu::util::DeviceExt;

use crate::camera::Camera;
use crate::capacity::Capacity;
use crate::context::{GpuContext, RenderError};
use crate::frame::Targets;
use crate::gpu_types::{GpuCamera, GpuState, Quad};
use crate::options::{Atmosphere, Background, DebugView, RendererOptions, StreamOptions};
use crate::passes::ComputeShared;
use crate::passes::cull::CullPass;
use crate::passes::draw::DrawPass;
use crate::passes::refine::RefinePass;
use crate::scene::GpuScene;
use crate::stats::FrameStats;
use crate::stream_buffers::{CAMERA_BYTES, Passes, Sized, buffer, capacity, readback};
use crate::view::{ForestView, Form};
use crate::work::{CountingPass, FrameWork, StatisticsQueries};

/// The quad stream of one view over a shared scene.
pub struct QuadStream {
    /// The counting quad pipelines, built at the first attached counter and kept.
    counting_draw: Option<crate::passes::draw::CountingDraw>,
    /// The uploaded scene (shared, immutable).
    pub scene: Arc<GpuScene>,
    /// Buffer sizes.
    pub capacity: Capacity,
    /// Quads [`Self::fit`] found frames need (0 until a frame overflows).
    grown: u32,
    opts: RendererOptions,
    passes: Passes,
    inputs: crate::view::FrameInputs,
    environment: wgpu::Buffer,
    sized: Sized,
    levels: u32,
    iterations: u32,
    queries: Option<(wgpu::QuerySet, wgpu::Buffer)>,
    statistics: Option<StatisticsQueries>,
    /// Dispatches and draws of the last recorded frame (counted as recorded).
    recorded: (AtomicU32, AtomicU32),
    debug: DebugView,
    options: StreamOptions,
    /// Replaces `options.sharpen` in the frames drawn ([`Self::set_sharpen_override`]).
    sharpen_override: Option<u32>,
    /// Replaces `options.opaque_first` in the frames drawn ([`Self::set_opaque_override`]).
    opaque_override: Option<bool>,
    /// The sun's shadow maps, when on ([`Self::set_shadows`]).
    shadows: Option<crate::shadow_maps::ShadowMaps<QuadStream>>,
    /// The last maps switched off, kept for switching them on again.
    parked: Option<crate::shadow_maps::ShadowMaps<QuadStream>>,
    /// The casting pipeline into a host's map ([`Self::prepare_light`]).
    host_cast: Option<crate::passes::cast::CastPass>,
}

impl QuadStream {
    /// Build the stream of one view over `scene` for the host's targets (`opts`: colour and
    /// depth formats, sample count, depth convention, and the largest viewport and smallest ε
    /// that size the stream). Nothing is drawn until the first [`ForestView::prepare`].
    pub fn new(
        device: &wgpu::Device,
        scene: impl Into<Arc<GpuScene>>,
        opts: &RendererOptions,
    ) -> Result<Self, RenderError> {
        let scene = scene.into();
        if !(1..=32).contains(&opts.sample_count) || !opts.sample_count.is_power_of_two() {
            return Err(RenderError::Parameter(format!(
                "sample count {} must be 1, 2, 4, 8, 16 or 32",
                opts.sample_count
            )));
        }
        if !opts.depth_format.is_depth_stencil_format() {
            return Err(RenderError::Parameter(format!(
                "{:?} is not a depth format",
                opts.depth_format
            )));
        }
        opts.atmosphere.validate().map_err(RenderError::Parameter)?;
        let capacity = capacity(&scene, opts, 0);
        let shared = ComputeShared::new(device);
        let passes = Passes {
            cull: CullPass::new(device, &shared),
            refine: RefinePass::new(device, &shared),
            draw: DrawPass::new(device, opts),
            shared,
        };
        use wgpu::BufferUsages as U;
        let camera = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("camera"),
            contents: bytemuck::cast_slice(
                &[crate::camera::nothing_visible(); 1 + crate::shadow::MAX_CASCADES as usize],
            ),
            usage: U::UNIFORM | U::COPY_DST | U::COPY_SRC,
        });
        debug_assert_eq!(camera.size() as usize, CAMERA_BYTES);
        let environment = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("environment"),
            contents: bytemuck::bytes_of(&crate::terrain::environment_uniform(
                &opts.atmosphere,
                &scene.terrain.grid,
            )),
            usage: U::UNIFORM,
        });
        let queries = device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY)
            .then(|| {
                let set = device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("pass times"),
                    ty: wgpu::QueryType::Timestamp,
                    count: 6,
                });
                let resolve = buffer(
                    device,
                    "timestamps",
                    crate::stream_buffers::TIMESTAMP_BYTES,
                    U::QUERY_RESOLVE | U::COPY_SRC,
                );
                (set, resolve)
            });
        let statistics = StatisticsQueries::new(device);
        let sized = crate::stream_buffers::build_sized(
            device,
            &scene,
            &passes,
            &camera,
            &environment,
            &capacity,
            &readback(queries.as_ref(), statistics.as_ref()),
        )?;
        let levels = scene.tables.max_levels;
        let inputs = crate::view::FrameInputs::new(
            device,
            camera,
            passes.draw.shadow_layout.clone(),
            crate::forms::FORMS_QUADS,
            opts,
        );
        Ok(Self {
            counting_draw: None,
            iterations: if opts.refine {
                levels.saturating_sub(1)
            } else {
                0
            },
            levels,
            scene,
            capacity,
            grown: 0,
            opts: opts.clone(),
            passes,
            inputs,
            environment,
            sized,
            queries,
            statistics,
            recorded: (AtomicU32::new(0), AtomicU32::new(0)),
            debug: DebugView::Off,
            options: StreamOptions::default(),
            sharpen_override: None,
            opaque_override: None,
            shadows: None,
            parked: None,
            host_cast: None,
        })
    }

    /// Write a host's light view (the frame's upload for this stream): from here on the stream
    /// casts into the host's shadow map, culled and refined from the light, drawn depth-only
    /// with [`Self::render_depth`] after [`Self::encode_compute`]. The stream's depth format
    /// and convention ([`RendererOptions`]) are the map's.
    pub fn prepare_light(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        light: &crate::shadow::LightParams,
    ) -> Result<(), RenderError> {
        light.validate().map_err(RenderError::Parameter)?;
        if self.host_cast.is_none() {
            let compare = if self.opts.reverse_z {
                wgpu::CompareFunction::Greater
            } else {
                wgpu::CompareFunction::Less
            };
            self.host_cast = Some(crate::passes::cast::CastPass::into(
                device,
                (self.opts.depth_format, compare),
            ));
        }
        let mut g = light.camera(self.drawn_options());
        // The trees cast where they are drawn, moved by the stream's wind.
        g.set_wind(&self.inputs.wind());
        self.inputs.upload_cameras(queue, &[g]);
        Ok(())
    }

    /// Draw the light view's quads depth-only into the host's pass (its shadow map's layer),
    /// after [`Self::prepare_light`] and [`Self::encode_compute`].
    pub fn render_depth(&self, pass: &mut wgpu::RenderPass) {
        if let Some(cast) = &self.host_cast {
            let (group, args) = crate::shadow_maps::LightView::cast_parts(self);
            cast.record(pass, group, args);
        }
    }

    /// Cast and receive the sun's shadows with `opts` from the next frame on, or not
    /// (`None`). The maps and their light-view streams are built here, and kept while the
    /// options stay the same (the last ones switched off too, for switching them on again);
    /// refused, with nothing changed, when the options are out of range or the device cannot
    /// hold the maps.
    pub fn set_shadows(
        &mut self,
        device: &wgpu::Device,
        opts: Option<crate::shadow::ShadowOptions>,
    ) -> Result<(), RenderError> {
        match opts {
            None => {
                if let Some(s) = self.shadows.take() {
                    self.parked = Some(s);
                }
            }
            Some(o) => {
                self.inputs.drop_host_shadows();
                if self.shadows.as_ref().map(|s| *s.options()) == Some(o) {
                    return Ok(());
                }
                if self.parked.as_ref().map(|s| *s.options()) == Some(o) {
                    let mut maps = self.parked.take();
                    if let Some(m) = &mut maps {
                        m.set_refine(self.iterations > 0);
                    }
                    self.parked = self.shadows.take();
                    self.shadows = maps;
                } else {
                    let light = crate::shadow_maps::light_view_options(&o);
                    let mut maps = crate::shadow_maps::ShadowMaps::new(
                        device,
                        &o,
                        &self.passes.draw.shadow_layout,
                        self.scene.band,
                        || QuadStream::new(device, self.scene.clone(), &light),
                    )?;
                    maps.set_refine(self.iterations > 0);
                    self.shadows = Some(maps);
                }
            }
        }
        Ok(())
    }

    /// Grow the shadow maps' light-view streams whose last frame overflowed (waits for the
    /// GPU); whether any grew, so that the frame should be drawn again.
    pub fn fit_shadows(&mut self, ctx: &GpuContext) -> Result<bool, RenderError> {
        match &mut self.shadows {
            Some(sh) => sh.fit(ctx),
            None => Ok(false),
        }
    }

    /// The shadow maps, when shadows are on.
    pub fn shadows(&self) -> Option<&crate::shadow_maps::ShadowMaps<QuadStream>> {
        self.shadows.as_ref()
    }

    /// The shadow maps, when shadows are on (to poll and grow their light views).
    pub fn shadows_mut(&mut self) -> Option<&mut crate::shadow_maps::ShadowMaps<QuadStream>> {
        self.shadows.as_mut()
    }

    /// Bytes of the view's own buffers (not the scene's).
    pub fn view_bytes(&self) -> u64 {
        self.sized.view_bytes
    }

    /// Resize for a new largest viewport: the stream, scan and counter buffers are rebuilt
    /// for the new capacity; the scene (atlas textures, tables) is kept as it is, never
    /// uploaded again. Nothing is rebuilt when the capacity does not change.
    pub fn resize(
        &mut self,
        device: &wgpu::Device,
        viewport: (u32, u32),
    ) -> Result<(), RenderError> {
        self.resize_for(device, viewport, self.opts.min_epsilon)
    }

    /// [`Self::resize`] for a new largest viewport and a new smallest ε (pixels).
    pub fn resize_for(
        &mut self,
        device: &wgpu::Device,
        viewport: (u32, u32),
        min_epsilon: f32,
    ) -> Result<(), RenderError> {
        let opts = RendererOptions {
            viewport,
            min_epsilon,
            ..self.opts.clone()
        };
        let capacity = capacity(&self.scene, &opts, self.grown);
        if capacity != self.capacity {
            self.rebuild(device, capacity)?;
        }
        self.opts = opts;
        Ok(())
    }

    /// The view's own buffers rebuilt for `capacity` (the scene is kept).
    fn rebuild(&mut self, device: &wgpu::Device, capacity: Capacity) -> Result<(), RenderError> {
        self.sized = crate::stream_buffers::build_sized(
            device,
            &self.scene,
            &self.passes,
            self.inputs.camera(),
            &self.environment,
            &capacity,
            &readback(self.queries.as_ref(), self.statistics.as_ref()),
        )?;
        self.capacity = capacity;
        Ok(())
    }

    /// Grow the stream after a frame that overflowed it (`stats`: that frame's counters), so
    /// that later frames of such views fit: to the frame's estimated need plus an eighth
    /// (its quads, the level-0 quads dropped, three per quad left unrefined), and at least
    /// 1.5× the capacity, within [`crate::MAX_QUADS`] and the device's limits.
    /// Nothing happens when the frame fit or the options fix the capacity
    /// ([`RendererOptions::max_quads`]). Returns whether the buffers were rebuilt; the
    /// overflowed frame itself is not redrawn. The stream never shrinks.
    pub fn fit(&mut self, device: &wgpu::Device, stats: &FrameStats) -> Result<bool, RenderError> {
        let overflow = u64::from(stats.overflow_cull) + 3 * u64::from(stats.overflow_refine);
        if overflow == 0 || self.opts.max_quads.is_some() {
            return Ok(false);
        }
        let need = u64::from(stats.quads) + overflow;
        let limit = (device.limits().max_storage_buffer_binding_size
            / std::mem::size_of::<Quad>() as u64)
            .min(crate::capacity::MAX_QUADS);
        let quads = (need + need / 8)
            .max(u64::from(self.capacity.quads) * 3 / 2)
            .min(limit) as u32;
        if quads <= self.capacity.quads {
            return Ok(false);
        }
        self.grown = quads;
        self.rebuild(device, capacity(&self.scene, &self.opts, quads))?;
        Ok(true)
    }

    /// The options the stream was built with (viewport: the last [`Self::resize`]).
    pub fn options_built(&self) -> &RendererOptions {
        &self.opts
    }

    /// Number of refinement iterations per frame (`max levels − 1`; 0 without refinement).
    pub fn iterations(&self) -> u32 {
        self.iterations
    }

    /// Choose what the draw pass shows from the next [`ForestView::prepare`] on.
    pub fn set_debug_view(&mut self, view: DebugView) {
        self.debug = view;
    }

    /// Whether frames gather pipeline statistics.
    pub fn pipeline_statistics(&self) -> bool {
        self.inputs.gathers_statistics()
    }

    /// The statistics queries when frames gather them.
    fn counting(&self) -> Option<&StatisticsQueries> {
        self.statistics
            .as_ref()
            .filter(|_| self.inputs.gathers_statistics())
    }

    /// The sky and haze, fixed when the stream was built.
    pub fn atmosphere(&self) -> Atmosphere {
        self.opts.atmosphere
    }

    /// The debug view in use.
    pub fn debug_view(&self) -> DebugView {
        self.debug
    }

    /// Choose the stream's run-time options from the next [`ForestView::prepare`] on.
    pub fn set_options(&mut self, options: StreamOptions) -> Result<(), RenderError> {
        options.validate()?;
        self.options = options;
        Ok(())
    }

    /// The run-time options as [`Self::set_options`] set them (what frames draw with is
    /// [`Self::drawn_options`]: these, with a method's own sharpening while it is set).
    pub fn options(&self) -> StreamOptions {
        self.options
    }

    /// An aspect sharpening (units of 1/[`crate::gpu_types::WEIGHT_ONE`], at most
    /// [`crate::options::SHARPEN_MAX`]) that replaces [`StreamOptions::sharpen`] in the frames
    /// written from the next camera on, whatever [`Self::set_options`] sets; None: the
    /// options' own. A method that draws only some trees as quads sets its own when it is
    /// chosen (the hybrid, for its trees beyond the switch). Refused out of range.
    pub fn set_sharpen_override(&mut self, sharpen: Option<u32>) -> Result<(), RenderError> {
        if let Some(s) = sharpen {
            StreamOptions {
                sharpen: s,
                ..self.options
            }
            .validate()?;
        }
        self.sharpen_override = sharpen;
        Ok(())
    }

    /// Whether the opaque pass runs ([`StreamOptions::opaque_first`]) in the frames written
    /// from the next camera on, whatever [`Self::set_options`] sets; None: the options' own.
    /// The hybrid turns it off for its trees beyond the switch: there it shaded more
    /// fragments than it saved (docs/overdraw.md, "The opaque pass").
    pub fn set_opaque_override(&mut self, opaque_first: Option<bool>) {
        self.opaque_override = opaque_first;
    }

    /// The options the frames are drawn with: [`Self::options`] with the sharpening and
    /// opaque-pass overrides.
    pub fn drawn_options(&self) -> StreamOptions {
        StreamOptions {
            sharpen: self.sharpen_override.unwrap_or(self.options.sharpen),
            opaque_first: self.opaque_override.unwrap_or(self.options.opaque_first),
            ..self.options
        }
    }

    /// Switch refinement on (the quad stream) or off (static impostors: level-0 quads only),
    /// in the shadow maps' light views too (each method casts as it draws).
    pub fn set_refine(&mut self, refine: bool) {
        self.iterations = if refine {
            self.levels.saturating_sub(1)
        } else {
            0
        };
        if let Some(sh) = &mut self.shadows {
            sh.set_refine(refine);
        }
    }

    fn bindings(&self) -> crate::passes::StreamBindings<'_> {
        crate::passes::StreamBindings {
            cull: &self.sized.bg_cull,
            instances: self.scene.tables.instances.len() as u32,
            ping: &self.sized.bg_ab,
            pong: &self.sized.bg_ba,
            args_group: &self.sized.args_group,
            args_buf: &self.sized.args,
        }
    }

    fn write_camera(&mut self, queue: &wgpu::Queue, mut g: GpuCamera) {
        g.debug_view = self.debug.shader_value() as f32;
        self.drawn_options().apply(&mut g);
        let own = self
            .shadows
            .as_ref()
            .map(|sh| (sh.options(), self.drawn_options(), sh.targets().band()));
        self.inputs.upload(queue, g, own);
    }

    /// [`ForestView::render_frame`], drawn again while the frame overflows the stream and
    /// [`Self::fit`] can grow it; the last frame's counters (waits for the GPU: front ends
    /// that draw single frames, benchmarks).
    pub fn render_fitted(
        &mut self,
        ctx: &GpuContext,
        camera: &Camera,
        target: &crate::target::Target,
    ) -> Result<FrameStats, RenderError> {
        loop {
            self.render_frame(ctx, camera, target)?;
            let stats = self.read_stats(ctx);
            let grew = self.fit(&ctx.device, &stats)? | self.fit_shadows(ctx)?;
            if !grew {
                return Ok(stats);
            }
        }
    }

    /// A host's frame: cull and refine, then the quads drawn into `targets` with its load
    /// operations (no ground, nothing cleared unless `targets` says so).
    pub fn encode_into(&self, encoder: &mut wgpu::CommandEncoder, targets: &Targets) {
        ForestView::encode_compute(self, encoder);
        {
            let mut pass = targets.begin(encoder, "forest", Form::draw_timestamps(self));
            self.render(&mut pass);
        }
        self.resolve_times(encoder);
    }

    /// The shadow maps' passes alone, when shadows are on: the quad stream's light views
    /// when `quads`, and `extra`'s (the geometry renderer's, for the methods it draws).
    pub fn encode_shadows(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        quads: bool,
        extra: Option<&dyn crate::shadow_maps::Caster>,
    ) {
        if let Some(sh) = &self.shadows {
            sh.encode_with(encoder, self.inputs.camera(), quads, extra);
        }
    }

    /// The view's own cull and refine, without the shadow maps' passes.
    pub fn encode_view_compute(&self, encoder: &mut wgpu::CommandEncoder) {
        let ts = |b: u32| {
            self.queries
                .as_ref()
                .map(|(set, _)| wgpu::ComputePassTimestampWrites {
                    query_set: set,
                    beginning_of_pass_write_index: Some(b),
                    end_of_pass_write_index: Some(b + 1),
                })
        };
        let p = &self.passes;
        let stats = self.counting().map(|q| &q.set);
        let mut dispatches = 0;
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("cull"),
                timestamp_writes: ts(0),
            });
            if let Some(set) = stats {
                pass.begin_pipeline_statistics_query(set, crate::work::CULL);
            }
            let mut counted = CountingPass::new(&mut pass);
            p.cull
                .record(&mut counted, &self.bindings(), self.iterations == 0);
            dispatches += counted.dispatches;
            if stats.is_some() {
                pass.end_pipeline_statistics_query();
            }
        }
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("refine"),
                timestamp_writes: ts(2),
            });
            if let Some(set) = stats {
                pass.begin_pipeline_statistics_query(set, crate::work::REFINE);
            }
            let mut counted = CountingPass::new(&mut pass);
            p.refine
                .record(&mut counted, self.iterations, &self.bindings());
            dispatches += counted.dispatches;
            if stats.is_some() {
                pass.end_pipeline_statistics_query();
            }
        }
        self.recorded.0.store(dispatches, Ordering::Relaxed);
    }

    fn decode(
        &self,
        state: &[u8],
        times: Option<&[u8]>,
        statistics: Option<&[u8]>,
        period: f32,
    ) -> FrameStats {
        let work = FrameWork {
            dispatches: self.recorded.0.load(Ordering::Relaxed),
            draws: self.recorded.1.load(Ordering::Relaxed),
            passes: statistics
                .filter(|_| self.inputs.gathers_statistics())
                .and_then(crate::work::decode),
            bytes: self.scene.bytes
                + self.sized.view_bytes
                + self.shadows.as_ref().map_or(0, |s| s.bytes()),
        };
        crate::stream_buffers::frame_stats(state, times, self.scene.tables.max_levels, period, work)
    }

    /// Counters (and pass times) of the last submitted frame; waits for the GPU (tests,
    /// benchmarks, screenshots). A frame loop uses [`Self::poll_stats`].
    pub fn read_stats(&self, ctx: &GpuContext) -> FrameStats {
        let state = ctx.read_buffer(&self.sized.state, std::mem::size_of::<GpuState>() as u64);
        let times = self
            .queries
            .as_ref()
            .map(|(_, resolve)| ctx.read_buffer(resolve, crate::stream_buffers::TIMESTAMP_BYTES));
        let statistics = self
            .statistics
            .as_ref()
            .map(|q| ctx.read_buffer(&q.resolve, crate::work::STATISTICS_BYTES));
        self.decode(
            &state,
            times.as_deref(),
            statistics.as_deref(),
            ctx.queue.get_timestamp_period(),
        )
    }

    /// Counters of a recent frame without waiting: `None` until a read-back has arrived
    /// (a few frames late; see [`crate::stats::StatsRing`]).
    pub fn poll_stats(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Option<FrameStats> {
        let parts = self.sized.ring.poll(device, queue)?;
        let (times, statistics) =
            crate::stats::query_parts(&parts, self.queries.is_some(), self.statistics.is_some());
        Some(self.decode(&parts[0], times, statistics, queue.get_timestamp_period()))
    }

    /// The final quad stream of the last submitted frame; waits for the GPU.
    pub fn read_quads(&self, ctx: &GpuContext) -> Vec<Quad> {
        let n = self.read_stats(ctx).quads as usize;
        let buf = &self.sized.quads[(self.iterations % 2) as usize];
        let bytes = ctx.read_buffer(buf, (n * std::mem::size_of::<Quad>()) as u64);
        bytemuck::pod_collect_to_vec(&bytes[..n * std::mem::size_of::<Quad>()])
    }

    /// Labels of the stream's buffers that accept queue writes or copies (only the camera).
    pub fn writable_buffers(&self) -> Vec<&'static str> {
        self.sized
            .owned
            .iter()
            .filter(|(_, b)| b.usage().contains(wgpu::BufferUsages::COPY_DST))
            .map(|(l, _)| *l)
            .collect()
    }
}

/// The quad stream's passes behind the frame API ([`crate::view::ForestView`]): cull, refine,
/// and the draw, which draws the quads back to front, blended, depth-tested, no depth written,
/// after the opaque pass ([`StreamOptions::opaque_first`], on by default), which writes depth
/// where the trees' fronts are opaque, a slab's thickness behind them (so a host's depth
/// attachment must be writable while it runs).
impl crate::view::Form for QuadStream {
    fn inputs(&self) -> &crate::view::FrameInputs {
        &self.inputs
    }

    fn inputs_mut(&mut self) -> &mut crate::view::FrameInputs {
        &mut self.inputs
    }

    fn write_frame(&mut self, queue: &wgpu::Queue, g: GpuCamera) {
        self.write_camera(queue, g);
    }

    fn park_own_shadows(&mut self, _device: &wgpu::Device) {
        self.shadows = None;
    }

    /// The compute passes of a frame: the sun's shadow maps when shadows are on (each
    /// cascade's cull, refine and casting pass, `ShadowMaps::encode`),
    /// then the view's cull and refine.
    fn encode_compute(&self, encoder: &mut wgpu::CommandEncoder) {
        self.encode_shadows(encoder, true, None);
        self.encode_view_compute(encoder);
    }

    /// The counting pipelines, built at the first counter and kept.
    fn build_counting(&mut self, device: &wgpu::Device) {
        if self.counting_draw.is_none() {
            self.counting_draw = Some(self.passes.draw.counting(device, &self.opts));
        }
    }

    /// Timestamp writes for the render pass that draws the stream (its draw time).
    fn draw_timestamps(&self) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        self.queries
            .as_ref()
            .map(|(set, _)| wgpu::RenderPassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: Some(4),
                end_of_pass_write_index: Some(5),
            })
    }

    /// Record the draw into a render pass after [`Self::encode_compute`]: the ground (when
    /// `ground` and the background is the sky), then the quads.
    fn record_draw(&self, pass: &mut wgpu::RenderPass, ground: bool) {
        let draws = self.passes.draw.record(
            pass,
            &self.sized.bg_draw[(self.iterations % 2) as usize],
            self.inputs
                .receivers(self.shadows.as_ref().map(|s| s.receivers())),
            &self.sized.args,
            (ground && self.inputs.background() == Background::Sky).then_some(&self.scene.terrain),
            self.options.far_nearest && self.options.far_composite,
            self.drawn_options().opaque_pass(),
            crate::passes::draw::Measured {
                statistics: self.counting().map(|q| &q.set),
                counted: self
                    .counting_draw
                    .as_ref()
                    .zip(self.inputs.fragment_counts()),
            },
        );
        self.recorded.1.store(draws, Ordering::Relaxed);
    }

    /// Resolve the frame's pass times (all six: the draw's are stale when its pass was not
    /// timed) and counters.
    fn resolve_queries(&self, encoder: &mut wgpu::CommandEncoder, _draw_timed: bool) {
        if let Some((set, resolve)) = &self.queries {
            encoder.resolve_query_set(set, 0..6, resolve, 0);
        }
        if let Some(q) = self.counting() {
            q.resolve(encoder);
        }
    }
}

/// A quad stream casting one cascade of another view's shadow maps.
impl crate::shadow_maps::LightView for QuadStream {
    fn camera_buffer(&self) -> &wgpu::Buffer {
        self.inputs.camera()
    }

    fn encode_view_compute(&self, encoder: &mut wgpu::CommandEncoder) {
        QuadStream::encode_view_compute(self, encoder);
    }

    fn cast_timestamps(&self) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        Form::draw_timestamps(self)
    }

    fn cast_parts(&self) -> (&wgpu::BindGroup, &wgpu::Buffer) {
        (
            &self.sized.bg_draw[(self.iterations % 2) as usize],
            &self.sized.args,
        )
    }

    fn resolve_cast(&self, encoder: &mut wgpu::CommandEncoder) {
        self.resolve_times(encoder);
    }

    fn set_refine(&mut self, refine: bool) {
        QuadStream::set_refine(self, refine);
    }

    fn read_stats(&self, ctx: &GpuContext) -> FrameStats {
        QuadStream::read_stats(self, ctx)
    }

    fn poll_stats(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Option<FrameStats> {
        QuadStream::poll_stats(self, device, queue)
    }

    fn fit(&mut self, device: &wgpu::Device, stats: &FrameStats) -> Result<bool, RenderError> {
        QuadStream::fit(self, device, stats)
    }

    fn view_bytes(&self) -> u64 {
        QuadStream::view_bytes(self)
    }
}
