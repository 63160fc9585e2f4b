//! Pass 1, cull (`shaders/cull.wgsl`): presorted instances → level-0 quads, order kept.

use super::{ComputeShared, StreamBindings};
use crate::capacity::BLOCK;
use crate::work::CountingPass;

/// The cull pass's pipelines.
pub struct CullPass {
    setup: wgpu::ComputePipeline,
    count: wgpu::ComputePipeline,
    top: wgpu::ComputePipeline,
    down: wgpu::ComputePipeline,
    emit: wgpu::ComputePipeline,
    emit_last: wgpu::ComputePipeline,
}

impl CullPass {
    /// Create the pipelines.
    pub fn new(device: &wgpu::Device, shared: &ComputeShared) -> Self {
        Self {
            setup: shared.pipeline(device, "frame_setup"),
            count: shared.pipeline(device, "cull_count"),
            top: shared.pipeline(device, "cull_top"),
            down: shared.pipeline(device, "cull_down"),
            emit: shared.pipeline(device, "cull_emit"),
            emit_last: shared.pipeline(device, "cull_emit_last"),
        }
    }

    /// Record five dispatches: reset the frame state, count each tree's quads (with the
    /// block sums), scan the block sums, turn counts into offsets, emit. `last`: no refine
    /// step follows (the emitter counts levels instead of the quads' refinement wishes).
    pub fn record(&self, pass: &mut CountingPass, b: &StreamBindings, last: bool) {
        // Every dispatch runs at least one workgroup (the entry points check their bounds),
        // so the count of dispatches does not depend on the scene.
        let blocks = b.instances.div_ceil(BLOCK).max(1);
        pass.pass.set_bind_group(0, b.cull, &[]);
        for (p, groups) in [
            (&self.setup, 1),
            (&self.count, blocks),
            (&self.top, 1),
            (&self.down, blocks),
            (if last { &self.emit_last } else { &self.emit }, blocks),
        ] {
            pass.pass.set_pipeline(p);
            pass.dispatch(groups, 1, 1);
        }
    }
}
