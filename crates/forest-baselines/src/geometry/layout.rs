//! The geometry renderer's bind-group layouts, as data (a test checks them against naga's
//! reflection of `shaders/geometry*.wgsl`).

use forest_render::extend::Slot;

/// The compute group shared by the four cull entry points (`shaders/geometry.wgsl`).
pub const COMPUTE_SLOTS: [Slot; 11] = [
    Slot::Uniform,   // 0 camera
    Slot::Read,      // 1 instances
    Slot::Read,      // 2 species
    Slot::ReadWrite, // 3 keys
    Slot::ReadWrite, // 4 counts
    Slot::ReadWrite, // 5 cursors
    Slot::ReadWrite, // 6 visible
    Slot::ReadWrite, // 7 args
    Slot::Uniform,   // 8 constants
    Slot::Uniform,   // 9 method
    Slot::Read,      // 10 leaf ends
];

/// Layout entries of the compute group.
pub fn compute_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
    forest_render::extend::layout_entries(&COMPUTE_SLOTS, wgpu::ShaderStages::COMPUTE)
}

/// Layout entries of the draw group (bindings as in `shaders/geometry_draw.wgsl`).
pub fn draw_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
    use wgpu::ShaderStages as S;
    let buffer = |binding, visibility, ty| wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    let read = wgpu::BufferBindingType::Storage { read_only: true };
    let uniform = wgpu::BufferBindingType::Uniform;
    let texture = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: S::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        },
        count: None,
    };
    vec![
        buffer(0, S::VERTEX_FRAGMENT, uniform),
        // The instances and species (9) are read by the fragment stage too, for each tree's
        // colour (tint.wgsl).
        buffer(1, S::VERTEX_FRAGMENT, read),
        buffer(2, S::VERTEX, read),
        buffer(3, S::VERTEX, read),
        buffer(4, S::FRAGMENT, read),
        texture(5),
        wgpu::BindGroupLayoutEntry {
            binding: 6,
            visibility: S::FRAGMENT,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        },
        // The billboards' surface attributes (linear).
        texture(7),
        // The environment: the terrain's grid is read by `vs_terrain`.
        buffer(8, S::VERTEX_FRAGMENT, uniform),
        buffer(9, S::VERTEX_FRAGMENT, read),
        // The method: its texture bias is read by `fs_geo`.
        buffer(10, S::VERTEX_FRAGMENT, uniform),
        buffer(11, S::VERTEX, read),
        texture(12),
        forest_render::extend::heights_entry(),
        // The species' opacity volumes and their clamping sampler.
        forest_render::extend::opacity_entry(14),
        wgpu::BindGroupLayoutEntry {
            binding: 15,
            visibility: S::VERTEX_FRAGMENT,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        },
        // The triangles' presorted draw orders, read by `draw_vertex`.
        buffer(16, S::VERTEX, read),
    ]
}
