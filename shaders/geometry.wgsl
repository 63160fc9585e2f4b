// Full geometry, the ground truth and brute-force baseline: every visible tree's triangles,
// instanced, frustum-culled on the GPU, alpha-tested, shaded with the project's one shading
// model (forest_format::shading) in the tree's object space — the bake's lighting rotates with
// the tree, so the reference must too — with per-vertex sun visibility traced by the bake's
// ray tracer. Appended after common.wgsl and geometry_types.wgsl.

struct GeoSpecies {
    sphere: vec4<f32>,
    first_vertex: u32,
    vertex_count: u32,
    seg_base: u32,
    pad: u32,
}

@group(0) @binding(0) var<uniform> camera: Camera;
@group(0) @binding(1) var<storage, read> instances: array<Instance>;
@group(0) @binding(2) var<storage, read> geo_species: array<GeoSpecies>;
@group(0) @binding(3) var<storage, read_write> visible_list: array<u32>;
@group(0) @binding(4) var<storage, read_write> counts: array<atomic<u32>>;
@group(0) @binding(5) var<storage, read_write> draw_args: array<vec4<u32>>;
@group(0) @binding(6) var<uniform> geo_consts: vec4<u32>; // x: instances, y: species

@compute @workgroup_size(64)
fn geo_reset(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x < geo_consts.y) { atomicStore(&counts[gid.x], 0u); }
}

@compute @workgroup_size(256)
fn geo_cull(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= geo_consts.x) { return; }
    let inst = instances[i];
    let sp = geo_species[inst.species];
    let c = to_world(inst, sp.sphere.xyz);
    let r = sp.sphere.w * inst.scale;
    for (var k = 0u; k < 6u; k++) {
        let pl = camera.planes[k];
        if (pl.x * c.x + pl.y * c.y + pl.z * c.z + pl.w < -r) { return; }
    }
    let slot = atomicAdd(&counts[inst.species], 1u);
    visible_list[sp.seg_base + slot] = i;
}

// Draw arguments per species: vertex count, visible instances, first vertex, first instance
// (the species' segment of the visible list).
@compute @workgroup_size(64)
fn geo_args(@builtin(global_invocation_id) gid: vec3<u32>) {
    let s = gid.x;
    if (s >= geo_consts.y) { return; }
    let sp = geo_species[s];
    draw_args[s] = vec4<u32>(sp.vertex_count, atomicLoad(&counts[s]), sp.first_vertex, sp.seg_base);
}
