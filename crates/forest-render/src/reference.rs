//! CPU reference of passes 1 (cull) and 2 (refine) over the same tables the GPU gets, with
//! the same arithmetic in the same order, so the GPU's quad stream must equal it exactly.

use forest_format::directions::blend;
use glam::{Vec3, Vec4};

use forest_format::QuadNode;
use forest_format::node::ERROR_BOUNDS;

use crate::gpu_types::{GpuCamera, GpuInstance, GpuSpecies, Quad, WEIGHT_ONE, kept_composites};
use crate::options::{
    FLAG_DEPTH_ERROR, FLAG_FAR_BLEND, FLAG_FAR_SLABS, FLAG_NEAREST, REACH_MASK, REACH_SHIFT,
    REACH_STEP, REACH_STEPS, SHARPEN_MASK, SHARPEN_MAX, SHARPEN_SHIFT,
};
use crate::scene::SceneTables;

/// Result of the reference: the final stream and the frame's counters.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Reference {
    /// Presort direction chosen.
    pub presort: u32,
    /// Trees passing the frustum test.
    pub visible: u32,
    /// The final stream.
    pub quads: Vec<Quad>,
    /// Quads per level (first `levels` entries).
    pub per_level: Vec<u32>,
    /// Level-0 quads dropped.
    pub overflow_cull: u32,
    /// Quads left unrefined for lack of room.
    pub overflow_refine: u32,
    /// Far trees' composited quads at level 0, before any were dropped (those kept lead the
    /// stream).
    pub composites: u32,
}

impl Reference {
    /// Composited quads leading the final stream.
    pub fn kept_composites(&self) -> u32 {
        kept_composites(self.composites, self.overflow_cull)
    }
}

fn to_world(inst: &GpuInstance, p: Vec3) -> Vec3 {
    let s = p * inst.scale;
    Vec3::new(
        inst.cos_rot * s.x + inst.sin_rot * s.z,
        s.y,
        -inst.sin_rot * s.x + inst.cos_rot * s.z,
    ) + Vec3::from_array(inst.position)
}

fn to_object_dir(inst: &GpuInstance, d: Vec3) -> Vec3 {
    Vec3::new(
        inst.cos_rot * d.x - inst.sin_rot * d.z,
        d.y,
        inst.sin_rot * d.x + inst.cos_rot * d.z,
    )
}

fn unorm12(x: f32) -> u32 {
    (x.clamp(0.0, 1.0) * 4095.0 + 0.5).floor() as u32
}

/// The camera's stream flags (`viewport.w`, see [`crate::options::StreamOptions::flags`]).
fn flags(cam: &GpuCamera) -> u32 {
    cam.stream_flags as u32
}

/// A blend's weights rounded to units of 1/[`WEIGHT_ONE`] (see `quantise` in
/// `shaders/cull.wgsl`).
pub fn quantise(weight: [f32; 3]) -> [u32; 3] {
    weight.map(unorm12)
}

/// Blend weights from [`quantise`]d ones, summing to exactly [`WEIGHT_ONE`]: sharpened by `t`
/// (each less that share, the rest scaled back to one; [`tree_sharpen`]), the remainder given
/// to the largest (first on ties); with [`FLAG_NEAREST`] in `flags` the largest alone (see
/// `aspect_weights` in `shaders/cull.wgsl`).
pub fn aspect_weights(quantised: [u32; 3], flags: u32, t: u32) -> [u32; 3] {
    let mut w = quantised;
    let big = largest(w);
    if flags & FLAG_NEAREST != 0 {
        let mut one = [0; 3];
        one[big] = WEIGHT_ONE;
        return one;
    }
    if t > 0 {
        let s = w.map(|x| x.max(t) - t);
        let sum = s[0] + s[1] + s[2];
        w = s.map(|x| x * WEIGHT_ONE / sum);
    }
    let sum = w[0] + w[1] + w[2];
    w[big] = w[big] + WEIGHT_ONE - sum;
    w
}

/// Index of the largest of quantised weights (first on ties): the nearest aspect (see
/// `largest` in `shaders/cull.wgsl`).
fn largest(w: [u32; 3]) -> usize {
    let mut big = 0;
    for a in 1..3 {
        if w[a] > w[big] {
            big = a;
        }
    }
    big
}

/// √3 in f32, as `SQRT3` in `shaders/cull.wgsl`.
const SQRT3: f32 = 1.732_050_8;

/// The class `tree_class` gives a far tree (`FAR_CLASS` in `shaders/common.wgsl`).
pub const FAR_CLASS: u32 = 255;

/// How near a tree is: [`FAR_CLASS`] when far (narrower than its far span, `forward.w` × ε,
/// pixels, seen at the depth of its nearest level-0 corner, and its nearest aspect's parallax
/// within ε), else how many of the sharpening reach's [`REACH_STEPS`] widths it is narrower
/// than (see `tree_class` in `shaders/cull.wgsl`; `v` the object-space view, `nd` that
/// aspect's unit direction).
#[allow(clippy::neg_cmp_op_on_partial_ord)]
fn tree_class(cam: &GpuCamera, c: Vec3, r: f32, v: Vec3, nd: Vec3) -> u32 {
    if flags(cam) & FLAG_FAR_BLEND != 0 {
        return 0;
    }
    let m = &cam.view_proj;
    let w = if m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 {
        m[0][3] * c.x + m[1][3] * c.y + m[2][3] * c.z + m[3][3] - SQRT3 * r
    } else {
        m[3][3]
    };
    if w <= 0.0 {
        return 0;
    }
    let fy = m[0][1] * m[0][1] + m[1][1] * m[1][1] + m[2][1] * m[2][1];
    let half = cam.viewport[1] * 0.5;
    let d = 2.0 * r * half;
    let e = cam.epsilon * w;
    let span = cam.far_span * e;
    let s2 = d * d * fy;
    let reach = ((flags(cam) >> REACH_SHIFT) & REACH_MASK) as f32;
    if s2 < span * span {
        let vv = v.x * v.x + v.y * v.y + v.z * v.z;
        let cv = nd.x * v.x + nd.y * v.y + nd.z * v.z;
        if s2 * (vv - cv * cv) < e * e * vv {
            return FAR_CLASS;
        }
        return if reach > 1.0 { REACH_STEPS } else { 0 };
    }
    // The step widths grow with i: count from the widest down to the first the tree is not
    // narrower than.
    let mut steps = 0;
    if reach > 1.0 {
        for i in (1..=REACH_STEPS).rev() {
            let k = span * (1.0 + (reach - 1.0) * (i as f32 * REACH_STEP));
            // Negated as in the WGSL, so that a NaN counts as not narrower on both sides.
            if !(s2 < k * k) {
                break;
            }
            steps += 1;
        }
    }
    steps
}

/// The aspect sharpening of a tree of class `class` (`tree_class`, not [`FAR_CLASS`]), in
/// units of 1/[`WEIGHT_ONE`]: the flags' own, raised towards [`SHARPEN_MAX`] by one
/// [`REACH_STEPS`]-th of the way per step (see `tree_sharpen` in `shaders/cull.wgsl`).
pub fn tree_sharpen(flags: u32, class: u32) -> u32 {
    let t = (flags >> SHARPEN_SHIFT) & SHARPEN_MASK;
    if t >= SHARPEN_MAX {
        return t;
    }
    t + (SHARPEN_MAX - t) * class.min(REACH_STEPS) / REACH_STEPS
}

fn xyz(v: [f32; 4]) -> Vec3 {
    Vec3::new(v[0], v[1], v[2])
}

/// The farthest the frame's wind moves any point of instance `id` now (metres;
/// `wind_reach_now` of `wind_height` in the shaders).
fn wind_reach(cam: &GpuCamera, inst: &GpuInstance, sp: &GpuSpecies, id: u32) -> f32 {
    let tree = forest_format::wind::SwayedTree::from_sphere(
        Vec3::from(inst.position),
        inst.scale,
        sp.sphere[1],
        sp.sphere[3],
        id,
    );
    forest_format::wind::reach_now(&cam.wind_uniform(), &tree)
}

fn visible(cam: &GpuCamera, inst: &GpuInstance, sp: &GpuSpecies, id: u32) -> bool {
    let c = to_world(inst, xyz(sp.sphere));
    let r = sp.sphere[3] * inst.scale + wind_reach(cam, inst, sp, id);
    cam.planes
        .iter()
        .all(|pl| pl[0] * c.x + pl[1] * c.y + pl[2] * c.z + pl[3] >= -r)
        && crate::shadow::casts_into(cam, c, r)
}

/// Level-0 quads of one tree (see `tree_quads` in `shaders/cull.wgsl`).
fn tree_quads(t: &SceneTables, cam: &GpuCamera, inst_id: u32) -> Vec<Quad> {
    let inst = &t.instances[inst_id as usize];
    let sp = &t.species[inst.species as usize];
    let centre = to_world(inst, xyz(sp.sphere));
    // Trees drawn as geometry alone (the hybrid method) have no quads.
    if crate::forms::quad_share(
        cam.forms,
        xyz(cam.form_eye).distance(centre),
        sp.switch_unit * inst.scale,
        inst_id,
    ) == 0
    {
        return Vec::new();
    }
    let eye_obj = to_object_dir(inst, Vec3::from_array(cam.eye) - centre);
    let base = sp.dir_base as usize;
    let dirs: Vec<Vec3> = t.frames[base..base + sp.directions as usize]
        .iter()
        .map(|f| xyz(f.dir))
        .collect();
    let tris = |from: u32, count: u32| -> Vec<[u32; 3]> {
        t.tris[from as usize..(from + count) as usize]
            .iter()
            .map(|x| [x[0], x[1], x[2]])
            .collect()
    };
    let upper = tris(sp.tri_base, sp.tri_count);
    let lower = tris(sp.tri_base + sp.tri_count, sp.lower_tri_count);
    let bl = blend(&dirs, &upper, &lower, eye_obj);
    let q = quantise(bl.weight);
    let nearest = dirs[bl.index[largest(q)] as usize];
    let class = tree_class(cam, centre, sp.sphere[3] * inst.scale, eye_obj, nearest);
    let far = class == FAR_CLASS;
    let w12 = aspect_weights(
        q,
        flags(cam) | if far { FLAG_NEAREST } else { 0 },
        tree_sharpen(flags(cam), class),
    );
    if far && sp.slabs > 1 && flags(cam) & FLAG_FAR_SLABS == 0 {
        // One quad for all the slabs of the nearest aspect, on the front-most slab's root.
        let a = (0..3).rev().find(|&a| w12[a] > 0).unwrap_or(0);
        let layer = |slab: u32| (sp.layer_base + bl.index[a] * sp.slabs + slab) as usize;
        return (0..sp.slabs)
            .map(|slab| t.roots[layer(slab)])
            .find(|&r| r != u32::MAX)
            .map(|root| Quad {
                instance: inst_id,
                node: root,
                pos: Quad::COMPOSITE_POS,
                dir_weight: Quad::pack_dir(bl.index[a], 0, WEIGHT_ONE),
            })
            .into_iter()
            .collect();
    }
    let mut out = Vec::new();
    for s in 0..sp.slabs {
        let slab = sp.slabs - 1 - s;
        let mut acc = 0u32;
        for (a, &w) in w12.iter().enumerate() {
            if w == 0 {
                continue;
            }
            let lo = acc;
            acc += w;
            let root = t.roots[(sp.layer_base + bl.index[a] * sp.slabs + slab) as usize];
            if root == u32::MAX {
                continue;
            }
            out.push(Quad {
                instance: inst_id,
                node: root,
                pos: Quad::pack_pos(0, 0, 0, slab),
                dir_weight: Quad::pack_dir(bl.index[a], lo, acc),
            });
        }
    }
    out
}

fn clip_corner(t: &SceneTables, cam: &GpuCamera, q: &Quad, depth: [u8; 4], c: u32) -> Vec4 {
    let size = 1.0 / (1u32 << q.level()) as f32;
    let u = (q.x() as f32 + (c & 1) as f32) * size;
    let v = (q.y() as f32 + (c >> 1) as f32) * size;
    let tt = f32::from(depth[c as usize]) / 255.0;
    clip_at(t, cam, q, u, v, tt)
}

/// Clip-space position of image point `(u, v)` at slab depth `tt` of a quad's layer.
fn clip_at(t: &SceneTables, cam: &GpuCamera, q: &Quad, u: f32, v: f32, tt: f32) -> Vec4 {
    let w = world_at(t, q, u, v, tt);
    let m = cam.view_proj.map(Vec4::from_array);
    m[0] * w.x + m[1] * w.y + m[2] * w.z + m[3]
}

/// World position of image point `(u, v)` at slab depth `tt` of a quad's layer.
fn world_at(t: &SceneTables, q: &Quad, u: f32, v: f32, tt: f32) -> Vec3 {
    let inst = &t.instances[q.instance as usize];
    let sp = &t.species[inst.species as usize];
    let f = &t.frames[(sp.dir_base + q.dir()) as usize];
    let r = sp.sphere[3];
    let d = (q.slab() as f32 + tt) / sp.slabs as f32;
    let p = xyz(sp.sphere)
        + xyz(f.right) * ((2.0 * u - 1.0) * r)
        + xyz(f.up) * ((1.0 - 2.0 * v) * r)
        + xyz(f.dir) * ((1.0 - 2.0 * d) * r);
    to_world(inst, p)
}

fn edge_long(cam: &GpuCamera, a: Vec4, b: Vec4) -> bool {
    let sx = cam.viewport[0] * 0.5;
    let sy = cam.viewport[1] * 0.5;
    let dx = (a.x * b.w - b.x * a.w) * sx;
    let dy = (a.y * b.w - b.y * a.w) * sy;
    let lim = cam.epsilon * a.w * b.w;
    dx * dx + dy * dy > lim * lim
}

/// 0: keep; else 1 + extra quads (see `wants` in `shaders/refine.wgsl`).
fn wants(t: &SceneTables, cam: &GpuCamera, q: &Quad) -> u32 {
    // A far tree's composited quad is never refined (the GPU's steps never visit one).
    if q.composite() {
        return 0;
    }
    let node = t.nodes[q.node as usize];
    let mask = u32::from(node.mask());
    if mask == 0 {
        return 0;
    }
    let clip: Vec<Vec4> = (0..4)
        .map(|c| clip_corner(t, cam, q, node.depth, c))
        .collect();
    let behind = clip.iter().filter(|c| c.w <= 0.0).count();
    if behind == 4 {
        return 0;
    }
    let mut long = behind > 0
        || edge_long(cam, clip[0], clip[1])
        || edge_long(cam, clip[1], clip[3])
        || edge_long(cam, clip[3], clip[2])
        || edge_long(cam, clip[2], clip[0]);
    if !long && flags(cam) & FLAG_DEPTH_ERROR != 0 {
        long = error_long(t, cam, q, node);
    }
    if long && !quad_outside(t, cam, q) {
        mask.count_ones()
    } else {
        0
    }
}

/// Whether everything a quad and its descendants may draw lies outside one of the view's
/// side planes: the sphere around its image rectangle over the slab's whole depth, grown by
/// half the quad's width and the wind's reach (see `quad_outside` in
/// `shaders/quad_geometry.wgsl`). Such a quad is kept as it is, not refined.
pub fn quad_outside(t: &SceneTables, cam: &GpuCamera, q: &Quad) -> bool {
    let inst = &t.instances[q.instance as usize];
    let sp = &t.species[inst.species as usize];
    let size = 1.0 / (1u32 << q.level()) as f32;
    let u = (q.x() as f32 + 0.5) * size;
    let v = (q.y() as f32 + 0.5) * size;
    let c = world_at(t, q, u, v, 0.5);
    let r = sp.sphere[3] * inst.scale;
    let slab = 1.0 / sp.slabs as f32;
    let reach = r * ((2.0 * size * size + slab * slab).sqrt() + size)
        + wind_reach(cam, inst, sp, q.instance);
    cam.planes[..4]
        .iter()
        .any(|pl| pl[0] * c.x + pl[1] * c.y + pl[2] * c.z + pl[3] < -reach)
}

/// Whether the node's depth error, as a displacement along its sampling direction at the
/// quad's centre and mean depth, projects longer than ε pixels (see `error_long` in
/// `shaders/quad_geometry.wgsl`); a displacement reaching behind the eye counts as long.
pub fn error_long(t: &SceneTables, cam: &GpuCamera, q: &Quad, node: QuadNode) -> bool {
    let e = ERROR_BOUNDS[usize::from(node.error())];
    if e <= 0.0 {
        return false;
    }
    let sum: u32 = node.depth.iter().map(|&d| u32::from(d)).sum();
    let tc = sum as f32 / 1020.0;
    let size = 1.0 / (1u32 << q.level()) as f32;
    let u = (q.x() as f32 + 0.5) * size;
    let v = (q.y() as f32 + 0.5) * size;
    let a = clip_at(t, cam, q, u, v, tc);
    let b = clip_at(t, cam, q, u, v, tc + e);
    if a.w <= 0.0 || b.w <= 0.0 {
        return true;
    }
    edge_long(cam, a, b)
}

/// Exclusive prefix sums and total.
fn scan(v: &[u32]) -> (Vec<u32>, u32) {
    let mut acc = 0u32;
    let p = v
        .iter()
        .map(|&x| {
            let e = acc;
            acc += x;
            e
        })
        .collect();
    (p, acc)
}

/// Run passes 1 and 2 for a camera with stream capacity `capacity`.
pub fn run(t: &SceneTables, cam: &GpuCamera, capacity: u32) -> Reference {
    run_with(t, cam, capacity, t.max_levels.saturating_sub(1))
}

/// Run pass 1 and `iterations` refinement steps (0: the static impostor).
pub fn run_with(t: &SceneTables, cam: &GpuCamera, capacity: u32, iterations: u32) -> Reference {
    let towards = -Vec3::from_array(cam.forward);
    let mut presort = 0usize;
    let mut best = f32::NEG_INFINITY;
    for (k, d) in t.presort_dirs.iter().enumerate() {
        let c = d[0] * towards.x + d[1] * towards.y + d[2] * towards.z;
        if c > best {
            presort = k;
            best = c;
        }
    }
    let n = t.instances.len();
    let mut r = Reference {
        presort: presort as u32,
        ..Default::default()
    };
    // Pass 1: two lists in presorted order, the composited quads first.
    let mut level0 = Vec::new();
    let mut plain = Vec::new();
    for i in 0..n {
        let id = if n == 0 {
            0
        } else {
            t.presort[presort * n + i]
        };
        let inst = &t.instances[id as usize];
        if visible(cam, inst, &t.species[inst.species as usize], id) {
            r.visible += 1;
            for q in tree_quads(t, cam, id) {
                if q.composite() {
                    level0.push(q);
                } else {
                    plain.push(q);
                }
            }
        }
    }
    r.composites = level0.len() as u32;
    level0.extend(plain);
    let total = level0.len() as u32;
    let skip = total.saturating_sub(capacity);
    r.overflow_cull = skip;
    let mut quads: Vec<Quad> = level0[skip as usize..].to_vec();
    // Pass 2.
    for _ in 0..iterations {
        let want: Vec<u32> = quads.iter().map(|q| wants(t, cam, q)).collect();
        let extra: Vec<u32> = want.iter().map(|&w| w.saturating_sub(1)).collect();
        let (p, total) = scan(&extra);
        let budget = capacity - quads.len() as u32;
        let refined: Vec<bool> = (0..quads.len())
            .map(|i| want[i] > 0 && total - p[i] <= budget)
            .collect();
        r.overflow_refine += (0..quads.len())
            .filter(|&i| want[i] > 0 && !refined[i])
            .count() as u32;
        let mut next = Vec::with_capacity(quads.len() + total as usize);
        for (i, q) in quads.iter().enumerate() {
            if !refined[i] {
                next.push(*q);
                continue;
            }
            let inst = &t.instances[q.instance as usize];
            let node_base = t.species[inst.species as usize].node_base;
            let node = t.nodes[q.node as usize];
            let mut child = node_base + node.first_child();
            for c in 0..4u32 {
                if node.mask() & (1 << c) == 0 {
                    continue;
                }
                next.push(Quad {
                    instance: q.instance,
                    node: child,
                    pos: Quad::pack_pos(
                        q.level() + 1,
                        q.x() * 2 + (c & 1),
                        q.y() * 2 + (c >> 1),
                        q.slab(),
                    ),
                    dir_weight: q.dir_weight,
                });
                child += 1;
            }
        }
        quads = next;
    }
    let levels = t.max_levels.max(1) as usize;
    r.per_level = vec![0; levels];
    for q in &quads {
        r.per_level[q.level() as usize] += 1;
    }
    r.quads = quads;
    r
}
