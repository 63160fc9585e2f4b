//! Pass 1, cull (`shaders/cull.wgsl`): presorted instances → level-0 quads, order kept.

use super::scan::ScanPass;
use super::{ComputeShared, StreamBindings, args};

/// The cull pass's pipelines.
pub struct CullPass {
    setup: wgpu::ComputePipeline,
    count: wgpu::ComputePipeline,
    emit: wgpu::ComputePipeline,
    finish: wgpu::ComputePipeline,
}

impl CullPass {
    /// Create the pipelines.
    pub fn new(device: &wgpu::Device, shared: &ComputeShared) -> Self {
        Self {
            setup: shared.writer(device, "frame_setup"),
            count: shared.pipeline(device, "cull_count"),
            emit: shared.pipeline(device, "cull_emit"),
            finish: shared.writer(device, "cull_finish"),
        }
    }

    /// Record: reset the frame state, count each tree's quads, scan, emit, clamp.
    pub fn record(&self, pass: &mut wgpu::ComputePass, b: &StreamBindings, scan: &ScanPass) {
        let args_buf = b.args_buf;
        pass.set_bind_group(0, b.cull, &[]);
        pass.set_bind_group(1, b.args_group, &[]);
        pass.set_pipeline(&self.setup);
        pass.dispatch_workgroups(1, 1, 1);
        pass.set_pipeline(&self.count);
        pass.dispatch_workgroups_indirect(args_buf, args::ITEMS);
        scan.record(pass, args_buf);
        pass.set_pipeline(&self.emit);
        pass.dispatch_workgroups_indirect(args_buf, args::ITEMS);
        pass.set_pipeline(&self.finish);
        pass.dispatch_workgroups(1, 1, 1);
    }
}
