//! Helpers shared by the CLI tests.
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

/// Run the `forest` binary.
pub fn forest(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_forest"))
        .args(args)
        .output()
        .expect("the forest binary runs")
}

/// The arguments of `forest view FOREST --path PATH --frames FRAMES`, then `extra`.
pub fn view_frames_args(forest: &str, path: &Path, frames: &Path, extra: &[&str]) -> Vec<String> {
    let mut a: Vec<String> = ["view", forest, "--path"]
        .map(String::from)
        .into_iter()
        .collect();
    a.push(path.display().to_string());
    a.push("--frames".into());
    a.push(frames.display().to_string());
    a.extend(extra.iter().map(|s| s.to_string()));
    a
}

/// Run `forest view FOREST --path PATH --frames FRAMES`, then `extra`.
pub fn view_frames(forest_file: &str, path: &Path, frames: &Path, extra: &[&str]) -> Output {
    let a = view_frames_args(forest_file, path, frames, extra);
    forest(&a.iter().map(String::as_str).collect::<Vec<_>>())
}

/// Path of a bundled model.
pub fn model(s: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(format!("../../assets/trees/{s}/{s}.obj"))
        .display()
        .to_string()
}

/// The stdout of a run that must succeed (its stderr is the failure message).
pub fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Bake bundled model `species` into `atlas`, small enough for tests: `resolution` px,
/// `directions` directions, 1 sample per pixel.
pub fn bake_small(species: &str, atlas: &Path, resolution: u32, directions: u32) {
    ok(&forest(&[
        "bake",
        &model(species),
        "-o",
        atlas.to_str().expect("a UTF-8 path"),
        "--resolution",
        &resolution.to_string(),
        "--directions",
        &directions.to_string(),
        "--spp",
        "1",
        // The hybrid's switch is measured by the bake's own test; these atlases keep the
        // default, which saves each test about 10 s of lavapipe.
        "--no-hybrid-switch",
    ]));
}

/// The stderr of a run that must fail, after checking that it did and that it said one line
/// (beside the Vulkan loader's complaints about `XDG_RUNTIME_DIR`, which are not ours).
pub fn one_line_error(out: &Output) -> String {
    assert!(
        !out.status.success(),
        "succeeded: {}",
        String::from_utf8_lossy(&out.stdout)
    );
    let e = String::from_utf8_lossy(&out.stderr).into_owned();
    let lines: Vec<&str> = e
        .lines()
        .filter(|l| !l.contains("XDG_RUNTIME_DIR"))
        .collect();
    assert_eq!(lines.len(), 1, "one line: {e}");
    e
}
