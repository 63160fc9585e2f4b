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
pub const FIRST_CHILD_BITS: u32 = 28;
/// The largest number of nodes an atlas can hold (the first-child index must fit 28 bits).
pub const MAX_NODES: u64 = 1 << FIRST_CHILD_BITS;

/// A quad-hierarchy node: 8 bytes, read by WGSL as one texel of an `Rg32Uint` texture.
///
/// - `child`: bits 0..28 the index of the first existing child, bits 28..32 the child mask
///   (bit `i` set when child `i` exists, i.e. is not blank). Zero for a leaf.
/// - `depth`: the fitted plane's depth at the 4 corners, unorm8 relative to the node's slab:
///   0 at the slab's near clipping plane (towards the sampling camera), 255 at its far one.
///   WGSL reads it as one little-endian `u32`, corner 0 in the low byte.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Pod, Zeroable)]
pub struct QuadNode {
    /// First child index (28 bits) and child mask (high 4 bits).
    pub child: u32,
    /// Corner depths, unorm8 within the slab, corners in the order TL, TR, BL, BR.
    pub depth: [u8; 4],
}

impl QuadNode {
    /// A node with the given child mask (4 bits), first child index and quantised corner depths.
    ///
    /// # Panics
    /// If `first_child` does not fit 28 bits or `mask` has bits above the 4th (caller bugs).
    pub fn new(mask: u8, first_child: u32, depth: [u8; 4]) -> Self {
        assert!(mask < 16, "child mask has 4 bits");
        assert!(
            u64::from(first_child) < MAX_NODES,
            "first child index fits 28 bits"
        );
        let first_child = if mask == 0 { 0 } else { first_child };
        Self {
            child: first_child | (u32::from(mask) << FIRST_CHILD_BITS),
            depth,
        }
    }

    /// The child mask: bit `i` is set when child `i` exists.
    pub fn mask(&self) -> u8 {
        (self.child >> FIRST_CHILD_BITS) as u8
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
