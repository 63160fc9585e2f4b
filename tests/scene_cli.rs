//! End-to-end: `forest scene` and `forest compare`, the outputs every subcommand refuses to
//! write over its inputs, and what a run leaves behind.

use std::path::Path;

mod cli;

use cli::{bake_small, forest, ok, one_line_error as err};

#[test]
fn compare_reports_metrics_and_refuses_mismatched_images() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).display().to_string();
    let a = image::RgbaImage::from_fn(32, 32, |x, y| {
        image::Rgba([
            (x * 8) as u8,
            (y * 8) as u8,
            90,
            if x < 16 { 255 } else { 0 },
        ])
    });
    let mut b = a.clone();
    for y in 0..32 {
        b.put_pixel(20, y, image::Rgba([255, 255, 255, 255]));
    }
    a.save(p("a.png")).unwrap();
    b.save(p("b.png")).unwrap();
    let out = ok(&forest(&[
        "compare",
        &p("a.png"),
        &p("b.png"),
        "--json",
        "--flip-map",
        &p("map.png"),
    ]));
    let v: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    // Coverage: 16 columns vs 17 (column 20 added): IoU 16/17.
    assert!(
        (v["coverage_iou"].as_f64().unwrap() - 16.0 / 17.0).abs() < 1e-9,
        "{v}"
    );
    assert!(v["flip_mean"].as_f64().unwrap() > 0.0 && v["psnr"].as_f64().unwrap() < 100.0);
    assert!(d_exists(&p("map.png")));
    let same = ok(&forest(&["compare", &p("a.png"), &p("a.png"), "--json"]));
    let s: serde_json::Value = serde_json::from_str(same.trim()).unwrap();
    assert_eq!(s["flip_mean"], 0.0);
    image::RgbaImage::new(8, 8).save(p("small.png")).unwrap();
    let e = err(&forest(&["compare", &p("a.png"), &p("small.png")]));
    assert!(e.contains("sizes differ"), "{e}");
    let e = err(&forest(&["compare", &p("a.png"), &p("none.png")]));
    assert!(e.contains("none.png"), "{e}");
}

fn d_exists(p: &str) -> bool {
    Path::new(p).is_file()
}

/// Every byte of every file under `dir`, by path: what a refused command must leave as it was.
fn snapshot(dir: &Path) -> Vec<(std::path::PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push((p.clone(), std::fs::read(&p).unwrap()));
            }
        }
    }
    out.sort();
    out
}

#[test]
fn outputs_that_would_destroy_inputs_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let p = |n: &str| d.join(n).display().to_string();
    // A copy of a bundled model, so that its own files can be targeted.
    let m = d.join("model");
    std::fs::create_dir(&m).unwrap();
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/trees/bush");
    for f in std::fs::read_dir(&src).unwrap() {
        let f = f.unwrap().path();
        std::fs::copy(&f, m.join(f.file_name().unwrap())).unwrap();
    }
    let obj = m.join("bush.obj").display().to_string();
    bake_small("bush", &d.join("bush.atlas"), 32, 5);
    ok(&forest(&[
        "scene",
        "--model-sizes",
        "--trees",
        "20",
        "--species",
        &p("bush.atlas"),
        "-o",
        &p("f.forest"),
    ]));
    ok(&forest(&[
        "render",
        &p("f.forest"),
        "--view",
        "inside",
        "--size",
        "32x24",
        "-o",
        &p("a.png"),
    ]));
    std::fs::copy(d.join("a.png"), d.join("b.png")).unwrap();
    std::fs::write(
        d.join("walk.json"),
        r#"{"version":1,"fov_deg":60,"keys":[{"eye":[0,1.7,5],"target":[0,1,0]}]}"#,
    )
    .unwrap();
    let before = snapshot(d);
    let (f, a, b, n, x) = (
        p("f.forest"),
        p("a.png"),
        p("b.png"),
        p("n.atlas"),
        p("x.jpg"),
    );
    let atlas = p("bush.atlas");
    let sheet_in_output = format!("{n}/sheet.png");
    let texture = m.join("leaves_aspen.png").display().to_string();
    let inside = format!("{}/manifest.json", p("bush.atlas"));
    let walk = p("walk.json");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["render", &f, "--view", "inside", "-o", &f],
            "is the input",
        ),
        (
            vec!["render", &f, "--view", "inside", "-o", &inside],
            "inside the input",
        ),
        (
            vec!["render", &f, "--view", "inside", "-o", &x],
            ".png name",
        ),
        (vec!["compare", &a, &b, "--flip-map", &a], "is the input"),
        (
            vec!["scene", "--trees", "5", "--species", &atlas, "-o", &inside],
            "inside the input",
        ),
        (
            vec!["bake", &obj, "-o", &n, "--contact-sheet", &texture],
            "is the input",
        ),
        (
            vec!["bake", &obj, "-o", &n, "--depth-exr", &obj],
            "is the input",
        ),
        (
            vec!["bake", &obj, "-o", &n, "--contact-sheet", &sheet_in_output],
            "inside the output atlas",
        ),
        (vec!["bake", &obj, "-o", &n, "--depth-exr", &b], ".exr name"),
        (vec!["view", &f, "--record", &f], "is the input"),
        (
            vec!["view", &f, "--record", &walk, "--path", &walk],
            "is the input",
        ),
        (vec!["view", &f, "--record", &inside], "inside the atlas"),
        (vec!["view", &f, "--record", &a], "JSON"),
        (
            vec!["view", &f, "--screenshots", &atlas],
            "inside the atlas",
        ),
        (
            vec!["view", &f, "--path", &walk, "--frames", &atlas],
            "inside the atlas",
        ),
    ];
    for (args, why) in cases {
        let e = err(&forest(&args));
        assert!(e.contains(why), "{args:?}: {e}");
        assert!(snapshot(d) == before, "{args:?} changed a file");
    }
    // A scene `render` would refuse is refused by `scene`, and nothing is written.
    let e = err(&forest(&[
        "scene",
        "--model-sizes",
        "--trees",
        "20",
        "--species",
        &atlas,
        "--area-per-tree",
        "1e38",
        "-o",
        &p("far.forest"),
    ]));
    assert!(e.contains("may span"), "{e}");
    assert!(snapshot(d) == before);
    // A negative number is an option's value, refused for what it is.
    let e = err(&forest(&[
        "render",
        &f,
        "--view",
        "inside",
        "--epsilon",
        "-1",
        "-o",
        &p("z.png"),
    ]));
    assert!(e.contains("epsilon -1 must be positive"), "{e}");
    // Messages name their cause once.
    let e = err(&forest(&[
        "render",
        &p("none.forest"),
        "--view",
        "inside",
        "-o",
        &p("y.png"),
    ]));
    assert_eq!(e.matches("os error 2").count(), 1, "{e}");
    // No temporary files were left either (the snapshot holds every file there is).
    assert!(
        !before
            .iter()
            .any(|(f, _)| f.to_string_lossy().contains(".tmp-"))
    );
}

#[test]
fn an_interrupted_scene_leaves_no_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    bake_small("bush", &d.join("bush.atlas"), 32, 5);
    let atlas = d.join("bush.atlas").display().to_string();
    let out = d.join("big.forest").display().to_string();
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_forest"))
        .args([
            "scene",
            "--model-sizes",
            "--trees",
            "3000000",
            "--species",
            &atlas,
            "-o",
            &out,
        ])
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // Interrupt while the temporary file is being written (or, failing that, while the trees
    // are being placed).
    let start = std::time::Instant::now();
    let writing = || {
        std::fs::read_dir(d)
            .unwrap()
            .any(|e| e.unwrap().file_name().to_string_lossy().contains(".tmp-"))
    };
    while !writing() && start.elapsed().as_secs() < 60 && child.try_wait().unwrap().is_none() {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let status = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let code = child.wait().unwrap();
    let names: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(!names.iter().any(|n| n.contains(".tmp-")), "{names:?}");
    // Stopped before the rename: no forest either (130 = interrupted); a run that finished
    // first left a whole one.
    if code.code() == Some(130) {
        assert!(!names.contains(&"big.forest".to_string()), "{names:?}");
    } else {
        assert!(code.success(), "{code:?}");
    }
}

#[test]
fn scene_gives_trees_their_species_heights() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let p = |n: &str| d.join(n).display().to_string();
    bake_small("bush", &d.join("bush.atlas"), 32, 3);
    let top = forest_format::atlas::Atlas::load(&d.join("bush.atlas"))
        .unwrap()
        .manifest
        .model_top();
    // The bake records the model's top (the bundled bush is about 3 m tall).
    assert!((2.5..3.5).contains(&top), "{top}");
    let heights = |file: &str| -> Vec<f32> {
        let f = forest_format::forest::Forest::load(&d.join(file)).unwrap();
        f.instances.iter().map(|i| i.scale * top).collect()
    };
    let scene = |extra: &[&str], out: &str| {
        let mut a = vec!["scene", "--trees", "60", "--species"];
        let s = p("bush.atlas");
        let o = p(out);
        a.push(&s);
        a.extend_from_slice(extra);
        a.extend_from_slice(&["-o", &o]);
        forest(&a)
    };
    // Given heights, then the built-in table (bush 1–3 m), then the model's own size.
    let text = ok(&scene(&["--heights", "bush=2-2.5"], "given.json"));
    assert!(text.contains("bush: 2-2.5 m tall"), "{text}");
    assert!(
        heights("given.json")
            .iter()
            .all(|h| (1.999..=2.501).contains(h))
    );
    ok(&scene(&[], "table.json"));
    let table = heights("table.json");
    assert!(
        table.iter().all(|h| (0.999..=3.001).contains(h)),
        "{table:?}"
    );
    assert!(table.iter().any(|h| *h < 2.0) && table.iter().any(|h| *h > 2.0));
    ok(&scene(&["--model-sizes"], "model.json"));
    assert!(
        heights("model.json")
            .iter()
            .all(|h| (0.8 * top - 1e-3..=1.25 * top + 1e-3).contains(h))
    );
    // Bad heights: one line naming the cause, nothing written.
    for (args, says) in [
        (vec!["--heights", "oak=15-25"], "--heights names 'oak'"),
        (vec!["--heights", "bush=3-2"], "MIN <= MAX"),
        (vec!["--heights", "bush15-25"], "expected NAME=MIN-MAX"),
        (
            vec!["--heights", "bush=2-3", "--model-sizes"],
            "cannot be used with",
        ),
    ] {
        let out = scene(&args, "bad.json");
        let e = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(!out.status.success() && e.contains(says), "{args:?}: {e}");
        assert!(!d.join("bad.json").exists());
    }
}

#[test]
fn a_forest_on_hills_or_a_height_field_stands_on_it_and_bad_height_fields_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let p = |n: &str| d.join(n).display().to_string();
    bake_small("bush", &d.join("bush.atlas"), 32, 3);
    let atlas = p("bush.atlas");
    let scene = |terrain: &str, out: &str, extra: &[&str]| {
        let trees = if extra.contains(&"--trees") {
            &[][..]
        } else {
            &["--trees", "300"][..]
        };
        let mut args = vec!["scene", "--model-sizes"];
        args.extend_from_slice(trees);
        args.extend_from_slice(&[
            "--species",
            &atlas,
            "--area-per-tree",
            "20",
            "--terrain",
            terrain,
            "-o",
        ]);
        args.push(out);
        args.extend_from_slice(extra);
        forest(&args)
    };
    // Generated hills: every tree's base on the lowest drawn ground under its model's foot
    // (the foot scene prints); the named views render.
    let hills = p("hills.forest");
    let text = ok(&scene("hills", &hills, &["--relief", "40"]));
    assert!(text.contains("terrain:"), "{text}");
    let foot = forest_format::model::PreparedModel::load(&d.join("bush.atlas"))
        .unwrap()
        .expect("the bake stores the model")
        .footprint_radius();
    // The bake records the same foot in the manifest, which scene reads instead of the model.
    let manifest = forest_format::Atlas::load_manifest(&d.join("bush.atlas")).unwrap();
    assert_eq!(manifest.source.foot, Some(foot));
    assert!(
        foot > 0.0 && text.contains(&format!("bush: foot {foot:.3} m")),
        "{foot}: {text}"
    );
    let f = forest_format::forest::Forest::load(Path::new(&hills)).unwrap();
    let t = f.terrain.as_ref().expect("a terrain");
    let (lo, hi) = t.height_range();
    assert!(hi - lo > 10.0, "{lo}..{hi}");
    for i in &f.instances {
        let [x, y, z] = i.position;
        assert_eq!(y, t.lowest_under(x, z, foot * i.scale), "{i:?}");
        assert!(y <= t.height(x, z), "{i:?}");
    }
    let out = ok(&forest(&[
        "render",
        &hills,
        "-o",
        &p("h.png"),
        "--view",
        "inside",
        "--view",
        "hill",
        "--view",
        "birds-eye",
        "--size",
        "64x48",
        "--json",
    ]));
    assert_eq!(out.lines().count(), 3, "{out}");
    // A 16-bit height field: a ramp rising 0 to 30 m along x.
    let png = d.join("ramp.png");
    image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(64, 64, |x, _| {
        image::Luma([(x * 1040) as u16])
    })
    .save(&png)
    .unwrap();
    let ramp = p("ramp.forest");
    ok(&scene(
        &png.display().to_string(),
        &ramp,
        &["--relief", "30", "--terrain-spacing", "3"],
    ));
    let f = forest_format::forest::Forest::load(Path::new(&ramp)).unwrap();
    let t = f.terrain.as_ref().unwrap();
    assert_eq!(t.size, [64, 64]);
    for i in &f.instances {
        let [x, y, z] = i.position;
        // Planted at the foot's downhill edge, `foot · scale` towards −x.
        let want = (x - foot * i.scale - t.origin[0]) / 3.0 * 1040.0 / 65535.0 * 30.0;
        assert!((y - want).abs() < 1e-3, "{i:?}: {want}");
        assert!(y < t.height(x, z), "{i:?}");
    }
    // Bad height fields and options: one line naming the cause, nothing written.
    let eight = d.join("eight.png");
    image::GrayImage::from_pixel(8, 8, image::Luma([3]))
        .save(&eight)
        .unwrap();
    let junk = d.join("junk.exr");
    std::fs::write(&junk, b"not an exr").unwrap();
    let cases: Vec<(String, Vec<&str>, &str)> = vec![
        (eight.display().to_string(), vec![], "16-bit greyscale"),
        (junk.display().to_string(), vec![], "junk.exr"),
        (p("missing.png"), vec![], "missing.png"),
        (
            "flat".into(),
            vec!["--relief", "5"],
            "--relief need(s) a --terrain",
        ),
        (
            "flat".into(),
            vec!["--max-slope", "20", "--treeline", "0.5"],
            "--max-slope, --treeline need(s) a --terrain",
        ),
        ("hills".into(), vec!["--terrain-spacing", "0"], "spacing"),
        (
            png.display().to_string(),
            vec!["--trees", "3000", "--terrain-spacing", "3"],
            "does not lie on the terrain",
        ),
        (
            "mountains".into(),
            vec![],
            "give flat, hills, or a height field",
        ),
    ];
    for (terrain, extra, why) in cases {
        let out = p("bad.forest");
        let e = err(&scene(&terrain, &out, &extra));
        assert!(e.contains(why), "{terrain} {extra:?}: {e}");
        assert!(!Path::new(&out).exists(), "{terrain}: wrote a forest");
    }
    // The height field is an input: never an output.
    let e = err(&scene(
        &png.display().to_string(),
        &png.display().to_string(),
        &[],
    ));
    assert!(e.contains("input"), "{e}");
}

/// Without `XDG_RUNTIME_DIR` the binary makes a private one for the Vulkan loader in the
/// temporary folder, and removes it when the command ends, whether it succeeds or fails.
#[test]
fn the_private_runtime_folder_is_removed_at_exit() {
    let tmp = tempfile::tempdir().unwrap();
    let atlas = tmp.path().join("missing.atlas");
    for args in [
        vec!["info", atlas.to_str().unwrap()], // fails: no such atlas
        vec!["compare", "--help"],             // clap's own exit
    ] {
        let status = std::process::Command::new(env!("CARGO_BIN_EXE_forest"))
            .args(&args)
            .env_remove("XDG_RUNTIME_DIR")
            .env("TMPDIR", tmp.path())
            .output()
            .unwrap()
            .status;
        assert!(status.code().is_some(), "{args:?}: {status}");
        let left: Vec<_> = std::fs::read_dir(tmp.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .filter(|n| n.to_string_lossy().starts_with("forest-xdg-"))
            .collect();
        assert!(left.is_empty(), "{args:?} left {left:?}");
    }
}

/// `forest view` without a forest, run outside the repository, names the cause and writes
/// nothing: not into the working folder, and not into the source tree it was built from.
#[test]
fn the_demo_is_made_only_in_the_repositorys_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_forest"))
        .arg("view")
        .current_dir(dir.path())
        .output()
        .unwrap();
    let e = cli::one_line_error(&out);
    assert!(
        e.contains("assets/trees") && e.contains("working folder"),
        "{e}"
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}
