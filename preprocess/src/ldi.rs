//! Ray tracing the slab images (layered depth images) of one model.
//!
//! For every direction, pixel and jittered sample, one ray enters the bounding sphere at its
//! front (sphere depth 0) and runs along `−dir`. Its first solid hit in each slab gives what
//! the run-time light needs, averaged into that slab's pixel: premultiplied albedo =
//! Σ albedo / spp, alpha = hits / spp, depth = mean sphere depth of the hits, and the surface
//! attributes (normal facing the ray, sky visibility from [`crate::sky`], translucency) as
//! coverage-weighted means stored premultiplied. No light is traced. Per sample the hits are opaque
//! (alpha-tested), so front-to-back compositing within a slab reduces to taking its first hit;
//! partial coverage comes from the samples.

use crate::sampling::{hash, unit};
use std::sync::atomic::{AtomicU64, Ordering};

use forest_format::shading::Surface;
use forest_format::shading::{hemi_oct_encode, srgb_decode_table, srgb_encode};
use forest_format::slab::{DirectionFrame, Sphere};
use glam::{Vec2, Vec3};
use rayon::prelude::*;

use crate::trace::Scene;

/// The traced slab images of all layers (`layer = direction·slabs + slab`).
#[derive(Clone, Debug, PartialEq)]
pub struct SlabImages {
    /// Side in pixels.
    pub resolution: u32,
    /// Number of layers.
    pub layers: u32,
    /// RGBA8 per layer pixel: premultiplied, sRGB-encoded albedo; linear alpha.
    pub rgba: Vec<u8>,
    /// RGBA8 per layer pixel, linear and premultiplied by the alpha: the hemispherical
    /// octahedral code of the mean normal in the direction's frame
    /// ([`forest_format::shading::hemi_oct_encode`]) in R and G, sky visibility in B,
    /// translucency in A.
    pub surface: Vec<u8>,
    /// Mean sphere depth of the hits per layer pixel, in `[0,1]` (0 where blank).
    pub depth: Vec<f32>,
}

/// Sample offset `k` of `spp` within pixel `seed`: stratified on an `n × n` grid when `spp`
/// is a square, else uniformly jittered; each in `[0,1)²`.
pub fn sample_offset(seed: u32, k: u32, spp: u32) -> Vec2 {
    let h1 = hash(seed ^ hash(k.wrapping_mul(0x9e37_79b9)));
    let h2 = hash(h1 ^ 0x5bd1_e995);
    let n = (spp as f32).sqrt().round() as u32;
    if spp == 1 {
        Vec2::splat(0.5)
    } else if n * n == spp {
        Vec2::new(
            ((k % n) as f32 + unit(h1)) / n as f32,
            ((k / n) as f32 + unit(h2)) / n as f32,
        )
    } else {
        Vec2::new(unit(h1), unit(h2))
    }
}

/// What to trace: the framing sphere, the direction frames and the slab layout.
#[derive(Clone, Copy, Debug)]
pub struct SlabSetup<'a> {
    /// The sphere every image frames.
    pub sphere: Sphere,
    /// One frame per sampling direction.
    pub frames: &'a [DirectionFrame],
    /// Slabs per direction.
    pub slabs: u32,
    /// Image side in pixels.
    pub resolution: u32,
    /// Samples per pixel.
    pub spp: u32,
}

/// How [`trace_layers_by`] finds each sample's first solid hit in each slab.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HitSearch {
    /// Visit the samples that each BVH piece covers: a direction's rays are parallel, so a
    /// piece can only be hit by the samples inside its projection. Each candidate runs the ray
    /// tracer's own ray test and alpha test on the very ray [`HitSearch::Rays`] casts, and
    /// the nearest per slab is kept (ties to the lower piece), so the hits are the tracer's.
    Pieces,
    /// Trace each sample's ray through the BVH, once per slab it reaches
    /// ([`Scene::closest`]): the reference [`HitSearch::Pieces`] is tested against.
    Rays,
}

/// Largest tile side (pixels) the slab images are traced in.
pub const MAX_TILE: u32 = 32;

/// Bytes of per-sample hit records one tile may hold (its rays, 20 B per sample, come on
/// top).
pub const TILE_BYTES: u32 = 1 << 20;

/// Side in pixels of the square tiles traced as one task: [`MAX_TILE`] or less, a power of
/// two no larger than the image, so that a tile's hit record per sample and slab (an
/// `Option<Hit>`) stays within [`TILE_BYTES`].
pub fn tile_side(resolution: u32, spp: u32, slabs: u32) -> u32 {
    let record = std::mem::size_of::<Option<crate::trace::Hit>>() as u64;
    let mut side = MAX_TILE.min(resolution);
    while side > 1
        && u64::from(side * side) * u64::from(spp * slabs) * record > u64::from(TILE_BYTES)
    {
        side /= 2;
    }
    side
}

/// Trace every layer ([`HitSearch::Pieces`]), with `sky` the sky visibility of the scene's
/// triangles ([`crate::sky::triangle_sky`]). `progress(done, total)` counts image tiles.
pub fn trace_layers(
    scene: &Scene,
    sky: &[crate::sky::TriangleSky],
    setup: &SlabSetup,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> SlabImages {
    trace_layers_by(HitSearch::Pieces, scene, sky, setup, progress)
}

/// [`trace_layers`] with the hit search chosen. The resolution must be a power of two, as
/// [`forest_format::BakeParams::validate`] requires, so that the tiles cover the image.
pub fn trace_layers_by(
    search: HitSearch,
    scene: &Scene,
    sky: &[crate::sky::TriangleSky],
    setup: &SlabSetup,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> SlabImages {
    let SlabSetup {
        frames,
        slabs,
        resolution,
        spp,
        ..
    } = *setup;
    assert!(
        resolution.is_power_of_two(),
        "slab image resolution {resolution} is not a power of two"
    );
    let r = resolution as usize;
    let layers = frames.len() as u32 * slabs;
    let side = tile_side(resolution, spp, slabs);
    let per_row = resolution / side;
    let tiles = (per_row * per_row) as usize;
    let total = (frames.len() * tiles) as u64;
    let done = AtomicU64::new(0);
    let table = srgb_decode_table();
    let mut out = SlabImages {
        resolution,
        layers,
        rgba: vec![0; layers as usize * r * r * 4],
        surface: vec![0; layers as usize * r * r * 4],
        depth: vec![0.0; layers as usize * r * r],
    };
    for (di, frame) in frames.iter().enumerate() {
        let bins = (search == HitSearch::Pieces).then(|| PieceBins::new(scene, setup, frame, side));
        let traced: Vec<TileOut> = (0..tiles)
            .into_par_iter()
            .map(|ti| {
                let tile = Tile {
                    direction: di as u32,
                    x0: (ti as u32 % per_row) * side,
                    y0: (ti as u32 / per_row) * side,
                    side,
                };
                let hits = match &bins {
                    Some(bins) => tile_hits_by_pieces(scene, setup, frame, &tile, bins.tile(ti)),
                    None => tile_hits_by_rays(scene, setup, frame, &tile),
                };
                let out = shade_tile(scene, sky, &table, setup, frame, &tile, &hits);
                let n = done.fetch_add(1, Ordering::Relaxed) + 1;
                if n.is_multiple_of(64) || n == total {
                    progress(n, total);
                }
                out
            })
            .collect();
        for (ti, (rgba, surface, depth)) in traced.into_iter().enumerate() {
            let (x0, y0) = (
                (ti % per_row as usize) * side as usize,
                (ti / per_row as usize) * side as usize,
            );
            let sd = side as usize;
            for s in 0..slabs as usize {
                let layer = di * slabs as usize + s;
                for y in 0..sd {
                    let base = (layer * r + y0 + y) * r + x0;
                    let from = (s * sd + y) * sd;
                    out.rgba[base * 4..(base + sd) * 4]
                        .copy_from_slice(rgba[from..from + sd].as_flattened());
                    out.surface[base * 4..(base + sd) * 4]
                        .copy_from_slice(surface[from..from + sd].as_flattened());
                    out.depth[base..base + sd].copy_from_slice(&depth[from..from + sd]);
                }
            }
        }
    }
    out
}

/// One square tile of one direction's images.
struct Tile {
    direction: u32,
    /// First pixel column and row.
    x0: u32,
    y0: u32,
    /// Side in pixels.
    side: u32,
}

/// The ray of sample `k` of pixel `(x, y)` of direction `di` (origin on the sphere's front
/// plane, sphere depth 0), and its position in pixel units.
fn sample_ray(
    setup: &SlabSetup,
    frame: &DirectionFrame,
    di: u32,
    x: u32,
    y: u32,
    k: u32,
) -> (Vec3, Vec2) {
    let seed = hash(di << 26 ^ y << 13 ^ x);
    let off = sample_offset(seed, k, setup.spp);
    let res = setup.resolution as f32;
    let u = (x as f32 + off.x) / res;
    let v = (y as f32 + off.y) / res;
    (
        setup.sphere.image_to_object(frame, u, v, 0.0),
        Vec2::new(x as f32 + off.x, y as f32 + off.y),
    )
}

/// The slab of a hit at distance `t` along a ray through the sphere of diameter `diameter`.
fn slab_of(t: f32, diameter: f32, slabs: u32) -> usize {
    (((t / diameter) * slabs as f32) as u32).min(slabs - 1) as usize
}

/// Each piece's footprint on one direction's image and, per tile, the pieces it touches (in
/// piece order).
struct PieceBins {
    /// Per piece: `[x0, y0, x1, y1]` in pixel units, widened by float tolerance; empty
    /// (`x0 > x1`) where the piece lies off the image.
    rects: Vec<[f32; 4]>,
    /// Tile `i`'s pieces are `ids[start[i]..start[i + 1]]`.
    start: Vec<usize>,
    ids: Vec<u32>,
}

impl PieceBins {
    fn new(scene: &Scene, setup: &SlabSetup, frame: &DirectionFrame, side: u32) -> Self {
        let res = setup.resolution as f32;
        let rects: Vec<[f32; 4]> = (0..scene.piece_count())
            .into_par_iter()
            .map(|id| {
                let r = Footprint::new(scene.piece_points(id), setup, frame, res).rect();
                let on_image = r.iter().all(|c| c.is_finite())
                    && r[2] >= 0.0
                    && r[3] >= 0.0
                    && r[0] < res
                    && r[1] < res;
                if on_image { r } else { [1.0, 1.0, 0.0, 0.0] }
            })
            .collect();
        let per_row = setup.resolution / side;
        let span = |lo: f32, hi: f32| {
            let t = |c: f32| ((c.max(0.0) as u32).min(setup.resolution - 1) / side) as usize;
            t(lo)..=t(hi)
        };
        let mut start = vec![0usize; (per_row * per_row) as usize + 1];
        for r in rects.iter().filter(|r| r[0] <= r[2]) {
            for ty in span(r[1], r[3]) {
                for tx in span(r[0], r[2]) {
                    start[ty * per_row as usize + tx + 1] += 1;
                }
            }
        }
        for i in 1..start.len() {
            start[i] += start[i - 1];
        }
        let mut fill = start.clone();
        let mut ids = vec![0u32; *start.last().unwrap_or(&0)];
        for (id, r) in rects.iter().enumerate().filter(|(_, r)| r[0] <= r[2]) {
            for ty in span(r[1], r[3]) {
                for tx in span(r[0], r[2]) {
                    let f = &mut fill[ty * per_row as usize + tx];
                    ids[*f] = id as u32;
                    *f += 1;
                }
            }
        }
        Self { rects, start, ids }
    }

    /// Tile `i`'s pieces with their footprints, in piece order.
    fn tile(&self, i: usize) -> impl Iterator<Item = (usize, [f32; 4])> + '_ {
        self.ids[self.start[i]..self.start[i + 1]]
            .iter()
            .map(|&id| (id as usize, self.rects[id as usize]))
    }
}

/// How far (pixels) a well-shaped piece's footprint is widened: the ray test and the
/// projection round differently, by about 1e-6 of the radius, and a pixel is 2/resolution of
/// it, so a hundredth of a pixel holds every sample the ray test can hit. Pieces near edge-on
/// are widened more ([`Footprint::new`]).
const MARGIN: f32 = 0.01;

/// Pieces whose ray test is this ill-conditioned (`|e1|·|e2| / |det|`) skip the edge and
/// depth tests: every sample in their rectangle goes to the ray test.
const ILL_CONDITIONED: f32 = 1e4;

/// A piece projected onto one direction's image, in pixel units, with its distance along the
/// rays: what decides, conservatively and cheaply, which samples need the exact ray test.
struct Footprint {
    /// Corners in pixels.
    p: [Vec2; 3],
    /// How far the footprint is widened (pixels).
    margin: f32,
    /// Edge functions `e_i(q) = a_i·q + c_i`, positive inside, scaled so that `|a_i| = 1`
    /// (signed distance in pixels) and offset by each edge's widening; `None` for an
    /// ill-conditioned piece.
    edges: Option<[(Vec2, f32); 3]>,
    /// `t(q) = g·q + t0` over the footprint's plane, with its error bound, for a
    /// well-conditioned piece.
    depth: Option<(Vec2, f32, f32)>,
}

impl Footprint {
    fn new(points: [Vec3; 3], setup: &SlabSetup, frame: &DirectionFrame, res: f32) -> Self {
        let diameter = 2.0 * setup.sphere.radius;
        let mut p = [Vec2::ZERO; 3];
        let mut t = [0.0f32; 3];
        for (i, q) in points.into_iter().enumerate() {
            let (u, v, d) = setup.sphere.object_to_image(frame, q);
            p[i] = Vec2::new(u * res, v * res);
            t[i] = d * diameter;
        }
        // The ray test's conditioning, `|e1|·|e2| / |det|`. Its barycentrics err by about 1e-7
        // times this relative to the piece and, as the ray's origin lies up to a diameter away
        // on the sphere's front plane, by about 1e-7 times this times the resolution in pixels:
        // the footprint is widened by ten to a hundred times both.
        let (e1, e2) = (points[1] - points[0], points[2] - points[0]);
        let signed_det = e1.cross(e2).dot(frame.dir);
        let cond = (e1.length() * e2.length() / signed_det.abs()).min(1.0 / crate::trace::EDGE_ON);
        let longest = (0..3)
            .map(|i| (p[(i + 1) % 3] - p[i]).length())
            .fold(0.0f32, f32::max);
        let margin = MARGIN + 1e-5 * cond * longest + 1e-6 * cond * res;
        let well = cond.is_finite() && cond < ILL_CONDITIONED;
        let area = (p[1] - p[0]).perp_dot(p[2] - p[0]);
        // The orientation from the object-space determinant, which a sliver's rounded pixel
        // corners can flip: (right, up, dir) is right-handed and pixel y runs down `up`.
        let sign = if signed_det > 0.0 { -1.0 } else { 1.0 };
        // The corners' own rounding (their coordinates reach the resolution), which turns a
        // short edge's normal: its effect grows with the distance along that edge.
        let rounding = 1e-6 * res;
        let edges = well.then(|| {
            [0, 1, 2].map(|i| {
                let (a, b) = (p[i], p[(i + 1) % 3]);
                let e = b - a;
                let len = e.length().max(1e-30);
                let n = Vec2::new(-e.y, e.x) * (sign / len);
                let m = margin + rounding * (1.0 + 2.0 * longest / len);
                (n, m - n.dot(a))
            })
        });
        let depth = well.then(|| {
            let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
            let (d1, d2) = (t[1] - t[0], t[2] - t[0]);
            let g = Vec2::new(d1 * e2.y - d2 * e1.y, d2 * e1.x - d1 * e2.x) / area;
            let t0 = t[0] - g.dot(p[0]);
            // The ray test's rounding of `t` (1e-5 of the diameter, more when ill-conditioned)
            // and the depth change over the widening.
            let err = 1e-5 * diameter * (1.0 + 0.1 * cond) + (g.x.abs() + g.y.abs()) * margin;
            (g, t0, err)
        });
        Self {
            p,
            margin,
            edges,
            depth,
        }
    }

    /// `[x0, y0, x1, y1]` (pixels) holding every sample the piece can be hit by.
    fn rect(&self) -> [f32; 4] {
        let m = self.margin;
        let (lo, hi) = (
            self.p[0].min(self.p[1]).min(self.p[2]),
            self.p[0].max(self.p[1]).max(self.p[2]),
        );
        [lo.x - m, lo.y - m, hi.x + m, hi.y + m]
    }

    /// The x range (pixels, widened) the footprint may cover within rows `y ∈ [y0, y1]`.
    fn row_span(&self, y0: f32, y1: f32) -> Option<(f32, f32)> {
        let m = self.margin;
        let (y0, y1) = (y0 - m, y1 + m);
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for i in 0..3 {
            let (a, b) = (self.p[i], self.p[(i + 1) % 3]);
            // The edge clipped to the strip.
            let (ya, yb) = (a.y.min(b.y), a.y.max(b.y));
            if yb < y0 || ya > y1 {
                continue;
            }
            for y in [ya.max(y0), yb.min(y1)] {
                // A level edge spans its own x range; else where it crosses `y`.
                let (l, h) = if yb - ya < 1e-6 {
                    (a.x.min(b.x), a.x.max(b.x))
                } else {
                    let x = a.x + (b.x - a.x) * ((y - a.y) / (b.y - a.y)).clamp(0.0, 1.0);
                    (x, x)
                };
                lo = lo.min(l);
                hi = hi.max(h);
            }
        }
        (lo <= hi).then_some((lo - m, hi + m))
    }

    /// Whether sample position `q` (pixels) may lie on the piece: inside the widened
    /// footprint.
    #[inline]
    fn may_cover(&self, q: Vec2) -> bool {
        self.edges
            .is_none_or(|e| e.iter().all(|&(n, c)| n.dot(q) + c >= 0.0))
    }

    /// Bounds on the ray test's distance at sample position `q`, for a well-conditioned piece.
    #[inline]
    fn depth_bounds(&self, q: Vec2) -> Option<(f32, f32)> {
        self.depth.map(|(g, t0, err)| {
            let t = g.dot(q) + t0;
            (t - err, t + err)
        })
    }
}

/// Hits of a tile, per pixel (row-major in the tile), sample and slab.
type TileHits = Vec<Option<crate::trace::Hit>>;

/// [`HitSearch::Pieces`] for one tile: a z-buffer per slab over the tile's samples.
fn tile_hits_by_pieces(
    scene: &Scene,
    setup: &SlabSetup,
    frame: &DirectionFrame,
    tile: &Tile,
    pieces: impl Iterator<Item = (usize, [f32; 4])>,
) -> TileHits {
    let (spp, slabs) = (setup.spp as usize, setup.slabs as usize);
    let side = tile.side as usize;
    let diameter = 2.0 * setup.sphere.radius;
    let dir = -frame.dir;
    let rays: Vec<(Vec3, Vec2)> = (0..side * side * spp)
        .map(|i| {
            let (p, k) = (i / spp, i % spp);
            let (x, y) = (tile.x0 + (p % side) as u32, tile.y0 + (p / side) as u32);
            sample_ray(setup, frame, tile.direction, x, y, k as u32)
        })
        .collect();
    // The nearest solid hit so far per sample and slab: a z-buffer per slab.
    let mut best: TileHits = vec![None; side * side * spp * slabs];
    let nearest = |h: &Option<crate::trace::Hit>| h.map_or(f32::INFINITY, |h| h.t);
    let ty1 = (tile.y0 + tile.side - 1) as f32;
    let res = setup.resolution as f32;
    for (id, r) in pieces {
        let foot = Footprint::new(scene.piece_points(id), setup, frame, res);
        let y0 = r[1].max(tile.y0 as f32) as u32;
        let y1 = r[3].min(ty1) as u32;
        for y in y0..=y1 {
            // Only the pixels the piece's row span reaches.
            let Some((xa, xb)) = foot.row_span(y as f32, y as f32 + 1.0) else {
                continue;
            };
            // Pixels, not positions: a span from 31.5 to 40 reaches pixel 31 of a tile ending
            // there.
            let xa = (xa.max(r[0]).max(0.0) as u32).max(tile.x0);
            let xb = (xb.min(r[2]).max(0.0) as u32).min(tile.x0 + tile.side - 1);
            for x in xa..=xb {
                let p = (y - tile.y0) as usize * side + (x - tile.x0) as usize;
                for k in 0..spp {
                    let (o, at) = rays[p * spp + k];
                    if at.x < r[0]
                        || at.x > r[2]
                        || at.y < r[1]
                        || at.y > r[3]
                        || !foot.may_cover(at)
                    {
                        continue;
                    }
                    // Early depth test: a lower bound on the distance, where the footprint
                    // gives one, against the nearest hit kept in its slab.
                    if let Some((lo, hi)) = foot.depth_bounds(at) {
                        let s = slab_of(lo, diameter, setup.slabs);
                        if s == slab_of(hi, diameter, setup.slabs)
                            && lo >= nearest(&best[(p * spp + k) * slabs + s])
                        {
                            continue;
                        }
                    }
                    let Some((t, b)) = scene.piece_intersect(id, o, dir, 0.0, diameter) else {
                        continue;
                    };
                    let cell = &mut best[(p * spp + k) * slabs + slab_of(t, diameter, setup.slabs)];
                    if t < nearest(cell)
                        && let Some(hit) = scene.solid_hit(id, t, b)
                    {
                        *cell = Some(hit);
                    }
                }
            }
        }
    }
    best
}

/// [`HitSearch::Rays`] for one tile.
fn tile_hits_by_rays(
    scene: &Scene,
    setup: &SlabSetup,
    frame: &DirectionFrame,
    tile: &Tile,
) -> TileHits {
    let (spp, slabs) = (setup.spp as usize, setup.slabs);
    let side = tile.side as usize;
    let diameter = 2.0 * setup.sphere.radius;
    let dir = -frame.dir;
    let mut hits = vec![None; side * side * spp * slabs as usize];
    for p in 0..side * side {
        let (x, y) = (tile.x0 + (p % side) as u32, tile.y0 + (p / side) as u32);
        for k in 0..spp {
            let (origin, _) = sample_ray(setup, frame, tile.direction, x, y, k as u32);
            let mut tmin = 0.0f32;
            while let Some(hit) = scene.closest(origin, dir, tmin, diameter) {
                let s = slab_of(hit.t, diameter, slabs);
                let cell = &mut hits[(p * spp + k) * slabs as usize + s];
                if cell.is_none() {
                    *cell = Some(hit);
                }
                if s + 1 >= slabs as usize {
                    break;
                }
                // Past the slab's end, and past this hit should rounding put that end before it.
                tmin = (diameter * (s + 1) as f32 / slabs as f32).max(hit.t.next_up());
            }
        }
    }
    hits
}

/// One tile's slab images, `slabs` of each (tile-row-major): colour, surface, depth.
type TileOut = (Vec<[u8; 4]>, Vec<[u8; 4]>, Vec<f32>);

/// Average a tile's hits into its slab pixels.
fn shade_tile(
    scene: &Scene,
    sky: &[crate::sky::TriangleSky],
    table: &[f32; 256],
    setup: &SlabSetup,
    frame: &DirectionFrame,
    tile: &Tile,
    hits: &TileHits,
) -> TileOut {
    let (spp, slabs) = (setup.spp as usize, setup.slabs as usize);
    let side = tile.side as usize;
    let n = side * side;
    let diameter = 2.0 * setup.sphere.radius;
    let dir = -frame.dir;
    let mut rgba = vec![[0u8; 4]; slabs * n];
    let mut surface = vec![[0u8; 4]; slabs * n];
    let mut depth = vec![0f32; slabs * n];
    let mut acc = vec![Acc::default(); slabs];
    for p in 0..n {
        acc.iter_mut().for_each(|a| *a = Acc::default());
        for k in 0..spp {
            for (s, a) in acc.iter_mut().enumerate() {
                let Some(hit) = hits[(p * spp + k) * slabs + s] else {
                    continue;
                };
                let hit_surface = surface_at(scene, sky, table, &hit, dir);
                a.albedo += hit_surface.albedo;
                a.normal += hit_surface.normal;
                a.sky += hit_surface.sky_visibility;
                a.translucency += hit_surface.translucency;
                a.hits += 1;
                a.depth += hit.t / diameter;
            }
        }
        for (s, a) in acc.iter().enumerate() {
            if a.hits == 0 {
                continue;
            }
            let alpha = a.hits as f32 / spp as f32;
            let colour = (a.albedo / spp as f32).min(Vec3::splat(alpha));
            let a8 = (alpha * 255.0).round() as u8;
            rgba[s * n + p] = [
                (srgb_encode(colour.x) * 255.0).round() as u8,
                (srgb_encode(colour.y) * 255.0).round() as u8,
                (srgb_encode(colour.z) * 255.0).round() as u8,
                a8,
            ];
            // The mean normal in the direction's frame (z towards the viewer).
            let nrm = a.normal.try_normalize().unwrap_or(frame.dir);
            let local = Vec3::new(nrm.dot(frame.right), nrm.dot(frame.up), nrm.dot(frame.dir));
            let e = hemi_oct_encode(local);
            let hits = a.hits as f32;
            // Premultiplied by the stored alpha, never above it.
            let q = |v: f32| ((v.clamp(0.0, 1.0) * f32::from(a8)).round() as u8).min(a8);
            surface[s * n + p] = [q(e.x), q(e.y), q(a.sky / hits), q(a.translucency / hits)];
            depth[s * n + p] = a.depth / hits;
        }
    }
    (rgba, surface, depth)
}

/// One slab pixel's sums over its samples' hits.
#[derive(Clone, Copy, Default)]
struct Acc {
    albedo: Vec3,
    normal: Vec3,
    sky: f32,
    translucency: f32,
    hits: u32,
    depth: f32,
}

/// What the shading model needs of a hit seen along `dir`: albedo, the normal turned towards
/// the viewer, the sky visibility of that side and the translucency.
pub fn surface_at(
    scene: &Scene,
    sky: &[crate::sky::TriangleSky],
    table: &[f32; 256],
    hit: &crate::trace::Hit,
    dir: Vec3,
) -> Surface {
    let tri = &scene.tris[hit.tri as usize];
    let (b1, b2) = (hit.bary.x, hit.bary.y);
    let b0 = 1.0 - b1 - b2;
    let uv = tri.uv[0] * b0 + tri.uv[1] * b1 + tri.uv[2] * b2;
    let mut n = (tri.n[0] * b0 + tri.n[1] * b1 + tri.n[2] * b2)
        .try_normalize()
        .unwrap_or(tri.n[0]);
    if n.dot(dir) > 0.0 {
        n = -n; // two-sided: face the viewer
    }
    let material = &scene.mesh.materials[tri.material as usize];
    let albedo = match material.colour {
        Some(t) => material.kd * scene.mesh.textures[t].linear_rgb(uv, table),
        None => material.kd,
    };
    Surface {
        albedo,
        normal: n,
        sky_visibility: crate::sky::sky_at(scene, sky, hit.tri, hit.bary, dir),
        translucency: material.translucency,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_offsets_are_stratified_and_deterministic() {
        for k in 0..16 {
            let o = sample_offset(77, k, 16);
            assert!(o.x >= (k % 4) as f32 / 4.0 && o.x < (k % 4 + 1) as f32 / 4.0);
            assert!(o.y >= (k / 4) as f32 / 4.0 && o.y < (k / 4 + 1) as f32 / 4.0);
            assert_eq!(o, sample_offset(77, k, 16));
        }
        assert_eq!(sample_offset(1, 0, 1), Vec2::splat(0.5));
        let o = sample_offset(5, 2, 3);
        assert!((0.0..1.0).contains(&o.x) && (0.0..1.0).contains(&o.y));
    }
}
