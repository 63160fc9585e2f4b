//! Loading a tree model from OBJ + MTL + textures into flat triangles.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use forest_format::bounded;

use forest_format::shading::{LEAF_TRANSLUCENCY, srgb_decode};
use glam::{Vec2, Vec3};

use crate::error::BakeError;
use crate::mesh::{
    FNV_OFFSET, MAX_MODEL_COORDINATE, Material, Mesh, Tri, fnv1a, min_area2, no_triangles,
};
use crate::texture::Texture;

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

/// Load an OBJ model with its material libraries and textures.
pub(crate) fn load(path: &Path) -> Result<Mesh, BakeError> {
    let obj_bytes = bounded::read(path, bounded::limit::DATA)?;
    let mut hash = fnv1a(FNV_OFFSET, &obj_bytes);
    let obj_dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let (models, materials) = parse(path, &obj_bytes, &obj_dir, &mut hash)?;
    let (mats, textures) = read_materials(path, &obj_dir, &materials, &mut hash)?;
    let (tris, degenerate) = triangles(path, &models, mats.len())?;
    Ok(Mesh {
        tris,
        materials: mats,
        textures,
        degenerate,
        hash,
        notes: Vec::new(),
    })
}

/// The OBJ's objects and its libraries' materials (libraries hashed into `hash`), every
/// `usemtl` naming one of them.
fn parse(
    path: &Path,
    obj_bytes: &[u8],
    obj_dir: &Path,
    hash: &mut u64,
) -> Result<(Vec<tobj::Model>, Vec<tobj::Material>), BakeError> {
    // Material libraries are read bounded (a `mtllib` naming a device or a huge file is
    // refused, not read until memory runs out) and hashed too.
    let mtl_hash = std::cell::Cell::new(*hash);
    let mtl_error = std::cell::RefCell::new(None);
    check_face_indices(path, obj_bytes)?;
    let loaded = tobj::load_obj_buf(
        &mut std::io::Cursor::new(obj_bytes),
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
    *hash = mtl_hash.get();
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
    for (n, line) in String::from_utf8_lossy(obj_bytes).lines().enumerate() {
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
    Ok((models, materials))
}

/// The bake's materials of the libraries' (a grey default when there are none) and their
/// textures, each read once (hashed into `hash`).
fn read_materials(
    path: &Path,
    obj_dir: &Path,
    materials: &[tobj::Material],
    hash: &mut u64,
) -> Result<(Vec<Material>, Vec<Texture>), BakeError> {
    let mut textures: Vec<Texture> = Vec::new();
    let mut by_path: HashMap<PathBuf, (usize, bool)> = HashMap::new();
    let mut load_texture =
        |material: &str, spec: &str, hash: &mut u64| -> Result<(usize, bool), BakeError> {
            let file = texture_path(obj_dir, spec);
            if let Some(&i) = by_path.get(&file) {
                return Ok(i);
            }
            let err = |reason: String| BakeError::Texture {
                path: path.into(),
                material: material.into(),
                texture: file.clone(),
                reason,
            };
            let bytes =
                bounded::read(&file, bounded::limit::TEXTURE).map_err(|e| err(e.to_string()))?;
            *hash = fnv1a(*hash, &bytes);
            let img = crate::texture::decode_rgba(&bytes, &file).map_err(err)?;
            let t = Texture::new(img.width(), img.height(), img.into_raw());
            let i = (textures.len(), t.has_alpha);
            textures.push(t);
            by_path.insert(file, i);
            Ok(i)
        };

    let mut mats = Vec::with_capacity(materials.len().max(1));
    for m in materials {
        let kd = m
            .diffuse
            .map(|c| Vec3::from_array(c.map(srgb_decode)))
            .unwrap_or(Vec3::ONE);
        let colour = match &m.diffuse_texture {
            Some(t) => Some(load_texture(&m.name, t, hash)?),
            None => None,
        };
        let alpha = match (&m.dissolve_texture, colour) {
            (Some(t), _) => Some(load_texture(&m.name, t, hash)?),
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
    Ok((mats, textures))
}

/// The objects' triangles (every coordinate finite and within [`MAX_MODEL_COORDINATE`]), less
/// the degenerate ones (counted); refused when none is left. Faces name materials below
/// `materials`, else the first.
fn triangles(
    path: &Path,
    models: &[tobj::Model],
    materials: usize,
) -> Result<(Vec<Tri>, u64), BakeError> {
    let mut tris = Vec::new();
    let mut degenerate = 0u64;
    let mut extent = 0.0f32;
    for model in models {
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
    for model in models {
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
        let material = mesh.material_id.filter(|&m| m < materials).unwrap_or(0) as u32;
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
    Ok((tris, degenerate))
}

/// The files an OBJ model is read from: the OBJ, its material libraries (`mtllib`) and every
/// texture they name (`map_*`, `bump`, `disp`, `decal`, `refl`).
pub(crate) fn source_files(obj: &Path) -> Result<Vec<PathBuf>, BakeError> {
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
