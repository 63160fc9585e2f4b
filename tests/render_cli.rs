//! End-to-end: `forest bake` → `forest scene` → `forest render`, and their bad inputs.

mod cli;

use cli::{bake_small, forest, model, ok, one_line_error as err};

#[test]
fn bake_scene_render_end_to_end() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    bake_scene_and_render_named_views(d);
    a_json_forest_renders(d);
    the_hybrid_draws_stored_and_obj_models_alike(d);
    no_method_draws_the_hybrid(d);
    an_atlas_without_its_model(d);
    fragment_counts_and_the_overdraw_view(d);
    view_plays_a_path_back(d);
    wind_moves_rendered_and_viewed_frames(d);
    bad_inputs_are_refused(d);
}

/// Bake two species, make a forest of them, and render two named views of it.
fn bake_scene_and_render_named_views(d: &std::path::Path) {
    let p = |n: &str| d.join(n).display().to_string();
    for s in ["bush", "aspen"] {
        bake_small(s, &d.join(format!("{s}.atlas")), 64, 5);
    }
    let species = format!("{},{}", p("bush.atlas"), p("aspen.atlas"));
    let text = ok(&forest(&[
        "scene",
        "--model-sizes",
        "--trees",
        "200",
        "--species",
        &species,
        "--area-per-tree",
        "15",
        "-o",
        &p("f.forest"),
    ]));
    assert!(text.contains("200 trees of 2 species"), "{text}");
    let out = ok(&forest(&[
        "render",
        &p("f.forest"),
        "-o",
        &p("shot.png"),
        "--view",
        "inside",
        "--view",
        "birds-eye",
        "--size",
        "96x72",
        "--json",
    ]));
    let lines: Vec<serde_json::Value> = out
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 2);
    for (v, name) in lines.iter().zip(["inside", "birds-eye"]) {
        assert_eq!(v["view"], name);
        assert!(v["visible_trees"].as_u64().unwrap() > 0, "{v}");
        assert!(v["quads"].as_u64().unwrap() > 0, "{v}");
        let img = image::open(d.join(format!("shot-{name}.png"))).unwrap();
        assert_eq!((img.width(), img.height()), (96, 72));
    }
}

/// A JSON forest written by `forest scene` renders the same way.
fn a_json_forest_renders(d: &std::path::Path) {
    let p = |n: &str| d.join(n).display().to_string();
    let species = format!("{},{}", p("bush.atlas"), p("aspen.atlas"));
    ok(&forest(&[
        "scene",
        "--model-sizes",
        "--trees",
        "20",
        "--species",
        &species,
        "-o",
        &p("small.json"),
    ]));
    ok(&forest(&[
        "render",
        &p("small.json"),
        "-o",
        &p("small.png"),
        "--eye",
        "0,2,30",
        "--target",
        "0,2,0",
        "--size",
        "64x48",
    ]));
    assert!(d.join("small.png").is_file());
}

/// The hybrid: near trees as geometry (a fixed switch distance), the rest as quads; drawn
/// from the models the bake stored in the atlases, and from the OBJ files, alike.
fn the_hybrid_draws_stored_and_obj_models_alike(d: &std::path::Path) {
    let p = |n: &str| d.join(n).display().to_string();
    let hybrid = |out: &str, models: &[&str]| {
        let mut a = vec![
            "render",
            &p("small.json"),
            "-o",
            out,
            "--eye",
            "0,2,30",
            "--target",
            "0,2,0",
            "--size",
            "64x48",
            "--method",
            "hybrid",
            "--near",
            "1000",
            "--json",
        ]
        .into_iter()
        .map(String::from)
        .collect::<Vec<_>>();
        a.extend(models.iter().map(|s| s.to_string()));
        forest(&a.iter().map(String::as_str).collect::<Vec<_>>())
    };
    let objs = format!("{},{}", model("bush"), model("aspen"));
    let text = ok(&hybrid(&p("hybrid.png"), &[]));
    ok(&hybrid(&p("hybrid-obj.png"), &["--models", &objs]));
    let v: serde_json::Value = serde_json::from_str(text.lines().next().unwrap()).unwrap();
    assert_eq!(v["method"], "hybrid");
    assert!(v["geometry_trees"].as_u64().unwrap() > 0, "{v}");
    assert_eq!(v["quads"], 0, "every tree nearer than 1 km: {v}");
    assert!(v.get("fragments").is_none(), "counted only when asked: {v}");
    let stored = image::open(d.join("hybrid.png")).unwrap().to_rgba8();
    let from_obj = image::open(d.join("hybrid-obj.png")).unwrap().to_rgba8();
    assert_eq!(stored, from_obj, "the stored models are the OBJs prepared");
}

/// Without --method: the hybrid at its defaults, the same image as asked for by name.
fn no_method_draws_the_hybrid(d: &std::path::Path) {
    let p = |n: &str| d.join(n).display().to_string();
    let small = p("small.json");
    let view = |out: &str, method: &[&str]| {
        let mut a = vec![
            "render", &small, "-o", out, "--eye", "0,1.5,6", "--target", "0,1,0", "--size",
            "64x48", "--json",
        ];
        a.extend(method);
        forest(&a)
    };
    let text = ok(&view(&p("default.png"), &[]));
    ok(&view(&p("named.png"), &["--method", "hybrid"]));
    let v: serde_json::Value = serde_json::from_str(text.lines().next().unwrap()).unwrap();
    assert_eq!(v["method"], "hybrid", "{v}");
    let default = image::open(d.join("default.png")).unwrap().to_rgba8();
    let named = image::open(d.join("named.png")).unwrap().to_rgba8();
    assert_eq!(default, named, "no --method draws the hybrid");
    ok(&view(&p("quads.png"), &["--method", "quads"]));
    let quads = image::open(d.join("quads.png")).unwrap().to_rgba8();
    assert_ne!(default, quads, "the near trees are drawn as their models");
}

/// Without model.bin (an atlas baked with --no-model), the message says what to do.
fn an_atlas_without_its_model(d: &std::path::Path) {
    let bare = d.join("bare");
    std::fs::create_dir_all(bare.join("bush.atlas")).unwrap();
    for e in std::fs::read_dir(d.join("bush.atlas")).unwrap() {
        let e = e.unwrap();
        if e.file_name() != "model.bin" {
            std::fs::copy(e.path(), bare.join("bush.atlas").join(e.file_name())).unwrap();
        }
    }
    ok(&forest(&[
        "scene",
        "--model-sizes",
        "--trees",
        "5",
        "--species",
        &bare.join("bush.atlas").display().to_string(),
        "-o",
        &bare.join("bare.json").display().to_string(),
    ]));
    // `forest render` of the bare forest's bird's-eye view into x.png, with `extra`.
    let render_bare = |extra: &[&str]| {
        let (forest_file, png) = (bare.join("bare.json"), bare.join("x.png"));
        let (forest_file, png) = (forest_file.display().to_string(), png.display().to_string());
        let mut a = vec!["render", &forest_file, "-o", &png, "--view", "birds-eye"];
        a.extend(extra);
        forest(&a)
    };
    let e = err(&render_bare(&["--method", "lods"]));
    assert!(
        e.contains("bush.atlas") && e.contains("model.bin") && e.contains("--models"),
        "{e}"
    );
    assert!(!bare.join("x.png").exists());
    // Left to choose, render draws the quad stream there, and says why.
    let out = render_bare(&["--json"]);
    let text = ok(&out);
    let note = String::from_utf8_lossy(&out.stderr);
    assert!(
        note.contains("quad stream") && note.contains("bush.atlas") && note.contains("model.bin"),
        "{note}"
    );
    let v: serde_json::Value = serde_json::from_str(text.lines().next().unwrap()).unwrap();
    assert!(v["quads"].as_u64().unwrap() > 0, "{v}");
    assert!(bare.join("x.png").is_file());
}

/// The overdraw view's legend is along the bottom of the image at `path`: its band-0 swatch
/// black, its band-8 swatch white.
fn assert_overdraw_legend(path: &dyn AsRef<std::path::Path>) {
    let img = image::open(path).unwrap().to_rgba8();
    let (w, h) = img.dimensions();
    let side = forest_render::fragments::legend_side(w);
    let p = path.as_ref().display();
    assert_eq!(
        img.get_pixel(side / 2, h - 2 * side).0,
        [0, 0, 0, 255],
        "{p}"
    );
    assert_eq!(
        img.get_pixel(8 * side + side / 2, h - 2 * side).0,
        [255; 4],
        "{p}"
    );
}

/// Exact fragment counts and the overdraw view, for a quad method and a geometry one.
fn fragment_counts_and_the_overdraw_view(d: &std::path::Path) {
    let p = |n: &str| d.join(n).display().to_string();
    for method in ["quads", "lods"] {
        let out = p(&format!("overdraw-{method}.png"));
        let text = ok(&forest(&[
            "render",
            &p("small.json"),
            "-o",
            &out,
            "--eye",
            "0,2,30",
            "--target",
            "0,2,0",
            "--size",
            "64x48",
            "--method",
            method,
            "--debug-view",
            "overdraw",
            "--json",
            "--models",
            &format!("{},{}", model("bush"), model("aspen")),
        ]));
        let v: serde_json::Value = serde_json::from_str(text.lines().next().unwrap()).unwrap();
        let f = &v["fragments"];
        assert!(f["covered_pixels"].as_u64().unwrap() > 0, "{v}");
        let mean = f["per_covered_mean"].as_f64().unwrap();
        assert!(
            mean >= 1.0 && f["quad_lanes_per_covered"].as_f64().unwrap() >= mean,
            "{v}"
        );
        assert!(v["work"]["draws"].as_u64().unwrap() > 0, "{v}");
        assert_overdraw_legend(&out);
    }
    let e = err(&forest(&[
        "render",
        &p("small.json"),
        "-o",
        &p("x.png"),
        "--view",
        "inside",
        "--debug-view",
        "overdraw",
        "--supersample",
        "2",
    ]));
    assert!(e.contains("without --supersample"), "{e}");
    let e = err(&forest(&[
        "render",
        &p("small.json"),
        "-o",
        &p("x.png"),
        "--view",
        "inside",
        "--method",
        "hybrid",
        "--near=-3",
    ]));
    assert!(e.contains("auto or a distance"), "{e}");
}

/// `forest view` plays a camera path back headless, one PNG per key, with any method.
fn view_plays_a_path_back(d: &std::path::Path) {
    let p = |n: &str| d.join(n).display().to_string();
    let walk = d.join("walk.json");
    let mut path = forest_format::camera_path::CameraPath::new(60.0);
    for i in 0..3 {
        let x = i as f32;
        path.push(glam::Vec3::new(x, 1.7, 20.0), glam::Vec3::new(x, 2.0, 0.0));
    }
    path.save(&walk).unwrap();
    let frames = d.join("frames");
    std::fs::create_dir(&frames).unwrap();
    // `forest view` of the forest along the walk into the frames folder, with `extra`.
    let forest_file = p("f.forest");
    let view_frames = |extra: &[&str]| cli::view_frames(&forest_file, &walk, &frames, extra);
    let models = format!("{},{}", model("bush"), model("aspen"));
    for method in ["quads", "lods"] {
        let text = ok(&view_frames(&[
            "--size", "64x48", "--method", method, "--models", &models,
        ]));
        assert!(text.contains(&format!("3 frames of {method}")), "{text}");
        for i in 0..3 {
            let img = image::open(frames.join(format!("frame-{i:05}.png"))).unwrap();
            assert_eq!((img.width(), img.height()), (64, 48));
        }
    }
    // The overdraw heat map is drawn into headless frames, legend and all.
    let text = ok(&view_frames(&[
        "--size",
        "64x48",
        "--debug-view",
        "overdraw",
    ]));
    assert!(text.contains("3 frames of"), "{text}");
    for i in 0..3 {
        assert_overdraw_legend(&frames.join(format!("frame-{i:05}.png")));
    }
    // A frames folder that is a file, or that is missing, is named as such.
    let file = d.join("frames.txt");
    std::fs::write(&file, "mine").unwrap();
    let into = |f: &std::path::Path| {
        err(&forest(&[
            "view",
            &forest_file,
            "--path",
            walk.to_str().unwrap(),
            "--frames",
            f.to_str().unwrap(),
        ]))
    };
    let e = into(&file);
    assert!(e.contains("frames.txt is a file, not a folder"), "{e}");
    assert_eq!(std::fs::read(&file).unwrap(), b"mine");
    let e = into(&d.join("no-such-folder"));
    assert!(e.contains("does not exist: create it first"), "{e}");
    std::fs::write(&walk, "{\"version\":1,\"fov_deg\":60,\"keys\":[]}").unwrap();
    let e = err(&view_frames(&[]));
    assert!(e.contains("no keys"), "{e}");
}

/// `--wind` moves what `render` draws (a calm one draws the same bytes as none), and
/// `view --frames` animates it: a still camera's frames change from key to key in wind only.
fn wind_moves_rendered_and_viewed_frames(d: &std::path::Path) {
    let p = |n: &str| d.join(n).display().to_string();
    let forest_file = p("f.forest");
    let shot = |name: &str, wind: &[&str]| {
        let out = p(name);
        let mut a = vec![
            "render",
            &forest_file,
            "-o",
            &out,
            "--eye",
            "0,3,25",
            "--target",
            "0,4,0",
            "--size",
            "64x48",
            "--method",
            "geometry",
        ];
        a.extend(wind);
        ok(&forest(&a));
        std::fs::read(&out).unwrap()
    };
    let still = shot("still.png", &[]);
    assert_eq!(
        shot("calm.png", &["--wind", "120,0", "--wind-time", "3"]),
        still
    );
    let windy = shot("windy.png", &["--wind", "120,15", "--wind-time", "3"]);
    assert_ne!(windy, still, "a 15 m/s wind moved nothing");
    let later = shot("later.png", &["--wind", "120,15", "--wind-time", "3.5"]);
    assert_ne!(
        later, windy,
        "half a second later the wind drew the same image"
    );
    // A still camera along a path: the frames change with the wind's clock only.
    let walk = d.join("still.json");
    let mut path = forest_format::camera_path::CameraPath::new(60.0);
    for _ in 0..3 {
        path.push(
            glam::Vec3::new(0.0, 3.0, 25.0),
            glam::Vec3::new(0.0, 4.0, 0.0),
        );
    }
    path.save(&walk).unwrap();
    let frames = d.join("wind-frames");
    std::fs::create_dir(&frames).unwrap();
    let play = |wind: &[&str]| {
        let mut a = vec!["--size", "64x48"];
        a.extend(wind);
        ok(&cli::view_frames(&forest_file, &walk, &frames, &a));
        (0..3)
            .map(|i| std::fs::read(frames.join(format!("frame-{i:05}.png"))).unwrap())
            .collect::<Vec<_>>()
    };
    let calm = play(&[]);
    assert!(calm.windows(2).all(|w| w[0] == w[1]), "calm frames differ");
    let windy = play(&["--wind", "45,12", "--frame-rate", "10"]);
    assert!(
        windy.windows(2).all(|w| w[0] != w[1]),
        "wind frames stand still"
    );
}

/// Bad inputs: one line, non-zero exit, nothing written.
fn bad_inputs_are_refused(d: &std::path::Path) {
    let p = |n: &str| d.join(n).display().to_string();
    let e = err(&forest(&[
        "render",
        &p("none.forest"),
        "-o",
        &p("x.png"),
        "--view",
        "inside",
    ]));
    assert!(e.contains("none.forest"), "{e}");
    let e = err(&forest(&[
        "render",
        &p("f.forest"),
        "-o",
        &p("x.png"),
        "--eye",
        "1,2,3",
        "--target",
        "1,2,3",
    ]));
    assert!(e.contains("target equals eye"), "{e}");
    let e = err(&forest(&[
        "render",
        &p("f.forest"),
        "-o",
        &p("no/dir/x.png"),
        "--view",
        "inside",
    ]));
    assert!(e.contains("does not exist"), "{e}");
    let e = err(&forest(&[
        "render",
        &p("f.forest"),
        "-o",
        &p("x.png"),
        "--view",
        "inside",
        "--size",
        "0x10",
    ]));
    assert!(e.contains("size"), "{e}");
    assert!(!d.join("x.png").exists());
    for (flag, value) in [
        ("--haze", "0"),
        ("--haze", "-3"),
        ("--haze", "fog"),
        ("--haze-height", "inf"),
    ] {
        let e = err(&forest(&[
            "render",
            &p("f.forest"),
            "-o",
            &p("x.png"),
            "--view",
            "inside",
            flag,
            value,
        ]));
        assert!(
            e.contains(flag) && e.contains("expected off or a distance in metres"),
            "{e}"
        );
        assert!(!d.join("x.png").exists());
    }
    std::fs::write(d.join("broken.forest"), b"FRST\x01\x00\x00\x00").unwrap();
    let e = err(&forest(&[
        "render",
        &p("broken.forest"),
        "-o",
        &p("x.png"),
        "--view",
        "inside",
    ]));
    assert!(e.contains("truncated"), "{e}");
    let e = err(&forest(&[
        "scene",
        "--trees",
        "10",
        "--species",
        &p("missing.atlas"),
        "-o",
        &p("g.forest"),
    ]));
    assert!(e.contains("missing.atlas"), "{e}");
    assert!(!d.join("g.forest").exists());
}
