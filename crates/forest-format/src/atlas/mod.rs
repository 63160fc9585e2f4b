//! The baked atlas of one tree model: a folder `NAME.atlas/` holding
//!
//! - `manifest.json`: format name and version, every bake parameter, the bounding sphere, the
//!   sampling directions with their frames and triangulation, per-level node counts;
//! - `colour.jpg` (or `colour.png` when baked lossless): every slab image's premultiplied,
//!   sRGB-encoded albedo (no light: light is applied at run time), tiled into one mosaic
//!   (layer `L = direction·slabs + slab` at column `L mod mosaic_columns`, row
//!   `L div mosaic_columns`);
//! - `alpha.png`: the coverage (alpha) mosaic, 8-bit, lossless;
//! - `surface.png`: what the run-time light needs besides the albedo, as RGBA8, linear and
//!   premultiplied by coverage like the colour: the octahedral code of the normal facing the
//!   sampling ray (object space, [`crate::shading::hemi_oct_encode`]) in R and G, the sky
//!   visibility in B and the translucency in A. The same tiling at [`SURFACE_SCALE`] times
//!   fewer pixels a side, straight (each texel its block's coverage-weighted mean), lossless;
//! - `opacity.png`: the opacity volume for self-shadowing under the run-time sun (see
//!   [`crate::opacity`]), 8-bit grey, slices stacked downwards;
//! - `nodes.bin`: the quad hierarchies of all layers (see [`crate::nodes_codec`]).
//!
//! [`Atlas::save`] writes to a temporary folder and renames it into place, so a reader never
//! sees half an atlas; [`Atlas::load`] checks the version and every size and count.

pub(crate) mod codecs;
mod manifest;
mod params;
mod surface;

pub use codecs::*;
pub use manifest::*;
pub use params::*;
pub use surface::SURFACE_SCALE;

use std::path::{Path, PathBuf};

use crate::error::FormatError;
use crate::node::QuadNode;
use crate::nodes_codec;
use crate::opacity::OpacityVolume;
use crate::shading::srgb_encode;

/// The `format` field of every atlas manifest.
pub const ATLAS_FORMAT: &str = "forest-atlas";
/// The atlas format version this crate reads and writes. Version 4 stores albedo, surface
/// attributes and an opacity volume for run-time light; versions 1 and 2 had one sun baked
/// into the colour, version 3 no volume: they are refused with a message to bake again.
pub const ATLAS_VERSION: u32 = 4;
/// Opacity-volume file name.
pub const OPACITY_FILE: &str = "opacity.png";
/// Surface-attribute mosaic file name.
pub const SURFACE_FILE: &str = "surface.png";
/// Manifest file name inside an atlas folder.
pub const MANIFEST_FILE: &str = "manifest.json";
/// Alpha mosaic file name.
pub const ALPHA_FILE: &str = "alpha.png";
/// Node file name.
pub const NODES_FILE: &str = "nodes.bin";
/// Width in texels of the node texture the runtime uploads (one node per texel).
pub const NODE_TEXTURE_WIDTH: u32 = 4096;
/// The largest mosaic side JPEG allows.
const MAX_MOSAIC_SIDE: u64 = 65_535;

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
    /// The surface mosaic file's bytes (RGBA8 PNG, see the module documentation).
    pub surface_file: Vec<u8>,
    /// The opacity volume file's bytes (8-bit grey PNG, see [`crate::opacity`]).
    pub opacity_file: Vec<u8>,
    /// All nodes, level by level; the roots are the first ones, in layer order.
    pub nodes: Vec<QuadNode>,
}

impl Atlas {
    /// Encode decoded layers and nodes into an atlas. `layers` (albedo and coverage) and
    /// `surface` (premultiplied surface attributes) must each hold `manifest.params.layers()`
    /// layers of `resolution²` pixels; `opacity` is the model's opacity volume (its size and
    /// coding go into the manifest).
    pub fn from_layers(
        mut manifest: AtlasManifest,
        layers: &Layers,
        surface: &Layers,
        opacity: &OpacityVolume,
        nodes: Vec<QuadNode>,
    ) -> Result<Self, FormatError> {
        manifest.opacity = OpacityInfo {
            resolution: opacity.resolution,
            max_depth: opacity.max_depth,
        };
        let p = &manifest.params;
        assert_eq!(layers.count, p.layers(), "one layer per direction and slab");
        assert_eq!(layers.resolution, p.resolution);
        assert_eq!(
            (surface.count, surface.resolution),
            (layers.count, layers.resolution)
        );
        let cols = p.mosaic_columns();
        let (w, h, mut rgb) = layers.mosaic(cols, &[0, 1, 2]);
        let (_, _, alpha) = layers.mosaic(cols, &[3]);
        if matches!(p.colour, ColourEncoding::Jpeg { .. }) {
            fill_blank(w, h, &mut rgb, &alpha);
        }
        let colour_file = match p.colour {
            ColourEncoding::Png => encode_png(w, h, &rgb, image::ExtendedColorType::Rgb8),
            #[cfg(not(feature = "atlas-jpeg"))]
            ColourEncoding::Jpeg { .. } => {
                return Err(FormatError::Image {
                    path: p.colour.file_name().into(),
                    what: "JPEG atlas colour needs forest-format's `atlas-jpeg` feature (the \
                           bake has it)"
                        .into(),
                });
            }
            #[cfg(feature = "atlas-jpeg")]
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
        let small = surface.surface_downsampled(layers, SURFACE_SCALE);
        let (sw, sh, surf) = small.mosaic(cols, &[0, 1, 2, 3]);
        let surface_file = encode_png(sw, sh, &surf, image::ExtendedColorType::Rgba8);
        Ok(Self {
            manifest,
            colour_file,
            alpha_file,
            surface_file,
            opacity_file: opacity.encode_png(),
            nodes,
        })
    }

    /// Decode the opacity volume (`path` names the atlas folder in errors).
    pub fn decode_opacity(&self, path: &Path) -> Result<OpacityVolume, FormatError> {
        let o = &self.manifest.opacity;
        OpacityVolume::decode_png(
            &self.opacity_file,
            o.resolution,
            o.max_depth,
            &path.join(OPACITY_FILE),
        )
    }

    /// Decode the surface mosaic (stored at `resolution /` [`SURFACE_SCALE`]) into layers at the
    /// slab resolution (RGBA8, premultiplied: each channel is clamped to the pixel's coverage from
    /// the alpha mosaic, `alpha`'s layers as [`Self::decode_layers`] returns them).
    pub fn decode_surface(&self, path: &Path, alpha: &Layers) -> Result<Layers, FormatError> {
        let p = &self.manifest.params;
        let file = path.join(SURFACE_FILE);
        let (cols, rows) = (p.mosaic_columns(), p.mosaic_rows());
        let side = p.resolution / SURFACE_SCALE;
        let (w, h) = (cols * side, rows * side);
        if (alpha.resolution, alpha.count) != (p.resolution, p.layers()) {
            return Err(FormatError::invalid(
                &file,
                format!(
                    "the coverage given holds {} layers of {}², the atlas {} of {}²",
                    alpha.count,
                    alpha.resolution,
                    p.layers(),
                    p.resolution
                ),
            ));
        }
        let dims = crate::bounded::image_dimensions(
            &self.surface_file,
            Some(image::ImageFormat::Png),
            &file,
        )?;
        if dims != (w, h) {
            return Err(FormatError::invalid(
                &file,
                format!(
                    "mosaic is {}×{} pixels, expected {w}×{h} ({cols}×{rows} tiles of {side}: \
                     the slab resolution over {SURFACE_SCALE})",
                    dims.0, dims.1
                ),
            ));
        }
        let img =
            crate::bounded::decode_image(&self.surface_file, Some(image::ImageFormat::Png), &file)?;
        let img = match img {
            image::DynamicImage::ImageRgba8(i) => i,
            other => {
                return Err(FormatError::invalid(
                    &file,
                    format!("surface mosaic is {:?}, expected 8-bit RGBA", other.color()),
                ));
            }
        };
        if img.dimensions() != (w, h) {
            return Err(FormatError::invalid(
                &file,
                format!(
                    "decoded to {}×{} pixels, expected {w}×{h}",
                    img.width(),
                    img.height()
                ),
            ));
        }
        let r = side as usize;
        let mut rgba = vec![0u8; p.layers() as usize * r * r * 4];
        for l in 0..p.layers() {
            let (tx, ty) = ((l % cols) * side, (l / cols) * side);
            let base = l as usize * r * r * 4;
            for y in 0..r {
                for x in 0..r {
                    let c = img.get_pixel(tx + x as u32, ty + y as u32).0;
                    let d = base + (y * r + x) * 4;
                    rgba[d..d + 4].copy_from_slice(&c);
                }
            }
        }
        let small = Layers {
            resolution: side,
            count: p.layers(),
            rgba,
        };
        Ok(small.surface_upsampled(alpha, SURFACE_SCALE))
    }

    /// Decode the colour and alpha mosaics into layers. Colour is clamped to the alpha
    /// (premultiplied: linear colour ≤ alpha, so fully transparent pixels are black), which
    /// undoes lossy-codec ringing outside the coverage.
    pub fn decode_layers(&self, path: &Path) -> Result<Layers, FormatError> {
        let p = &self.manifest.params;
        let colour_path = path.join(p.colour.file_name());
        let alpha_path = path.join(ALPHA_FILE);
        let format = match p.colour {
            ColourEncoding::Jpeg { .. } => image::ImageFormat::Jpeg,
            ColourEncoding::Png => image::ImageFormat::Png,
        };
        // Sizes from the headers first: a mosaic of the wrong size is refused undecoded.
        let (cols, rows) = (p.mosaic_columns(), p.mosaic_rows());
        let (w, h) = (cols * p.resolution, rows * p.resolution);
        for (file, bytes, format) in [
            (&colour_path, &self.colour_file, format),
            (&alpha_path, &self.alpha_file, image::ImageFormat::Png),
        ] {
            let dims = crate::bounded::image_dimensions(bytes, Some(format), file)?;
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
        let colour = crate::bounded::decode_image(&self.colour_file, Some(format), &colour_path)?
            .into_rgb8();
        let alpha = crate::bounded::decode_image(
            &self.alpha_file,
            Some(image::ImageFormat::Png),
            &alpha_path,
        )?;
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
        // The decoders must agree with the headers they were checked by.
        for (file, dims) in [
            (&colour_path, colour.dimensions()),
            (&alpha_path, alpha.dimensions()),
        ] {
            if dims != (w, h) {
                return Err(FormatError::invalid(
                    file,
                    format!("decoded to {}×{} pixels, expected {w}×{h}", dims.0, dims.1),
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
        self.save_with_model(path, None)
    }

    /// [`Self::save`] with the species' prepared model ([`crate::model`], its encoded bytes)
    /// written into the same folder, in the same atomic rename.
    pub fn save_with_model(&self, path: &Path, model: Option<&[u8]>) -> Result<u64, FormatError> {
        if path.exists() && !path.join(MANIFEST_FILE).is_file() {
            return Err(FormatError::invalid(
                path,
                "exists and is not an atlas folder: refusing to overwrite it",
            ));
        }
        check_only_atlas_files(path)?;
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
        crate::atomic::pending(&tmp);
        let result = (|| {
            std::fs::create_dir_all(&tmp).map_err(|e| FormatError::io(&tmp, e))?;
            let manifest =
                serde_json::to_vec_pretty(&self.manifest).expect("the manifest serialises to JSON");
            let files: [(&str, &[u8]); 6] = [
                (MANIFEST_FILE, &manifest),
                (self.manifest.params.colour.file_name(), &self.colour_file),
                (ALPHA_FILE, &self.alpha_file),
                (SURFACE_FILE, &self.surface_file),
                (OPACITY_FILE, &self.opacity_file),
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
            if let Some(bytes) = model {
                let f = tmp.join(crate::model::MODEL_FILE);
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
        crate::atomic::done(&tmp);
        result
    }

    /// Each file of the atlas folder with its bytes on disk, in [`Atlas::save`]'s order after
    /// the manifest: the colour mosaic, alpha, surface attributes, opacity volume and nodes.
    pub fn file_bytes(&self) -> Vec<(&'static str, u64)> {
        vec![
            (
                self.manifest.params.colour.file_name(),
                self.colour_file.len() as u64,
            ),
            (ALPHA_FILE, self.alpha_file.len() as u64),
            (SURFACE_FILE, self.surface_file.len() as u64),
            (OPACITY_FILE, self.opacity_file.len() as u64),
            (
                NODES_FILE,
                nodes_codec::encode(&self.nodes, self.root_count()).len() as u64,
            ),
        ]
    }

    /// Number of non-blank layers, whose roots are the first nodes.
    pub fn root_count(&self) -> usize {
        self.manifest.layer_roots.iter().flatten().count()
    }

    /// Read and check an atlas folder. Every error names the file and what is wrong.
    pub fn load(path: &Path) -> Result<Self, FormatError> {
        check_folder(path)?;
        let read = |file: &str| {
            let limit = if file == MANIFEST_FILE {
                crate::bounded::limit::TEXT
            } else {
                crate::bounded::limit::DATA
            };
            crate::bounded::read(&path.join(file), limit)
        };
        Self::from_files(path, &read)
    }

    /// Read and check an atlas folder's manifest alone (what was baked and how, the
    /// bounding sphere, the model's top), without reading its images or nodes.
    pub fn load_manifest(path: &Path) -> Result<AtlasManifest, FormatError> {
        check_folder(path)?;
        let mpath = path.join(MANIFEST_FILE);
        parse_manifest(
            &mpath,
            &crate::bounded::read(&mpath, crate::bounded::limit::TEXT)?,
        )
    }

    /// [`Atlas::load`] from the folder's files as `read(file name)` returns them (the files
    /// of the folder `path`, which errors name). The manifest is read and checked first, so
    /// no other file is read for an atlas whose manifest is refused.
    pub fn from_files(
        path: &Path,
        read: &dyn Fn(&str) -> Result<Vec<u8>, FormatError>,
    ) -> Result<Self, FormatError> {
        let mpath = path.join(MANIFEST_FILE);
        let manifest = parse_manifest(&mpath, &read(MANIFEST_FILE)?)?;
        let colour_file = read(manifest.params.colour.file_name())?;
        let alpha_file = read(ALPHA_FILE)?;
        let surface_file = read(SURFACE_FILE)?;
        let opacity_file = read(OPACITY_FILE)?;
        let npath = path.join(NODES_FILE);
        let node_bytes = read(NODES_FILE)?;
        // The header's count is checked against the manifest's before anything is inflated.
        let (claimed, _) =
            nodes_codec::header(&node_bytes).map_err(|e| FormatError::invalid(&npath, e))?;
        if claimed as u64 != manifest.node_count {
            return Err(FormatError::invalid(
                &npath,
                format!(
                    "its header claims {claimed} nodes, the manifest says {}",
                    manifest.node_count
                ),
            ));
        }
        let (nodes, roots) =
            nodes_codec::decode(&node_bytes).map_err(|e| FormatError::invalid(&npath, e))?;
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
            surface_file,
            opacity_file,
            nodes,
        };
        // Decoding checks the image sizes too.
        let layers = atlas.decode_layers(path)?;
        atlas.decode_surface(path, &layers)?;
        atlas.decode_opacity(path)?;
        Ok(atlas)
    }
}

/// An atlas path must name a folder; the error says how to make one.
fn check_folder(path: &Path) -> Result<(), FormatError> {
    if path.is_dir() {
        return Ok(());
    }
    Err(FormatError::invalid(
        path,
        if path.exists() {
            "is not an atlas folder (bake one with `forest bake MODEL.obj -o NAME.atlas`)"
        } else {
            "no such atlas (bake one with `forest bake MODEL.obj -o NAME.atlas`)"
        },
    ))
}

/// Parse and check the manifest read from `mpath` (which errors name).
/// Every file a bake may write into an atlas folder (both colour encodings').
pub const ATLAS_FILES: [&str; 8] = [
    MANIFEST_FILE,
    "colour.jpg",
    "colour.png",
    ALPHA_FILE,
    SURFACE_FILE,
    OPACITY_FILE,
    NODES_FILE,
    crate::model::MODEL_FILE,
];

/// The entries of atlas folder `path` that no bake writes (the user's own files, or
/// folders), sorted; empty when `path` does not exist.
pub fn foreign_entries(path: &Path) -> Vec<String> {
    let Ok(dir) = std::fs::read_dir(path) else {
        return Vec::new();
    };
    let mut out: Vec<String> = dir
        .flatten()
        .filter(|e| {
            let name = e.file_name();
            !(e.file_type().is_ok_and(|t| t.is_file())
                && ATLAS_FILES.iter().any(|f| name == std::ffi::OsStr::new(f)))
        })
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    out.sort();
    out
}

/// An atlas folder is replaced whole when baked again: refused while it holds anything a
/// bake did not write, which would be lost.
pub fn check_only_atlas_files(path: &Path) -> Result<(), FormatError> {
    let foreign = foreign_entries(path);
    if foreign.is_empty() {
        return Ok(());
    }
    Err(FormatError::invalid(
        path,
        format!(
            "holds {}, which no bake writes: baking into it again would replace the folder \
             and lose {}; move {} out, or bake to another folder",
            foreign.join(", "),
            if foreign.len() == 1 { "it" } else { "them" },
            if foreign.len() == 1 { "it" } else { "them" },
        ),
    ))
}

fn parse_manifest(mpath: &Path, bytes: &[u8]) -> Result<AtlasManifest, FormatError> {
    // The version first: an older manifest has other fields, and the error must say why.
    #[derive(serde::Deserialize)]
    struct Probe {
        format: Option<String>,
        version: Option<u32>,
    }
    if let Ok(Probe {
        format: Some(f),
        version: Some(v),
    }) = serde_json::from_slice::<Probe>(bytes)
        && f == ATLAS_FORMAT
        && v != ATLAS_VERSION
    {
        return Err(FormatError::Version {
            path: mpath.to_path_buf(),
            what: if v == 3 {
                format!(
                    "atlas version 3 has no opacity volume, which trees need to shade \
                     themselves under the run-time sun (version {ATLAS_VERSION}): bake the \
                     model again with `forest bake`"
                )
            } else if v < ATLAS_VERSION {
                format!(
                    "atlas version {v} has one sun baked into its colours; this program lights \
                     trees at run time (from version 3 on) and reads version {ATLAS_VERSION}: \
                     bake the model again \
                     with `forest bake` (the sun is now `forest render --sun AZ,EL`)"
                )
            } else {
                format!(
                    "atlas version {v} is newer than this program reads ({ATLAS_VERSION}): \
                     update forest or bake the model again"
                )
            },
        });
    }
    let manifest: AtlasManifest =
        serde_json::from_slice(bytes).map_err(|source| FormatError::Json {
            path: mpath.to_path_buf(),
            source,
        })?;
    let mut manifest = manifest;
    manifest.check(mpath)?;
    // The frames as this program computes them from the params, which the stored ones
    // were checked to be within rounding of.
    manifest.directions =
        crate::directions::sampling_directions(manifest.params.directions, manifest.params.below)
            .into_iter()
            .map(crate::slab::DirectionFrame::new)
            .collect();
    Ok(manifest)
}

#[cfg(test)]
mod tests;
