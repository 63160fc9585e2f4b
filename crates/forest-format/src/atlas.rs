//! The baked atlas of one tree model: a folder `NAME.atlas/` holding
//!
//! - `manifest.json`: format name and version, every bake parameter, the bounding sphere, the
//!   sampling directions with their frames and triangulation, per-level node counts;
//! - `colour.jpg` (or `colour.png` when baked lossless): every slab image's premultiplied,
//!   sRGB-encoded RGB, tiled into one mosaic (layer `L = direction·slabs + slab` at column
//!   `L mod mosaic_columns`, row `L div mosaic_columns`);
//! - `alpha.png`: the coverage (alpha) mosaic, 8-bit, lossless;
//! - `nodes.bin`: the quad hierarchies of all layers (see [`crate::nodes_codec`]).
//!
//! [`Atlas::save`] writes to a temporary folder and renames it into place, so a reader never
//! sees half an atlas; [`Atlas::load`] checks the version and every size and count.

use std::path::{Path, PathBuf};

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::error::FormatError;
use crate::node::{MAX_NODES, QuadNode, level_count};
use crate::shading::{Lighting, srgb_encode};
use crate::slab::{DirectionFrame, Sphere};
use crate::{directions, nodes_codec};

/// The `format` field of every atlas manifest.
pub const ATLAS_FORMAT: &str = "forest-atlas";
/// The atlas format version this crate reads and writes.
pub const ATLAS_VERSION: u32 = 2;
/// Manifest file name inside an atlas folder.
pub const MANIFEST_FILE: &str = "manifest.json";
/// Alpha mosaic file name.
pub const ALPHA_FILE: &str = "alpha.png";
/// Node file name.
pub const NODES_FILE: &str = "nodes.bin";
/// Width in texels of the node texture the runtime uploads (`Rg32Uint`, one node per texel).
pub const NODE_TEXTURE_WIDTH: u32 = 4096;
/// The largest mosaic side JPEG allows.
const MAX_MOSAIC_SIDE: u64 = 65_535;

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
    /// Sun azimuth in degrees from +Z towards +X.
    pub sun_azimuth_deg: f32,
    /// Sun elevation in degrees above the horizon (0..=90).
    pub sun_elevation_deg: f32,
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
            sun_azimuth_deg: 30.0,
            sun_elevation_deg: 55.0,
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
        if !self.sun_azimuth_deg.is_finite()
            || !self.sun_elevation_deg.is_finite()
            || !(0.0..=90.0).contains(&self.sun_elevation_deg)
        {
            return p(format!(
                "sun = {},{}: azimuth must be finite and elevation 0 to 90 degrees",
                self.sun_azimuth_deg, self.sun_elevation_deg
            ));
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

    /// The lighting of this bake.
    pub fn lighting(&self) -> Lighting {
        Lighting::with_sun(self.sun_azimuth_deg, self.sun_elevation_deg)
    }
}

/// Where the baked model came from.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
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
    /// The lighting baked into the colours.
    pub lighting: Lighting,
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
}

impl AtlasManifest {
    /// Bytes the runtime puts in GPU textures for this atlas: the colour layers as BC7 (16
    /// bytes per 4×4 block) with mips down to 4×4, plus the node texture (8 bytes per texel,
    /// [`NODE_TEXTURE_WIDTH`] wide, rows rounded up).
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
        per_layer * u64::from(self.params.layers()) + rows * u64::from(NODE_TEXTURE_WIDTH) * 8
    }

    /// Sampling directions as vectors.
    pub fn direction_vectors(&self) -> Vec<Vec3> {
        self.directions.iter().map(|f| f.dir).collect()
    }

    /// Check the manifest's own consistency (counts, ranges, finite numbers).
    fn check(&self, path: &Path) -> Result<(), FormatError> {
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
        for (i, f) in self.directions.iter().enumerate() {
            let ok = [f.dir, f.right, f.up]
                .iter()
                .all(|v| v.is_finite() && (v.length() - 1.0).abs() < 1e-3);
            if !ok {
                return bad(format!("direction {i} is not a unit frame"));
            }
        }
        if let Some(t) = self
            .direction_triangles
            .iter()
            .chain(&self.lower_triangles)
            .find(|t| t.iter().any(|&i| i >= total))
        {
            return bad(format!(
                "direction triangle {t:?} names a direction beyond {total}"
            ));
        }
        let s = &self.bounding_sphere;
        if !(s.center.is_finite() && s.radius.is_finite() && s.radius > 0.0) {
            return bad(format!("bounding sphere {s:?} is not finite and positive"));
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
        let lighting_ok = [
            self.lighting.sun_dir,
            self.lighting.sun,
            self.lighting.sky,
            self.lighting.ground,
        ]
        .iter()
        .all(|v| v.is_finite());
        if !lighting_ok {
            return bad("lighting has a non-finite value".into());
        }
        Ok(())
    }
}

/// A baked atlas in memory: the manifest, the encoded colour and alpha mosaics (exactly the
/// bytes on disk) and the decoded nodes.
#[derive(Clone, Debug, PartialEq)]
pub struct Atlas {
    /// The manifest.
    pub manifest: AtlasManifest,
    /// The colour mosaic file's bytes (JPEG or PNG, per `manifest.params.colour`).
    pub colour_file: Vec<u8>,
    /// The alpha mosaic file's bytes (8-bit grey PNG).
    pub alpha_file: Vec<u8>,
    /// All nodes, level by level; the roots are the first ones, in layer order.
    pub nodes: Vec<QuadNode>,
}

/// Slab images decoded to RGBA8: layer-major, rows top to bottom, premultiplied sRGB-encoded RGB
/// and linear alpha (`layers × resolution² × 4` bytes).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Layers {
    /// Side of each layer in pixels.
    pub resolution: u32,
    /// Number of layers.
    pub count: u32,
    /// The pixels.
    pub rgba: Vec<u8>,
}

impl Layers {
    /// The RGBA8 pixels of one layer.
    pub fn layer(&self, layer: u32) -> &[u8] {
        let n = (self.resolution as usize).pow(2) * 4;
        &self.rgba[layer as usize * n..(layer as usize + 1) * n]
    }

    /// Tile the layers into a mosaic of `columns` columns; returns (width, height, pixels).
    pub fn mosaic(&self, columns: u32, channels: &[usize]) -> (u32, u32, Vec<u8>) {
        let r = self.resolution as usize;
        let rows = self.count.div_ceil(columns);
        let (w, h) = (columns * self.resolution, rows * self.resolution);
        let c = channels.len();
        let mut out = vec![0u8; w as usize * h as usize * c];
        for l in 0..self.count {
            let (tx, ty) = ((l % columns) as usize * r, (l / columns) as usize * r);
            let src = self.layer(l);
            for y in 0..r {
                for x in 0..r {
                    let s = (y * r + x) * 4;
                    let d = ((ty + y) * w as usize + tx + x) * c;
                    for (k, &ch) in channels.iter().enumerate() {
                        out[d + k] = src[s + ch];
                    }
                }
            }
        }
        (w, h, out)
    }
}

fn encode_png(w: u32, h: u32, data: &[u8], colour: image::ExtendedColorType) -> Vec<u8> {
    use image::ImageEncoder;
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new_with_quality(
        &mut out,
        image::codecs::png::CompressionType::Best,
        image::codecs::png::FilterType::Adaptive,
    )
    .write_image(data, w, h, colour)
    .expect("PNG encoding of an in-memory image of valid size cannot fail");
    out
}

/// Fill the colour of blank pixels (alpha 0) with the average of nearby fully covered ones
/// (push-pull over a 2×2 pyramid). Decoding clamps colour to alpha, so blank pixels read back
/// black whatever they hold; filling them keeps JPEG from ringing and darkening the
/// silhouettes against a black background, and makes the file smaller.
pub fn fill_blank(w: u32, h: u32, rgb: &mut [u8], alpha: &[u8]) {
    let (w, h) = (w as usize, h as usize);
    // Level 0: colour sums and weights of fully covered pixels.
    let mut levels: Vec<(usize, usize, Vec<[f32; 4]>)> = vec![(
        w,
        h,
        (0..w * h)
            .map(|i| {
                if alpha[i] == 255 {
                    let c = &rgb[i * 3..i * 3 + 3];
                    [f32::from(c[0]), f32::from(c[1]), f32::from(c[2]), 1.0]
                } else {
                    [0.0; 4]
                }
            })
            .collect(),
    )];
    while levels.last().is_some_and(|l| l.0 > 1 || l.1 > 1) {
        let (pw, ph, prev) = levels.last().unwrap();
        let (nw, nh) = (pw.div_ceil(2), ph.div_ceil(2));
        let mut next = vec![[0f32; 4]; nw * nh];
        for y in 0..*ph {
            for x in 0..*pw {
                let s = prev[y * pw + x];
                let d = &mut next[(y / 2) * nw + x / 2];
                for k in 0..4 {
                    d[k] += s[k];
                }
            }
        }
        levels.push((nw, nh, next));
    }
    // Pull, coarsest first: a cell becomes its average (weight 1) or, when empty, its
    // parent's (already pulled) value.
    let normalise = |c: &mut [f32; 4]| {
        if c[3] > 0.0 {
            *c = [c[0] / c[3], c[1] / c[3], c[2] / c[3], 1.0];
        }
    };
    levels.last_mut().unwrap().2.iter_mut().for_each(normalise);
    for k in (0..levels.len() - 1).rev() {
        let (upper, lower) = levels.split_at_mut(k + 1);
        let (lw, _, cells) = &mut upper[k];
        let (pw, _, parents) = &lower[0];
        for (i, cell) in cells.iter_mut().enumerate() {
            if cell[3] > 0.0 {
                normalise(cell);
            } else {
                let (x, y) = (i % *lw, i / *lw);
                *cell = parents[(y / 2) * pw + x / 2];
            }
        }
    }
    let (_, _, fine) = &levels[0];
    for i in 0..w * h {
        if alpha[i] == 0 {
            for c in 0..3 {
                rgb[i * 3 + c] = fine[i][c].round().clamp(0.0, 255.0) as u8;
            }
        }
    }
}

/// Encode 8-bit coverage as the smallest PNG: indexed with 1, 2 or 4 bits per pixel when it
/// has at most 2, 4 or 16 distinct values (as it does with up to 15 samples per pixel: coverage
/// takes `spp + 1` values), else 8-bit grey. The palette holds grey `(v, v, v)` entries.
pub fn encode_alpha_png(w: u32, h: u32, alpha: &[u8]) -> Vec<u8> {
    let mut seen = [false; 256];
    alpha.iter().for_each(|&a| seen[a as usize] = true);
    let values: Vec<u8> = (0..=255u8).filter(|&v| seen[v as usize]).collect();
    let bits = match values.len() {
        0..=2 => 1,
        3..=4 => 2,
        5..=16 => 4,
        _ => return encode_png(w, h, alpha, image::ExtendedColorType::L8),
    };
    let mut index = [0u8; 256];
    for (i, &v) in values.iter().enumerate() {
        index[v as usize] = i as u8;
    }
    let per_byte = 8 / bits;
    let row_bytes = (w as usize).div_ceil(per_byte);
    let mut packed = vec![0u8; row_bytes * h as usize];
    for y in 0..h as usize {
        for x in 0..w as usize {
            let i = index[alpha[y * w as usize + x] as usize];
            let shift = 8 - bits * (x % per_byte + 1);
            packed[y * row_bytes + x / per_byte] |= i << shift;
        }
    }
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, w, h);
    enc.set_color(png::ColorType::Indexed);
    enc.set_depth(match bits {
        1 => png::BitDepth::One,
        2 => png::BitDepth::Two,
        _ => png::BitDepth::Four,
    });
    enc.set_palette(values.iter().flat_map(|&v| [v, v, v]).collect::<Vec<u8>>());
    enc.set_deflate_compression(png::DeflateCompression::Level(9));
    // Filters only hurt packed low-bit indices.
    enc.set_filter(png::Filter::NoFilter);
    let mut writer = enc
        .write_header()
        .expect("PNG header of an in-memory image cannot fail");
    writer
        .write_image_data(&packed)
        .expect("PNG data of the declared size cannot fail");
    writer
        .finish()
        .expect("finishing an in-memory PNG cannot fail");
    out
}

impl Atlas {
    /// Encode decoded layers and nodes into an atlas. `layers` must hold
    /// `manifest.params.layers()` layers of `resolution²` pixels.
    pub fn from_layers(
        manifest: AtlasManifest,
        layers: &Layers,
        nodes: Vec<QuadNode>,
    ) -> Result<Self, FormatError> {
        let p = &manifest.params;
        assert_eq!(layers.count, p.layers(), "one layer per direction and slab");
        assert_eq!(layers.resolution, p.resolution);
        let cols = p.mosaic_columns();
        let (w, h, mut rgb) = layers.mosaic(cols, &[0, 1, 2]);
        let (_, _, alpha) = layers.mosaic(cols, &[3]);
        if matches!(p.colour, ColourEncoding::Jpeg { .. }) {
            fill_blank(w, h, &mut rgb, &alpha);
        }
        let colour_file = match p.colour {
            ColourEncoding::Png => encode_png(w, h, &rgb, image::ExtendedColorType::Rgb8),
            ColourEncoding::Jpeg { quality } => {
                let mut out = Vec::new();
                let mut enc = jpeg_encoder::Encoder::new(&mut out, quality);
                // Optimised Huffman tables with 4:2:0 decode wrongly in zune-jpeg 0.5 (the
                // image crate's decoder): colours come out green. The standard tables cost ~3%.
                enc.set_optimized_huffman_tables(false);
                enc.set_sampling_factor(jpeg_encoder::SamplingFactor::R_4_2_0);
                enc.encode(&rgb, w as u16, h as u16, jpeg_encoder::ColorType::Rgb)
                    .map_err(|e| FormatError::Image {
                        path: p.colour.file_name().into(),
                        what: e.to_string(),
                    })?;
                out
            }
        };
        let alpha_file = encode_alpha_png(w, h, &alpha);
        Ok(Self {
            manifest,
            colour_file,
            alpha_file,
            nodes,
        })
    }

    /// Decode the colour and alpha mosaics into layers. Colour is clamped to the alpha
    /// (premultiplied: linear colour ≤ alpha, so fully transparent pixels are black), which
    /// undoes lossy-codec ringing outside the coverage.
    pub fn decode_layers(&self, path: &Path) -> Result<Layers, FormatError> {
        let p = &self.manifest.params;
        let colour_path = path.join(p.colour.file_name());
        let alpha_path = path.join(ALPHA_FILE);
        let img_err = |path: &Path, e: image::ImageError| FormatError::Image {
            path: path.into(),
            what: e.to_string(),
        };
        let format = match p.colour {
            ColourEncoding::Jpeg { .. } => image::ImageFormat::Jpeg,
            ColourEncoding::Png => image::ImageFormat::Png,
        };
        let colour = image::load_from_memory_with_format(&self.colour_file, format)
            .map_err(|e| img_err(&colour_path, e))?
            .to_rgb8();
        let alpha = image::load_from_memory_with_format(&self.alpha_file, image::ImageFormat::Png)
            .map_err(|e| img_err(&alpha_path, e))?;
        // 8-bit grey, or a grey palette (which decodes to RGB with equal channels).
        let alpha = match alpha {
            image::DynamicImage::ImageLuma8(a) => a,
            image::DynamicImage::ImageRgb8(rgb)
                if rgb.pixels().all(|p| p[0] == p[1] && p[1] == p[2]) =>
            {
                image::GrayImage::from_fn(rgb.width(), rgb.height(), |x, y| {
                    image::Luma([rgb.get_pixel(x, y)[0]])
                })
            }
            other => {
                return Err(FormatError::invalid(
                    &alpha_path,
                    format!("alpha mosaic is {:?}, expected grey", other.color()),
                ));
            }
        };
        let (cols, rows) = (p.mosaic_columns(), p.mosaic_rows());
        let (w, h) = (cols * p.resolution, rows * p.resolution);
        for (file, dims) in [
            (&colour_path, colour.dimensions()),
            (&alpha_path, alpha.dimensions()),
        ] {
            if dims != (w, h) {
                return Err(FormatError::invalid(
                    file,
                    format!(
                        "mosaic is {}×{} pixels, expected {w}×{h} ({cols}×{rows} tiles of {})",
                        dims.0, dims.1, p.resolution
                    ),
                ));
            }
        }
        // Largest encoded colour allowed for each alpha: srgb_encode(alpha), the encoded form
        // of `srgb_decode(c) ≤ a`.
        let limit: [u8; 256] = std::array::from_fn(|a| {
            (srgb_encode(a as f32 / 255.0) * 255.0)
                .floor()
                .clamp(0.0, 255.0) as u8
        });
        let r = p.resolution as usize;
        let mut rgba = vec![0u8; p.layers() as usize * r * r * 4];
        for l in 0..p.layers() {
            let (tx, ty) = ((l % cols) * p.resolution, (l / cols) * p.resolution);
            let base = l as usize * r * r * 4;
            for y in 0..r {
                for x in 0..r {
                    let (mx, my) = (tx + x as u32, ty + y as u32);
                    let a = alpha.get_pixel(mx, my).0[0];
                    let c = colour.get_pixel(mx, my).0;
                    let d = base + (y * r + x) * 4;
                    let m = limit[a as usize];
                    rgba[d..d + 4].copy_from_slice(&[c[0].min(m), c[1].min(m), c[2].min(m), a]);
                }
            }
        }
        Ok(Layers {
            resolution: p.resolution,
            count: p.layers(),
            rgba,
        })
    }

    /// Write the atlas folder atomically: into a temporary sibling folder, then renamed onto
    /// `path`. An existing atlas at `path` is replaced; any other existing file or folder there
    /// is left alone and reported as an error.
    pub fn save(&self, path: &Path) -> Result<u64, FormatError> {
        if path.exists() && !path.join(MANIFEST_FILE).is_file() {
            return Err(FormatError::invalid(
                path,
                "exists and is not an atlas folder: refusing to overwrite it",
            ));
        }
        let name = path
            .file_name()
            .ok_or_else(|| FormatError::invalid(path, "not a folder name"))?
            .to_string_lossy()
            .into_owned();
        let parent = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let tmp = crate::atomic::tmp_name(&parent.join(&name));
        let _ = std::fs::remove_dir_all(&tmp);
        let result = (|| {
            std::fs::create_dir_all(&tmp).map_err(|e| FormatError::io(&tmp, e))?;
            let manifest =
                serde_json::to_vec_pretty(&self.manifest).expect("the manifest serialises to JSON");
            let files: [(&str, &[u8]); 4] = [
                (MANIFEST_FILE, &manifest),
                (self.manifest.params.colour.file_name(), &self.colour_file),
                (ALPHA_FILE, &self.alpha_file),
                (
                    NODES_FILE,
                    &nodes_codec::encode(&self.nodes, self.root_count()),
                ),
            ];
            let mut total = 0u64;
            for (file, bytes) in files {
                let f = tmp.join(file);
                std::fs::write(&f, bytes).map_err(|e| FormatError::io(&f, e))?;
                total += bytes.len() as u64;
            }
            if path.exists() {
                let old = parent.join(format!(".{name}.old-{}", std::process::id()));
                std::fs::rename(path, &old).map_err(|e| FormatError::io(path, e))?;
                std::fs::rename(&tmp, path).map_err(|e| FormatError::io(path, e))?;
                let _ = std::fs::remove_dir_all(&old);
            } else {
                std::fs::rename(&tmp, path).map_err(|e| FormatError::io(path, e))?;
            }
            Ok(total)
        })();
        if result.is_err() {
            let _ = std::fs::remove_dir_all(&tmp);
        }
        result
    }

    /// Number of non-blank layers, whose roots are the first nodes.
    pub fn root_count(&self) -> usize {
        self.manifest.layer_roots.iter().flatten().count()
    }

    /// Read and check an atlas folder. Every error names the file and what is wrong.
    pub fn load(path: &Path) -> Result<Self, FormatError> {
        if !path.is_dir() {
            return Err(FormatError::invalid(
                path,
                if path.exists() {
                    "is not an atlas folder (bake one with `forest bake MODEL.obj -o NAME.atlas`)"
                } else {
                    "no such atlas (bake one with `forest bake MODEL.obj -o NAME.atlas`)"
                },
            ));
        }
        let read = |file: &str| {
            let f = path.join(file);
            std::fs::read(&f).map_err(|e| FormatError::io(&f, e))
        };
        let mpath = path.join(MANIFEST_FILE);
        let manifest: AtlasManifest =
            serde_json::from_slice(&read(MANIFEST_FILE)?).map_err(|source| FormatError::Json {
                path: mpath.clone(),
                source,
            })?;
        manifest.check(&mpath)?;
        let colour_file = read(manifest.params.colour.file_name())?;
        let alpha_file = read(ALPHA_FILE)?;
        let npath = path.join(NODES_FILE);
        let (nodes, roots) =
            nodes_codec::decode(&read(NODES_FILE)?).map_err(|e| FormatError::invalid(&npath, e))?;
        if nodes.len() as u64 != manifest.node_count {
            return Err(FormatError::invalid(
                &npath,
                format!(
                    "holds {} nodes, the manifest says {}",
                    nodes.len(),
                    manifest.node_count
                ),
            ));
        }
        // Roots are the first nodes, in layer order.
        let expected: Vec<u32> = manifest.layer_roots.iter().flatten().copied().collect();
        if expected != (0..roots as u32).collect::<Vec<_>>() {
            return Err(FormatError::invalid(
                &mpath,
                format!(
                    "layer_roots {:?} do not number the {roots} roots of {NODES_FILE} in order",
                    manifest.layer_roots
                ),
            ));
        }
        let per_level = nodes_per_level(&nodes, roots, manifest.levels);
        match per_level {
            Some(counts) if counts == manifest.nodes_per_level => {}
            other => {
                return Err(FormatError::invalid(
                    &npath,
                    format!(
                        "nodes per level {:?} do not match the manifest's {:?} ({} levels)",
                        other, manifest.nodes_per_level, manifest.levels
                    ),
                ));
            }
        }
        let atlas = Self {
            manifest,
            colour_file,
            alpha_file,
            nodes,
        };
        // Decoding checks the image sizes too.
        atlas.decode_layers(path)?;
        Ok(atlas)
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
        lighting: params.lighting(),
        levels: params.levels(),
        bounding_sphere,
        direction_triangles: upper,
        lower_triangles: lower,
        directions: dirs.into_iter().map(DirectionFrame::new).collect(),
        layer_roots,
        node_count: nodes_per_level.iter().sum(),
        nodes_per_level,
        params,
    }
}
