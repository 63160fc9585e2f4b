//! The manifest (`manifest.json`): what was baked, how, and the counts the loader checks.

use std::path::Path;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::directions;
use crate::error::FormatError;
use crate::node::{MAX_NODES, QuadNode};
use crate::slab::{DirectionFrame, Sphere};

use super::*;

/// Where the baked model came from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SourceInfo {
    /// File name of the OBJ (no folder, so that bakes are reproducible anywhere).
    pub file: String,
    /// FNV-1a 64 hash (hex) of the OBJ, MTL and texture bytes: a cache key.
    pub hash: String,
    /// Triangles used (after triangulating polygons and skipping degenerate ones).
    pub triangles: u64,
    /// Degenerate (zero-area) triangles skipped.
    pub degenerate_triangles: u64,
    /// Material names.
    pub materials: Vec<String>,
    /// Height of the model's highest vertex above y = 0 (metres; a tree stands on y = 0).
    /// Absent in atlases baked before it was recorded: [`AtlasManifest::model_top`] then
    /// falls back to the top of the bounding sphere.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub top: Option<f32>,
    /// How far the model's foot reaches from its axis (metres at scale 1,
    /// [`crate::model::footprint_radius`] of its vertices): `forest scene` lowers a tree on a
    /// slope to the lowest ground under it. Absent in atlases baked before it was recorded:
    /// it is then computed from the atlas's stored model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub foot: Option<f32>,
}

/// The manifest of an atlas (`manifest.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AtlasManifest {
    /// Always [`ATLAS_FORMAT`].
    pub format: String,
    /// Always [`ATLAS_VERSION`] for this crate.
    pub version: u32,
    /// The model baked.
    pub source: SourceInfo,
    /// Bake parameters.
    pub params: BakeParams,
    /// The sphere every slab image frames (object space, metres).
    pub bounding_sphere: Sphere,
    /// Sampling directions with their image frames (`params.directions` of them).
    pub directions: Vec<DirectionFrame>,
    /// Triangulation of the directions seen from above the horizon (see [`crate::directions`]).
    pub direction_triangles: Vec<[u32; 3]>,
    /// Triangulation of the directions seen from below the horizon (empty when `below` is 0).
    pub lower_triangles: Vec<[u32; 3]>,
    /// Quad levels per slab image.
    pub levels: u32,
    /// Root node index of each layer (`direction·slabs + slab`); `None` for a blank layer.
    pub layer_roots: Vec<Option<u32>>,
    /// Nodes per level, summed over all layers (`levels` entries).
    pub nodes_per_level: Vec<u64>,
    /// Total nodes.
    pub node_count: u64,
    /// Where the hybrid method should switch this model from its triangles to the quad
    /// stream, measured by `forest bake` on the GPU. Absent in atlases baked without a GPU
    /// or before it was measured: the hybrid then uses its default.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hybrid_switch: Option<HybridSwitch>,
    /// The opacity volume in [`OPACITY_FILE`] (see [`crate::opacity`]).
    pub opacity: OpacityInfo,
}

/// How the opacity volume ([`OPACITY_FILE`]) is sized and coded.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OpacityInfo {
    /// Voxels per side: [`crate::opacity::VOLUME_RESOLUTION`].
    pub resolution: u32,
    /// Optical depth per voxel length of code 255 (finite, ≥ 0).
    pub max_depth: f32,
}

/// Where the quad stream becomes as accurate as the model's own triangles (full geometry at
/// 1×), both compared with 4×4 supersampled full geometry (mean FLIP over seeded cameras
/// around one tree). The distance is stored as the size the finest quads project to there,
/// `finest_quad_pixels`, which carries over to any viewport, field of view and tree size
/// ("as accurate" within [`HybridSwitch::tolerance`]):
/// at focal length `f` pixels a tree of crown radius `R` switches at
/// `d = f · (2R / 2^(levels−1)) / finest_quad_pixels`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HybridSwitch {
    /// Projected width (pixels) of the finest quads at the crossover; in
    /// [`HybridSwitch::MIN_PIXELS`, `HybridSwitch::MAX_PIXELS`].
    pub finest_quad_pixels: f32,
    /// The crossover in crown radii from the crown's centre, at the viewport and field of
    /// view it was measured with.
    pub crown_radii: f32,
    /// Viewport it was measured at (pixels).
    pub viewport: [u32; 2],
    /// Vertical field of view it was measured at (degrees).
    pub fov_y_deg: f32,
    /// ε of the quad stream it was measured at (pixels).
    pub epsilon: f32,
    /// Cameras per distance.
    pub cameras: u32,
    /// The error the switch allows the quad stream above the triangles', as a fraction of
    /// theirs: the crossover is where the stream's mean FLIP first reaches `(1 + tolerance)`
    /// times the triangles'. 0 (atlases measured before it was recorded): as accurate.
    #[serde(default)]
    pub tolerance: f32,
    /// Where the hybrid may draw its near trees in the discrete-LOD baseline's mesh LOD 1 and
    /// LOD 2 instead of the full model, as fractions of the switch distance in (0, 1): from
    /// there on, measured at the same rungs, the LOD was as accurate as the full model (within
    /// `tolerance`). `None`: never (the LOD's error stayed above the full model's up to the
    /// switch), as in atlases measured before it was recorded. LOD 2 never starts before LOD 1.
    #[serde(default, skip_serializing_if = "no_lods")]
    pub lod_from: [Option<f32>; 2],
    /// The stream's error stayed above `(1 + tolerance)` times the triangles' at every
    /// distance measured: `crown_radii` is the farthest one, where the measurement stopped,
    /// not a crossover, and the hybrid switches there. Written only when true; false in
    /// atlases measured before it was recorded.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub never_reached: bool,
}

/// The rule for where the hybrid's near trees take mesh LOD 1 and LOD 2
/// ([`HybridSwitch::lod_from`]), for the manifest and for hosts that set it
/// (`PreparedGeometry::set_lod_from`): each start, where present, a fraction of the switch
/// distance in (0, 1), and LOD 2 not before LOD 1. The error names the value.
pub fn check_lod_from(lod_from: &[Option<f32>; 2]) -> Result<(), String> {
    for (k, f) in lod_from.iter().enumerate() {
        if let Some(f) = *f
            && !(f > 0.0 && f < 1.0)
        {
            return Err(format!(
                "lod_from[{k}] = {f}, outside (0, 1) (a fraction of the switch distance)"
            ));
        }
    }
    if let [Some(a), Some(b)] = *lod_from
        && b < a
    {
        return Err(format!(
            "lod_from = [{a}, {b}]: mesh LOD 2 starts before LOD 1"
        ));
    }
    Ok(())
}

/// Whether a switch records no mesh-LOD band (such records are written without the field).
fn no_lods(lod_from: &[Option<f32>; 2]) -> bool {
    lod_from.iter().all(Option::is_none)
}

impl HybridSwitch {
    /// Smallest accepted [`HybridSwitch::finest_quad_pixels`].
    pub const MIN_PIXELS: f32 = 0.05;
    /// Largest accepted [`HybridSwitch::finest_quad_pixels`].
    pub const MAX_PIXELS: f32 = 64.0;
    /// Largest accepted [`HybridSwitch::crown_radii`]: the measurement's farthest rung lies
    /// well inside it.
    pub const MAX_CROWN_RADII: f32 = 1e4;
    /// Largest viewport side it may have been measured at (pixels), as `render --size`.
    pub const MAX_VIEWPORT: u32 = 16384;
    /// Largest ε it may have been measured at (pixels).
    pub const MAX_EPSILON: f32 = 1e4;
    /// Largest accepted [`HybridSwitch::tolerance`].
    pub const MAX_TOLERANCE: f32 = 10.0;

    /// Every field in its range: the switch size in [`Self::MIN_PIXELS`,
    /// `Self::MAX_PIXELS`], crown radii in (0, [`Self::MAX_CROWN_RADII`]], a viewport of 1 to
    /// [`Self::MAX_VIEWPORT`] pixels a side, a field of view in (0°, 180°), ε in (0,
    /// [`Self::MAX_EPSILON`]] and at least one camera. The error names the field.
    pub fn check(&self) -> Result<(), String> {
        let p = self.finest_quad_pixels;
        if !(Self::MIN_PIXELS..=Self::MAX_PIXELS).contains(&p) {
            return Err(format!(
                "finest_quad_pixels = {p}, outside [{}, {}]",
                Self::MIN_PIXELS,
                Self::MAX_PIXELS
            ));
        }
        let r = self.crown_radii;
        if !(r > 0.0 && r <= Self::MAX_CROWN_RADII) {
            return Err(format!(
                "crown_radii = {r}, outside (0, {}]",
                Self::MAX_CROWN_RADII
            ));
        }
        if self
            .viewport
            .iter()
            .any(|&v| !(1..=Self::MAX_VIEWPORT).contains(&v))
        {
            return Err(format!(
                "viewport = {:?}, expected 1 to {} pixels a side",
                self.viewport,
                Self::MAX_VIEWPORT
            ));
        }
        let f = self.fov_y_deg;
        if !(f > 0.0 && f < 180.0) {
            return Err(format!("fov_y_deg = {f}, outside (0, 180)"));
        }
        let e = self.epsilon;
        if !(e > 0.0 && e <= Self::MAX_EPSILON) {
            return Err(format!("epsilon = {e}, outside (0, {}]", Self::MAX_EPSILON));
        }
        if self.cameras == 0 {
            return Err("cameras = 0, expected at least 1".into());
        }
        let t = self.tolerance;
        if !(0.0..=Self::MAX_TOLERANCE).contains(&t) {
            return Err(format!(
                "tolerance = {t}, outside [0, {}]",
                Self::MAX_TOLERANCE
            ));
        }
        check_lod_from(&self.lod_from)?;
        Ok(())
    }
}

impl AtlasManifest {
    /// Height of the model's top above y = 0 (metres): the recorded [`SourceInfo::top`], else
    /// the top of the bounding sphere (an overestimate of up to the crown's half-width).
    pub fn model_top(&self) -> f32 {
        self.source
            .top
            .filter(|t| t.is_finite() && *t > 0.0)
            .unwrap_or(self.bounding_sphere.center.y + self.bounding_sphere.radius)
    }

    /// Bytes the runtime puts in GPU textures for this atlas: the colour and surface layers
    /// as BC7 each (16 bytes per 4×4 block) with mips down to 4×4, the node texture (8 bytes
    /// per texel, [`NODE_TEXTURE_WIDTH`] wide, rows rounded up) and the opacity volume (one
    /// byte per voxel).
    pub fn gpu_bytes(&self) -> u64 {
        let mut per_layer = 0u64;
        let mut side = u64::from(self.params.resolution);
        loop {
            let blocks = side.div_ceil(4);
            per_layer += blocks * blocks * 16;
            if side <= 4 {
                break;
            }
            side /= 2;
        }
        let rows = self
            .node_count
            .div_ceil(u64::from(NODE_TEXTURE_WIDTH))
            .max(1);
        2 * per_layer * u64::from(self.params.layers())
            + rows * u64::from(NODE_TEXTURE_WIDTH) * 8
            + u64::from(self.opacity.resolution).pow(3)
    }

    /// Sampling directions as vectors.
    pub fn direction_vectors(&self) -> Vec<Vec3> {
        self.directions.iter().map(|f| f.dir).collect()
    }

    /// Check the manifest's own consistency (counts, ranges, finite numbers).
    pub(super) fn check(&self, path: &Path) -> Result<(), FormatError> {
        let bad = |what: String| Err(FormatError::invalid(path, what));
        if self.format != ATLAS_FORMAT {
            return Err(FormatError::Version {
                path: path.into(),
                what: format!("format is {:?}, expected {ATLAS_FORMAT:?}", self.format),
            });
        }
        if self.version != ATLAS_VERSION {
            return Err(FormatError::Version {
                path: path.into(),
                what: format!(
                    "atlas version {} but this program reads version {ATLAS_VERSION}: bake \
                     the model again",
                    self.version
                ),
            });
        }
        self.params
            .validate()
            .or_else(|e| bad(format!("params: {e}")))?;
        if self.opacity.resolution != crate::opacity::VOLUME_RESOLUTION {
            return bad(format!(
                "opacity.resolution = {}, but this program reads volumes of {} voxels a side",
                self.opacity.resolution,
                crate::opacity::VOLUME_RESOLUTION
            ));
        }
        let max = crate::opacity::MAX_VOXEL_DEPTH;
        if !(self.opacity.max_depth.is_finite() && (0.0..=max).contains(&self.opacity.max_depth)) {
            return bad(format!(
                "opacity.max_depth = {}, expected an optical depth per voxel of 0 to {max}",
                self.opacity.max_depth
            ));
        }
        if self.levels != self.params.levels() {
            return bad(format!(
                "levels = {}, but resolution {} and min_quad {} give {}",
                self.levels,
                self.params.resolution,
                self.params.min_quad,
                self.params.levels()
            ));
        }
        let total = self.params.total_directions();
        if self.directions.len() != total as usize {
            return bad(format!(
                "{} direction frames for {} directions",
                self.directions.len(),
                total
            ));
        }
        // The frames are the params' directions (within rounding of the platform's
        // trigonometry), and the triangles triangulate them.
        let want = directions::sampling_directions(self.params.directions, self.params.below);
        for (i, (f, &d)) in self.directions.iter().zip(&want).enumerate() {
            let w = DirectionFrame::new(d);
            let close = [(f.dir, w.dir), (f.right, w.right), (f.up, w.up)]
                .iter()
                .all(|(a, b)| a.is_finite() && a.abs_diff_eq(*b, 1e-4));
            if !close {
                return bad(format!(
                    "direction {i} is not the frame of the params' direction {i} (dir {}, right \
                     {}, up {}; expected {}, {}, {})",
                    f.dir, f.right, f.up, w.dir, w.right, w.up
                ));
            }
        }
        let dirs = self.direction_vectors();
        directions::check_triangulation(&dirs, &self.direction_triangles, false)
            .or_else(|e| bad(format!("direction_triangles: {e}")))?;
        if self.params.below == 0 && !self.lower_triangles.is_empty() {
            return bad("lower_triangles given for an atlas without directions below".into());
        }
        directions::check_triangulation(&dirs, &self.lower_triangles, true)
            .or_else(|e| bad(format!("lower_triangles: {e}")))?;
        // Empty lists pass the check above; they are right only where there is nothing to
        // triangulate (fewer than three directions in a half).
        let (upper, lower) = directions::triangulate_sphere(&dirs);
        for (name, stored, made) in [
            ("direction_triangles", &self.direction_triangles, upper),
            ("lower_triangles", &self.lower_triangles, lower),
        ] {
            if stored.is_empty() && !made.is_empty() {
                return bad(format!(
                    "{name} is empty, but its directions make {} triangles",
                    made.len()
                ));
            }
        }
        let s = &self.bounding_sphere;
        if !(s.center.is_finite() && s.radius.is_finite() && s.radius > 0.0) {
            return bad(format!("bounding sphere {s:?} is not finite and positive"));
        }
        let reach = s.center.abs().max_element() + s.radius;
        if reach > crate::species::MAX_MODEL_COORDINATE {
            return bad(format!(
                "bounding sphere (centre {}, radius {:e}) reaches {reach:e} model units from the \
                 origin, beyond the ±{:e} a model may have",
                s.center,
                s.radius,
                crate::species::MAX_MODEL_COORDINATE
            ));
        }
        if self.layer_roots.len() != self.params.layers() as usize {
            return bad(format!(
                "{} layer roots for {} layers",
                self.layer_roots.len(),
                self.params.layers()
            ));
        }
        if self.nodes_per_level.len() != self.levels as usize {
            return bad(format!(
                "{} per-level counts for {} levels",
                self.nodes_per_level.len(),
                self.levels
            ));
        }
        let sum: u64 = self.nodes_per_level.iter().sum();
        if sum != self.node_count || self.node_count > MAX_NODES {
            return bad(format!(
                "node_count = {} but the per-level counts add up to {sum} (at most {MAX_NODES})",
                self.node_count
            ));
        }
        if let Some(h) = &self.hybrid_switch {
            h.check().or_else(|e| bad(format!("hybrid_switch.{e}")))?;
        }
        if let Some(t) = self.source.top {
            // The highest vertex of a tree standing on y = 0, within a model's coordinates.
            let max = crate::species::MAX_MODEL_COORDINATE;
            if !(t.is_finite() && t > 0.0 && t <= max) {
                return bad(format!(
                    "source.top = {t}, expected a height above 0 (the tree's foot) of at most \
                     {max:e}"
                ));
            }
        }
        if let Some(f) = self.source.foot
            && !(f.is_finite() && f >= 0.0)
        {
            return bad(format!(
                "source.foot = {f}, expected a finite radius of 0 or more"
            ));
        }
        Ok(())
    }
}

/// Count nodes per level from the structure, or `None` when a node lies deeper than `levels`.
pub fn nodes_per_level(nodes: &[QuadNode], roots: usize, levels: u32) -> Option<Vec<u64>> {
    let mut level = vec![0u32; nodes.len()];
    let mut counts = vec![0u64; levels as usize];
    for (i, n) in nodes.iter().enumerate() {
        if i >= roots && level[i] == 0 {
            return None; // not reached from a root
        }
        *counts.get_mut(level[i] as usize)? += 1;
        for c in 0..4 {
            if let Some(k) = n.child_index(c) {
                *level.get_mut(k as usize)? = level[i] + 1;
            }
        }
    }
    Some(counts)
}

/// Build the manifest of a bake from its parts (directions from [`directions`]).
pub fn manifest_for(
    params: BakeParams,
    source: SourceInfo,
    bounding_sphere: Sphere,
    layer_roots: Vec<Option<u32>>,
    nodes_per_level: Vec<u64>,
) -> AtlasManifest {
    let dirs = directions::sampling_directions(params.directions, params.below);
    let (upper, lower) = directions::triangulate_sphere(&dirs);
    AtlasManifest {
        format: ATLAS_FORMAT.into(),
        version: ATLAS_VERSION,
        source,
        levels: params.levels(),
        bounding_sphere,
        direction_triangles: upper,
        lower_triangles: lower,
        directions: dirs.into_iter().map(DirectionFrame::new).collect(),
        layer_roots,
        node_count: nodes_per_level.iter().sum(),
        nodes_per_level,
        params,
        hybrid_switch: None,
        opacity: OpacityInfo {
            resolution: crate::opacity::VOLUME_RESOLUTION,
            max_depth: 0.0,
        },
    }
}
