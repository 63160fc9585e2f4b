//! The quad-stream renderer: buffers, bind groups, and the frame function that records the
//! three passes in order. Per frame the CPU writes the camera and nothing else.

use std::cell::Cell;

use forest_format::shading::Lighting;
use wgpu::util::DeviceExt;

use crate::camera::{Camera, CameraError};
use crate::capacity::{Capacity, CapacityInput};
use crate::context::{GpuContext, RenderError};
use crate::gpu_types::{GpuArgs, GpuCamera, GpuGround, GpuState, Quad, SceneConsts};
use crate::passes::ComputeShared;
use crate::passes::cull::CullPass;
use crate::passes::draw::DrawPass;
use crate::passes::refine::RefinePass;
use crate::passes::scan::ScanPass;
use crate::scene::GpuScene;

/// What the trees are drawn over.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Background {
    /// Sky colour and a ground plane (the demo).
    #[default]
    Sky,
    /// Transparent black, no ground: the alpha channel is the trees' coverage (for metrics).
    Transparent,
}

impl Background {
    /// The colour a frame is cleared to.
    pub fn clear_colour(self) -> wgpu::Color {
        match self {
            Background::Sky => SKY,
            Background::Transparent => wgpu::Color::TRANSPARENT,
        }
    }
}

/// Options of a renderer.
#[derive(Clone, Debug, PartialEq)]
pub struct RendererOptions {
    /// Colour target format.
    pub format: wgpu::TextureFormat,
    /// Largest viewport the renderer will draw (sizes the stream).
    pub viewport: (u32, u32),
    /// Smallest ε that will be used (sizes the stream).
    pub min_epsilon: f32,
    /// Quad layers per pixel the stream affords.
    pub overdraw: f32,
    /// Explicit quad capacity (overrides the formula; tests use small ones to force overflow).
    pub max_quads: Option<u32>,
    /// Lighting for the ground (the atlases carry their own baked lighting).
    pub lighting: Lighting,
    /// Sky and ground, or transparent.
    pub background: Background,
    /// Refine the stream (the method). `false` draws the level-0 quads only: the static
    /// impostor baseline (each tree as its 1–3 blended slab images, never subdivided).
    pub refine: bool,
}

impl Default for RendererOptions {
    fn default() -> Self {
        Self {
            format: wgpu::TextureFormat::Rgba8UnormSrgb,
            viewport: (800, 600),
            min_epsilon: 8.0,
            overdraw: 16.0,
            max_quads: None,
            lighting: Lighting::with_sun(30.0, 55.0),
            background: Background::Sky,
            refine: true,
        }
    }
}

/// Per-pass GPU times in milliseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PassTimes {
    /// Cull.
    pub cull_ms: f64,
    /// Refine (all iterations and statistics).
    pub refine_ms: f64,
    /// Draw (ground and quads).
    pub draw_ms: f64,
}

/// Counters of the last frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameStats {
    /// Presort direction used.
    pub presort: u32,
    /// Trees that passed the frustum test.
    pub visible_trees: u32,
    /// Quads drawn.
    pub quads: u32,
    /// Quads per level.
    pub per_level: Vec<u32>,
    /// Level-0 quads dropped for lack of room.
    pub overflow_cull: u32,
    /// Quads left unrefined for lack of room.
    pub overflow_refine: u32,
    /// GPU pass times, where the adapter has timestamp queries.
    pub times: Option<PassTimes>,
}

/// What the draw pass shows: the stream's colours, or one of the viewer's debug views.
/// Takes effect with the next camera write (it travels in the camera uniform's `viewport.z`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DebugView {
    /// The textured quads (the product).
    #[default]
    Off,
    /// Every quad in the colour of its hierarchy level ([`LEVEL_COLOURS`]), times its coverage.
    Levels,
    /// Every quad in the colour of its sampling direction, blended with its aspect weight, so
    /// the mix of directions at a pixel shows the blend.
    Weights,
    /// The textured quads with their outlines drawn over them.
    Wireframe,
}

impl DebugView {
    /// Every view, in the order the viewer cycles through them.
    pub const ALL: [DebugView; 4] = [
        DebugView::Off,
        DebugView::Levels,
        DebugView::Weights,
        DebugView::Wireframe,
    ];

    /// Short name for menus and file names.
    pub fn name(self) -> &'static str {
        match self {
            DebugView::Off => "off",
            DebugView::Levels => "levels",
            DebugView::Weights => "blend weights",
            DebugView::Wireframe => "wireframe",
        }
    }
}

/// How the 1–3 aspects (sampling directions) of a tree are combined where they overlap.
///
/// The default is [`AspectBlend::Over`], chosen by measurement (`forest bench fidelity`): with
/// the gap-aware bake its union of silhouettes covers about as many pixels as the reference
/// (1.02× at 14 m from a bundled oak), while each single aspect misses what its two slabs
/// could not see from its own direction, so the dither's weighted mean of coverages falls
/// short (0.95×) and its FLIP is no better anywhere we looked.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AspectBlend {
    /// Alpha-composited "over" each other with alpha `w_a / Σ_{b ≤ a} w_b`: the weighted mean
    /// where every aspect is opaque, the union of their silhouettes elsewhere (the paper's
    /// blending).
    #[default]
    Over,
    /// Every pixel shows exactly one aspect, chosen by an ordered dither with probability equal
    /// to its weight (per tree), so the blended coverage is the weighted mean of the aspects'
    /// coverages.
    Dither,
    /// The aspect of largest weight alone (pops where the view crosses a direction).
    Nearest,
}

impl AspectBlend {
    /// Every blend, the default first.
    pub const ALL: [AspectBlend; 3] =
        [AspectBlend::Over, AspectBlend::Dither, AspectBlend::Nearest];

    /// The blend named `name` ([`AspectBlend::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|b| b.name() == name)
    }

    /// Short name for the CLI and the benchmark tables.
    pub fn name(self) -> &'static str {
        match self {
            AspectBlend::Dither => "dither",
            AspectBlend::Over => "over",
            AspectBlend::Nearest => "nearest",
        }
    }
}

/// Run-time choices of the quad stream. They travel in the camera uniform's `viewport.w` as
/// bit flags ([`StreamOptions::flags`]), so the camera stays the only per-frame upload.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StreamOptions {
    /// How overlapping aspects combine.
    pub blend: AspectBlend,
    /// Refine a quad also when its depth error (the largest distance between its drawn
    /// surface and its pixels, as a displacement along its sampling direction projected to
    /// the screen from the current view) exceeds ε. Off (the default): the paper's metric
    /// alone (projected edge length). Measured on a bundled oak at 14–30 m, the error metric
    /// buys 1–3 % lower FLIP for 2–6× the quads, where a smaller ε buys as much for fewer
    /// quads, so it is off unless asked for.
    pub depth_error: bool,
}

impl Default for StreamOptions {
    fn default() -> Self {
        Self {
            blend: AspectBlend::Over,
            depth_error: false,
        }
    }
}

/// Flag bits of [`StreamOptions`] in `viewport.w`; mirrored in `shaders/common.wgsl`.
pub const FLAG_DITHER: u32 = 1;
/// See [`FLAG_DITHER`].
pub const FLAG_NEAREST: u32 = 2;
/// See [`FLAG_DITHER`].
pub const FLAG_DEPTH_ERROR: u32 = 4;

impl StreamOptions {
    /// The flag bits written to the camera uniform's `viewport.w`.
    pub fn flags(self) -> u32 {
        let blend = match self.blend {
            AspectBlend::Dither => FLAG_DITHER,
            AspectBlend::Over => 0,
            AspectBlend::Nearest => FLAG_NEAREST,
        };
        blend
            | if self.depth_error {
                FLAG_DEPTH_ERROR
            } else {
                0
            }
    }
}

/// Colours of levels 0, 1, … in the [`DebugView::Levels`] view (linear RGB; level `l` uses
/// entry `l % 8`). Mirrored by `level_colour` in `shaders/draw.wgsl`.
pub const LEVEL_COLOURS: [[f32; 3]; 8] = [
    [0.9, 0.1, 0.1],
    [0.95, 0.55, 0.05],
    [0.9, 0.9, 0.1],
    [0.1, 0.8, 0.1],
    [0.1, 0.8, 0.8],
    [0.1, 0.2, 0.95],
    [0.6, 0.1, 0.9],
    [0.95, 0.95, 0.95],
];

/// Colour of sampling direction `dir` in the [`DebugView::Weights`] view (linear RGB): hues
/// spaced by the golden ratio, softened. Mirrors `direction_colour` in `shaders/draw.wgsl`.
pub fn direction_colour(dir: u32) -> [f32; 3] {
    let h = (dir as f32 * 0.618034).fract();
    [0.0, 2.0 / 3.0, 1.0 / 3.0].map(|k: f32| {
        let v = (((h + k).fract() * 6.0 - 3.0).abs() - 1.0).clamp(0.0, 1.0);
        0.15 + 0.8 * v
    })
}

/// Background colour (sky) the demo clears to, linear RGB.
pub const SKY: wgpu::Color = wgpu::Color {
    r: 0.45,
    g: 0.62,
    b: 0.85,
    a: 1.0,
};

/// The ground's uniform: the ground albedo lit by the shared shading model (facing up, in sun),
/// and a square reaching 5 km beyond the farthest tree.
pub fn ground_uniform(
    lighting: &Lighting,
    instances: &[crate::gpu_types::GpuInstance],
) -> GpuGround {
    let extent = instances
        .iter()
        .map(|i| glam::Vec3::from_array(i.position).length())
        .fold(0.0f32, f32::max);
    let lit = lighting.shade(glam::Vec3::new(0.16, 0.14, 0.09), glam::Vec3::Y, 1.0, 0.0);
    GpuGround {
        colour: [lit.x, lit.y, lit.z, extent + 5000.0],
    }
}

/// The renderer of one scene.
pub struct QuadStream {
    /// The uploaded scene.
    pub scene: GpuScene,
    /// Buffer sizes.
    pub capacity: Capacity,
    cull: CullPass,
    scan: ScanPass,
    refine: RefinePass,
    draw: DrawPass,
    camera: wgpu::Buffer,
    state: wgpu::Buffer,
    args: wgpu::Buffer,
    quads: [wgpu::Buffer; 2],
    bg_cull: wgpu::BindGroup,
    bg_ab: wgpu::BindGroup,
    bg_ba: wgpu::BindGroup,
    bg_draw: [wgpu::BindGroup; 2],
    levels: u32,
    args_group: wgpu::BindGroup,
    iterations: Cell<u32>,
    queries: Option<(wgpu::QuerySet, wgpu::Buffer, f64)>,
    writes: Cell<(u64, u64)>,
    camera_set: Cell<bool>,
    debug: Cell<DebugView>,
    options: Cell<StreamOptions>,
    forms: Cell<[f32; 4]>,
    background: Background,
    owned: Vec<(&'static str, wgpu::Buffer)>,
}

fn buffer(ctx: &GpuContext, label: &str, size: u64, usage: wgpu::BufferUsages) -> wgpu::Buffer {
    ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(16),
        usage,
        mapped_at_creation: false,
    })
}

impl QuadStream {
    /// Create the renderer of an uploaded scene.
    pub fn new(
        ctx: &GpuContext,
        scene: GpuScene,
        opts: &RendererOptions,
    ) -> Result<Self, RenderError> {
        let t = &scene.tables;
        let capacity = Capacity::new(&CapacityInput {
            instances: t.instances.len() as u32,
            quads_per_tree: t.quads_per_tree.max(1),
            viewport: opts.viewport,
            min_epsilon: opts.min_epsilon,
            overdraw: opts.overdraw,
            max_quads: opts.max_quads,
        });
        let limit = ctx.device.limits().max_storage_buffer_binding_size;
        let quad_bytes = u64::from(capacity.quads) * std::mem::size_of::<Quad>() as u64;
        if quad_bytes > limit {
            return Err(RenderError::DeviceLimit {
                what: format!("a stream of {} quads (bytes per buffer)", capacity.quads),
                needed: quad_bytes,
                limit,
                hint: ": lower the viewport or raise the minimum epsilon",
            });
        }
        let device = &ctx.device;
        let shared = ComputeShared::new(device);
        let cull = CullPass::new(device, &shared);
        let scan = ScanPass::new(device, &shared);
        let refine = RefinePass::new(device, &shared);
        let draw = DrawPass::new(device, opts.format);

        use wgpu::BufferUsages as U;
        let camera = buffer(
            ctx,
            "camera",
            std::mem::size_of::<GpuCamera>() as u64,
            U::UNIFORM | U::COPY_DST,
        );
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
        let ground = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("ground"),
            contents: bytemuck::bytes_of(&ground_uniform(&opts.lighting, &t.instances)),
            usage: U::UNIFORM,
        });
        let state = buffer(
            ctx,
            "state",
            std::mem::size_of::<GpuState>() as u64,
            U::STORAGE | U::COPY_SRC,
        );
        let args = buffer(
            ctx,
            "args",
            std::mem::size_of::<GpuArgs>() as u64,
            U::STORAGE | U::INDIRECT,
        );
        let spare = buffer(ctx, "spare", 16, U::STORAGE);
        let args_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("indirect arguments"),
            layout: &shared.args_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: args.as_entire_binding(),
            }],
        });
        let data = buffer(ctx, "scan data", u64::from(capacity.items) * 4, U::STORAGE);
        let want = buffer(ctx, "want", u64::from(capacity.items) * 4, U::STORAGE);
        let sums = buffer(ctx, "block sums", u64::from(capacity.sums) * 4, U::STORAGE);
        let quads = [0, 1].map(|k| {
            buffer(
                ctx,
                if k == 0 { "stream A" } else { "stream B" },
                quad_bytes,
                U::STORAGE | U::COPY_SRC,
            )
        });
        let presort_view = scene.presort.create_view(&Default::default());
        let nodes_view = scene.nodes.create_view(&Default::default());
        let compute_bg = |label: &str, q_in: &wgpu::Buffer, q_out: &wgpu::Buffer| {
            let res: [wgpu::BindingResource; 17] = [
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
                spare.as_entire_binding(),
                data.as_entire_binding(),
                sums.as_entire_binding(),
                want.as_entire_binding(),
                q_in.as_entire_binding(),
                q_out.as_entire_binding(),
            ];
            let entries = crate::passes::numbered(res.into());
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout: &shared.bind_layout,
                entries: &entries,
            })
        };
        let bg_cull = compute_bg("cull", &quads[1], &quads[0]);
        let bg_ab = compute_bg("refine A->B", &quads[0], &quads[1]);
        let bg_ba = compute_bg("refine B->A", &quads[1], &quads[0]);
        let levels = t.max_levels;
        let iterations = if opts.refine {
            t.max_levels.saturating_sub(1)
        } else {
            0
        };
        let colour_view = scene.colour.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("colour"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        // One draw group per stream buffer: the final stream is A after an even number of
        // refinement iterations, B after an odd one (refinement can be switched at run time).
        let bg_draw = [&quads[0], &quads[1]].map(|final_quads| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("draw"),
                layout: &draw.bind_layout,
                entries: &crate::passes::numbered(vec![
                    camera.as_entire_binding(),
                    scene.instances.as_entire_binding(),
                    scene.species.as_entire_binding(),
                    scene.frames.as_entire_binding(),
                    final_quads.as_entire_binding(),
                    wgpu::BindingResource::TextureView(&nodes_view),
                    wgpu::BindingResource::TextureView(&colour_view),
                    wgpu::BindingResource::Sampler(&sampler),
                    ground.as_entire_binding(),
                ]),
            })
        });
        let owned: Vec<(&'static str, wgpu::Buffer)> = [
            ("camera", &camera),
            ("scene constants", &consts),
            ("ground", &ground),
            ("state", &state),
            ("args", &args),
            ("spare", &spare),
            ("scan data", &data),
            ("want", &want),
            ("block sums", &sums),
            ("stream A", &quads[0]),
            ("stream B", &quads[1]),
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
        let queries = device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY)
            .then(|| {
                let set = device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("pass times"),
                    ty: wgpu::QueryType::Timestamp,
                    count: 6,
                });
                let resolve = buffer(ctx, "timestamps", 48, U::QUERY_RESOLVE | U::COPY_SRC);
                (set, resolve, f64::from(ctx.queue.get_timestamp_period()))
            });
        Ok(Self {
            scene,
            capacity,
            cull,
            scan,
            refine,
            draw,
            camera,
            state,
            args,
            quads,
            bg_cull,
            bg_ab,
            bg_ba,
            bg_draw,
            args_group,
            iterations: Cell::new(iterations),
            levels,
            queries,
            writes: Cell::new((0, 0)),
            camera_set: Cell::new(false),
            debug: Cell::new(DebugView::Off),
            options: Cell::new(StreamOptions::default()),
            forms: Cell::new(crate::forms::FORMS_QUADS),
            background: opts.background,
            owned,
        })
    }

    /// Number of refinement iterations per frame (`max levels − 1`; 0 without refinement).
    pub fn iterations(&self) -> u32 {
        self.iterations.get()
    }

    /// Choose what the draw pass shows from the next camera write on.
    pub fn set_debug_view(&self, view: DebugView) {
        self.debug.set(view);
    }

    /// The debug view in use.
    pub fn debug_view(&self) -> DebugView {
        self.debug.get()
    }

    /// Choose the stream's run-time options from the next camera write on.
    pub fn set_options(&self, options: StreamOptions) {
        self.options.set(options);
    }

    /// The run-time options in use.
    pub fn options(&self) -> StreamOptions {
        self.options.get()
    }

    /// What the trees are drawn over.
    pub fn background(&self) -> Background {
        self.background
    }

    /// Which trees the stream draws from the next camera write on (the camera's `forms`, see
    /// [`crate::hybrid`]); [`crate::forms::FORMS_QUADS`], every tree, unless the hybrid
    /// method set it.
    pub fn set_forms(&self, forms: [f32; 4]) {
        self.forms.set(forms);
    }

    /// Switch refinement on (the quad stream) or off (static impostors: level-0 quads only).
    pub fn set_refine(&self, refine: bool) {
        self.iterations.set(if refine {
            self.levels.saturating_sub(1)
        } else {
            0
        });
    }

    fn bindings(&self) -> crate::passes::StreamBindings<'_> {
        crate::passes::StreamBindings {
            cull: &self.bg_cull,
            ping: &self.bg_ab,
            pong: &self.bg_ba,
            args_group: &self.args_group,
            args_buf: &self.args,
        }
    }

    /// Write the camera, record a frame into `target` and submit it.
    pub fn render_frame(
        &self,
        ctx: &GpuContext,
        camera: &Camera,
        target: &crate::target::Target,
    ) -> Result<(), CameraError> {
        self.set_camera(ctx, camera)?;
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        self.encode(&mut enc, &target.colour_view, &target.depth_view);
        ctx.queue.submit([enc.finish()]);
        Ok(())
    }

    /// Write the camera: the one upload of a frame.
    pub fn set_camera(&self, ctx: &GpuContext, camera: &Camera) -> Result<(), CameraError> {
        camera.validate()?;
        let mut g = camera.to_gpu();
        g.viewport[2] = self.debug.get() as u32 as f32;
        g.viewport[3] = self.options.get().flags() as f32;
        g.forms = self.forms.get();
        crate::camera::upload(&ctx.queue, &self.camera, &g, &self.writes);
        self.camera_set.set(true);
        Ok(())
    }

    /// Queue writes made by this renderer since it was created: (count, bytes).
    pub fn uploads(&self) -> (u64, u64) {
        self.writes.get()
    }

    /// The frame function: cull, refine and draw into `colour` (cleared to the sky) and
    /// `depth` (cleared to 1). `set_camera` must have been called once before.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        colour: &wgpu::TextureView,
        depth: &wgpu::TextureView,
    ) {
        self.encode_compute(encoder);
        {
            let mut pass = crate::target::begin_pass(
                encoder,
                "draw",
                colour,
                depth,
                self.background.clear_colour(),
                self.draw_timestamps(),
            );
            self.record_draw(&mut pass, true);
        }
        self.resolve_times(encoder);
    }

    /// The compute passes of a frame: cull and refine. `set_camera` must have been called
    /// once before.
    pub fn encode_compute(&self, encoder: &mut wgpu::CommandEncoder) {
        assert!(self.camera_set.get(), "set_camera before the first frame");
        let ts = |b: u32| {
            self.queries
                .as_ref()
                .map(|(set, _, _)| wgpu::ComputePassTimestampWrites {
                    query_set: set,
                    beginning_of_pass_write_index: Some(b),
                    end_of_pass_write_index: Some(b + 1),
                })
        };
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("cull"),
                timestamp_writes: ts(0),
            });
            self.cull.record(&mut pass, &self.bindings(), &self.scan);
        }
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("refine"),
                timestamp_writes: ts(2),
            });
            self.refine
                .record(&mut pass, self.iterations(), &self.bindings(), &self.scan);
        }
    }

    /// Timestamp writes for the render pass that draws the stream (its draw time).
    pub fn draw_timestamps(&self) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        self.queries
            .as_ref()
            .map(|(set, _, _)| wgpu::RenderPassTimestampWrites {
                query_set: set,
                beginning_of_pass_write_index: Some(4),
                end_of_pass_write_index: Some(5),
            })
    }

    /// Record the draw into a render pass after [`Self::encode_compute`]: the ground (when
    /// `ground` and the background is the sky), then the quads.
    pub fn record_draw(&self, pass: &mut wgpu::RenderPass, ground: bool) {
        self.draw.record(
            pass,
            &self.bg_draw[(self.iterations() % 2) as usize],
            &self.args,
            ground && self.background == Background::Sky,
        );
    }

    /// Resolve the frame's pass times (after the render pass that used
    /// [`Self::draw_timestamps`]).
    pub fn resolve_times(&self, encoder: &mut wgpu::CommandEncoder) {
        if let Some((set, resolve, _)) = &self.queries {
            encoder.resolve_query_set(set, 0..6, resolve, 0);
        }
    }

    /// Counters (and pass times) of the last submitted frame; waits for the GPU.
    pub fn read_stats(&self, ctx: &GpuContext) -> FrameStats {
        let s: GpuState = bytemuck::pod_read_unaligned(
            &ctx.read_buffer(&self.state, std::mem::size_of::<GpuState>() as u64),
        );
        let levels = self.scene.tables.max_levels.max(1) as usize;
        let times = self.queries.as_ref().map(|(_, resolve, period)| {
            let t: Vec<u64> = bytemuck::pod_collect_to_vec(&ctx.read_buffer(resolve, 48));
            let ms = |a: usize| t[a + 1].saturating_sub(t[a]) as f64 * period / 1e6;
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
            per_level: s.per_level[..levels].to_vec(),
            overflow_cull: s.overflow_cull,
            overflow_refine: s.overflow_refine,
            times,
        }
    }

    /// The final quad stream of the last submitted frame; waits for the GPU.
    pub fn read_quads(&self, ctx: &GpuContext) -> Vec<Quad> {
        let n = self.read_stats(ctx).quads as usize;
        let buf = &self.quads[(self.iterations() % 2) as usize];
        let bytes = ctx.read_buffer(buf, (n * std::mem::size_of::<Quad>()) as u64);
        bytemuck::pod_collect_to_vec(&bytes[..n * std::mem::size_of::<Quad>()])
    }

    /// Labels of the renderer's buffers that accept queue writes or copies (only the camera).
    pub fn writable_buffers(&self) -> Vec<&'static str> {
        self.owned
            .iter()
            .filter(|(_, b)| b.usage().contains(wgpu::BufferUsages::COPY_DST))
            .map(|(l, _)| *l)
            .collect()
    }
}
