//! Why the runtime refuses: one variant per cause, so a host can match on it.

/// Why the renderer cannot start, load a scene or draw a frame.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// No usable GPU adapter.
    #[error(
        "no GPU adapter found ({0}). Without a GPU, install a software Vulkan driver: \
         `apt-get install mesa-vulkan-drivers` (Debian/Ubuntu)"
    )]
    NoAdapter(String),
    /// The adapter refused the device.
    #[error("cannot open the GPU device: {0}")]
    Device(String),
    /// The forest names a different number of species than were given.
    #[error("the forest names {forest} species but {given} {what} were given")]
    SpeciesCount {
        /// Species the forest names.
        forest: usize,
        /// Species given.
        given: usize,
        /// What was given ("atlases", "models").
        what: &'static str,
    },
    /// Species of one forest baked at different resolutions.
    #[error(
        "species {index} ({name}) was baked at {resolution} px but species 0 at {first} px: \
         bake all species of a forest at one resolution"
    )]
    MixedResolution {
        /// Index of the species.
        index: usize,
        /// Its name in the forest.
        name: String,
        /// Its resolution (texels).
        resolution: u32,
        /// Species 0's resolution (texels).
        first: u32,
    },
    /// Something the scene or the stream needs is larger than a limit of the device.
    #[error("{what} needs {needed}, the device allows {limit}{hint}")]
    DeviceLimit {
        /// What is too large, and in which unit.
        what: String,
        /// What it needs.
        needed: u64,
        /// The device's limit.
        limit: u64,
        /// What to do about it (empty, or starting with ": ").
        hint: &'static str,
    },
    /// The adapter lacks a feature a method needs.
    #[error("{method} needs {feature}, which this adapter lacks")]
    MissingFeature {
        /// The method or pass.
        method: &'static str,
        /// The wgpu feature.
        feature: &'static str,
    },
    /// A colour format a target cannot be read back in.
    #[error("cannot read back a {format:?} target: use one of {allowed:?}")]
    UnreadableFormat {
        /// The format asked for.
        format: wgpu::TextureFormat,
        /// The formats that can be read back.
        allowed: &'static [wgpu::TextureFormat],
    },
    /// A parameter out of its range; the message names it.
    #[error("{0}")]
    Parameter(String),
    /// A species' atlas that a forest names could not be loaded.
    #[error("species {name} of {}", forest.display())]
    Species {
        /// The species' name in the forest file.
        name: String,
        /// The forest file.
        forest: std::path::PathBuf,
        /// Why its atlas could not be loaded.
        #[source]
        source: Box<RenderError>,
    },
    /// A method that needs data the renderer was not given (for example OBJ models).
    #[error("the {method} method needs {needs} (none were loaded)")]
    MissingData {
        /// The method.
        method: &'static str,
        /// What it needs.
        needs: &'static str,
    },
    /// The camera or frame parameters are invalid.
    #[error(transparent)]
    Camera(#[from] CameraError),
    /// The device reported validation or out-of-memory errors.
    #[error("the GPU reported: {}", .0.join("; "))]
    Gpu(Vec<String>),
    /// An atlas or forest file problem.
    #[error(transparent)]
    Format(#[from] forest_format::FormatError),
}

/// The one check behind every [`RenderError::DeviceLimit`]: `Err` naming `what` (with its
/// unit), what it needs and the limit, followed by `hint` (empty, or starting with ": "), when
/// `needed` exceeds `limit`.
pub fn within_limit(
    what: impl FnOnce() -> String,
    needed: u64,
    limit: u64,
    hint: &'static str,
) -> Result<(), RenderError> {
    if needed > limit {
        return Err(RenderError::DeviceLimit {
            what: what(),
            needed,
            limit,
            hint,
        });
    }
    Ok(())
}

/// The largest storage buffer a device of `limits` can bind: its storage-binding limit, or
/// its largest buffer where that is smaller (bytes).
pub fn storage_limit(limits: &wgpu::Limits) -> u64 {
    limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_limit_refuses_only_what_exceeds_it_and_names_it() {
        assert!(within_limit(|| unreachable!(), 10, 10, "").is_ok());
        let e = within_limit(|| "the thing (bytes)".into(), 11, 10, ": use less")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "the thing (bytes) needs 11, the device allows 10: use less"
        );
        let limits = wgpu::Limits {
            max_storage_buffer_binding_size: 100,
            max_buffer_size: 50,
            ..Default::default()
        };
        assert_eq!(storage_limit(&limits), 50);
    }
}

/// Why a camera cannot be used.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("invalid camera: {0}")]
pub struct CameraError(pub String);
