//! Level-of-detail preparation for the rival methods, done once per species on the CPU:
//!
//! * **Stochastic simplification** (Cook et al. 2007, as in seeds 000/001): leaves (*elements*:
//!   connected alpha-tested triangles) shuffled once; a tree at distance `d` draws the first
//!   `λ·N` of them with `λ = min(1, d0²/d²)^(log_h ½)`, each scaled by the area-preservation
//!   factor `s(r, λ)`, its colour pulled towards the species' mean by `√λ` (contrast
//!   preservation), and faded by size over a band of buffer positions around `λ`.
//! * **Discrete LODs** (seed 004): fewer, larger leaves chosen by k-means to stay evenly spread,
//!   and fewer branches (the smallest branch pieces dropped).
//!
//! Everything here is a pure function with its bounds documented; the WGSL in
//! `shaders/geometry*.wgsl` evaluates [`lambda`], [`area_scale`], [`fade`] and [`lambda_band`]
//! the same way.

use glam::Vec3;
use rayon::prelude::*;

use crate::RefVertex;

/// "No element" (a triangle that is not a leaf, or a branch triangle in leaf numbering).
pub const NONE: u32 = u32::MAX;

pub use forest_format::model::{BANDS, dilate_colour_from, lambda, lambda_band};

/// Area-preservation factor `s = (1 − (1 − r)^(1/λ)) / r` (Cook et al.): how much to enlarge
/// each kept element's area so the object's *visible* area stays the same, where `r` is one
/// element's mean visible area over the object's visible area. `s(r, 1) = 1`; `s → 1/λ` as
/// `r → 0`; `1 ≤ s ≤ 1/λ`.
pub fn area_scale(r: f32, lambda: f32) -> f32 {
    if lambda >= 1.0 {
        return 1.0;
    }
    let r = r.clamp(1e-9, 1.0);
    let s = (1.0 - (1.0 - r).powf(1.0 / lambda.max(1e-9))) / r;
    if s.is_finite() {
        s.clamp(1.0, 1.0 / lambda.max(1e-9))
    } else {
        1.0 / lambda.max(1e-9)
    }
}

/// Size factor in `[0, 1]` of the element at normalised buffer position `u = (rank + ½)/N` for
/// level `λ`: 1 below `λ − R`, 0 above `λ + R`, linear between, with the fading radius
/// `R = min(1 − λ, width·λ)` (so at `λ = 1` every element is whole).
pub fn fade(u: f32, lambda: f32, width: f32) -> f32 {
    let r = (1.0 - lambda).min(width * lambda);
    if r <= 0.0 {
        return if u < lambda { 1.0 } else { 0.0 };
    }
    ((lambda + r - u) / (2.0 * r)).clamp(0.0, 1.0)
}

/// The largest `λ` of band `k`: `2^(−k/2)`.
pub fn band_lambda(k: u32) -> f32 {
    (-(k as f32) / 2.0).exp2()
}

/// Elements a tree of band `k` may need: `⌈min(1, λ_k·(1 + width))·N⌉` (covers the fading band).
pub fn band_elements(k: u32, n: u32, width: f32) -> u32 {
    let f = (band_lambda(k) * (1.0 + width)).min(1.0);
    ((f * n as f32).ceil() as u32).min(n)
}

/// Connected groups of the `member` triangles (sharing a vertex position exactly).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Elements {
    /// Element of each triangle ([`NONE`] for non-members).
    pub of_tri: Vec<u32>,
    /// Area-weighted centroid of each element (object space, metres).
    pub centre: Vec<Vec3>,
    /// Total area of each element (m²).
    pub area: Vec<f32>,
}

impl Elements {
    /// Number of elements.
    pub fn len(&self) -> usize {
        self.centre.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.centre.is_empty()
    }
}

fn tri_area(t: &[Vec3; 3]) -> f32 {
    0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length()
}

/// Group the `member` triangles into connected elements (union-find over exact vertex
/// positions). Elements are numbered in order of their first triangle.
pub fn group_elements(tris: &[[Vec3; 3]], member: &[bool]) -> Elements {
    use std::collections::HashMap;
    let mut parent: Vec<u32> = (0..tris.len() as u32).collect();
    fn find(p: &mut [u32], mut x: u32) -> u32 {
        while p[x as usize] != x {
            p[x as usize] = p[p[x as usize] as usize];
            x = p[x as usize];
        }
        x
    }
    let mut owner: HashMap<[u32; 3], u32> = HashMap::new();
    for (i, t) in tris.iter().enumerate() {
        if !member[i] {
            continue;
        }
        for v in t {
            let key = v.to_array().map(f32::to_bits);
            let o = *owner.entry(key).or_insert(i as u32);
            let (a, b) = (find(&mut parent, o), find(&mut parent, i as u32));
            if a != b {
                parent[a.max(b) as usize] = a.min(b);
            }
        }
    }
    let mut out = Elements {
        of_tri: vec![NONE; tris.len()],
        ..Default::default()
    };
    let mut id_of_root: HashMap<u32, u32> = HashMap::new();
    let mut weighted: Vec<Vec3> = Vec::new();
    for (i, t) in tris.iter().enumerate() {
        if !member[i] {
            continue;
        }
        let root = find(&mut parent, i as u32);
        let next = id_of_root.len() as u32;
        let id = *id_of_root.entry(root).or_insert(next);
        if id as usize == weighted.len() {
            weighted.push(Vec3::ZERO);
            out.area.push(0.0);
        }
        let a = tri_area(t);
        weighted[id as usize] += (t[0] + t[1] + t[2]) / 3.0 * a;
        out.area[id as usize] += a;
        out.of_tri[i] = id;
    }
    out.centre = weighted
        .iter()
        .zip(&out.area)
        .zip(tris_first_vertex(tris, &out.of_tri, weighted.len()))
        .map(|((w, &a), v0)| if a > 0.0 { *w / a } else { v0 })
        .collect();
    out
}

/// First vertex of every element (the centre of a zero-area element).
fn tris_first_vertex(tris: &[[Vec3; 3]], of_tri: &[u32], n: usize) -> Vec<Vec3> {
    let mut v = vec![None; n];
    for (t, &e) in tris.iter().zip(of_tri) {
        if e != NONE && v[e as usize].is_none() {
            v[e as usize] = Some(t[0]);
        }
    }
    v.into_iter().map(|x| x.unwrap_or(Vec3::ZERO)).collect()
}

/// SplitMix64 step.
fn splitmix(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A deterministic uniform permutation of `0..n` (Fisher–Yates with SplitMix64).
pub fn shuffle(n: usize, seed: u64) -> Vec<u32> {
    let mut p: Vec<u32> = (0..n as u32).collect();
    let mut s = seed;
    for i in (1..n).rev() {
        let j = (splitmix(&mut s) % (i as u64 + 1)) as usize;
        p.swap(i, j);
    }
    p
}

/// `k` of the `points` spread evenly: Lloyd's k-means (`iterations` rounds, seeded with a
/// shuffled pick), then the point nearest each cluster mean, without repeats (a point claimed
/// twice goes to the first mean, and the later mean takes its next-nearest free point).
/// Returns sorted indices; `min(k, points.len())` of them. Nearest neighbours come from R*-trees
/// (`rstar`), so a round costs O(n log k), not O(n k): the 63 000 leaves of a 280k-triangle tree
/// took 34 s by brute force.
pub fn even_subset(points: &[Vec3], k: usize, iterations: u32, seed: u64) -> Vec<u32> {
    use rstar::{RTree, primitives::GeomWithData};
    let k = k.min(points.len());
    if k == 0 {
        return Vec::new();
    }
    let order = shuffle(points.len(), seed);
    let mut means: Vec<Vec3> = order[..k].iter().map(|&i| points[i as usize]).collect();
    let indexed = |v: &[Vec3]| -> Vec<GeomWithData<[f32; 3], usize>> {
        v.iter()
            .enumerate()
            .map(|(i, p)| GeomWithData::new(p.to_array(), i))
            .collect()
    };
    for _ in 0..iterations {
        let tree = RTree::bulk_load(indexed(&means));
        let assign: Vec<usize> = points
            .par_iter()
            .map(|p| tree.nearest_neighbor(&p.to_array()).map_or(0, |m| m.data))
            .collect();
        let mut sum = vec![(Vec3::ZERO, 0u32); k];
        for (p, &a) in points.iter().zip(&assign) {
            sum[a].0 += *p;
            sum[a].1 += 1;
        }
        for (m, (s, c)) in means.iter_mut().zip(sum) {
            if c > 0 {
                *m = s / c as f32;
            }
        }
    }
    let mut free = RTree::bulk_load(indexed(points));
    let mut out: Vec<u32> = means
        .iter()
        .filter_map(|m| free.pop_nearest_neighbor(&m.to_array()))
        .map(|p| p.data as u32)
        .collect();
    out.sort_unstable();
    out
}

/// `r` of [`area_scale`]: one leaf's mean visible area (half its area: the mean projected area
/// of a flat shape over all directions) over the leaves' projected coverage, averaged over
/// five views (four horizontal, one from above) rasterised on a `grid²` raster. In `(0, 1]`;
/// 1 when there are no leaves.
pub fn visible_area_ratio(tris: &[[Vec3; 3]], leaves: &Elements, grid: u32) -> f32 {
    if leaves.is_empty() {
        return 1.0;
    }
    let mean_area = leaves.area.iter().sum::<f32>() / leaves.len() as f32;
    let dirs = [Vec3::X, Vec3::Z, -Vec3::X, -Vec3::Z, Vec3::Y];
    let leaf_tris: Vec<&[Vec3; 3]> = tris
        .iter()
        .zip(&leaves.of_tri)
        .filter(|(_, e)| **e != NONE)
        .map(|(t, _)| t)
        .collect();
    let coverage: f32 = dirs
        .par_iter()
        .map(|&d| {
            let f = forest_format::slab::DirectionFrame::new(d);
            let proj: Vec<[glam::Vec2; 3]> = leaf_tris
                .iter()
                .map(|t| t.map(|p| glam::Vec2::new(p.dot(f.right), p.dot(f.up))))
                .collect();
            let (mut lo, mut hi) = (
                glam::Vec2::splat(f32::INFINITY),
                glam::Vec2::splat(-f32::INFINITY),
            );
            for t in &proj {
                for p in t {
                    lo = lo.min(*p);
                    hi = hi.max(*p);
                }
            }
            let cell = ((hi - lo).max_element() / grid as f32).max(1e-6);
            let g = grid as usize + 1;
            let mut covered = vec![false; g * g];
            for t in &proj {
                let (a, b) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
                let x0 = ((a.x - lo.x) / cell).floor() as usize;
                let y0 = ((a.y - lo.y) / cell).floor() as usize;
                let x1 = (((b.x - lo.x) / cell).ceil() as usize).min(g - 1);
                let y1 = (((b.y - lo.y) / cell).ceil() as usize).min(g - 1);
                for y in y0..=y1 {
                    for x in x0..=x1 {
                        let p = lo + glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5) * cell;
                        if inside(t, p) {
                            covered[y * g + x] = true;
                        }
                    }
                }
            }
            covered.iter().filter(|c| **c).count() as f32 * cell * cell
        })
        .sum::<f32>()
        / dirs.len() as f32;
    (0.5 * mean_area / coverage.max(1e-12)).clamp(1e-9, 1.0)
}

fn inside(t: &[glam::Vec2; 3], p: glam::Vec2) -> bool {
    let e = |a: glam::Vec2, b: glam::Vec2| (b - a).perp_dot(p - a);
    let (d0, d1, d2) = (e(t[0], t[1]), e(t[1], t[2]), e(t[2], t[0]));
    (d0 >= 0.0 && d1 >= 0.0 && d2 >= 0.0) || (d0 <= 0.0 && d1 <= 0.0 && d2 <= 0.0)
}

/// The vertex data of one species for the geometry-based methods.
#[derive(Clone, Debug, Default)]
pub struct LodSet {
    /// LOD 0, the full model: branch triangles first, then leaves in shuffled order; each leaf
    /// vertex's `element` is its leaf's rank in that order, [`NONE`] for branches.
    pub lod0: Vec<RefVertex>,
    /// Vertices of branch triangles at the start of `lod0`.
    pub branch_vertices: u32,
    /// `leaf_end[k]`: vertices of `lod0` through the leaf of rank `k` (monotone, last = len).
    pub leaf_end: Vec<u32>,
    /// Centre of the leaf of each rank.
    pub leaf_centre: Vec<Vec3>,
    /// `r` of [`area_scale`].
    pub r: f32,
    /// LODs 1 and 2: fewer branches and fewer, larger, evenly spread leaves.
    pub lods: [Vec<RefVertex>; 2],
}

/// Parameters of [`build_lods`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LodParams {
    /// Fraction of leaves kept by LOD 1 and LOD 2.
    pub leaf_fraction: [f32; 2],
    /// Fraction of the branch area kept by LOD 1 and LOD 2 (the largest pieces first).
    pub branch_fraction: [f32; 2],
    /// Shuffle / k-means seed.
    pub seed: u64,
}

impl Default for LodParams {
    fn default() -> Self {
        Self {
            leaf_fraction: [0.25, 1.0 / 16.0],
            branch_fraction: [0.9, 0.6],
            seed: 0x5eed,
        }
    }
}

/// Scale an element's vertices about `centre` by `k` (linear).
fn scaled(v: &RefVertex, centre: Vec3, k: f32) -> RefVertex {
    let p = Vec3::from_array(v.pos);
    RefVertex {
        pos: (centre + (p - centre) * k).to_array(),
        ..*v
    }
}

/// Build the LOD set of a species from its reference vertices (three per triangle, as
/// [`crate::reference_vertices`] returns them) and whether each triangle is a leaf.
pub fn build_lods(vertices: &[RefVertex], leaf: &[bool], params: &LodParams) -> LodSet {
    let tris: Vec<[Vec3; 3]> = vertices
        .chunks_exact(3)
        .map(|c| [0, 1, 2].map(|k| Vec3::from_array(c[k].pos)))
        .collect();
    assert_eq!(tris.len(), leaf.len(), "one leaf flag per triangle");
    let leaves = group_elements(&tris, leaf);
    let not_leaf: Vec<bool> = leaf.iter().map(|l| !l).collect();
    let branches = group_elements(&tris, &not_leaf);
    let n = leaves.len();
    // rank[element] = position in the shuffled order.
    let order = shuffle(n, params.seed);
    let mut rank = vec![0u32; n];
    for (k, &e) in order.iter().enumerate() {
        rank[e as usize] = k as u32;
    }
    let tri_verts = |t: usize| &vertices[3 * t..3 * t + 3];
    let mut set = LodSet {
        r: visible_area_ratio(&tris, &leaves, 256),
        ..Default::default()
    };
    for (t, _) in leaf.iter().enumerate().filter(|(_, l)| !**l) {
        set.lod0.extend(tri_verts(t).iter().map(|v| RefVertex {
            element: NONE,
            ..*v
        }));
    }
    set.branch_vertices = set.lod0.len() as u32;
    let mut leaf_tris: Vec<(u32, usize)> = (0..tris.len())
        .filter(|&t| leaf[t])
        .map(|t| (rank[leaves.of_tri[t] as usize], t))
        .collect();
    leaf_tris.sort_unstable();
    set.leaf_end = vec![set.branch_vertices; n];
    for &(k, t) in &leaf_tris {
        set.lod0
            .extend(tri_verts(t).iter().map(|v| RefVertex { element: k, ..*v }));
        set.leaf_end[k as usize] = set.lod0.len() as u32;
    }
    set.leaf_centre = order.iter().map(|&e| leaves.centre[e as usize]).collect();

    // Branch pieces by area, largest first.
    let mut pieces: Vec<u32> = (0..branches.len() as u32).collect();
    pieces.sort_by(|a, b| branches.area[*b as usize].total_cmp(&branches.area[*a as usize]));
    let total_branch: f32 = branches.area.iter().sum();
    for (l, lod) in set.lods.iter_mut().enumerate() {
        let mut keep_piece = vec![false; branches.len()];
        let mut acc = 0.0;
        for &p in &pieces {
            if acc < params.branch_fraction[l] * total_branch || acc == 0.0 {
                keep_piece[p as usize] = true;
                acc += branches.area[p as usize];
            }
        }
        let k = ((n as f32 * params.leaf_fraction[l]).round() as usize).clamp(n.min(1), n);
        let keep = even_subset(&leaves.centre, k, 8, params.seed ^ l as u64);
        let mut kept = vec![false; n];
        keep.iter().for_each(|&e| kept[e as usize] = true);
        let grow = area_scale(set.r, k as f32 / n.max(1) as f32).sqrt();
        for t in 0..tris.len() {
            if leaf[t] {
                let e = leaves.of_tri[t] as usize;
                if kept[e] {
                    lod.extend(tri_verts(t).iter().map(|v| RefVertex {
                        element: NONE,
                        ..scaled(v, leaves.centre[e], grow)
                    }));
                }
            } else if keep_piece[branches.of_tri[t] as usize] {
                lod.extend(tri_verts(t).iter().map(|v| RefVertex {
                    element: NONE,
                    ..*v
                }));
            }
        }
    }
    set
}

/// Mean albedo (linear RGB) of a species' leaves, the `c̄` of contrast preservation (applied to
/// the albedo, before the run-time light): over the leaf triangles of `lod0` (area-weighted),
/// the material's mean texture colour (over texels with alpha ≥ ½) × Kd. Black when there are
/// no leaves.
pub fn mean_leaf_colour(mesh: &crate::Mesh, lod0: &[RefVertex]) -> Vec3 {
    let table = forest_format::shading::srgb_decode_table();
    let albedo: Vec<Vec3> = mesh
        .materials
        .iter()
        .map(|m| {
            let tex = m.colour.map(|c| {
                let t = &mesh.textures[c];
                let (mut sum, mut n) = (Vec3::ZERO, 0u32);
                for p in t.rgba.chunks_exact(4) {
                    if !t.has_alpha || p[3] >= 128 {
                        sum += Vec3::new(
                            table[p[0] as usize],
                            table[p[1] as usize],
                            table[p[2] as usize],
                        );
                        n += 1;
                    }
                }
                if n > 0 { sum / n as f32 } else { Vec3::ONE }
            });
            m.kd * tex.unwrap_or(Vec3::ONE)
        })
        .collect();
    let (mut sum, mut area) = (Vec3::ZERO, 0.0);
    for t in lod0.chunks_exact(3).filter(|t| t[0].element != NONE) {
        let p = [0, 1, 2].map(|k| Vec3::from_array(t[k].pos));
        let a = tri_area(&p);
        sum += albedo[t[0].material as usize] * a;
        area += a;
    }
    if area > 0.0 { sum / area } else { Vec3::ZERO }
}

/// Elevations (degrees above the horizon) of the billboard images, seed 004's four.
pub const BILLBOARD_ELEVATIONS: [f32; forest_format::model::BILLBOARDS as usize] =
    [0.0, 30.0, 60.0, 90.0];

/// A billboard's two images: albedo with coverage, and its surface attributes.
pub struct BillboardImage {
    /// RGBA8, straight alpha, sRGB albedo; blank texels take the colour of the nearest covered
    /// one so filtering does not darken edges.
    pub albedo: image::RgbaImage,
    /// RGBA8, straight (not premultiplied), linear: the hemispherical octahedral code of the
    /// normal in the image's frame in R and G ([`forest_format::shading::hemi_oct_encode`]),
    /// sky visibility in B, translucency in A; dilated like the albedo.
    pub surface: image::RgbaImage,
}

/// Billboard images of a model: one ray-traced view (the bake's tracer, one slab) per
/// [`BILLBOARD_ELEVATIONS`] entry, seen from azimuth +Z, framing the bounding sphere, each
/// `resolution²`, with `sky` the sky visibility of the mesh's triangles
/// ([`crate::sky::triangle_sky`]). They hold no light: the renderer lights them at run time.
/// Image x runs along the view frame's `right`, y down its `up`
/// ([`forest_format::slab::DirectionFrame`]).
pub fn billboard_images(
    mesh: &crate::Mesh,
    sky: &[crate::sky::TriangleSky],
    resolution: u32,
    spp: u32,
) -> Vec<BillboardImage> {
    use forest_format::shading::{srgb_decode_table, srgb_encode};
    let scene = crate::trace::Scene::new(mesh);
    let frames: Vec<_> = BILLBOARD_ELEVATIONS
        .iter()
        .map(|e| {
            let e = e.to_radians();
            forest_format::slab::DirectionFrame::new(Vec3::new(0.0, e.sin(), e.cos()))
        })
        .collect();
    let setup = crate::ldi::SlabSetup {
        sphere: crate::bounding_sphere(mesh),
        frames: &frames,
        slabs: 1,
        resolution,
        spp,
    };
    let images = crate::ldi::trace_layers(&scene, sky, &setup, &|_, _| {});
    let table = srgb_decode_table();
    let n = (resolution * resolution) as usize;
    images
        .rgba
        .chunks_exact(4 * n)
        .zip(images.surface.chunks_exact(4 * n))
        .map(|(layer, surface)| {
            // Unpremultiply in linear space.
            let mut img = image::RgbaImage::from_fn(resolution, resolution, |x, y| {
                let i = 4 * (y * resolution + x) as usize;
                let p = &layer[i..i + 4];
                let a = f32::from(p[3]) / 255.0;
                if a <= 0.0 {
                    return image::Rgba([0, 0, 0, 0]);
                }
                let c =
                    |v: u8| (srgb_encode((table[v as usize] / a).min(1.0)) * 255.0).round() as u8;
                image::Rgba([c(p[0]), c(p[1]), c(p[2]), p[3]])
            });
            dilate_colour(&mut img);
            // Unpremultiply the surface attributes (linear).
            let mut surf = image::RgbaImage::from_fn(resolution, resolution, |x, y| {
                let i = 4 * (y * resolution + x) as usize;
                let a = layer[i + 3];
                if a == 0 {
                    return image::Rgba([0, 0, 0, 0]);
                }
                let c = |v: u8| ((f32::from(v) / f32::from(a)).min(1.0) * 255.0).round() as u8;
                let p = &surface[i..i + 4];
                image::Rgba([c(p[0]), c(p[1]), c(p[2]), c(p[3])])
            });
            // The dilation copies covered neighbours' values into blank texels; the coverage
            // the shader reads is the albedo image's, so the surface's alpha channel (its
            // translucency) is restored afterwards from the dilated copy of itself.
            let keep_alpha: Vec<u8> = surf.pixels().map(|p| p[3]).collect();
            let cover: Vec<u8> = img.pixels().map(|p| p[3]).collect();
            for (p, &a) in surf.pixels_mut().zip(&cover) {
                p[3] = a;
            }
            dilate_colour(&mut surf);
            for ((p, &t), &a) in surf.pixels_mut().zip(&keep_alpha).zip(&cover) {
                p[3] = if a > 0 { t } else { 0 };
            }
            BillboardImage {
                albedo: img,
                surface: surf,
            }
        })
        .collect()
}

/// Give blank texels (alpha 0) the colour of a covered neighbour, ring by ring, so that
/// bilinear filtering and mip-mapping at silhouettes average only real colours.
pub fn dilate_colour(img: &mut image::RgbaImage) {
    dilate_colour_from(img, 1);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lambda_matches_its_definition() {
        // h = ½: λ = b = d0²/d².
        assert_eq!(lambda(5.0, 10.0, 0.5), 1.0);
        assert!((lambda(20.0, 10.0, 0.5) - 0.25).abs() < 1e-6);
        // λ = ½ where b = h, for any h.
        for h in [0.3f32, 0.5, 0.7, 0.9] {
            let d = 10.0 / h.sqrt();
            assert!((lambda(d, 10.0, h) - 0.5).abs() < 1e-5, "h {h}");
        }
        // Monotone in d.
        let mut last = 1.0;
        for i in 1..100 {
            let l = lambda(i as f32, 10.0, 0.7);
            assert!(l <= last && l > 0.0);
            last = l;
        }
    }

    #[test]
    fn area_scale_has_its_limits() {
        assert_eq!(area_scale(0.01, 1.0), 1.0);
        // r → 0: s → 1/λ.
        assert!((area_scale(1e-6, 0.25) - 4.0).abs() < 1e-2);
        // r = 1 (one element covers everything): nothing to add.
        assert!((area_scale(1.0, 0.25) - 1.0).abs() < 1e-6);
        // Closed form at r = ½, λ = ½: (1 − ¼)/½ = 1.5.
        assert!((area_scale(0.5, 0.5) - 1.5).abs() < 1e-6);
        for l in [0.9f32, 0.5, 0.1, 0.01] {
            let s = area_scale(0.001, l);
            assert!((1.0..=1.0 / l + 1e-3).contains(&s), "λ {l}: s {s}");
        }
    }

    #[test]
    fn fade_is_whole_below_and_gone_above_the_band() {
        assert_eq!(fade(0.999, 1.0, 0.1), 1.0);
        let (l, w) = (0.5, 0.1);
        assert_eq!(fade(0.44, l, w), 1.0);
        assert_eq!(fade(0.56, l, w), 0.0);
        assert!((fade(0.5, l, w) - 0.5).abs() < 1e-6);
        // Every element a band may need is within its drawn count.
        for k in 0..BANDS {
            let n = 1000;
            let drawn = band_elements(k, n, w);
            let lam = band_lambda(k);
            assert_eq!(lambda_band(lam * 0.99), k);
            for rank in drawn..n {
                let u = (rank as f32 + 0.5) / n as f32;
                assert_eq!(fade(u, lam, w), 0.0, "band {k} rank {rank}");
            }
        }
        assert_eq!(lambda_band(1.0), 0);
        assert_eq!(lambda_band(0.5), 2);
        assert_eq!(lambda_band(1e-9), BANDS - 1);
    }

    fn quad(c: Vec3, s: f32) -> [[Vec3; 3]; 2] {
        let p = [
            c + Vec3::new(-s, -s, 0.0),
            c + Vec3::new(s, -s, 0.0),
            c + Vec3::new(s, s, 0.0),
            c + Vec3::new(-s, s, 0.0),
        ];
        [[p[0], p[1], p[2]], [p[0], p[2], p[3]]]
    }

    #[test]
    fn elements_are_connected_groups_with_centres_and_areas() {
        let mut tris = Vec::new();
        tris.extend(quad(Vec3::new(0.0, 0.0, 0.0), 0.5));
        tris.extend(quad(Vec3::new(3.0, 1.0, 0.0), 1.0));
        tris.push([Vec3::ZERO, Vec3::X, Vec3::Y]); // not a member
        let member = [true, true, true, true, false];
        let e = group_elements(&tris, &member);
        assert_eq!(e.len(), 2);
        assert_eq!(e.of_tri, vec![0, 0, 1, 1, NONE]);
        assert!((e.area[0] - 1.0).abs() < 1e-6 && (e.area[1] - 4.0).abs() < 1e-6);
        assert!(e.centre[1].distance(Vec3::new(3.0, 1.0, 0.0)) < 1e-5);
    }

    #[test]
    fn dilation_fills_blank_texels_from_covered_ones_and_keeps_alpha() {
        let mut img = image::RgbaImage::from_pixel(8, 8, image::Rgba([0, 0, 0, 0]));
        img.put_pixel(2, 2, image::Rgba([200, 100, 50, 255]));
        dilate_colour(&mut img);
        assert!(
            img.pixels()
                .all(|p| p[0] == 200 && p[1] == 100 && p[2] == 50)
        );
        assert_eq!(img.pixels().filter(|p| p[3] > 0).count(), 1);
    }

    #[test]
    fn shuffle_is_a_deterministic_permutation() {
        let p = shuffle(1000, 7);
        let mut s = p.clone();
        s.sort_unstable();
        assert_eq!(s, (0..1000).collect::<Vec<u32>>());
        assert_eq!(p, shuffle(1000, 7));
        assert_ne!(p, shuffle(1000, 8));
        assert_ne!(p, s, "shuffled");
    }

    #[test]
    fn even_subset_covers_a_grid_better_than_chance() {
        // 32×32 grid of unit spacing; 16 points should leave no grid point far away.
        let pts: Vec<Vec3> = (0..1024)
            .map(|i| Vec3::new((i % 32) as f32, (i / 32) as f32, 0.0))
            .collect();
        let worst = |sel: &[u32]| {
            pts.iter()
                .map(|p| {
                    sel.iter()
                        .map(|&s| pts[s as usize].distance(*p))
                        .fold(f32::INFINITY, f32::min)
                })
                .fold(0.0f32, f32::max)
        };
        let even = even_subset(&pts, 16, 10, 3);
        assert_eq!(even.len(), 16);
        let mut dedup = even.clone();
        dedup.dedup();
        assert_eq!(dedup.len(), 16, "no repeats");
        let random: Vec<u32> = shuffle(1024, 3)[..16].to_vec();
        // A perfect 4×4 layout leaves every point within √2·4 ≈ 5.7 of a pick.
        assert!(
            worst(&even) < 7.5,
            "k-means worst distance {}",
            worst(&even)
        );
        assert!(worst(&even) < worst(&random), "better than a random pick");
    }

    #[test]
    fn visible_area_ratio_of_one_square_is_half() {
        // One unit square seen face-on from ±Z covers 1 m², edge-on from ±X and from above 0:
        // the raster's coverage is 2/5 m² on average; mean visible area ½ → r = 1 (clamped).
        // Two squares far apart: r is half that of one.
        let mut tris = Vec::new();
        tris.extend(quad(Vec3::ZERO, 0.5));
        tris.extend(quad(Vec3::new(0.0, 0.0, 0.0) + Vec3::Z * 5.0, 0.5));
        let e = group_elements(&tris, &[true; 4]);
        let r = visible_area_ratio(&tris, &e, 256);
        // From ±Z the two squares overlap exactly (1 m²); from ±X/above both are edge-on
        // lines (≈ a raster row each): coverage ≈ 2/5 m², r ≈ ½·1/(2/5) clamped to 1.
        assert!(r > 0.9, "r {r}");
        // Spread 16 squares in a plane facing Z: coverage from ±Z is 16 m² → r small.
        let mut tris = Vec::new();
        for i in 0..16 {
            tris.extend(quad(
                Vec3::new((i % 4) as f32 * 2.0, (i / 4) as f32 * 2.0, 0.0),
                0.5,
            ));
        }
        let e = group_elements(&tris, &[true; 32]);
        let r16 = visible_area_ratio(&tris, &e, 256);
        assert!(r16 < r / 4.0, "r16 {r16} vs r {r}");
    }

    fn vertices(tris: &[[Vec3; 3]]) -> Vec<RefVertex> {
        tris.iter()
            .flat_map(|t| {
                t.map(|p| RefVertex {
                    pos: p.to_array(),
                    ..Default::default()
                })
            })
            .collect()
    }

    #[test]
    fn lods_keep_branches_first_and_shuffle_leaves() {
        let mut tris = Vec::new();
        // A big and a small branch piece.
        tris.extend(quad(Vec3::new(0.0, 0.0, 9.0), 2.0));
        tris.extend(quad(Vec3::new(0.0, 0.0, -9.0), 0.1));
        let mut leaf = vec![false; 4];
        for i in 0..64 {
            tris.extend(quad(Vec3::new((i % 8) as f32, (i / 8) as f32, 0.0), 0.3));
            leaf.extend([true, true]);
        }
        let v = vertices(&tris);
        let set = build_lods(&v, &leaf, &LodParams::default());
        assert_eq!(set.lod0.len(), v.len(), "LOD 0 is every triangle");
        assert_eq!(set.branch_vertices, 12);
        assert!(set.lod0[..12].iter().all(|v| v.element == NONE));
        assert_eq!(set.leaf_end.len(), 64);
        assert_eq!(*set.leaf_end.last().unwrap() as usize, v.len());
        assert!(set.leaf_end.windows(2).all(|w| w[1] == w[0] + 6));
        // Ranks ascend through LOD 0 and each rank's vertices sit around its centre.
        for (i, x) in set.lod0[12..].iter().enumerate() {
            assert_eq!(x.element as usize, i / 6);
            let c = set.leaf_centre[x.element as usize];
            assert!(Vec3::from_array(x.pos).distance(c) < 0.5);
        }
        // LOD 1: a quarter of the leaves, larger; only the big branch piece (90 % of area).
        let leaves1 = (set.lods[0].len() - 6) / 6;
        assert_eq!(leaves1, 16);
        let leaves2 = (set.lods[1].len() - 6) / 6;
        assert_eq!(leaves2, 4);
        let area = |v: &[RefVertex]| -> f32 {
            v.chunks_exact(3)
                .map(|c| tri_area(&[0, 1, 2].map(|k| Vec3::from_array(c[k].pos))))
                .sum()
        };
        let a0 = area(&set.lod0[12..]);
        let a1 = area(&set.lods[0][6..]);
        assert!(
            a1 > a0 / 4.0 * 1.01 && a1 <= a0 * 1.001,
            "leaf area {a0} → {a1}"
        );
    }
}
