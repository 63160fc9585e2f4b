//! The order-preserving prefix sum (`shaders/scan.wgsl`) used by cull and refine.

use super::{ComputeShared, args};
use crate::work::CountingPass;

/// Exclusive scan of `data[0..state.n]` in place; total in `state.total`.
pub struct ScanPass {
    reduce0: wgpu::ComputePipeline,
    reduce1: wgpu::ComputePipeline,
    top: wgpu::ComputePipeline,
    down1: wgpu::ComputePipeline,
    down0: wgpu::ComputePipeline,
}

impl ScanPass {
    /// Create the pipelines.
    pub fn new(device: &wgpu::Device, shared: &ComputeShared) -> Self {
        Self {
            reduce0: shared.pipeline(device, "scan_reduce0"),
            reduce1: shared.pipeline(device, "scan_reduce1"),
            top: shared.pipeline(device, "scan_top"),
            down1: shared.pipeline(device, "scan_down1"),
            down0: shared.pipeline(device, "scan_down0"),
        }
    }

    /// Record the five dispatches (the bind group is already set).
    pub fn record(&self, pass: &mut CountingPass, args_buf: &wgpu::Buffer) {
        for (p, offset) in [
            (&self.reduce0, args::BLOCKS0),
            (&self.reduce1, args::BLOCKS1),
            (&self.top, args::ONE),
            (&self.down1, args::BLOCKS1),
            (&self.down0, args::BLOCKS0),
        ] {
            pass.pass.set_pipeline(p);
            pass.dispatch_indirect(args_buf, offset);
        }
    }
}
