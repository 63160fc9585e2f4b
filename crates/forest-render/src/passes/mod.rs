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

pub use crate::bindings::{COMPUTE_SLOTS, Slot, layout_entries, numbered};
pub use crate::shaders::*;

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
