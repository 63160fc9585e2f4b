//! Fuzz targets of every loader that reads a user's files, in one place for the two drivers
//! that run them:
//!
//! - the coverage-guided fuzzer (`fuzz/afl`, cargo-afl with AFL++; `scripts/fuzz.sh`), which
//!   runs each target for millions of executions from the seed corpus in `corpus/TARGET/`;
//! - the smoke run in this crate's tests, which runs every seed and a few thousand seeded
//!   mutations of each in every `cargo test`, so no target can rot.
//!
//! Every target takes arbitrary bytes, must not panic, must return (no hang), and must not
//! allocate more than its [`Target::bound`] at once: [`alloc::Counting`] measures the peak
//! and, in the fuzzer, aborts the process (a crash AFL++ records) when a bound is crossed.
//!
//! Loaders that read several files (an OBJ with its material library and texture; an atlas
//! folder) take one input split into files at [`FILE_SEPARATOR`].
//!
//! ```
//! let target = forest_fuzz::targets::target("forest_json").expect("a target of that name");
//! // Errors are expected; a panic or an allocation past the bound would be the failure.
//! assert!(!(target.run)(b"{\"species\": 7}"));
//! ```

#![deny(missing_docs)]

pub mod alloc;
pub mod mutate;
pub mod targets;

pub use targets::{TARGETS, Target};

/// Separates the files of a multi-file input (an OBJ, its MTL and its texture; an atlas
/// folder's four files), in the order each target lists.
pub const FILE_SEPARATOR: &[u8] = b"\n%%FILE%%\n";

/// Split `data` at [`FILE_SEPARATOR`] into exactly `n` files (missing ones are empty, extra
/// separators stay in the last file).
pub fn split_files(data: &[u8], n: usize) -> Vec<&[u8]> {
    let mut out = Vec::with_capacity(n);
    let mut rest = data;
    while out.len() + 1 < n {
        match rest
            .windows(FILE_SEPARATOR.len())
            .position(|w| w == FILE_SEPARATOR)
        {
            Some(i) => {
                out.push(&rest[..i]);
                rest = &rest[i + FILE_SEPARATOR.len()..];
            }
            None => break,
        }
    }
    out.push(rest);
    out.resize(n, &[]);
    out
}

/// Join files into one input for [`split_files`].
pub fn join_files(files: &[&[u8]]) -> Vec<u8> {
    files.join(FILE_SEPARATOR)
}

/// The seed corpus folder of `target` in this repository.
pub fn corpus_dir(target: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("corpus")
        .join(target)
}

/// Inputs the fuzzer once found to crash or hang `target`, kept as regression cases (the
/// smoke run replays them; they need not load).
pub fn regressions_dir(target: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("regressions")
        .join(target)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn files_split_as_joined() {
        let files: [&[u8]; 3] = [b"a", b"", b"ccc"];
        assert_eq!(split_files(&join_files(&files), 3), files.to_vec());
        assert_eq!(split_files(b"only", 3), vec![&b"only"[..], b"", b""]);
        let joined = join_files(&[b"x", b"y", b"z"]);
        assert_eq!(
            split_files(&joined, 2)[1],
            &joined[1 + FILE_SEPARATOR.len()..]
        );
    }
}
