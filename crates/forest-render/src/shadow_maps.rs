//! The sun's shadow maps of one view: a depth array with a layer per cascade, one light-view
//! quad stream per cascade (its own cull and refine, as for a camera), the casting pass, and
//! the bind group (group 2 of the draw) the receivers look the maps up through.
//!
//! Per frame nothing more is uploaded: the view's stream writes its own camera and each
//! cascade's light-view camera in one write ([`crate::shadow::light_camera`]), and
//! [`ShadowMaps::encode`] copies each light camera into its stream's camera buffer on the GPU
//! before that stream's passes.

use std::sync::Arc;

use crate::context::RenderError;
use crate::gpu_types::GpuCamera;
use crate::options::RendererOptions;
use crate::passes::cast::CastPass;
use crate::receivers::{depth_array, receiver_group};
use crate::shadow::ShadowOptions;
use crate::stats::FrameStats;

/// Mean quad layers per texel a light-view stream is first sized for (it grows to what
/// frames need, [`ShadowMaps::fit`]): a shadow map sees the canopy's top, far fewer layers
/// than a camera looking through the forest.
const LIGHT_OVERDRAW: f32 = 0.25;

/// Casters besides the quad stream's that draw into the maps (the geometry renderer's light
/// views): for cascade `k`, their compute work before its pass, then their draws in it.
pub trait Caster {
    /// Record cascade `k`'s compute passes (after its light camera is in place).
    fn encode_light(&self, encoder: &mut wgpu::CommandEncoder, k: usize);
    /// Draw into cascade `k`'s depth-only pass.
    fn record_light(&self, pass: &mut wgpu::RenderPass, k: usize);
}

/// The maps themselves: a depth layer per cascade, each drawn into by its own pass, and the
/// receivers' group that reads them all. Shared by the renderers that cast into them (the
/// quad stream's light views and the geometry renderer's, in the hybrid).
pub struct ShadowTargets {
    opts: ShadowOptions,
    band: crate::shadow::ReceiverBand,
    layers: Vec<wgpu::TextureView>,
    receivers: wgpu::BindGroup,
    bytes: u64,
}

impl ShadowTargets {
    /// The maps of `opts` (checked, and against the device, before anything is allocated),
    /// read through `layout` (the receivers' layout, [`crate::receivers::receiver_layout`]), for receivers in
    /// `band` (every renderer casting into the maps fits its cascades to it).
    pub fn new(
        device: &wgpu::Device,
        opts: &ShadowOptions,
        layout: &wgpu::BindGroupLayout,
        band: crate::shadow::ReceiverBand,
    ) -> Result<Self, RenderError> {
        opts.validate().map_err(RenderError::Parameter)?;
        let limits = device.limits();
        crate::error::within_limit(
            || {
                format!(
                    "{} shadow cascades of {}² texels (texels on a side)",
                    opts.cascades, opts.resolution
                )
            },
            opts.resolution.into(),
            limits.max_texture_dimension_2d.into(),
            ": lower the shadow resolution",
        )?;
        crate::error::within_limit(
            || "the shadow cascades (texture array layers)".into(),
            opts.cascades.into(),
            limits.max_texture_array_layers.into(),
            ": use fewer cascades",
        )?;
        let texture = depth_array(device, opts.resolution, opts.cascades);
        let layers = (0..opts.cascades)
            .map(|k| {
                texture.create_view(&wgpu::TextureViewDescriptor {
                    label: Some("shadow cascade"),
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: k,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        Ok(Self {
            opts: *opts,
            band,
            layers,
            receivers: receiver_group(device, layout, &texture),
            bytes: u64::from(opts.resolution).pow(2) * 4 * u64::from(opts.cascades),
        })
    }

    /// The options the maps were built for.
    pub fn options(&self) -> &ShadowOptions {
        &self.opts
    }

    /// The heights the maps' receivers lie between.
    pub fn band(&self) -> crate::shadow::ReceiverBand {
        self.band
    }

    /// The receivers' bind group (group 2 of every draw that reads the maps).
    pub fn receivers(&self) -> &wgpu::BindGroup {
        &self.receivers
    }

    /// Bytes of the maps.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    /// Begin cascade `k`'s depth-only pass, its layer cleared to the far depth.
    pub fn begin_cascade<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        k: usize,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> wgpu::RenderPass<'e> {
        depth_pass(encoder, &self.layers[k], 1.0, timestamp_writes)
    }
}

/// A depth-only render pass over a shadow map's layer `view`, cleared first to `far` (1 for
/// standard depth, 0 for reverse-Z): what the cascades, or a host's map, are drawn in.
pub fn depth_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    view: &wgpu::TextureView,
    far: f32,
    timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("shadow map"),
        color_attachments: &[],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(far),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        timestamp_writes,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// The shadow maps of one view and the light-view streams that fill them.
pub struct ShadowMaps<V> {
    targets: Arc<ShadowTargets>,
    streams: Vec<V>,
    cast: CastPass,
}

/// What the maps need of a cascade's light view (the quad stream of the light, which
/// `crate::stream` makes and implements this for).
pub trait LightView {
    /// The view's camera uniform, into which the cascade's light camera is copied.
    fn camera_buffer(&self) -> &wgpu::Buffer;
    /// The view's cull and refine.
    fn encode_view_compute(&self, encoder: &mut wgpu::CommandEncoder);
    /// Timestamp writes of the casting pass.
    fn cast_timestamps(&self) -> Option<wgpu::RenderPassTimestampWrites<'_>>;
    /// What the casting pass draws from: the final stream's draw group and the arguments.
    fn cast_parts(&self) -> (&wgpu::BindGroup, &wgpu::Buffer);
    /// Resolve the frame's queries.
    fn resolve_cast(&self, encoder: &mut wgpu::CommandEncoder);
    /// Refine (the quad stream) or not (static impostors).
    fn set_refine(&mut self, refine: bool);
    /// Counters of the last submitted frame (waits for the GPU).
    fn read_stats(&self, ctx: &crate::GpuContext) -> FrameStats;
    /// Counters of a recent frame without waiting.
    fn poll_stats(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Option<FrameStats>;
    /// Grow after a frame that overflowed; whether the buffers were rebuilt.
    fn fit(&mut self, device: &wgpu::Device, stats: &FrameStats) -> Result<bool, RenderError>;
    /// Bytes of the view's own buffers.
    fn view_bytes(&self) -> u64;
}

/// The options a cascade's light-view stream is built with for maps of `opts`: the map's
/// side as its viewport, the light views' ε, and a small first overdraw.
pub fn light_view_options(opts: &ShadowOptions) -> RendererOptions {
    RendererOptions {
        viewport: (opts.resolution, opts.resolution),
        min_epsilon: opts.epsilon,
        overdraw: LIGHT_OVERDRAW,
        ..Default::default()
    }
}

impl<V: LightView> ShadowMaps<V> {
    /// The maps of `opts` (`layout`: the receivers' layout of the view that reads them; `band`
    /// the scene's receivers), cast by `streams`, one light view per cascade
    /// ([`light_view_options`]). Sizes are checked against the device before anything is
    /// allocated.
    pub fn new(
        device: &wgpu::Device,
        opts: &ShadowOptions,
        layout: &wgpu::BindGroupLayout,
        band: crate::shadow::ReceiverBand,
        streams: impl FnMut() -> Result<V, RenderError>,
    ) -> Result<Self, RenderError> {
        let targets = Arc::new(ShadowTargets::new(device, opts, layout, band)?);
        let streams = std::iter::repeat_with(streams)
            .take(opts.cascades as usize)
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            targets,
            streams,
            cast: CastPass::new(device),
        })
    }

    /// The options the maps were built for.
    pub fn options(&self) -> &ShadowOptions {
        self.targets.options()
    }

    /// The receivers' bind group (group 2 of the draw).
    pub fn receivers(&self) -> &wgpu::BindGroup {
        self.targets.receivers()
    }

    /// The maps, to share with another renderer casting into them and reading them.
    pub fn targets(&self) -> &Arc<ShadowTargets> {
        &self.targets
    }

    /// The light-view streams, one per cascade (their counters: [`Self::stats`]).
    pub fn streams(&self) -> &[V] {
        &self.streams
    }

    /// Bytes on the GPU: the maps and the light-view streams' own buffers.
    pub fn bytes(&self) -> u64 {
        self.targets.bytes() + self.streams.iter().map(|s| s.view_bytes()).sum::<u64>()
    }

    /// Record every cascade: copy its light camera from slot `k + 1` of `cameras` (the view's
    /// camera buffer, [`crate::shadow`]), cull and refine for it, then draw its quads into
    /// its layer, cleared first to the far depth. Each stream times its passes as a view's
    /// stream does (its counters' `draw_ms` is the casting pass).
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, cameras: &wgpu::Buffer) {
        self.encode_with(encoder, cameras, true, None);
    }

    /// [`Self::encode`] with the quad stream's casting when `quads`, and `extra`'s.
    pub fn encode_with(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        cameras: &wgpu::Buffer,
        quads: bool,
        extra: Option<&dyn Caster>,
    ) {
        let size = std::mem::size_of::<GpuCamera>() as u64;
        for (k, stream) in self.streams.iter().enumerate() {
            if quads {
                encoder.copy_buffer_to_buffer(
                    cameras,
                    size * (k as u64 + 1),
                    stream.camera_buffer(),
                    0,
                    size,
                );
                stream.encode_view_compute(encoder);
            }
            if let Some(c) = extra {
                c.encode_light(encoder, k);
            }
            let ts = if quads {
                stream.cast_timestamps()
            } else {
                None
            };
            let mut pass = self.targets.begin_cascade(encoder, k, ts);
            if quads {
                let (group, args) = stream.cast_parts();
                self.cast.record(&mut pass, group, args);
            }
            if let Some(c) = extra {
                c.record_light(&mut pass, k);
            }
            drop(pass);
            if quads {
                stream.resolve_cast(encoder);
            }
        }
    }

    /// Refine the light views (the quad stream) or not (static impostors).
    pub fn set_refine(&mut self, refine: bool) {
        for s in &mut self.streams {
            s.set_refine(refine);
        }
    }

    /// Each cascade's counters of the last submitted frame (waits for the GPU).
    pub fn stats(&self, ctx: &crate::GpuContext) -> Vec<FrameStats> {
        self.streams.iter().map(|s| s.read_stats(ctx)).collect()
    }

    /// Each cascade's counters of a recent frame without waiting (`None` until one arrives),
    /// growing a light-view stream whose frame overflowed for the frames after (a frame
    /// loop's [`Self::fit`]).
    pub fn poll(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Vec<Option<FrameStats>>, RenderError> {
        self.streams
            .iter_mut()
            .map(|s| {
                let stats = s.poll_stats(device, queue);
                if let Some(st) = &stats {
                    s.fit(device, st)?;
                }
                Ok(stats)
            })
            .collect()
    }

    /// Grow every light-view stream whose last frame overflowed (see [`LightView::fit`]);
    /// whether any grew (the frame should then be drawn again).
    pub fn fit(&mut self, ctx: &crate::GpuContext) -> Result<bool, RenderError> {
        let mut grew = false;
        for s in &mut self.streams {
            let stats = s.read_stats(ctx);
            grew |= s.fit(&ctx.device, &stats)?;
        }
        Ok(grew)
    }
}
