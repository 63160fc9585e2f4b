// Exact fragment counts (forest_render::fragments): every tree fragment stage calls
// count_enter first, in uniform control flow, and count_shown with the alpha it returns
// (discarded fragments never reach it). Per pixel, COUNT_STRIDE counters:
//   0: fragment invocations, helper lanes excluded (their stores and atomics have no effect);
//   1: 2×2-quad lanes: 4 per quad of a primitive with at least one live lane, added by the
//      quad's first live lane (what a GPU that shades in 2×2 quads runs);
//   2: fragments shown, of alpha at least SHOWN_ALPHA;
//   3: shown fragments hidden behind an opaque one at the pixel (phase 1 only);
//   4: the nearest opaque fragment's nearness, as f32 bits (phase 0; max of nearness);
//   5, 6: the nearest depth written so far by the stages that write depth (count_depth), in
//      phase 0 and phase 1.
// Phase 0 counts and records the opaque front; phase 1 redraws the same frame and counts only
// the hidden fragments against that front.
//
// A fragment stage with storage writes runs its depth test late, so these stages see
// fragments that the uncounted pipelines reject before shading. The early test is emulated
// (forcing it needs a native-only feature, and would write the geometry's depth before its
// alpha test): a fragment behind the depth that the frame's depth-writing tree stages (the
// geometry's, count_depth) have written at the pixel so far (counter 5 or 6) is rejected and
// counted nowhere. The emulation sees the trees' depth, not the ground's, and assumes the
// fragments of one pixel are shaded in draw order, as lavapipe does.

struct CountParams {
    width: u32,
    height: u32,
    phase: u32,
    // 1 with reversed depth (near at 1).
    reverse_z: u32,
}

@group(1) @binding(0) var<storage, read_write> fragment_counts: array<atomic<u32>>;
@group(1) @binding(1) var<uniform> count_params: CountParams;

const COUNT_STRIDE: u32 = 7u;

// Whether this invocation's fragment failed the emulated early depth test (count_enter).
var<private> count_rejected: bool;
// A fragment of less alpha adds nothing visible to an 8-bit target.
const SHOWN_ALPHA: f32 = 0.5 / 255.0;
// A fragment this opaque hides what lies behind it (to 8 bits).
const OPAQUE_ALPHA: f32 = 1.0 - 0.5 / 255.0;

// The pixel's first counter; the position is clamped into the target, so no write falls
// outside the buffer.
fn count_base(pos: vec4<f32>) -> u32 {
    let x = min(u32(max(pos.x, 0.0)), count_params.width - 1u);
    let y = min(u32(max(pos.y, 0.0)), count_params.height - 1u);
    return (y * count_params.width + x) * COUNT_STRIDE;
}

// The fragment's nearness as ordered bits (larger is nearer).
fn count_key(pos: vec4<f32>) -> u32 {
    let near = select(1.0 - pos.z, pos.z, count_params.reverse_z != 0u);
    return bitcast<u32>(max(near, 0.0));
}

fn count_enter(pos: vec4<f32>) {
    let written = count_base(pos) + 5u + count_params.phase;
    count_rejected = count_key(pos) < atomicLoad(&fragment_counts[written]);
    if (count_params.phase != 0u) { return; }
    // A helper lane's atomics have no effect (the WGSL and Vulkan rules), so a lane is live
    // when its own increment shows in the count it reads back (lavapipe gives helper lanes a
    // sample mask of 1, so the mask cannot tell them apart). Another fragment's increment at
    // the same pixel between the two loads would make a helper look live: fragments of one
    // pixel are shaded one after another on lavapipe.
    let i = count_base(pos);
    let before = atomicLoad(&fragment_counts[i]);
    if (!count_rejected) {
        atomicAdd(&fragment_counts[i], 1u);
    }
    let live = atomicLoad(&fragment_counts[i]) != before;
    let ox = u32(max(pos.x, 0.0)) & 1u;
    let oy = u32(max(pos.y, 0.0)) & 1u;
    let lane = ox + 2u * oy;
    // The quad's mask of live lanes, summed through fine derivatives (which read the other
    // lanes of the 2×2 quad, helpers included): dpdxFine(b) is b(odd x) − b(even x). The
    // phase is uniform, so this is uniform control flow.
    let b = select(0.0, f32(1u << lane), live);
    let dx = dpdxFine(b);
    let row = b + select(b - dx, b + dx, ox == 0u);
    let dy = dpdyFine(row);
    let lanes = u32(row + select(row - dy, row + dy, oy == 0u));
    if (live && (lanes & ((1u << lane) - 1u)) == 0u) {
        atomicAdd(&fragment_counts[i + 1u], 4u);
    }
}

fn count_shown(pos: vec4<f32>, alpha: f32) {
    if (alpha < SHOWN_ALPHA || count_rejected) { return; }
    let i = count_base(pos);
    let key = count_key(pos);
    if (count_params.phase == 0u) {
        atomicAdd(&fragment_counts[i + 2u], 1u);
        if (alpha >= OPAQUE_ALPHA) { atomicMax(&fragment_counts[i + 4u], key); }
    } else if (key < atomicLoad(&fragment_counts[i + 4u])) {
        atomicAdd(&fragment_counts[i + 3u], 1u);
    }
}

// A depth-writing stage's fragment that passed its alpha test: its depth is written.
fn count_depth(pos: vec4<f32>) {
    if (count_rejected) { return; }
    atomicMax(&fragment_counts[count_base(pos) + 5u + count_params.phase], count_key(pos));
}
