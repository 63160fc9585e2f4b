// Drawing of the geometry-based methods (see geometry.wgsl), with environment.wgsl (the sky,
// the ground and the haze every fragment goes through).
//
// Meshes are shaded with the project's one shading model (shade_light, forest_format::shading)
// in world space under the frame's light (the camera uniform's): an instance's rotation turns
// its normals, not the sun. Sky visibility is per vertex and per side, traced by the bake's
// ray tracer (the values the slab images are baked with). Sun visibility comes from marching
// the species' opacity volume towards the frame's sun (sun_transmittance): per vertex for
// meshes, per fragment through the volume's coarse level for billboards
// (sun_transmittance_coarse). Under stochastic simplification a
// leaf vertex is moved towards its leaf's centre by the fade × area factor and the leaf's
// albedo pulled towards the species' mean by √λ; at λ = 1 nothing is touched, so the image is
// exactly the full geometry's.

#import common
#import geometry_types
#import ground
#import environment
#import shadow
#import count
#import wind
#import tint

@group(0) @binding(0) var<uniform> camera: Camera;
@group(0) @binding(1) var<storage, read> instances: array<Instance>;
@group(0) @binding(2) var<storage, read> vertices: array<GeoVertex>;
@group(0) @binding(3) var<storage, read> visible_list: array<u32>;
@group(0) @binding(4) var<storage, read> materials: array<GeoMaterial>;
@group(0) @binding(5) var textures: texture_2d_array<f32>;
@group(0) @binding(6) var tex_sampler: sampler;
// The billboards' surface attributes (hemispherical octahedral normal code in the image's
// frame, sky visibility, translucency; straight, linear), layered as `billboards`.
@group(0) @binding(7) var billboard_surface: texture_2d_array<f32>;
// binding 8: the environment (environment.wgsl).
@group(0) @binding(9) var<storage, read> geo_species: array<GeoSpecies>;
@group(0) @binding(10) var<uniform> method: Method;
@group(0) @binding(11) var<storage, read> leaf_centre: array<vec4<f32>>;
@group(0) @binding(12) var billboards: texture_2d_array<f32>;
// Every species' opacity volume, stacked (forest_render::opacity), and its clamping sampler.
@group(0) @binding(14) var opacity: texture_3d<f32>;
@group(0) @binding(15) var opacity_sampler: sampler;
// The triangles' presorted draw orders (forest_baselines::geometry::draw_orders): for
// view-direction bin k, entry k·T + t is the triangle drawn t-th, T = every species' LODs'
// triangles (the vertices' count / 3).
@group(0) @binding(16) var<storage, read> draw_order: array<u32>;

struct GeoOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    // World space.
    @location(1) normal: vec3<f32>,
    @location(2) to_eye: vec3<f32>,
    // Sky visibility of the front (x) and back (y) sides.
    @location(3) sky: vec2<f32>,
    @location(4) @interpolate(flat) material: u32,
    // rgb: mean leaf colour; a: contrast weight α = √λ (1: untouched).
    @location(5) @interpolate(flat) contrast: vec4<f32>,
    // The instance, its quad share (see quad_share) and its mesh LOD's share range: in the
    // hybrid's transition band the geometry keeps the pixels the quads leave, and in a
    // crossfade between mesh LODs each LOD the pixels of its range (lod_range).
    @location(6) @interpolate(flat) form: vec4<u32>,
    // The surface point (world, metres), for the haze.
    @location(7) world: vec3<f32>,
    // Transmittance towards the sun through the tree's own crown (its opacity volume).
    @location(8) sun_vis: f32,
    // The tree's bounding sphere (world centre, radius), where the sun's shadow map is read
    // (tree_shadow, shadow_on.wgsl).
    @location(9) @interpolate(flat) tree: vec4<f32>,
}

// The instance, its quad share (0 outside the hybrid's transition band) and the share range
// of its mesh LOD `lod` under the hybrid's LOD bands (else, or for NONE, [0, WEIGHT_ONE):
// every pixel).
fn geo_form(id: u32, inst: Instance, lod: u32) -> vec4<u32> {
    let sp = geo_species[inst.species];
    let d = distance(camera.form_eye.xyz, to_world(inst, sp.sphere.xyz));
    let unit = sp.switch_unit * inst.scale;
    var range = vec2<u32>(0u, WEIGHT_ONE);
    if (lod != NONE && lod_bands_on(method, camera.forms, sp)) {
        range = lod_range(lod, lod_shares(method, camera.forms, sp, d, unit, id));
    }
    return vec4<u32>(id, quad_share(camera.forms, d, unit, id), range);
}

// The albedo `a` (translucency `tau`) of instance `id` in its own colour (tint.wgsl).
fn geo_tree_albedo(a: vec3<f32>, tau: f32, id: u32) -> vec3<f32> {
    let inst = instances[id];
    return tree_albedo(a, tau, tint_key(id, inst.colour), geo_species[inst.species].colour);
}

// Whether a pixel of a tree is not this draw's: the quads own it (the transition band), or
// another of its mesh LODs does (a crossfade between them).
fn not_drawn_here(pixel: vec2<f32>, form: vec4<u32>) -> bool {
    if (form.y > 0u && form_threshold(pixel, form.x) < form.y) { return true; }
    if (form.z == 0u && form.w == WEIGHT_ONE) { return false; }
    let t = lod_threshold(pixel, form.x);
    return t < form.z || t >= form.w;
}

@vertex
fn vs_geo(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32) -> GeoOut {
    return geo_vertex(vi, ii, true);
}

// The vertex a tree draws `vi`-th, `bin` the order bin of its visible-list entry (geo_scatter).
// Depth-sorted (not under stochastic simplification, whose draws are prefixes of its shuffled
// leaves), each triangle comes from the presorted order of that bin, nearest leaves first, so
// that the depth test rejects what they hide before it is shaded; the image is the same.
fn draw_vertex(vi: u32, bin: u32) -> u32 {
    if (method.depth_sort == 0u || method.mode == 1u) { return vi; }
    let triangles = arrayLength(&vertices) / 3u;
    let t = draw_order[bin * triangles + vi / 3u];
    return 3u * t + vi % 3u;
}

// Vertex `vi` of listed tree `ii`; `shaded`: with the march towards the sun (the draw), or
// without (the light views' casting pass, geometry_cast.wgsl).
fn geo_vertex(vi: u32, ii: u32, shaded: bool) -> GeoOut {
    let entry = visible_list[ii];
    let id = entry & VISIBLE_ID_MASK;
    let inst = instances[id];
    let v = vertices[draw_vertex(vi, entry >> VISIBLE_ID_BITS)];
    let lod = vertex_lod(geo_species[inst.species], vi);
    var p = v.pos;
    var contrast = vec4<f32>(0.0, 0.0, 0.0, 1.0);
    if (method.mode == 1u && v.element != NONE) {
        let sp = geo_species[inst.species];
        let d = distance(camera.form_eye.xyz, to_world(inst, sp.sphere.xyz)) / inst.scale;
        let lambda = lod_lambda(method, d);
        if (lambda < 1.0) {
            let u = (f32(v.element) + 0.5) / f32(sp.leaves);
            var k = lod_fade(u, lambda, method.fade);
            if (method.area != 0u) { k = k * sqrt(lod_area_scale(sp.r, lambda)); }
            let c = leaf_centre[sp.leaf_base + v.element].xyz;
            p = c + (p - c) * k;
            if (method.contrast != 0u) { contrast = vec4<f32>(sp.mean_leaf, sqrt(lambda)); }
        }
    }
    let sp = geo_species[inst.species];
    // The frame's wind moves the vertex with its tree, as every method moves that point.
    let w = swayed(to_world(inst, p), inst.position, wind_height(sp.sphere, inst.scale),
                   sp.sphere.w * inst.scale, id);
    var out: GeoOut;
    out.clip = camera.view_proj * vec4<f32>(w, 1.0);
    out.world = w;
    out.uv = v.uv;
    out.normal = to_world_dir(inst, v.normal);
    out.to_eye = camera.eye - w;
    out.sky = vec2<f32>(v.sky_front, v.sky_back);
    out.material = v.material;
    out.contrast = contrast;
    out.form = geo_form(id, inst, lod);
    out.tree = vec4<f32>(to_world(inst, sp.sphere.xyz), sp.sphere.w * inst.scale);
    out.sun_vis = 1.0;
    if (shaded) {
        out.sun_vis = sun_transmittance(opacity, opacity_sampler, inst.species, sp.sphere,
                                        sp.opacity_depth, p, to_object_dir(inst, camera.sun));
    }
    return out;
}

@fragment
fn fs_geo(in: GeoOut) -> @location(0) vec4<f32> {
    count_enter(in.clip);
    if (not_drawn_here(in.clip.xy, in.form)) { discard; }
    let m = materials[in.material];
    var albedo = m.kd.rgb;
    if (m.layer != NONE) {
        // OBJ texture coordinates: v = 0 is the bottom row.
        let t = textureSampleBias(textures, tex_sampler, vec2<f32>(in.uv.x, 1.0 - in.uv.y),
                                  m.layer, method.texture_bias);
        if (m.alpha_tested != 0u && t.a < 0.5) { discard; }
        albedo = albedo * t.rgb;
    }
    if (in.contrast.a < 1.0) {
        albedo = in.contrast.rgb + in.contrast.a * (albedo - in.contrast.rgb);
    }
    albedo = geo_tree_albedo(albedo, m.kd.a, in.form.x);
    var n = normalize(in.normal);
    var sky = in.sky.x;
    if (dot(n, in.to_eye) < 0.0) {
        n = -n;
        sky = in.sky.y;
    }
    // The crown's own shadow (the march) times the other casters' (the sun's shadow map).
    let c = shade_light(albedo, n, in.sun_vis * tree_shadow(in.world, in.tree), sky, m.kd.a);
    let out = hazed(vec4<f32>(c, 1.0), in.world);
    count_shown(in.clip, out.a);
    count_depth(in.clip);
    return out;
}

struct BillboardOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
    @location(1) @interpolate(flat) layer: u32,
    @location(2) @interpolate(flat) form: vec4<u32>,
    @location(3) world: vec3<f32>,
    // The billboard's frame (world): image x, image up, towards the viewer.
    @location(4) @interpolate(flat) right: vec3<f32>,
    @location(5) @interpolate(flat) up: vec3<f32>,
    @location(6) @interpolate(flat) back: vec3<f32>,
    // The point in object space (on the plane through the tree's centre), where the march
    // towards the sun starts.
    @location(7) obj: vec3<f32>,
    // The species' bounding sphere; its index.
    @location(8) @interpolate(flat) sphere: vec4<f32>,
    @location(9) @interpolate(flat) species: u32,
    // xyz: the sun's direction in object space; w: the species' opacity depth.
    @location(10) @interpolate(flat) sun_obj: vec4<f32>,
    // Unit direction from the eye through the tree's centre, in object space: the view ray
    // that median_depth_point follows through the crown.
    @location(11) @interpolate(flat) view_obj: vec3<f32>,
    // The tree's bounding sphere (world centre, radius).
    @location(12) @interpolate(flat) tree: vec4<f32>,
}

// A camera-facing quad over the tree's bounding sphere showing the billboard image whose
// elevation (0°, 30°, 60°, 90°) is nearest the view's (seed 004).
@vertex
fn vs_billboard(@builtin(vertex_index) vi: u32, @builtin(instance_index) ii: u32)
    -> BillboardOut {
    let id = visible_list[ii] & VISIBLE_ID_MASK;
    let inst = instances[id];
    let sp = geo_species[inst.species];
    let c = to_world(inst, sp.sphere.xyz);
    let r = sp.sphere.w * inst.scale;
    let f = normalize(c - camera.eye);
    var right = cross(f, vec3<f32>(0.0, 1.0, 0.0));
    if (dot(right, right) < 1e-8) { right = vec3<f32>(1.0, 0.0, 0.0); }
    right = normalize(right);
    let up = cross(right, f);
    // Two triangles: corners (-1,-1) (1,-1) (1,1) / (-1,-1) (1,1) (-1,1).
    let xs = array<f32, 6>(-1.0, 1.0, 1.0, -1.0, 1.0, -1.0);
    let ys = array<f32, 6>(-1.0, -1.0, 1.0, -1.0, 1.0, 1.0);
    let x = xs[vi % 6u];
    let y = ys[vi % 6u];
    let elevation = degrees(asin(clamp(-f.y, -1.0, 1.0)));
    let e = u32(clamp(round(elevation / 30.0), 0.0, 3.0));
    var out: BillboardOut;
    let rest = c + (right * x + up * y) * r;
    // The card's corners move with the tree (it sways as a whole, bending with its height).
    out.world = swayed(rest, inst.position, wind_height(sp.sphere, inst.scale), r, id);
    out.clip = camera.view_proj * vec4<f32>(out.world, 1.0);
    out.uv = vec2<f32>(0.5 + 0.5 * x, 0.5 - 0.5 * y);
    out.layer = sp.lod_first.w + e;
    out.form = geo_form(id, inst, NONE);
    out.right = right;
    out.up = up;
    out.back = -f;
    out.obj = to_object_point(inst, rest);
    out.sphere = sp.sphere;
    out.species = inst.species;
    out.sun_obj = vec4<f32>(to_object_dir(inst, camera.sun), sp.opacity_depth);
    out.view_obj = to_object_dir(inst, f);
    out.tree = vec4<f32>(c, r);
    return out;
}

@fragment
fn fs_billboard(in: BillboardOut) -> @location(0) vec4<f32> {
    count_enter(in.clip);
    if (not_drawn_here(in.clip.xy, in.form)) { discard; }
    let t = textureSample(billboards, tex_sampler, in.uv, in.layer);
    let g = textureSample(billboard_surface, tex_sampler, in.uv, in.layer);
    if (t.a < 0.5) { discard; }
    let local = hemi_oct_decode(g.xy);
    let n = normalize(local.x * in.right + local.y * in.up + local.z * in.back);
    // The billboard lies on the plane through the tree's centre, but its texels show the
    // crown's first surfaces: march towards the sun from where the view ray has spent half its
    // light in the crown (median_depth_point). Marched from the plane, the shadowed side of a
    // crown seen against a low sun was lit through (1.28 times the reference's luminance;
    // 1.07 times from the median depth).
    let start = median_depth_point(opacity, opacity_sampler, in.species, in.sphere,
                                   in.sun_obj.w, in.obj, in.view_obj);
    let v = sun_transmittance_coarse(opacity, opacity_sampler, in.species, in.sphere,
                                     in.sun_obj.w, start, in.sun_obj.xyz);
    let vis = v * tree_shadow(in.world, in.tree);
    let albedo = geo_tree_albedo(t.rgb, g.w, in.form.x);
    let out = hazed(vec4<f32>(shade_light(albedo, n, vis, g.z, g.w), 1.0), in.world);
    count_shown(in.clip, out.a);
    count_depth(in.clip);
    return out;
}
