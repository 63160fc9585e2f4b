//! The one place that sizes every GPU buffer of the runtime: the quad stream's ([`Capacity`])
//! and the geometry renderer's per-frame lists ([`GeometryCapacity`]), which the hybrid uses
//! side by side.

use crate::gpu_types::{GpuArgs, GpuState, Quad};

/// Workgroup size of per-item passes.
pub const WG: u32 = 256;
/// Scan block (two items per thread).
pub const BLOCK: u32 = 512;
/// Most quads a stream holds: per-quad dispatches run one workgroup per [`WG`] quads, at
/// most 65 535 workgroups (the limit every device has).
pub const MAX_QUADS: u64 = WG as u64 * 65_535;

/// What the buffer sizes are computed from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CapacityInput {
    /// Tree instances in the forest.
    pub instances: u32,
    /// Largest `3 × slabs` over the species: level-0 quads one tree can emit.
    pub quads_per_tree: u32,
    /// Viewport in pixels.
    pub viewport: (u32, u32),
    /// Smallest ε (pixels) the scene will be refined with.
    pub min_epsilon: f32,
    /// Mean number of quad layers covering a pixel that refinement must afford.
    pub overdraw: f32,
    /// Explicit quad capacity, overriding the formula (and `grown`).
    pub max_quads: Option<u32>,
    /// Quads frames were found to need ([`crate::QuadStream::fit`]; 0 at first): the formula
    /// gives at least this many.
    pub grown: u32,
}

/// Buffer sizes in elements and bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Capacity {
    /// Quads each of the two stream buffers holds: `Q`.
    pub quads: u32,
    /// Elements of the first scan-data buffer (tree counts, then quads): `max(N, Q)`; the
    /// second holds `Q`.
    pub items: u32,
    /// Elements of the scan's block-sum buffer: `ceil(items/512)`, and at least two per
    /// block of trees (the cull scans its plain and composited counts side by side).
    pub sums: u32,
}

impl Capacity {
    /// `Q = min(N · quads_per_tree, W · H / 4) + overdraw · W · H / (ε_min / 2)²`, at most
    /// and at least `grown`, at most [`crate::MAX_QUADS`], unless given.
    ///
    /// The second term holds the quads refinement adds: each refined quad is at least `ε/2`
    /// pixels on a side, so a screen covered `overdraw` times holds at most that many. The
    /// first holds the level-0 quads of the visible trees, which no screen bound limits (a
    /// bird's-eye view sees every tree): it is an estimate, and a stream whose frames
    /// overflow it grows to what they need ([`crate::QuadStream::fit`]). When a frame needs
    /// more than the stream holds, the overflow policy applies (far trees' composited quads,
    /// then the farthest trees' quads first; refinement for the nearest) and counters report
    /// it; nothing is written out of bounds.
    pub fn new(c: &CapacityInput) -> Self {
        let quads = c.max_quads.unwrap_or_else(|| {
            let pixels = u64::from(c.viewport.0) * u64::from(c.viewport.1);
            let level0 = (u64::from(c.instances) * u64::from(c.quads_per_tree)).min(pixels / 4);
            let half = f64::from(c.min_epsilon.max(1.0)) / 2.0;
            let refine = f64::from(c.overdraw) * pixels as f64 / (half * half);
            (level0 + refine as u64)
                .max(u64::from(c.grown))
                .clamp(1, MAX_QUADS) as u32
        });
        let items = quads.max(c.instances).max(1);
        Self {
            quads,
            items,
            sums: items.div_ceil(BLOCK).max(2 * c.instances.div_ceil(BLOCK)),
        }
    }

    /// Bytes of each buffer the runtime allocates per renderer (not counting scene data).
    pub fn bytes(&self) -> u64 {
        let quad = std::mem::size_of::<Quad>() as u64;
        2 * u64::from(self.quads) * quad
            + u64::from(self.items) * 4
            + u64::from(self.quads) * 4
            + u64::from(self.sums) * 4
            + (std::mem::size_of::<GpuState>() + std::mem::size_of::<GpuArgs>()) as u64
    }
}

/// The geometry renderer's per-frame buffers, in elements. Every tree can be drawn as
/// geometry at once (the hybrid's near trees are a subset), so the lists hold every instance
/// and nothing can overflow.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GeometryCapacity {
    /// Draw segments: distance bands × species (at least 1).
    pub segments: u32,
    /// Elements of the classification-key list: every instance (at least 1, so that empty
    /// forests still bind a buffer).
    pub instances: u32,
    /// Elements of the visible list: every instance, listed up to `listings` times (a tree
    /// in a crossfade between two or three of the hybrid's mesh LODs is listed once per LOD),
    /// at least 1.
    pub listed: u32,
}

impl GeometryCapacity {
    /// Sizes for `instances` trees of `species` species drawn in `bands` distance bands,
    /// each listed at most `listings` times (1 to 3). `None` when the visible list's entries
    /// overflow 32 bits.
    pub fn new(instances: u32, species: u32, bands: u32, listings: u32) -> Option<Self> {
        Some(Self {
            segments: (bands * species).max(1),
            instances: instances.max(1),
            listed: instances.checked_mul(listings.clamp(1, 3))?.max(1),
        })
    }

    /// Bytes of the per-frame buffers: keys (4 bytes per instance), visible list (4 bytes
    /// per listing), counts and cursors (4 bytes per segment), indirect draw arguments (16
    /// bytes per segment).
    pub fn bytes(&self) -> u64 {
        (u64::from(self.instances) + u64::from(self.listed)) * 4
            + u64::from(self.segments) * (4 + 4 + 16)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formula_matches_the_documentation() {
        let input = CapacityInput {
            instances: 100_000,
            quads_per_tree: 6,
            viewport: (800, 600),
            min_epsilon: 8.0,
            overdraw: 4.0,
            max_quads: None,
            grown: 0,
        };
        let c = Capacity::new(&input);
        assert_eq!(c.quads, 120_000 + 120_000);
        assert_eq!(c.items, 240_000);
        assert_eq!(c.sums, 240_000u32.div_ceil(512));
        // Few trees: their level-0 quads, not the screen's quarter.
        let few = Capacity::new(&CapacityInput {
            instances: 10,
            ..input
        });
        assert_eq!(few.quads, 60 + 120_000);
        // Grown past the formula by frames that needed more; never below it.
        let grown = |quads| {
            Capacity::new(&CapacityInput {
                grown: quads,
                ..input
            })
            .quads
        };
        assert_eq!((grown(1_000_000), grown(1_000)), (1_000_000, 240_000));
        let fixed = Capacity::new(&CapacityInput {
            max_quads: Some(10),
            instances: 3,
            ..CapacityInput {
                instances: 0,
                quads_per_tree: 6,
                viewport: (8, 8),
                min_epsilon: 8.0,
                overdraw: 1.0,
                max_quads: None,
                grown: 1_000,
            }
        });
        assert_eq!((fixed.quads, fixed.items), (10, 10));
        // Many trees, a small stream: the cull's two block sums per block of trees.
        let many = Capacity::new(&CapacityInput {
            max_quads: Some(10),
            instances: 100_000,
            ..input
        });
        assert_eq!(
            (many.items, many.sums),
            (100_000, 2 * 100_000u32.div_ceil(512))
        );
        let g = GeometryCapacity::new(1000, 2, 12, 1).unwrap();
        assert_eq!((g.segments, g.instances, g.listed), (24, 1000, 1000));
        assert_eq!(g.bytes(), 8000 + 24 * 24);
        let empty = GeometryCapacity::new(0, 0, 12, 3).unwrap();
        assert_eq!((empty.segments, empty.listed), (1, 1));
        // Mesh-LOD crossfades list a tree up to three times.
        let g = GeometryCapacity::new(1000, 2, 12, 3).unwrap();
        assert_eq!((g.instances, g.listed), (1000, 3000));
        assert_eq!(g.bytes(), 16000 + 24 * 24);
        assert!(GeometryCapacity::new(u32::MAX / 2, 1, 16, 3).is_none());
    }
}
