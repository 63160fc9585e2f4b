//! The one way this project writes files: into a temporary sibling, then renamed over the
//! destination, so that a reader never sees a half-written file and an error (or an
//! interrupted write) leaves the destination as it was.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::error::FormatError;

/// Temporary files and folders being written now: what [`remove_pending`] deletes when the
/// process is interrupted.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Mark `tmp` (a file or folder) as being written until [`done`].
pub fn pending(tmp: &Path) {
    PENDING
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .push(tmp.to_path_buf());
}

/// `tmp` was renamed into place or removed.
pub fn done(tmp: &Path) {
    PENDING
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .retain(|p| p != tmp);
}

/// Remove every temporary file or folder still being written: for an interrupt handler
/// (SIGINT, SIGTERM), so that a stopped command leaves no litter.
pub fn remove_pending() {
    let pending = std::mem::take(&mut *PENDING.lock().unwrap_or_else(|e| e.into_inner()));
    for p in pending {
        let _ = std::fs::remove_file(&p);
        let _ = std::fs::remove_dir_all(&p);
    }
}

/// The temporary sibling of `path` a writer fills before the rename: `.NAME.tmp-PID` in the
/// same folder (so the rename stays on one file system).
pub fn tmp_name(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.tmp-{}", std::process::id()))
}

/// Write `path` through its temporary sibling: `write` fills the temporary path (any error
/// type with a message), which is then renamed over `path`; on any error it is removed and
/// `path` is untouched.
pub fn write_with<E: std::fmt::Display>(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), FormatError> {
    if path.file_name().is_none() {
        return Err(FormatError::invalid(path, "not a file name"));
    }
    let tmp = tmp_name(path);
    pending(&tmp);
    let result = write(&tmp)
        .map_err(|e| FormatError::invalid(path, e.to_string()))
        .and_then(|()| std::fs::rename(&tmp, path).map_err(|e| FormatError::io(path, e)));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    done(&tmp);
    result
}

/// Write `bytes` to `path` atomically (synced before the rename).
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), FormatError> {
    write_with(path, |tmp| {
        let mut f = std::fs::File::create(tmp)?;
        f.write_all(bytes)?;
        f.sync_all()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_write_leaves_the_destination_and_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.txt");
        write_bytes(&p, b"first").unwrap();
        let err = write_with(&p, |tmp| {
            std::fs::write(tmp, b"half")?;
            Err::<(), std::io::Error>(std::io::Error::other("disk full"))
        })
        .unwrap_err();
        assert!(err.to_string().contains("disk full"), "{err}");
        assert_eq!(std::fs::read(&p).unwrap(), b"first");
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            1,
            "no temporary left"
        );
        write_bytes(&p, b"second").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"second");
    }
}
