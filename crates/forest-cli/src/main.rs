//! `forest`: the command-line front end of the quad-stream forest renderer.

use std::process::ExitCode;

use clap::Parser;

mod bake;

/// GPU forest rendering with dynamic quad streams.
#[derive(Parser)]
#[command(name = "forest", version, about, long_about = None)]
enum Cli {
    /// Bake a tree model (OBJ + MTL + textures) into a quad-stream atlas.
    Bake(bake::BakeArgs),
    /// Check an atlas and print its summary.
    Info(bake::InfoArgs),
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => e.exit(), // --help, --version
        Err(e) => {
            // One line: clap's message without its usage block and hint.
            let text = e.to_string();
            let first = text.lines().next().unwrap_or("invalid arguments");
            eprintln!("forest: {first} (see forest --help)");
            return ExitCode::from(2);
        }
    };
    let result = match cli {
        Cli::Bake(args) => bake::run(&args),
        Cli::Info(args) => bake::info(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("forest: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
