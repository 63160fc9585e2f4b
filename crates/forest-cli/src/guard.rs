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
}
