//! The light views' casting pass (`shaders/cast.wgsl`): a light-view stream's plain quads,
//! depth only and alpha-tested, into one layer of the sun's shadow map.

use super::draw::bind_entries;

pub use crate::receivers::SHADOW_FORMAT;

/// A casting pipeline: `entries` (vertex, fragment) of `module` drawing depth only into a
/// shadow map ([`crate::extend::SHADOW_FORMAT`], nearest wins), no face culling. The quad stream's and the
/// geometry renderer's casting pipelines are all built here.
pub fn cast_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    topology: wgpu::PrimitiveTopology,
    entries: [&str; 2],
) -> wgpu::RenderPipeline {
    cast_pipeline_into(
        device,
        layout,
        module,
        topology,
        entries,
        (SHADOW_FORMAT, wgpu::CompareFunction::Less),
    )
}

/// [`cast_pipeline`] into a host's map: its depth format and its test (less for standard
/// depth, greater for reverse-Z).
pub fn cast_pipeline_into(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    topology: wgpu::PrimitiveTopology,
    [vs, fs]: [&str; 2],
    (format, compare): (wgpu::TextureFormat, wgpu::CompareFunction),
) -> wgpu::RenderPipeline {
    super::draw::render_pipeline(
        device,
        layout,
        module,
        topology,
        [vs, fs],
        wgpu::DepthStencilState {
            format,
            depth_write_enabled: Some(true),
            depth_compare: Some(compare),
            stencil: Default::default(),
            bias: Default::default(),
        },
        Default::default(),
        &[],
    )
}

/// The casting pipeline (built once per set of shadow maps).
pub struct CastPass {
    /// Far trees' composited quads (drawn first).
    composite: wgpu::RenderPipeline,
    quads: wgpu::RenderPipeline,
}

impl CastPass {
    /// The pipeline over the draw pass's group 0 (a light-view stream's draw bind group),
    /// into the forest's own maps.
    pub fn new(device: &wgpu::Device) -> Self {
        Self::into(device, (SHADOW_FORMAT, wgpu::CompareFunction::Less))
    }

    /// The pipeline into maps of depth `format` tested with `compare` (a host's).
    pub fn into(
        device: &wgpu::Device,
        depth: (wgpu::TextureFormat, wgpu::CompareFunction),
    ) -> Self {
        let bind_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("cast"),
            entries: &bind_entries(),
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("cast"),
            bind_group_layouts: &[Some(&bind_layout)],
            immediate_size: 0,
        });
        let source = super::cast_source();
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("cast"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let pipeline = |entries| {
            cast_pipeline_into(
                device,
                &layout,
                &module,
                wgpu::PrimitiveTopology::TriangleStrip,
                entries,
                depth,
            )
        };
        Self {
            composite: pipeline(["vs_cast_composite", "fs_cast_composite"]),
            quads: pipeline(["vs_cast", "fs_cast"]),
        }
    }

    /// Draw a light-view stream's quads (its draw group and indirect arguments) into the
    /// pass's depth attachment: the composited far trees, then the plain quads.
    pub fn record(
        &self,
        pass: &mut wgpu::RenderPass,
        bind_group: &wgpu::BindGroup,
        args_buf: &wgpu::Buffer,
    ) {
        pass.set_bind_group(0, bind_group, &[]);
        pass.set_pipeline(&self.composite);
        pass.draw_indirect(args_buf, super::args::DRAW_COMPOSITE);
        pass.set_pipeline(&self.quads);
        pass.draw_indirect(args_buf, super::args::DRAW);
    }
}
