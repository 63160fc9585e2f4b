//! Loading a tree model from glTF 2.0 (`.gltf` with external or GLB-embedded data, or `.glb`)
//! into the same flat triangles as the OBJ loader, with the `gltf` crate.
//!
//! What is read:
//! - the default scene (else the first), every node's mesh with the node's world transform
//!   (normals by its inverse transpose);
//! - triangle primitives (`mode` 4): POSITION, NORMAL (else the face normal), TEXCOORD_0
//!   (else zero) turned to the OBJ convention `v = 1 − v`, indices (else in order);
//! - materials: `baseColorFactor` (linear RGB, into `kd`) and `baseColorTexture`; alphaMode
//!   OPAQUE ignores alpha; MASK tests `factor alpha × texture alpha ≥ alphaCutoff`, which the
//!   loader turns into the bake's fixed test at 0.5 by remapping the texture's alpha
//!   piecewise-linearly (a copy per image and cutoff; untouched for cutoff 0.5 and factor 1);
//!   BLEND is drawn alpha-tested at 0.5 like MASK at its default cutoff (the bake and every
//!   renderer composite opaque, alpha-tested leaves). Every triangle is drawn double-sided,
//!   as the OBJ's are, whatever `doubleSided` says;
//! - buffers and images from the GLB's binary chunk or from files next to the model (their
//!   URIs percent-decoded; read with the same size limits as the OBJ's files), images as PNG
//!   or JPEG.
//!
//! Refused, with a message naming it: `extensionsRequired`, `KHR_texture_transform` (it moves
//! texture coordinates), `data:` URIs, skins, non-triangle primitives, textures on a
//! coordinate set other than 0, sparse accessors, and a file with no mesh; and, before the
//! gltf crates (1.4.1) would panic on them, attributes naming missing accessors, accessors of
//! types glTF does not allow for their attribute, images without a source or MIME type, and
//! node hierarchies that are not trees.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use forest_format::bounded;
use forest_format::shading::LEAF_TRANSLUCENCY;
use glam::{Mat3, Mat4, Vec2, Vec3};

use crate::error::BakeError;
use crate::mesh::{FNV_OFFSET, MAX_MODEL_COORDINATE, Material, Mesh, Tri, fnv1a};
use crate::texture::Texture;

/// Whether `path` names a glTF model (by its extension, `.gltf` or `.glb`).
pub fn is_gltf(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"))
}

/// A world-space triangle before the degenerate test: positions, texture coordinates,
/// normals (None: the face normal), material.
type RawTri = ([Vec3; 3], [Vec2; 3], Option<[Vec3; 3]>, u32);

fn parse_err(path: &Path, reason: impl Into<String>) -> BakeError {
    BakeError::Parse {
        path: path.into(),
        what: "glTF",
        reason: reason.into(),
    }
}

/// An external file a URI names, relative to the model's folder, its `%XX` escapes decoded
/// (a URI reference, as glTF requires; `data:` URIs refused).
fn external(path: &Path, uri: &str, what: &str) -> Result<PathBuf, BakeError> {
    if uri.starts_with("data:") {
        return Err(parse_err(
            path,
            format!("{what} is a data: URI, which is not supported (use a .glb or a file)"),
        ));
    }
    let name = percent_encoding::percent_decode_str(uri)
        .decode_utf8()
        .map_err(|_| {
            parse_err(
                path,
                format!("{what} URI {uri:?} does not decode to a UTF-8 file name"),
            )
        })?;
    let dir = path.parent().unwrap_or(Path::new("."));
    Ok(dir.join(name.as_ref()))
}

/// The files a glTF model is read from: itself, and the buffers and images its URIs name.
pub fn source_files(path: &Path) -> Result<Vec<PathBuf>, BakeError> {
    let bytes = bounded::read(path, bounded::limit::DATA)?;
    let doc = gltf::Gltf::from_slice_without_validation(&bytes)
        .map_err(|e| parse_err(path, e.to_string()))?;
    // From the JSON itself: the document is not validated, and the crate's accessors unwrap.
    let json = doc.document.as_json();
    let mut files = vec![path.to_path_buf()];
    let uris = (json.buffers.iter().map(|b| b.uri.as_deref()))
        .chain(json.images.iter().map(|i| i.uri.as_deref()));
    for uri in uris.flatten() {
        if let Ok(f) = external(path, uri, "a file") {
            files.push(f);
        }
    }
    files.sort();
    files.dedup();
    Ok(files)
}

/// Remap alpha so that `a ≥ c` (a in 0..=1) becomes `a' ≥ 0.5`, the bake's test: linear on
/// `[0, c]` onto `[0, 0.5)` and on `[c, 1]` onto `[0.5, 1]`, rounded so a passing texel stays
/// at 128 or above and a failing one at 127 or below.
fn remap_alpha(a: u8, c: f32) -> u8 {
    let x = f32::from(a) / 255.0;
    if c <= 0.0 {
        return 255;
    }
    if x >= c {
        let y = if c >= 1.0 {
            1.0
        } else {
            0.5 + 0.5 * (x - c) / (1.0 - c)
        };
        ((y * 255.0).round() as u8).max(128)
    } else {
        ((0.5 * x / c * 255.0).round() as u8).min(127)
    }
}

/// Refuse the extensions the loader cannot honour: any required one, and
/// `KHR_texture_transform` (it moves texture coordinates).
fn refuse_extensions(path: &Path, doc: &gltf::Document) -> Result<(), BakeError> {
    let required: Vec<&str> = doc.extensions_required().collect();
    if !required.is_empty() {
        return Err(parse_err(
            path,
            format!(
                "requires the extension(s) {}, which the loader does not support",
                required.join(", ")
            ),
        ));
    }
    if doc.extensions_used().any(|e| e == "KHR_texture_transform") {
        return Err(parse_err(
            path,
            "uses KHR_texture_transform, which the loader does not support (it moves texture \
         coordinates)",
        ));
    }
    Ok(())
}

/// What the gltf crates (1.4.1) would panic on: a primitive attribute naming an accessor the
/// file lacks (validation indexes the accessors with POSITION's before checking it), an image
/// with neither a URI nor a buffer view, or a buffer view without a MIME type
/// (`Image::source` unwraps both).
fn check_json(path: &Path, json: &gltf::json::Root) -> Result<(), BakeError> {
    for (i, image) in json.images.iter().enumerate() {
        let reason = match (&image.buffer_view, &image.uri, &image.mime_type) {
            (Some(_), _, None) => "has a buffer view but no mimeType",
            (None, None, _) => "has neither a uri nor a buffer view",
            _ => continue,
        };
        return Err(parse_err(path, format!("image {i} {reason}")));
    }
    let count = json.accessors.len();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            for (semantic, index) in &primitive.attributes {
                if index.value() >= count {
                    let name = match semantic {
                        gltf::json::validation::Checked::Valid(s) => s.to_string(),
                        gltf::json::validation::Checked::Invalid => "an unknown attribute".into(),
                    };
                    return Err(parse_err(
                        path,
                        format!(
                            "mesh {m}, primitive {p}: {name} names accessor {}, but the file \
                             has {count}",
                            index.value()
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// The accessors a primitive is read through have the types glTF requires of them (the gltf
/// crate's readers assume them and panic otherwise), and none is sparse.
fn check_accessors(path: &Path, at: &str, prim: &gltf::Primitive) -> Result<(), BakeError> {
    use gltf::accessor::{DataType as D, Dimensions as N};
    use gltf::mesh::Semantic as S;
    let check = |name: &str, a: gltf::Accessor, types: &[D], dims: N| {
        if a.sparse().is_some() {
            return Err(parse_err(
                path,
                format!("{at}: {name} is a sparse accessor, which is not supported"),
            ));
        }
        if !types.contains(&a.data_type()) || a.dimensions() != dims {
            return Err(parse_err(
                path,
                format!(
                    "{at}: {name} is {:?} {:?}; glTF requires {dims:?} of {types:?}",
                    a.dimensions(),
                    a.data_type()
                ),
            ));
        }
        Ok(())
    };
    for (semantic, a) in prim.attributes() {
        match semantic {
            S::Positions => check("POSITION", a, &[D::F32], N::Vec3)?,
            S::Normals => check("NORMAL", a, &[D::F32], N::Vec3)?,
            S::TexCoords(0) => check("TEXCOORD_0", a, &[D::F32, D::U8, D::U16], N::Vec2)?,
            _ => {}
        }
    }
    if let Some(a) = prim.indices() {
        check("the indices", a, &[D::U8, D::U16, D::U32], N::Scalar)?;
    }
    Ok(())
}

/// Load a glTF 2.0 model (see the module docs for what is read and what is refused).
pub fn load(path: &Path) -> Result<Mesh, BakeError> {
    let bytes = bounded::read(path, bounded::limit::DATA)?;
    let mut hash = fnv1a(FNV_OFFSET, &bytes);
    // Parsed, then checked for what validation would call invalid without naming (an
    // unsupported required extension) or lets through to a panic in the gltf crates, then
    // validated.
    let parsed = gltf::Gltf::from_slice_without_validation(&bytes)
        .map_err(|e| parse_err(path, e.to_string()))?;
    refuse_extensions(path, &parsed)?;
    check_json(path, parsed.document.as_json())?;
    let doc = gltf::Gltf {
        document: gltf::Document::from_json(parsed.document.into_json())
            .map_err(|e| parse_err(path, e.to_string()))?,
        blob: parsed.blob,
    };

    // Buffers: the GLB's binary chunk (borrowed, not copied), or files; each at least as long
    // as it says.
    let mut buffers: Vec<std::borrow::Cow<[u8]>> = Vec::new();
    for b in doc.buffers() {
        let data = match b.source() {
            gltf::buffer::Source::Bin => {
                std::borrow::Cow::Borrowed(doc.blob.as_deref().ok_or_else(|| {
                    parse_err(
                        path,
                        format!(
                            "buffer {} is the binary chunk, which the file lacks",
                            b.index()
                        ),
                    )
                })?)
            }
            gltf::buffer::Source::Uri(uri) => {
                let f = external(path, uri, &format!("buffer {}", b.index()))?;
                std::borrow::Cow::Owned(bounded::read(&f, bounded::limit::DATA)?)
            }
        };
        if data.len() < b.length() {
            return Err(parse_err(
                path,
                format!(
                    "buffer {} holds {} bytes, it says {}",
                    b.index(),
                    data.len(),
                    b.length()
                ),
            ));
        }
        hash = fnv1a(hash, &data);
        buffers.push(data);
    }

    // Images, decoded on demand, and textures per (image, alpha cutoff).
    let mut images: HashMap<usize, image::RgbaImage> = HashMap::new();
    let mut textures: Vec<Texture> = Vec::new();
    let mut texture_of: HashMap<(usize, Option<u32>), usize> = HashMap::new();
    let mut materials: Vec<Material> = Vec::new();
    // For each glTF material: its index in `materials`, or None when nothing of it passes.
    let mut material_of: Vec<Option<u32>> = Vec::new();
    for m in doc.materials() {
        let name = m
            .name()
            .map(str::to_owned)
            .unwrap_or_else(|| format!("material {}", m.index().unwrap_or(0)));
        let pbr = m.pbr_metallic_roughness();
        let factor = pbr.base_color_factor();
        let mode = m.alpha_mode();
        // The cutoff on texture alpha (None: opaque).
        let cutoff = match mode {
            gltf::material::AlphaMode::Opaque => None,
            gltf::material::AlphaMode::Mask => Some(m.alpha_cutoff().unwrap_or(0.5) / factor[3]),
            gltf::material::AlphaMode::Blend => Some(0.5 / factor[3]),
        };
        let colour = match pbr.base_color_texture() {
            None => None,
            Some(info) => {
                if info.tex_coord() != 0 {
                    return Err(parse_err(
                        path,
                        format!(
                            "material {name:?}: its base colour texture uses coordinate set {}; \
                             only set 0 is supported",
                            info.tex_coord()
                        ),
                    ));
                }
                let image = info.texture().source();
                let ii = image.index();
                if let std::collections::hash_map::Entry::Vacant(slot) = images.entry(ii) {
                    let err = |texture: PathBuf, reason: String| BakeError::Texture {
                        path: path.into(),
                        material: name.clone(),
                        texture,
                        reason,
                    };
                    let (data, file) = match image.source() {
                        gltf::image::Source::View { view, .. } => {
                            let b = &buffers[view.buffer().index()];
                            let range = view.offset()..view.offset() + view.length();
                            let data = b.get(range).ok_or_else(|| {
                                parse_err(
                                    path,
                                    format!("image {ii}: its view lies outside its buffer"),
                                )
                            })?;
                            (
                                std::borrow::Cow::Borrowed(data),
                                path.join(format!("image {ii}")),
                            )
                        }
                        gltf::image::Source::Uri { uri, .. } => {
                            let f = external(path, uri, &format!("image {ii}"))?;
                            let data = bounded::read(&f, bounded::limit::TEXTURE)
                                .map_err(|e| err(f.clone(), e.to_string()))?;
                            hash = fnv1a(hash, &data);
                            (std::borrow::Cow::Owned(data), f)
                        }
                    };
                    let img = crate::texture::decode_rgba(&data, &file)
                        .map_err(|reason| err(file.clone(), reason))?;
                    slot.insert(img);
                }
                Some(ii)
            }
        };
        // A material with no alpha texture is wholly in or out by its factor.
        let untextured_out = cutoff.is_some_and(|c| colour.is_none() && c > 1.0);
        if untextured_out || cutoff.is_some_and(|c| !c.is_finite()) {
            material_of.push(None);
            continue;
        }
        let key = colour.map(|ii| {
            let c = cutoff.filter(|&c| c != 0.5).map(f32::to_bits);
            (ii, c)
        });
        let tex = key.map(|k| match texture_of.get(&k) {
            Some(&t) => t,
            None => {
                let img = &images[&k.0];
                let mut rgba = img.as_raw().clone();
                if let Some(bits) = k.1 {
                    let c = f32::from_bits(bits);
                    for p in rgba.chunks_exact_mut(4) {
                        p[3] = remap_alpha(p[3], c);
                    }
                }
                textures.push(Texture::new(img.width(), img.height(), rgba));
                texture_of.insert(k, textures.len() - 1);
                textures.len() - 1
            }
        });
        let alpha = match (cutoff, tex) {
            (Some(_), Some(t)) if textures[t].has_alpha => Some((t, true)),
            _ => None,
        };
        materials.push(Material {
            name,
            kd: Vec3::new(factor[0], factor[1], factor[2]),
            colour: tex,
            alpha,
            translucency: if alpha.is_some() {
                LEAF_TRANSLUCENCY
            } else {
                0.0
            },
        });
        material_of.push(Some(materials.len() as u32 - 1));
    }
    // glTF's default material (white, opaque) for primitives that name none: added after
    // the others when a primitive uses it.
    let default_material = materials.len() as u32;

    // Triangles in world space.
    let scene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .ok_or_else(|| parse_err(path, "no scene: nothing to bake"))?;
    let mut raw: Vec<RawTri> = Vec::new();
    let mut stack: Vec<(gltf::Node, Mat4)> = scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    let mut meshes = 0usize;
    // Nodes form trees: a scene visits each at most once (a cycle would never end).
    let mut visits = 0usize;
    while let Some((node, parent)) = stack.pop() {
        visits += 1;
        if visits > doc.nodes().len() {
            return Err(parse_err(
                path,
                "the node hierarchy is not a tree (a cycle, or a node with two parents)",
            ));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if node.skin().is_some() {
            return Err(parse_err(
                path,
                format!("node {}: skinned meshes are not supported", node.index()),
            ));
        }
        stack.extend(node.children().map(|c| (c, world)));
        let Some(mesh) = node.mesh() else { continue };
        meshes += 1;
        let normal_matrix = Mat3::from_mat4(world).inverse().transpose();
        for prim in mesh.primitives() {
            let at = || format!("mesh {} primitive {}", mesh.index(), prim.index());
            if prim.mode() != gltf::mesh::Mode::Triangles {
                return Err(parse_err(
                    path,
                    format!(
                        "{}: mode {:?}; only triangles are supported",
                        at(),
                        prim.mode()
                    ),
                ));
            }
            let material = match prim.material().index() {
                None => default_material,
                Some(i) => match material_of[i] {
                    Some(m) => m,
                    None => continue,
                },
            };
            check_accessors(path, &at(), &prim)?;
            let reader = prim.reader(|b| buffers.get(b.index()).map(|d| d.as_ref()));
            let pos: Vec<Vec3> = reader
                .read_positions()
                .ok_or_else(|| parse_err(path, format!("{}: no POSITION", at())))?
                .map(|p| world.transform_point3(Vec3::from_array(p)))
                .collect();
            let nrm: Option<Vec<Vec3>> = reader
                .read_normals()
                .map(|n| n.map(|n| normal_matrix * Vec3::from_array(n)).collect());
            let uv: Option<Vec<Vec2>> = reader
                .read_tex_coords(0)
                .map(|t| t.into_f32().map(|[u, v]| Vec2::new(u, 1.0 - v)).collect());
            let idx: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..pos.len() as u32).collect(),
            };
            let n_ok = nrm.as_ref().is_none_or(|n| n.len() == pos.len());
            let uv_ok = uv.as_ref().is_none_or(|t| t.len() == pos.len());
            if !n_ok || !uv_ok || idx.iter().any(|&i| i as usize >= pos.len()) {
                return Err(parse_err(
                    path,
                    format!(
                        "{}: an index or attribute count does not match its {} positions",
                        at(),
                        pos.len()
                    ),
                ));
            }
            for f in idx.chunks_exact(3) {
                let f = [f[0] as usize, f[1] as usize, f[2] as usize];
                raw.push((
                    f.map(|i| pos[i]),
                    f.map(|i| uv.as_ref().map_or(Vec2::ZERO, |t| t[i])),
                    nrm.as_ref().map(|n| f.map(|i| n[i])),
                    material,
                ));
            }
        }
    }
    if raw.iter().any(|t| t.3 == default_material) {
        materials.push(Material {
            name: "default".into(),
            kd: Vec3::ONE,
            colour: None,
            alpha: None,
            translucency: 0.0,
        });
    }
    if meshes == 0 {
        return Err(parse_err(path, "the scene has no mesh: nothing to bake"));
    }

    let mut extent = 0.0f32;
    for (i, (p, ..)) in raw.iter().enumerate() {
        for x in p.iter().flat_map(|v| v.to_array()) {
            if !x.is_finite() || x.abs() > MAX_MODEL_COORDINATE {
                return Err(BakeError::Model {
                    path: path.into(),
                    what: format!(
                        "triangle {} has the coordinate {x:e}, beyond the ±{MAX_MODEL_COORDINATE:e} \
                         model units the bake handles or not finite",
                        i + 1
                    ),
                });
            }
            extent = extent.max(x.abs());
        }
    }
    let min_area2 = crate::mesh::min_area2(extent);
    let mut tris = Vec::with_capacity(raw.len());
    let mut degenerate = 0u64;
    for (p, uv, n, material) in raw {
        match Tri::new(p, uv, n, material, min_area2) {
            Some(t) => tris.push(t),
            None => degenerate += 1,
        }
    }
    if tris.is_empty() {
        return Err(crate::mesh::no_triangles(path, degenerate));
    }
    Ok(Mesh {
        tris,
        materials,
        textures,
        degenerate,
        hash,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn alpha_remap_moves_the_cutoff_to_one_half() {
        for c in [0.1f32, 0.3, 0.5, 0.7, 0.95] {
            for a in 0..=255u8 {
                let passes = f32::from(a) / 255.0 >= c;
                assert_eq!(remap_alpha(a, c) >= 128, passes, "a {a} cutoff {c}");
            }
        }
        assert_eq!(remap_alpha(0, 0.5), 0);
        assert_eq!(remap_alpha(255, 0.5), 255);
        assert_eq!(remap_alpha(10, 0.0), 255);
    }
}
