// The light views' casting pass (appended to the draw module): a light-view stream's plain
// quads (its camera asks for no composited far trees) as depth only into one cascade's layer
// of the shadow map. Each quad lies on its plane, as in the draw. A fragment is kept where the
// slab image's coverage exceeds an ordered-dither threshold (a screen door: a texel of
// coverage a casts in a share a of the map's texels, which the receivers' filter averages
// back into a shadow of strength a), and a tree's aspects combine as the draw combines them:
// split by its dither, or "over" each other (see fs_cast). A fixed
// threshold of ½ was measured to drop a sparse crown's top: the test pine's shadow fell 1.1 m
// short of its silhouette's. No opacity march: nothing is shaded.

struct CastOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) layer: u32,
    // Share [lo, hi) of the blend (x, y), the instance (z) and the tree's quad share (w, see
    // quad_share: in the hybrid's transition band the geometry casts the other texels).
    @location(2) @interpolate(flat) share: vec4<u32>,
}

@vertex
fn vs_cast(@builtin(vertex_index) vi: u32, @builtin(instance_index) qi: u32) -> CastOut {
    let v = quad_vertex(vi, kept_composites(state.composites, state.overflow_cull) + qi, false);
    return CastOut(v.clip, v.uv, v.ids.x, v.share);
}

@fragment
fn fs_cast(in: CastOut) {
    let a = textureSample(colour, colour_sampler, in.uv, in.layer).a;
    if (in.share.w < WEIGHT_ONE && form_threshold(in.clip.xy, in.share.z) >= in.share.w) {
        discard;
    }
    if ((stream_flags(camera) & FLAG_DITHER) != 0u) {
        // The draw's dither: each texel shows one aspect, and the coverage's door has its own
        // matrix (transposed, salted) so that it does not follow the aspects' split.
        let u = dither_threshold(in.clip.xy, in.share.z);
        let door = (f32(dither_threshold(in.clip.yx, in.share.z ^ 0x27d4eb2du)) + 0.5)
            / f32(WEIGHT_ONE);
        if (a <= door || u < in.share.x || u >= in.share.y) { discard; }
    } else {
        // The draw's "over": each aspect covers a share (hi − lo) / hi of what its image
        // covers, over the earlier ones. A door of its own per layer (salted by it) makes the
        // layers' texels independent, so the union casts 1 − Π(1 − a·alpha), the coverage
        // the draw composites.
        let alpha = select(0.0, f32(in.share.y - in.share.x) / f32(in.share.y), in.share.y > 0u);
        let salt = in.share.z ^ (in.layer * 0x9e3779b9u) ^ 0x27d4eb2du;
        let door = (f32(dither_threshold(in.clip.yx, salt)) + 0.5) / f32(WEIGHT_ONE);
        if (a * alpha <= door) { discard; }
    }
}
