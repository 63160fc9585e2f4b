//! Covered boxes of quad-hierarchy nodes: the smallest rectangle of each node that holds all
//! of its covered (alpha > 0) texels, so that a quad is drawn over its leaves and not over the
//! blank rest of its square (a level-0 quad spans the whole slab image; the crown covers a
//! fraction of it). Derived from an atlas's alpha when it is loaded: no format change.
//!
//! A box is packed in a `u32` as fractions of the node's side in 1/255 steps: `lo_x | lo_y << 8
//! | hi_x << 16 | hi_y << 24`, `lo = floor(255 · first / side)` and `hi = ceil(255 · end /
//! side)` for the covered texels `first..end` along each axis, so the decoded box always holds
//! every covered texel. A node without covered texels gets an empty box (`lo = hi = 0`).

use crate::atlas::Layers;
use crate::node::QuadNode;

/// The whole node.
pub const FULL: u32 = pack([0, 0], [255, 255]);

/// Pack a box of 1/255 fractions.
pub const fn pack(lo: [u8; 2], hi: [u8; 2]) -> u32 {
    lo[0] as u32 | (lo[1] as u32) << 8 | (hi[0] as u32) << 16 | (hi[1] as u32) << 24
}

/// The box as fractions of the node's side: `(lo, hi)`, each `[x, y]` in `[0, 1]`.
pub fn unpack(t: u32) -> ([f32; 2], [f32; 2]) {
    let f = |s: u32| ((t >> s) & 255) as f32 / 255.0;
    ([f(0), f(8)], [f(16), f(24)])
}

/// A texel rectangle `[x0, x1) × [y0, y1)`; empty when `x0 >= x1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Rect {
    x0: u32,
    y0: u32,
    x1: u32,
    y1: u32,
}

const EMPTY: Rect = Rect {
    x0: u32::MAX,
    y0: u32::MAX,
    x1: 0,
    y1: 0,
};

impl Rect {
    fn union(self, o: Rect) -> Rect {
        Rect {
            x0: self.x0.min(o.x0),
            y0: self.y0.min(o.y0),
            x1: self.x1.max(o.x1),
            y1: self.y1.max(o.y1),
        }
    }
}

/// A value of every aligned block of one layer at every level: `out[level][by · 2^level +
/// bx]`, blocks of side `resolution >> level`, for levels `0..levels`; a block's value merges
/// its texels' (`texel`) or its quadrants' values with `merge`, starting from `none`.
fn pyramid<T: Copy>(
    texel: impl Fn(u32, u32) -> T,
    none: T,
    merge: impl Fn(T, T) -> T,
    resolution: u32,
    levels: u32,
) -> Vec<Vec<T>> {
    let finest = levels.saturating_sub(1);
    let blocks = 1u32 << finest;
    let side = (resolution >> finest).max(1);
    let mut level: Vec<T> = (0..blocks * blocks)
        .map(|b| {
            let (bx, by) = (b % blocks, b / blocks);
            let mut v = none;
            for y in by * side..(by + 1) * side {
                for x in bx * side..(bx + 1) * side {
                    v = merge(v, texel(x, y));
                }
            }
            v
        })
        .collect();
    let mut out = vec![Vec::new(); levels as usize];
    for l in (0..levels).rev() {
        if l < finest {
            let n = 1u32 << l;
            level = (0..n * n)
                .map(|b| {
                    let (bx, by) = (b % n, b / n);
                    let child =
                        |dx: u32, dy: u32| level[((2 * by + dy) * 2 * n + 2 * bx + dx) as usize];
                    merge(
                        merge(child(0, 0), child(1, 0)),
                        merge(child(0, 1), child(1, 1)),
                    )
                })
                .collect();
        }
        out[l as usize] = level.clone();
    }
    out
}

/// The packed box of block `(bx, by)` of side `side` texels holding `r`.
fn packed(r: Rect, bx: u32, by: u32, side: u32) -> u32 {
    if r.x0 >= r.x1 {
        return 0;
    }
    let lo = |v: u32, o: u32| ((u64::from(v - o * side) * 255) / u64::from(side)) as u8;
    let hi = |v: u32, o: u32| (u64::from(v - o * side) * 255).div_ceil(u64::from(side)) as u8;
    pack([lo(r.x0, bx), lo(r.y0, by)], [hi(r.x1, bx), hi(r.y1, by)])
}

/// A node's opaque share in 1/255 steps: `floor(255 · opaque / box)` for its opaque texels
/// (alpha 255) and the texels of its covered box; 0 for an empty box.
fn opaque_share(opaque: u32, r: Rect) -> u32 {
    if r.x0 >= r.x1 {
        return 0;
    }
    let area = u64::from(r.x1 - r.x0) * u64::from(r.y1 - r.y0);
    (u64::from(opaque) * 255 / area).min(255) as u32
}

/// The covered box of every node of one atlas, in node order, and its opaque share:
/// `[box, share]`, the box packed as this module says, the share the fraction of the box's
/// texels that are opaque (alpha 255) in 1/255 steps. `layer_roots[l]` is the root (index
/// into `nodes`) of layer `l` of `layers`; a node's children are its quadrants in the order of
/// [`QuadNode::child_index`] (child `c` at `x · 2 + (c & 1)`, `y · 2 + (c >> 1)`). Nodes
/// reached from no root, or deeper than `levels`, keep `[FULL, 0]`. Cost: two passes over
/// every texel of every non-blank layer, then a constant per block.
pub fn node_trims(
    nodes: &[QuadNode],
    layer_roots: &[Option<u32>],
    layers: &Layers,
    levels: u32,
) -> Vec<[u32; 2]> {
    let mut out = vec![[FULL, 0]; nodes.len()];
    let res = layers.resolution;
    for (l, root) in layer_roots.iter().enumerate() {
        let Some(root) = root else { continue };
        if l as u32 >= layers.count || *root as usize >= nodes.len() {
            continue;
        }
        let rgba = layers.layer(l as u32);
        let alpha = |x: u32, y: u32| rgba[((y * res + x) * 4 + 3) as usize];
        // Each covered texel's own box, merged by union.
        let covered = |x: u32, y: u32| {
            if alpha(x, y) > 0 {
                Rect {
                    x0: x,
                    y0: y,
                    x1: x + 1,
                    y1: y + 1,
                }
            } else {
                EMPTY
            }
        };
        let boxes = pyramid(covered, EMPTY, Rect::union, res, levels);
        let opaque = pyramid(
            |x, y| u32::from(alpha(x, y) == 255),
            0,
            |a, b| a + b,
            res,
            levels,
        );
        let mut stack = vec![(*root, 0u32, 0u32, 0u32)];
        while let Some((n, level, x, y)) = stack.pop() {
            let Some(node) = nodes.get(n as usize) else {
                continue;
            };
            let Some(level_boxes) = boxes.get(level as usize) else {
                continue;
            };
            let side = res >> level;
            let block = (y * (1 << level) + x) as usize;
            let r = level_boxes[block];
            out[n as usize] = [
                packed(r, x, y, side),
                opaque_share(opaque[level as usize][block], r),
            ];
            for c in 0..4 {
                if let Some(k) = node.child_index(c) {
                    stack.push((k, level + 1, x * 2 + (c & 1), y * 2 + (c >> 1)));
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One 8×8 layer with covered texels at (2, 1) and (5, 3): two levels (8 and 4 texels).
    fn layer() -> Layers {
        let mut rgba = vec![0u8; 8 * 8 * 4];
        for (x, y) in [(2usize, 1usize), (5, 3)] {
            rgba[(y * 8 + x) * 4 + 3] = 200;
        }
        Layers {
            resolution: 8,
            count: 1,
            rgba,
        }
    }

    #[test]
    fn boxes_hold_exactly_the_covered_texels() {
        // Root with children 0 (top left) and 1 (top right): the covered quadrants.
        let nodes = vec![
            QuadNode::new(0b0011, 1, [0; 4]),
            QuadNode::new(0, 0, [0; 4]),
            QuadNode::new(0, 0, [0; 4]),
        ];
        let t: Vec<u32> = node_trims(&nodes, &[Some(0)], &layer(), 2)
            .iter()
            .map(|t| t[0])
            .collect();
        // Root: texels x 2..6, y 1..4 of 8 → lo floor(255·2/8) = 63, floor(255/8) = 31;
        // hi ceil(255·6/8) = 192, ceil(255·4/8) = 128.
        assert_eq!(unpack(t[0]), unpack(pack([63, 31], [192, 128])));
        // Top-left child (texels 0..4): (2, 1) alone → x 2..3, y 1..2 of 4.
        assert_eq!(t[1], pack([127, 63], [192, 128]));
        // Top-right child (texels 4..8): (5, 3) → x 1..2, y 3..4 of 4.
        assert_eq!(t[2], pack([63, 191], [128, 255]));
        // Every box holds its texels: decoded fractions bracket them.
        let (lo, hi) = unpack(t[0]);
        assert!(lo[0] * 8.0 <= 2.0 && hi[0] * 8.0 >= 6.0 && lo[1] * 8.0 <= 1.0);
        assert!(hi[1] * 8.0 >= 4.0);
    }

    /// Opaque shares: a 4×4 layer, its top-left 2×2 quadrant opaque (255), one texel of the
    /// top-right half covered (200), the bottom blank.
    #[test]
    fn opaque_share_of_the_box() {
        let mut rgba = vec![0u8; 4 * 4 * 4];
        for (x, y, a) in [
            (0usize, 0usize, 255u8),
            (1, 0, 255),
            (0, 1, 255),
            (1, 1, 255),
            (3, 1, 200),
        ] {
            rgba[(y * 4 + x) * 4 + 3] = a;
        }
        let layers = Layers {
            resolution: 4,
            count: 1,
            rgba,
        };
        let nodes = vec![
            QuadNode::new(0b0011, 1, [0; 4]),
            QuadNode::new(0, 0, [0; 4]),
            QuadNode::new(0, 0, [0; 4]),
        ];
        let t = node_trims(&nodes, &[Some(0)], &layers, 2);
        // Root: box x 0..4, y 0..2 (8 texels), 4 opaque → 255 · 4 / 8 = 127.
        assert_eq!(t[0][1], 127);
        // Top-left: all 4 opaque.
        assert_eq!(t[1][1], 255);
        // Top-right: its box is the one texel of alpha 200.
        assert_eq!(t[2][1], 0);
    }

    #[test]
    fn blank_and_unreached_nodes() {
        let blank = Layers {
            resolution: 8,
            count: 1,
            rgba: vec![0; 256],
        };
        let nodes = vec![QuadNode::new(0, 0, [0; 4]), QuadNode::new(0, 0, [0; 4])];
        let t = node_trims(&nodes, &[Some(0)], &blank, 2);
        assert_eq!(
            t,
            vec![[0, 0], [FULL, 0]],
            "empty box for the root, FULL for the unreached node"
        );
        assert_eq!(unpack(FULL), ([0.0, 0.0], [1.0, 1.0]));
    }
}
