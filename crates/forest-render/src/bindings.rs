//! Bind-group layout entries shared by the passes and by the resources they bind (the slots
//! of the compute layout, numbered entries, vertex-stage storage).

/// Bindings of the compute layout, in order: (binding, kind).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    /// Uniform buffer.
    Uniform,
    /// Read-only storage buffer.
    Read,
    /// Read-write storage buffer.
    ReadWrite,
    /// `texture_2d<u32>`.
    UintTexture,
}

/// The compute layout's group 0: 16 bindings (see `shaders/bindings.wgsl`); the arguments are
/// group 1, bound only for the entry points that write them.
pub const COMPUTE_SLOTS: [Slot; 16] = [
    Slot::Uniform,     // 0 camera
    Slot::Uniform,     // 1 scene constants
    Slot::Read,        // 2 instances
    Slot::Read,        // 3 species
    Slot::Read,        // 4 frames
    Slot::Read,        // 5 direction triangles
    Slot::Read,        // 6 roots
    Slot::Read,        // 7 presort directions
    Slot::UintTexture, // 8 presort
    Slot::UintTexture, // 9 nodes
    Slot::ReadWrite,   // 10 state
    Slot::ReadWrite,   // 11 data of the next step (the emitters' wishes)
    Slot::ReadWrite,   // 12 data (counts, wishes, prefixes)
    Slot::ReadWrite,   // 13 block sums
    Slot::ReadWrite,   // 14 quads in (the cull writes composited quads to both buffers)
    Slot::ReadWrite,   // 15 quads out
];

/// Bind-group entries numbered 0, 1, 2, … in the order given.
pub fn numbered(resources: Vec<wgpu::BindingResource<'_>>) -> Vec<wgpu::BindGroupEntry<'_>> {
    resources
        .into_iter()
        .enumerate()
        .map(|(i, resource)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource,
        })
        .collect()
}

/// Layout entries for slots.
pub fn layout_entries(
    slots: &[Slot],
    visibility: wgpu::ShaderStages,
) -> Vec<wgpu::BindGroupLayoutEntry> {
    slots
        .iter()
        .enumerate()
        .map(|(i, s)| wgpu::BindGroupLayoutEntry {
            binding: i as u32,
            visibility,
            ty: match s {
                Slot::Uniform => wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                Slot::Read | Slot::ReadWrite => wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage {
                        read_only: *s == Slot::Read,
                    },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                Slot::UintTexture => wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Uint,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
            },
            count: None,
        })
        .collect()
}

/// A read-only storage buffer at `binding`, read in the vertex stage (the scene tables, the
/// stream and the terrain's heights).
pub fn vertex_storage_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}
