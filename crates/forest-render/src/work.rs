//! The work a frame asks of a GPU, counted in units any GPU understands: shader invocations
//! and primitives from pipeline-statistics queries (where the adapter has them: lavapipe and
//! desktop Vulkan/D3D12 drivers do), dispatches and draws as they are recorded, and the bytes
//! of buffers and textures a frame can touch. Times say how fast one machine was; these
//! counts say how much there was to do.

/// The statistics each query gathers, in the order the resolved values come (wgpu writes one
/// `u64` per set flag, in flag order).
pub const STATISTICS: wgpu::PipelineStatisticsTypes =
    wgpu::PipelineStatisticsTypes::VERTEX_SHADER_INVOCATIONS
        .union(wgpu::PipelineStatisticsTypes::CLIPPER_PRIMITIVES_OUT)
        .union(wgpu::PipelineStatisticsTypes::FRAGMENT_SHADER_INVOCATIONS)
        .union(wgpu::PipelineStatisticsTypes::COMPUTE_SHADER_INVOCATIONS);

/// Values per query.
const VALUES: usize = 4;

/// A renderer's passes a frame's statistics are split into (cull, refine or classify, draw).
pub const PASSES: usize = 3;
/// Index of the cull pass's query.
pub const CULL: u32 = 0;
/// Index of the refine (or classify) pass's query.
pub const REFINE: u32 = 1;
/// Index of the draw pass's query.
pub const DRAW: u32 = 2;

/// Bytes of one frame's resolved statistics.
pub const STATISTICS_BYTES: u64 = (PASSES * VALUES * 8) as u64;

/// Pipeline statistics of one pass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PassWork {
    /// Vertex-shader invocations.
    pub vertex_invocations: u64,
    /// Primitives out of the clipper (rasterised).
    pub primitives: u64,
    /// Fragment-shader invocations (fragments shaded, before depth and blending).
    pub fragment_invocations: u64,
    /// Compute-shader invocations (threads).
    pub compute_invocations: u64,
}

impl PassWork {
    fn add(self, o: Self) -> Self {
        Self {
            vertex_invocations: self.vertex_invocations + o.vertex_invocations,
            primitives: self.primitives + o.primitives,
            fragment_invocations: self.fragment_invocations + o.fragment_invocations,
            compute_invocations: self.compute_invocations + o.compute_invocations,
        }
    }
}

/// The work of one frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameWork {
    /// Compute dispatches recorded (direct and indirect).
    pub dispatches: u32,
    /// Draw calls recorded (direct and indirect; an indirect draw counts once).
    pub draws: u32,
    /// Pipeline statistics per pass (cull, refine or classify, draw), where the device has
    /// pipeline-statistics queries.
    pub passes: Option<[PassWork; PASSES]>,
    /// Bytes of buffers and textures the frame's passes can read or write.
    pub bytes: u64,
}

impl FrameWork {
    /// The passes' statistics summed.
    pub fn total(&self) -> Option<PassWork> {
        self.passes
            .map(|p| p.into_iter().fold(PassWork::default(), PassWork::add))
    }

    /// Two renderers' work in one frame (the hybrid's quads and geometry): counts added,
    /// statistics where both have them.
    pub fn combined(&self, other: &Self) -> Self {
        Self {
            dispatches: self.dispatches + other.dispatches,
            draws: self.draws + other.draws,
            passes: self
                .passes
                .zip(other.passes)
                .map(|(a, b)| std::array::from_fn(|i| a[i].add(b[i]))),
            bytes: self.bytes + other.bytes,
        }
    }

    /// How the counts were obtained, for reports.
    pub fn source(&self) -> &'static str {
        if self.passes.is_some() {
            "pipeline-statistics queries"
        } else {
            "recorded commands only (no pipeline-statistics queries on this adapter)"
        }
    }
}

/// A query set of [`PASSES`] pipeline-statistics queries and the buffer they resolve into.
pub struct StatisticsQueries {
    /// The queries (one per pass: [`CULL`], [`REFINE`], [`DRAW`]).
    pub set: wgpu::QuerySet,
    /// Resolved values ([`STATISTICS_BYTES`]; `COPY_SRC` for read-back).
    pub resolve: wgpu::Buffer,
}

impl StatisticsQueries {
    /// Queries for `device`, or `None` without `PIPELINE_STATISTICS_QUERY`.
    pub fn new(device: &wgpu::Device) -> Option<Self> {
        if !device
            .features()
            .contains(wgpu::Features::PIPELINE_STATISTICS_QUERY)
        {
            return None;
        }
        Some(Self {
            set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pipeline statistics"),
                ty: wgpu::QueryType::PipelineStatistics(STATISTICS),
                count: PASSES as u32,
            }),
            resolve: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pipeline statistics"),
                size: STATISTICS_BYTES,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
        })
    }

    /// Resolve the frame's queries (after the last pass that used them).
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.resolve_query_set(&self.set, 0..PASSES as u32, &self.resolve, 0);
    }
}

/// Decode resolved statistics ([`STATISTICS_BYTES`] or more); `None` when too short.
pub fn decode(bytes: &[u8]) -> Option<[PassWork; PASSES]> {
    let bytes = bytes.get(..STATISTICS_BYTES as usize)?;
    let v: Vec<u64> = bytemuck::pod_collect_to_vec(bytes);
    Some(std::array::from_fn(|p| {
        let q = &v[p * VALUES..(p + 1) * VALUES];
        PassWork {
            vertex_invocations: q[0],
            primitives: q[1],
            fragment_invocations: q[2],
            compute_invocations: q[3],
        }
    }))
}

/// A compute pass that counts the dispatches recorded into it.
pub struct CountingPass<'a, 'p> {
    /// The pass (pipelines and bind groups are set on it directly).
    pub pass: &'a mut wgpu::ComputePass<'p>,
    /// Dispatches recorded so far.
    pub dispatches: u32,
}

impl<'a, 'p> CountingPass<'a, 'p> {
    /// Count the dispatches recorded into `pass`.
    pub fn new(pass: &'a mut wgpu::ComputePass<'p>) -> Self {
        Self {
            pass,
            dispatches: 0,
        }
    }

    /// A direct dispatch.
    pub fn dispatch(&mut self, x: u32, y: u32, z: u32) {
        self.pass.dispatch_workgroups(x, y, z);
        self.dispatches += 1;
    }

    /// An indirect dispatch.
    pub fn dispatch_indirect(&mut self, args: &wgpu::Buffer, offset: u64) {
        self.pass.dispatch_workgroups_indirect(args, offset);
        self.dispatches += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_decode_in_flag_order() {
        let values: Vec<u64> = (1..=(PASSES * VALUES) as u64).collect();
        let p = decode(bytemuck::cast_slice(&values)).unwrap();
        assert_eq!(
            p[DRAW as usize],
            PassWork {
                vertex_invocations: 9,
                primitives: 10,
                fragment_invocations: 11,
                compute_invocations: 12
            }
        );
        let w = FrameWork {
            passes: Some(p),
            ..Default::default()
        };
        assert_eq!(w.total().unwrap().vertex_invocations, 1 + 5 + 9);
        assert!(decode(&[0; 8]).is_none());
        // The flags are in the order the values are decoded.
        assert_eq!(
            STATISTICS.bits().count_ones() as usize,
            VALUES,
            "one value per flag"
        );
        assert!(
            wgpu::PipelineStatisticsTypes::VERTEX_SHADER_INVOCATIONS.bits()
                < wgpu::PipelineStatisticsTypes::CLIPPER_PRIMITIVES_OUT.bits()
                && wgpu::PipelineStatisticsTypes::CLIPPER_PRIMITIVES_OUT.bits()
                    < wgpu::PipelineStatisticsTypes::FRAGMENT_SHADER_INVOCATIONS.bits()
                && wgpu::PipelineStatisticsTypes::FRAGMENT_SHADER_INVOCATIONS.bits()
                    < wgpu::PipelineStatisticsTypes::COMPUTE_SHADER_INVOCATIONS.bits()
        );
    }
}
