// The sun's shadow lookup of a module drawn without shadow maps bound: every point is lit.
// Modules that shade the ground or trees import the `shadow` slot: this or shadow_on.wgsl.
fn sun_shadow(world: vec3<f32>, normal: vec3<f32>) -> f32 {
    return 1.0;
}

fn tree_shadow(p: vec3<f32>, tree: vec4<f32>) -> f32 {
    return 1.0;
}
