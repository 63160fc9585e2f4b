//! The overdraw view (`shaders/overdraw.wgsl`): a heat map of a counted frame's fragment
//! invocations per pixel ([`crate::fragments`]), in bands of powers of two, with a legend of
//! the bands along the bottom-left edge. It draws over the whole target, for every method.

use crate::fragments::FragmentCounter;

/// Linear RGB of the bands: 0 (no fragment), 1 (one), 2 (2–3), 3 (4–7) … 8 (128 or more).
/// Mirrors `OVERDRAW_COLOURS` in the WGSL.
pub const OVERDRAW_COLOURS: [[f32; 3]; 9] = [
    [0.0, 0.0, 0.0],
    [0.02, 0.05, 0.6],
    [0.0, 0.4, 0.75],
    [0.02, 0.55, 0.05],
    [0.8, 0.72, 0.02],
    [0.87, 0.22, 0.01],
    [0.72, 0.01, 0.01],
    [0.8, 0.05, 0.8],
    [1.0, 1.0, 1.0],
];

/// The band of `n` fragments: 0 for none, else 1 + ⌊log₂ n⌋, at most 8 (128 or more).
pub fn band(n: u32) -> usize {
    if n == 0 {
        0
    } else {
        (n.ilog2() as usize + 1).min(OVERDRAW_COLOURS.len() - 1)
    }
}

/// The fewest fragments of band `b` (0, 1, 2, 4 … 128), as the legend labels it.
pub fn band_floor(b: usize) -> u32 {
    if b == 0 { 0 } else { 1 << (b - 1) }
}

/// Side in pixels of a legend swatch for a target `width` pixels wide: 1/16 of it, 16 to 48,
/// but no wider than a ninth, so that all nine fit (the last column of each is a dark gap;
/// below [`LABELLED_SIDE`] the labels are left out).
pub fn legend_side(width: u32) -> u32 {
    (width / 16).clamp(16, 48).min(width / 9)
}

/// The narrowest swatch (pixels) that holds its label ("128" is 11 pixels wide, then the gap
/// and a margin). Mirrors the WGSL.
pub const LABELLED_SIDE: u32 = 14;

/// `OverdrawParams` of the WGSL.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct OverdrawParams {
    /// Target width (pixels); the counters' width.
    pub width: u32,
    /// Target height (pixels).
    pub height: u32,
    /// Side of a legend swatch (pixels; 0: no legend).
    pub legend: u32,
    /// Padding.
    pub _pad: u32,
}

/// The overdraw view's pipeline, for one colour format.
pub struct OverdrawPass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
}

/// What the view reads: a counter's buffer and the view's parameters.
pub struct OverdrawBinding {
    bind_group: wgpu::BindGroup,
}

impl OverdrawPass {
    /// The pipeline for `format` targets of one sample, no depth.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("overdraw"),
            entries: &layout_entries(),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("overdraw"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("overdraw"),
            source: wgpu::ShaderSource::Wgsl(crate::shaders::OVERDRAW_WGSL.into()),
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("overdraw"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_overdraw"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_overdraw"),
                compilation_options: Default::default(),
                targets: &[Some(format.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        Self { layout, pipeline }
    }

    /// Bind `counter`'s counts, with a legend when `legend`.
    pub fn bind(
        &self,
        device: &wgpu::Device,
        counter: &FragmentCounter,
        legend: bool,
    ) -> OverdrawBinding {
        use wgpu::util::DeviceExt;
        let (width, height) = counter.size();
        let params = OverdrawParams {
            width,
            height,
            legend: if legend { legend_side(width) } else { 0 },
            _pad: 0,
        };
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("overdraw parameters"),
            contents: bytemuck::bytes_of(&params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("overdraw"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: counter.buffer().as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: params.as_entire_binding(),
                },
            ],
        });
        OverdrawBinding { bind_group }
    }

    /// Draw the heat map over the whole of the pass's target (of the counter's size), after
    /// the counted frames were submitted.
    pub fn record(&self, pass: &mut wgpu::RenderPass, binding: &OverdrawBinding) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &binding.bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}

impl OverdrawPass {
    /// Record the heat map into `view` (a target of the counter's size and this pass's
    /// format) in a pass of its own, colour only, over whatever it held.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        view: &wgpu::TextureView,
        binding: &OverdrawBinding,
    ) {
        let mut pass = crate::target::begin_overlay_pass(encoder, "overdraw view", view);
        self.record(&mut pass, binding);
    }
}

/// The view's bind-group layout: the counts (read-only) and [`OverdrawParams`].
pub fn layout_entries() -> [wgpu::BindGroupLayoutEntry; 2] {
    let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    [
        entry(0, wgpu::BufferBindingType::Storage { read_only: true }),
        entry(1, wgpu::BufferBindingType::Uniform),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_are_powers_of_two() {
        let bands: Vec<usize> = [0, 1, 2, 3, 4, 7, 8, 127, 128, 1 << 20].map(band).to_vec();
        assert_eq!(bands, [0, 1, 2, 2, 3, 3, 4, 7, 8, 8]);
        for b in 1..OVERDRAW_COLOURS.len() {
            assert_eq!(band(band_floor(b)), b);
            assert_eq!(band(band_floor(b) - 1), b - 1);
        }
    }
}
