// Bindings of the compute passes (cull, scan, refine, stats): one layout for all of them, see
// crates/forest-render/src/bindings.rs.

#import common

struct SceneConsts {
    instances: u32,     // N
    presort_dirs: u32,  // K
    capacity: u32,      // quad capacity Q of each stream buffer
    species: u32,
}

@group(0) @binding(0) var<uniform> camera: Camera;
@group(0) @binding(1) var<uniform> scene: SceneConsts;
@group(0) @binding(2) var<storage, read> instances: array<Instance>;
@group(0) @binding(3) var<storage, read> species: array<Species>;
@group(0) @binding(4) var<storage, read> frames: array<Frame>;
@group(0) @binding(5) var<storage, read> dir_tris: array<vec4<u32>>;
// Root node of every layer, global index (species node base included); NONE when blank.
@group(0) @binding(6) var<storage, read> roots: array<u32>;
@group(0) @binding(7) var<storage, read> presort_dirs: array<vec4<f32>>;
@group(0) @binding(8) var presort: texture_2d<u32>;
@group(0) @binding(9) var nodes: texture_2d<u32>;
@group(0) @binding(10) var<storage, read_write> state: StateAtomic;
// Per item of the step being run: packed tree counts then offsets (cull), or each plain quad's
// wish then
// (prefix << 3) | wish (refine); the emitters write the next step's wishes to data_next.
@group(0) @binding(11) var<storage, read_write> data_next: array<u32>;
@group(0) @binding(12) var<storage, read_write> data: array<u32>;
// One sum per block of BLOCK items (scan.wgsl).
@group(0) @binding(13) var<storage, read_write> sums: array<atomic<u32>>;
// The cull writes far trees' composited quads to both stream buffers (refinement never
// touches them), so quads_in is writable too.
@group(0) @binding(14) var<storage, read_write> quads_in: array<Quad>;
@group(0) @binding(15) var<storage, read_write> quads_out: array<Quad>;

// The indirect arguments are a separate group: a buffer may not be bound for writing in the
// same dispatch that reads its arguments from it, so only the two directly dispatched entry
// points that write them (refine_top, refine_finish) use a layout with group 1.
@group(1) @binding(0) var<storage, read_write> args: Args;

// `State` with atomic members (same layout).
struct StateAtomic {
    presort: atomic<u32>,
    n: atomic<u32>,
    total: atomic<u32>,
    pmin: atomic<u32>,
    overflow_cull: atomic<u32>,
    overflow_refine: atomic<u32>,
    visible: atomic<u32>,
    quads: atomic<u32>,
    composites: atomic<u32>,
    per_level: array<atomic<u32>, 16>,
}

// The composited quads leading a stream of any step: refinement runs over the rest.
fn stream_front() -> u32 {
    return kept_composites(atomicLoad(&state.composites), atomicLoad(&state.overflow_cull));
}

// Arguments for a stream of n quads: the per-item and per-block dispatches over its plain
// quads, and both draws.
fn set_args(n: u32) {
    let c = stream_front();
    let m = n - c;
    args.items = vec4<u32>((m + WG - 1u) / WG, 1u, 1u, 0u);
    args.blocks = vec4<u32>((m + BLOCK - 1u) / BLOCK, 1u, 1u, 0u);
    args.draw = vec4<u32>(4u, m, 0u, 0u);
    args.draw_composite = vec4<u32>(4u, c, 0u, 0u);
}

fn node_at(i: u32) -> vec2<u32> {
    return textureLoad(nodes, vec2<u32>(i % NODE_TEX_WIDTH, i / NODE_TEX_WIDTH), 0).xy;
}
