// Where a quad lies on screen, for the refine pass. Mirrored by clip_at, edge_long,
// error_long and quad_outside in crates/forest-render/src/reference.rs, operation for operation.

#import common
#import bindings
#import wind

// Clip-space position of image point (u, v) at slab-relative depth t of a quad's layer.
fn quad_clip_at(q: Quad, u: f32, v: f32, t: f32) -> vec4<f32> {
    let inst = instances[q.instance];
    let sp = species[inst.species];
    let f = frames[sp.dir_base + quad_dir(q)];
    let w = to_world(inst, slab_point(sp, f, quad_slab(q), u, v, t));
    let m = camera.view_proj;
    return m[0] * w.x + m[1] * w.y + m[2] * w.z + m[3];
}

// Whether the projected segment a-b is longer than ε pixels; both ends in front of the eye.
fn edge_long(a: vec4<f32>, b: vec4<f32>) -> bool {
    let sx = camera.viewport.x * 0.5;
    let sy = camera.viewport.y * 0.5;
    let dx = (a.x * b.w - b.x * a.w) * sx;
    let dy = (a.y * b.w - b.y * a.w) * sy;
    let lim = camera.epsilon * a.w * b.w;
    return dx * dx + dy * dy > lim * lim;
}


// Whether the node's depth error, as a displacement along its sampling direction at the quad's
// centre and mean depth, projects longer than ε pixels; reaching behind the eye counts as long.
fn error_long(q: Quad, node: vec2<u32>) -> bool {
    let e = node_error(node);
    if (e <= 0.0) { return false; }
    let tc = node_mean_depth(node);
    let size = 1.0 / f32(1u << quad_level(q));
    let u = (f32(quad_x(q)) + 0.5) * size;
    let v = (f32(quad_y(q)) + 0.5) * size;
    let a = quad_clip_at(q, u, v, tc);
    let b = quad_clip_at(q, u, v, tc + e);
    if (a.w <= 0.0 || b.w <= 0.0) { return true; }
    return edge_long(a, b);
}

// Whether everything a quad and its descendants may draw lies outside one of the view's side
// planes (left, right, bottom, top): the sphere around its image rectangle over the slab's
// whole depth, grown by half the quad's width (the crack margins and trim fringes its
// descendants reach past their rectangles) and by the wind's reach. Such a quad is not
// refined: it is off screen, and so are all its children. The depth planes are not tested
// (a light view's casters reach its receivers from beyond its near plane).
fn quad_outside(q: Quad) -> bool {
    let inst = instances[q.instance];
    let sp = species[inst.species];
    let f = frames[sp.dir_base + quad_dir(q)];
    let size = 1.0 / f32(1u << quad_level(q));
    let u = (f32(quad_x(q)) + 0.5) * size;
    let v = (f32(quad_y(q)) + 0.5) * size;
    let c = to_world(inst, slab_point(sp, f, quad_slab(q), u, v, 0.5));
    let r = sp.sphere.w * inst.scale;
    let slab = 1.0 / f32(sp.slabs);
    let reach = r * (sqrt(2.0 * size * size + slab * slab) + size)
        + wind_reach_now(inst.position, wind_height(sp.sphere, inst.scale), q.instance);
    for (var k = 0u; k < 4u; k++) {
        let pl = camera.planes[k];
        if (dot(pl.xyz, c) + pl.w < -reach) { return true; }
    }
    return false;
}
