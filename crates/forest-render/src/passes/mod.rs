//! The GPU passes, one struct each, and the layout they share.
//!
//! All compute entry points live in one WGSL module (common + bindings + scan + cull +
//! refine) and share one bind-group layout, so the ping-pong stream and scan buffers are
//! swapped by swapping bind groups. The order-preserving prefix sums (`shaders/scan.wgsl`)
//! have no dispatches of their own: their phases are fused into the passes' dispatches. The
//! draw pass has its own module (common + draw).

pub mod cast;
pub mod cull;
pub mod draw;
pub mod overdraw;
pub mod refine;

/// The WGSL every module starts with: the camera, the scene's structs, the shared helpers
/// (other crates' shaders that read the camera, such as the baselines', start with it too).
pub const COMMON_WGSL: &str = include_str!("../../shaders/common.wgsl");
/// The ground's pattern (soil and moss) as pure WGSL functions of world (x, z), no bindings:
/// `ground_moss(xz) -> f32`. The environment uses it; a host drawing its own ground may too.
pub const GROUND_WGSL: &str = include_str!("../../shaders/ground.wgsl");
/// The environment (sky, ground, terrain) and the haze every method's fragments go through
/// (after a module declaring `camera`, and [`GROUND_WGSL`]).
pub const ENVIRONMENT_WGSL: &str = include_str!("../../shaders/environment.wgsl");

/// WGSL of the compute passes.
pub const COMPUTE_WGSL: [&str; 6] = [
    COMMON_WGSL,
    include_str!("../../shaders/bindings.wgsl"),
    include_str!("../../shaders/quad_geometry.wgsl"),
    include_str!("../../shaders/scan.wgsl"),
    include_str!("../../shaders/cull.wgsl"),
    include_str!("../../shaders/refine.wgsl"),
];

/// WGSL of the draw pass (without fragment counting: [`COUNT_OFF_WGSL`] closes it), with the
/// sun's shadow lookups ([`SHADOW_ON_WGSL`]).
pub const DRAW_WGSL: [&str; 6] = [
    COMMON_WGSL,
    include_str!("../../shaders/draw.wgsl"),
    GROUND_WGSL,
    ENVIRONMENT_WGSL,
    SHADOW_ON_WGSL,
    COUNT_OFF_WGSL,
];

/// The sun's shadow lookups against the cascades' maps, bound as group 2
/// (`shaders/shadow_on.wgsl`; see [`crate::shadow_maps`]): `sun_shadow(world, normal)` and
/// `tree_shadow(point, sphere)`.
pub const SHADOW_ON_WGSL: &str = include_str!("../../shaders/shadow_on.wgsl");

/// The same lookups for a module drawn without shadow maps: every point lit
/// (`shaders/shadow_off.wgsl`). Every module that includes [`ENVIRONMENT_WGSL`] also includes
/// this or [`SHADOW_ON_WGSL`].
pub const SHADOW_OFF_WGSL: &str = include_str!("../../shaders/shadow_off.wgsl");

/// The light views' casting pass (`shaders/cast.wgsl`), appended to [`DRAW_WGSL`].
pub const CAST_WGSL: &str = include_str!("../../shaders/cast.wgsl");

/// The fragment-count hooks that do nothing (`shaders/count_off.wgsl`): every draw module
/// that shades tree fragments ends with this or [`COUNT_ON_WGSL`].
pub const COUNT_OFF_WGSL: &str = include_str!("../../shaders/count_off.wgsl");

/// The fragment-count hooks that count (`shaders/count_on.wgsl`, group 1: see
/// [`crate::fragments`]).
pub const COUNT_ON_WGSL: &str = include_str!("../../shaders/count_on.wgsl");

/// The module of `parts` (a draw module's sources, [`COUNT_OFF_WGSL`] among them) with the
/// counting hooks in place of the empty ones.
pub fn counting_source(parts: &[&str]) -> String {
    parts
        .iter()
        .map(|p| {
            if *p == COUNT_OFF_WGSL {
                COUNT_ON_WGSL
            } else {
                p
            }
        })
        .collect()
}

/// The compute module's source.
pub fn compute_source() -> String {
    COMPUTE_WGSL.concat()
}

/// The draw module's source.
pub fn draw_source() -> String {
    DRAW_WGSL.concat()
}

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

/// The shared compute layout and module.
pub struct ComputeShared {
    /// Bind-group layout of all compute passes (group 0).
    pub bind_layout: wgpu::BindGroupLayout,
    /// Group 1: the indirect-argument buffer, for the entry points that write it.
    pub args_layout: wgpu::BindGroupLayout,
    /// Pipeline layout of the passes that read their arguments (group 0 only).
    pub pipeline_layout: wgpu::PipelineLayout,
    /// Pipeline layout of the argument writers (groups 0 and 1).
    pub writer_layout: wgpu::PipelineLayout,
    /// The compute module.
    pub module: wgpu::ShaderModule,
}

impl ComputeShared {
    /// Create the layout and compile the module.
    pub fn new(device: &wgpu::Device) -> Self {
        let bind_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("compute"),
            entries: &layout_entries(&COMPUTE_SLOTS, wgpu::ShaderStages::COMPUTE),
        });
        let args_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("indirect arguments"),
            entries: &layout_entries(&[Slot::ReadWrite], wgpu::ShaderStages::COMPUTE),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("compute"),
            bind_group_layouts: &[Some(&bind_layout)],
            immediate_size: 0,
        });
        let writer_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("compute, argument writers"),
            bind_group_layouts: &[Some(&bind_layout), Some(&args_layout)],
            immediate_size: 0,
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("compute passes"),
            source: wgpu::ShaderSource::Wgsl(compute_source().into()),
        });
        Self {
            bind_layout,
            args_layout,
            pipeline_layout,
            writer_layout,
            module,
        }
    }

    /// A pipeline for one entry point that reads its dispatch arguments.
    pub fn pipeline(&self, device: &wgpu::Device, entry: &str) -> wgpu::ComputePipeline {
        self.make(device, entry, &self.pipeline_layout)
    }

    /// A pipeline for one entry point that writes the dispatch arguments (group 1).
    pub fn writer(&self, device: &wgpu::Device, entry: &str) -> wgpu::ComputePipeline {
        self.make(device, entry, &self.writer_layout)
    }

    fn make(
        &self,
        device: &wgpu::Device,
        entry: &str,
        layout: &wgpu::PipelineLayout,
    ) -> wgpu::ComputePipeline {
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout: Some(layout),
            module: &self.module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        })
    }
}

/// The bind groups and argument buffer the compute passes record with.
pub struct StreamBindings<'a> {
    /// Cull: writes stream A.
    pub cull: &'a wgpu::BindGroup,
    /// Tree instances in the scene (the cull's dispatches are sized by them).
    pub instances: u32,
    /// Refine A → B.
    pub ping: &'a wgpu::BindGroup,
    /// Refine B → A.
    pub pong: &'a wgpu::BindGroup,
    /// Group 1 (the arguments) for the writers.
    pub args_group: &'a wgpu::BindGroup,
    /// The arguments buffer, read by indirect dispatches.
    pub args_buf: &'a wgpu::Buffer,
}

/// Byte offsets of the dispatch arguments in the args buffer (see `GpuArgs`).
pub mod args {
    /// `ceil(m/256)` workgroups, `m` the plain quads (the composited ones are never refined).
    pub const ITEMS: u64 = 0;
    /// `ceil(m/512)`.
    pub const BLOCKS: u64 = 16;
    /// Draw arguments of the plain quads.
    pub const DRAW: u64 = 32;
    /// Draw arguments of the composited quads.
    pub const DRAW_COMPOSITE: u64 = 48;
}
