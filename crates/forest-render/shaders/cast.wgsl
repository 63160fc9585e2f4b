// The light views' casting pass (appended to the draw module): a light-view stream's plain
// quads (its camera asks for no composited far trees) as depth only into one cascade's layer
// of the shadow map. Each quad lies on its plane, as in the draw. A fragment is kept where the
// slab image's coverage exceeds an ordered-dither threshold (a screen door: a texel of
// coverage a casts in a share a of the map's texels, which the receivers' filter averages
// back into a shadow of strength a), and a tree's aspects split the texels by the ordered
// dither the draw uses, so a tree casts the weighted mean of its aspects' coverages. A fixed
// threshold of ½ was measured to drop a sparse crown's top: the test pine's shadow fell 1.1 m
// short of its silhouette's. No opacity march: nothing is shaded.

struct CastOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) layer: u32,
    // Share [lo, hi) of the blend (x, y) and the instance (z).
    @location(2) @interpolate(flat) share: vec3<u32>,
}

@vertex
fn vs_cast(@builtin(vertex_index) vi: u32, @builtin(instance_index) qi: u32) -> CastOut {
    let v = quad_vertex(vi, kept_composites(state.composites, state.overflow_cull) + qi, false);
    return CastOut(v.clip, v.uv, v.ids.x, v.share.xyz);
}

@fragment
fn fs_cast(in: CastOut) {
    let a = textureSample(colour, colour_sampler, in.uv, in.layer).a;
    let u = dither_threshold(in.clip.xy, in.share.z);
    // The coverage's door: its own matrix (transposed, salted) so that it does not follow
    // the aspects' split.
    let door = (f32(dither_threshold(in.clip.yx, in.share.z ^ 0x27d4eb2du)) + 0.5)
        / f32(WEIGHT_ONE);
    if (a <= door || u < in.share.x || u >= in.share.y) { discard; }
}
