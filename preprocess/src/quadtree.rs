//! The quad hierarchy of one slab image: alpha-weighted least-squares planes per node.
//!
//! Level 0 is the whole image; level `k` has `2^k × 2^k` quads of `resolution / 2^k` pixels,
//! down to quads of `min_quad` pixels. A node is *blank* when none of its pixels has non-zero
//! (8-bit) alpha; blank nodes are dropped. Every other node fits the plane
//! `t(x, y) = t̄ + g·((x, y) − (x̄, ȳ))` to its pixels' slab-relative depths `t` at their centres,
//! weighted by alpha, and keeps the plane's depth at its 4 corners (clamped to the slab).
//! Moments are summed bottom-up, so building all levels costs one pass over the pixels plus
//! a third of the finest level's node count.

use forest_format::PlaneFit;
#[cfg(test)]
use forest_format::node::error_bound;
use forest_format::node::{error_code, quantize_depth};

/// Weighted moments of the pixels of a node (coordinates in pixels, depth slab-relative).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Moments {
    /// Σw
    pub w: f64,
    /// Σw·x, Σw·y
    pub x: f64,
    /// Σw·y
    pub y: f64,
    /// Σw·x²
    pub xx: f64,
    /// Σw·x·y
    pub xy: f64,
    /// Σw·y²
    pub yy: f64,
    /// Σw·t
    pub t: f64,
    /// Σw·x·t
    pub xt: f64,
    /// Σw·y·t
    pub yt: f64,
}

impl Moments {
    /// Add a sample of weight `w` at `(x, y)` with depth `t`.
    pub fn add(&mut self, w: f64, x: f64, y: f64, t: f64) {
        self.w += w;
        self.x += w * x;
        self.y += w * y;
        self.xx += w * x * x;
        self.xy += w * x * y;
        self.yy += w * y * y;
        self.t += w * t;
        self.xt += w * x * t;
        self.yt += w * y * t;
    }

    fn sum(parts: [&Moments; 4]) -> Moments {
        let mut m = Moments::default();
        for p in parts {
            m.w += p.w;
            m.x += p.x;
            m.y += p.y;
            m.xx += p.xx;
            m.xy += p.xy;
            m.yy += p.yy;
            m.t += p.t;
            m.xt += p.xt;
            m.yt += p.yt;
        }
        m
    }

    /// The weighted least-squares plane, or `None` when the weight is zero.
    ///
    /// Slopes solve the centred 2×2 normal equations with a pseudo-inverse: directions with
    /// (near) zero spread (a single pixel, one row) get zero slope, so the fit is always finite.
    pub fn plane(&self) -> Option<Plane> {
        if self.w <= 0.0 {
            return None;
        }
        let (mx, my, mt) = (self.x / self.w, self.y / self.w, self.t / self.w);
        let cxx = (self.xx / self.w - mx * mx).max(0.0);
        let cyy = (self.yy / self.w - my * my).max(0.0);
        let cxy = self.xy / self.w - mx * my;
        let cxt = self.xt / self.w - mx * mt;
        let cyt = self.yt / self.w - my * mt;
        // Eigen-decomposition of [[cxx, cxy], [cxy, cyy]].
        let half_tr = 0.5 * (cxx + cyy);
        let disc = (0.25 * (cxx - cyy).powi(2) + cxy * cxy).sqrt();
        let (l1, l2) = (half_tr + disc, half_tr - disc);
        let v1 = if cxy.abs() > 1e-300 || cxx >= cyy {
            let v = if cxy.abs() > 1e-300 {
                (l1 - cyy, cxy)
            } else {
                (1.0, 0.0)
            };
            let n = (v.0 * v.0 + v.1 * v.1).sqrt();
            (v.0 / n, v.1 / n)
        } else {
            (0.0, 1.0)
        };
        let v2 = (-v1.1, v1.0);
        const EPS: f64 = 1e-9;
        let mut g = (0.0, 0.0);
        for (l, v) in [(l1, v1), (l2, v2)] {
            if l > EPS {
                let k = (v.0 * cxt + v.1 * cyt) / l;
                g.0 += k * v.0;
                g.1 += k * v.1;
            }
        }
        Some(Plane {
            cx: mx,
            cy: my,
            t: mt,
            gx: g.0,
            gy: g.1,
        })
    }
}

/// A fitted depth plane in pixel coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Centroid x.
    pub cx: f64,
    /// Centroid y.
    pub cy: f64,
    /// Depth at the centroid.
    pub t: f64,
    /// ∂t/∂x per pixel.
    pub gx: f64,
    /// ∂t/∂y per pixel.
    pub gy: f64,
}

impl Plane {
    /// Depth at pixel coordinates `(x, y)` (pixel edges are integers, centres at `+0.5`).
    pub fn at(&self, x: f64, y: f64) -> f64 {
        self.t + self.gx * (x - self.cx) + self.gy * (y - self.cy)
    }

    /// Depths at the corners TL, TR, BL, BR of the square `[x0, x0+size] × [y0, y0+size]`.
    pub fn corners(&self, x0: f64, y0: f64, size: f64) -> [f64; 4] {
        [
            self.at(x0, y0),
            self.at(x0 + size, y0),
            self.at(x0, y0 + size),
            self.at(x0 + size, y0 + size),
        ]
    }
}

/// A node of one layer's tree before global numbering.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LocalNode {
    /// Quad column at its level.
    pub x: u32,
    /// Quad row at its level.
    pub y: u32,
    /// Child mask (bit `i` for child `(2x + (i & 1), 2y + (i >> 1))`).
    pub mask: u8,
    /// Quantised corner depths, slab-relative.
    pub depth: [u8; 4],
    /// Depth-error code ([`forest_format::node::error_code`]) of the largest distance between a
    /// pixel's depth and the bilinear surface of the quantised corners at that pixel.
    pub error: u8,
}

/// One layer's quad hierarchy: per level, the non-blank nodes in breadth-first order (children
/// of earlier parents first, each parent's children in child order).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LayerTree {
    /// `levels` lists; empty when the layer is blank.
    pub levels: Vec<Vec<LocalNode>>,
}

/// Depth bins of the gap search: one per unorm8 quantisation step of the corner depths.
const BINS: usize = 256;

/// A depth gap, in pixel widths of depth, that splits a node's pixels into separate clusters:
/// a surface less steep than this many pixels of depth per pixel across leaves no empty run
/// this long between its sorted depths.
pub const GAP_PIXELS: f32 = 3.0;

/// The pixels of one node that its plane is fitted to: their depth range and moments.
struct Cluster {
    moments: Moments,
    t_min: f64,
    t_max: f64,
}

/// The heaviest cluster of the node's pixels once they are split wherever `gap_bins` or more
/// consecutive depth bins are empty (ties: the front one, nearer the sampling camera).
fn front_cluster(
    alpha: &[u8],
    depth: &[f32],
    r: usize,
    rect: (usize, usize, usize),
    gap_bins: usize,
) -> Option<Cluster> {
    let (x0, y0, side) = rect;
    let bin = |t: f32| ((t.clamp(0.0, 1.0) * (BINS - 1) as f32).round() as usize).min(BINS - 1);
    let mut hist = [0f64; BINS];
    for y in y0..y0 + side {
        for x in x0..x0 + side {
            let a = alpha[y * r + x];
            if a > 0 {
                hist[bin(depth[y * r + x])] += f64::from(a);
            }
        }
    }
    // Runs of bins separated by at least `gap_bins` empty bins; keep the heaviest.
    let mut best: Option<(f64, usize, usize)> = None;
    let mut cur: Option<(f64, usize, usize)> = None;
    let mut empty = 0usize;
    for (b, &w) in hist.iter().enumerate() {
        if w > 0.0 {
            cur = match cur {
                Some((sum, lo, _)) if empty < gap_bins => Some((sum + w, lo, b)),
                _ => {
                    if let Some(c) = cur
                        && best.is_none_or(|bb| c.0 > bb.0)
                    {
                        best = Some(c);
                    }
                    Some((w, b, b))
                }
            };
            empty = 0;
        } else {
            empty += 1;
        }
    }
    if let Some(c) = cur
        && best.is_none_or(|bb| c.0 > bb.0)
    {
        best = Some(c);
    }
    let (_, lo, hi) = best?;
    let mut m = Moments::default();
    let (mut t_min, mut t_max) = (f64::INFINITY, f64::NEG_INFINITY);
    for y in y0..y0 + side {
        for x in x0..x0 + side {
            let a = alpha[y * r + x];
            let t = depth[y * r + x];
            if a == 0 || !(lo..=hi).contains(&bin(t)) {
                continue;
            }
            let t = f64::from(t);
            m.add(f64::from(a) / 255.0, x as f64 + 0.5, y as f64 + 0.5, t);
            t_min = t_min.min(t);
            t_max = t_max.max(t);
        }
    }
    Some(Cluster {
        moments: m,
        t_min,
        t_max,
    })
}

/// The largest distance between a covered pixel's depth and the bilinear surface through the
/// quantised corner depths `q` of the square `(x0, y0, side)`, slab-relative.
fn depth_error(
    alpha: &[u8],
    depth: &[f32],
    r: usize,
    rect: (usize, usize, usize),
    q: [u8; 4],
) -> f32 {
    let (x0, y0, side) = rect;
    let c = q.map(|d| f32::from(d) / 255.0);
    let mut err = 0f32;
    for y in y0..y0 + side {
        let fy = ((y - y0) as f32 + 0.5) / side as f32;
        let left = c[0] + (c[2] - c[0]) * fy;
        let right = c[1] + (c[3] - c[1]) * fy;
        for x in x0..x0 + side {
            if alpha[y * r + x] == 0 {
                continue;
            }
            let fx = ((x - x0) as f32 + 0.5) / side as f32;
            err = err.max((depth[y * r + x] - (left + (right - left) * fx)).abs());
        }
    }
    err
}

/// Build the hierarchy of one layer from its 8-bit alpha and slab-relative depth (`t`, only
/// read where alpha > 0), both `resolution²` row-major. `slabs` (of the bake) sets how deep a
/// pixel is in slab units (`slabs / resolution`), which scales the gap of
/// [`PlaneFit::GapAware`].
///
/// With [`PlaneFit::GapAware`] each node fits the heaviest depth cluster of its pixels
/// ([`GAP_PIXELS`]) and clamps its corners to that cluster's depth range, so no node's corners
/// span a gap between clusters; with [`PlaneFit::LeastSquares`] it fits all its pixels and
/// clamps to the slab. Either way each node records its depth error.
///
/// # Panics
/// If the sizes disagree or `min_quad` is not a power of two below `resolution` (the bake
/// checks its parameters first).
pub fn build_layer(
    alpha: &[u8],
    depth: &[f32],
    resolution: u32,
    min_quad: u32,
    slabs: u32,
    fit: PlaneFit,
) -> LayerTree {
    let r = resolution as usize;
    assert_eq!(alpha.len(), r * r);
    assert_eq!(depth.len(), r * r);
    assert!(min_quad.is_power_of_two() && min_quad < resolution);
    let gap_bins = ((GAP_PIXELS * slabs as f32 / resolution as f32) * (BINS - 1) as f32)
        .ceil()
        .max(2.0) as usize;
    let levels = forest_format::node::level_count(resolution, min_quad) as usize;
    // Moments per level, dense 2^k × 2^k.
    let mut moments: Vec<Vec<Moments>> = Vec::with_capacity(levels);
    let finest = 1usize << (levels - 1);
    let q = min_quad as usize;
    let mut fine = vec![Moments::default(); finest * finest];
    for y in 0..r {
        for x in 0..r {
            let a = alpha[y * r + x];
            if a == 0 {
                continue;
            }
            let w = f64::from(a) / 255.0;
            fine[(y / q) * finest + x / q].add(
                w,
                x as f64 + 0.5,
                y as f64 + 0.5,
                f64::from(depth[y * r + x]),
            );
        }
    }
    moments.push(fine);
    for k in (0..levels - 1).rev() {
        let n = 1usize << k;
        let child = moments.last().unwrap();
        let cn = 2 * n;
        let level: Vec<Moments> = (0..n * n)
            .map(|i| {
                let (x, y) = (i % n, i / n);
                Moments::sum([
                    &child[2 * y * cn + 2 * x],
                    &child[2 * y * cn + 2 * x + 1],
                    &child[(2 * y + 1) * cn + 2 * x],
                    &child[(2 * y + 1) * cn + 2 * x + 1],
                ])
            })
            .collect();
        moments.push(level);
    }
    moments.reverse(); // moments[k] is level k

    let mut tree = LayerTree { levels: Vec::new() };
    if moments[0][0].w <= 0.0 {
        return tree;
    }
    let mut frontier = vec![(0u32, 0u32)];
    for k in 0..levels {
        let n = 1u32 << k;
        let side = r >> k;
        let size = side as f64;
        let mut nodes = Vec::with_capacity(frontier.len());
        let mut next = Vec::new();
        for &(x, y) in &frontier {
            let rect = (x as usize * side, y as usize * side, side);
            let (x0, y0) = (f64::from(x) * size, f64::from(y) * size);
            let c = match fit {
                PlaneFit::LeastSquares => {
                    let m = &moments[k][(y * n + x) as usize];
                    let plane = m.plane().expect("only non-blank nodes are visited");
                    plane.corners(x0, y0, size)
                }
                PlaneFit::GapAware => {
                    let cl = front_cluster(alpha, depth, r, rect, gap_bins)
                        .expect("only non-blank nodes are visited");
                    let plane = cl.moments.plane().expect("a cluster has weight");
                    // Corners lie half a pixel beyond the outermost pixel centres: the range
                    // extends by the plane's rise over that half pixel.
                    let margin = 0.5 * (plane.gx.abs() + plane.gy.abs());
                    plane
                        .corners(x0, y0, size)
                        .map(|d| d.clamp(cl.t_min - margin, cl.t_max + margin))
                }
            };
            let quantised = c.map(|d| quantize_depth(d as f32));
            let error = error_code(depth_error(alpha, depth, r, rect, quantised));
            let mut mask = 0u8;
            if k + 1 < levels {
                for i in 0..4u32 {
                    let (cx, cy) = (2 * x + (i & 1), 2 * y + (i >> 1));
                    if moments[k + 1][(cy * 2 * n + cx) as usize].w > 0.0 {
                        mask |= 1 << i;
                        next.push((cx, cy));
                    }
                }
            }
            nodes.push(LocalNode {
                x,
                y,
                mask,
                depth: quantised,
                error,
            });
        }
        tree.levels.push(nodes);
        frontier = next;
    }
    tree
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tilted_plane_is_fitted_exactly_at_every_level() {
        let r = 64usize;
        let plane = |x: f64, y: f64| 0.2 + 0.004 * x + 0.006 * y;
        let mut depth = vec![0f32; r * r];
        let mut alpha = vec![0u8; r * r];
        for y in 0..r {
            for x in 0..r {
                depth[y * r + x] = plane(x as f64 + 0.5, y as f64 + 0.5) as f32;
                // Varying weights must not change an exact fit.
                alpha[y * r + x] = (1 + (x * 7 + y * 13) % 255) as u8;
            }
        }
        let tree = build_layer(&alpha, &depth, r as u32, 4, 2, PlaneFit::LeastSquares);
        assert_eq!(tree.levels.len(), 5);
        for (k, level) in tree.levels.iter().enumerate() {
            assert_eq!(level.len(), 1 << (2 * k), "level {k} is full");
            let size = (r >> k) as f64;
            for n in level {
                let (x0, y0) = (n.x as f64 * size, n.y as f64 * size);
                let want = [
                    plane(x0, y0),
                    plane(x0 + size, y0),
                    plane(x0, y0 + size),
                    plane(x0 + size, y0 + size),
                ];
                assert_eq!(n.depth, want.map(|d| quantize_depth(d as f32)), "level {k}");
            }
        }
        // And the float fit itself is exact.
        let mut m = Moments::default();
        for y in 0..r {
            for x in 0..r {
                let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                m.add(
                    f64::from(alpha[y * r + x]) / 255.0,
                    px,
                    py,
                    f64::from(depth[y * r + x]),
                );
            }
        }
        let p = m.plane().unwrap();
        for (x, y) in [
            (0.0, 0.0),
            (64.0, 0.0),
            (0.0, 64.0),
            (64.0, 64.0),
            (13.0, 40.0),
        ] {
            assert!((p.at(x, y) - plane(x, y)).abs() < 1e-6, "({x},{y})");
        }
    }

    #[test]
    fn empty_regions_produce_no_nodes() {
        let r = 32usize;
        let mut alpha = vec![0u8; r * r];
        let depth = vec![0.5f32; r * r];
        assert!(
            build_layer(&alpha, &depth, 32, 4, 2, PlaneFit::GapAware)
                .levels
                .is_empty()
        );
        // One opaque pixel at (5, 9): exactly one node per level, on the path to it.
        alpha[9 * r + 5] = 255;
        let tree = build_layer(&alpha, &depth, 32, 4, 2, PlaneFit::GapAware);
        assert_eq!(tree.levels.len(), 4);
        for (k, level) in tree.levels.iter().enumerate() {
            assert_eq!(level.len(), 1, "level {k}");
            let size = 32 >> k;
            assert_eq!((level[0].x, level[0].y), (5 / size, 9 / size));
            // A single pixel fits a flat plane at its depth.
            assert_eq!(level[0].depth, [128; 4]);
        }
        assert_eq!(tree.levels[0][0].mask, 0b0001);
        assert_eq!(tree.levels[1][0].mask, 0b0100); // (5,9) in 8-px quads of the (0,0) 16-px quad: child (0,1)
        assert_eq!(tree.levels[3][0].mask, 0);
    }

    #[test]
    fn a_single_row_gets_a_slope_along_it_only() {
        let mut m = Moments::default();
        for x in 0..8 {
            m.add(1.0, x as f64 + 0.5, 3.5, 0.1 * x as f64);
        }
        let p = m.plane().unwrap();
        assert!((p.gx - 0.1).abs() < 1e-12 && p.gy.abs() < 1e-12);
        let single = {
            let mut m = Moments::default();
            m.add(0.3, 2.5, 2.5, 0.7);
            m.plane().unwrap()
        };
        assert_eq!((single.gx, single.gy, single.t), (0.0, 0.0, 0.7));
    }

    /// Two parallel cards, one at slab depth 0.2 over the left half of every quad, one at 0.8
    /// over the right half: `(alpha, depth)` of a `r`² layer.
    fn two_cards(r: usize) -> (Vec<u8>, Vec<f32>) {
        let mut alpha = vec![255u8; r * r];
        let mut depth = vec![0f32; r * r];
        for y in 0..r {
            for x in 0..r {
                // Left half of each 4-px column pair is near, right half far; a few texels
                // weigh less, which must not matter.
                depth[y * r + x] = if x % 4 < 2 { 0.2 } else { 0.8 };
                if (x + y) % 7 == 0 {
                    alpha[y * r + x] = 200;
                }
            }
        }
        (alpha, depth)
    }

    #[test]
    fn no_gap_aware_node_spans_the_gap_between_two_cards() {
        let r = 32;
        let (alpha, depth) = two_cards(r);
        let near = quantize_depth(0.2);
        let far = quantize_depth(0.8);
        let tree = build_layer(&alpha, &depth, r as u32, 4, 2, PlaneFit::GapAware);
        assert_eq!(tree.levels.len(), 4);
        for (k, level) in tree.levels.iter().enumerate() {
            for n in level {
                // Every corner lies on one card: all at the near depth or all at the far one.
                let on_near = n.depth.iter().all(|&d| d == near);
                let on_far = n.depth.iter().all(|&d| d == far);
                assert!(on_near || on_far, "level {k} node {n:?} spans the gap");
                // The other card's pixels are 0.6 away: the error code bounds that.
                assert!(
                    error_bound(n.error) >= 0.6 - 1.0 / 255.0,
                    "level {k}: {n:?}"
                );
                assert!(
                    error_bound(n.error.saturating_sub(1)) < 0.6,
                    "level {k}: {n:?}"
                );
            }
        }
        // The paper's least-squares fit bridges the gap with a steep plane: the same input
        // gives nodes whose corners reach from near the one card to near the other.
        let ls = build_layer(&alpha, &depth, r as u32, 4, 2, PlaneFit::LeastSquares);
        let bridging = ls.levels[3]
            .iter()
            .filter(|n| {
                let (lo, hi) = (n.depth.iter().min().unwrap(), n.depth.iter().max().unwrap());
                *lo < near + 20 && *hi > far - 20
            })
            .count();
        assert_eq!(bridging, ls.levels[3].len());
    }

    #[test]
    fn a_single_card_has_no_depth_error_and_a_lone_far_pixel_sets_it() {
        let r = 16usize;
        let mut alpha = vec![255u8; r * r];
        let mut depth = vec![0f32; r * r];
        for y in 0..r {
            for x in 0..r {
                depth[y * r + x] = 0.3 + 0.01 * x as f32;
            }
        }
        let tree = build_layer(&alpha, &depth, r as u32, 4, 1, PlaneFit::GapAware);
        assert!(
            tree.levels.iter().flatten().all(|n| n.error == 0),
            "{tree:?}"
        );
        // One far pixel: it is its own cluster (ignored by the fit) but sets the error of the
        // nodes that hold it, and only those.
        depth[5 * r + 6] = 0.95;
        alpha[0] = 0;
        let tree = build_layer(&alpha, &depth, r as u32, 4, 1, PlaneFit::GapAware);
        for (k, level) in tree.levels.iter().enumerate() {
            let side = r >> k;
            for n in level {
                let holds = n.x as usize == 6 / side && n.y as usize == 5 / side;
                let want = 0.95 - (0.3 + 0.01 * 6.5);
                if holds {
                    assert!(error_bound(n.error) >= want - 0.01, "level {k}: {n:?}");
                } else {
                    assert_eq!(n.error, 0, "level {k}: {n:?}");
                }
            }
        }
    }
}
