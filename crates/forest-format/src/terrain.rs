//! Terrain: a regular height field the trees stand on, drawn by every method.
//!
//! Samples lie on a square grid in the x–z plane, `spacing` metres apart, sample `(i, j)` at
//! `(origin.x + i·spacing, origin.z + j·spacing)`. Each cell is split into two triangles along
//! its diagonal from `(i, j)` to `(i+1, j+1)`, and the surface is linear on each: this is the
//! mesh the renderers draw, so [`Terrain::height`] is exactly the surface on screen and a tree
//! placed at that height stands on it. Outside the grid the ground is flat at y = 0 (the
//! environment pass's endless plane); the renderers close the gap at the border with vertical
//! skirts down to y = 0.
//!
//! Sources: [`Terrain::generate`] (seeded hills fading into the plain at the border) and
//! [`Terrain::from_image`] (a 16-bit greyscale PNG, or an OpenEXR file of heights in metres).

use std::path::Path;

use crate::error::FormatError;
use crate::noise::value_noise;

/// Most samples along either side of a height field (4097 × 4097 heights are 64 MiB).
pub const MAX_SIDE: u32 = 4097;
/// Largest height magnitude (metres): higher than any mountain, low enough that every
/// coordinate stays within [`crate::limits::MAX_COORDINATE`].
pub const MAX_HEIGHT: f32 = 20_000.0;

/// A height field: see the module documentation.
#[derive(Clone, Debug, PartialEq)]
pub struct Terrain {
    /// Samples along x and along z (each 2 to [`MAX_SIDE`]).
    pub size: [u32; 2],
    /// World (x, z) of sample (0, 0), metres.
    pub origin: [f32; 2],
    /// Metres between neighbouring samples (> 0).
    pub spacing: f32,
    /// Heights (metres, finite, |h| ≤ [`MAX_HEIGHT`]), row after row: sample `(i, j)` at
    /// `heights[j·size[0] + i]`.
    pub heights: Vec<f32>,
}

/// The ground's height at world (x, z) over an optional terrain, metres: the terrain's
/// [`Terrain::height`], or the flat ground's 0 without one.
pub fn ground_height(terrain: Option<&Terrain>, x: f32, z: f32) -> f32 {
    terrain.map_or(0.0, |t| t.height(x, z))
}

/// Parameters of [`Terrain::generate`].
#[derive(Clone, Debug, PartialEq)]
pub struct TerrainParams {
    /// The field covers `[−half_extent, half_extent]²` (metres, > 0).
    pub half_extent: f32,
    /// Metres between samples (> 0).
    pub spacing: f32,
    /// Height of the highest possible hilltop above the lowest valley floor, metres (≥ 0).
    pub relief: f32,
    /// Size of a hill, metres (> 0): the wavelength of the noise's first octave.
    pub hill_size: f32,
    /// Width of the border over which the hills fade to the plain, as a fraction of
    /// `half_extent` (0 to 1).
    pub fade: f32,
    /// Random seed.
    pub seed: u64,
}

impl Default for TerrainParams {
    fn default() -> Self {
        Self {
            half_extent: 1000.0,
            spacing: 8.0,
            relief: 80.0,
            hill_size: 900.0,
            fade: 0.125,
            seed: 1,
        }
    }
}

impl Terrain {
    /// Check the grid and every height; the message names the first problem.
    pub fn check(&self) -> Result<(), String> {
        let [nx, nz] = self.size;
        if !(2..=MAX_SIDE).contains(&nx) || !(2..=MAX_SIDE).contains(&nz) {
            return Err(format!(
                "a {nx}×{nz} height field: each side must hold 2 to {MAX_SIDE} samples"
            ));
        }
        if self.heights.len() != nx as usize * nz as usize {
            return Err(format!(
                "{} heights for a {nx}×{nz} height field",
                self.heights.len()
            ));
        }
        if !(self.spacing.is_finite() && self.spacing > 0.0) {
            return Err(format!(
                "sample spacing {} m must be positive",
                self.spacing
            ));
        }
        if !self.origin.iter().all(|o| o.is_finite()) {
            return Err(format!("grid origin {:?} must be finite", self.origin));
        }
        // The farthest grid coordinate from the origin on either axis.
        let far = [(self.origin[0], nx), (self.origin[1], nz)]
            .iter()
            .map(|&(o, n)| o.abs().max((o + self.spacing * (n - 1) as f32).abs()))
            .fold(0.0, f32::max);
        if far.is_nan() || far > crate::limits::MAX_COORDINATE {
            return Err(format!(
                "the height field reaches {far} m from the origin, farther than {} m",
                crate::limits::MAX_COORDINATE
            ));
        }
        if let Some(k) = self
            .heights
            .iter()
            .position(|h| !(h.is_finite() && h.abs() <= MAX_HEIGHT))
        {
            return Err(format!(
                "height {} at sample ({}, {}) is not a finite height within ±{MAX_HEIGHT} m",
                self.heights[k],
                k % nx as usize,
                k / nx as usize
            ));
        }
        Ok(())
    }

    /// World (x, z) extent of the grid: `(min, max)` corners, metres.
    pub fn bounds(&self) -> ([f32; 2], [f32; 2]) {
        let [nx, nz] = self.size;
        let [ox, oz] = self.origin;
        (
            [ox, oz],
            [
                ox + self.spacing * (nx - 1) as f32,
                oz + self.spacing * (nz - 1) as f32,
            ],
        )
    }

    /// Whether world (x, z) lies on the grid (borders included).
    pub fn contains(&self, x: f32, z: f32) -> bool {
        let (lo, hi) = self.bounds();
        x >= lo[0] && x <= hi[0] && z >= lo[1] && z <= hi[1]
    }

    fn sample(&self, i: usize, j: usize) -> f32 {
        self.heights[j * self.size[0] as usize + i]
    }

    /// The triangle holding world (x, z), which must be on the grid: its first corner (i, j),
    /// the height there, and the rise per sample along x and along z on the triangle
    /// (00, 10, 11) when the fractions satisfy fx ≥ fz, else (00, 11, 01); with the fractions.
    fn triangle(&self, x: f32, z: f32) -> (f32, f32, f32, f32, f32) {
        let [nx, nz] = self.size;
        let u = (x - self.origin[0]) / self.spacing;
        let v = (z - self.origin[1]) / self.spacing;
        // The last row and column belong to the cell before them.
        let i = (u.floor() as usize).min(nx as usize - 2);
        let j = (v.floor() as usize).min(nz as usize - 2);
        let (fx, fz) = (u - i as f32, v - j as f32);
        let (h00, h11) = (self.sample(i, j), self.sample(i + 1, j + 1));
        let (dx, dz) = if fx >= fz {
            let h10 = self.sample(i + 1, j);
            (h10 - h00, h11 - h10)
        } else {
            let h01 = self.sample(i, j + 1);
            (h11 - h01, h01 - h00)
        };
        (h00, dx, dz, fx, fz)
    }

    /// The drawn surface's height at world (x, z), metres: linear on each of a cell's two
    /// triangles (see the module documentation); 0 outside the grid.
    pub fn height(&self, x: f32, z: f32) -> f32 {
        if !self.contains(x, z) {
            return 0.0;
        }
        let (h00, dx, dz, fx, fz) = self.triangle(x, z);
        h00 + fx * dx + fz * dz
    }

    /// The slope of the drawn surface at world (x, z), as the tangent of its angle to the
    /// horizontal (rise over run), from the gradient of the triangle holding (x, z) (0 outside
    /// the grid).
    pub fn slope(&self, x: f32, z: f32) -> f32 {
        if !self.contains(x, z) {
            return 0.0;
        }
        let (_, dx, dz, _, _) = self.triangle(x, z);
        (dx * dx + dz * dz).sqrt() / self.spacing
    }

    /// The drawn surface's lowest height under the disk of `radius` metres about world (x, z)
    /// (a negative or non-finite radius counts as 0), where a tree whose foot reaches that far
    /// stands without floating on any side ([`crate::model::footprint_radius`]). The surface is
    /// linear on each triangle, so its minimum over the disk lies at a grid sample inside the
    /// disk or on the disk's circle: every sample inside is taken, and on the circle every
    /// point where it crosses a triangle's edge (a grid line or a cell's diagonal) and
    /// [`Self::FOOT_SAMPLES`] points between. So the result is never below the true minimum and
    /// at most `radius·s·(1 − cos(π/FOOT_SAMPLES))` above it, `s` the steepest slope under the
    /// circle (2 mm for a 0.5 m foot on a 35° slope). Only the grid counts: the part of a disk
    /// past its border (where the drawn ground drops to the plane) is left out. The work grows
    /// with the grid lines and samples the disk covers, at most the grid's.
    pub fn lowest_under(&self, x: f32, z: f32, radius: f32) -> f32 {
        let mut lo = self.height(x, z);
        if !(radius.is_finite() && radius > 0.0) {
            return lo;
        }
        // Only points on the grid count: past its border the drawn ground drops to the plane
        // at y = 0, which a foot overhanging the border does not stand on.
        let mut point = |px: f32, pz: f32| {
            if self.contains(px, pz) {
                lo = lo.min(self.height(px, pz));
            }
        };
        for k in 0..Self::FOOT_SAMPLES {
            let a = k as f32 * std::f32::consts::TAU / Self::FOOT_SAMPLES as f32;
            point(x + radius * a.cos(), z + radius * a.sin());
        }
        // Where the circle crosses the triangles' edges: the grid lines x = const and
        // z = const, and the cells' diagonals x − z = const (see `triangle`), each only where
        // the grid has one (so a huge radius costs at most the grid's lines).
        let (ox, oz, sp) = (self.origin[0], self.origin[1], self.spacing);
        let [nx, nz] = self.size.map(i64::from);
        // Offsets k·sp from `o`, for k in kmin..=kmax, between two coordinates.
        let lines = |lo_w: f32, hi_w: f32, o: f32, kmin: i64, kmax: i64| {
            let first = (((lo_w - o) / sp).ceil() as i64).max(kmin);
            let last = (((hi_w - o) / sp).floor() as i64).min(kmax);
            (first..=last).map(move |k| o + k as f32 * sp)
        };
        for gx in lines(x - radius, x + radius, ox, 0, nx - 1) {
            let h = (radius * radius - (gx - x) * (gx - x)).max(0.0).sqrt();
            point(gx, z - h);
            point(gx, z + h);
        }
        for gz in lines(z - radius, z + radius, oz, 0, nz - 1) {
            let h = (radius * radius - (gz - z) * (gz - z)).max(0.0).sqrt();
            point(x - h, gz);
            point(x + h, gz);
        }
        // Diagonals x − z = ox − oz + k·sp (k = i − j): signed distance d of the centre.
        let reach = radius * std::f32::consts::SQRT_2;
        let c0 = x - z - (ox - oz);
        for k in lines(c0 - reach, c0 + reach, 0.0, 1 - nz, nx - 1) {
            let d = (c0 - k) / std::f32::consts::SQRT_2;
            let h = (radius * radius - d * d).max(0.0).sqrt() / std::f32::consts::SQRT_2;
            let (fx, fz) = (
                x - d / std::f32::consts::SQRT_2,
                z + d / std::f32::consts::SQRT_2,
            );
            point(fx + h, fz + h);
            point(fx - h, fz - h);
        }
        // Grid samples inside the disk.
        let index = |w: f32, o: f32, n: i64| ((w - o) / sp).clamp(0.0, (n - 1) as f32);
        let (i0, i1) = (
            index(x - radius, ox, nx).ceil() as usize,
            index(x + radius, ox, nx).floor() as usize,
        );
        let (j0, j1) = (
            index(z - radius, oz, nz).ceil() as usize,
            index(z + radius, oz, nz).floor() as usize,
        );
        for j in j0..=j1 {
            for i in i0..=i1 {
                let (sx, sz) = (ox + i as f32 * sp, oz + j as f32 * sp);
                if (sx - x).hypot(sz - z) <= radius {
                    lo = lo.min(self.sample(i, j));
                }
            }
        }
        lo
    }

    /// Points on the circle [`Self::lowest_under`] samples.
    pub const FOOT_SAMPLES: u32 = 32;

    /// Lowest and highest sample, metres.
    pub fn height_range(&self) -> (f32, f32) {
        self.heights
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &h| {
                (lo.min(h), hi.max(h))
            })
    }

    /// Seeded rolling hills: five octaves of value noise, shaped so valleys are broad and
    /// hilltops rounder, from 0 m to at most `relief`, fading to 0 m over the outer `fade` of
    /// the field so that it meets the flat ground around it without a step.
    pub fn generate(p: &TerrainParams) -> Result<Self, String> {
        if !(p.half_extent.is_finite() && p.half_extent > 0.0) {
            return Err(format!(
                "terrain half extent {} m must be positive",
                p.half_extent
            ));
        }
        if !(p.spacing.is_finite() && p.spacing > 0.0) {
            return Err(format!("terrain spacing {} m must be positive", p.spacing));
        }
        if !(p.relief.is_finite() && (0.0..=MAX_HEIGHT).contains(&p.relief)) {
            return Err(format!("relief {} m must be 0 to {MAX_HEIGHT} m", p.relief));
        }
        if !(p.fade > 0.0 && p.fade <= 1.0) {
            return Err(format!(
                "fade {}: must be above 0 and at most 1 (of the half extent)",
                p.fade
            ));
        }
        if !(p.hill_size.is_finite() && p.hill_size > 0.0) {
            return Err(format!("hill size {} m must be positive", p.hill_size));
        }
        let cells = (2.0 * f64::from(p.half_extent) / f64::from(p.spacing)).ceil();
        if cells + 1.0 > f64::from(MAX_SIDE) {
            return Err(format!(
                "a terrain {:.0} m across at {} m spacing needs {} samples a side, more than \
                 {MAX_SIDE}: raise the spacing to at least {:.1} m",
                2.0 * p.half_extent,
                p.spacing,
                cells + 1.0,
                2.0 * p.half_extent / (MAX_SIDE - 1) as f32
            ));
        }
        let n = cells as u32 + 1;
        let spacing = 2.0 * p.half_extent / (n - 1) as f32;
        let origin = [-p.half_extent, -p.half_extent];
        let border = p.half_extent * p.fade;
        let mut heights = Vec::with_capacity(n as usize * n as usize);
        for j in 0..n {
            for i in 0..n {
                let x = origin[0] + i as f32 * spacing;
                let z = origin[1] + j as f32 * spacing;
                let mut sum = 0.0;
                let mut norm = 0.0;
                for o in 0..5 {
                    let f = (1 << o) as f32;
                    let a = 0.5f32.powi(o);
                    sum += a * value_noise(
                        x * f / p.hill_size,
                        z * f / p.hill_size,
                        p.seed.wrapping_add(0x7e44 + o as u64),
                    );
                    norm += a;
                }
                // Noise sums cluster near 0: stretch to [0, 1], then flatten the valleys.
                let u = (0.5 + 0.9 * sum / norm).clamp(0.0, 1.0);
                let shaped = u * u * (3.0 - 2.0 * u);
                let edge = (p.half_extent - x.abs()).min(p.half_extent - z.abs());
                let t = (edge / border).clamp(0.0, 1.0);
                let fade = t * t * (3.0 - 2.0 * t);
                heights.push(p.relief * shaped * fade);
            }
        }
        let t = Terrain {
            size: [n, n],
            origin,
            spacing,
            heights,
        };
        t.check()?;
        Ok(t)
    }

    /// Load a height field from an image, centred on the origin, `spacing` metres between
    /// pixels, row 0 at the smallest z:
    /// - a 16-bit greyscale PNG: 0 to 65535 map to 0 to `png_relief` metres;
    /// - an OpenEXR file (`.exr`): heights in metres, from its `Y` channel, else `R`, else
    ///   `Z`, else the first (any sample type; single-channel files are the usual export).
    ///
    /// 8-bit or colour PNGs are refused (256 levels would terrace every slope; a colour image
    /// is rarely a height field), and so are images smaller than 2×2 or larger than
    /// [`MAX_SIDE`], and non-finite heights. Errors name the file and the cause.
    pub fn from_image(path: &Path, spacing: f32, png_relief: f32) -> Result<Self, FormatError> {
        let bytes = crate::bounded::read(path, crate::bounded::limit::DATA)?;
        Self::parse_image(path, &bytes, spacing, png_relief)
    }

    /// [`Terrain::from_image`] of the file's bytes (`path` names the file and, by its
    /// extension, the format).
    pub fn parse_image(
        path: &Path,
        bytes: &[u8],
        spacing: f32,
        png_relief: f32,
    ) -> Result<Self, FormatError> {
        let bad = |what: String| FormatError::invalid(path, what);
        if !(spacing.is_finite() && spacing > 0.0) {
            return Err(bad(format!("sample spacing {spacing} m must be positive")));
        }
        let exr = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        let png = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"));
        if !exr && !png {
            return Err(bad(
                "a height field must be a 16-bit greyscale .png or an .exr".into(),
            ));
        }
        if png && !(png_relief.is_finite() && (0.0..=MAX_HEIGHT).contains(&png_relief)) {
            return Err(bad(format!(
                "relief {png_relief} m must be 0 to {MAX_HEIGHT} m"
            )));
        }
        let (w, h, heights) = if exr {
            exr_heights(path, bytes)?
        } else {
            let format = image::ImageFormat::Png;
            let (w, h) = crate::bounded::image_dimensions(bytes, Some(format), path)?;
            if !(2..=MAX_SIDE).contains(&w) || !(2..=MAX_SIDE).contains(&h) {
                return Err(bad(format!(
                    "a {w}×{h} image: a height field needs 2 to {MAX_SIDE} pixels a side"
                )));
            }
            let scale = |v: u16| f32::from(v) / 65535.0 * png_relief;
            let heights: Vec<f32> = match crate::bounded::decode_image(bytes, Some(format), path)? {
                image::DynamicImage::ImageLuma16(g) => g.pixels().map(|p| scale(p.0[0])).collect(),
                image::DynamicImage::ImageLumaA16(g) => g.pixels().map(|p| scale(p.0[0])).collect(),
                other => {
                    let c = other.color();
                    return Err(bad(format!(
                        "a PNG of {} bits per sample with {} channel(s): a height field must \
                         be a 16-bit greyscale PNG (or an EXR of heights in metres)",
                        c.bits_per_pixel() / u16::from(c.channel_count()),
                        c.channel_count()
                    )));
                }
            };
            (w, h, heights)
        };
        let t = Terrain {
            size: [w, h],
            origin: [
                -spacing * (w - 1) as f32 / 2.0,
                -spacing * (h - 1) as f32 / 2.0,
            ],
            spacing,
            heights,
        };
        t.check().map_err(bad)?;
        Ok(t)
    }

    /// Append the binary form (sizes, origin, spacing, heights; little-endian).
    pub fn write_to(&self, out: &mut Vec<u8>) {
        for v in self.size {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in [self.origin[0], self.origin[1], self.spacing] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(bytemuck::cast_slice(&self.heights));
    }

    /// Read the binary form from `take` (a reader of the next `n` bytes), checking the sizes
    /// before allocating.
    pub fn read_from(
        mut take: impl FnMut(usize) -> Result<Vec<u8>, String>,
    ) -> Result<Self, String> {
        let mut u32s = |n: usize| -> Result<Vec<u32>, String> {
            Ok(bytemuck::pod_collect_to_vec(&take(4 * n)?))
        };
        let head = u32s(5)?;
        let size = [head[0], head[1]];
        if !(2..=MAX_SIDE).contains(&size[0]) || !(2..=MAX_SIDE).contains(&size[1]) {
            return Err(format!(
                "a {}×{} height field: each side must hold 2 to {MAX_SIDE} samples",
                size[0], size[1]
            ));
        }
        let f = |k: usize| f32::from_bits(head[k]);
        let n = size[0] as usize * size[1] as usize;
        let heights = bytemuck::pod_collect_to_vec(&take(4 * n)?);
        let t = Terrain {
            size,
            origin: [f(2), f(3)],
            spacing: f(4),
            heights,
        };
        t.check()?;
        Ok(t)
    }
}

/// Without the `terrain-exr` feature (the runtime's build): an EXR height field is refused.
#[cfg(not(feature = "terrain-exr"))]
fn exr_heights(path: &Path, _bytes: &[u8]) -> Result<(u32, u32, Vec<f32>), FormatError> {
    Err(FormatError::invalid(
        path,
        "an EXR height field needs forest-format's `terrain-exr` feature (forest scene has it); \
         or give a 16-bit greyscale .png",
    ))
}

/// The heights of an EXR height field: its size read from the header and checked before any
/// pixel is decoded, then one channel (`Y`, else `R`, else `Z`, else the first) of the first
/// flat layer, as f32.
#[cfg(feature = "terrain-exr")]
fn exr_heights(path: &Path, bytes: &[u8]) -> Result<(u32, u32, Vec<f32>), FormatError> {
    use exr::prelude::{ReadChannels, ReadLayers};
    let img_err = |e: exr::error::Error| FormatError::Image {
        path: path.into(),
        what: e.to_string(),
    };
    let bad = |what: String| FormatError::invalid(path, what);
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false)
        .map_err(img_err)?;
    let header = meta
        .headers
        .iter()
        .find(|h| !h.deep)
        .ok_or_else(|| bad("an EXR without a flat (non-deep) layer".into()))?;
    let size = header.layer_size;
    let side = |n: usize| u32::try_from(n).ok().filter(|n| (2..=MAX_SIDE).contains(n));
    let (Some(_), Some(_)) = (side(size.0), side(size.1)) else {
        return Err(bad(format!(
            "a {}×{} image: a height field needs 2 to {MAX_SIDE} pixels a side",
            size.0, size.1
        )));
    };
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(img_err)?;
    let layer = image.layer_data;
    let (w, h) = (layer.size.0, layer.size.1);
    let (Some(w), Some(h)) = (side(w), side(h)) else {
        return Err(bad(format!(
            "a {w}×{h} image: a height field needs 2 to {MAX_SIDE} pixels a side"
        )));
    };
    let channels = &layer.channel_data.list;
    let named = |n: &str| channels.iter().find(|c| c.name.eq(n));
    let channel = named("Y")
        .or_else(|| named("R"))
        .or_else(|| named("Z"))
        .or_else(|| channels.first())
        .ok_or_else(|| bad("an EXR without channels".into()))?;
    use exr::prelude::FlatSamples as S;
    let heights: Vec<f32> = match &channel.sample_data {
        S::F16(v) => v.iter().map(|x| x.to_f32()).collect(),
        S::F32(v) => v.clone(),
        S::U32(v) => v.iter().map(|&x| x as f32).collect(),
    };
    if heights.len() != w as usize * h as usize {
        return Err(bad(format!(
            "channel {} holds {} samples for {w}×{h} pixels (subsampled channels are not \
             height fields)",
            channel.name,
            heights.len()
        )));
    }
    Ok((w, h, heights))
}

#[cfg(test)]
mod tests;
