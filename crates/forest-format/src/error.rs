//! Errors of the format crate: every message names the file and what exactly is wrong.

use std::path::PathBuf;

/// An error reading, checking or writing an atlas or forest file.
#[derive(Debug, thiserror::Error)]
pub enum FormatError {
    /// An I/O error on a named path.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder concerned.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The manifest is not valid JSON for this format.
    #[error("{path}: not a valid atlas manifest: {source}")]
    Json {
        /// The manifest path.
        path: PathBuf,
        /// The parse error (with line and column).
        source: serde_json::Error,
    },
    /// The file is of another format or version.
    #[error("{path}: {what}")]
    Version {
        /// The manifest path.
        path: PathBuf,
        /// What was found and what was expected.
        what: String,
    },
    /// The content is inconsistent: a size, count or index does not match.
    #[error("{path}: {what}")]
    Invalid {
        /// The file concerned.
        path: PathBuf,
        /// What does not match, with the found and expected values.
        what: String,
    },
    /// An image could not be encoded or decoded.
    #[error("{path}: image: {what}")]
    Image {
        /// The image file.
        path: PathBuf,
        /// The codec's message.
        what: String,
    },
    /// Bake parameters out of their documented range.
    #[error("invalid parameter: {0}")]
    Param(String),
}

impl FormatError {
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Self::Io {
            path: path.into(),
            source,
        }
    }
    /// An error naming `path` and what is wrong with it.
    pub fn invalid(path: impl Into<PathBuf>, what: impl Into<String>) -> Self {
        Self::Invalid {
            path: path.into(),
            what: what.into(),
        }
    }
}
