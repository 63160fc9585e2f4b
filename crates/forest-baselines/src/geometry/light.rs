//! The geometry renderer's shadow casting: one light view per cascade of the sun's shadow
//! maps, with its own camera (copied on the GPU from the renderer's camera buffer, which holds
//! the view's camera then each cascade's light camera), per-frame lists and indirect
//! arguments, classified within the cascade's box with the view's forms and levels of
//! detail, and drawn depth-only (`shaders/geometry_cast.wgsl`).

use std::sync::Arc;

use forest_render::extend::ShadowTargets;
use forest_render::extend::cast_pipeline;

use super::views::{Shared, View};

/// The light views of every cascade and the maps they cast into.
pub(super) struct LightViews {
    pub(super) targets: Arc<ShadowTargets>,
    pub(super) views: Vec<View>,
    /// The casting pipelines: meshes, billboards.
    pub(super) cast: [wgpu::RenderPipeline; 2],
}

impl LightViews {
    /// A light view per cascade of `targets` over the renderer's `shared` tables.
    pub(super) fn new(device: &wgpu::Device, shared: &Shared, targets: Arc<ShadowTargets>) -> Self {
        let views = (0..targets.options().cascades)
            .map(|_| shared.view(device, "geometry light view"))
            .collect();
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("geometry cast"),
            bind_group_layouts: &[Some(&shared.draw_layout)],
            immediate_size: 0,
        });
        let source = crate::shaders::cast_source();
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("geometry cast"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let pipeline = |vs: &str, fs: &str| {
            cast_pipeline(
                device,
                &layout,
                &module,
                wgpu::PrimitiveTopology::TriangleList,
                [vs, fs],
            )
        };
        Self {
            targets,
            views,
            cast: [
                pipeline("vs_geo_cast", "fs_geo_cast"),
                pipeline("vs_billboard", "fs_billboard_cast"),
            ],
        }
    }

    /// Bytes of the light views' own buffers (the maps are counted where they were made).
    pub(super) fn bytes(&self) -> u64 {
        self.views.iter().map(|v| v.bytes).sum()
    }
}
