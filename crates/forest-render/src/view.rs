//! The frame API: one prepared view of a forest, whichever method draws it.
//!
//! ```text
//! set_background / set_light / set_wind / set_forms / receive_host_shadows / set_host_cascades
//!         (state, kept until changed)
//! per frame: prepare (the one upload) ─► encode_compute ─► render (host's pass) ─► resolve_times
//!            or: render_frame (headless: all of it into a cleared target, submitted)
//! ```
//!
//! [`FrameInputs`] is what every form of a forest writes into its camera uniform each frame
//! (the light, the wind, which trees it draws, the host's shadow receivers) and the uniform's buffer with
//! its upload counter. A drawing form (the quad stream; the geometry renderer of
//! `forest-baselines`) holds one and implements [`Form`], its own passes; [`ForestView`], the
//! frame API the front ends drive, follows for every form from that, once. A method made of
//! several forms (the hybrid) implements [`ForestView`] by composing theirs. A per-frame
//! parameter added later goes into [`FrameInputs`] (and the camera uniform it fills), and every
//! form and method receives it.

use crate::camera::{Camera, CameraError};
use crate::context::{GpuContext, RenderError};
use crate::frame::{FrameParams, Targets};
use crate::gpu_types::GpuCamera;
use crate::options::Background;
use crate::receivers::HostShadows;
use crate::target::Target;

/// A host's shadow maps as given to [`ForestView::receive_host_shadows`]: its depth array (a
/// layer per cascade), the side of each layer in texels, and whether it is reverse-Z.
pub type HostMaps<'a> = (&'a wgpu::TextureView, u32, bool);

/// The per-frame inputs a form writes into its camera uniform, and the uniform itself.
pub struct FrameInputs {
    camera: wgpu::Buffer,
    light: forest_format::shading::Lighting,
    wind: forest_format::wind::Wind,
    season: Option<f32>,
    forms: [f32; 4],
    background: Background,
    depth_clear: f32,
    shadow_layout: wgpu::BindGroupLayout,
    no_shadows: wgpu::BindGroup,
    host_shadows: Option<HostShadows>,
    writes: (u64, u64),
    prepared: bool,
    statistics: bool,
    fragment_counts: Option<wgpu::BindGroup>,
}

impl FrameInputs {
    /// The inputs of a form whose camera uniform is `camera`, drawing the trees `forms` selects
    /// ([`crate::extend::quad_share`]) with the light, background and depth convention of `opts`; its draw
    /// reads shadow receivers through `shadow_layout` ([`crate::receivers::receiver_layout`]).
    pub fn new(
        device: &wgpu::Device,
        camera: wgpu::Buffer,
        shadow_layout: wgpu::BindGroupLayout,
        forms: [f32; 4],
        opts: &crate::options::RendererOptions,
    ) -> Self {
        Self {
            no_shadows: crate::receivers::no_shadows(device, &shadow_layout),
            camera,
            light: opts.lighting,
            wind: forest_format::wind::Wind::CALM,
            season: None,
            forms,
            background: opts.background,
            depth_clear: opts.depth_clear(),
            shadow_layout,
            host_shadows: None,
            writes: (0, 0),
            prepared: false,
            statistics: false,
            fragment_counts: None,
        }
    }

    /// The camera uniform's buffer (the view's camera, then its light views').
    pub fn camera(&self) -> &wgpu::Buffer {
        &self.camera
    }

    /// The light of the frames written next.
    pub fn light(&self) -> forest_format::shading::Lighting {
        self.light
    }

    /// Which trees the form draws ([`crate::extend::quad_share`]).
    pub fn forms(&self) -> [f32; 4] {
        self.forms
    }

    /// The background the form draws over.
    pub fn background(&self) -> Background {
        self.background
    }

    /// The layout of the draw's shadow receivers (group 2).
    pub fn shadow_layout(&self) -> &wgpu::BindGroupLayout {
        &self.shadow_layout
    }

    /// Whether a camera was written (before that, frames draw nothing).
    pub fn is_prepared(&self) -> bool {
        self.prepared
    }

    /// Queue writes of the camera uniform since the form was created: (count, bytes).
    pub fn uploads(&self) -> (u64, u64) {
        self.writes
    }

    /// Whether frames gather pipeline statistics ([`ForestView::set_pipeline_statistics`]).
    pub fn gathers_statistics(&self) -> bool {
        self.statistics
    }

    /// The fragment counter's group while fragments are counted
    /// ([`ForestView::set_fragment_counter`]).
    pub fn fragment_counts(&self) -> Option<&wgpu::BindGroup> {
        self.fragment_counts.as_ref()
    }

    /// Whether the form receives a host's shadows.
    pub fn receives_host_shadows(&self) -> bool {
        self.host_shadows.is_some()
    }

    /// Stop receiving a host's shadows (the form's own are switched on).
    pub fn drop_host_shadows(&mut self) {
        self.host_shadows = None;
    }

    /// The receivers the draw binds: the form's own maps' `own` when it casts its own, else
    /// the host's, else none.
    pub fn receivers<'a>(&'a self, own: Option<&'a wgpu::BindGroup>) -> &'a wgpu::BindGroup {
        own.or(self.host_shadows.as_ref().map(HostShadows::group))
            .unwrap_or(&self.no_shadows)
    }

    /// The wind of the frames written next.
    pub fn wind(&self) -> forest_format::wind::Wind {
        self.wind
    }

    /// The frame's camera `g` with the inputs filled in: which trees, the light, the wind, and
    /// the host's cascades when its shadows are received.
    pub fn fill(&self, g: &mut GpuCamera) {
        g.forms = self.forms;
        g.set_light(&self.light);
        g.set_wind(&self.wind);
        g.set_season(self.season);
        if let Some(h) = &self.host_shadows {
            h.write(g);
        }
    }

    /// Fill in the frame's camera `g` ([`Self::fill`]) and upload it in one write, followed by
    /// its light views' cameras when the form casts its own shadows (`own`: the maps' options,
    /// the stream options the light views draw with, and the band of receivers).
    pub fn upload(
        &mut self,
        queue: &wgpu::Queue,
        mut g: GpuCamera,
        own: Option<(
            &crate::shadow::ShadowOptions,
            crate::options::StreamOptions,
            crate::shadow::ReceiverBand,
        )>,
    ) {
        self.fill(&mut g);
        let cameras = match own {
            Some((opts, stream, band)) => {
                crate::shadow::cameras(&g, &self.light, opts, stream, band)
            }
            None => vec![g],
        };
        self.upload_cameras(queue, &cameras);
    }

    /// Upload `cameras` as they are, one after another from the buffer's start, in one write
    /// (a host's light view, which takes no input of the view's).
    pub fn upload_cameras(&mut self, queue: &wgpu::Queue, cameras: &[GpuCamera]) {
        crate::camera::upload_all(queue, &self.camera, cameras, &mut self.writes);
        self.prepared = true;
    }

    /// Draw the trees `forms` selects from the next frame on ([`crate::extend::quad_share`]; a hybrid
    /// method sets each form's share).
    pub fn set_forms(&mut self, forms: [f32; 4]) {
        self.forms = forms;
    }

    /// The depth a frame's depth target is cleared to (the far plane in the form's
    /// convention).
    pub fn depth_clear(&self) -> f32 {
        self.depth_clear
    }
}

/// A drawing form of a forest: the passes behind the frame API. Implement this (with a
/// [`FrameInputs`]) and [`ForestView`] follows.
pub trait Form {
    /// The form's per-frame inputs.
    fn inputs(&self) -> &FrameInputs;
    /// The form's per-frame inputs, to change.
    fn inputs_mut(&mut self) -> &mut FrameInputs;
    /// Fill the form's own fields of the frame's camera `g` and upload it with its inputs and
    /// its light views' cameras ([`FrameInputs::upload`]).
    fn write_frame(&mut self, queue: &wgpu::Queue, g: GpuCamera);
    /// The form stops casting and receiving shadows of its own (a host's shadows replace
    /// them).
    fn park_own_shadows(&mut self, device: &wgpu::Device);
    /// Build the pipelines that count fragments ([`crate::fragments`]), if not yet built: the
    /// draw uses them while [`FrameInputs::fragment_counts`] holds a counter.
    fn build_counting(&mut self, device: &wgpu::Device);
    /// The frame's compute passes (its shadow maps' first, when it casts its own).
    fn encode_compute(&self, encoder: &mut wgpu::CommandEncoder);
    /// Record the draw into a render pass after [`Self::encode_compute`]: the ground first when
    /// `ground` and the background is the sky.
    fn record_draw(&self, pass: &mut wgpu::RenderPass, ground: bool);
    /// Timestamp writes for the render pass that draws the form.
    fn draw_timestamps(&self) -> Option<wgpu::RenderPassTimestampWrites<'_>>;
    /// Resolve the frame's queries; `draw_timed`: the draw's pass used
    /// [`Self::draw_timestamps`].
    fn resolve_queries(&self, encoder: &mut wgpu::CommandEncoder, draw_timed: bool);
}

/// The frame API: a prepared view of a forest, drawn by one method. Every front end drives
/// every method through it; see the module's documentation for the order of calls.
pub trait ForestView {
    /// Draw over `background` from the next frame on: the sky and ground, or transparent black
    /// (whose alpha is the trees' coverage).
    fn set_background(&mut self, background: Background);
    /// The background frames draw over.
    fn background(&self) -> Background;
    /// The light of the frames written from the next [`Self::set_camera`] on (a
    /// [`Self::prepare`] takes its frame's own light). Refused when a value is out of range.
    fn set_light(&mut self, light: forest_format::shading::Lighting) -> Result<(), RenderError>;
    /// The light frames are shaded with.
    fn light(&self) -> forest_format::shading::Lighting;
    /// The wind of the frames written from the next [`Self::set_camera`] on (a
    /// [`Self::prepare`] takes its frame's own wind): every method and every shadow caster
    /// moves its trees by it ([`forest_format::wind`]). Refused when a value is out of range.
    fn set_wind(&mut self, wind: forest_format::wind::Wind) -> Result<(), RenderError>;
    /// The wind frames are drawn in.
    fn wind(&self) -> forest_format::wind::Wind;
    /// The season of the frames written from the next [`Self::set_camera`] on (a
    /// [`Self::prepare`] takes its frame's own): 0 (spring) to 1 (late autumn) turns every
    /// tree's leaves ([`forest_format::colour`]); `None` keeps the models' own colours.
    /// Refused outside 0 to 1.
    fn set_season(&mut self, season: Option<f32>) -> Result<(), RenderError>;
    /// The season frames are drawn in.
    fn season(&self) -> Option<f32>;
    /// Gather pipeline statistics from the next frame on, where the device has
    /// `PIPELINE_STATISTICS_QUERY` (off by default; see [`crate::work`]).
    fn set_pipeline_statistics(&mut self, on: bool);
    /// Count the trees' fragments into `counter` from the next frame on, or stop counting
    /// (`None`); see [`crate::fragments`].
    fn set_fragment_counter(
        &mut self,
        device: &wgpu::Device,
        counter: Option<&crate::fragments::FragmentCounter>,
    );
    /// Receive a host's sun shadows instead of casting the forest's own: `maps` is the host's
    /// depth array (a layer per cascade, `resolution`² texels, standard depth or reverse-Z);
    /// `None` stops. Each frame's cascades come from [`Self::set_host_cascades`].
    fn receive_host_shadows(&mut self, device: &wgpu::Device, maps: Option<HostMaps<'_>>);
    /// The host's cascades for the next frames' receivers: each one's world → shadow clip
    /// matrix, the view depth where it ends, its texel and its depth range (metres); at most
    /// [`crate::shadow::MAX_CASCADES`], finite. Refused without host shadow maps.
    fn set_host_cascades(&mut self, cascades: &[crate::shadow::Cascade])
    -> Result<(), RenderError>;
    /// Write the frame's camera from the host's matrices: the one upload of a frame.
    fn prepare(&mut self, queue: &wgpu::Queue, frame: &FrameParams) -> Result<(), RenderError>;
    /// [`Self::prepare`] from an eye/target [`Camera`] with the view's own light.
    fn set_camera(&mut self, ctx: &GpuContext, camera: &Camera) -> Result<(), CameraError>;
    /// The compute passes of a frame, after [`Self::prepare`]: shadow maps, culls, refinement.
    fn encode_compute(&self, encoder: &mut wgpu::CommandEncoder);
    /// Record the frame's draws into a render pass after [`Self::encode_compute`]: the
    /// ground first when `ground` (and the background is the sky), then the trees.
    fn record(&self, pass: &mut wgpu::RenderPass, ground: bool);
    /// The depth a frame's depth target is cleared to (the far plane in the view's
    /// convention).
    fn depth_clear(&self) -> f32;
    /// Timestamp writes for the host's render pass that draws the forest.
    fn draw_timestamps(&self) -> Option<wgpu::RenderPassTimestampWrites<'_>>;
    /// Resolve the frame's pass times and counters, after the pass [`Self::render`] drew into.
    fn resolve_times(&self, encoder: &mut wgpu::CommandEncoder);
    /// Queue writes made since the view was created: (count, bytes). A frame writes the
    /// camera uniform once per form and nothing else.
    fn uploads(&self) -> (u64, u64);

    /// Draw into the host's render pass after [`Self::encode_compute`] (no ground).
    fn render(&self, pass: &mut wgpu::RenderPass) {
        self.record(pass, false);
    }

    /// Record a whole frame into `colour` and `depth`, both cleared first (to the background
    /// and the far depth), the ground drawn with the sky, after [`Self::set_camera`].
    fn encode_frame(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        colour: &wgpu::TextureView,
        depth: &wgpu::TextureView,
    ) {
        self.encode_compute(encoder);
        {
            let clear = self.background().clear_colour();
            let targets = Targets::cleared(colour, depth, clear, self.depth_clear());
            let mut pass = targets.begin(encoder, "forest draw", self.draw_timestamps());
            self.record(&mut pass, true);
        }
        self.resolve_times(encoder);
    }

    /// Write the camera, record the frame into `target` (cleared) and submit.
    fn render_frame(
        &mut self,
        ctx: &GpuContext,
        camera: &Camera,
        target: &Target,
    ) -> Result<(), CameraError> {
        self.set_camera(ctx, camera)?;
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        self.encode_frame(&mut enc, &target.colour_view, &target.depth_view);
        ctx.queue.submit([enc.finish()]);
        Ok(())
    }
}

impl<F: Form> ForestView for F {
    fn set_background(&mut self, background: Background) {
        self.inputs_mut().background = background;
    }

    fn background(&self) -> Background {
        self.inputs().background
    }

    fn set_light(&mut self, light: forest_format::shading::Lighting) -> Result<(), RenderError> {
        light.validate().map_err(RenderError::Parameter)?;
        self.inputs_mut().light = light;
        Ok(())
    }

    fn light(&self) -> forest_format::shading::Lighting {
        self.inputs().light
    }

    fn set_wind(&mut self, wind: forest_format::wind::Wind) -> Result<(), RenderError> {
        wind.validate().map_err(RenderError::Parameter)?;
        self.inputs_mut().wind = wind;
        Ok(())
    }

    fn wind(&self) -> forest_format::wind::Wind {
        self.inputs().wind
    }

    fn set_season(&mut self, season: Option<f32>) -> Result<(), RenderError> {
        forest_format::colour::check_season(season).map_err(RenderError::Parameter)?;
        self.inputs_mut().season = season;
        Ok(())
    }

    fn season(&self) -> Option<f32> {
        self.inputs().season
    }

    fn set_pipeline_statistics(&mut self, on: bool) {
        self.inputs_mut().statistics = on;
    }

    fn set_fragment_counter(
        &mut self,
        device: &wgpu::Device,
        counter: Option<&crate::fragments::FragmentCounter>,
    ) {
        if counter.is_some() {
            self.build_counting(device);
        }
        self.inputs_mut().fragment_counts = counter.map(|c| c.bind_group().clone());
    }

    fn receive_host_shadows(&mut self, device: &wgpu::Device, maps: Option<HostMaps<'_>>) {
        if maps.is_some() {
            self.park_own_shadows(device);
        }
        let inputs = self.inputs_mut();
        inputs.host_shadows = maps.map(|(view, resolution, reverse_z)| {
            HostShadows::new(device, &inputs.shadow_layout, view, resolution, reverse_z)
        });
    }

    fn set_host_cascades(
        &mut self,
        cascades: &[crate::shadow::Cascade],
    ) -> Result<(), RenderError> {
        match &mut self.inputs_mut().host_shadows {
            Some(h) => h.set_cascades(cascades),
            None => Err(RenderError::Parameter(
                "host cascades without host shadow maps: call receive_host_shadows first".into(),
            )),
        }
    }

    fn prepare(&mut self, queue: &wgpu::Queue, frame: &FrameParams) -> Result<(), RenderError> {
        frame.validate()?;
        self.inputs_mut().light = frame.light;
        self.inputs_mut().wind = frame.wind;
        self.inputs_mut().season = frame.season;
        self.write_frame(queue, frame.to_gpu());
        Ok(())
    }

    fn set_camera(&mut self, ctx: &GpuContext, camera: &Camera) -> Result<(), CameraError> {
        camera.validate()?;
        self.write_frame(&ctx.queue, camera.to_gpu());
        Ok(())
    }

    fn encode_compute(&self, encoder: &mut wgpu::CommandEncoder) {
        Form::encode_compute(self, encoder);
    }

    fn record(&self, pass: &mut wgpu::RenderPass, ground: bool) {
        self.record_draw(pass, ground);
    }

    fn depth_clear(&self) -> f32 {
        self.inputs().depth_clear
    }

    fn draw_timestamps(&self) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        Form::draw_timestamps(self)
    }

    fn resolve_times(&self, encoder: &mut wgpu::CommandEncoder) {
        self.resolve_queries(encoder, Form::draw_timestamps(self).is_some());
    }

    fn uploads(&self) -> (u64, u64) {
        self.inputs().writes
    }
}
