//! `forest view` used as a person would: under Xvfb with lavapipe, the test opens the window,
//! drives keyboard and mouse through XTEST (xdotool), takes screenshots with F12, and compares
//! them with a stored reference and with headless renders of the cameras they recorded (mean
//! FLIP). Needs `Xvfb` and `xdotool` (scripts/setup.sh installs them).

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use forest_format::camera_path::CameraPath;
use glam::Vec3;

mod cli;
mod x11;

use cli::{bake_small, forest, model, ok};
use x11::{Xvfb, need};

/// The viewer process and its stdout, line by line.
struct Viewer {
    child: Child,
    lines: mpsc::Receiver<String>,
    seen: Vec<String>,
}

impl Viewer {
    /// Wait for a stdout line containing `text`.
    fn wait_for(&mut self, text: &str, secs: u64) -> String {
        let end = Instant::now() + Duration::from_secs(secs);
        while let Some(left) = end.checked_duration_since(Instant::now()) {
            match self.lines.recv_timeout(left) {
                Ok(l) => {
                    self.seen.push(l.clone());
                    if l.contains(text) {
                        return l;
                    }
                }
                Err(_) => break,
            }
        }
        let _ = self.child.kill();
        let err = self.child.stderr.take().map(|mut e| {
            let mut s = String::new();
            std::io::Read::read_to_string(&mut e, &mut s).unwrap();
            s
        });
        panic!(
            "no {text:?} from the viewer within {secs} s; stdout {:?}, stderr {err:?}",
            self.seen
        );
    }
}

impl Drop for Viewer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn out_dir() -> PathBuf {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/test-output");
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn key_of(path: &Path) -> (Vec3, Vec3) {
    let p = CameraPath::load(path).unwrap();
    assert_eq!(p.keys.len(), 1, "{}", path.display());
    (
        Vec3::from_array(p.keys[0].eye),
        Vec3::from_array(p.keys[0].target),
    )
}

#[test]
fn walk_look_switch_and_screenshot_in_a_window() {
    need("xdotool");
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let last = scene_and_start_path(d);
    let shots = d.join("shots");
    std::fs::create_dir(&shots).unwrap();
    let x = Xvfb::start();
    let mut v = start_viewer(&x, d, &shots);
    let win = walk_look_and_switch(&x, &mut v);
    record_grow_and_close(&x, &mut v, d, &win);
    the_overdraw_legend_is_drawn(&shots);
    let (eye0, dir0) = the_start_is_the_paths_end(&shots, last);
    the_input_moved_the_walker(&shots, eye0, dir0);
    the_window_draws_what_the_headless_renderer_draws(d, &shots);
}

/// Two species baked, a forest of them, and a short path the window plays first (control
/// returns at its last key, returned).
fn scene_and_start_path(d: &Path) -> forest_format::camera_path::CameraKey {
    let p = |n: &str| d.join(n).display().to_string();
    for s in ["bush", "pine"] {
        bake_small(s, &d.join(format!("{s}.atlas")), 64, 5);
    }
    ok(&forest(&[
        "scene",
        "--model-sizes",
        "--trees",
        "300",
        "--area-per-tree",
        "20",
        "--species",
        &format!("{},{}", p("bush.atlas"), p("pine.atlas")),
        "--seed",
        "3",
        "-o",
        &p("f.forest"),
    ]));
    // A short path the window plays first; control returns at its last key.
    let mut path = CameraPath::new(60.0);
    for i in 0..3 {
        let z = 50.0 - 2.0 * i as f32;
        path.push(Vec3::new(0.0, 8.0, z), Vec3::new(-3.0, 0.0, z - 30.0));
    }
    path.save(&d.join("start.json")).unwrap();
    path.keys[2]
}

/// The viewer started in `x`'s display on the forest, playing the start path, saving
/// screenshots into `shots` and recording into walk.json; once its first frame is on screen.
fn start_viewer(x: &Xvfb, d: &Path, shots: &Path) -> Viewer {
    let p = |n: &str| d.join(n).display().to_string();
    let mut child = Command::new(env!("CARGO_BIN_EXE_forest"))
        .args([
            "view",
            &p("f.forest"),
            "--size",
            "320x240",
            // A coarse ε sizes a small stream, which the end of the test outgrows.
            "--epsilon",
            "32",
            "--path",
            &p("start.json"),
            "--screenshots",
            shots.to_str().unwrap(),
            "--record",
            &p("walk.json"),
            "--models",
            &format!("{},{}", model("bush"), model("pine")),
        ])
        .env("DISPLAY", &x.display)
        .env_remove("WAYLAND_DISPLAY")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the forest binary runs");
    let (tx, rx) = mpsc::channel();
    let stdout = child.stdout.take().unwrap();
    std::thread::spawn(move || {
        for l in BufReader::new(stdout).lines().map_while(Result::ok) {
            if tx.send(l).is_err() {
                break;
            }
        }
    });
    let mut v = Viewer {
        child,
        lines: rx,
        seen: Vec::new(),
    };
    let first = v.wait_for("first frame on screen", 240);
    assert!(first.contains("320x240"), "{first}");

    v
}

/// Walk, look and switch the method and debug views, with screenshots; the window's id.
fn walk_look_and_switch(x: &Xvfb, v: &mut Viewer) -> String {
    let win = x.xdotool(&["search", "--sync", "--name", "^forest view$"]);
    let win = win.lines().next().unwrap().to_string();
    // No window manager: give the window the keyboard focus by hand, as a WM would on click.
    x.xdotool(&["windowfocus", "--sync", &win]);
    x.xdotool(&["mousemove", "--window", &win, "160", "120"]);
    // H hides the HUD (so the mouse reaches the scene); F12 saves the view: the path's end.
    x.xdotool(&["key", "h"]);
    x.xdotool(&["key", "F12"]);
    v.wait_for("screenshot-000.png", 60);

    // Walk forward, look right with the right mouse button held, slow down with the wheel,
    // then switch to static impostors (key 2) and the levels debug view (V).
    x.xdotool(&["keydown", "w"]);
    std::thread::sleep(Duration::from_millis(1000));
    x.xdotool(&["keyup", "w"]);
    x.xdotool(&["mousedown", "3"]);
    for _ in 0..4 {
        x.xdotool(&["mousemove_relative", "--", "15", "0"]);
        std::thread::sleep(Duration::from_millis(50));
    }
    x.xdotool(&["mouseup", "3"]);
    x.xdotool(&["click", "5"]);
    x.xdotool(&["key", "2"]);
    x.xdotool(&["key", "v"]);
    x.xdotool(&["key", "F12"]);
    let saved = v.wait_for("screenshot-001.png", 60);
    assert!(saved.contains("(impostor, debug view levels)"), "{saved}");
    // V on through weights and wireframe to the overdraw view, which every method has: the
    // heat map with its legend (checked below).
    for _ in 0..3 {
        x.xdotool(&["key", "v"]);
    }
    x.xdotool(&["key", "F12"]);
    let saved = v.wait_for("screenshot-002.png", 60);
    assert!(saved.contains("(impostor, debug view overdraw)"), "{saved}");
    win
}

/// Record a path, grow the window past the stream's size, and close the viewer with Esc.
fn record_grow_and_close(x: &Xvfb, v: &mut Viewer, d: &Path, win: &str) {
    // R records a path while walking sideways; R again saves it.
    x.xdotool(&["key", "r"]);
    x.xdotool(&["keydown", "d"]);
    std::thread::sleep(Duration::from_millis(500));
    x.xdotool(&["keyup", "d"]);
    x.xdotool(&["key", "r"]);
    let saved = v.wait_for("keys to", 60);
    let recorded = CameraPath::load(&d.join("walk.json")).unwrap();
    assert!(recorded.keys.len() >= 2, "{saved}");
    let (a, b) = (
        recorded.keys[0].eye,
        recorded.keys[recorded.keys.len() - 1].eye,
    );
    assert!(
        Vec3::from_array(a).distance(Vec3::from_array(b)) > 0.1,
        "{a:?} -> {b:?}"
    );
    // A larger window and a smaller ε than the stream was sized for: it overflows, and the
    // viewer builds a larger stream.
    x.xdotool(&["windowsize", win, "640", "480"]);
    // (It grows at whichever ε first overflows, 16 to 2 depending on the frames drawn in
    // between; ε 2 at 640x480 fits lavapipe's 128 MiB storage-buffer limit, ε 1 would not.)
    x.xdotool(&["key", "1"]);
    for _ in 0..4 {
        x.xdotool(&["key", "bracketleft"]);
    }
    v.wait_for("stream resized for 640x480 at ε", 120);
    assert!(
        !v.seen.iter().any(|l| l.contains("cannot grow")),
        "{:?}",
        v.seen
    );
    x.xdotool(&["key", "Escape"]);
    let t = Instant::now();
    let status = loop {
        if let Some(s) = v.child.try_wait().unwrap() {
            break s;
        }
        assert!(
            t.elapsed() < Duration::from_secs(30),
            "Esc did not close the viewer"
        );
        std::thread::sleep(Duration::from_millis(100));
    };
    assert!(status.success(), "the viewer exited with {status}");
}

/// The overdraw screenshot shows the legend's swatches along the bottom edge, in the bands'
/// colours.
fn the_overdraw_legend_is_drawn(shots: &Path) {
    // The overdraw screenshot: the legend's swatches along the bottom edge, in the bands'
    // colours.
    let shot2 = image::open(shots.join("screenshot-002.png"))
        .unwrap()
        .to_rgba8();
    let side = forest_render::fragments::legend_side(320);
    for (b, c) in forest_render::fragments::OVERDRAW_COLOURS
        .iter()
        .enumerate()
    {
        let p = shot2.get_pixel(b as u32 * side + side / 2, 240 - 2 * side);
        let want = c.map(|v| (forest_format::shading::srgb_encode(v) * 255.0).round() as u8);
        assert!(
            (0..3).all(|k| p[k].abs_diff(want[k]) <= 1),
            "legend swatch {b}: {p:?}, want {want:?}"
        );
    }
}

/// The first screenshot is the path's last key, drawn as the stored reference shows it; its
/// eye and view direction.
fn the_start_is_the_paths_end(
    shots: &Path,
    last: forest_format::camera_path::CameraKey,
) -> (Vec3, Vec3) {
    // The first screenshot is the path's last key drawn by the default method (the hybrid: the
    // models are given), and looks like the stored reference.
    let (eye0, target0) = key_of(&shots.join("screenshot-000.json"));
    assert!(eye0.distance(Vec3::from_array(last.eye)) < 1e-4, "{eye0}");
    let dir0 = (target0 - eye0).normalize();
    let want = (Vec3::from_array(last.target) - Vec3::from_array(last.eye)).normalize();
    assert!(dir0.dot(want) > 0.9999, "{dir0} vs {want}");
    let shot0 = image::open(shots.join("screenshot-000.png"))
        .unwrap()
        .to_rgba8();
    assert_eq!(shot0.dimensions(), (320, 240));
    let reference = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/images/view-start.png");
    let Ok(stored) = image::open(&reference) else {
        shot0.save(&reference).unwrap();
        panic!(
            "no reference image: wrote {} (inspect it and commit it)",
            reference.display()
        );
    };
    let (mean, map) = forest_metrics::flip(&stored.to_rgba8(), &shot0).unwrap();
    println!("screenshot vs stored reference: mean FLIP {mean:.5}");
    if mean > 0.05 {
        shot0.save(out_dir().join("view-start-actual.png")).unwrap();
        map.save(out_dir().join("view-start-flip.png")).unwrap();
    }
    assert!(
        mean <= 0.05,
        "screenshot vs stored reference: mean FLIP {mean:.4} > 0.05 (see target/test-output/)"
    );

    (eye0, dir0)
}

/// The input moved the walker: forward along the view, turned right by the drag.
fn the_input_moved_the_walker(shots: &Path, eye0: Vec3, dir0: Vec3) {
    // The input moved the walker: forward along the view, turned right by the drag.
    let (eye1, target1) = key_of(&shots.join("screenshot-001.json"));
    let flat = Vec3::new(dir0.x, 0.0, dir0.z).normalize();
    let walked = (eye1 - eye0).dot(flat);
    // (A frame step is at most 0.1 s, so even a slow machine moves 0.5 m per slow frame.)
    assert!(walked > 0.2, "walked {walked} m forward ({eye0} -> {eye1})");
    let dir1 = (target1 - eye1).normalize();
    let turned = flat.cross(Vec3::new(dir1.x, 0.0, dir1.z).normalize()).y;
    assert!(turned < -0.02, "did not turn right: {dir0} -> {dir1}");
}

/// The window draws what the headless renderer draws for that camera, method and view.
fn the_window_draws_what_the_headless_renderer_draws(d: &Path, shots: &Path) {
    let p = |n: &str| d.join(n).display().to_string();
    // The window draws what the headless renderer draws for that camera, method and view.
    let frames = d.join("frames");
    std::fs::create_dir(&frames).unwrap();
    ok(&forest(&[
        "view",
        &p("f.forest"),
        "--path",
        shots.join("screenshot-001.json").to_str().unwrap(),
        "--frames",
        frames.to_str().unwrap(),
        "--size",
        "320x240",
        "--epsilon",
        "32",
        "--method",
        "impostor",
        "--debug-view",
        "levels",
    ]));
    let headless = image::open(frames.join("frame-00000.png"))
        .unwrap()
        .to_rgba8();
    let shot1 = image::open(shots.join("screenshot-001.png"))
        .unwrap()
        .to_rgba8();
    let (mean, map) = forest_metrics::flip(&headless, &shot1).unwrap();
    println!("window vs headless renderer: mean FLIP {mean:.5}");
    if mean > 0.01 {
        shot1.save(out_dir().join("view-moved-actual.png")).unwrap();
        headless
            .save(out_dir().join("view-moved-headless.png"))
            .unwrap();
        map.save(out_dir().join("view-moved-flip.png")).unwrap();
    }
    assert!(mean <= 0.01, "window vs headless: mean FLIP {mean:.4}");
}

#[test]
fn without_a_display_the_viewer_says_what_to_do() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("f.forest");
    bake_small("bush", &dir.path().join("bush.atlas"), 32, 3);
    ok(&forest(&[
        "scene",
        "--model-sizes",
        "--trees",
        "10",
        "--species",
        dir.path().join("bush.atlas").to_str().unwrap(),
        "-o",
        f.to_str().unwrap(),
    ]));
    let out = Command::new(env!("CARGO_BIN_EXE_forest"))
        .args(["view", f.to_str().unwrap()])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("--frames"), "{e}");
    assert_eq!(e.lines().filter(|l| l.contains("error")).count(), 1, "{e}");
    // Missing or broken files: one message naming the file, before any window opens.
    std::fs::write(dir.path().join("broken.forest"), b"not a forest").unwrap();
    for name in ["missing.forest", "broken.forest"] {
        let bad = dir.path().join(name);
        let out = Command::new(env!("CARGO_BIN_EXE_forest"))
            .args(["view", bad.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(!out.status.success());
        let e = String::from_utf8_lossy(&out.stderr);
        assert!(e.contains(name), "{e}");
    }
    // A missing screenshot folder is refused before any window opens.
    let out = Command::new(env!("CARGO_BIN_EXE_forest"))
        .args(["view", f.to_str().unwrap(), "--screenshots", "/no/such/dir"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("does not exist"));
}
