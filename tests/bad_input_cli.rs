//! Bad inputs that once gave silent results or misleading messages: each now fails with one
//! line naming the real cause, a non-zero exit, and every input byte for byte as it was.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

mod cli;

use cli::{bake_small, forest, model, ok, one_line_error};

/// Every file under `dir` and its bytes.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.insert(p.clone(), std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

/// The command fails with one line holding every one of `causes`, and leaves `dir` as it was.
fn refused(args: &[&str], dir: &Path, causes: &[&str]) -> String {
    let before = snapshot(dir);
    let e = one_line_error(&forest(args));
    for c in causes {
        assert!(e.contains(c), "{args:?}: expected {c:?} in: {e}");
    }
    assert!(snapshot(dir) == before, "{args:?} changed the folder");
    e
}

/// A copy of atlas `from` at `to` whose manifest has `edit` applied to its JSON.
fn edited_atlas(from: &Path, to: &Path, edit: impl Fn(&mut serde_json::Value)) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap().flatten() {
        std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
    let m = to.join("manifest.json");
    let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(&m).unwrap()).unwrap();
    edit(&mut v);
    std::fs::write(&m, serde_json::to_vec_pretty(&v).unwrap()).unwrap();
}

/// A small bush atlas `d/bush.atlas` and a forest of 3 of its trees, `d/f.json` (at the
/// model's own size with `model_sizes`); returns the atlas's and the forest's paths.
fn bush_forest(d: &Path, model_sizes: bool) -> (PathBuf, String) {
    let atlas = d.join("bush.atlas");
    bake_small("bush", &atlas, 32, 4);
    let forest_file = d.join("f.json").display().to_string();
    let atlas_arg = atlas.display().to_string();
    let mut args = vec![
        "scene",
        "--trees",
        "3",
        "--species",
        &atlas_arg,
        "-o",
        &forest_file,
    ];
    if model_sizes {
        args.push("--model-sizes");
    }
    ok(&forest(&args));
    (atlas, forest_file)
}

/// Borrowed views of owned arguments.
fn strs(args: &[String]) -> Vec<&str> {
    args.iter().map(String::as_str).collect()
}

#[test]
fn rebaking_keeps_the_users_files_and_outputs_in_files_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let atlas = d.join("bush.atlas");
    bake_small("bush", &atlas, 32, 4);
    std::fs::write(atlas.join("notes.txt"), "mine").unwrap();
    let small = [
        "--resolution",
        "32",
        "--directions",
        "4",
        "--spp",
        "1",
        "--no-hybrid-switch",
    ];
    let bush = model("bush");
    let mut args = vec!["bake", &bush, "-o", atlas.to_str().unwrap()];
    args.extend(small);
    refused(&args, d, &["notes.txt", "no bake writes", "move it out"]);
    // Without the user's file it bakes again over the old atlas.
    std::fs::remove_file(atlas.join("notes.txt")).unwrap();
    ok(&forest(&args));
    // An output inside a file: the file is named as a file, not as missing.
    std::fs::write(d.join("plain"), "x").unwrap();
    let inside = d.join("plain/x.atlas");
    let mut args = vec!["bake", &bush, "-o", inside.to_str().unwrap()];
    args.extend(small);
    refused(&args, d, &["plain is a file, not a folder"]);
}

#[test]
fn species_are_checked_alike_by_scene_info_and_render() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let p = |n: &str| d.join(n).display().to_string();
    let (good, forest_file) = bush_forest(d, false);
    // A hybrid-switch record out of range in each field it has, and a bounding sphere beyond
    // any model's coordinates.
    let cases: [(&str, serde_json::Value, &str); 7] = [
        ("crown_radii", serde_json::json!(-2.0), "crown_radii = -2"),
        ("tolerance", serde_json::json!(11.0), "tolerance = 11"),
        ("viewport", serde_json::json!([0, 0]), "viewport = [0, 0]"),
        ("fov_y_deg", serde_json::json!(7200.0), "fov_y_deg = 7200"),
        ("epsilon", serde_json::json!(0.0), "epsilon = 0"),
        ("cameras", serde_json::json!(0), "cameras = 0"),
        (
            "finest_quad_pixels",
            serde_json::json!(1e9),
            "finest_quad_pixels",
        ),
    ];
    for (i, (field, value, cause)) in cases.into_iter().enumerate() {
        let bad = d.join(format!("bad{i}.atlas"));
        edited_atlas(&good, &bad, |m| {
            m["hybrid_switch"] = serde_json::json!({
                "finest_quad_pixels": 1.5, "crown_radii": 6.0, "viewport": [320, 240],
                "fov_y_deg": 60.0, "epsilon": 16.0, "cameras": 4
            });
            m["hybrid_switch"][field] = value.clone();
        });
        let b = bad.display().to_string();
        refused(&["info", &b], d, &["hybrid_switch.", cause]);
        refused(
            &["scene", "--trees", "5", "--species", &b, "-o", &p("x.json")],
            d,
            &["hybrid_switch.", cause],
        );
    }
    let huge = d.join("huge.atlas");
    edited_atlas(&good, &huge, |m| {
        m["bounding_sphere"]["radius"] = serde_json::json!(1e38)
    });
    let h = huge.display().to_string();
    refused(&["info", &h], d, &["bounding sphere", "beyond"]);
    // scene loads every atlas whole, as render does: a broken colour file is refused there.
    let broken = d.join("broken.atlas");
    edited_atlas(&good, &broken, |_| {});
    let colour = std::fs::read_dir(&broken)
        .unwrap()
        .flatten()
        .find(|e| e.file_name().to_string_lossy().starts_with("colour."))
        .unwrap()
        .path();
    std::fs::write(&colour, b"not an image").unwrap();
    let b = broken.display().to_string();
    refused(
        &[
            "scene",
            "--trees",
            "5",
            "--model-sizes",
            "--species",
            &b,
            "-o",
            &p("x.json"),
        ],
        d,
        &["broken.atlas"],
    );
    // A colour mosaic cut to a quarter of its bytes (the JPEG decoder fills the rest with
    // grey and says nothing) is refused by info and render alike.
    let cut = d.join("cut.atlas");
    edited_atlas(&good, &cut, |_| {});
    let colour = cut.join(colour.file_name().unwrap());
    let bytes = std::fs::read(&colour).unwrap();
    std::fs::write(&colour, &bytes[..bytes.len() / 4]).unwrap();
    let name = colour.file_name().unwrap().to_string_lossy().into_owned();
    let c = cut.display().to_string();
    // Small bakes store their colour as JPEG by default.
    assert_eq!(name, "colour.jpg");
    refused(&["info", &c], d, &[&name, "JPEG cut short"]);
    let mut cut_forest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&forest_file).unwrap()).unwrap();
    cut_forest["species"] = serde_json::json!(["cut.atlas"]);
    std::fs::write(d.join("cut.json"), serde_json::to_vec(&cut_forest).unwrap()).unwrap();
    refused(
        &[
            "render",
            &p("cut.json"),
            "-o",
            &p("x.png"),
            "--size",
            "32x24",
        ],
        d,
        &["cut.atlas", &name],
    );
    // Instances scaled past the physical range, in a forest written by hand.
    let mut f: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&forest_file).unwrap()).unwrap();
    f["instances"][1]["scale"] = serde_json::json!(1e30);
    std::fs::write(d.join("big.json"), serde_json::to_vec(&f).unwrap()).unwrap();
    refused(
        &[
            "render",
            &p("big.json"),
            "-o",
            &p("x.png"),
            "--size",
            "32x24",
        ],
        d,
        &["instance 1", "scale 1e30", "outside"],
    );
    // A scale within range, but a tree as big as the forest's bound allows no more.
    f["instances"][1]["scale"] = serde_json::json!(9000.0);
    f["instances"][1]["position"] = serde_json::json!([9.99e6, 0.0, 0.0]);
    std::fs::write(d.join("far.json"), serde_json::to_vec(&f).unwrap()).unwrap();
    refused(
        &[
            "render",
            &p("far.json"),
            "-o",
            &p("x.png"),
            "--size",
            "32x24",
        ],
        d,
        &["instance 1", "beyond the ±1e7 m"],
    );
}

#[test]
fn models_must_be_their_atlases_own() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let p = |n: &str| d.join(n).display().to_string();
    let (_, forest_file) = bush_forest(d, true);
    let render = |models: &str, extra: &[&str]| {
        let mut a = vec![
            "render".to_string(),
            forest_file.clone(),
            "-o".into(),
            p("g.png"),
            "--size".into(),
            "32x24".into(),
            "--view".into(),
            "birds-eye".into(),
            "--method".into(),
            "geometry".into(),
            "--models".into(),
            models.to_string(),
        ];
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    let args = render(&model("aspen"), &[]);
    refused(
        &strs(&args),
        d,
        &[
            "aspen.obj",
            "not the file its atlas was baked from",
            "bush.obj",
            "--allow-other-models",
        ],
    );
    let args = render(&model("aspen"), &["--allow-other-models"]);
    let out = forest(&strs(&args));
    ok(&out);
    assert!(String::from_utf8_lossy(&out.stderr).contains("note: model"));
    let args = render(&model("bush"), &[]);
    ok(&forest(&strs(&args)));
}

#[test]
fn cameras_and_numbers_are_named_for_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let p = |n: &str| d.join(n).display().to_string();
    let (_, forest_file) = bush_forest(d, false);
    let render = |eye: &str| {
        vec![
            "render".to_string(),
            forest_file.clone(),
            "-o".into(),
            p("x.png"),
            "--size".into(),
            "32x24".into(),
            format!("--eye={eye}"),
            "--target".into(),
            "0,1,0".into(),
        ]
    };
    let a = render("1e38,2,3");
    refused(&strs(&a), d, &["eye", "beyond ±1e8 m"]);
    let a = render("nan,2,3");
    refused(&strs(&a), d, &["NaN is not a finite number"]);
    let a = render("1,2");
    refused(&strs(&a), d, &["expected three numbers", "got 2"]);
    let bush = model("bush");
    refused(
        &["bake", &bush, "-o", &p("n.atlas"), "--resolution", "-64"],
        d,
        &["'-64'", "--resolution"],
    );
    for t in ["-0.5", "11", "nan"] {
        refused(
            &["bake", &bush, "-o", &p("n.atlas"), "--switch-tolerance", t],
            d,
            &[&format!("'{t}'"), "--switch-tolerance", "0 to 10"],
        );
    }
    refused(
        &[
            "scene",
            "--seed",
            "-1",
            "--species",
            &p("bush.atlas"),
            "-o",
            &p("s.json"),
        ],
        d,
        &["'-1'", "--seed"],
    );
    for span in ["0", "65"] {
        let mut a = render("1,2,3");
        a.extend(["--far-span".to_string(), span.to_string()]);
        refused(
            &strs(&a),
            d,
            &[&format!("'{span}'"), "--far-span", "1..=64"],
        );
    }
    // Every numeric option takes a leading minus, so that its own parser names the value
    // and the option (not "unexpected argument").
    for (option, value) in [
        ("--far-span", "-1"),
        ("--sharpen-reach", "-2"),
        ("--sharpen", "-0.1"),
        ("--shadow-resolution", "-1"),
        ("--shadow-cascades", "-1"),
    ] {
        let mut a = render("1,2,3");
        a.extend(["--shadows", "on", option, value].map(String::from));
        let e = refused(&strs(&a), d, &[&format!("'{value}'"), option]);
        assert!(!e.contains("unexpected argument"), "{e}");
    }
    // Shadow options out of range.
    for (option, value, cause) in [
        (
            "--shadow-cascades",
            "5",
            "shadow cascades 5: expected 1 to 4",
        ),
        ("--shadow-resolution", "16", "shadow resolution 16"),
        ("--shadow-distance", "-5", "shadow distance -5"),
        ("--shadow-epsilon", "0", "shadow epsilon 0"),
    ] {
        for shadows in ["on", "off"] {
            let mut a = render("1,2,3");
            a.extend(["--shadows", shadows, option, value].map(String::from));
            refused(&strs(&a), d, &[cause]);
        }
    }
    // Options whose values may start with a hyphen reach their own check.
    let f = &forest_file;
    for (option, value, cause) in [
        ("--near", "-3", "a distance of 0 metres or more"),
        ("--lod-distances", "-3,4,5", "must be positive"),
    ] {
        refused(
            &[
                "render",
                f,
                "-o",
                &p("x.png"),
                "--view",
                "inside",
                "--method",
                "lods",
                "--models",
                &bush,
                option,
                value,
            ],
            d,
            &[cause],
        );
    }
}

/// The bench refuses results that would land inside its inputs, and a frame count of 0,
/// before any work.
#[test]
fn bench_results_stay_out_of_their_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    bush_forest(d, false);
    let atlas = d.join("bush.atlas").display().to_string();
    let inside = d.join("bush.atlas").join("results").display().to_string();
    refused(
        &["bench", "storage", "--species", &atlas, "--out", &inside],
        d,
        &["--out results folder", "bush.atlas"],
    );
    refused(
        &["bench", "table1", "--species", &atlas, "--frames", "0"],
        d,
        &["--frames 0"],
    );
}

/// Fragment counters too large for the device are refused before any frame is drawn.
#[test]
fn counters_too_large_are_refused_before_drawing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (_, forest_file) = bush_forest(d, false);
    let png = d.join("x.png").display().to_string();
    refused(
        &[
            "render",
            &forest_file,
            "-o",
            &png,
            "--view",
            "birds-eye",
            "--size",
            "8192x8192",
            "--debug-view",
            "overdraw",
        ],
        d,
        &["fragment counts of a 8192×8192 target", "smaller size"],
    );
}

/// A model whose only texture is transparent at every texel bakes nothing: the bake says so,
/// names the material, and writes no atlas. With one solid material beside it, it bakes.
#[test]
fn a_model_that_draws_nothing_is_refused_before_baking() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    image::RgbaImage::from_pixel(4, 4, image::Rgba([60, 140, 40, 0]))
        .save(d.join("clear.png"))
        .unwrap();
    std::fs::write(
        d.join("m.mtl"),
        "newmtl leaf\nmap_Kd clear.png\nnewmtl bark\nKd 0.3 0.2 0.1\n",
    )
    .unwrap();
    let quad = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
                vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl leaf\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
    std::fs::write(d.join("clear.obj"), quad).unwrap();
    let small = ["--resolution", "32", "--directions", "4", "--spp", "1"];
    let bake = |obj: &str, atlas: &Path| {
        let mut args = vec!["bake".to_string(), d.join(obj).display().to_string()];
        args.extend(["-o".into(), atlas.display().to_string()]);
        args.extend(small.map(String::from));
        args.push("--no-hybrid-switch".into());
        args
    };
    let atlas = d.join("clear.atlas");
    refused(
        &strs(&bake("clear.obj", &atlas)),
        d,
        &["clear.obj", "\"leaf\"", "transparent", "draws nothing"],
    );
    assert!(!atlas.exists(), "a refused bake left {}", atlas.display());
    // A solid triangle beside the clear quad: the model draws something, and bakes.
    let mixed = format!("{quad}v 0 0 1\nusemtl bark\nf 1 2 5\n");
    std::fs::write(d.join("mixed.obj"), mixed).unwrap();
    ok(&forest(&strs(&bake("mixed.obj", &d.join("mixed.atlas")))));
}

/// An option that needs another names the one missing, on the same line as clap's message.
#[test]
fn a_missing_companion_option_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let png = d.join("x.png").display().to_string();
    let frames = d.display().to_string();
    for (args, missing) in [
        (
            vec!["render", "f.json", "-o", &png, "--eye", "1,2,3"],
            "--target",
        ),
        (vec!["view", "f.json", "--frames", &frames], "--path"),
        (vec!["render", "f.json"], "--output"),
    ] {
        refused(&args, d, &["required arguments were not provided", missing]);
    }
}

/// No command writes into an atlas, its inputs or not: an atlas holds what the bake wrote.
#[test]
fn no_output_lands_inside_an_atlas() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let p = |n: &str| d.join(n).display().to_string();
    let (good, forest_file) = bush_forest(d, false);
    // An atlas that none of the commands reads.
    let other = d.join("other.atlas");
    edited_atlas(&good, &other, |_| {});
    let inside = |n: &str| other.join(n).display().to_string();
    for n in ["a.png", "b.png"] {
        image::RgbaImage::from_pixel(8, 8, image::Rgba([9, 9, 9, 255]))
            .save(d.join(n))
            .unwrap();
    }
    let walk = d.join("walk.json");
    let mut path = forest_format::camera_path::CameraPath::new(60.0);
    path.push(
        glam::Vec3::new(0.0, 1.7, 20.0),
        glam::Vec3::new(0.0, 2.0, 0.0),
    );
    path.save(&walk).unwrap();
    let bush = model("bush");
    let atlas = good.display().to_string();
    let cases: [(Vec<String>, &str); 6] = [
        (
            vec![
                "render".into(),
                forest_file.clone(),
                "-o".into(),
                inside("x.png"),
                "--view".into(),
                "hill".into(),
            ],
            "output",
        ),
        (
            vec![
                "scene".into(),
                "--trees".into(),
                "2".into(),
                "--species".into(),
                atlas.clone(),
                "-o".into(),
                inside("f.json"),
            ],
            "output",
        ),
        (
            vec![
                "compare".into(),
                p("a.png"),
                p("b.png"),
                "--flip-map".into(),
                inside("m.png"),
            ],
            "FLIP map",
        ),
        (
            vec!["bake".into(), bush, "-o".into(), inside("inner.atlas")],
            "output atlas's folder",
        ),
        (
            vec![
                "bench".into(),
                "storage".into(),
                "--species".into(),
                atlas,
                "--out".into(),
                inside("results"),
            ],
            "--out results folder",
        ),
        (
            vec![
                "view".into(),
                forest_file,
                "--path".into(),
                walk.display().to_string(),
                "--frames".into(),
                p(""),
                "--record".into(),
                inside("r.json"),
            ],
            "--record",
        ),
    ];
    for (args, what) in cases {
        refused(
            &strs(&args),
            d,
            &[what, "lies inside the atlas", "other.atlas"],
        );
    }
}

/// A bad wind is named with its bound, by every command that draws, before any work.
#[test]
fn winds_are_named_with_their_bound() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (atlas, forest_file) = bush_forest(d, false);
    let png = d.join("x.png").display().to_string();
    let atlas = atlas.display().to_string();
    let results = d.join("results").display().to_string();
    let cases: [(&[&str], &[&str]); 9] = [
        (
            &["--wind", "90,-1"],
            &["--wind 90,-1", "expected 0 to 50 m/s"],
        ),
        (
            &["--wind", "90,1e9"],
            &["wind speed 1000000000", "0 to 50 m/s"],
        ),
        (
            &["--wind", "90,nan"],
            &["--wind", "\"nan\" is not a finite speed"],
        ),
        (
            &["--wind", "abc,5"],
            &["--wind", "not a finite number of degrees"],
        ),
        (
            &["--wind", "inf,5"],
            &["--wind", "not a finite number of degrees"],
        ),
        (&["--wind", "90"], &["--wind", "expected TOWARDS,SPEED"]),
        (
            &["--wind-gustiness", "-0.5"],
            &["--wind-gustiness -0.5", "0 (steady) to 1"],
        ),
        (
            &["--wind-time", "1e9"],
            &["--wind-time 1000000000", "±1e5 s"],
        ),
        (&["--wind-time", "nan"], &["--wind-time NaN", "±1e5 s"]),
    ];
    for (wind, causes) in cases {
        let mut a = vec!["render", &forest_file, "-o", &png, "--size", "32x24"];
        a.extend(wind);
        refused(&a, d, causes);
        let mut a = vec!["bench", "table1", "--species", &atlas, "--frames", "1"];
        a.extend(wind);
        a.extend(["--out", &results]);
        refused(&a, d, causes);
    }
    // --animate's length and rate, the clock it runs past, and a count asked of it.
    for (extra, cause) in [
        (
            &["--animate", "0"][..],
            "--animate 0: expected more than 0 and at most 60",
        ),
        (&["--animate", "1e9"][..], "--animate 1000000000"),
        (&["--animate", "nan"][..], "--animate NaN"),
        (
            &["--animate", "1", "--frame-rate", "0"][..],
            "--frame-rate 0: expected 1 to 60",
        ),
        (
            &["--animate", "2", "--wind", "0,5", "--wind-time", "99999.5"][..],
            "the last frame's wind time",
        ),
        (&["--animate", "1", "--fragments"][..], "count fragments"),
    ] {
        let mut a = vec![
            "render",
            &forest_file,
            "-o",
            &png,
            "--size",
            "32x24",
            "--view",
            "inside",
        ];
        a.extend(extra);
        refused(&a, d, &[cause]);
    }
    let walk = d.join("walk.json");
    std::fs::write(
        &walk,
        r#"{"version":1,"fov_deg":60,"keys":[{"eye":[0,2,20],"target":[0,2,0]},{"eye":[0,2,20],"target":[0,2,0]}]}"#,
    )
    .unwrap();
    let frames = d.join("frames");
    std::fs::create_dir(&frames).unwrap();
    let view = |extra: &[&str]| cli::view_frames_args(&forest_file, &walk, &frames, extra);
    for (extra, cause) in [
        (&["--wind", "0,51"][..], "expected 0 to 50 m/s"),
        (
            &["--frame-rate", "0"][..],
            "--frame-rate 0: expected 1 to 1000",
        ),
        (&["--frame-rate", "nan"][..], "--frame-rate NaN"),
    ] {
        refused(&strs(&view(extra)), d, &[cause]);
    }
    // A path running past the wind's clock: refused before its first frame.
    refused(
        &strs(&view(&[
            "--wind",
            "0,5",
            "--wind-time",
            "99999.5",
            "--frame-rate",
            "1",
        ])),
        d,
        &[
            "--wind-time 99999.5 with 2 keys",
            "the last key's wind time",
        ],
    );
}

#[test]
fn seasons_and_colour_variations_are_named_with_their_bound() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (atlas, forest_file) = bush_forest(d, false);
    let png = d.join("x.png").display().to_string();
    let atlas_arg = atlas.display().to_string();
    let results = d.join("results").display().to_string();
    for (season, cause) in [
        ("1.5", "season 1.5 is outside 0 (spring) to 1 (late autumn)"),
        ("-0.1", "season -0.1 is outside"),
        ("nan", "season NaN is outside"),
        ("winter", "neither a number from 0 to 1 nor one of spring"),
    ] {
        let a = [
            "render",
            &forest_file,
            "-o",
            &png,
            "--size",
            "32x24",
            "--season",
            season,
        ];
        refused(&a, d, &["--season", cause]);
        let a = [
            "bench",
            "table1",
            "--species",
            &atlas_arg,
            "--frames",
            "1",
            "--season",
            season,
            "--out",
            &results,
        ];
        refused(&a, d, &["--season", cause]);
    }
    let out = d.join("g.forest").display().to_string();
    for (extra, cause) in [
        (
            &["--variation", "4"][..],
            "--variation 4: expected 0 (none) to 3",
        ),
        (&["--variation", "nan"][..], "--variation NaN"),
        (&["--variation", "-1"][..], "--variation -1"),
        (
            &["--evergreen", "oak"][..],
            "--evergreen oak: no species of that name (the species are bush)",
        ),
    ] {
        let mut a = vec!["scene", "--trees", "3", "--species", &atlas_arg, "-o", &out];
        a.extend(extra);
        refused(&a, d, &[cause]);
    }
    // A forest file's colouring is checked as render loads it.
    let text = std::fs::read_to_string(&forest_file).unwrap();
    for (edit, cause) in [
        (
            r#""amount": 9.0"#,
            "colour variation amount 9 is outside 0 to 3",
        ),
        (r#""hue_deg": -2.0"#, "species 0's colour: hue_deg is -2"),
    ] {
        let key = edit.split(':').next().unwrap();
        let bad = text
            .lines()
            .map(|l| {
                if l.trim_start().starts_with(key) {
                    format!("{edit},")
                } else {
                    l.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n");
        assert_ne!(bad, text, "{key} is in the scene's JSON");
        let path = d.join("bad.json");
        std::fs::write(&path, bad).unwrap();
        let p = path.display().to_string();
        refused(&["render", &p, "-o", &png, "--size", "32x24"], d, &[cause]);
    }
}
