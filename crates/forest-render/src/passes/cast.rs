//! The light views' casting pass (`shaders/cast.wgsl`): a light-view stream's plain quads,
//! depth only and alpha-tested, into one layer of the sun's shadow map.

use super::draw::bind_entries;

/// Depth format of the shadow maps.
pub const SHADOW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The casting pipeline (built once per set of shadow maps).
pub struct CastPass {
    pipeline: wgpu::RenderPipeline,
}

impl CastPass {
    /// The pipeline over the draw pass's group 0 (a light-view stream's draw bind group).
    pub fn new(device: &wgpu::Device) -> Self {
        let bind_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("cast"),
            entries: &bind_entries(),
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("cast"),
            bind_group_layouts: &[Some(&bind_layout)],
            immediate_size: 0,
        });
        let source = [super::DRAW_WGSL.concat().as_str(), super::CAST_WGSL].concat();
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("cast"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("cast"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_cast"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleStrip,
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: SHADOW_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_cast"),
                compilation_options: Default::default(),
                targets: &[],
            }),
            multiview_mask: None,
            cache: None,
        });
        Self { pipeline }
    }

    /// Draw a light-view stream's plain quads (its draw group and indirect arguments) into
    /// the pass's depth attachment.
    pub fn record(
        &self,
        pass: &mut wgpu::RenderPass,
        bind_group: &wgpu::BindGroup,
        args_buf: &wgpu::Buffer,
    ) {
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.draw_indirect(args_buf, super::args::DRAW);
    }
}
