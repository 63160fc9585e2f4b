// Pass 3, draw: the environment (environment.wgsl), then every quad of the final stream becomes 4
// vertices (a triangle strip, one instance per quad, drawn indirectly): its image-space rectangle
// at its 4 corner depths in the sampling frame of its direction and slab (object space), then the
// instance transform. Each vertex marches the tree's opacity volume towards the sun (opacity_march,
// from the corner's Gauss point, at the mip level that suits the quad's size: quad_march): the
// crown's self-shadowing under the frame's sun; a composited quad, which spans a whole far
// tree, marches per fragment from where its coverage lies, through the volume's coarse mip
// level in fewer steps (sun_transmittance_coarse).
// Textured from the colour array (premultiplied albedo, sRGB-decoded by the format) and the
// surface array (premultiplied normal code, sky visibility, translucency), lit by the frame's
// light in world space (shade_light in common.wgsl), and blended colour = src + dst·(1 − src.a). A
// tree's 1–3 aspects combine by an ordered dither (each pixel shows the aspect whose share [lo, hi)
// of the blend holds the pixel's threshold, so coverage is the weighted mean of the aspects'
// coverages) or, without FLAG_DITHER, "over" each other with alpha (hi − lo) / hi.
//
// Finest-level quads magnified past CRACK_PIXELS reach a little past their rectangles (see
// crack_margin), so that neighbours at different depths overlap rather than crack apart.
//
// A finest-level quad is drawn on its plane even where its depth error projects longer than ε:
// the bake keeps every node's corners within one depth cluster of its pixels, so no quad is
// stretched across a gap, and flattening such quads to their mean depth was measured to lose
// accuracy (close-up FLIP 0.190 against 0.185 on its plane).
//
// Depth: the quads are drawn strictly back to front (presorted trees, back slab first), so
// ordering comes from the stream and blending needs no depth writes; writing depth would make
// semi-transparent quads hide what is drawn after them behind their transparent parts. The
// quads are still depth-tested against the opaque ground drawn first, so trees are hidden by
// hills and the ground hides the parts of slabs below it. The opaque pass (vs_quad_opaque,
// StreamOptions::opaque_first), before every blended quad, writes depth only where a fragment
// is opaque, and a slab's thickness behind it: what lies further behind would have been
// covered by it, and what lies nearer (the tree's other aspects, which blend over it, and the
// fragment itself, drawn again) is drawn as without the pass.

#import common
#import ground
#import environment
#import shadow
#import count
#import wind
#import tint

@group(0) @binding(0) var<uniform> camera: Camera;
@group(0) @binding(1) var<storage, read> instances: array<Instance>;
@group(0) @binding(2) var<storage, read> species: array<Species>;
@group(0) @binding(3) var<storage, read> frames: array<Frame>;
@group(0) @binding(4) var<storage, read> quads: array<Quad>;
@group(0) @binding(5) var nodes: texture_2d<u32>;
@group(0) @binding(6) var colour: texture_2d_array<f32>;
@group(0) @binding(7) var colour_sampler: sampler;
// Root node of every layer (NONE when blank): a composited quad's slabs.
@group(0) @binding(9) var<storage, read> roots: array<u32>;
// The frame's counters: where the plain quads start in the stream.
@group(0) @binding(10) var<storage, read> state: State;
// Surface attributes, the colour array's layout (see forest_format::atlas).
@group(0) @binding(11) var surface: texture_2d_array<f32>;
// Every species' opacity volume, stacked (forest_render::opacity), read through colour_sampler.
@group(0) @binding(14) var opacity: texture_3d<f32>;

// Everything quad_vertex works out for one corner of a quad; each pipeline passes on what
// its fragment stage reads (QuadOut, CompositeOut). The two are kept apart because a CPU
// rasteriser sets up every output of every triangle: the composite's 16 extra floats on
// plain quads cost 4 % of the draw time (Table 1's scene on lavapipe).
struct QuadVertex {
    clip: vec4<f32>,
    uv: vec2<f32>,
    // The quad's first layer (x), level (y), sampling direction (z) and the layers it
    // composites, front first from x (w: a far tree's slabs; else 1).
    ids: vec4<u32>,
    alpha: f32,
    // Share [lo, hi) of the blend (x, y), the instance (z) and the tree's quad share (w, see
    // quad_share: below WEIGHT_ONE in the hybrid's transition band).
    share: vec4<u32>,
    // The tree's colouring (see tree_tint): its key (x) and species + 1 (y; 0: drawn in the
    // atlas's own colours).
    tint: vec2<u32>,
    // A composited quad's parallax: the uv shift per unit of stack depth behind its plane,
    // along the view ray (0 for other quads).
    parallax: vec2<f32>,
    // Depths in the stack (0 front, 1 back) of the first three slabs' root planes (their
    // corners' mean), where their images are sampled (0.5, the quad's plane, for the others),
    // and in `w` the mip level a composited quad samples (one for the whole quad: the tree is
    // under ε pixels).
    depths: vec4<f32>,
    // The quad's point (world, metres), for the haze.
    world: vec3<f32>,
    // The sampling direction's frame turned into world space (the instance's rotation): the
    // axes the baked normal codes are relative to. Its third axis is right × up
    // (forest_format::slab::DirectionFrame), which rotations keep, so it is not passed: the
    // inter-stage variables are few (GLES 3.0 guarantees 15).
    frame_right: vec3<f32>,
    frame_up: vec3<f32>,
    // Transmittance towards the sun through the tree's own crown at the vertex (its opacity
    // volume): plain quads only.
    sun_vis: f32,
    // For a composited quad, which marches per fragment: the points in object space on its
    // front slab's root plane and its second slab's, where the march starts (between them
    // by the slabs' shares of the pixel), the species, its bounding sphere, and the sun's
    // direction in object space with the species' opacity depth in w.
    obj_front: vec3<f32>,
    obj_back: vec3<f32>,
    species: u32,
    sphere: vec4<f32>,
    sun_obj: vec4<f32>,
    // The tree's bounding sphere (world centre, radius): where its points look up the sun's
    // shadow map (tree_shadow).
    tree: vec4<f32>,
}

// A plain quad's inter-stage variables (QuadVertex's fields of the same names).
struct QuadOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) ids: vec4<u32>,
    @location(2) @interpolate(flat) alpha: f32,
    @location(3) @interpolate(flat) share: vec4<u32>,
    @location(4) world: vec3<f32>,
    @location(5) @interpolate(flat) frame_right: vec3<f32>,
    @location(6) @interpolate(flat) frame_up: vec3<f32>,
    // Interpolated over the quad from its corners' marches.
    @location(7) sun_vis: f32,
    @location(8) @interpolate(flat) tree: vec4<f32>,
    @location(9) @interpolate(flat) tint: vec2<u32>,
}

// A composited quad's inter-stage variables (QuadVertex's fields of the same names).
struct CompositeOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) ids: vec4<u32>,
    @location(2) @interpolate(flat) alpha: f32,
    @location(3) @interpolate(flat) share: vec4<u32>,
    @location(4) world: vec3<f32>,
    @location(5) @interpolate(flat) frame_right: vec3<f32>,
    @location(6) @interpolate(flat) frame_up: vec3<f32>,
    @location(7) @interpolate(flat) parallax: vec2<f32>,
    @location(8) @interpolate(flat) depths: vec4<f32>,
    @location(9) obj_front: vec3<f32>,
    @location(10) obj_back: vec3<f32>,
    // The species (x) and the tree's tint (y, z: QuadVertex's tint), in one location: a
    // sixteenth would pass the 15 inter-stage variables downlevel devices offer.
    @location(11) @interpolate(flat) species: vec3<u32>,
    @location(12) @interpolate(flat) sphere: vec4<f32>,
    @location(13) @interpolate(flat) sun_obj: vec4<f32>,
    @location(14) @interpolate(flat) tree: vec4<f32>,
}

// What every quad's fragment needs besides its colour (see shade) and its lighting (see
// lit_texel).
struct Fragment {
    clip: vec4<f32>,
    uv: vec2<f32>,
    ids: vec4<u32>,
    alpha: f32,
    share: vec4<u32>,
    world: vec3<f32>,
    frame_right: vec3<f32>,
    frame_up: vec3<f32>,
    sun_vis: f32,
    tint: vec2<u32>,
}

// 1 inside a slab image, 0 outside (a shifted sample must not repeat the edge texels).
fn inside_image(uv: vec2<f32>) -> f32 {
    return select(0.0, 1.0, all(uv >= vec2<f32>(0.0)) && all(uv <= vec2<f32>(1.0)));
}

// Where slab k is sampled on a composited quad's plane (which lies at half the stack): at
// its root plane's depth, shifted along the view ray; slabs after the third at the plane.
fn slab_uv(in: CompositeOut, k: u32) -> vec2<f32> {
    var d = 0.5;
    if (k < 3u) { d = in.depths[k]; }
    return in.uv + in.parallax * (d - 0.5);
}

// How far (in finest-quad widths) a finest-level quad reaches past its rectangle, so that
// neighbouring quads at different depths overlap instead of leaving cracks once the view
// magnifies their texels: 0 while a finest quad covers at most CRACK_PIXELS pixels at `p`,
// rising to CRACK_MARGIN at twice that.
const CRACK_PIXELS: f32 = 4.0;
const CRACK_MARGIN: f32 = 0.25;
fn crack_margin(sp: Species, inst: Instance, level: u32, p: vec3<f32>) -> f32 {
    if (level + 1u != sp.levels) { return 0.0; }
    let m = camera.view_proj;
    let w = m[0].w * p.x + m[1].w * p.y + m[2].w * p.z + m[3].w;
    if (w <= 0.0) { return CRACK_MARGIN; }
    // |row 1 of the view-projection's 3×3| is the projection's y scale (the view is a rotation).
    let focal = length(vec3<f32>(m[0].y, m[1].y, m[2].y)) * camera.viewport.y * 0.5;
    let quad_px = 2.0 * sp.sphere.w * inst.scale / f32(1u << (sp.levels - 1u)) * focal / w;
    return CRACK_MARGIN * clamp(quad_px / CRACK_PIXELS - 1.0, 0.0, 1.0);
}

// Pixels the covered box of a node is widened by on each side (within the node), so that the
// texture filter's fringe around covered texels is still drawn. The mip level the derivatives
// pick is set by the node's most compressed screen extent, where its texels are at most a
// pixel wide: its coverage reaches past the box by under a texel (block alignment) and the
// bilinear footprint by half a texel more, together under 1.5 pixels, which the fringe holds.
// Trilinear filtering's coarser level reaches up to twice as far with a weight under one, and
// is cut there (faint: against the untrimmed quads the test cameras stay within FLIP 0.008,
// 0.0075 at 2 pixels; the walkthrough's stream shades 3 % fewer fragments than at 2 pixels at
// the same FLIP against the reference). The fringe is at least one texel of the finest level
// (magnified, the bilinear filter spreads half a texel).
const TRIM_FRINGE: f32 = 1.5;

// The shortest screen extent (pixels) of the edges of the node (`x`, `y`, side `size` in slab
// units, corner depths `d`), or 0 when a corner is behind the eye.
fn node_min_extent(sp: Species, f: Frame, inst: Instance, slab: u32, x: f32, y: f32, size: f32,
                   d: vec4<f32>) -> f32 {
    var s: array<vec2<f32>, 4>;
    for (var c = 0u; c < 4u; c++) {
        let p = to_world(inst, slab_point(sp, f, slab, (x + f32(c & 1u)) * size,
                                          (y + f32(c >> 1u)) * size, d[c]));
        let clip = camera.view_proj * vec4<f32>(p, 1.0);
        if (clip.w <= 0.0) { return 0.0; }
        s[c] = clip.xy / clip.w * camera.viewport.xy * 0.5;
    }
    return min(min(distance(s[0], s[1]), distance(s[2], s[3])),
               min(distance(s[0], s[2]), distance(s[1], s[3])));
}

// The stream is two lists (cull.wgsl): far trees' composited quads at its front, then every
// other quad; each has its own draw, in that order (vs_composite and fs_composite over the
// first `draw_composite` instances, vs_quad and fs_quad over the rest). Two pipelines keep the
// single texture sample of fs_quad free of the composite's loop (a branch around texture
// samples slowed every fragment by 30–120 % on a CPU rasteriser). A composited tree thus lies
// under every other tree's quads: exact where it is behind them, as far trees almost always
// are.
@vertex
fn vs_quad(@builtin(vertex_index) vi: u32, @builtin(instance_index) qi: u32) -> QuadOut {
    let i = kept_composites(state.composites, state.overflow_cull) + qi;
    let v = quad_vertex(vi, i, true);
    return QuadOut(v.clip, v.uv, v.ids, v.alpha, v.share, v.world, v.frame_right, v.frame_up,
                   v.sun_vis, v.tree, v.tint);
}

// The opaque pass, before every blended quad: the plain quads of each tree's first aspect in
// its front slab (the aspect drawn with alpha 1, which the others blend over), front to back
// (the stream reversed), their opaque fragments drawn with depth written a slab's thickness
// behind them, so that the depth test rejects what lies further behind: most of the tree's
// back slab and the trees behind. The tree's other front-slab aspects lie within that
// thickness and still blend over the fragment, which the blended draw draws again (the same
// colour at alpha 1). Nothing moves nearer than its surface, so terrain and a host's geometry
// hide what they hid without the pass; where they lie within the thickness behind a fragment,
// the pass's fragment fails the depth test and the blended draw alone draws it. Other quads
// collapse to a point outside the view.
@vertex
fn vs_quad_opaque(@builtin(vertex_index) vi: u32, @builtin(instance_index) qi: u32) -> QuadOut {
    // The plain list is [kept composites, n): instance qi is its (qi + 1)-th quad from the end.
    let i = state.n - 1u - qi;
    let q = quads[i];
    var out: QuadOut;
    out.clip = vec4<f32>(2.0, 2.0, 0.5, 1.0);
    if (quad_slab(q) != 0u || quad_lo(q) != 0u || camera.debug_view != 0.0) { return out; }
    // Only nodes mostly opaque: the rest of its fragments the blended draw shades again.
    let share = textureLoad(nodes, vec2<u32>(q.node % NODE_TEX_WIDTH, q.node / NODE_TEX_WIDTH), 0).w;
    if (share < OPAQUE_SHARE_MIN) { return out; }
    let v = quad_vertex(vi, i, true);
    if (v.share.w < WEIGHT_ONE) { return out; }
    // Behind its surface by the tree's slab thickness (2r / slabs): a uniform scale about the
    // eye, at most doubling the distance, keeps every point on its pixel and the
    // interpolation unchanged.
    let slabs = species[instances[q.instance].species].slabs;
    let reach = distance(v.tree.xyz, camera.eye);
    let push = 2.0 * v.tree.w / f32(max(slabs, 1u));
    let p = camera.eye + (v.world - camera.eye) * (1.0 + push / max(reach, push));
    return QuadOut(camera.view_proj * vec4<f32>(p, 1.0), v.uv, v.ids, v.alpha, v.share, v.world,
                   v.frame_right, v.frame_up, v.sun_vis, v.tree, v.tint);
}
// Mirrors passes::draw::OPAQUE_SHARE_MIN.
const OPAQUE_SHARE_MIN: u32 = 128u;

@vertex
fn vs_composite(@builtin(vertex_index) vi: u32, @builtin(instance_index) qi: u32) -> CompositeOut {
    let v = quad_vertex(vi, qi, true);
    return CompositeOut(v.clip, v.uv, v.ids, v.alpha, v.share, v.world, v.frame_right,
                        v.frame_up, v.parallax, v.depths, v.obj_front, v.obj_back,
                        vec3<u32>(v.species, v.tint),
                        v.sphere, v.sun_obj, v.tree);
}

// Corner `vi` of stream quad `qi`; `shaded`: with the sun's march (the draw), or without
// (the light views' casting pass, cast.wgsl, which shades nothing).
fn quad_vertex(vi: u32, qi: u32, shaded: bool) -> QuadVertex {
    let q = quads[qi];
    let inst = instances[q.instance];
    let sp = species[inst.species];
    let dir = quad_dir(q);
    let f = frames[sp.dir_base + dir];
    var node = textureLoad(nodes, vec2<u32>(q.node % NODE_TEX_WIDTH, q.node / NODE_TEX_WIDTH), 0).xyz;
    let level = quad_level(q);
    let size = 1.0 / f32(1u << level);
    let finest = 1.0 / f32(1u << (sp.levels - 1u));
    let corner = vec2<f32>(f32(vi & 1u), f32(vi >> 1u));
    var d = vec4<f32>(f32(node.y & 255u), f32((node.y >> 8u) & 255u),
                      f32((node.y >> 16u) & 255u), f32(node.y >> 24u)) / 255.0;
    let composite = quad_composite(q);
    var qx = quad_x(q);
    var slab = quad_slab(q);
    var parallax = vec2<f32>(0.0);
    var depths = vec4<f32>(0.5);
    if (composite) {
        // The view ray from the eye through the tree's centre in the direction's frame (the
        // tree spans less than ε pixels: one ray stands for all): moving one unit of
        // slab-relative depth (2r along −dir) shifts uv by (−a/c, b/c) (v runs down).
        let ray = to_object_dir(inst, to_world(inst, sp.sphere.xyz) - camera.eye);
        let c = min(dot(ray, f.dir.xyz), -0.2 * length(ray));
        parallax = vec2<f32>(-dot(ray, f.right.xyz) / c, dot(ray, f.up.xyz) / c);
        // All the slabs on the plane through the tree's centre (slab-relative depth of slab
        // 0 reaching half the stack), over the union of their covered boxes.
        qx = 0u;
        slab = 0u;
        d = vec4<f32>(0.5 * f32(sp.slabs));
        var lo = vec2<u32>(255u);
        var hi = vec2<u32>(0u);
        for (var s = 0u; s < sp.slabs; s++) {
            let r = roots[sp.layer_base + dir * sp.slabs + s];
            if (r == NONE) { continue; }
            let root = textureLoad(nodes, vec2<u32>(r % NODE_TEX_WIDTH, r / NODE_TEX_WIDTH), 0);
            let z = root.z;
            lo = min(lo, vec2<u32>(z & 255u, (z >> 8u) & 255u));
            hi = max(hi, vec2<u32>((z >> 16u) & 255u, z >> 24u));
            if (s < 3u) {
                depths[s] = (f32(s) + node_mean_depth(root.xy)) / f32(sp.slabs);
            }
        }
        node.z = lo.x | (lo.y << 8u) | (hi.x << 16u) | (hi.y << 24u);
    }
    // The node's shortest screen extent (pixels), which sets the trim fringe and a
    // composited quad's mip level.
    let trimmed = (stream_flags(camera) & FLAG_UNTRIMMED) == 0u;
    var px = 0.0;
    if (trimmed || composite) {
        px = node_min_extent(sp, f, inst, slab, f32(qx), f32(quad_y(q)), size, d);
    }
    if (composite) {
        // Texels of the slab image per pixel of its shortest edge on screen.
        depths.w = log2(max(f32(sp.resolution) / max(px, 1e-3), 1.0));
    }
    // The node's covered box (fractions of its side; see forest_format::trim), widened by
    // the fringe; the whole node when untrimmed.
    var box_lo = vec2<f32>(0.0);
    var box_hi = vec2<f32>(1.0);
    if (trimmed) {
        // At least one texel too: magnified, the bilinear filter spreads half a texel.
        let texel = 1.0 / f32(max(sp.resolution >> level, 1u));
        let fringe = select(1.0, max(TRIM_FRINGE / px, texel), px > 0.0);
        box_lo = max(vec2<f32>(f32(node.z & 255u), f32((node.z >> 8u) & 255u)) / 255.0 - fringe,
                 vec2<f32>(0.0));
        box_hi = min(vec2<f32>(f32((node.z >> 16u) & 255u), f32(node.z >> 24u)) / 255.0 + fringe,
                 vec2<f32>(1.0));
        // A composited quad reaches as far as its slabs' shifted boxes (other quads have no
        // parallax).
        let far_slab = max(max(abs(depths.x - 0.5), abs(depths.y - 0.5)), abs(depths.z - 0.5));
        let spread = abs(parallax) * far_slab;
        box_lo = box_lo - spread;
        box_hi = box_hi + spread;
    }
    let a = mix(box_lo, box_hi, corner);
    let u0 = (f32(qx) + a.x) * size;
    let v0 = (f32(quad_y(q)) + a.y) * size;
    // The node's plane at `a`: bilinear in its corner depths (exact for a plane).
    let t0 = mix(mix(d.x, d.y, a.x), mix(d.z, d.w, a.x), a.y);
    var p = slab_point(sp, f, slab, u0, v0, t0);
    var w = to_world(inst, p);
    // Crack margin outwards on every side (finest level), as untrimmed: from a side that
    // reaches the node's edge it overlaps the neighbour's quad; from a trimmed side it only
    // covers the node's own blank texels.
    let margin = crack_margin(sp, inst, level, w);
    let u = u0 + (corner.x * 2.0 - 1.0) * margin * finest;
    let v = v0 + (corner.y * 2.0 - 1.0) * margin * finest;
    if (margin > 0.0) {
        p = slab_point(sp, f, slab, u, v, t0);
        w = to_world(inst, p);
    }
    // The frame's wind moves the corner with its tree, as every method moves that point (the
    // node's quads move with their corners; a composited tree sways as a whole).
    w = swayed(w, inst.position, wind_height(sp.sphere, inst.scale), sp.sphere.w * inst.scale,
               q.instance);
    let flags = stream_flags(camera);
    var out: QuadVertex;
    out.clip = camera.view_proj * vec4<f32>(w, 1.0);
    out.world = w;
    out.uv = vec2<f32>(u, v);
    out.ids = vec4<u32>(sp.layer_base + dir * sp.slabs + slab, quad_level(q), dir,
                        select(1u, sp.slabs, composite));
    out.parallax = parallax;
    out.depths = depths;
    let lo = quad_lo(q);
    let hi = quad_hi(q);
    out.alpha = select(0.0, f32(hi - lo) / f32(hi), hi > 0u);
    if ((flags & FLAG_DITHER) != 0u) { out.alpha = 1.0; }
    let form = quad_share(camera.forms, distance(camera.form_eye.xyz, to_world(inst, sp.sphere.xyz)),
                          sp.switch_unit * inst.scale, q.instance);
    out.share = vec4<u32>(lo, hi, q.instance, form);
    out.tint = tree_tint(q.instance, inst);
    out.frame_right = to_world_dir(inst, f.right.xyz);
    out.frame_up = to_world_dir(inst, f.up.xyz);
    let sun_obj = to_object_dir(inst, camera.sun);
    // Stack depth d lies (1 − 2d)·r along the direction from the centre (slab_point); the
    // quad's plane is at d = ½.
    let to_slab = f.dir.xyz * (2.0 * sp.sphere.w);
    out.obj_front = p + to_slab * (0.5 - depths.x);
    out.obj_back = p + to_slab * (0.5 - select(depths.x, depths.y, sp.slabs > 1u));
    out.species = inst.species;
    out.sphere = sp.sphere;
    out.sun_obj = vec4<f32>(sun_obj, sp.opacity_depth);
    out.tree = vec4<f32>(to_world(inst, sp.sphere.xyz), sp.sphere.w * inst.scale);
    // A plain quad marches at its corners and interpolates. Coarse quads smear the crown's
    // shadow so (a far view: FLIP 0.164 against the reference, 0.124 marching per fragment),
    // but a march per fragment in fs_quad, even behind a branch no fragment takes, cost a CPU
    // rasteriser 2.4 times the draw time; per vertex costs 1.15 times. The march reads the
    // volume's mip level that suits the quad's size (quad_march): on coarse quads the coarse
    // level lowered a far view's FLIP by a tenth. A composited quad, which spans a whole far
    // tree, marches per fragment (fs_composite), through the coarse level: the full march
    // there cost a tenth of the draw time.
    out.sun_vis = 1.0;
    if (!composite && shaded) {
        let m = quad_march(level);
        // From the corner's Gauss point: the quad's 2×2 Gauss–Legendre nodes, ±1/√3 of the
        // half box about its middle, on the node's plane.
        let ag = mix(0.5 * (box_lo + box_hi), a, 0.57735027);
        let tg = mix(mix(d.x, d.y, ag.x), mix(d.z, d.w, ag.x), ag.y);
        let pg = slab_point(sp, f, slab, (f32(qx) + ag.x) * size, (f32(quad_y(q)) + ag.y) * size,
                            tg);
        out.sun_vis = opacity_march(opacity, colour_sampler, inst.species, sp.sphere,
                                    sp.opacity_depth, pg, sun_obj, m.x, m.y);
    }
    return out;
}

// How instance `id` (record `inst`) is coloured: its tint key (x) and its species + 1 (y), or
// (0, 0) where tree_albedo would return the atlas's albedo unchanged (no per-tree amplitude
// for its species and no season). Taken per vertex, so that a quad's fragments
// read no instance or species record where nothing is coloured (those reads cost 12 % of the
// quad draw on lavapipe, Table 1's scene). Composited quads carry it beside their species.
fn tree_tint(id: u32, inst: Instance) -> vec2<u32> {
    if (!tree_coloured(species[inst.species].colour)) { return vec2<u32>(0u); }
    return vec2<u32>(tint_key(id, inst.colour), inst.species + 1u);
}

// The radiance of a texel (premultiplied albedo and coverage `c`, premultiplied surface `g`)
// under the frame's light: premultiplied, linear.
fn lit_texel(in: Fragment, c: vec4<f32>, g: vec4<f32>) -> vec4<f32> {
    if (c.a <= 0.0) { return vec4<f32>(0.0); }
    let inv = 1.0 / c.a;
    let local = hemi_oct_decode(g.xy * inv);
    let frame_dir = cross(in.frame_right, in.frame_up);
    let n = normalize(local.x * in.frame_right + local.y * in.frame_up + local.z * frame_dir);
    let sky = min(g.z * inv, 1.0);
    let tau = min(g.w * inv, 1.0);
    // The tree's own colour, where it has one.
    var a = c.rgb * inv;
    if (in.tint.y != 0u) { a = tree_albedo(a, tau, in.tint.x, species[in.tint.y - 1u].colour); }
    return vec4<f32>(shade_light(a, n, in.sun_vis, sky, tau) * c.a, c.a);
}

// Debug views (camera.debug_view, see forest_render::options::DebugView): 0 off, 1 levels, 2 blend weights,
// 3 wireframe.
const DEBUG_LEVELS: u32 = 1u;
const DEBUG_WEIGHTS: u32 = 2u;
const DEBUG_WIREFRAME: u32 = 3u;

// Colour of a hierarchy level; mirrors forest_render::options::LEVEL_COLOURS.
fn level_colour(level: u32) -> vec3<f32> {
    var c = array<vec3<f32>, 8>(
        vec3<f32>(0.9, 0.1, 0.1), vec3<f32>(0.95, 0.55, 0.05), vec3<f32>(0.9, 0.9, 0.1),
        vec3<f32>(0.1, 0.8, 0.1), vec3<f32>(0.1, 0.8, 0.8), vec3<f32>(0.1, 0.2, 0.95),
        vec3<f32>(0.6, 0.1, 0.9), vec3<f32>(0.95, 0.95, 0.95));
    return c[level % 8u];
}

// A distinct, saturated colour per sampling direction (hues by the golden ratio).
fn direction_colour(dir: u32) -> vec3<f32> {
    let h = fract(f32(dir) * 0.618034);
    let rgb = clamp(abs(fract(vec3<f32>(h) + vec3<f32>(0.0, 2.0 / 3.0, 1.0 / 3.0)) * 6.0 - 3.0) - 1.0,
                    vec3<f32>(0.0), vec3<f32>(1.0));
    return 0.15 + 0.8 * rgb;
}

@fragment
fn fs_quad(in: QuadOut) -> @location(0) vec4<f32> {
    count_enter(in.clip);
    let out = quad_colour(in);
    count_shown(in.clip, out.a);
    return out;
}

// A plain quad's fragment: its texel lit and shaded (see shade).
fn quad_colour(in: QuadOut) -> vec4<f32> {
    let c = textureSample(colour, colour_sampler, in.uv, in.ids.x);
    let g = textureSample(surface, colour_sampler, in.uv, in.ids.x);
    // The crown's own shadow (the march) times the other casters' (the sun's shadow map).
    let f = Fragment(in.clip, in.uv, in.ids, in.alpha, in.share, in.world, in.frame_right,
                     in.frame_up, in.sun_vis * tree_shadow(in.world, in.tree), in.tint);
    return shade(f, lit_texel(f, c, g));
}

@fragment
fn fs_quad_opaque(in: QuadOut) -> @location(0) vec4<f32> {
    count_enter(in.clip);
    let out = quad_colour(in);
    // The rest is drawn by fs_quad, blended. Pushed back, the quad reaches past the near
    // plane where the blended draw's is clipped: only what that draw shows is drawn here.
    let own = camera.view_proj * vec4<f32>(in.world, 1.0);
    if (out.a < OPAQUE_FRAGMENT || own.w <= 0.0 || own.z < 0.0 || own.z > own.w) { discard; }
    count_shown(in.clip, out.a);
    count_depth(in.clip);
    return out;
}
// What the opaque pass draws: as opaque as an 8-bit target tells.
const OPAQUE_FRAGMENT: f32 = 1.0 - 0.5 / 255.0;

@fragment
fn fs_composite(in: CompositeOut) -> @location(0) vec4<f32> {
    count_enter(in.clip);
    // The slabs "over" each other from the front (premultiplied), at the quad's mip level.
    // Albedo and surface attributes are composited with the same weights, then lit once.
    var c = vec4<f32>(0.0);
    var g = vec4<f32>(0.0);
    var front = 0.0;
    for (var k = 0u; k < in.ids.w; k++) {
        let uv = slab_uv(in, k);
        let w = inside_image(uv) * (1.0 - c.a);
        let b = textureSampleLevel(colour, colour_sampler, uv, in.ids.x + k, in.depths.w);
        g = g + textureSampleLevel(surface, colour_sampler, uv, in.ids.x + k, in.depths.w) * w;
        c = c + b * w;
        if (k == 0u) { front = c.a; }
    }
    // The march starts where the pixel's coverage lies: on the front slab's plane, moved
    // towards the second's by the share the slabs behind the front one add.
    let p = mix(in.obj_front, in.obj_back, (c.a - front) / max(c.a, 1e-6));
    let vis = sun_transmittance_coarse(opacity, colour_sampler, in.species.x, in.sphere,
                                       in.sun_obj.w, p, in.sun_obj.xyz);
    let f = Fragment(in.clip, in.uv, in.ids, in.alpha, in.share, in.world, in.frame_right,
                     in.frame_up, vis * tree_shadow(in.world, in.tree), in.species.yz);
    let out = shade(f, lit_texel(f, c, g));
    count_shown(in.clip, out.a);
    return out;
}

// The host's depth after the blended quads (`RendererOptions::write_depth`): the same
// fragments with their coverage alone (no light), colour writes off, kept where the quad is at
// least half opaque and not masked out.
@fragment
fn fs_quad_depth(in: QuadOut) -> @location(0) vec4<f32> {
    let a = textureSample(colour, colour_sampler, in.uv, in.ids.x).a * in.alpha;
    if (a < DEPTH_WRITE_ALPHA || masked(in.clip.xy, in.share)) { discard; }
    return vec4<f32>(0.0);
}

@fragment
fn fs_composite_depth(in: CompositeOut) -> @location(0) vec4<f32> {
    var a = 0.0;
    for (var k = 0u; k < in.ids.w; k++) {
        let uv = slab_uv(in, k);
        let b = textureSampleLevel(colour, colour_sampler, uv, in.ids.x + k, in.depths.w).a;
        a = a + b * inside_image(uv) * (1.0 - a);
    }
    if (a * in.alpha < DEPTH_WRITE_ALPHA || masked(in.clip.xy, in.share)) { discard; }
    return vec4<f32>(0.0);
}

// Coverage from which the depth pass writes a fragment's depth (mirrors
// passes::draw::DEPTH_WRITE_ALPHA).
const DEPTH_WRITE_ALPHA: f32 = 0.5;

// Whether the pixel `clip` of a quad whose form share and dither interval are `share` belongs
// to another form (the hybrid's screen door) or another aspect (the dither).
fn masked(clip: vec2<f32>, share: vec4<u32>) -> bool {
    if (share.w < WEIGHT_ONE && form_threshold(clip, share.z) >= share.w) { return true; }
    if ((stream_flags(camera) & FLAG_DITHER) != 0u) {
        let u = dither_threshold(clip, share.z);
        if (u < share.x || u >= share.y) { return true; }
    }
    return false;
}

// A quad's fragment of lit colour `c` (premultiplied): the hybrid's and the dither's masks, the
// debug views, the haze, the aspect's alpha.
fn shade(in: Fragment, c: vec4<f32>) -> vec4<f32> {
    // Position inside the quad in quad widths and its screen derivative (before any branch).
    let g = in.uv * f32(1u << in.ids.y);
    let px = max(fwidth(g), vec2<f32>(1e-6));
    let mode = u32(camera.debug_view);
    if (masked(in.clip.xy, in.share)) { discard; }
    if (mode == DEBUG_LEVELS) {
        return vec4<f32>(level_colour(in.ids.y) * c.a, c.a) * in.alpha;
    }
    if (mode == DEBUG_WEIGHTS) {
        return vec4<f32>(direction_colour(in.ids.z) * c.a, c.a) * in.alpha;
    }
    if (mode == DEBUG_WIREFRAME) {
        // Distance to the quad's nearest edge in pixels: a line about one pixel wide.
        let e = min(fract(g), vec2<f32>(1.0) - fract(g)) / px;
        if (min(e.x, e.y) < 1.0) {
            return vec4<f32>(1.0, 0.95, 0.2, 1.0) * in.alpha;
        }
    }
    return hazed(c, in.world) * in.alpha;
}
