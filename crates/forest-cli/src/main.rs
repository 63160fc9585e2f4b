//! `forest`: the command-line front end of the quad-stream forest renderer.

use std::process::ExitCode;

use clap::Parser;

mod animation;
mod bake;
mod bench;
mod compare;
mod demo;
mod guard;
mod progress;
mod render;
mod render_args;
mod scene;
mod view;
mod window;

/// DejaVu Sans (assets/fonts/, with its licence): the charts' and the viewer HUD's one font,
/// embedded so text renders the same everywhere.
pub(crate) const FONT: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

/// How the front ends store colour layers on the GPU: `FOREST_COLOUR_FORMAT=bc7|rgba8`
/// overrides the library's automatic choice (BC7 on GPUs, RGBA8 on CPU rasterisers). The
/// library itself reads no environment: this is the command's policy.
pub(crate) fn colour_format() -> forest_render::ColourFormat {
    match std::env::var("FOREST_COLOUR_FORMAT").as_deref() {
        Ok("bc7") => forest_render::ColourFormat::Bc7,
        Ok("rgba8") => forest_render::ColourFormat::Rgba8,
        _ => forest_render::ColourFormat::Auto,
    }
}

/// The headless GPU context of the sub-commands, with wgpu's environment variables
/// (`WGPU_BACKEND`, ...) honoured: the command's policy, not the library's.
pub(crate) fn gpu_context() -> Result<forest_render::GpuContext, forest_render::RenderError> {
    forest_render::GpuContext::headless_with(
        wgpu::InstanceDescriptor::new_without_display_handle_from_env(),
    )
}

/// GPU forest rendering with dynamic quad streams.
#[derive(Parser)]
#[command(
    name = "forest",
    version,
    about,
    long_about = None,
    after_help = "Your own tree in three commands:\n  forest bake my-tree.glb -o my-tree.atlas\n  forest scene --trees 5000 --species my-tree.atlas -o my.forest --terrain hills\n  forest view my.forest --models my-tree.glb\n\nEach subcommand's --help lists its options with examples."
)]
enum Cli {
    /// Bake a tree model (OBJ + MTL + textures, or glTF 2.0) into a quad-stream atlas.
    ///
    /// Baking again into an existing atlas folder replaces it whole; a folder holding any
    /// file a bake does not write is refused, so nothing of yours in it is lost.
    #[command(
        after_help = "Examples:\n  forest bake assets/trees/oak/oak.obj -o oak.atlas\n  forest bake tree.glb -o tree.atlas --resolution 256 --contact-sheet tree.png --json"
    )]
    Bake(bake::BakeArgs),
    /// Check an atlas and print its summary.
    #[command(after_help = "Example:\n  forest info oak.atlas --json")]
    Info(bake::InfoArgs),
    /// Generate a forest of clumped trees with presorted orders.
    #[command(
        after_help = "Examples:\n  forest scene --trees 100000 --species oak.atlas,pine.atlas -o f.forest --terrain hills\n  forest scene --trees 200 --species oak.atlas --model-sizes -o small.json"
    )]
    Scene(scene::SceneArgs),
    /// Render views of a forest to PNG, headless.
    #[command(
        after_help = "Examples:\n  forest render f.forest -o shot.png --view inside --view birds-eye --time 8\n  forest render f.forest -o ref.png --view inside --method reference --models oak.obj,pine.obj --supersample 4"
    )]
    Render(render::RenderArgs),
    /// Run benchmark suites: CSV, charts (PNG + SVG) and, for `all`, REPORT.md.
    #[command(
        after_help = "Examples:\n  forest bench table1 --species oak.atlas,pine.atlas\n  forest bench all --species oak.atlas,pine.atlas --models oak.obj,pine.obj --quick --out results"
    )]
    Bench(bench::BenchArgs),
    /// Accuracy of an image against a reference: mean FLIP, SSIM, PSNR, coverage IoU.
    ///
    /// Colour is compared as stored (renders over a transparent background are
    /// premultiplied), except under alpha 0, where it is taken as black in both images: no
    /// compositing shows it, and straight-alpha images leave anything there.
    #[command(after_help = "Example:\n  forest compare ref.png shot.png --flip-map diff.png")]
    Compare(compare::CompareArgs),
    /// Walkthrough viewer (a window), or a camera path rendered headless to numbered PNGs.
    #[command(
        after_help = "Examples:\n  forest view                       (the bundled demo forest)\n  forest view f.forest --models oak.obj,pine.obj --method hybrid\n  forest view f.forest --path walk.json --frames out/frames"
    )]
    View(view::ViewArgs),
}

/// The command line, every option that takes a value accepting a leading minus: a negative
/// number (`--far-span -1`) reaches the option's own parser and check, which name the bound,
/// instead of clap's "unexpected argument '-1'".
fn command() -> clap::Command {
    fn negatives(cmd: clap::Command) -> clap::Command {
        cmd.mut_args(|a| {
            if !a.is_positional() && a.get_action().takes_values() {
                a.allow_negative_numbers(true)
            } else {
                a
            }
        })
        .mut_subcommands(negatives)
    }
    negatives(<Cli as clap::CommandFactory>::command())
}

fn main() -> ExitCode {
    let parsed = command()
        .try_get_matches()
        .and_then(|m| <Cli as clap::FromArgMatches>::from_arg_matches(&m));
    let cli = match parsed {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => e.exit(), // --help, --version
        Err(e) => {
            // One line: clap's first paragraph (its message, and the arguments it names on the
            // lines below it), without the usage block and hint.
            let text = e.to_string();
            let first: Vec<&str> = text
                .lines()
                .map(str::trim)
                .take_while(|l| !l.is_empty())
                .collect();
            let first = if first.is_empty() {
                "invalid arguments".to_string()
            } else {
                first.join(" ")
            };
            eprintln!("forest: {first} (see forest --help)");
            return ExitCode::from(2);
        }
    };
    // Vulkan loaders print a warning without it; give them a private folder, removed again
    // when the command ends.
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        let dir = std::env::temp_dir().join(format!("forest-xdg-{}", std::process::id()));
        if std::fs::create_dir_all(&dir).is_ok() {
            // SAFETY: in main before any other thread exists (the signal handler's is next).
            unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
            let _ = RUNTIME_DIR.set(dir);
        }
    }
    // Stopped by SIGINT or SIGTERM: remove the temporary files being written, then exit as
    // the shell expects (128 + SIGINT).
    let _ = ctrlc::set_handler(|| {
        forest_format::atomic::remove_pending();
        remove_runtime_dir();
        eprintln!("forest: interrupted; temporary files removed");
        std::process::exit(130);
    });
    let result = match cli {
        Cli::Bake(args) => bake::run(&args),
        Cli::Info(args) => bake::info(&args),
        Cli::Scene(args) => scene::run(&args),
        Cli::Render(args) => render::run(&args),
        Cli::Bench(args) => bench::run(&args),
        Cli::View(args) => view::run(&args),
        Cli::Compare(args) => compare::run(&args),
    };
    remove_runtime_dir();
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("forest: error: {}", message(&e));
            ExitCode::FAILURE
        }
    }
}

/// The private `XDG_RUNTIME_DIR` this process made for the Vulkan loader, if it made one.
static RUNTIME_DIR: std::sync::OnceLock<std::path::PathBuf> = std::sync::OnceLock::new();

/// Remove [`RUNTIME_DIR`] and what the loader left in it.
fn remove_runtime_dir() {
    if let Some(dir) = RUNTIME_DIR.get() {
        let _ = std::fs::remove_dir_all(dir);
    }
}

/// An error and its causes on one line, each cause once: a cause whose text the message
/// already holds (an I/O error wrapped with its path) is not repeated.
fn message(e: &anyhow::Error) -> String {
    let mut text = e.to_string();
    for cause in e.chain().skip(1) {
        let c = cause.to_string();
        if !text.contains(&c) {
            text.push_str(": ");
            text.push_str(&c);
        }
    }
    text
}

#[cfg(test)]
mod tests {
    #[test]
    fn causes_are_named_once() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "no such file");
        let wrapped = forest_format::FormatError::Io {
            path: "f.forest".into(),
            source: io,
        };
        let e = anyhow::Error::from(wrapped).context("loading the scene");
        assert_eq!(
            super::message(&e),
            "loading the scene: f.forest: no such file"
        );
    }
}
