// The ground: a square at y = 0 around the eye, lit by the shared shading model (constant
// colour), drawn first with depth writes. Appended to draw.wgsl and geometry_draw.wgsl, which
// declare `camera` at binding 0.

struct Ground {
    // xyz: lit colour (linear); w: half side of the square in metres.
    colour: vec4<f32>,
}

@group(0) @binding(8) var<uniform> ground: Ground;

struct GroundOut {
    @builtin(position) clip: vec4<f32>,
}

@vertex
fn vs_ground(@builtin(vertex_index) vi: u32) -> GroundOut {
    let s = ground.colour.w;
    let x = select(-s, s, (vi & 1u) == 1u) + camera.eye.x;
    let z = select(-s, s, (vi >> 1u) == 1u) + camera.eye.z;
    var out: GroundOut;
    out.clip = camera.view_proj * vec4<f32>(x, 0.0, z, 1.0);
    return out;
}

@fragment
fn fs_ground() -> @location(0) vec4<f32> {
    return vec4<f32>(ground.colour.xyz, 1.0);
}
