//! A species' prepared model for the geometry-based methods (full geometry, stochastic
//! simplification, discrete LODs + billboards, and the hybrid's near trees): what the bake's
//! tracer, simplifier and voxeliser make of an OBJ/glTF model, stored so that a renderer needs
//! neither the model file nor the bake.
//!
//! `forest bake` writes it into the atlas folder as [`MODEL_FILE`]; it records the hash of the
//! model it was prepared from, which must equal the atlas manifest's `source.hash`.
//!
//! The file: an uncompressed header (magic, version, counts, the few scalars, and an FNV-1a
//! 64 checksum of the header's bytes before it), then one zlib stream holding the arrays in a
//! fixed order (zlib's Adler-32 covers them). A header changed by a byte is refused, whatever
//! the value it was changed to. Every count is checked, and the inflated size
//! computed from them bounded, before anything is allocated; every index is checked against
//! what it indexes, so a renderer can upload the arrays as they are.

use std::io::Read;
use std::path::Path;

use crate::error::FormatError;
use crate::opacity::{OpacityVolume, VOLUME_RESOLUTION};

/// The prepared model's file name inside an atlas folder.
pub const MODEL_FILE: &str = "model.bin";
/// The file's first eight bytes.
pub const MODEL_MAGIC: [u8; 8] = *b"FORESTMD";
/// The format version this crate reads and writes.
pub const MODEL_VERSION: u32 = 2;
/// Side (texels) of every material texture layer.
pub const MATERIAL_TEXTURE_SIZE: u32 = 512;
/// Billboard image side (texels).
pub const BILLBOARD_RESOLUTION: u32 = 256;
/// Billboard views per model (one per elevation the discrete-LOD baseline picks among).
pub const BILLBOARDS: u32 = 4;
/// "No index": a branch vertex's `element`, a material without a texture layer.
pub const NONE: u32 = u32::MAX;
/// The largest hash string stored (bytes).
const MAX_HASH: u32 = 256;
/// Deflate cannot expand more than about 1032 to 1: an inflated size claimed beyond this
/// multiple of the stream's length is a corrupt header, refused before allocating.
const MAX_RATIO: u64 = 1100;

/// Distance bands of the runtime's draw segments (depth sorting and per-band vertex counts).
pub const BANDS: u32 = 16;

/// Level of detail `λ ∈ (0, 1]` of an object at distance `d` (metres, already divided by the
/// instance scale): `b = min(1, d0²/d²)`, `λ = b^(ln ½ / ln h)`. `h ∈ (0, 1)` is the value of
/// `b` at which half the elements are drawn (`h = ½` gives `λ = b`). `λ = 1` for `d ≤ d0`.
pub fn lambda(d: f32, d0: f32, h: f32) -> f32 {
    if d <= d0 {
        return 1.0;
    }
    let b = (d0 / d) * (d0 / d);
    b.powf(0.5f32.ln() / h.ln()).clamp(1e-9, 1.0)
}

/// Draw band of level `λ`: `min(BANDS − 1, ⌊−2·log2 λ⌋)`; every `λ` of band `k` is at most
/// `2^(−k/2)`.
pub fn lambda_band(lambda: f32) -> u32 {
    let b = (-2.0 * lambda.max(1e-9).log2()).floor();
    (b.max(0.0) as u32).min(BANDS - 1)
}

/// Dilate an image's colour from the texels whose alpha is at least `min_alpha` (1..=255): every
/// other texel takes the colour of the nearest such texel, ring by ring. With 128 only the
/// texels that pass a 0.5 alpha test keep their colour (an alpha-tested texture's fringe of
/// faint texels, often matted against another colour, never shows).
pub fn dilate_colour_from(img: &mut image::RgbaImage, min_alpha: u8) {
    let (w, h) = (img.width() as usize, img.height() as usize);
    let min_alpha = min_alpha.max(1);
    let mut known: Vec<bool> = img.pixels().map(|p| p[3] >= min_alpha).collect();
    if !known.iter().any(|k| *k) {
        return;
    }
    // Ring by ring from the known texels, visiting only each ring (every texel once in all):
    // a texel of the next ring averages its 4-neighbours known before that ring.
    let neighbours = |i: usize| {
        let (x, y) = (i % w, i / w);
        [
            (x > 0).then(|| i - 1),
            (x + 1 < w).then(|| i + 1),
            (y > 0).then(|| i - w),
            (y + 1 < h).then(|| i + w),
        ]
        .into_iter()
        .flatten()
    };
    let mut queued = known.clone();
    let mut ring: Vec<usize> = (0..w * h)
        .filter(|&i| !known[i] && neighbours(i).any(|n| known[n]))
        .collect();
    ring.iter().for_each(|&i| queued[i] = true);
    let raw = &mut **img;
    let mut colours = Vec::new();
    while !ring.is_empty() {
        colours.clear();
        for &i in &ring {
            let (mut acc, mut c) = ([0u32; 3], 0u32);
            for n in neighbours(i).filter(|&n| known[n]) {
                (0..3).for_each(|k| acc[k] += u32::from(raw[4 * n + k]));
                c += 1;
            }
            colours.push(acc.map(|a| (a / c) as u8));
        }
        let mut next = Vec::new();
        for (&i, c) in ring.iter().zip(&colours) {
            raw[4 * i..4 * i + 3].copy_from_slice(c);
            known[i] = true;
            for n in neighbours(i) {
                if !queued[n] {
                    queued[n] = true;
                    next.push(n);
                }
            }
        }
        ring = next;
    }
}

/// One vertex of a model (48 bytes, as `GeoVertex` in the geometry renderer's WGSL):
/// object-space position, sky visibility of both sides, normal (towards the front side),
/// material, uv.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct RefVertex {
    /// Object-space position (metres).
    pub pos: [f32; 3],
    /// Sky visibility of the front side (the side `normal` faces) at this corner, `[0, 1]`.
    pub sky_front: f32,
    /// Unit normal.
    pub normal: [f32; 3],
    /// Material index.
    pub material: u32,
    /// Texture coordinates (OBJ convention).
    pub uv: [f32; 2],
    /// Leaf rank for stochastic simplification ([`NONE`] when not a leaf, or unused).
    pub element: u32,
    /// Sky visibility of the back side at this corner, `[0, 1]`.
    pub sky_back: f32,
}

/// A material of a prepared model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelMaterial {
    /// Diffuse albedo (linear RGB) and translucency.
    pub kd: [f32; 4],
    /// Its layer in [`PreparedModel::layers`], or [`NONE`].
    pub layer: u32,
    /// Alpha tested (a leaf card's cut-out).
    pub alpha_tested: bool,
}

/// One billboard view: albedo (sRGB, straight alpha) and surface attributes (linear: normal
/// code in R and G, sky visibility in B, translucency in A), both
/// [`BILLBOARD_RESOLUTION`]² RGBA8.
#[derive(Clone, Debug, PartialEq)]
pub struct BillboardPair {
    /// Albedo.
    pub albedo: image::RgbaImage,
    /// Surface attributes.
    pub surface: image::RgbaImage,
}

/// A species' prepared model (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct PreparedModel {
    /// Hash of the model file it was prepared from (the atlas manifest's `source.hash`).
    pub source_hash: String,
    /// Bounding sphere (object space): centre, radius (metres).
    pub sphere: [f32; 4],
    /// LOD 0 (every triangle: branches first, then leaves in shuffled order), then LODs 1 and
    /// 2; three vertices per triangle.
    pub vertices: Vec<RefVertex>,
    /// Vertices of LOD 0, 1 and 2 (each a multiple of 3, summing to `vertices.len()`).
    pub lod_vertices: [u32; 3],
    /// Branch vertices at the start of LOD 0.
    pub branch_vertices: u32,
    /// `r` of the stochastic method's area-preservation factor.
    pub r: f32,
    /// Mean leaf colour (linear RGB), for the stochastic method's contrast preservation.
    pub mean_leaf: [f32; 3],
    /// The materials.
    pub materials: Vec<ModelMaterial>,
    /// Material texture layers, [`MATERIAL_TEXTURE_SIZE`]² RGBA8 sRGB.
    pub layers: Vec<image::RgbaImage>,
    /// `leaf_end[k]`: vertices of LOD 0 through the leaf of rank `k` (monotone, at most LOD
    /// 0's count).
    pub leaf_end: Vec<u32>,
    /// Object-space centre of the leaf of each rank.
    pub leaf_centre: Vec<[f32; 3]>,
    /// The [`BILLBOARDS`] billboard views.
    pub billboards: Vec<BillboardPair>,
    /// The model's opacity volume (the bake's, the same self-shadowing as its quads).
    pub opacity: OpacityVolume,
}

/// The counts and scalars the header stores.
struct Header {
    lod_vertices: [u32; 3],
    branch_vertices: u32,
    leaves: u32,
    materials: u32,
    layers: u32,
    layer_side: u32,
    billboards: u32,
    billboard_side: u32,
    opacity_resolution: u32,
    hash_len: u32,
    sphere: [f32; 4],
    r: f32,
    mean_leaf: [f32; 3],
    opacity_depth: f32,
}

const HEADER_U32S: usize = 12;
const HEADER_F32S: usize = 9;
/// Magic, version, the header's words, then their checksum.
const HEADER_BYTES: usize = SUMMED_BYTES + 8;
/// The header's bytes its checksum covers: magic, version and words.
const SUMMED_BYTES: usize = 8 + 4 + 4 * (HEADER_U32S + HEADER_F32S);

/// FNV-1a 64 of `bytes`: the header's checksum.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}
const MATERIAL_BYTES: u64 = 24;

impl Header {
    fn of(m: &PreparedModel) -> Self {
        let side = |v: &[image::RgbaImage], f: fn(&image::RgbaImage) -> u32| v.first().map_or(0, f);
        Self {
            lod_vertices: m.lod_vertices,
            branch_vertices: m.branch_vertices,
            leaves: m.leaf_end.len() as u32,
            materials: m.materials.len() as u32,
            layers: m.layers.len() as u32,
            layer_side: side(&m.layers, image::RgbaImage::width),
            billboards: m.billboards.len() as u32,
            billboard_side: m.billboards.first().map_or(0, |b| b.albedo.width()),
            opacity_resolution: m.opacity.resolution,
            hash_len: m.source_hash.len() as u32,
            sphere: m.sphere,
            r: m.r,
            mean_leaf: m.mean_leaf,
            opacity_depth: m.opacity.max_depth,
        }
    }

    fn words(&self) -> ([u32; HEADER_U32S], [f32; HEADER_F32S]) {
        let [l0, l1, l2] = self.lod_vertices;
        let [sx, sy, sz, sr] = self.sphere;
        let [mr, mg, mb] = self.mean_leaf;
        (
            [
                l0,
                l1,
                l2,
                self.branch_vertices,
                self.leaves,
                self.materials,
                self.layers,
                self.layer_side,
                self.billboards,
                self.billboard_side,
                self.opacity_resolution,
                self.hash_len,
            ],
            [sx, sy, sz, sr, self.r, mr, mg, mb, self.opacity_depth],
        )
    }

    fn from_words(u: [u32; HEADER_U32S], f: [f32; HEADER_F32S]) -> Self {
        Self {
            lod_vertices: [u[0], u[1], u[2]],
            branch_vertices: u[3],
            leaves: u[4],
            materials: u[5],
            layers: u[6],
            layer_side: u[7],
            billboards: u[8],
            billboard_side: u[9],
            opacity_resolution: u[10],
            hash_len: u[11],
            sphere: [f[0], f[1], f[2], f[3]],
            r: f[4],
            mean_leaf: [f[5], f[6], f[7]],
            opacity_depth: f[8],
        }
    }

    /// Check the counts against the sizes this version stores; then the payload's inflated
    /// size in bytes.
    fn check(&self) -> Result<u64, String> {
        let vertices: u64 = self.lod_vertices.iter().map(|&v| u64::from(v)).sum();
        if let Some(l) = self.lod_vertices.iter().position(|v| !v.is_multiple_of(3)) {
            return Err(format!(
                "LOD {l} has {} vertices, not whole triangles",
                self.lod_vertices[l]
            ));
        }
        if self.branch_vertices > self.lod_vertices[0] || !self.branch_vertices.is_multiple_of(3) {
            return Err(format!(
                "{} branch vertices of LOD 0's {}",
                self.branch_vertices, self.lod_vertices[0]
            ));
        }
        if self.layers > 0 && self.layer_side != MATERIAL_TEXTURE_SIZE {
            return Err(format!(
                "material textures are {0}², this version reads {MATERIAL_TEXTURE_SIZE}²: bake \
                 the model again",
                self.layer_side
            ));
        }
        if self.billboards != BILLBOARDS || self.billboard_side != BILLBOARD_RESOLUTION {
            return Err(format!(
                "{} billboards of {}², expected {BILLBOARDS} of {BILLBOARD_RESOLUTION}²: bake \
                 the model again",
                self.billboards, self.billboard_side
            ));
        }
        if self.opacity_resolution != VOLUME_RESOLUTION {
            return Err(format!(
                "opacity volume of {}³ voxels, expected {VOLUME_RESOLUTION}³",
                self.opacity_resolution
            ));
        }
        if self.hash_len > MAX_HASH {
            return Err(format!(
                "source hash of {} bytes (at most {MAX_HASH})",
                self.hash_len
            ));
        }
        let radius = self.sphere[3];
        let finite = self
            .sphere
            .iter()
            .chain(&self.mean_leaf)
            .chain([&self.r, &self.opacity_depth])
            .all(|v| v.is_finite());
        let sound = finite && radius > 0.0 && self.opacity_depth >= 0.0;
        if !sound {
            return Err(format!(
                "bad scalars: sphere {:?}, r {}, mean leaf {:?}, opacity depth {}",
                self.sphere, self.r, self.mean_leaf, self.opacity_depth
            ));
        }
        let image = |side: u32| u64::from(side) * u64::from(side) * 4;
        Ok(u64::from(self.hash_len)
            + vertices * size_of::<RefVertex>() as u64
            + u64::from(self.materials) * MATERIAL_BYTES
            + u64::from(self.leaves) * 16
            + u64::from(self.layers) * image(self.layer_side)
            + 2 * u64::from(self.billboards) * image(self.billboard_side)
            + u64::from(self.opacity_resolution).pow(3))
    }

    /// The figures within the ranges an atlas's manifest allows, checked when a file is read
    /// (a bake writes only models whose coordinates its loaders checked).
    fn check_ranges(&self) -> Result<(), String> {
        let radius = self.sphere[3];
        let reach = self.sphere[..3].iter().fold(0f32, |m, v| m.max(v.abs())) + radius;
        if reach > crate::species::MAX_MODEL_COORDINATE {
            return Err(format!(
                "bounding sphere {:?} reaches {reach:e} model units from the origin, beyond the \
                 ±{:e} a model may have",
                self.sphere,
                crate::species::MAX_MODEL_COORDINATE
            ));
        }
        if self.opacity_depth > crate::opacity::MAX_VOXEL_DEPTH {
            return Err(format!(
                "opacity depth {} per voxel, beyond the {} an atlas may record",
                self.opacity_depth,
                crate::opacity::MAX_VOXEL_DEPTH
            ));
        }
        Ok(())
    }
}

/// Share of a model's height, above its lowest point, that counts as its foot
/// ([`footprint_radius`]).
pub const FOOT_BAND: f32 = 0.02;

/// How far a model's foot reaches from its vertical axis (object space, metres): the largest
/// horizontal distance from the axis x = z = 0 (where a tree stands on its ground) of the
/// points within [`FOOT_BAND`] of its height above its lowest point. A tree planted on a slope
/// is lowered to the ground's lowest point under that circle, so that no side of its trunk
/// floats. 0 for no points, and the non-finite points are skipped.
pub fn footprint_radius(points: impl Iterator<Item = [f32; 3]> + Clone) -> f32 {
    let finite = |p: &[f32; 3]| p.iter().all(|c| c.is_finite());
    let (lo, hi) = points
        .clone()
        .filter(finite)
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p[1]), hi.max(p[1]))
        });
    if lo > hi {
        return 0.0;
    }
    let top = lo + FOOT_BAND * (hi - lo);
    points
        .filter(|p| finite(p) && p[1] <= top)
        .map(|p| p[0].hypot(p[2]))
        .fold(0.0, f32::max)
}

impl PreparedModel {
    /// [`footprint_radius`] of LOD 0 (the full model).
    pub fn footprint_radius(&self) -> f32 {
        let n = (self.lod_vertices[0] as usize).min(self.vertices.len());
        footprint_radius(self.vertices[..n].iter().map(|v| v.pos))
    }

    /// The file's bytes.
    ///
    /// # Panics
    /// If its counts break the sizes this version stores (a bug in the bake); indices are
    /// checked by [`Self::decode`].
    pub fn encode(&self) -> Vec<u8> {
        let header = Header::of(self);
        let size = header
            .check()
            .expect("a prepared model within this version's sizes");
        let mut payload = Vec::with_capacity(size as usize);
        payload.extend_from_slice(self.source_hash.as_bytes());
        payload.extend_from_slice(bytemuck::cast_slice(&self.vertices));
        for m in &self.materials {
            for v in m.kd {
                payload.extend_from_slice(&v.to_le_bytes());
            }
            payload.extend_from_slice(&m.layer.to_le_bytes());
            payload.extend_from_slice(&u32::from(m.alpha_tested).to_le_bytes());
        }
        for e in &self.leaf_end {
            payload.extend_from_slice(&e.to_le_bytes());
        }
        for c in &self.leaf_centre {
            for v in c {
                payload.extend_from_slice(&v.to_le_bytes());
            }
        }
        for l in &self.layers {
            payload.extend_from_slice(l.as_raw());
        }
        for b in &self.billboards {
            payload.extend_from_slice(b.albedo.as_raw());
        }
        for b in &self.billboards {
            payload.extend_from_slice(b.surface.as_raw());
        }
        payload.extend_from_slice(&self.opacity.codes);
        assert_eq!(payload.len() as u64, size, "payload size");
        let mut out = Vec::with_capacity(HEADER_BYTES + payload.len() / 4);
        out.extend_from_slice(&MODEL_MAGIC);
        out.extend_from_slice(&MODEL_VERSION.to_le_bytes());
        let (u, f) = header.words();
        u.iter()
            .for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
        f.iter()
            .for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
        let sum = fnv1a(&out);
        out.extend_from_slice(&sum.to_le_bytes());
        let mut z = flate2::write::ZlibEncoder::new(out, flate2::Compression::fast());
        std::io::Write::write_all(&mut z, &payload).expect("writing to memory");
        z.finish().expect("writing to memory")
    }

    /// Write it into atlas folder `atlas` (atomically: a temporary name, then a rename).
    pub fn save(&self, atlas: &Path) -> Result<(), FormatError> {
        let bytes = self.encode();
        crate::atomic::write_with(&atlas.join(MODEL_FILE), |tmp| std::fs::write(tmp, &bytes))
    }

    /// Read and check the prepared model of atlas folder `atlas`: `Ok(None)` when it has none
    /// (an atlas baked without one, or by an older bake). A `model.bin` that is there but not
    /// a regular file (a folder, a device behind a link) is an error, not a missing model.
    pub fn load(atlas: &Path) -> Result<Option<Self>, FormatError> {
        let path = atlas.join(MODEL_FILE);
        match std::fs::metadata(&path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Ok(m) if !m.is_file() => {
                return Err(FormatError::invalid(
                    &path,
                    "not a regular file (a folder, or a link to a device): bake the atlas \
                     again, or remove it to draw without the model",
                ));
            }
            _ => {}
        }
        let bytes = crate::bounded::read(&path, crate::bounded::limit::DATA)?;
        Self::decode(&bytes, &path).map(Some)
    }

    /// Decode and check a file's bytes (`path` names it in errors).
    pub fn decode(bytes: &[u8], path: &Path) -> Result<Self, FormatError> {
        let bad = |what: String| FormatError::invalid(path, what);
        if bytes.len() < 12 || bytes[..8] != MODEL_MAGIC {
            return Err(bad(
                "not a prepared model (no FORESTMD header): bake the model again".into(),
            ));
        }
        let word = |i: usize| u32::from_le_bytes(bytes[i..i + 4].try_into().expect("4 bytes"));
        let version = word(8);
        if version != MODEL_VERSION {
            return Err(FormatError::Version {
                path: path.to_path_buf(),
                what: format!(
                    "prepared model version {version}, this program reads {MODEL_VERSION}: \
                     bake the model again with `forest bake`"
                ),
            });
        }
        if bytes.len() < HEADER_BYTES {
            return Err(bad(format!(
                "{} bytes, shorter than its {HEADER_BYTES}-byte header",
                bytes.len()
            )));
        }
        let sum = u64::from_le_bytes(bytes[SUMMED_BYTES..HEADER_BYTES].try_into().expect("8"));
        if sum != fnv1a(&bytes[..SUMMED_BYTES]) {
            return Err(bad(
                "its header does not match its checksum (the file was changed or damaged): \
                 bake the model again"
                    .into(),
            ));
        }
        let u: [u32; HEADER_U32S] = std::array::from_fn(|i| word(12 + 4 * i));
        let f: [f32; HEADER_F32S] =
            std::array::from_fn(|i| f32::from_bits(word(12 + 4 * (HEADER_U32S + i))));
        let header = Header::from_words(u, f);
        let size = header.check().map_err(bad)?;
        header.check_ranges().map_err(bad)?;
        let stream = &bytes[HEADER_BYTES..];
        if size > crate::bounded::limit::DATA || size > stream.len() as u64 * MAX_RATIO + 1024 {
            return Err(bad(format!(
                "its header claims {size} bytes of arrays, which {} compressed bytes cannot hold",
                stream.len()
            )));
        }
        let mut payload = Vec::with_capacity(size as usize);
        flate2::read::ZlibDecoder::new(stream)
            .take(size + 1)
            .read_to_end(&mut payload)
            .map_err(|e| bad(format!("arrays do not inflate: {e}")))?;
        if payload.len() as u64 != size {
            return Err(bad(format!(
                "arrays inflate to {} bytes, the header's counts need {size}",
                payload.len()
            )));
        }
        let mut at = 0usize;
        let mut take = |n: u64| {
            let s = &payload[at..at + n as usize];
            at += n as usize;
            s
        };
        let f32s = |s: &[u8]| -> Vec<f32> {
            s.chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
                .collect()
        };
        let u32s = |s: &[u8]| -> Vec<u32> {
            s.chunks_exact(4)
                .map(|c| u32::from_le_bytes(c.try_into().expect("4 bytes")))
                .collect()
        };
        let source_hash = String::from_utf8(take(u64::from(header.hash_len)).to_vec())
            .map_err(|_| bad("its source hash is not UTF-8".into()))?;
        let count: u64 = header.lod_vertices.iter().map(|&v| u64::from(v)).sum();
        let vertices: Vec<RefVertex> =
            bytemuck::pod_collect_to_vec(take(count * size_of::<RefVertex>() as u64));
        let materials: Vec<ModelMaterial> = take(u64::from(header.materials) * MATERIAL_BYTES)
            .chunks_exact(MATERIAL_BYTES as usize)
            .map(|c| {
                let f = f32s(&c[..16]);
                let u = u32s(&c[16..]);
                ModelMaterial {
                    kd: [f[0], f[1], f[2], f[3]],
                    layer: u[0],
                    alpha_tested: u[1] != 0,
                }
            })
            .collect();
        let leaf_end = u32s(take(u64::from(header.leaves) * 4));
        let leaf_centre: Vec<[f32; 3]> = f32s(take(u64::from(header.leaves) * 12))
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        let mut image = |side: u32| {
            image::RgbaImage::from_raw(side, side, take(u64::from(side).pow(2) * 4).to_vec())
                .expect("the size taken")
        };
        let layers: Vec<_> = (0..header.layers)
            .map(|_| image(header.layer_side))
            .collect();
        let albedo: Vec<_> = (0..header.billboards)
            .map(|_| image(header.billboard_side))
            .collect();
        let surface: Vec<_> = (0..header.billboards)
            .map(|_| image(header.billboard_side))
            .collect();
        let billboards = albedo
            .into_iter()
            .zip(surface)
            .map(|(albedo, surface)| BillboardPair { albedo, surface })
            .collect();
        let codes = take(u64::from(header.opacity_resolution).pow(3)).to_vec();
        let model = Self {
            source_hash,
            sphere: header.sphere,
            vertices,
            lod_vertices: header.lod_vertices,
            branch_vertices: header.branch_vertices,
            r: header.r,
            mean_leaf: header.mean_leaf,
            materials,
            layers,
            leaf_end,
            leaf_centre,
            billboards,
            opacity: OpacityVolume {
                resolution: header.opacity_resolution,
                max_depth: header.opacity_depth,
                codes,
            },
        };
        model.check_indices().map_err(bad)?;
        model
            .opacity
            .check_scale()
            .map_err(|e| bad(format!("opacity volume: {e}")))?;
        Ok(model)
    }

    /// Every index within what it indexes, every value finite: what a renderer relies on to
    /// upload the arrays unchanged.
    pub fn check_indices(&self) -> Result<(), String> {
        let (materials, layers, leaves) = (
            self.materials.len() as u32,
            self.layers.len() as u32,
            self.leaf_end.len() as u32,
        );
        let lod0 = self.lod_vertices[0];
        if self.branch_vertices > lod0 {
            return Err(format!(
                "{} branch vertices of LOD 0's {lod0}",
                self.branch_vertices
            ));
        }
        for (i, v) in self.vertices.iter().enumerate() {
            let finite = v
                .pos
                .iter()
                .chain(&v.normal)
                .chain(&v.uv)
                .all(|x| x.is_finite())
                && (0.0..=1.0).contains(&v.sky_front)
                && (0.0..=1.0).contains(&v.sky_back);
            if !finite {
                return Err(format!("vertex {i} is not finite ({v:?})"));
            }
            if v.material >= materials {
                return Err(format!(
                    "vertex {i} names material {} of {materials}",
                    v.material
                ));
            }
            if v.element != NONE && v.element >= leaves {
                return Err(format!("vertex {i} names leaf {} of {leaves}", v.element));
            }
        }
        for (i, m) in self.materials.iter().enumerate() {
            if !m.kd.iter().all(|v| v.is_finite()) || (m.layer != NONE && m.layer >= layers) {
                return Err(format!(
                    "material {i}: colour {:?}, layer {} of {layers}",
                    m.kd, m.layer
                ));
            }
        }
        if self.leaf_centre.len() != self.leaf_end.len() {
            return Err(format!(
                "{} leaf centres for {} leaves",
                self.leaf_centre.len(),
                leaves
            ));
        }
        let mut last = self.branch_vertices;
        for (k, &e) in self.leaf_end.iter().enumerate() {
            if e < last || e > lod0 {
                return Err(format!(
                    "leaf {k} ends at vertex {e}, outside {last}..={lod0}"
                ));
            }
            last = e;
        }
        if !self.leaf_centre.iter().flatten().all(|v| v.is_finite()) {
            return Err("a leaf centre is not finite".into());
        }
        Ok(())
    }

    /// Refuse a model that is not its atlas's: prepared from another model file
    /// ([`Self::check_source`]), or with another bounding sphere or opacity scale than the
    /// manifest records (both come from the same bake; `atlas` names the folder).
    pub fn check_atlas(
        &self,
        atlas: &Path,
        manifest: &crate::atlas::AtlasManifest,
    ) -> Result<(), FormatError> {
        self.check_source(atlas, &manifest.source.hash)?;
        let bad = |what: String| Err(FormatError::invalid(atlas.join(MODEL_FILE), what));
        let s = manifest.bounding_sphere;
        let [x, y, z, r] = self.sphere;
        let off = (glam::Vec3::new(x, y, z) - s.center)
            .abs()
            .max_element()
            .max((r - s.radius).abs());
        // NaN fails too.
        if off.is_nan() || off > 1e-5 * s.radius {
            return bad(format!(
                "its bounding sphere (centre [{x}, {y}, {z}], radius {r}) is not the atlas's \
                 (centre {}, radius {}): bake the model again",
                s.center, s.radius
            ));
        }
        if self.opacity.max_depth != manifest.opacity.max_depth {
            return bad(format!(
                "its opacity volume's max_depth {} is not the atlas's {}: bake the model again",
                self.opacity.max_depth, manifest.opacity.max_depth
            ));
        }
        Ok(())
    }

    /// Refuse a model prepared from another model file than the atlas's (`atlas` names the
    /// folder; `hash` is its manifest's `source.hash`).
    pub fn check_source(&self, atlas: &Path, hash: &str) -> Result<(), FormatError> {
        if self.source_hash == hash {
            return Ok(());
        }
        Err(FormatError::invalid(
            atlas.join(MODEL_FILE),
            format!(
                "was prepared from another model (hash {}) than the atlas (hash {hash}): bake \
                 the model again",
                self.source_hash
            ),
        ))
    }
}

#[cfg(test)]
mod tests;
