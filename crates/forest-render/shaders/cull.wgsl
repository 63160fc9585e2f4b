// Pass 1, cull: over the instances in the presorted order nearest the view, frustum-test each
// tree's bounding sphere; for each visible tree find the 1–3 sampling directions around the
// view direction in the tree's own frame, and emit the level-0 quads of their slabs, back slab
// first. Compaction keeps the order: cull_count writes per-tree counts and block sums,
// cull_top scans the block sums, cull_down turns the counts into offsets, cull_emit writes
// each tree's quads at its offset (scan.wgsl). With frame_setup: five dispatches.
//
// The level-0 stream is two lists, each in presorted order: the far trees' composited quads
// first, then every other quad. A tree's count packs both (TREE_COMPOSITE per composited
// quad above the plain count, which is at most 3 · 16 slabs, so a block's plain sum stays
// below 2^16), and the two scans run side by side: block sums [0, B) plain, [B, 2B)
// composited, B the blocks of trees. The composited quads go to both stream buffers and
// refinement never visits them (refine.wgsl), so the final stream keeps them at its front
// and the draw pass draws each list alone.

#import common
#import bindings
#import scan
#import wind

// Blend of the species' directions for an object-space view vector (unnormalised), exactly as
// forest_format::directions::blend. Returns indices in .idx and weights in .w.
struct Blend {
    idx: vec3<u32>,
    w: vec3<f32>,
}

fn cross2(a: vec2<f32>, b: vec2<f32>) -> f32 {
    return a.x * b.y - a.y * b.x;
}

// Views from below use the lower triangles and the projection with y negated.
fn blend(sp: Species, view: vec3<f32>) -> Blend {
    let below = view.y < 0.0 && sp.lower_tri_count > 0u;
    var flip = vec3<f32>(1.0, 1.0, 1.0);
    var first = sp.tri_base;
    var count = sp.tri_count;
    if (below) {
        flip.y = -1.0;
        first = sp.tri_base + sp.tri_count;
        count = sp.lower_tri_count;
    }
    let p = disk_point(view * flip);
    var best_d = 3.4e38;
    var best = Blend(vec3<u32>(0u), vec3<f32>(1.0, 0.0, 0.0));
    var have_edge = false;
    for (var k = 0u; k < count; k++) {
        let t = dir_tris[first + k].xyz;
        let a = disk_point(frames[sp.dir_base + t.x].dir.xyz * flip);
        let b = disk_point(frames[sp.dir_base + t.y].dir.xyz * flip);
        let c = disk_point(frames[sp.dir_base + t.z].dir.xyz * flip);
        let den = cross2(b - a, c - a);
        if (abs(den) < 1e-12) { continue; }
        let wb = cross2(p - a, c - a) / den;
        let wc = cross2(b - a, p - a) / den;
        let wa = 1.0 - wb - wc;
        if (wa >= -1e-6 && wb >= -1e-6 && wc >= -1e-6) {
            let w = vec3<f32>(max(wa, 0.0), max(wb, 0.0), max(wc, 0.0));
            let s = w.x + w.y + w.z;
            return Blend(t, w / s);
        }
        let pts = array<vec2<f32>, 3>(a, b, c);
        for (var e = 0u; e < 3u; e++) {
            let q0 = pts[e];
            let q1 = pts[(e + 1u) % 3u];
            let ev = q1 - q0;
            let d = p - q0;
            let s = clamp((d.x * ev.x + d.y * ev.y) / (ev.x * ev.x + ev.y * ev.y), 0.0, 1.0);
            let r = q0 + ev * s - p;
            let dist = r.x * r.x + r.y * r.y;
            if (!have_edge || dist < best_d) {
                have_edge = true;
                best_d = dist;
                let i0 = t[e];
                let i1 = t[(e + 1u) % 3u];
                best = Blend(vec3<u32>(i0, i1, i0), vec3<f32>(1.0 - s, s, 0.0));
            }
        }
    }
    if (have_edge) { return best; }
    // No triangles: the nearest direction.
    var nearest = 0u;
    var best_c = -3.4e38;
    for (var i = 0u; i < sp.directions; i++) {
        let d = frames[sp.dir_base + i].dir.xyz;
        let c = d.x * view.x + d.y * view.y + d.z * view.z;
        if (c > best_c) { nearest = i; best_c = c; }
    }
    return Blend(vec3<u32>(nearest), vec3<f32>(1.0, 0.0, 0.0));
}

fn instance_in_order(i: u32) -> u32 {
    let idx = atomicLoad(&state.presort) * scene.instances + i;
    return textureLoad(presort, vec2<u32>(idx % PRESORT_TEX_WIDTH, idx / PRESORT_TEX_WIDTH), 0).x;
}

// Whether the instance's bounding sphere touches the frustum (and, in a light view, whether
// its shadow can reach the view's receivers).
fn visible(inst: Instance, sp: Species, id: u32) -> bool {
    let c = to_world(inst, sp.sphere.xyz);
    // Grown by the farthest the wind moves any of its points now.
    let r = sp.sphere.w * inst.scale
        + wind_reach_now(inst.position, wind_height(sp.sphere, inst.scale), id);
    for (var k = 0u; k < 6u; k++) {
        let pl = camera.planes[k];
        if (pl.x * c.x + pl.y * c.y + pl.z * c.z + pl.w < -r) { return false; }
    }
    return casts_into(c, r);
}

const SQRT3: f32 = 1.7320508;

// How near a tree of bounding radius `r` (world) centred at `c` is, as a class: seen at the
// depth of its nearest level-0 corner it spans S pixels across. FAR_CLASS: a far tree, with
// S < far span × ε (forward.w × eye.w) and S · sin θ < ε, θ the angle between the view
// (object space, `v`, unnormalised) and the nearest aspect's direction `nd` (unit): the
// parallax its one aspect makes is then within ε. Trees narrower than ε are always far. A far
// tree's level-0 quads are never refined, and it is drawn with its nearest aspect alone (its
// slabs composited into one quad, unless FLAG_FAR_SLABS). Otherwise the number of the
// sharpening reach's REACH_STEPS widths span · (1 + (R − 1) · i / REACH_STEPS), i = 1 …
// REACH_STEPS, that S is under (R the flags' reach; 0 when R is 1): see tree_sharpen. With
// FLAG_FAR_BLEND always 0. Mirrored by `tree_class` in reference.rs, operation for
// operation; no division, so that both round alike.
fn tree_class(c: vec3<f32>, r: f32, v: vec3<f32>, nd: vec3<f32>) -> u32 {
    if ((stream_flags(camera) & FLAG_FAR_BLEND) != 0u) { return 0u; }
    let m = camera.view_proj;
    // The nearest a level-0 quad's corner can be: the slab squares' corners lie within
    // √3 r of the centre. An orthographic view (a light's: no row of w depends on the point)
    // sees every point at its one scale.
    var w = m[3].w;
    if (m[0].w != 0.0 || m[1].w != 0.0 || m[2].w != 0.0) {
        w = m[0].w * c.x + m[1].w * c.y + m[2].w * c.z + m[3].w - SQRT3 * r;
    }
    if (w <= 0.0) { return 0u; }
    let fy = m[0].y * m[0].y + m[1].y * m[1].y + m[2].y * m[2].y;
    let half = camera.viewport.y * 0.5;
    let d = 2.0 * r * half;
    let e = camera.epsilon * w;
    let span = camera.far_span * e;
    let s2 = d * d * fy;
    let reach = f32((stream_flags(camera) >> REACH_SHIFT) & REACH_MASK);
    if (s2 < span * span) {
        // Narrower than the far span: far if its nearest aspect's parallax stays within ε
        // (sin²θ |v|² = |v|² − (nd · v)²); else narrower than every step's width.
        let vv = v.x * v.x + v.y * v.y + v.z * v.z;
        let cv = nd.x * v.x + nd.y * v.y + nd.z * v.z;
        if (s2 * (vv - cv * cv) < e * e * vv) { return FAR_CLASS; }
        return select(0u, REACH_STEPS, reach > 1.0);
    }
    // The step widths grow with i, so the tree is narrower than steps i0..REACH_STEPS: count
    // them from the widest down, stopping at the first it is not narrower than.
    var steps = 0u;
    if (reach > 1.0) {
        for (var i = REACH_STEPS; i >= 1u; i--) {
            let k = span * (1.0 + (reach - 1.0) * (f32(i) * REACH_STEP));
            if (!(s2 < k * k)) { break; }
            steps = steps + 1u;
        }
    }
    return steps;
}

// The aspect sharpening of a tree of class `near_class` (tree_class, not FAR_CLASS), in units of
// 1/WEIGHT_ONE: the flags' sharpening, raised towards SHARPEN_MAX by one REACH_STEPS-th of
// the way per step, so that a tree's faint aspects fade out as it narrows towards the far
// span, where it is drawn with its nearest aspect alone. Mirrors reference::tree_sharpen.
fn tree_sharpen(near_class: u32) -> u32 {
    let t = (stream_flags(camera) >> SHARPEN_SHIFT) & SHARPEN_MASK;
    if (t >= SHARPEN_MAX) { return t; }
    return t + (SHARPEN_MAX - t) * min(near_class, REACH_STEPS) / REACH_STEPS;
}

// A blend's weights rounded to units of 1/WEIGHT_ONE. Quantising first puts every later
// decision on integers, so a weight a rounding error away from zero cannot make the GPU and
// the CPU reference (reference::quantise, aspect_weights) disagree.
fn quantise(w: vec3<f32>) -> vec3<u32> {
    return vec3<u32>(unorm12(w.x), unorm12(w.y), unorm12(w.z));
}

// Blend weights from quantised ones `q`, summing to exactly WEIGHT_ONE: sharpened by `t`
// (tree_sharpen), the remainder given to the largest (first on ties); with FLAG_NEAREST or
// `nearest` the largest alone.
fn aspect_weights(quantised: vec3<u32>, nearest: bool, t: u32) -> vec3<u32> {
    var q = quantised;
    let big = largest(q);
    if (nearest || (stream_flags(camera) & FLAG_NEAREST) != 0u) {
        var one = vec3<u32>(0u);
        one[big] = WEIGHT_ONE;
        return one;
    }
    // Sharpening: each weight less t, the rest scaled back up (integers, as the CPU mirror;
    // the largest keeps at least one since t < WEIGHT_ONE / 3).
    if (t > 0u) {
        let s = vec3<u32>(max(q.x, t) - t, max(q.y, t) - t, max(q.z, t) - t);
        q = (s * WEIGHT_ONE) / (s.x + s.y + s.z);
    }
    let sum = q.x + q.y + q.z;
    q[big] = q[big] + WEIGHT_ONE - sum;
    return q;
}

// Index of the largest of quantised weights `q` (first on ties): the nearest aspect.
fn largest(q: vec3<u32>) -> u32 {
    var big = 0u;
    if (q.y > q[big]) { big = 1u; }
    if (q.z > q[big]) { big = 2u; }
    return big;
}

// Level-0 quads of one tree, in drawing order: slabs back to front (a far tree's slabs as one
// composited quad, unless FLAG_FAR_SLABS); within a slab the present aspects, each with its share
// [lo, hi) of the blend, cumulative over the aspects of non-zero weight (present or blank), which
// the draw pass turns into a dither interval or an "over" alpha (hi − lo) / hi. Puts them from
// `out` on (skipping indices below `skip`; plain quads after the `front` kept composited ones) when
// `emit` (`last`: see put_quad); returns the count, a composited quad counted as TREE_COMPOSITE.
// One composited quad in a tree's packed count (plain quads count 1).
const TREE_COMPOSITE: u32 = 65536u;

fn tree_quads(inst_id: u32, emit: bool, out: u32, skip: u32, front: u32, last: bool) -> u32 {
    let inst = instances[inst_id];
    let sp = species[inst.species];
    let centre = to_world(inst, sp.sphere.xyz);
    // Trees drawn as geometry alone (the hybrid method) have no quads.
    if (quad_share(camera.forms, distance(camera.form_eye.xyz, centre), sp.switch_unit * inst.scale,
                   inst_id) == 0u) {
        return 0u;
    }
    let eye_obj = to_object_dir(inst, camera.eye - centre);
    let bl = blend(sp, eye_obj);
    let q = quantise(bl.w);
    let nearest_dir = frames[sp.dir_base + bl.idx[largest(q)]].dir.xyz;
    let near_class = tree_class(centre, sp.sphere.w * inst.scale, eye_obj, nearest_dir);
    let far = near_class == FAR_CLASS;
    let w12 = aspect_weights(q, far, tree_sharpen(near_class));
    if (far && sp.slabs > 1u && (stream_flags(camera) & FLAG_FAR_SLABS) == 0u) {
        // One quad for all the slabs of the nearest aspect, on the front-most slab's root.
        var a = 0u;
        if (w12.y > 0u) { a = 1u; }
        if (w12.z > 0u) { a = 2u; }
        var root = NONE;
        for (var s = sp.slabs; s > 0u; s--) {
            let r = roots[sp.layer_base + bl.idx[a] * sp.slabs + s - 1u];
            if (r != NONE) { root = r; }
        }
        if (root == NONE) { return 0u; }
        if (emit && out >= skip) {
            // In both stream buffers: no refinement step moves it (refine.wgsl).
            let q = Quad(inst_id, root, COMPOSITE_POS, pack_dir(bl.idx[a], 0u, WEIGHT_ONE));
            quads_out[out - skip] = q;
            quads_in[out - skip] = q;
        }
        return TREE_COMPOSITE;
    }
    var n = 0u;
    for (var s = 0u; s < sp.slabs; s++) {
        let slab = sp.slabs - 1u - s;
        var acc = 0u;
        for (var a = 0u; a < 3u; a++) {
            let w = w12[a];
            if (w == 0u) { continue; }
            let lo = acc;
            acc = acc + w;
            let layer = sp.layer_base + bl.idx[a] * sp.slabs + slab;
            let root = roots[layer];
            if (root == NONE) { continue; }
            if (emit && out + n >= skip) {
                put_quad(front, out + n - skip - front,
                    Quad(inst_id, root, pack_pos(0u, 0u, 0u, slab), pack_dir(bl.idx[a], lo, acc)),
                    last);
            }
            n = n + 1u;
        }
    }
    return n;
}

// Clears the frame's counters and every block sum, and picks the presort direction.
@compute @workgroup_size(256)
fn frame_setup(@builtin(local_invocation_index) t: u32) {
    for (var i = t; i < arrayLength(&sums); i = i + WG) { atomicStore(&sums[i], 0u); }
    if (t != 0u) { return; }
    // Presort direction nearest the direction towards the viewer (first on ties).
    let towards = -camera.forward;
    var best = 0u;
    var best_c = -3.4e38;
    for (var k = 0u; k < scene.presort_dirs; k++) {
        let d = presort_dirs[k].xyz;
        let c = d.x * towards.x + d.y * towards.y + d.z * towards.z;
        if (c > best_c) { best = k; best_c = c; }
    }
    atomicStore(&state.presort, best);
    atomicStore(&state.n, 0u);
    atomicStore(&state.total, 0u);
    atomicStore(&state.pmin, NONE);
    atomicStore(&state.overflow_cull, 0u);
    atomicStore(&state.overflow_refine, 0u);
    atomicStore(&state.visible, 0u);
    atomicStore(&state.quads, 0u);
    atomicStore(&state.composites, 0u);
    for (var l = 0u; l < 16u; l++) { atomicStore(&state.per_level[l], 0u); }
}

// Level-0 quads of the i-th tree in presorted order, packed (0 past the end or outside the
// frustum).
fn tree_count(i: u32) -> u32 {
    if (i >= scene.instances) { return 0u; }
    let inst_id = instance_in_order(i);
    let inst = instances[inst_id];
    if (!visible(inst, species[inst.species], inst_id)) { return 0u; }
    atomicAdd(&state.visible, 1u);
    return tree_quads(inst_id, false, 0u, 0u, 0u, false);
}

// Blocks of trees: B.
fn tree_blocks() -> u32 { return (scene.instances + BLOCK - 1u) / BLOCK; }

// Each tree's packed quad count, and each block's plain and composited sums (two trees a
// thread, a block a workgroup).
@compute @workgroup_size(256)
fn cull_count(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    let i0 = wg.x * BLOCK + 2u * t;
    let a = tree_count(i0);
    let c = tree_count(i0 + 1u);
    if (i0 < scene.instances) { data[i0] = a; }
    if (i0 + 1u < scene.instances) { data[i0 + 1u] = c; }
    let excl = wg_exclusive(t, a + c);
    if (t == WG - 1u) {
        let sum = excl + a + c;
        atomicStore(&sums[wg.x], sum % TREE_COMPOSITE);
        atomicStore(&sums[tree_blocks() + wg.x], sum / TREE_COMPOSITE);
    }
}

// The scans of the block sums; the level-0 stream's length, C composited quads then P plain
// ones. When the level-0 quads exceed the capacity, the first `total − capacity` of the
// stream are dropped: the far trees' composited quads, then the farthest trees' plain ones,
// so the near trees stay.
@compute @workgroup_size(256)
fn cull_top(@builtin(local_invocation_index) t: u32) {
    let blocks = tree_blocks();
    let plain = scan_block_sums(t, 0u, blocks);
    let composites = scan_block_sums(t, blocks, blocks);
    if (t == 0u) {
        let total = plain + composites;
        let n = min(total, scene.capacity);
        atomicStore(&state.overflow_cull, total - n);
        atomicStore(&state.n, n);
        atomicStore(&state.composites, composites);
        atomicStore(&state.total, 0u);
        atomicStore(&state.pmin, NONE);
    }
}

// Each tree's first quad in the stream (before dropping): its composited quad's place in
// [0, C), or its plain quads' from C on. Clears the block's two sums.
@compute @workgroup_size(256)
fn cull_down(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    let i0 = wg.x * BLOCK + 2u * t;
    var v = vec2<u32>(0u);
    if (i0 < scene.instances) { v.x = data[i0]; }
    if (i0 + 1u < scene.instances) { v.y = data[i0 + 1u]; }
    let c_sum = tree_blocks() + wg.x;
    let base = vec2<u32>(atomicLoad(&state.composites) + atomicLoad(&sums[wg.x]),
                         atomicLoad(&sums[c_sum]));
    let excl = wg_exclusive(t, v.x + v.y);
    storageBarrier();
    if (t == 0u) {
        atomicStore(&sums[wg.x], 0u);
        atomicStore(&sums[c_sum], 0u);
    }
    let e = vec2<u32>(excl, excl + v.x);
    for (var k = 0u; k < 2u; k++) {
        let i = i0 + k;
        if (i >= scene.instances) { continue; }
        if (v[k] >= TREE_COMPOSITE) {
            data[i] = base.y + e[k] / TREE_COMPOSITE;
        } else {
            data[i] = base.x + e[k] % TREE_COMPOSITE;
        }
    }
}

var<workgroup> wg_first_plain: atomic<u32>;

fn cull_emit_body(wg: u32, t: u32, last: bool) {
    let skip = atomicLoad(&state.overflow_cull);
    let composites = atomicLoad(&state.composites);
    let first = wg * BLOCK;
    // The bins of block sums follow the workgroup's run of plain quads (composited ones
    // add nothing: they are never refined), which starts at its first tree that is not
    // composited.
    if (t == 0u) { atomicStore(&wg_first_plain, NONE); }
    workgroupBarrier();
    for (var k = 0u; k < 2u; k++) {
        let i = first + 2u * t + k;
        if (i < scene.instances && data[i] >= composites) {
            atomicMin(&wg_first_plain, data[i]);
        }
    }
    workgroupBarrier();
    let front = stream_front();
    emit_begin(t, max(atomicLoad(&wg_first_plain), skip + front) - skip - front);
    for (var k = 0u; k < 2u; k++) {
        let i = first + 2u * t + k;
        if (i >= scene.instances) { continue; }
        let inst_id = instance_in_order(i);
        let inst = instances[inst_id];
        if (visible(inst, species[inst.species], inst_id)) {
            _ = tree_quads(inst_id, true, data[i], skip, front, last);
        }
    }
    emit_end(t);
}

// Each visible tree's quads at its offset (two trees a thread); each with its refinement
// wish for the first refine step.
@compute @workgroup_size(256)
fn cull_emit(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    cull_emit_body(wg.x, t, false);
}

// Without refinement: each visible tree's quads, their levels counted.
@compute @workgroup_size(256)
fn cull_emit_last(@builtin(workgroup_id) wg: vec3<u32>,
                  @builtin(local_invocation_index) t: u32) {
    cull_emit_body(wg.x, t, true);
}
