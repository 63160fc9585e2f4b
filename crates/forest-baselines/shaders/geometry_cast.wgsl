// The light views' casting pass of the geometry-based methods (it imports the draw module):
// a light view's listed trees, culled by the cascade's box with their forms and levels of
// detail chosen from the view's eye (camera.form_eye), as depth only into the cascade's layer.
// Alpha-tested leaves and billboards are kept where the draw keeps them; in the hybrid's
// transition band each texel belongs to the form that owns it (not_drawn_here), so the two
// forms never both cast, and in a crossfade between mesh LODs to one of them. No march
// towards the sun: nothing is shaded.

#import geometry_draw

@vertex
fn vs_geo_cast(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> GeoOut {
    return geo_vertex(vi, ii, false);
}

@fragment
fn fs_geo_cast(in: GeoOut) {
    if (not_drawn_here(in.clip.xy, in.form)) { discard; }
    let m = materials[in.material];
    if (m.layer != NONE && m.alpha_tested != 0u) {
        let t = textureSampleBias(textures, tex_sampler, vec2<f32>(in.uv.x, 1.0 - in.uv.y),
                                  m.layer, method.texture_bias);
        if (t.a < 0.5) { discard; }
    }
}

@fragment
fn fs_billboard_cast(in: BillboardOut) {
    if (not_drawn_here(in.clip.xy, in.form)) { discard; }
    if (textureSample(billboards, tex_sampler, in.uv, in.layer).a < 0.5) { discard; }
}
