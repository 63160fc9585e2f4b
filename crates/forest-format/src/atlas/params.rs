//! The bake parameters an atlas records: sizes, directions, slabs, colour encoding, plane fit.

use serde::{Deserialize, Serialize};

use crate::error::FormatError;
use crate::node::level_count;

use super::*;

/// How the colour mosaic is stored on disk.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase", tag = "codec")]
pub enum ColourEncoding {
    /// Baseline JPEG, 4:2:0, standard Huffman tables, at this quality (1–100).
    Jpeg {
        /// JPEG quality.
        quality: u8,
    },
    /// Lossless PNG.
    Png,
}

impl ColourEncoding {
    /// The colour file name inside the atlas folder.
    pub fn file_name(&self) -> &'static str {
        match self {
            Self::Jpeg { .. } => "colour.jpg",
            Self::Png => "colour.png",
        }
    }
}

/// How a quad-hierarchy node's depth plane is fitted to its pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PlaneFit {
    /// Split the node's pixels at depth gaps, fit the heaviest cluster (front on ties), and
    /// keep the corner depths within that cluster's depth range: no plane bridges a gap.
    #[default]
    GapAware,
    /// One weighted least-squares plane over all the node's pixels (the paper's fit); corners
    /// clamped to the slab only.
    LeastSquares,
}

impl PlaneFit {
    /// Short name for the CLI and the benchmark tables.
    pub fn name(self) -> &'static str {
        match self {
            PlaneFit::GapAware => "gap-aware",
            PlaneFit::LeastSquares => "least-squares",
        }
    }
}

/// Every parameter of a bake, with the defaults of the paper.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BakeParams {
    /// Number of sampling directions over the upper hemisphere, horizon and zenith included
    /// (1..=256; default 15).
    pub directions: u32,
    /// Sampling directions below the horizon, for trees seen from below (default 5: four at
    /// −45° and the nadir; 0 clamps views from below onto the horizon). `directions + below`
    /// is at most 256.
    pub below: u32,
    /// How node planes are fitted.
    pub plane_fit: PlaneFit,
    /// Parallel slabs per direction (1..=16; default 2).
    pub slabs: u32,
    /// Slab image side in pixels, a power of two (2..=8192; default 512).
    pub resolution: u32,
    /// Side of the smallest quad in pixels, a power of two below `resolution` (default 4).
    pub min_quad: u32,
    /// Jittered samples per pixel (1..=256; default 4).
    pub spp: u32,
    /// How the colour mosaic is stored.
    pub colour: ColourEncoding,
}

impl Default for BakeParams {
    fn default() -> Self {
        Self {
            directions: 15,
            below: 5,
            plane_fit: PlaneFit::GapAware,
            slabs: 2,
            resolution: 512,
            min_quad: 4,
            spp: 4,
            colour: ColourEncoding::Jpeg { quality: 80 },
        }
    }
}

impl BakeParams {
    /// Number of slab images (layers): `(directions + below) × slabs`.
    pub fn layers(&self) -> u32 {
        self.total_directions() * self.slabs
    }

    /// Sampling directions in all: `directions + below`.
    pub fn total_directions(&self) -> u32 {
        self.directions + self.below
    }

    /// Number of quad levels, `log2(resolution) − log2(min_quad) + 1`.
    pub fn levels(&self) -> u32 {
        level_count(self.resolution, self.min_quad)
    }

    /// Columns of the colour and alpha mosaics: `ceil(sqrt(layers))`.
    pub fn mosaic_columns(&self) -> u32 {
        (f64::from(self.layers()).sqrt().ceil() as u32).max(1)
    }

    /// Rows of the mosaics.
    pub fn mosaic_rows(&self) -> u32 {
        self.layers().div_ceil(self.mosaic_columns())
    }

    /// Check every parameter; the error names the parameter, its value and the allowed range.
    pub fn validate(&self) -> Result<(), FormatError> {
        let p = |s: String| Err(FormatError::Param(s));
        if !(1..=256).contains(&self.directions) {
            return p(format!(
                "directions = {}: must be 1 to 256",
                self.directions
            ));
        }
        if self.below > 256 - self.directions {
            return p(format!(
                "below = {}: directions + below must be at most 256 (directions = {})",
                self.below, self.directions
            ));
        }
        if !(1..=16).contains(&self.slabs) {
            return p(format!("slabs = {}: must be 1 to 16", self.slabs));
        }
        if !self.resolution.is_power_of_two() || !(2..=8192).contains(&self.resolution) {
            return p(format!(
                "resolution = {}: must be a power of two from 2 to 8192",
                self.resolution
            ));
        }
        if !self.min_quad.is_power_of_two() {
            return p(format!(
                "min-quad = {}: must be a power of two",
                self.min_quad
            ));
        }
        if self.min_quad >= self.resolution {
            return p(format!(
                "min-quad = {} must be smaller than the resolution ({})",
                self.min_quad, self.resolution
            ));
        }
        if self.levels() > 13 {
            return p(format!(
                "resolution / min-quad = {} gives {} levels; at most 13 are supported",
                self.resolution / self.min_quad,
                self.levels()
            ));
        }
        if !(1..=256).contains(&self.spp) {
            return p(format!("spp = {}: must be 1 to 256", self.spp));
        }
        if let ColourEncoding::Jpeg { quality } = self.colour
            && !(1..=100).contains(&quality)
        {
            return p(format!("quality = {quality}: must be 1 to 100"));
        }
        let side =
            u64::from(self.resolution) * u64::from(self.mosaic_columns().max(self.mosaic_rows()));
        if side > MAX_MOSAIC_SIDE {
            return p(format!(
                "the colour mosaic would be {side} pixels wide, above {MAX_MOSAIC_SIDE}: lower \
                 the resolution or the number of directions or slabs"
            ));
        }
        Ok(())
    }
}
