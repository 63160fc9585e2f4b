// Order-preserving exclusive prefix sum of data[0..n], n = state.n, in three levels of blocks
// of 512 (so n < 512^3): reduce0 (block sums of data -> sums[0..b1]), reduce1 (block sums of
// those -> sums[S2..]), top (one workgroup scans the top level and writes state.total),
// down1, down0 (each block scans itself and adds its block's offset). Deterministic: the
// same n values give the same sums on any GPU, and the CPU reference computes the same.


var<workgroup> wg_sum: array<u32, 256>;

fn level1_count() -> u32 { return (atomicLoad(&state.n) + BLOCK - 1u) / BLOCK; }
fn level2_count() -> u32 { return (level1_count() + BLOCK - 1u) / BLOCK; }
// Level-2 sums start after the level-1 sums' capacity, kept in the last element's place.
fn l2_base() -> u32 { return arrayLength(&sums) - 512u; }

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

fn load_level(level: u32, i: u32, n: u32) -> u32 {
    if (i >= n) { return 0u; }
    if (level == 0u) { return data[i]; }
    if (level == 1u) { return sums[i]; }
    return sums[l2_base() + i];
}

fn store_level(level: u32, i: u32, n: u32, v: u32) {
    if (i >= n) { return; }
    if (level == 0u) { data[i] = v; } else if (level == 1u) { sums[i] = v; } else { sums[l2_base() + i] = v; }
}

fn count_of(level: u32) -> u32 {
    if (level == 0u) { return atomicLoad(&state.n); }
    if (level == 1u) { return level1_count(); }
    return level2_count();
}

// Sum of block `b` of `level` into the next level.
fn reduce(level: u32, b: u32, t: u32) {
    let n = count_of(level);
    let a = load_level(level, b * BLOCK + 2u * t, n);
    let c = load_level(level, b * BLOCK + 2u * t + 1u, n);
    let excl = wg_exclusive(t, a + c);
    if (t == WG - 1u) {
        store_level(level + 1u, b, count_of(level + 1u), excl + a + c);
    }
}

// Exclusive scan of block `b` of `level`, plus `base`.
fn down(level: u32, b: u32, t: u32, base: u32) -> u32 {
    let n = count_of(level);
    let i0 = b * BLOCK + 2u * t;
    let a = load_level(level, i0, n);
    let c = load_level(level, i0 + 1u, n);
    let excl = wg_exclusive(t, a + c);
    store_level(level, i0, n, base + excl);
    store_level(level, i0 + 1u, n, base + excl + a);
    return excl + a + c;
}

@compute @workgroup_size(256)
fn scan_reduce0(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    reduce(0u, wg.x, t);
}

@compute @workgroup_size(256)
fn scan_reduce1(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    reduce(1u, wg.x, t);
}

@compute @workgroup_size(256)
fn scan_top(@builtin(local_invocation_index) t: u32) {
    let total = down(2u, 0u, t, 0u);
    if (t == WG - 1u) {
        atomicStore(&state.total, total);
    }
}

@compute @workgroup_size(256)
fn scan_down1(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    let base = load_level(2u, wg.x, level2_count());
    workgroupBarrier();
    _ = down(1u, wg.x, t, base);
}

@compute @workgroup_size(256)
fn scan_down0(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) t: u32) {
    let base = load_level(1u, wg.x, level1_count());
    workgroupBarrier();
    _ = down(0u, wg.x, t, base);
}
