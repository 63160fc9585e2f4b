//! Pass 2, refine (`shaders/refine.wgsl`): `l − 1` order-preserving subdivision steps
//! between the two stream buffers, then per-level statistics of the final stream.

use super::scan::ScanPass;
use super::{ComputeShared, StreamBindings, args};
use crate::work::CountingPass;

/// The refine pass's pipelines.
pub struct RefinePass {
    count: wgpu::ComputePipeline,
    decide: wgpu::ComputePipeline,
    emit: wgpu::ComputePipeline,
    finish: wgpu::ComputePipeline,
    stats: wgpu::ComputePipeline,
}

impl RefinePass {
    /// Create the pipelines.
    pub fn new(device: &wgpu::Device, shared: &ComputeShared) -> Self {
        Self {
            count: shared.pipeline(device, "refine_count"),
            decide: shared.pipeline(device, "refine_decide"),
            emit: shared.pipeline(device, "refine_emit"),
            finish: shared.writer(device, "refine_finish"),
            stats: shared.pipeline(device, "stats"),
        }
    }

    /// Record `iterations` steps alternating `ping` (A → B) and `pong` (B → A), then the
    /// statistics over the final buffer through `final_in` (a bind group reading it).
    pub fn record(
        &self,
        pass: &mut CountingPass,
        iterations: u32,
        b: &StreamBindings,
        scan: &ScanPass,
    ) {
        let (ping, pong, args_buf) = (b.ping, b.pong, b.args_buf);
        pass.pass.set_bind_group(1, b.args_group, &[]);
        for it in 0..iterations {
            pass.pass
                .set_bind_group(0, if it.is_multiple_of(2) { ping } else { pong }, &[]);
            pass.pass.set_pipeline(&self.count);
            pass.dispatch_indirect(args_buf, args::ITEMS);
            scan.record(pass, args_buf);
            for p in [&self.decide, &self.emit] {
                pass.pass.set_pipeline(p);
                pass.dispatch_indirect(args_buf, args::ITEMS);
            }
            pass.pass.set_pipeline(&self.finish);
            pass.dispatch(1, 1, 1);
        }
        // The final stream is A after an even number of steps (read it through `ping`).
        pass.pass.set_bind_group(
            0,
            if iterations.is_multiple_of(2) {
                ping
            } else {
                pong
            },
            &[],
        );
        pass.pass.set_pipeline(&self.stats);
        pass.dispatch_indirect(args_buf, args::ITEMS);
    }
}
