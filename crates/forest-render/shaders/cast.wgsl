// The light views' casting pass (it imports the draw module): a light-view stream's quads as
// depth only into one cascade's layer of the shadow map: far trees' composited quads
// (vs_cast_composite, fs_cast_composite), then the plain ones (vs_cast, fs_cast). Each quad lies on
// its plane, as in the draw. A fragment is kept where the slab image's coverage exceeds an
// ordered-dither threshold (a screen door: a texel of coverage a casts in a share a of the map's
// texels, which the receivers' filter averages back into a shadow of strength a), and a tree's
// aspects combine as the draw combines them: split by its dither, or "over" each other (see
// fs_cast). A fixed threshold of ½ was measured to drop a sparse crown's top: the test pine's
// shadow fell 1.1 m short of its silhouette's. No opacity march: nothing is shaded.

#import draw

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

// A far tree's composited quad: its slabs' coverage "over" each other along the light's
// parallax (as fs_composite composites them), through the same coverage door.
@vertex
fn vs_cast_composite(@builtin(vertex_index) vi: u32, @builtin(instance_index) qi: u32)
    -> CompositeOut {
    let v = quad_vertex(vi, qi, false);
    return CompositeOut(v.clip, v.uv, v.ids, v.alpha, v.share, v.world, v.frame_right,
                        v.frame_up, v.parallax, v.depths, v.obj_front, v.obj_back,
                        vec3<u32>(v.species, v.tint), v.sphere, v.sun_obj, v.tree);
}

@fragment
fn fs_cast_composite(in: CompositeOut) {
    var a = 0.0;
    for (var k = 0u; k < in.ids.w; k++) {
        let uv = slab_uv(in, k);
        let b = textureSampleLevel(colour, colour_sampler, uv, in.ids.x + k, in.depths.w).a;
        a = a + b * inside_image(uv) * (1.0 - a);
    }
    if (in.share.w < WEIGHT_ONE && form_threshold(in.clip.xy, in.share.z) >= in.share.w) {
        discard;
    }
    let door = (f32(dither_threshold(in.clip.yx, in.share.z ^ 0x27d4eb2du)) + 0.5)
        / f32(WEIGHT_ONE);
    if (a <= door) { discard; }
}
