//! Pass 1, cull (`shaders/cull.wgsl`): presorted instances → level-0 quads, order kept.

use super::scan::ScanPass;
use super::{ComputeShared, StreamBindings, args};
use crate::work::CountingPass;

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
    pub fn record(&self, pass: &mut CountingPass, b: &StreamBindings, scan: &ScanPass) {
        let args_buf = b.args_buf;
        pass.pass.set_bind_group(0, b.cull, &[]);
        pass.pass.set_bind_group(1, b.args_group, &[]);
        pass.pass.set_pipeline(&self.setup);
        pass.dispatch(1, 1, 1);
        pass.pass.set_pipeline(&self.count);
        pass.dispatch_indirect(args_buf, args::ITEMS);
        scan.record(pass, args_buf);
        pass.pass.set_pipeline(&self.emit);
        pass.dispatch_indirect(args_buf, args::ITEMS);
        pass.pass.set_pipeline(&self.finish);
        pass.dispatch(1, 1, 1);
    }
}
