// Pass 2, refine (run l − 1 times, input quads_in -> output quads_out): a quad whose
// screen-projected edge is longer than ε pixels is replaced by its existing children (blank
// ones were dropped at bake). Order is kept by a prefix sum over each quad's extra output.
// When the output would overflow, the quads nearest the front of the stream (the nearest
// trees) are refined first and the rest stay as they are, counted in state.overflow_refine.

// Clip-space position of corner c (0 TL, 1 TR, 2 BL, 3 BR) of a quad.
fn quad_corner_clip(q: Quad, node: vec2<u32>, c: u32) -> vec4<f32> {
    let size = 1.0 / f32(1u << quad_level(q));
    let u = (f32(quad_x(q)) + f32(c & 1u)) * size;
    let v = (f32(quad_y(q)) + f32(c >> 1u)) * size;
    let t = f32((node.y >> (8u * c)) & 255u) / 255.0;
    return quad_clip_at(q, u, v, t);
}

// 0: keep; otherwise 1 + the number of extra quads refining it makes (children − 1).
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
    if (!long) { return 0u; }
    return countOneBits(mask);
}

@compute @workgroup_size(256)
fn refine_count(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= atomicLoad(&state.n)) { return; }
    let w = wants(quads_in[i]);
    want[i] = w;
    data[i] = select(0u, w - 1u, w > 0u);
}

fn refined(i: u32) -> bool {
    let n = atomicLoad(&state.n);
    let total = atomicLoad(&state.total);
    let budget = scene.capacity - n;
    return want[i] > 0u && total - data[i] <= budget;
}

@compute @workgroup_size(256)
fn refine_decide(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= atomicLoad(&state.n)) { return; }
    if (refined(i)) {
        atomicMin(&state.pmin, data[i]);
    } else if (want[i] > 0u) {
        atomicAdd(&state.overflow_refine, 1u);
    }
}

@compute @workgroup_size(256)
fn refine_emit(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= atomicLoad(&state.n)) { return; }
    let pmin = atomicLoad(&state.pmin);
    let p = data[i];
    var out = i;
    if (pmin != NONE && p > pmin) { out = i + (p - pmin); }
    let q = quads_in[i];
    if (!refined(i)) {
        quads_out[out] = q;
        return;
    }
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
        quads_out[out] = Quad(q.instance, child, pack_pos(level, x, y, quad_slab(q)), q.dir_weight);
        out = out + 1u;
        child = child + 1u;
    }
}

@compute @workgroup_size(1)
fn refine_finish() {
    let n = atomicLoad(&state.n);
    let pmin = atomicLoad(&state.pmin);
    var m = n;
    if (pmin != NONE) { m = n + (atomicLoad(&state.total) - pmin); }
    atomicStore(&state.n, m);
    atomicStore(&state.pmin, NONE);
    set_args(m);
}

// Quads per level of the final stream, and its length.
var<workgroup> wg_level: array<atomic<u32>, 16>;

@compute @workgroup_size(256)
fn stats(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    if (t < 16u) { atomicStore(&wg_level[t], 0u); }
    workgroupBarrier();
    let n = atomicLoad(&state.n);
    if (gid.x < n) {
        atomicAdd(&wg_level[quad_level(quads_in[gid.x])], 1u);
    }
    workgroupBarrier();
    if (t < 16u) {
        let c = atomicLoad(&wg_level[t]);
        if (c > 0u) { atomicAdd(&state.per_level[t], c); }
    }
    if (gid.x == 0u) { atomicStore(&state.quads, n); }
}
