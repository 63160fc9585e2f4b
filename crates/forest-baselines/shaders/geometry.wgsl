// Culling of the geometry-based methods: every instance is frustum-tested and given a draw
// segment (distance band × species, see method_band); a count, one serial pass of offsets and
// indirect arguments, and a scatter build the visible list segment by segment, nearest band
// first. In the hybrid method (camera.forms) trees drawn as quads alone get no segment, and
// a species with mesh-LOD bands lists each near tree once per mesh LOD that draws some of its
// pixels (tree_keys): once, or twice or three times in a crossfade.

#import common
#import geometry_types
#import wind

@group(0) @binding(0) var<uniform> camera: Camera;
@group(0) @binding(1) var<storage, read> instances: array<Instance>;
@group(0) @binding(2) var<storage, read> geo_species: array<GeoSpecies>;
@group(0) @binding(3) var<storage, read_write> keys: array<u32>;
@group(0) @binding(4) var<storage, read_write> counts: array<atomic<u32>>;
@group(0) @binding(5) var<storage, read_write> cursor: array<atomic<u32>>;
@group(0) @binding(6) var<storage, read_write> visible_list: array<u32>;
@group(0) @binding(7) var<storage, read_write> draw_args: array<vec4<u32>>;
@group(0) @binding(8) var<uniform> geo_consts: vec4<u32>; // x: instances, y: species
@group(0) @binding(9) var<uniform> method: Method;
@group(0) @binding(10) var<storage, read> leaf_end: array<u32>;

@compute @workgroup_size(64)
fn geo_reset(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x < BANDS * geo_consts.y) { atomicStore(&counts[gid.x], 0u); }
}

@compute @workgroup_size(256)
fn geo_classify(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= geo_consts.x) { return; }
    let inst = instances[i];
    let sp = geo_species[inst.species];
    let c = to_world(inst, sp.sphere.xyz);
    // Grown by the farthest the wind moves any of its points now.
    let r = sp.sphere.w * inst.scale
        + wind_reach_now(inst.position, wind_height(sp.sphere, inst.scale), i);
    for (var k = 0u; k < 6u; k++) {
        let pl = camera.planes[k];
        if (pl.x * c.x + pl.y * c.y + pl.z * c.z + pl.w < -r) {
            keys[i] = NONE;
            return;
        }
    }
    // In a light view, trees whose shadow cannot reach the view's receivers.
    if (!casts_into(c, r)) {
        keys[i] = NONE;
        return;
    }
    // Trees drawn as quads alone (the hybrid method) are not drawn here.
    if (quad_share(camera.forms, distance(camera.form_eye.xyz, c), sp.switch_unit * inst.scale, i)
        == WEIGHT_ONE) {
        keys[i] = NONE;
        return;
    }
    let k = tree_keys(i, inst, sp, c);
    keys[i] = k.x;
    for (var j = 0u; j < 3u; j++) {
        if (k[j] != NONE) { atomicAdd(&counts[k[j]], 1u); }
    }
}

// The segments (band · species + species) listing tree `i`, centred at `c`, which the cull
// keeps: one, the first; under the hybrid's mesh-LOD bands one per LOD whose share range is
// not empty (lod_shares), in LOD order, NONE for the others. The first is never NONE.
fn tree_keys(i: u32, inst: Instance, sp: GeoSpecies, c: vec3<f32>) -> vec3<u32> {
    let dw = distance(camera.form_eye.xyz, c);
    let d = dw / inst.scale;
    let species = geo_consts.y;
    if (!lod_bands_on(method, camera.forms, sp)) {
        return vec3<u32>(method_band(method, d) * species + inst.species, NONE, NONE);
    }
    let unit = sp.switch_unit * inst.scale;
    let shares = lod_shares(method, camera.forms, sp, dw, unit, i);
    let s = (camera.forms.x + camera.forms.y * unit) / inst.scale;
    var keys = vec3<u32>(NONE);
    var n = 0u;
    for (var k = 0u; k < 3u; k++) {
        let r = lod_range(k, shares);
        if (r.x < r.y) {
            keys[n] = lod_band(k, d, s, sp) * species + inst.species;
            n += 1u;
        }
    }
    return keys;
}

// One invocation: segment offsets in draw order and the indirect arguments of every segment
// (vertex count, instances, first vertex, first instance). Billboard segments draw 6 vertices.
@compute @workgroup_size(1)
fn geo_args() {
    var offset = 0u;
    let species = geo_consts.y;
    for (var seg = 0u; seg < BANDS * species; seg++) {
        let band = seg / species;
        let sp = geo_species[seg % species];
        var count = sp.lod_count.x;
        var first = sp.lod_first.x;
        if (lod_bands_on(method, camera.forms, sp)) {
            let lod = band_lod(band);
            count = sp.lod_count[lod];
            first = sp.lod_first[lod];
        } else if (method.mode == 1u) {
            let k = band_elements(band, sp.leaves, method.fade);
            count = sp.branch_vertices;
            if (k > 0u) { count = leaf_end[sp.leaf_base + k - 1u]; }
        } else if (method.mode == 2u) {
            let lod = band / 4u;
            if (lod == 3u) {
                count = 6u;
                first = 0u;
            } else {
                count = sp.lod_count[lod];
                first = sp.lod_first[lod];
            }
        }
        let n = atomicLoad(&counts[seg]);
        draw_args[seg] = vec4<u32>(count, n, first, offset);
        atomicStore(&cursor[seg], offset);
        offset += n;
    }
}

@compute @workgroup_size(256)
fn geo_scatter(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= geo_consts.x) { return; }
    let key = keys[i];
    if (key == NONE) { return; }
    // The order bin its triangles are drawn in (geometry_draw.wgsl's draw_vertex), once per
    // tree here rather than per vertex there.
    let inst = instances[i];
    let sp = geo_species[inst.species];
    let centre = to_world(inst, sp.sphere.xyz);
    let bin = order_bin(to_object_dir(inst, centre - camera.eye));
    let entry = i | (bin << VISIBLE_ID_BITS);
    visible_list[atomicAdd(&cursor[key], 1u)] = entry;
    // A tree in a crossfade between mesh LODs: its other LODs' segments.
    if (lod_bands_on(method, camera.forms, sp)) {
        let k = tree_keys(i, inst, sp, centre);
        for (var j = 1u; j < 3u; j++) {
            if (k[j] != NONE) { visible_list[atomicAdd(&cursor[k[j]], 1u)] = entry; }
        }
    }
}
