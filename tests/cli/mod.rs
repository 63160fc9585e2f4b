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

/// Path of a bundled model.
pub fn model(s: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(format!("../../assets/trees/{s}/{s}.obj"))
        .display()
        .to_string()
}
