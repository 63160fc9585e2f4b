// Pass 2, refine (run l − 1 times, input quads_in -> output quads_out): a quad whose
// screen-projected edge is longer than ε pixels is replaced by its existing children (blank
// ones were dropped at bake), unless all it and they may draw lies outside the view's sides
// (quad_outside). Order is kept by a prefix sum over each quad's extra output.
// When the output would overflow, the quads nearest the end of the stream (the nearest
// trees) are refined first and the rest stay as they are, counted in state.overflow_refine.
//
// Three dispatches a step, the scan's phases fused into them (scan.wgsl):
//   refine_top    one workgroup: the stream's new length from the previous step, the
//                 dispatch arguments, the scan of the block sums;
//   refine_down   per block: each quad's prefix, and which quads are refined (the
//                 smallest refined prefix, pmin);
//   refine_emit   per quad: the quad or its children, written at their offsets, each with
//                 its own refinement wish for the next step (`wants`, in data_next, its
//                 extra quads added to its block's sum). The last step's emitter counts
//                 the levels of the final stream instead.
// A quad's entry in data / data_next: its wish w (3 bits: 0 keep, else its child count)
// before the scan, (prefix << 3) | w after it.
//
// The far trees' composited quads that lead the stream (stream_front) are never refined:
// the cull wrote them to both stream buffers, and every step runs over the plain quads
// after them alone. Indices into data, data_next and the block sums count from the first
// plain quad; the stream buffers are indexed from the front (quads_in[front + i]).

#import common
#import bindings
#import quad_geometry
#import scan

// Clip-space position of corner c (0 TL, 1 TR, 2 BL, 3 BR) of a quad.
fn quad_corner_clip(q: Quad, node: vec2<u32>, c: u32) -> vec4<f32> {
    let size = 1.0 / f32(1u << quad_level(q));
    let u = (f32(quad_x(q)) + f32(c & 1u)) * size;
    let v = (f32(quad_y(q)) + f32(c >> 1u)) * size;
    let t = f32((node.y >> (8u * c)) & 255u) / 255.0;
    return quad_clip_at(q, u, v, t);
}

// 0: keep; otherwise the number of children refining it makes (1 + its extra quads). Asked
// of plain quads only: a far tree's composited quad, never refined, is written by the cull
// itself and no step visits it (the CPU reference, whose stream holds both lists, gives it 0).
fn wants(q: Quad) -> u32 {
    let node = node_at(q.node);
    let mask = node.x >> 28u;
    if (mask == 0u) { return 0u; }
    var clip: array<vec4<f32>, 4>;
    var behind = 0u;
    for (var c = 0u; c < 4u; c++) {
        clip[c] = quad_corner_clip(q, node, c);
        if (clip[c].w <= 0.0) { behind = behind + 1u; }
    }
    if (behind == 4u) { return 0u; }
    var long = behind > 0u;
    if (!long) {
        long = edge_long(clip[0], clip[1]) || edge_long(clip[1], clip[3])
            || edge_long(clip[3], clip[2]) || edge_long(clip[2], clip[0]);
    }
    if (!long && (stream_flags(camera) & FLAG_DEPTH_ERROR) != 0u) {
        long = error_long(q, node);
    }
    // Tested last: only a quad that would refine pays for the test.
    if (!long || quad_outside(q)) { return 0u; }
    return countOneBits(mask);
}

// The extra quads a wish adds to the stream.
fn extra_of(w: u32) -> u32 { return select(0u, w - 1u, w > 0u); }

// The stream's length after the step whose pmin and scan total are in `state` (before the
// first step, cull_top leaves the level-0 length with no pmin).
fn advance() -> u32 {
    let n = atomicLoad(&state.n);
    let pmin = atomicLoad(&state.pmin);
    if (pmin == NONE) { return n; }
    return n + (atomicLoad(&state.total) - pmin);
}

// Emitting (cull_emit and refine_emit): each output quad is written with either its own
// refinement wish for the next step or, in the last step, its level in the statistics.
var<workgroup> wg_level: array<atomic<u32>, 16>;

// Before the workgroup's first output, whose index thread 0 gives.
fn emit_begin(t: u32, first_out: u32) {
    if (t < BINS) {
        atomicStore(&wg_bins[t], 0u);
        atomicStore(&wg_level[t], 0u);
    }
    if (t == 0u) { wg_first_block = first_out / BLOCK; }
    workgroupBarrier();
}

// Plain quad `out` (counted from the first plain quad; `front` composited quads before it).
fn put_quad(front: u32, out: u32, q: Quad, last: bool) {
    quads_out[front + out] = q;
    if (last) {
        atomicAdd(&wg_level[quad_level(q)], 1u);
        return;
    }
    let w = wants(q);
    data_next[out] = w;
    add_to_block(out, extra_of(w));
}

// After the workgroup's last output: the bins and level counts reach the frame's buffers.
fn emit_end(t: u32) {
    workgroupBarrier();
    if (t < BINS) {
        let v = atomicLoad(&wg_bins[t]);
        if (v > 0u) { atomicAdd(&sums[wg_first_block + t], v); }
        let c = atomicLoad(&wg_level[t]);
        if (c > 0u) { atomicAdd(&state.per_level[t], c); }
    }
}

@compute @workgroup_size(256)
fn refine_top(@builtin(local_invocation_index) t: u32) {
    var n = 0u;
    if (t == 0u) {
        n = advance();
        atomicStore(&state.n, n);
        atomicStore(&state.pmin, NONE);
        set_args(n);
    }
    var plain_blocks = 0u;
    if (t == 0u) { plain_blocks = (n - stream_front() + BLOCK - 1u) / BLOCK; }
    let total = scan_block_sums(t, 0u, plain_blocks);
    if (t == 0u) { atomicStore(&state.total, total); }
}

// Refined: wishes to, and its extra quads with those of every refined quad after it (the
// nearer trees) fit the room left.
fn refined(w: u32, prefix: u32, n: u32, total: u32) -> bool {
    return w > 0u && total - prefix <= scene.capacity - n;
}

var<workgroup> wg_pmin: atomic<u32>;
var<workgroup> wg_unrefined: atomic<u32>;

@compute @workgroup_size(256)
fn refine_down(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    if (t == 0u) {
        atomicStore(&wg_pmin, NONE);
        atomicStore(&wg_unrefined, 0u);
    }
    let n = atomicLoad(&state.n);
    let m = n - stream_front();
    let total = atomicLoad(&state.total);
    let i0 = wg.x * BLOCK + 2u * t;
    var w = vec2<u32>(0u);
    if (i0 < m) { w.x = data[i0] & 7u; }
    if (i0 + 1u < m) { w.y = data[i0 + 1u] & 7u; }
    let p = block_prefix(wg.x, t, extra_of(w.x), extra_of(w.y));
    for (var k = 0u; k < 2u; k++) {
        let i = i0 + k;
        if (i >= m) { continue; }
        data[i] = (p[k] << 3u) | w[k];
        if (refined(w[k], p[k], n, total)) {
            atomicMin(&wg_pmin, p[k]);
        } else if (w[k] > 0u) {
            atomicAdd(&wg_unrefined, 1u);
        }
    }
    workgroupBarrier();
    if (t == 0u) {
        let m = atomicLoad(&wg_pmin);
        if (m != NONE) { atomicMin(&state.pmin, m); }
        let u = atomicLoad(&wg_unrefined);
        if (u > 0u) { atomicAdd(&state.overflow_refine, u); }
    }
}

// Where quad i's output starts: after the extra quads of the refined quads before it.
fn refined_out(i: u32, prefix: u32, pmin: u32) -> u32 {
    if (pmin != NONE && prefix > pmin) { return i + (prefix - pmin); }
    return i;
}

fn refine_emit_body(wg: u32, t: u32, last: bool) {
    let n = atomicLoad(&state.n);
    let front = stream_front();
    let m = n - front;
    let total = atomicLoad(&state.total);
    let pmin = atomicLoad(&state.pmin);
    let first = wg * WG;
    emit_begin(t, refined_out(first, data[min(first, m - 1u)] >> 3u, pmin));
    let i = first + t;
    if (i < m) {
        let entry = data[i];
        let prefix = entry >> 3u;
        let w = entry & 7u;
        var out = refined_out(i, prefix, pmin);
        let q = quads_in[front + i];
        if (!refined(w, prefix, n, total)) {
            put_quad(front, out, q, last);
        } else {
            let inst = instances[q.instance];
            let node_base = species[inst.species].node_base;
            let node = node_at(q.node);
            let mask = node.x >> 28u;
            var child = node_base + (node.x & 0x00ffffffu);
            let level = quad_level(q) + 1u;
            for (var c = 0u; c < 4u; c++) {
                if ((mask & (1u << c)) == 0u) { continue; }
                let x = quad_x(q) * 2u + (c & 1u);
                let y = quad_y(q) * 2u + (c >> 1u);
                put_quad(front, out, Quad(q.instance, child,
                    pack_pos(level, x, y, quad_slab(q)), q.dir_weight), last);
                out = out + 1u;
                child = child + 1u;
            }
        }
    }
    emit_end(t);
}

@compute @workgroup_size(256)
fn refine_emit(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    refine_emit_body(wg.x, t, false);
}

@compute @workgroup_size(256)
fn refine_emit_last(@builtin(workgroup_id) wg: vec3<u32>,
                    @builtin(local_invocation_index) t: u32) {
    refine_emit_body(wg.x, t, true);
}

// After the last step: the final stream's length, in the statistics and the draw arguments;
// the composited quads' level (0), which no emitter counted.
@compute @workgroup_size(1)
fn refine_finish() {
    let n = advance();
    atomicStore(&state.n, n);
    atomicStore(&state.pmin, NONE);
    atomicStore(&state.quads, n);
    atomicAdd(&state.per_level[0], stream_front());
    set_args(n);
}
