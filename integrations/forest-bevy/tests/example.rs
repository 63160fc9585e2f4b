//! The plugin's defaults and its example as a person runs them: `ForestCamera::default()` is
//! the hybrid, and `SCREENSHOT=PATH cargo run --example forest -- FOREST` in a real window
//! (Xvfb, lavapipe) writes its screenshot of the forest and exits 0 as soon as it has.

mod common;
#[path = "../../../tests/x11/mod.rs"]
mod x11;

use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use forest_bevy::{ForestCamera, ForestMethod};

#[test]
fn the_default_camera_draws_the_hybrid() {
    assert_eq!(ForestCamera::default().method, ForestMethod::Hybrid);
    assert_eq!(ForestMethod::default(), ForestMethod::Hybrid);
    assert_eq!(ForestCamera::default().epsilon, 4.0);
}

/// The example's binary, which `cargo test` builds beside the test binaries
/// (`target/<profile>/examples/forest`).
fn example() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let profile = exe.parent().and_then(|deps| deps.parent()).unwrap();
    let path = profile.join("examples/forest");
    assert!(
        path.is_file(),
        "{} is not built (cargo test builds the examples)",
        path.display()
    );
    path
}

#[test]
fn the_example_saves_its_screenshot_and_exits() {
    let forest = common::assets().join("small.forest");
    let shot = common::out_dir().join("example-screenshot.png");
    let _ = std::fs::remove_file(&shot);
    let x = x11::Xvfb::start();
    let mut child = Command::new(example())
        .arg(&forest)
        .env("SCREENSHOT", &shot)
        .env("DISPLAY", &x.display)
        .env_remove("WAYLAND_DISPLAY")
        .stdout(Stdio::null())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let mut written = None;
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if written.is_none() && shot.is_file() {
            written = Some(Instant::now());
        }
        // Bounds on a hang, not timings: a frame of the small forest takes well under a
        // second on lavapipe, and the example exits on the frame after the file is written.
        let hung = written.is_some_and(|w| w.elapsed() > Duration::from_secs(60))
            || start.elapsed() > Duration::from_secs(900);
        if hung {
            let _ = child.kill();
            let _ = child.wait();
            panic!(
                "the example still ran {:?} after it started ({:?} after its screenshot)",
                start.elapsed(),
                written.map(|w| w.elapsed())
            );
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    assert!(status.success(), "the example exited with {status}");
    let img = image::open(&shot)
        .unwrap_or_else(|e| panic!("{}: {e}", shot.display()))
        .to_rgba8();
    // The forest in view: the frame is not one colour (sky alone, or a trunk filling it).
    let first = *img.get_pixel(0, 0);
    let other = img.pixels().filter(|p| **p != first).count();
    assert!(
        other > img.pixels().len() / 10,
        "{other} of {} pixels differ from the corner's: {}",
        img.pixels().len(),
        shot.display()
    );
}
