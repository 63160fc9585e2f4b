//! Pass 2, refine (`shaders/refine.wgsl`): `l − 1` order-preserving subdivision steps
//! between the two stream buffers, three dispatches each, then the final stream's length.

use super::{ComputeShared, StreamBindings, args};
use crate::work::CountingPass;

/// The refine pass's pipelines.
pub struct RefinePass {
    top: wgpu::ComputePipeline,
    down: wgpu::ComputePipeline,
    emit: wgpu::ComputePipeline,
    emit_last: wgpu::ComputePipeline,
    finish: wgpu::ComputePipeline,
}

impl RefinePass {
    /// Create the pipelines.
    pub fn new(device: &wgpu::Device, shared: &ComputeShared) -> Self {
        Self {
            top: shared.writer(device, "refine_top"),
            down: shared.pipeline(device, "refine_down"),
            emit: shared.pipeline(device, "refine_emit"),
            emit_last: shared.pipeline(device, "refine_emit_last"),
            finish: shared.writer(device, "refine_finish"),
        }
    }

    /// Record `iterations` steps alternating `ping` (A → B) and `pong` (B → A), each a
    /// one-workgroup top (stream length, arguments, block-sum scan), a per-block down
    /// (prefixes, which quads refine) and a per-quad emit, then the final length and the
    /// draw arguments: `3 · iterations + 1` dispatches.
    pub fn record(&self, pass: &mut CountingPass, iterations: u32, b: &StreamBindings) {
        pass.pass.set_bind_group(1, b.args_group, &[]);
        for it in 0..iterations {
            let group = if it.is_multiple_of(2) { b.ping } else { b.pong };
            pass.pass.set_bind_group(0, group, &[]);
            pass.pass.set_pipeline(&self.top);
            pass.dispatch(1, 1, 1);
            pass.pass.set_pipeline(&self.down);
            pass.dispatch_indirect(b.args_buf, args::BLOCKS);
            pass.pass.set_pipeline(if it + 1 == iterations {
                &self.emit_last
            } else {
                &self.emit
            });
            pass.dispatch_indirect(b.args_buf, args::ITEMS);
        }
        pass.pass.set_bind_group(0, b.ping, &[]);
        pass.pass.set_pipeline(&self.finish);
        pass.dispatch(1, 1, 1);
    }
}
