//! The checks a glTF file passes before the `gltf` crates read it (a GLB's header, the
//! extensions the loader cannot honour, JSON the crates would panic on), and its parse.

use std::path::Path;

use crate::error::BakeError;

/// The error for a file the loader refuses, naming the reason.
pub(crate) fn parse_err(path: &Path, reason: impl Into<String>) -> BakeError {
    BakeError::Parse {
        path: path.into(),
        what: "glTF",
        reason: reason.into(),
    }
}

/// A GLB's header, checked before the gltf crate (1.4.1) reads it: it subtracts the header's
/// 12 bytes from the length the header states without checking that it is at least that.
pub(crate) fn check_glb_header(path: &Path, bytes: &[u8]) -> Result<(), BakeError> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    let Some(length) = bytes.get(8..12) else {
        return Err(parse_err(path, "a GLB shorter than its 12-byte header"));
    };
    let length = u32::from_le_bytes([length[0], length[1], length[2], length[3]]);
    if length < 12 || length as usize > bytes.len() {
        return Err(parse_err(
            path,
            format!(
                "its GLB header says the file is {length} bytes; it is {} (and the header \
                 alone is 12)",
                bytes.len()
            ),
        ));
    }
    Ok(())
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

/// The document of `bytes`: parsed, then checked for what validation would call invalid
/// without naming (an unsupported required extension) or lets through to a panic in the gltf
/// crates, then validated.
pub(crate) fn parse(path: &Path, bytes: &[u8]) -> Result<gltf::Gltf, BakeError> {
    check_glb_header(path, bytes)?;
    let parsed = gltf::Gltf::from_slice_without_validation(bytes)
        .map_err(|e| parse_err(path, e.to_string()))?;
    refuse_extensions(path, &parsed)?;
    check_json(path, parsed.document.as_json())?;
    Ok(gltf::Gltf {
        document: gltf::Document::from_json(parsed.document.into_json())
            .map_err(|e| parse_err(path, e.to_string()))?,
        blob: parsed.blob,
    })
}
