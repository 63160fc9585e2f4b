//! Errors of the bake: each names the file or parameter and what is wrong.

use std::path::PathBuf;

/// Why a bake failed. Nothing is written when any of these is returned.
#[derive(Debug, thiserror::Error)]
pub enum BakeError {
    /// The model file cannot be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The OBJ or its MTL cannot be parsed.
    #[error("{path}: cannot parse {what}: {reason}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// "OBJ" or "material library".
        what: &'static str,
        /// The parser's reason.
        reason: String,
    },
    /// The model is unusable: no faces, non-finite coordinates, …
    #[error("{path}: {what}")]
    Model {
        /// The model file.
        path: PathBuf,
        /// What is wrong.
        what: String,
    },
    /// A texture named by a material is missing or unreadable.
    #[error("{path}: material {material:?}: texture {texture}: {reason}")]
    Texture {
        /// The model file.
        path: PathBuf,
        /// The material naming it.
        material: String,
        /// The texture path.
        texture: PathBuf,
        /// Why it cannot be used.
        reason: String,
    },
    /// A parameter is out of range, or an output cannot be written.
    #[error(transparent)]
    Format(#[from] forest_format::FormatError),
}
