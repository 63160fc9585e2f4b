//! What every view of a geometry renderer binds (the main view and the shadow cascades'
//! light views alike), each view's own buffers, and the feature the renderer needs.

use forest_render::gpu_types::GpuCamera;
use wgpu::util::DeviceExt;

use super::models::GpuModels;
use std::sync::Arc;

/// The renderer's tables, textures and layouts that every view binds, the main view and the
/// shadow cascades' light views alike.
pub(super) struct Shared {
    /// The forest's models, trees and terrain, perhaps shared with other renderers.
    pub(super) models: Arc<GpuModels>,
    pub(super) method: wgpu::Buffer,
    pub(super) environment: wgpu::Buffer,
    pub(super) compute_layout: wgpu::BindGroupLayout,
    pub(super) draw_layout: wgpu::BindGroupLayout,
}

/// One view's own buffers and its two groups: its camera (the view's, then each cascade's
/// light camera after it), the per-frame lists and indirect arguments.
pub(super) struct View {
    pub(super) camera: wgpu::Buffer,
    pub(super) args: wgpu::Buffer,
    pub(super) compute_bg: wgpu::BindGroup,
    pub(super) draw_bg: wgpu::BindGroup,
    /// Bytes of the view's buffers.
    pub(super) bytes: u64,
}

impl Shared {
    /// A view's buffers (zeroed) and groups.
    pub(super) fn view(&self, device: &wgpu::Device, label: &str) -> View {
        use wgpu::BufferUsages as U;
        let zeros = |what: &str, bytes: usize, usage: U| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(&format!("{label} {what}")),
                contents: &vec![0u8; bytes.max(16)],
                usage,
            })
        };
        let camera_bytes =
            std::mem::size_of::<GpuCamera>() * (1 + forest_render::shadow::MAX_CASCADES as usize);
        let camera = zeros(
            "camera",
            camera_bytes,
            U::UNIFORM | U::COPY_DST | U::COPY_SRC,
        );
        let m = &*self.models;
        let (segments, instances, listed) = (
            m.capacity.segments as usize,
            m.capacity.instances as usize,
            m.capacity.listed as usize,
        );
        let keys = zeros("segment keys", instances * 4, U::STORAGE);
        let counts = zeros("segment counts", segments * 4, U::STORAGE | U::COPY_SRC);
        let cursor = zeros("segment cursors", segments * 4, U::STORAGE);
        let visible = zeros("visible instances", listed * 4, U::STORAGE);
        let args = zeros(
            "draw args",
            segments * 16,
            U::STORAGE | U::INDIRECT | U::COPY_SRC,
        );
        let bytes = [&camera, &keys, &counts, &cursor, &visible, &args]
            .iter()
            .map(|b| b.size())
            .sum();
        let compute_bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout: &self.compute_layout,
            entries: &forest_render::extend::numbered(vec![
                camera.as_entire_binding(),
                m.instances.as_entire_binding(),
                m.species.as_entire_binding(),
                keys.as_entire_binding(),
                counts.as_entire_binding(),
                cursor.as_entire_binding(),
                visible.as_entire_binding(),
                args.as_entire_binding(),
                m.consts.as_entire_binding(),
                self.method.as_entire_binding(),
                m.leaf_end.as_entire_binding(),
            ]),
        });
        let resources = vec![
            (0, camera.as_entire_binding()),
            (1, m.instances.as_entire_binding()),
            (2, m.vertices.as_entire_binding()),
            (3, visible.as_entire_binding()),
            (4, m.materials.as_entire_binding()),
            (5, wgpu::BindingResource::TextureView(&m.material_view)),
            (6, wgpu::BindingResource::Sampler(&m.sampler)),
            (
                7,
                wgpu::BindingResource::TextureView(&m.billboard_surface_view),
            ),
            (8, self.environment.as_entire_binding()),
            (9, m.species.as_entire_binding()),
            (10, self.method.as_entire_binding()),
            (11, m.leaf_centre.as_entire_binding()),
            (12, wgpu::BindingResource::TextureView(&m.billboard_view)),
            (
                forest_render::extend::HEIGHTS_BINDING,
                m.terrain.heights.as_entire_binding(),
            ),
            (14, wgpu::BindingResource::TextureView(&m.opacity_view)),
            (15, wgpu::BindingResource::Sampler(&m.opacity_sampler)),
            (16, m.draw_order.as_entire_binding()),
        ];
        let draw_bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout: &self.draw_layout,
            entries: &resources
                .into_iter()
                .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource })
                .collect::<Vec<_>>(),
        });
        View {
            camera,
            args,
            compute_bg,
            draw_bg,
            bytes,
        }
    }
}
