// The sun's shadow lookup (group 2): the cascades' maps, one layer each, written by the light
// views' casting pass (cast.wgsl) and described by the camera uniform (forest_render::shadow).

#import common

@group(2) @binding(0) var shadow_map: texture_depth_2d_array;
// Compares with less-equal and filters bilinearly: each tap is a 2×2 PCF.
@group(2) @binding(1) var shadow_sampler: sampler_comparison;

// The fraction of the sun that reaches `world` past the casters, from the cascade whose slice
// of the view holds it (1 beyond the last). The point is moved camera.shadow_offset texels
// towards the sun and along `normal` (unit, or zero for points without one) before the
// lookup: the bias that keeps a receiver from shadowing itself. Four bilinear compare taps
// half a texel apart: a 3×3-texel tent.
fn sun_shadow(world: vec3<f32>, normal: vec3<f32>) -> f32 {
    let n = u32(camera.shadow_cascades);
    if (n == 0u) { return 1.0; }
    let depth = dot(world - camera.eye, camera.forward);
    var k = 0u;
    loop {
        if (k >= n || depth <= camera.shadow_splits[k]) { break; }
        k = k + 1u;
    }
    if (k >= n) { return 1.0; }
    let texel = camera.shadow_texel[k];
    let p = world + (camera.sun + normal) * (camera.shadow_offset * texel);
    let c = camera.shadow[k] * vec4<f32>(p, 1.0);
    let uv = vec2<f32>(0.5 + 0.5 * c.x, 0.5 - 0.5 * c.y);
    // Reverse-Z maps (a host's, shadow_params.w = 1) keep the nearest caster's greatest depth.
    let reverse = camera.shadow_reverse_z != 0.0;
    // Outside the map, or nearer the sun than its box: nothing casts there.
    let beyond = select(c.z <= 0.0, c.z >= 1.0, reverse);
    if (any(uv < vec2<f32>(0.0)) || any(uv > vec2<f32>(1.0)) || beyond) { return 1.0; }
    let z = clamp(select(c.z - camera.shadow_bias[k], c.z + camera.shadow_bias[k], reverse),
                  0.0, 1.0);
    let d = 0.5 / camera.shadow_side;
    var lit = textureSampleCompareLevel(shadow_map, shadow_sampler, uv + vec2<f32>(-d, -d), k, z);
    lit = lit + textureSampleCompareLevel(shadow_map, shadow_sampler, uv + vec2<f32>(d, -d), k, z);
    lit = lit + textureSampleCompareLevel(shadow_map, shadow_sampler, uv + vec2<f32>(-d, d), k, z);
    lit = lit + textureSampleCompareLevel(shadow_map, shadow_sampler, uv + vec2<f32>(d, d), k, z);
    return lit * 0.25;
}

// The sun's visibility past other casters for a point `p` of a tree whose bounding sphere is
// `tree` (world centre, radius): looked up where the ray towards the sun leaves the sphere.
// The tree's own crown, whose shadow the opacity march already gives, is then never counted
// twice, and its quads cannot shadow themselves (no acne on their planes). What it misses: a
// neighbour's leaves inside this tree's sphere.
fn tree_shadow(p: vec3<f32>, tree: vec4<f32>) -> f32 {
    if (camera.shadow_cascades == 0.0) { return 1.0; }
    let l = camera.sun;
    let o = p - tree.xyz;
    let b = dot(o, l);
    let c = dot(o, o) - tree.w * tree.w;
    let t = max(-b + sqrt(max(b * b - c, 0.0)), 0.0);
    return sun_shadow(p + l * t, vec3<f32>(0.0));
}
