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
//! Every accessor is read through [`crate::gltf_accessor`], which checks it against its
//! buffer view and buffer (offset, stride, count, component type, normalised flag) before
//! reading, instead of the gltf crate's reader (which asserts on a stride below the element
//! size and cuts reads short at a buffer's end).
//!
//! Refused, with a message naming it: `extensionsRequired`, `KHR_texture_transform` (it moves
//! texture coordinates), `data:` URIs, skins, non-triangle primitives, index counts that are
//! not whole triangles, textures on a coordinate set other than 0, sparse accessors, a file
//! with no mesh; node transforms that are not finite, a rotation that is not a unit
//! quaternion (beyond rounding; a zero one is not taken as the identity), a scale of 0 or a
//! singular or projective matrix; `alphaCutoff` or `baseColorFactor` outside [0, 1]; a base
//! colour texture that does not repeat while its coordinates leave [0, 1] (the bake repeats
//! every texture); and, before the gltf crates (1.4.1) would panic on them, attributes
//! naming missing accessors, images without a source or MIME type, and node hierarchies that
//! are not trees.
//!
//! Read past, with a note in [`Mesh::notes`]: animations, morph targets, vertex colours, cameras,
//! single-sided materials (baked double-sided), normal, occlusion, emissive and
//! metal-roughness maps, and extensions the file uses without requiring them. `extras`
//! anywhere are ignored whatever their JSON type.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use forest_format::bounded;
use forest_format::shading::LEAF_TRANSLUCENCY;
use glam::{Mat3, Mat4, Vec2, Vec3};

use crate::error::BakeError;
use crate::gltf_checks::{check_glb_header, parse, parse_err};
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
    check_glb_header(path, &bytes)?;
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

/// A primitive's vertex data as the file holds it: positions, normals, texture coordinates
/// (set 0) and indices (in order when it has none), every accessor read through
/// [`crate::gltf_accessor`]'s checks, the counts matching and every index in range.
type PrimitiveData = (
    Vec<[f32; 3]>,
    Option<Vec<[f32; 3]>>,
    Option<Vec<[f32; 2]>>,
    Vec<u32>,
);

fn read_primitive(
    prim: &gltf::Primitive,
    buffers: &[std::borrow::Cow<[u8]>],
    at: &str,
) -> Result<PrimitiveData, String> {
    use crate::gltf_accessor::{read_floats, read_indices};
    use gltf::accessor::DataType as D;
    use gltf::mesh::Semantic as S;
    let max = bounded::limit::DATA;
    let named = |what: &str, a: &gltf::Accessor| format!("{at}: {what} (accessor {})", a.index());
    let position = prim
        .get(&S::Positions)
        .ok_or_else(|| format!("{at} has no POSITION attribute"))?;
    let pos: Vec<[f32; 3]> = read_floats(
        &position,
        buffers,
        &named("POSITION", &position),
        &[D::F32],
        max,
    )?;
    let nrm = match prim.get(&S::Normals) {
        Some(a) => Some(read_floats::<3>(
            &a,
            buffers,
            &named("NORMAL", &a),
            &[D::F32],
            max,
        )?),
        None => None,
    };
    let uv = match prim.get(&S::TexCoords(0)) {
        Some(a) => Some(read_floats::<2>(
            &a,
            buffers,
            &named("TEXCOORD_0", &a),
            &[D::F32, D::U8, D::U16],
            max,
        )?),
        None => None,
    };
    for (what, n) in [
        ("NORMAL", nrm.as_ref().map(Vec::len)),
        ("TEXCOORD_0", uv.as_ref().map(Vec::len)),
    ] {
        if let Some(n) = n.filter(|&n| n != pos.len()) {
            return Err(format!(
                "{at}: {what} has {n} elements, POSITION {}; glTF requires the same count",
                pos.len()
            ));
        }
    }
    let idx = match prim.indices() {
        Some(a) => read_indices(&a, buffers, &named("the indices", &a), max)?,
        None => (0..pos.len() as u32).collect(),
    };
    if idx.len() % 3 != 0 {
        return Err(format!(
            "{at}: {} indices (or vertices, without indices) are not whole triangles",
            idx.len()
        ));
    }
    if let Some((i, v)) = idx
        .iter()
        .enumerate()
        .find(|(_, v)| **v as usize >= pos.len())
    {
        return Err(format!(
            "{at}: index {i} is {v}, past its {} vertices",
            pos.len()
        ));
    }
    Ok((pos, nrm, uv, idx))
}

/// How far a node's rotation may be from a unit quaternion (in length) and still be taken
/// as one, normalised: exporters writing rounded decimals stay within it.
const QUATERNION_TOLERANCE: f32 = 1e-3;

/// A node's local transform, checked: finite; a matrix affine and invertible; a rotation a
/// unit quaternion (within [`QUATERNION_TOLERANCE`], then normalised; a zero one is refused,
/// not taken as the identity); no scale of 0, which would flatten its mesh.
fn node_matrix(node: &gltf::Node) -> Result<Mat4, String> {
    let at = format!("node {}", node.index());
    match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => {
            let m = Mat4::from_cols_array_2d(&matrix);
            if !m.is_finite() {
                return Err(format!("{at}: its matrix is not finite"));
            }
            if m.row(3) != glam::Vec4::W {
                return Err(format!(
                    "{at}: its matrix's last row is {:?}, not (0, 0, 0, 1) (glTF matrices \
                     are affine)",
                    m.row(3).to_array()
                ));
            }
            let det = m.determinant();
            if !det.is_normal() {
                return Err(format!(
                    "{at}: its matrix is singular (determinant {det:e}): it flattens its mesh"
                ));
            }
            Ok(m)
        }
        gltf::scene::Transform::Decomposed {
            translation,
            rotation,
            scale,
        } => {
            let all = translation.iter().chain(&rotation).chain(&scale);
            if let Some(x) = all.copied().find(|x| !x.is_finite()) {
                return Err(format!(
                    "{at}: its transform holds {x}, which is not finite"
                ));
            }
            let q = glam::Quat::from_array(rotation);
            let len = q.length();
            if (len - 1.0).abs() > QUATERNION_TOLERANCE {
                return Err(format!(
                    "{at}: its rotation {rotation:?} is not a unit quaternion (length {len}; \
                     glTF requires 1)"
                ));
            }
            if scale.contains(&0.0) {
                return Err(format!(
                    "{at}: its scale {scale:?} has a 0, which flattens its mesh"
                ));
            }
            Ok(Mat4::from_scale_rotation_translation(
                Vec3::from_array(scale),
                q.normalize(),
                Vec3::from_array(translation),
            ))
        }
    }
}

/// Load a glTF 2.0 model (see the module docs for what is read and what is refused).
pub fn load(path: &Path) -> Result<Mesh, BakeError> {
    let bytes = bounded::read(path, bounded::limit::DATA)?;
    let mut hash = fnv1a(FNV_OFFSET, &bytes);
    let doc = parse(path, &bytes)?;
    let buffers = load_buffers(path, &doc, &mut hash)?;
    let mut m = read_materials(path, &doc, &buffers, &mut hash)?;
    // glTF's default material (white, opaque) for primitives that name none: added after
    // the others when a primitive uses it.
    let default_material = m.materials.len() as u32;
    let (raw, coloured) = scene_triangles(path, &doc, &buffers, &m, default_material)?;
    if raw.iter().any(|t| t.3 == default_material) {
        m.materials.push(Material {
            name: "default".into(),
            kd: Vec3::ONE,
            colour: None,
            alpha: None,
            translucency: 0.0,
        });
    }
    let (tris, degenerate) = checked_triangles(path, raw)?;
    let notes = notes(&doc, coloured, &m);
    Ok(Mesh {
        tris,
        materials: m.materials,
        textures: m.textures,
        degenerate,
        hash,
        notes,
    })
}

/// The buffers: the GLB's binary chunk (borrowed, not copied), or files; each at least as
/// long as it says, hashed into `hash`.
fn load_buffers<'a>(
    path: &Path,
    doc: &'a gltf::Gltf,
    hash: &mut u64,
) -> Result<Vec<std::borrow::Cow<'a, [u8]>>, BakeError> {
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
        *hash = fnv1a(*hash, &data);
        buffers.push(data);
    }
    Ok(buffers)
}

/// What the glTF materials become: the bake's materials and textures, and per glTF material
/// its index among them (None when nothing of it passes) and its texture's wrap modes where
/// they do not repeat (the bake, repeating every texture, honours them only for coordinates in
/// [0, 1]); the materials the notes name.
struct Materials {
    materials: Vec<Material>,
    textures: Vec<Texture>,
    material_of: Vec<Option<u32>>,
    clamped: Vec<Option<String>>,
    single_sided: Vec<String>,
    unused_maps: Vec<String>,
}

/// Every material with its base colour texture (images decoded once, textures made per
/// (image, alpha cutoff)); image files are hashed into `hash`.
fn read_materials(
    path: &Path,
    doc: &gltf::Gltf,
    buffers: &[std::borrow::Cow<[u8]>],
    hash: &mut u64,
) -> Result<Materials, BakeError> {
    let mut images: HashMap<usize, image::RgbaImage> = HashMap::new();
    let mut texture_of: HashMap<(usize, Option<u32>), usize> = HashMap::new();
    let mut m = Materials {
        materials: Vec::new(),
        textures: Vec::new(),
        material_of: Vec::new(),
        clamped: Vec::new(),
        single_sided: Vec::new(),
        unused_maps: Vec::new(),
    };
    for mat in doc.materials() {
        let name = mat
            .name()
            .map(str::to_owned)
            .unwrap_or_else(|| format!("material {}", mat.index().unwrap_or(0)));
        let pbr = mat.pbr_metallic_roughness();
        let factor = pbr.base_color_factor();
        if factor.iter().any(|x| !(0.0..=1.0).contains(x)) {
            return Err(parse_err(
                path,
                format!(
                    "material {name:?}: baseColorFactor {factor:?} lies outside [0, 1] (glTF \
                     requires it inside)"
                ),
            ));
        }
        if let Some(c) = mat.alpha_cutoff().filter(|c| !(0.0..=1.0).contains(c)) {
            return Err(parse_err(
                path,
                format!(
                    "material {name:?}: alphaCutoff {c} lies outside [0, 1] (glTF requires \
                     it inside)"
                ),
            ));
        }
        let mode = mat.alpha_mode();
        // The cutoff on texture alpha (None: opaque).
        let cutoff = match mode {
            gltf::material::AlphaMode::Opaque => None,
            gltf::material::AlphaMode::Mask => Some(mat.alpha_cutoff().unwrap_or(0.5) / factor[3]),
            gltf::material::AlphaMode::Blend => Some(0.5 / factor[3]),
        };
        if !mat.double_sided() {
            m.single_sided.push(name.clone());
        }
        if mat.normal_texture().is_some()
            || mat.occlusion_texture().is_some()
            || mat.emissive_texture().is_some()
            || pbr.metallic_roughness_texture().is_some()
        {
            m.unused_maps.push(name.clone());
        }
        use gltf::texture::WrappingMode as W;
        m.clamped.push(pbr.base_color_texture().and_then(|info| {
            let sampler = info.texture().sampler();
            let (s, t) = (sampler.wrap_s(), sampler.wrap_t());
            (s != W::Repeat || t != W::Repeat).then(|| format!("wraps {s:?} × {t:?}"))
        }));
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
                    slot.insert(decode_image(path, &image, &name, buffers, hash)?);
                }
                Some(ii)
            }
        };
        // A material with no alpha texture is wholly in or out by its factor.
        let untextured_out = cutoff.is_some_and(|c| colour.is_none() && c > 1.0);
        if untextured_out || cutoff.is_some_and(|c| !c.is_finite()) {
            m.material_of.push(None);
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
                m.textures
                    .push(Texture::new(img.width(), img.height(), rgba));
                texture_of.insert(k, m.textures.len() - 1);
                m.textures.len() - 1
            }
        });
        let alpha = match (cutoff, tex) {
            (Some(_), Some(t)) if m.textures[t].has_alpha => Some((t, true)),
            _ => None,
        };
        m.materials.push(Material {
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
        m.material_of.push(Some(m.materials.len() as u32 - 1));
    }
    Ok(m)
}

/// Image `image` of material `name`, decoded: from a buffer view, or from a file (hashed
/// into `hash`).
fn decode_image(
    path: &Path,
    image: &gltf::Image,
    name: &str,
    buffers: &[std::borrow::Cow<[u8]>],
    hash: &mut u64,
) -> Result<image::RgbaImage, BakeError> {
    let ii = image.index();
    let err = |texture: PathBuf, reason: String| BakeError::Texture {
        path: path.into(),
        material: name.to_owned(),
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
            *hash = fnv1a(*hash, &data);
            (std::borrow::Cow::Owned(data), f)
        }
    };
    crate::texture::decode_rgba(&data, &file).map_err(|reason| err(file.clone(), reason))
}

/// The scene's triangles in world space, each with its material (`default_material` for
/// primitives that name none), and how many primitives carry vertex colours.
fn scene_triangles(
    path: &Path,
    doc: &gltf::Gltf,
    buffers: &[std::borrow::Cow<[u8]>],
    m: &Materials,
    default_material: u32,
) -> Result<(Vec<RawTri>, usize), BakeError> {
    let mut coloured = 0usize;
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
        let world = parent * node_matrix(&node).map_err(|reason| parse_err(path, reason))?;
        if !world.is_finite() {
            return Err(parse_err(
                path,
                format!(
                    "node {}: its transform times its parents' is not finite",
                    node.index()
                ),
            ));
        }
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
                Some(i) => match m.material_of[i] {
                    Some(m) => m,
                    None => continue,
                },
            };
            if prim.get(&gltf::mesh::Semantic::Colors(0)).is_some() {
                coloured += 1;
            }
            let (pos, nrm, uv, idx) =
                read_primitive(&prim, buffers, &at()).map_err(|reason| parse_err(path, reason))?;
            let wrap = prim.material().index().and_then(|i| m.clamped[i].as_ref());
            if let (Some(wrap), Some(uv)) = (wrap, &uv) {
                let outside = uv
                    .iter()
                    .flatten()
                    .find(|x| !(-1e-4..=1.0 + 1e-4).contains(*x));
                if let Some(x) = outside {
                    return Err(parse_err(
                        path,
                        format!(
                            "{}: its material's base colour texture {wrap}, but TEXCOORD_0 \
                             reaches {x} outside [0, 1]; the bake repeats every texture \
                             (use REPEAT, or keep the coordinates inside [0, 1])",
                            at()
                        ),
                    ));
                }
            }
            let pos: Vec<Vec3> = pos
                .into_iter()
                .map(|p| world.transform_point3(Vec3::from_array(p)))
                .collect();
            let nrm: Option<Vec<Vec3>> = nrm.map(|n| {
                n.into_iter()
                    .map(|n| normal_matrix * Vec3::from_array(n))
                    .collect()
            });
            let uv: Option<Vec<Vec2>> =
                uv.map(|t| t.into_iter().map(|[u, v]| Vec2::new(u, 1.0 - v)).collect());
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
    if meshes == 0 {
        return Err(parse_err(path, "the scene has no mesh: nothing to bake"));
    }
    Ok((raw, coloured))
}

/// The triangles checked (every coordinate finite and within [`MAX_MODEL_COORDINATE`]) and
/// made, less the degenerate ones (counted); refused when none is left.
fn checked_triangles(path: &Path, raw: Vec<RawTri>) -> Result<(Vec<Tri>, u64), BakeError> {
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
    Ok((tris, degenerate))
}

/// What the bake ignores of the file, said once each.
fn notes(doc: &gltf::Gltf, coloured: usize, m: &Materials) -> Vec<String> {
    let mut notes: Vec<String> = Vec::new();
    let count = |n: usize, what: &str| format!("{n} {what}{}", if n == 1 { "" } else { "s" });
    if doc.animations().len() > 0 {
        notes.push(format!(
            "{} ignored: the model is baked at rest",
            count(doc.animations().len(), "animation")
        ));
    }
    let morphs = doc
        .meshes()
        .flat_map(|m| m.primitives())
        .filter(|p| p.morph_targets().len() > 0)
        .count();
    if morphs > 0 {
        notes.push(format!(
            "morph targets of {} ignored: the base shape is baked",
            count(morphs, "primitive")
        ));
    }
    if coloured > 0 {
        notes.push(format!(
            "vertex colours (COLOR_0) of {} ignored",
            count(coloured, "primitive")
        ));
    }
    if doc.cameras().len() > 0 {
        notes.push(format!("{} ignored", count(doc.cameras().len(), "camera")));
    }
    if !m.single_sided.is_empty() {
        notes.push(format!(
            "material(s) {} are single-sided in the file; every triangle is baked double-sided",
            m.single_sided.join(", ")
        ));
    }
    if !m.unused_maps.is_empty() {
        notes.push(format!(
            "material(s) {}: normal, occlusion, emissive and metal-roughness maps are ignored \
             (the bake shades base colour and alpha)",
            m.unused_maps.join(", ")
        ));
    }
    let other: Vec<&str> = doc.extensions_used().collect();
    if !other.is_empty() {
        notes.push(format!(
            "extension(s) {} ignored (not required by the file)",
            other.join(", ")
        ));
    }
    notes
}

#[cfg(test)]
mod tests;
