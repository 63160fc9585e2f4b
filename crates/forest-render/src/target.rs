//! An offscreen colour + depth target and its read-back, for headless rendering.

use crate::context::GpuContext;

/// Depth format of the targets the crate's own front ends draw into ([`crate::target`]);
/// a host chooses its own in [`crate::options::RendererOptions`].
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Colour (`Rgba8UnormSrgb` unless made [`Target::with_format`]) and depth textures of one
/// size.
pub struct Target {
    /// Colour texture.
    pub colour: wgpu::Texture,
    /// Depth texture.
    pub depth: wgpu::Texture,
    /// View of the colour texture.
    pub colour_view: wgpu::TextureView,
    /// View of the depth texture.
    pub depth_view: wgpu::TextureView,
    /// Size in pixels.
    pub size: (u32, u32),
    /// Colour format.
    pub format: wgpu::TextureFormat,
}

/// Begin a render pass that clears `colour` to `clear` and `depth` to 1.
pub fn begin_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    colour: &wgpu::TextureView,
    depth: &wgpu::TextureView,
    clear: wgpu::Color,
    timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
) -> wgpu::RenderPass<'e> {
    crate::frame::Targets::cleared(colour, depth, clear, 1.0).begin(
        encoder,
        label,
        timestamp_writes,
    )
}

/// Begin a colour-only render pass over `colour` that keeps what it holds (for overlays drawn
/// over a finished frame: the overdraw view, a HUD).
pub fn begin_overlay_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    colour: &wgpu::TextureView,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: colour,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Load,
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// Colour format of [`Target`].
pub const TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// Colour formats a [`Target`] can be made in and read back from (8-bit RGBA or BGRA: what
/// window surfaces offer).
pub const READABLE_FORMATS: [wgpu::TextureFormat; 4] = [
    wgpu::TextureFormat::Rgba8UnormSrgb,
    wgpu::TextureFormat::Bgra8UnormSrgb,
    wgpu::TextureFormat::Rgba8Unorm,
    wgpu::TextureFormat::Bgra8Unorm,
];

impl Target {
    /// Create a target of `width × height` pixels in [`TARGET_FORMAT`].
    pub fn new(ctx: &GpuContext, width: u32, height: u32) -> Self {
        Self::make(ctx, width, height, TARGET_FORMAT)
    }

    /// Create a target in another colour format (one of [`READABLE_FORMATS`]), for pipelines
    /// built for a window surface's format; [`Target::read`] still returns RGBA.
    pub fn with_format(
        ctx: &GpuContext,
        width: u32,
        height: u32,
        format: wgpu::TextureFormat,
    ) -> Result<Self, crate::context::RenderError> {
        if !READABLE_FORMATS.contains(&format) {
            return Err(crate::context::RenderError::UnreadableFormat {
                format,
                allowed: &READABLE_FORMATS,
            });
        }
        Ok(Self::make(ctx, width, height, format))
    }

    fn make(ctx: &GpuContext, width: u32, height: u32, format: wgpu::TextureFormat) -> Self {
        let make = |label, format, usage| {
            ctx.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let colour = make(
            "target colour",
            format,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let depth = make(
            "target depth",
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        Self {
            colour_view: colour.create_view(&Default::default()),
            depth_view: depth.create_view(&Default::default()),
            colour,
            depth,
            size: (width, height),
            format,
        }
    }

    /// Read the colour back as an RGBA8 image (sRGB-encoded for the sRGB formats; BGRA
    /// targets are swizzled); waits for the GPU.
    pub fn read(&self, ctx: &GpuContext) -> image::RgbaImage {
        let (w, h) = self.size;
        let data = self.copy_out(ctx, &self.colour, wgpu::TextureAspect::All);
        let mut img = image::RgbaImage::from_raw(w, h, data).expect("one RGBA8 texel per pixel");
        if matches!(
            self.format,
            wgpu::TextureFormat::Bgra8UnormSrgb | wgpu::TextureFormat::Bgra8Unorm
        ) {
            for p in img.pixels_mut() {
                p.0.swap(0, 2);
            }
        }
        img
    }

    /// Read the depth back (one value per pixel, rows top to bottom); waits for the GPU.
    pub fn read_depth(&self, ctx: &GpuContext) -> Vec<f32> {
        bytemuck::pod_collect_to_vec(&self.copy_out(
            ctx,
            &self.depth,
            wgpu::TextureAspect::DepthOnly,
        ))
    }

    /// The texels of `texture` (4 bytes each, the target's size), rows packed; waits.
    fn copy_out(
        &self,
        ctx: &GpuContext,
        texture: &wgpu::Texture,
        aspect: wgpu::TextureAspect,
    ) -> Vec<u8> {
        let (w, h) = self.size;
        let row = (w * 4).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let buf = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("target readback"),
            size: u64::from(row) * u64::from(h),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        enc.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buf,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
        );
        let data = ctx.submit_and_read(enc, &buf);
        let mut out = Vec::with_capacity((w * h * 4) as usize);
        for y in 0..h as usize {
            out.extend_from_slice(&data[y * row as usize..y * row as usize + w as usize * 4]);
        }
        out
    }
}
