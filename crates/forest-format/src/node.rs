//! One node of a slab image's quad hierarchy, as stored in GPU textures.
//!
//! Image-space conventions (see also [`crate::slab`]): a slab image is `2^r` pixels square, x to
//! the right, y downwards. Level 0 is the whole image; a node at level `k` covers the square of
//! side `2^(r-k)` pixels starting at pixel `(x·2^(r-k), y·2^(r-k))`, with `x, y < 2^k`. Its child
//! `i` (0..4) is at `(2x + (i & 1), 2y + (i >> 1))` on level `k + 1`. Corner `c` of a node is at
//! its top-left (0), top-right (1), bottom-left (2) and bottom-right (3).
//!
//! Nodes of all layers are stored level by level (all level-0 nodes first, then all level-1 nodes
//! in the order of their parents, …), so the existing children of a node are contiguous and in
//! child order: child `i` is at `first_child + popcount(mask & ((1 << i) - 1))`.

use bytemuck::{Pod, Zeroable};

/// Bits of [`QuadNode::child`] holding the index of the first child.
pub const FIRST_CHILD_BITS: u32 = 24;
/// The largest number of nodes an atlas can hold (the first-child index must fit 24 bits).
pub const MAX_NODES: u64 = 1 << FIRST_CHILD_BITS;
/// Shift of the 4-bit depth-error code in [`QuadNode::child`].
pub const ERROR_SHIFT: u32 = 24;
/// Shift of the 4-bit child mask in [`QuadNode::child`].
pub const MASK_SHIFT: u32 = 28;

/// The depth error that code `k` stands for, slab-relative: 0 for `k = 0`, else
/// `2^((k − 15)/2)` (from 2^−7 ≈ 2 quantisation steps up to 1, the whole slab). Codes step by
/// √2; [`error_code`] rounds up, so the decoded error bounds the true one. Mirrored by
/// `node_error` in `shaders/common.wgsl`.
pub fn error_bound(code: u8) -> f32 {
    ERROR_BOUNDS[usize::from(code.min(15))]
}

/// [`error_bound`] of every code, as decimal literals that WGSL parses to the same `f32`s.
pub const ERROR_BOUNDS: [f32; 16] = [
    0.0,
    0.0078125,
    0.011048543,
    0.015625,
    0.022097087,
    0.03125,
    0.044194173,
    0.0625,
    0.088388346,
    0.125,
    0.17677669,
    0.25,
    0.35355338,
    0.5,
    0.70710677,
    1.0,
];

/// The smallest code whose [`error_bound`] is at least `err` (slab-relative): 0 when `err` is
/// within a quantisation step (1/255) or not positive, 15 for anything from `2^−0.5` up.
pub fn error_code(err: f32) -> u8 {
    if err.is_nan() || err <= 1.0 / 255.0 {
        return 0;
    }
    (1..15).find(|&k| error_bound(k) >= err).unwrap_or(15)
}

/// A quad-hierarchy node: 8 bytes, read by WGSL as the first two words of a texel of the
/// runtime's node texture.
///
/// - `child`: bits 0..24 the index of the first existing child (zero for a leaf), bits 24..28
///   the depth-error code ([`error_code`]: how far the node's pixels lie from its drawn
///   corners' bilinear surface, slab-relative), bits 28..32 the child mask (bit `i` set when
///   child `i` exists, i.e. is not blank).
/// - `depth`: the fitted plane's depth at the 4 corners, unorm8 relative to the node's slab:
///   0 at the slab's near clipping plane (towards the sampling camera), 255 at its far one.
///   WGSL reads it as one little-endian `u32`, corner 0 in the low byte.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Pod, Zeroable)]
pub struct QuadNode {
    /// First child index (24 bits), depth-error code (4 bits) and child mask (high 4 bits).
    pub child: u32,
    /// Corner depths, unorm8 within the slab, corners in the order TL, TR, BL, BR.
    pub depth: [u8; 4],
}

impl QuadNode {
    /// A node with the given child mask (4 bits), first child index and quantised corner depths.
    ///
    /// # Panics
    /// If `first_child` does not fit 24 bits or `mask` has bits above the 4th (caller bugs).
    pub fn new(mask: u8, first_child: u32, depth: [u8; 4]) -> Self {
        assert!(mask < 16, "child mask has 4 bits");
        assert!(
            u64::from(first_child) < MAX_NODES,
            "first child index fits 24 bits"
        );
        let first_child = if mask == 0 { 0 } else { first_child };
        Self {
            child: first_child | (u32::from(mask) << MASK_SHIFT),
            depth,
        }
    }

    /// The same node with depth-error code `code` (4 bits; larger values are clamped to 15).
    pub fn with_error(self, code: u8) -> Self {
        Self {
            child: (self.child & !(15 << ERROR_SHIFT)) | (u32::from(code.min(15)) << ERROR_SHIFT),
            depth: self.depth,
        }
    }

    /// The child mask: bit `i` is set when child `i` exists.
    pub fn mask(&self) -> u8 {
        (self.child >> MASK_SHIFT) as u8
    }

    /// The depth-error code ([`error_bound`] decodes it).
    pub fn error(&self) -> u8 {
        ((self.child >> ERROR_SHIFT) & 15) as u8
    }

    /// Index of the first existing child (meaningless when [`Self::mask`] is 0).
    pub fn first_child(&self) -> u32 {
        self.child & ((1 << FIRST_CHILD_BITS) - 1)
    }

    /// Index of child `i` (0..4), or `None` when that child is blank.
    pub fn child_index(&self, i: u32) -> Option<u32> {
        let mask = u32::from(self.mask());
        if i >= 4 || mask & (1 << i) == 0 {
            return None;
        }
        Some(self.first_child() + (mask & ((1 << i) - 1)).count_ones())
    }

    /// Corner depths relative to the slab, in `[0, 1]`.
    pub fn corner_depths(&self) -> [f32; 4] {
        self.depth.map(|d| f32::from(d) / 255.0)
    }
}

/// Quantise a slab-relative depth in `[0, 1]` to unorm8 (values outside are clamped).
pub fn quantize_depth(d: f32) -> u8 {
    (d.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// Number of levels of a slab image of `2^r` pixels with smallest quads of `2^m` pixels:
/// `l = r − m + 1` (the paper's formula; 8 at the defaults r = 9, m = 2).
pub fn level_count(resolution: u32, min_quad: u32) -> u32 {
    resolution.trailing_zeros() - min_quad.trailing_zeros() + 1
}

/// Side of a level-`level` quad in pixels, for a slab image of `resolution` pixels.
pub fn quad_size(resolution: u32, level: u32) -> u32 {
    resolution >> level
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_is_eight_bytes_and_packs_fields() {
        assert_eq!(std::mem::size_of::<QuadNode>(), 8);
        let n = QuadNode::new(0b1010, 12345, [1, 2, 3, 4]);
        assert_eq!(n.mask(), 0b1010);
        assert_eq!(n.first_child(), 12345);
        assert_eq!(n.child_index(0), None);
        assert_eq!(n.child_index(1), Some(12345));
        assert_eq!(n.child_index(2), None);
        assert_eq!(n.child_index(3), Some(12346));
        let bytes = bytemuck::bytes_of(&n);
        assert_eq!(&bytes[4..], &[1, 2, 3, 4]);
        assert_eq!(QuadNode::new(0, 99, [0; 4]).first_child(), 0);
    }

    #[test]
    fn error_codes_bound_the_error_and_pack_beside_the_mask() {
        assert_eq!(error_code(0.0), 0);
        assert_eq!(error_code(1.0 / 255.0), 0);
        assert_eq!(error_code(f32::NAN), 0);
        assert_eq!(error_code(1.0), 15);
        assert_eq!(error_code(7.0), 15);
        for e in [0.005f32, 0.01, 0.05, 0.1, 0.3, 0.7, 0.99] {
            let k = error_code(e);
            assert!(error_bound(k) >= e, "{e}: code {k}");
            assert!(error_bound(k - 1) < e, "{e}: code {k} is the smallest");
        }
        assert_eq!(error_bound(15), 1.0);
        let n = QuadNode::new(0b1001, (1 << 24) - 1, [9, 8, 7, 6]).with_error(11);
        assert_eq!(
            (n.mask(), n.first_child(), n.error()),
            (0b1001, (1 << 24) - 1, 11)
        );
        assert_eq!(n.with_error(3).error(), 3);
        assert_eq!(n.with_error(3).mask(), 0b1001);
    }

    #[test]
    fn level_count_formula() {
        assert_eq!(level_count(512, 4), 8);
        assert_eq!(level_count(1024, 2), 10);
        assert_eq!(level_count(64, 32), 2);
        assert_eq!(quad_size(512, 7), 4);
    }

    #[test]
    fn depth_quantisation_clamps() {
        assert_eq!(quantize_depth(-1.0), 0);
        assert_eq!(quantize_depth(0.5), 128);
        assert_eq!(quantize_depth(2.0), 255);
        assert_eq!(quantize_depth(f32::NAN), 0);
    }
}
