//! A model file of either kind, chosen by its extension: OBJ ([`crate::obj_mesh`]) or glTF 2.0
//! ([`crate::gltf_mesh`]).

use std::path::{Path, PathBuf};

use crate::error::BakeError;
use crate::mesh::Mesh;

impl Mesh {
    /// Load a model with its materials and textures: OBJ, or glTF 2.0 (`.gltf`, `.glb`; see
    /// [`crate::gltf_mesh`]) by the file's extension.
    pub fn load(path: &Path) -> Result<Self, BakeError> {
        if crate::gltf_mesh::is_gltf(path) {
            crate::gltf_mesh::load(path)
        } else {
            crate::obj_mesh::load(path)
        }
    }
}

/// The files a model is read from, without decoding any of them: for an OBJ, itself, its
/// material libraries (`mtllib`) and every texture they name; for a glTF, itself and the
/// buffers and images its URIs name. Front ends use it to refuse outputs that would overwrite
/// the model's own files. Unreadable libraries are skipped here (the loader reports them).
pub fn source_files(path: &Path) -> Result<Vec<PathBuf>, BakeError> {
    if crate::gltf_mesh::is_gltf(path) {
        crate::gltf_mesh::source_files(path)
    } else {
        crate::obj_mesh::source_files(path)
    }
}
