//! Outputs that would destroy inputs are refused before any work: an output may not be one of
//! the command's input files, lie inside an input folder (an atlas), or be a folder that holds
//! an input; and its extension must name the format that is written.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};

/// `path` made absolute with symbolic links resolved, for a path that may not exist yet (its
/// folder is resolved, the file name kept).
fn resolved(path: &Path) -> PathBuf {
    if let Ok(p) = std::fs::canonicalize(path) {
        return p;
    }
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let base = std::fs::canonicalize(parent).unwrap_or_else(|_| parent.to_path_buf());
    match path.file_name() {
        Some(name) => base.join(name),
        None => base,
    }
}

/// Refuse `output` (described as `what`) when it is, holds or lies inside one of `inputs`,
/// or lies inside any atlas ([`not_in_atlas`]): the check every command's outputs pass.
pub fn output(output: &Path, what: &str, inputs: &[PathBuf]) -> Result<()> {
    not_an_input(output, what, inputs)?;
    not_in_atlas(output, what)
}

/// Refuse `output` (described as `what`) when it is, holds or lies inside one of `inputs`.
pub fn not_an_input(output: &Path, what: &str, inputs: &[PathBuf]) -> Result<()> {
    apart(output, what, inputs, "input")
}

/// Refuse `output` when it is, holds or lies inside `other`, another output (`noun`).
pub fn apart_from(output: &Path, what: &str, other: &Path, noun: &str) -> Result<()> {
    apart(output, what, &[other.to_path_buf()], noun)
}

fn apart(output: &Path, what: &str, inputs: &[PathBuf], noun: &str) -> Result<()> {
    let out = resolved(output);
    for input in inputs {
        let inp = resolved(input);
        if out == inp {
            bail!(
                "{what} {} is the {noun} {}: refusing to overwrite it",
                output.display(),
                input.display()
            );
        }
        if out.starts_with(&inp) {
            bail!(
                "{what} {} lies inside the {noun} {}: refusing to write into it",
                output.display(),
                input.display()
            );
        }
        if inp.starts_with(&out) {
            bail!(
                "{what} {} would replace the folder holding the {noun} {}",
                output.display(),
                input.display()
            );
        }
    }
    Ok(())
}

/// Refuse an output whose extension does not name `format` (one of `extensions`, compared
/// without case).
pub fn extension(output: &Path, what: &str, format: &str, extensions: &[&str]) -> Result<()> {
    let ext = output
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    if !extensions.contains(&ext.as_str()) {
        bail!(
            "{what} {} is written as {format}: give it a .{} name",
            output.display(),
            extensions.join(" or .")
        );
    }
    Ok(())
}

/// Refuse `output` (a file or folder the command writes into) when it is an atlas folder or
/// lies inside one, whatever the command's inputs: an atlas is a folder holding
/// `manifest.json` and `nodes.bin`, and nothing but the bake writes there.
pub fn not_in_atlas(output: &Path, what: &str) -> Result<()> {
    let out = resolved(output);
    for dir in out.ancestors() {
        if dir.join(forest_format::atlas::MANIFEST_FILE).is_file()
            && dir.join(forest_format::atlas::NODES_FILE).is_file()
        {
            bail!(
                "{what} {} lies inside the atlas {}: refusing to write into it",
                output.display(),
                dir.display()
            );
        }
    }
    Ok(())
}

/// `path` when nothing exists there, else the first free `STEM-N.EXT` beside it (N = 1, 2,
/// …): a file the user already has is never written over.
pub fn unused(path: &Path) -> PathBuf {
    if !path.exists() {
        return path.to_path_buf();
    }
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ext = path
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    (1u64..)
        .map(|n| path.with_file_name(format!("{stem}-{n}{ext}")))
        .find(|p| !p.exists())
        .expect("some number is free")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_that_are_hold_or_lie_in_inputs_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let atlas = d.join("oak.atlas");
        std::fs::create_dir(&atlas).unwrap();
        std::fs::write(atlas.join("manifest.json"), "{}").unwrap();
        let forest = d.join("f.forest");
        std::fs::write(&forest, "x").unwrap();
        let inputs = [forest.clone(), atlas.clone()];
        let err = |p: &Path| not_an_input(p, "output", &inputs).unwrap_err().to_string();
        assert!(err(&forest).contains("is the input"));
        // The same file through another spelling.
        assert!(err(&d.join(".").join("f.forest")).contains("is the input"));
        assert!(err(&atlas.join("manifest.json")).contains("inside the input"));
        assert!(err(d).contains("holding the input"));
        assert!(not_an_input(&d.join("shot.png"), "output", &inputs).is_ok());
        assert!(extension(&d.join("x.jpg"), "image", "PNG", &["png"]).is_err());
        assert!(extension(&d.join("x.PNG"), "image", "PNG", &["png"]).is_ok());
    }

    #[test]
    fn unused_names_skip_existing_files() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("camera-path.json");
        assert_eq!(unused(&p), p);
        std::fs::write(&p, "{}").unwrap();
        std::fs::write(dir.path().join("camera-path-1.json"), "{}").unwrap();
        assert_eq!(unused(&p), dir.path().join("camera-path-2.json"));
    }

    #[test]
    fn atlas_folders_are_refused_as_outputs() {
        let dir = tempfile::tempdir().unwrap();
        let atlas = dir.path().join("oak.atlas");
        std::fs::create_dir(&atlas).unwrap();
        std::fs::write(atlas.join("manifest.json"), "{}").unwrap();
        std::fs::write(atlas.join("nodes.bin"), "").unwrap();
        assert!(not_in_atlas(&atlas, "frames").is_err());
        assert!(not_in_atlas(&atlas.join("manifest.json"), "--record").is_err());
        assert!(not_in_atlas(&atlas.join("x/y.png"), "output").is_err());
        assert!(not_in_atlas(&dir.path().join("frames"), "frames").is_ok());
    }
}
