//! Camera paths: a recorded walk or flight through a forest, played back by `forest view`
//! (interactively, or headless to numbered PNGs with `--path FILE --frames DIR`).
//!
//! JSON: `{"version": 1, "fov_deg": 60, "keys": [{"eye": [x, y, z], "target": [x, y, z]}, …]}`,
//! one key per frame, world metres, +Y up. Loading checks every value and names the first bad
//! one; saving writes a temporary file and renames it.

use std::path::Path;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::error::FormatError;

/// Camera path format version.
pub const CAMERA_PATH_VERSION: u32 = 1;

/// One frame's camera.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraKey {
    /// Eye position (world, metres).
    pub eye: [f32; 3],
    /// A point the camera looks at.
    pub target: [f32; 3],
}

/// A recorded camera path.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraPath {
    /// Format version ([`CAMERA_PATH_VERSION`]).
    pub version: u32,
    /// Vertical field of view in degrees, in (0, 180).
    pub fov_deg: f32,
    /// One camera per frame.
    pub keys: Vec<CameraKey>,
}

impl CameraPath {
    /// An empty path with the given field of view.
    pub fn new(fov_deg: f32) -> Self {
        Self {
            version: CAMERA_PATH_VERSION,
            fov_deg,
            keys: Vec::new(),
        }
    }

    /// Append a frame.
    pub fn push(&mut self, eye: Vec3, target: Vec3) {
        self.keys.push(CameraKey {
            eye: eye.to_array(),
            target: target.to_array(),
        });
    }

    /// Check every value; the error names the first bad one.
    pub fn check(&self, path: &Path) -> Result<(), FormatError> {
        if self.version != CAMERA_PATH_VERSION {
            return Err(FormatError::Version {
                path: path.into(),
                what: format!(
                    "camera path version {} (this program reads {CAMERA_PATH_VERSION})",
                    self.version
                ),
            });
        }
        if !(self.fov_deg > 0.0 && self.fov_deg < 180.0) {
            return Err(FormatError::invalid(
                path,
                format!("fov_deg {} must be in (0, 180)", self.fov_deg),
            ));
        }
        if self.keys.is_empty() {
            return Err(FormatError::invalid(path, "the path has no keys"));
        }
        for (i, k) in self.keys.iter().enumerate() {
            let (e, t) = (Vec3::from_array(k.eye), Vec3::from_array(k.target));
            if !(e.is_finite() && t.is_finite()) {
                return Err(FormatError::invalid(
                    path,
                    format!("key {i}: eye and target must be finite"),
                ));
            }
            if e.distance_squared(t) < 1e-12 {
                return Err(FormatError::invalid(
                    path,
                    format!("key {i}: target equals eye"),
                ));
            }
        }
        Ok(())
    }

    /// Load and check a path file.
    pub fn load(path: &Path) -> Result<Self, FormatError> {
        let bytes = crate::bounded::read(path, crate::bounded::limit::TEXT)?;
        Self::parse(path, &bytes)
    }

    /// [`CameraPath::load`] from the file's bytes; errors name `path`.
    pub fn parse(path: &Path, bytes: &[u8]) -> Result<Self, FormatError> {
        let p: CameraPath = serde_json::from_slice(bytes)
            .map_err(|e| FormatError::invalid(path, format!("not a valid camera path: {e}")))?;
        p.check(path)?;
        Ok(p)
    }

    /// Check and write atomically (temporary name, then rename).
    pub fn save(&self, path: &Path) -> Result<(), FormatError> {
        self.check(path)?;
        let json = serde_json::to_vec_pretty(self)
            .map_err(|e| FormatError::invalid(path, e.to_string()))?;
        crate::forest::write_atomic(path, &json)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_path_round_trips_and_bad_files_name_their_fault() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("walk.json");
        let mut p = CameraPath::new(60.0);
        p.push(Vec3::new(0.0, 1.7, 0.0), Vec3::new(0.0, 1.7, -10.0));
        p.push(Vec3::new(0.5, 1.7, 0.0), Vec3::new(0.5, 1.7, -10.0));
        p.save(&file).unwrap();
        assert_eq!(CameraPath::load(&file).unwrap(), p);

        let bad = |json: &str| {
            std::fs::write(&file, json).unwrap();
            CameraPath::load(&file).unwrap_err().to_string()
        };
        assert!(bad("{").contains("not a valid camera path"));
        assert!(bad(r#"{"version":2,"fov_deg":60,"keys":[]}"#).contains("version 2"));
        assert!(bad(r#"{"version":1,"fov_deg":0,"keys":[]}"#).contains("fov_deg"));
        assert!(bad(r#"{"version":1,"fov_deg":60,"keys":[]}"#).contains("no keys"));
        assert!(
            bad(r#"{"version":1,"fov_deg":60,"keys":[{"eye":[0,0,0],"target":[0,0,0]}]}"#)
                .contains("key 0: target equals eye")
        );
        assert!(
            bad(r#"{"version":1,"fov_deg":60,"keys":[{"eye":[0,0,0],"target":[1,0,0],"x":1}]}"#)
                .contains("unknown field")
        );
        // Saving an invalid path writes nothing.
        let other = dir.path().join("empty.json");
        assert!(CameraPath::new(60.0).save(&other).is_err());
        assert!(!other.exists());
    }
}
