//! Every method behind one switch: the quad stream, static impostors (the stream without
//! refinement), the geometry-based methods (full geometry, stochastic simplification,
//! discrete LODs + billboards), and the hybrid (near trees as geometry, the rest as quads).
//! Switching is a uniform write or an iteration count: nothing is rebuilt, so a viewer or a
//! benchmark can compare methods frame by frame.

use forest_render::camera::{Camera, CameraError};
use forest_render::context::{GpuContext, RenderError};
use forest_render::extend::{FORMS_GEOMETRY, FORMS_QUADS};
use forest_render::options::Background;
use forest_render::stats::PassTimes;
use forest_render::stream::QuadStream;
use forest_render::target::Target;
use forest_render::view::HostMaps;
use forest_render::{ForestView, Form};

use forest_render::stats::FrameStats;

use crate::geometry::{GeometryRenderer, GeometryStats, MeshMethod};
use crate::hybrid::Hybrid;

/// A rendering method.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// The dynamic quad stream (cull, refine by ε, draw).
    Quads,
    /// Static impostors: the quad stream's level-0 quads, no refinement.
    Impostor,
    /// A geometry-based method.
    Mesh(MeshMethod),
    /// Near trees as a geometry-based method, the rest as the quad stream.
    Hybrid(Hybrid),
}

impl Method {
    /// Short name, as the CLI and the benchmark tables spell it.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Quads => "quads",
            Method::Impostor => "impostor",
            Method::Mesh(MeshMethod::Full { depth_sort: true }) => "geometry",
            Method::Mesh(MeshMethod::Full { depth_sort: false }) => "geometry-unsorted",
            Method::Mesh(MeshMethod::Reference) => "reference",
            Method::Mesh(MeshMethod::Stochastic(_)) => "stochastic",
            Method::Mesh(MeshMethod::Lods(_)) => "lods",
            Method::Hybrid(_) => "hybrid",
        }
    }

    /// Whether the method draws from the species' prepared models (the geometry renderer).
    pub fn needs_models(&self) -> bool {
        matches!(self, Method::Mesh(_) | Method::Hybrid(_))
    }

    /// Whether the method draws trees as quads (the quad stream).
    pub fn draws_quads(&self) -> bool {
        !matches!(self, Method::Mesh(_))
    }

    /// The aspect sharpening the method's quads draw with in place of the stream's own
    /// ([`QuadStream::set_sharpen_override`]): the hybrid's; None for every other method.
    pub fn quad_sharpen(&self) -> Option<u32> {
        match self {
            Method::Hybrid(h) => Some(h.sharpen),
            _ => None,
        }
    }

    /// Whether the method's quads run the opaque pass in place of the stream's own choice
    /// ([`QuadStream::set_opaque_override`]): off for the hybrid, whose quads are the trees
    /// beyond its switch, where the pass shaded more fragments than it saved (see "The opaque
    /// pass" in docs/overdraw.md); None for every other method.
    pub fn quad_opaque_first(&self) -> Option<bool> {
        match self {
            Method::Hybrid(_) => Some(false),
            _ => None,
        }
    }
}

/// Counters of the last frame of whichever method drew it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MethodStats {
    /// Trees that passed the frustum test.
    pub visible_trees: u32,
    /// Quads (quad-stream methods) or triangles (geometry-based methods) drawn; the hybrid's
    /// quads plus its triangles.
    pub primitives: u64,
    /// Trees drawn as billboards (discrete LODs).
    pub billboards: u32,
    /// Trees drawn as geometry by the hybrid (near ones and those in the transition band,
    /// which the quads draw too; a tree in a crossfade between mesh LODs counts once per
    /// LOD); 0 for the other methods.
    pub geometry_trees: u32,
    /// Quads per hierarchy level (quad-stream methods; empty for the others).
    pub per_level: Vec<u32>,
    /// Quads dropped or left unrefined for lack of room (quad-stream methods).
    pub overflow: u32,
    /// GPU pass times, where the adapter has timestamp queries.
    pub times: Option<PassTimes>,
    /// The work the frame asked of the GPU (both forms' for the hybrid).
    pub work: forest_render::work::FrameWork,
    /// The quad stream's own counters (default when the method draws no quads), for
    /// [`ForestRenderer::fit`].
    pub stream: FrameStats,
}

/// The quad stream and, when models were given, the geometry renderer of one forest.
pub struct ForestRenderer {
    /// The quad stream (also the static impostors).
    pub stream: QuadStream,
    /// The geometry-based methods, when the species' models were prepared.
    pub geometry: Option<GeometryRenderer>,
    method: Method,
    /// The shadows asked for ([`Self::set_shadows`]); the reference draws them finer.
    shadows: Option<forest_render::shadow::ShadowOptions>,
}

/// The side of the reference's shadow maps (texels): the largest the options allow, and what
/// wgpu's default limits guarantee. Ground shadows of ten trees from 50 m above matched
/// Mitsuba 3's with IoU 0.72, 0.80 and 0.90 at 2048², 4096² and 8192²
/// (`scripts/validate_shadows.sh`).
pub const REFERENCE_SHADOW_RESOLUTION: u32 = forest_render::shadow::RESOLUTION_RANGE.1;

/// The shadows `method` draws when `asked` are asked for: the reference's maps are
/// [`REFERENCE_SHADOW_RESOLUTION`] texels on a side, so that metrics measure every method's
/// shadows against finer ones.
pub fn shadows_for(
    method: Method,
    asked: Option<forest_render::shadow::ShadowOptions>,
) -> Option<forest_render::shadow::ShadowOptions> {
    asked.map(|mut o| {
        if method == Method::Mesh(MeshMethod::Reference) {
            o.resolution = o.resolution.max(REFERENCE_SHADOW_RESOLUTION);
        }
        o
    })
}

impl ForestRenderer {
    /// Start with the quad stream.
    pub fn new(mut stream: QuadStream, geometry: Option<GeometryRenderer>) -> Self {
        stream.set_refine(true);
        Self {
            stream,
            geometry,
            method: Method::Quads,
            shadows: None,
        }
    }

    /// The current method.
    pub fn method(&self) -> Method {
        self.method
    }

    /// The exact fragment counts of the current method's frame from `camera` into `target`
    /// (drawn twice: see `FragmentCounter::count_frame`). Counting is on only for these two
    /// frames.
    pub fn count_fragments(
        &mut self,
        ctx: &GpuContext,
        camera: &Camera,
        target: &Target,
    ) -> Result<forest_render::fragments::FragmentCounts, RenderError> {
        let counter = forest_render::fragments::FragmentCounter::new(
            &ctx.device,
            target.size.0,
            target.size.1,
            self.stream.options_built().reverse_z,
        )?;
        forest_render::fragments::count_fragments(
            ctx,
            &counter,
            self,
            |r: &mut Self, d, c| ForestView::set_fragment_counter(r, d, c),
            |r| Ok(r.render_frame(ctx, camera, target)?),
        )
    }

    /// Whether frames gather pipeline statistics.
    pub fn pipeline_statistics(&self) -> bool {
        self.stream.pipeline_statistics()
    }

    /// Cast and receive the sun's shadows with `opts` from the next frame on, or not
    /// (`None`), for every method: one set of maps, the quad stream's, which the geometry
    /// renderer casts into and reads as well (so the hybrid's two forms share them). The
    /// reference draws them in finer maps ([`shadows_for`]).
    pub fn set_shadows(
        &mut self,
        device: &wgpu::Device,
        opts: Option<forest_render::shadow::ShadowOptions>,
    ) -> Result<(), RenderError> {
        self.apply_shadows(device, self.method, opts)?;
        self.shadows = opts;
        Ok(())
    }

    /// Make the maps `method` draws with `asked` shadows, shared by both renderers.
    fn apply_shadows(
        &mut self,
        device: &wgpu::Device,
        method: Method,
        asked: Option<forest_render::shadow::ShadowOptions>,
    ) -> Result<(), RenderError> {
        self.stream
            .set_shadows(device, shadows_for(method, asked))?;
        if let Some(g) = &mut self.geometry {
            g.share_shadows(device, self.stream.shadows().map(|s| s.targets().clone()));
        }
        Ok(())
    }

    /// Switch the method; the geometry-based ones and the hybrid need the geometry renderer.
    pub fn set_method(&mut self, ctx: &GpuContext, method: Method) -> Result<(), RenderError> {
        let missing = RenderError::MissingData {
            method: method.name(),
            needs: "the species' OBJ models",
        };
        match method {
            Method::Quads | Method::Impostor => self.stream.set_refine(method == Method::Quads),
            Method::Mesh(m) => self.geometry.as_mut().ok_or(missing)?.set_method(ctx, m)?,
            Method::Hybrid(h) => {
                h.validate()?;
                let g = self.geometry.as_mut().ok_or(missing)?;
                // Both forms draw into one image: one haze for both.
                if g.atmosphere() != self.stream.atmosphere() {
                    return Err(RenderError::Parameter(
                        "the hybrid needs the same atmosphere for the quad stream and the \
                         geometry renderer (build both from one RendererOptions)"
                            .into(),
                    ));
                }
                g.set_method(ctx, h.near_form)?;
                self.stream.set_refine(true);
            }
        }
        self.set_forms(FORMS_QUADS, FORMS_GEOMETRY);
        if shadows_for(method, self.shadows) != shadows_for(self.method, self.shadows) {
            self.apply_shadows(&ctx.device, method, self.shadows)?;
        }
        // The hybrid's quads draw with its own sharpening; every other method with the
        // stream's options. Set with the method, once nothing can fail (validated above).
        self.stream.set_sharpen_override(method.quad_sharpen())?;
        self.stream.set_opaque_override(method.quad_opaque_first());
        self.method = method;
        Ok(())
    }

    /// Which trees each form draws from the next frame on: `quads` for the stream, `geometry`
    /// for the geometry renderer ([`forest_render::extend::switch_unit`]).
    fn set_forms(&mut self, quads: [f32; 4], geometry: [f32; 4]) {
        self.stream.inputs_mut().set_forms(quads);
        if let Some(g) = &mut self.geometry {
            g.inputs_mut().set_forms(geometry);
        }
    }

    /// Every form, drawn by the current method or not (for state every form keeps).
    fn forms_mut(&mut self) -> impl Iterator<Item = &mut dyn ForestView> {
        std::iter::once(&mut self.stream as &mut dyn ForestView)
            .chain(self.geometry.as_mut().map(|g| g as &mut dyn ForestView))
    }

    /// The forms the current method draws: the geometry (drawn first, opaque, depth
    /// written) and the quads (then, back to front, depth-tested against it).
    fn drawn(&self) -> (Option<&GeometryRenderer>, Option<&QuadStream>) {
        match (self.method, &self.geometry) {
            (Method::Mesh(_), Some(g)) => (Some(g), None),
            (Method::Hybrid(_), Some(g)) => (Some(g), Some(&self.stream)),
            _ => (None, Some(&self.stream)),
        }
    }

    /// Write each form's camera for the current method with `write`; the hybrid's per-tree
    /// forms first, from `forms`.
    fn write_drawn<E>(
        &mut self,
        forms: impl FnOnce(&crate::hybrid::Hybrid) -> [f32; 4],
        mut write: impl FnMut(&mut dyn ForestView) -> Result<(), E>,
    ) -> Result<(), E> {
        if let Method::Hybrid(h) = self.method {
            let f = forms(&h);
            self.set_forms(f, f);
        }
        let (g, q) = self.drawn();
        let (g, q) = (g.is_some(), q.is_some());
        if q {
            write(&mut self.stream)?;
        }
        match &mut self.geometry {
            Some(geo) if g => write(geo),
            _ => Ok(()),
        }
    }

    /// A new largest viewport: the quad stream's per-view buffers are rebuilt for it (see
    /// `QuadStream::resize`); the geometry's buffers do not depend on the viewport.
    pub fn resize(
        &mut self,
        device: &wgpu::Device,
        viewport: (u32, u32),
    ) -> Result<(), RenderError> {
        self.stream.resize(device, viewport)
    }

    /// Camera writes of both forms since they were created: (count, bytes). A hybrid frame
    /// writes the camera once for each form and nothing else.
    pub fn uploads(&self) -> (u64, u64) {
        ForestView::uploads(self)
    }

    /// [`ForestView::render_frame`], drawn again while the frame overflows the quad stream and
    /// [`Self::fit`] can grow it; the last frame's counters (waits for the GPU).
    pub fn render_fitted(
        &mut self,
        ctx: &GpuContext,
        camera: &Camera,
        target: &Target,
    ) -> Result<MethodStats, RenderError> {
        loop {
            self.render_frame(ctx, camera, target)?;
            let stats = self.read_stats(ctx);
            // The light views' streams grow too, so no tree is left out of the shadows.
            if !(self.fit(&ctx.device, &stats)? | self.stream.fit_shadows(ctx)?) {
                return Ok(stats);
            }
        }
    }

    /// Grow the quad stream after a frame that overflowed it (see [`QuadStream::fit`]).
    /// Returns whether its buffers were rebuilt.
    pub fn fit(&mut self, device: &wgpu::Device, stats: &MethodStats) -> Result<bool, RenderError> {
        self.stream.fit(device, &stats.stream)
    }

    /// Counters and pass times of the last submitted frame; waits for the GPU.
    pub fn read_stats(&self, ctx: &GpuContext) -> MethodStats {
        self.combine(
            || self.stream.read_stats(ctx),
            |g: &GeometryRenderer| g.read_stats(ctx),
        )
    }

    /// Counters of a recent frame without waiting (a few frames late; `None` until the
    /// read-backs of the current method have arrived): for frame loops.
    pub fn poll_stats(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Option<MethodStats> {
        let quads = || self.stream.poll_stats(device, queue);
        let geometry = |g: &GeometryRenderer| g.poll_stats(device, queue);
        match (self.method, &self.geometry) {
            (Method::Hybrid(_), Some(g)) => {
                // Both rings are polled every time, so they advance together.
                let (q, s) = (quads(), geometry(g));
                let (q, s) = (q?, s?);
                Some(self.combine(|| q, |_| s))
            }
            (Method::Mesh(_), Some(g)) => {
                let s = geometry(g)?;
                Some(self.combine(FrameStats::default, |_| s))
            }
            _ => {
                let q = quads()?;
                Some(self.combine(|| q, |_| GeometryStats::default()))
            }
        }
    }

    /// The current method's statistics from the stream's and the geometry renderer's.
    fn combine(
        &self,
        quads: impl FnOnce() -> FrameStats,
        geometry: impl FnOnce(&GeometryRenderer) -> GeometryStats,
    ) -> MethodStats {
        match (self.method, &self.geometry) {
            (Method::Hybrid(_), Some(g)) => {
                let q = quads();
                let s = geometry(g);
                MethodStats {
                    visible_trees: q.visible_trees,
                    primitives: u64::from(q.quads) + s.triangles,
                    billboards: s.billboards,
                    geometry_trees: s.visible_trees,
                    per_level: q.per_level.clone(),
                    overflow: q.overflow_cull + q.overflow_refine,
                    times: q.times.zip(s.times).map(|(q, s)| PassTimes {
                        cull_ms: q.cull_ms + s.cull_ms,
                        refine_ms: q.refine_ms,
                        draw_ms: q.draw_ms,
                    }),
                    work: q.work.combined(&s.work),
                    stream: q.clone(),
                }
            }
            (Method::Mesh(_), Some(g)) => {
                let s = geometry(g);
                MethodStats {
                    visible_trees: s.visible_trees,
                    primitives: s.triangles,
                    billboards: s.billboards,
                    geometry_trees: 0,
                    per_level: Vec::new(),
                    overflow: 0,
                    times: s.times,
                    work: s.work,
                    stream: FrameStats::default(),
                }
            }
            _ => {
                let s = quads();
                MethodStats {
                    visible_trees: s.visible_trees,
                    primitives: u64::from(s.quads),
                    billboards: 0,
                    geometry_trees: 0,
                    per_level: s.per_level.clone(),
                    overflow: s.overflow_cull + s.overflow_refine,
                    times: s.times,
                    work: s.work.clone(),
                    stream: s,
                }
            }
        }
    }
}

/// Every method through one frame API: state every form keeps goes to both forms, a frame to
/// the forms the method draws. The hybrid's stream casts both forms into the shared shadow
/// maps, each tree in the form it is drawn in.
impl ForestView for ForestRenderer {
    fn set_background(&mut self, background: Background) {
        self.forms_mut().for_each(|f| f.set_background(background));
    }

    fn background(&self) -> Background {
        self.stream.background()
    }

    /// Both forms' light, so that the hybrid's two forms agree.
    fn set_light(&mut self, light: forest_format::shading::Lighting) -> Result<(), RenderError> {
        self.forms_mut().try_for_each(|f| f.set_light(light))
    }

    fn light(&self) -> forest_format::shading::Lighting {
        self.stream.light()
    }

    /// Both forms' wind, so that the hybrid's two forms move alike.
    fn set_wind(&mut self, wind: forest_format::wind::Wind) -> Result<(), RenderError> {
        self.forms_mut().try_for_each(|f| f.set_wind(wind))
    }

    fn wind(&self) -> forest_format::wind::Wind {
        self.stream.wind()
    }

    /// Both forms' season, so that the hybrid's two forms colour a tree alike.
    fn set_season(&mut self, season: Option<f32>) -> Result<(), RenderError> {
        self.forms_mut().try_for_each(|f| f.set_season(season))
    }

    fn season(&self) -> Option<f32> {
        self.stream.season()
    }

    fn set_pipeline_statistics(&mut self, on: bool) {
        self.forms_mut().for_each(|f| f.set_pipeline_statistics(on));
    }

    fn set_fragment_counter(
        &mut self,
        device: &wgpu::Device,
        counter: Option<&forest_render::fragments::FragmentCounter>,
    ) {
        self.forms_mut()
            .for_each(|f| f.set_fragment_counter(device, counter));
    }

    fn receive_host_shadows(&mut self, device: &wgpu::Device, maps: Option<HostMaps<'_>>) {
        self.forms_mut()
            .for_each(|f| f.receive_host_shadows(device, maps));
    }

    fn set_host_cascades(
        &mut self,
        cascades: &[forest_render::shadow::Cascade],
    ) -> Result<(), RenderError> {
        self.forms_mut()
            .try_for_each(|f| f.set_host_cascades(cascades))
    }

    /// The current method's cameras from the host's matrices; the hybrid's per-tree forms
    /// follow the projection's focal length.
    fn prepare(
        &mut self,
        queue: &wgpu::Queue,
        frame: &forest_render::FrameParams,
    ) -> Result<(), RenderError> {
        frame.validate()?;
        let focal = frame.focal_pixels();
        self.write_drawn(|h| h.forms_for_focal(focal), |f| f.prepare(queue, frame))
    }

    fn set_camera(&mut self, ctx: &GpuContext, camera: &Camera) -> Result<(), CameraError> {
        camera.validate()?;
        self.write_drawn(|h| h.forms(camera), |f| f.set_camera(ctx, camera))
    }

    /// The shadow maps (the forms the method draws cast into them), then each form's cull
    /// (and the quad stream's refinement).
    fn encode_compute(&self, encoder: &mut wgpu::CommandEncoder) {
        match self.drawn() {
            (Some(g), Some(q)) => {
                q.encode_shadows(encoder, true, Some(g));
                q.encode_view_compute(encoder);
                g.encode_view_compute(encoder);
            }
            (Some(g), None) => Form::encode_compute(g, encoder),
            (None, Some(q)) => Form::encode_compute(q, encoder),
            (None, None) => {}
        }
    }

    /// The geometry first (opaque and alpha-tested, depth written; the ground when `ground`),
    /// then the quads back to front, depth-tested.
    fn record(&self, pass: &mut wgpu::RenderPass, ground: bool) {
        match self.drawn() {
            (Some(g), quads) => {
                g.record_draw(pass, ground);
                if let Some(q) = quads {
                    q.record_draw(pass, false);
                }
            }
            (None, Some(q)) => q.record_draw(pass, ground),
            (None, None) => {}
        }
    }

    fn depth_clear(&self) -> f32 {
        self.stream.depth_clear()
    }

    /// The quad stream's draw time when the method draws quads, else the geometry's.
    fn draw_timestamps(&self) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        match self.drawn() {
            (_, Some(q)) => Form::draw_timestamps(q),
            (Some(g), None) => Form::draw_timestamps(g),
            (None, None) => None,
        }
    }

    fn resolve_times(&self, encoder: &mut wgpu::CommandEncoder) {
        let (g, q) = self.drawn();
        if let Some(q) = q {
            q.resolve_queries(encoder, true);
        }
        if let Some(g) = g {
            g.resolve_queries(encoder, q.is_none());
        }
    }

    fn uploads(&self) -> (u64, u64) {
        let (n, b) = self.stream.uploads();
        let (gn, gb) = self.geometry.as_ref().map_or((0, 0), |g| g.uploads());
        (n + gn, b + gb)
    }
}
