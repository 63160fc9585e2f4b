//! Loading a tree model (OBJ + MTL + textures; glTF in [`crate::gltf_mesh`]) into flat
//! triangles for the ray tracer.
//!
//! Polygons are triangulated by tobj. Texture alpha comes from `map_d` (its alpha channel, or
//! its grey level when it has none) or else from the alpha channel of `map_Kd`; a material with
//! either is *alpha-tested* at 0.5 and shaded as a leaf (translucent, see
//! [`forest_format::shading`]). A missing or unreadable texture is an error naming the material
//! and the file: silently drawing leaf cards as opaque squares would ruin the bake.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use forest_format::bounded;

use forest_format::shading::{LEAF_TRANSLUCENCY, srgb_decode};
use glam::{Vec2, Vec3};

use crate::error::BakeError;
use crate::texture::Texture;

/// Alpha below this is a hole in an alpha-tested material.
pub const ALPHA_CUTOFF: f32 = 0.5;

/// A material as the bake uses it.
#[derive(Clone, Debug)]
pub struct Material {
    /// Name from the MTL.
    pub name: String,
    /// `Kd` as a linear multiplier (sRGB-decoded; white when absent).
    pub kd: Vec3,
    /// Index of the colour texture (`map_Kd`).
    pub colour: Option<usize>,
    /// Index of the texture giving alpha, and whether to read its alpha channel (else grey).
    pub alpha: Option<(usize, bool)>,
    /// Translucency of the shading model (leaves: [`LEAF_TRANSLUCENCY`]).
    pub translucency: f32,
}

/// One triangle with its attributes.
#[derive(Clone, Copy, Debug)]
pub struct Tri {
    /// Object-space positions (metres).
    pub p: [Vec3; 3],
    /// Texture coordinates (zero when the model has none).
    pub uv: [Vec2; 3],
    /// Vertex normals (the face normal when the model has none), unit length.
    pub n: [Vec3; 3],
    /// Material index.
    pub material: u32,
}

/// A loaded model.
#[derive(Clone, Debug)]
pub struct Mesh {
    /// Usable triangles.
    pub tris: Vec<Tri>,
    /// Materials (at least one: a grey default when the OBJ names none).
    pub materials: Vec<Material>,
    /// Textures referenced by materials.
    pub textures: Vec<Texture>,
    /// Zero-area triangles skipped.
    pub degenerate: u64,
    /// FNV-1a 64 hash of the OBJ, MTL and texture bytes.
    pub hash: u64,
    /// What the loader read past without using, for the user to see (a glTF's animations,
    /// cameras, morph targets, …); empty when nothing was left out.
    pub notes: Vec<String>,
}

/// FNV-1a 64-bit hash, continued from `h`.
pub fn fnv1a(mut h: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}
/// FNV-1a 64-bit offset basis.
pub(crate) const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

/// Refuse face (`f`, `l`) indices that name no vertex, texture coordinate or normal defined
/// before them: tobj 4 overflows on such indices (a panic with overflow checks, a wrong
/// vertex without). The error names the line and the index.
fn check_face_indices(path: &Path, bytes: &[u8]) -> Result<(), BakeError> {
    const KINDS: [&str; 3] = ["vertex", "texture coordinate", "normal"];
    let mut defined = [0i64; 3];
    for (n, line) in String::from_utf8_lossy(bytes).lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => defined[0] += 1,
            Some("vt") => defined[1] += 1,
            Some("vn") => defined[2] += 1,
            Some("f" | "l") => {
                for word in words {
                    for (k, part) in word.split('/').enumerate().take(3) {
                        // Unparsable indices are tobj's to report.
                        let Ok(i) = part.parse::<i64>() else { continue };
                        if i == 0 || i.unsigned_abs() > defined[k] as u64 {
                            return Err(BakeError::Parse {
                                path: path.into(),
                                what: "OBJ",
                                reason: format!(
                                    "line {}: {} index {i} names none of the {} defined before it",
                                    n + 1,
                                    KINDS[k],
                                    defined[k]
                                ),
                            });
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// Refuse what tobj 4 would panic on in a material library: a colour statement (`Ka`, `Kd`,
/// `Ks`, `Ke`) with fewer than three values.
fn check_mtl(file: &Path, bytes: &[u8]) -> Result<(), forest_format::FormatError> {
    for (n, line) in String::from_utf8_lossy(bytes).lines().enumerate() {
        let mut words = line.split_whitespace();
        if let Some(w @ ("Ka" | "Kd" | "Ks" | "Ke")) = words.next() {
            let values = words.count();
            if values < 3 {
                return Err(forest_format::FormatError::invalid(
                    file,
                    format!(
                        "line {}: {w} needs three numbers (r g b), found {values}",
                        n + 1
                    ),
                ));
            }
        }
    }
    Ok(())
}

fn texture_path(obj_dir: &Path, spec: &str) -> PathBuf {
    // MTL map statements may carry options before the file name (`-bm 1 file.png`): the file
    // is the last word.
    let file = spec.split_whitespace().last().unwrap_or(spec);
    obj_dir.join(file.replace('\\', "/"))
}

/// The squared-area threshold below which a triangle of a model reaching `extent` model units
/// from the origin counts as degenerate (relative to the model's size).
pub(crate) fn min_area2(extent: f32) -> f32 {
    (extent * 1e-7).powi(4)
}

impl Tri {
    /// A triangle, or None when it is degenerate (squared cross product at most `min_area2`,
    /// or not finite). Missing normals (`n` None) and normals that do not normalise take the
    /// face normal.
    pub(crate) fn new(
        p: [Vec3; 3],
        uv: [Vec2; 3],
        n: Option<[Vec3; 3]>,
        material: u32,
        min_area2: f32,
    ) -> Option<Self> {
        let cross = (p[1] - p[0]).cross(p[2] - p[0]);
        if cross.length_squared() <= min_area2 || !cross.is_finite() {
            return None;
        }
        let face_n = cross.normalize();
        let n = n
            .unwrap_or([face_n; 3])
            .map(|v| v.try_normalize().unwrap_or(face_n));
        Some(Self { p, uv, n, material })
    }
}

/// The error of a model left with no triangle (none at all, or `degenerate` of zero area).
pub(crate) fn no_triangles(path: &Path, degenerate: u64) -> BakeError {
    BakeError::Model {
        path: path.into(),
        what: if degenerate > 0 {
            format!("all {degenerate} triangles are degenerate (zero area)")
        } else {
            "no faces: the model has no triangles to bake".into()
        },
    }
}

/// The largest vertex coordinate (absolute value, model units) a model may have (NaN and
/// infinities are refused by the same test).
pub use forest_format::species::MAX_MODEL_COORDINATE;

impl Mesh {
    /// Load a model with its materials and textures: OBJ, or glTF 2.0 (`.gltf`, `.glb`; see
    /// [`crate::gltf_mesh`]) by the file's extension.
    pub fn load(path: &Path) -> Result<Self, BakeError> {
        if crate::gltf_mesh::is_gltf(path) {
            return crate::gltf_mesh::load(path);
        }
        let obj_bytes = bounded::read(path, bounded::limit::DATA)?;
        let mut hash = fnv1a(FNV_OFFSET, &obj_bytes);
        let obj_dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
        // Material libraries are read bounded (a `mtllib` naming a device or a huge file is
        // refused, not read until memory runs out) and hashed too.
        let mtl_hash = std::cell::Cell::new(hash);
        let mtl_error = std::cell::RefCell::new(None);
        check_face_indices(path, &obj_bytes)?;
        let loaded = tobj::load_obj_buf(
            &mut std::io::Cursor::new(&obj_bytes),
            &tobj::GPU_LOAD_OPTIONS,
            |p| {
                let file = obj_dir.join(p);
                match bounded::read(&file, bounded::limit::TEXT) {
                    Ok(b) => {
                        mtl_hash.set(fnv1a(mtl_hash.get(), &b));
                        if let Err(e) = check_mtl(&file, &b) {
                            *mtl_error.borrow_mut() = Some(e);
                            return Err(tobj::LoadError::MaterialParseError);
                        }
                        tobj::load_mtl_buf(&mut std::io::Cursor::new(b))
                    }
                    // A missing library is tobj's to report; a refused one is ours.
                    Err(e) => {
                        if file.exists() {
                            *mtl_error.borrow_mut() = Some(e);
                        }
                        Err(tobj::LoadError::OpenFileFailed)
                    }
                }
            },
        );
        hash = mtl_hash.get();
        if let Some(e) = mtl_error.into_inner() {
            return Err(e.into());
        }
        let (models, materials) = loaded.map_err(|e| BakeError::Parse {
            path: path.into(),
            what: "OBJ",
            reason: e.to_string(),
        })?;
        let materials = materials.map_err(|e| BakeError::Parse {
            path: path.into(),
            what: "material library",
            reason: e.to_string(),
        })?;

        // A `usemtl` naming no material of the libraries is an error, not material 0.
        for (n, line) in String::from_utf8_lossy(&obj_bytes).lines().enumerate() {
            if let Some(name) = line.trim_start().strip_prefix("usemtl") {
                let name = name.trim();
                if !name.is_empty() && !materials.iter().any(|m| m.name == name) {
                    return Err(BakeError::Parse {
                        path: path.into(),
                        what: "OBJ",
                        reason: format!(
                            "line {}: usemtl {name}: no material of that name in the material \
                             libraries ({} defined)",
                            n + 1,
                            materials.len()
                        ),
                    });
                }
            }
        }

        let mut textures: Vec<Texture> = Vec::new();
        let mut by_path: HashMap<PathBuf, (usize, bool)> = HashMap::new();
        let mut load_texture =
            |material: &str, spec: &str, hash: &mut u64| -> Result<(usize, bool), BakeError> {
                let file = texture_path(&obj_dir, spec);
                if let Some(&i) = by_path.get(&file) {
                    return Ok(i);
                }
                let err = |reason: String| BakeError::Texture {
                    path: path.into(),
                    material: material.into(),
                    texture: file.clone(),
                    reason,
                };
                let bytes = bounded::read(&file, bounded::limit::TEXTURE)
                    .map_err(|e| err(e.to_string()))?;
                *hash = fnv1a(*hash, &bytes);
                let img = crate::texture::decode_rgba(&bytes, &file).map_err(err)?;
                let t = Texture::new(img.width(), img.height(), img.into_raw());
                let i = (textures.len(), t.has_alpha);
                textures.push(t);
                by_path.insert(file, i);
                Ok(i)
            };

        let mut mats = Vec::with_capacity(materials.len().max(1));
        for m in &materials {
            let kd = m
                .diffuse
                .map(|c| Vec3::from_array(c.map(srgb_decode)))
                .unwrap_or(Vec3::ONE);
            let colour = match &m.diffuse_texture {
                Some(t) => Some(load_texture(&m.name, t, &mut hash)?),
                None => None,
            };
            let alpha = match (&m.dissolve_texture, colour) {
                (Some(t), _) => Some(load_texture(&m.name, t, &mut hash)?),
                (None, Some((c, true))) => Some((c, true)),
                _ => None,
            };
            let colour = colour.map(|(i, _)| i);
            mats.push(Material {
                name: m.name.clone(),
                kd,
                colour,
                alpha,
                translucency: if alpha.is_some() {
                    LEAF_TRANSLUCENCY
                } else {
                    0.0
                },
            });
        }
        if mats.is_empty() {
            mats.push(Material {
                name: "default".into(),
                kd: Vec3::splat(0.5),
                colour: None,
                alpha: None,
                translucency: 0.0,
            });
        }

        let mut tris = Vec::new();
        let mut degenerate = 0u64;
        let mut extent = 0.0f32;
        for model in &models {
            let mesh = &model.mesh;
            if let Some(i) = mesh
                .positions
                .iter()
                .position(|x| !x.is_finite() || x.abs() > MAX_MODEL_COORDINATE)
            {
                let x = mesh.positions[i];
                let why = if x.is_finite() {
                    format!(
                        "the coordinate {x:e}, beyond the ±{MAX_MODEL_COORDINATE:e} model units \
                         the bake handles (rescale the model)"
                    )
                } else {
                    format!("a non-finite coordinate ({x})")
                };
                return Err(BakeError::Model {
                    path: path.into(),
                    what: format!("object {:?}: vertex {} has {why}", model.name, i / 3 + 1),
                });
            }
            for p in mesh.positions.chunks_exact(3) {
                extent = extent.max(p[0].abs()).max(p[1].abs()).max(p[2].abs());
            }
        }
        // Zero-area test relative to the model's size.
        let min_area2 = min_area2(extent);
        for model in &models {
            let mesh = &model.mesh;
            let pos = |i: u32| {
                let i = i as usize * 3;
                Vec3::new(
                    mesh.positions[i],
                    mesh.positions[i + 1],
                    mesh.positions[i + 2],
                )
            };
            let has_uv = mesh.texcoords.len() * 3 == mesh.positions.len() * 2;
            let has_n = mesh.normals.len() == mesh.positions.len();
            let material = mesh.material_id.filter(|&m| m < mats.len()).unwrap_or(0) as u32;
            for f in mesh.indices.chunks_exact(3) {
                let f: [u32; 3] = [f[0], f[1], f[2]];
                let uv = f.map(|i| {
                    let i = i as usize * 2;
                    if has_uv {
                        Vec2::new(mesh.texcoords[i], mesh.texcoords[i + 1])
                    } else {
                        Vec2::ZERO
                    }
                });
                let n = has_n.then(|| {
                    f.map(|i| {
                        let i = i as usize * 3;
                        Vec3::new(mesh.normals[i], mesh.normals[i + 1], mesh.normals[i + 2])
                    })
                });
                match Tri::new(f.map(pos), uv, n, material, min_area2) {
                    Some(t) => tris.push(t),
                    None => degenerate += 1,
                }
            }
        }
        if tris.is_empty() {
            return Err(no_triangles(path, degenerate));
        }
        Ok(Self {
            tris,
            materials: mats,
            textures,
            degenerate,
            hash,
            notes: Vec::new(),
        })
    }

    /// Whether barycentric point `b` of triangle `t` is solid: not a hole of an alpha-tested
    /// material (alpha below [`ALPHA_CUTOFF`]).
    pub fn solid_at(&self, t: &Tri, b: [f32; 3]) -> bool {
        self.materials[t.material as usize].alpha.is_none()
            || self.alpha(t.material, t.uv[0] * b[0] + t.uv[1] * b[1] + t.uv[2] * b[2])
                >= ALPHA_CUTOFF
    }

    /// Alpha of material `m` at `uv` (1 for materials without alpha).
    pub fn alpha(&self, m: u32, uv: Vec2) -> f32 {
        match self.materials[m as usize].alpha {
            None => 1.0,
            Some((t, channel)) => {
                f32::from(texel_alpha(self.textures[t].fetch(uv), channel)) / 255.0
            }
        }
    }
}

/// The alpha byte a material reads from an RGBA8 texel: its alpha channel when `channel`,
/// else its grey (the mean of R, G and B).
pub fn texel_alpha(texel: [u8; 4], channel: bool) -> u8 {
    if channel {
        texel[3]
    } else {
        ((u32::from(texel[0]) + u32::from(texel[1]) + u32::from(texel[2])) / 3) as u8
    }
}

/// The files a model is read from, without decoding any of them: the OBJ, its material
/// libraries (`mtllib`) and every texture they name (`map_*`, `bump`, `disp`, `decal`, `refl`).
/// Front ends use it to refuse outputs that would overwrite the model's own files. Unreadable
/// libraries are skipped here (the loader reports them).
pub fn source_files(obj: &Path) -> Result<Vec<PathBuf>, BakeError> {
    if crate::gltf_mesh::is_gltf(obj) {
        return crate::gltf_mesh::source_files(obj);
    }
    let bytes = bounded::read(obj, bounded::limit::DATA)?;
    let dir = obj.parent().unwrap_or(Path::new("."));
    let mut files = vec![obj.to_path_buf()];
    for line in String::from_utf8_lossy(&bytes).lines() {
        let Some(rest) = line.trim_start().strip_prefix("mtllib") else {
            continue;
        };
        for lib in rest.split_whitespace() {
            let mtl = dir.join(lib);
            if let Ok(text) = bounded::read_text(&mtl, bounded::limit::TEXT) {
                for l in text.lines() {
                    let l = l.trim_start();
                    let key = l.split_whitespace().next().unwrap_or("");
                    if key.starts_with("map_") || ["bump", "disp", "decal", "refl"].contains(&key) {
                        let spec = l[key.len()..].trim();
                        if !spec.is_empty() {
                            files.push(texture_path(dir, spec));
                        }
                    }
                }
            }
            files.push(mtl);
        }
    }
    files.sort();
    files.dedup();
    Ok(files)
}
