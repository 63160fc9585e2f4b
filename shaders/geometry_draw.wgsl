// Drawing of the full geometry (see geometry.wgsl). Appended after common.wgsl and
// geometry_types.wgsl; ground.wgsl follows.

@group(0) @binding(0) var<uniform> camera: Camera;
@group(0) @binding(1) var<storage, read> instances: array<Instance>;
@group(0) @binding(2) var<storage, read> vertices: array<GeoVertex>;
@group(0) @binding(3) var<storage, read> visible_list: array<u32>;
@group(0) @binding(4) var<storage, read> materials: array<GeoMaterial>;
@group(0) @binding(5) var textures: texture_2d_array<f32>;
@group(0) @binding(6) var tex_sampler: sampler;
@group(0) @binding(7) var<uniform> light: Light;

struct GeoOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) to_eye: vec3<f32>,
    @location(3) sun_visibility: f32,
    @location(4) @interpolate(flat) material: u32,
}

@vertex
fn vs_geo(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> GeoOut {
    let inst = instances[visible_list[ii]];
    let v = vertices[vi];
    let w = to_world(inst, v.pos);
    var out: GeoOut;
    out.clip = camera.view_proj * vec4<f32>(w, 1.0);
    out.uv = v.uv;
    out.normal = v.normal;
    out.to_eye = to_object_dir(inst, camera.eye.xyz - w);
    out.sun_visibility = v.sun_visibility;
    out.material = v.material;
    return out;
}

@fragment
fn fs_geo(in: GeoOut) -> @location(0) vec4<f32> {
    let m = materials[in.material];
    var albedo = m.kd.rgb;
    if (m.layer != NONE) {
        // OBJ texture coordinates: v = 0 is the bottom row.
        let t = textureSample(textures, tex_sampler, vec2<f32>(in.uv.x, 1.0 - in.uv.y), m.layer);
        if (m.alpha_tested != 0u && t.a < 0.5) { discard; }
        albedo = albedo * t.rgb;
    }
    var n = normalize(in.normal);
    if (dot(n, in.to_eye) < 0.0) { n = -n; }
    let ndl = dot(n, light.sun_dir.xyz);
    let direct = max(ndl, 0.0) + m.kd.a * max(-ndl, 0.0);
    let hemi = 0.5 + 0.5 * n.y;
    let ambient = light.sky.rgb * hemi + light.ground.rgb * (1.0 - hemi);
    return vec4<f32>(albedo * (ambient + light.sun.rgb * (in.sun_visibility * direct)), 1.0);
}
