// Order-preserving exclusive prefix sum in two levels, its phases fused into the passes'
// own dispatches (see cull.wgsl and refine.wgsl):
//   1. the producer of the values also gives each block of BLOCK = 512 values its sum in
//      `sums` (cull_count writes it; the emitters add each value with `add_to_block`);
//   2. one workgroup scans the block sums in place (`scan_block_sums`), serially in chunks
//      of 512 with a running carry, so any number of blocks fits;
//   3. each block scans its own values and adds its block's offset (`block_prefix`; the
//      cull's packed two-list version is cull_down's own), and clears its block sum for the
//      next scan.
// Integer sums in a fixed order: the same values give the same prefixes on any GPU, and the
// CPU reference (reference.rs) computes the same. Between scans every block sum is zero
// (frame_setup clears them all; each block clears its own after reading it).

#import bindings

var<workgroup> wg_sum: array<u32, 256>;
var<workgroup> wg_uniform: u32;

// Inclusive scan of one value per thread across the workgroup; returns the exclusive prefix
// and leaves the workgroup total in wg_sum[255].
fn wg_exclusive(t: u32, v: u32) -> u32 {
    wg_sum[t] = v;
    workgroupBarrier();
    for (var off = 1u; off < WG; off = off * 2u) {
        var x = 0u;
        if (t >= off) { x = wg_sum[t - off]; }
        workgroupBarrier();
        wg_sum[t] = wg_sum[t] + x;
        workgroupBarrier();
    }
    return wg_sum[t] - v;
}

// A value thread 0 knows, made uniform across the workgroup (the loops below depend on it).
fn share(t: u32, v: u32) -> u32 {
    if (t == 0u) { wg_uniform = v; }
    return workgroupUniformLoad(&wg_uniform);
}

// Exclusive scan of sums[first..first + blocks) in place by one workgroup; returns the total.
fn scan_block_sums(t: u32, first: u32, blocks_of_thread0: u32) -> u32 {
    let blocks = share(t, blocks_of_thread0);
    var carry = 0u;
    for (var c = 0u; c < blocks; c = c + BLOCK) {
        let i0 = c + 2u * t;
        var a = 0u;
        var b = 0u;
        if (i0 < blocks) { a = atomicLoad(&sums[first + i0]); }
        if (i0 + 1u < blocks) { b = atomicLoad(&sums[first + i0 + 1u]); }
        let excl = wg_exclusive(t, a + b);
        let chunk = wg_sum[WG - 1u];
        if (i0 < blocks) { atomicStore(&sums[first + i0], carry + excl); }
        if (i0 + 1u < blocks) { atomicStore(&sums[first + i0 + 1u], carry + excl + a); }
        carry = carry + chunk;
        workgroupBarrier();
    }
    return carry;
}

// Exclusive prefixes of a block's values, thread t holding values 2t and 2t + 1: the block's
// offset (scanned by scan_block_sums) plus the sum of the values before. Clears the block's
// sum for the next scan.
fn block_prefix(b: u32, t: u32, v0: u32, v1: u32) -> vec2<u32> {
    let base = atomicLoad(&sums[b]);
    let excl = wg_exclusive(t, v0 + v1);
    storageBarrier();
    if (t == 0u) { atomicStore(&sums[b], 0u); }
    return vec2<u32>(base + excl, base + excl + v0);
}

// Per-workgroup bins of block sums: an emitting workgroup writes a contiguous run of the
// output, which spans a few blocks from `first_block` on; values go to the bins and one
// atomic per bin reaches `sums` (a value beyond the bins goes there directly).
const BINS: u32 = 16u;
var<workgroup> wg_bins: array<atomic<u32>, 16>;
var<workgroup> wg_first_block: u32;

fn add_to_block(out: u32, v: u32) {
    if (v == 0u) { return; }
    let b = out / BLOCK;
    let k = b - wg_first_block;
    if (b >= wg_first_block && k < BINS) {
        atomicAdd(&wg_bins[k], v);
    } else {
        atomicAdd(&sums[b], v);
    }
}
