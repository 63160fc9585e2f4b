//! End-to-end tests of `forest bake` and `forest info`: figures, outputs, and every bad input
//! giving one clear error line, a non-zero exit and nothing written.

use std::path::{Path, PathBuf};

mod cli;

use cli::{forest, model, ok};

fn bush() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets/trees/bush/bush.obj")
        .display()
        .to_string()
}

const SMALL: [&str; 6] = ["--resolution", "64", "--directions", "4", "--spp", "2"];

/// Run a bake that must fail; returns stderr after checking the exit code, that stderr is one
/// line, and that nothing was written to the output folder.
fn fails(model: &str, extra: &[&str], dir: &Path) -> String {
    let out_path = dir.join("out.atlas");
    let mut args = vec!["bake", model, "-o", out_path.to_str().unwrap()];
    // The small settings, unless the case sets that option itself.
    for pair in SMALL.chunks(2) {
        if !extra.contains(&pair[0]) {
            args.extend_from_slice(pair);
        }
    }
    args.extend_from_slice(extra);
    let before: Vec<PathBuf> = listing(dir);
    let out = forest(&args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "{args:?} succeeded");
    assert_eq!(stderr.trim_end().lines().count(), 1, "one line: {stderr}");
    assert!(!out_path.exists(), "{args:?} wrote {}", out_path.display());
    assert_eq!(listing(dir), before, "{args:?} left files behind");
    stderr
}

fn listing(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    v.sort();
    v
}

#[test]
fn bake_writes_an_atlas_a_contact_sheet_and_json_figures() {
    let dir = tempfile::tempdir().unwrap();
    let atlas = dir.path().join("bush.atlas");
    let sheet = dir.path().join("sheet.png");
    let exr = dir.path().join("depth.exr");
    let mut args = vec![
        "bake",
        &bush(),
        "-o",
        atlas.to_str().unwrap(),
        "--json",
        "--contact-sheet",
        sheet.to_str().unwrap(),
        "--depth-exr",
        exr.to_str().unwrap(),
    ]
    .into_iter()
    .map(String::from)
    .collect::<Vec<_>>();
    args.extend(SMALL.iter().map(|s| s.to_string()));
    let out = forest(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let line = String::from_utf8(out.stdout).unwrap();
    assert_eq!(line.lines().count(), 1);
    let v: serde_json::Value = serde_json::from_str(&line).unwrap();
    for key in [
        "triangles",
        "seconds",
        "disk_bytes",
        "gpu_bytes",
        "levels",
        "nodes_per_level",
    ] {
        assert!(v.get(key).is_some(), "missing {key} in {line}");
    }
    assert_eq!(v["levels"], 5);
    assert_eq!(v["nodes_per_level"].as_array().unwrap().len(), 5);
    assert_eq!(
        v["nodes_per_level"][0], 18,
        "every one of the 18 layers ((4 + 5 below) directions x 2 slabs) has a root"
    );
    let on_disk: u64 = std::fs::read_dir(&atlas)
        .unwrap()
        .map(|e| e.unwrap().metadata().unwrap().len())
        .sum();
    assert_eq!(v["disk_bytes"].as_u64().unwrap(), on_disk);
    // The hybrid's switch, measured on the GPU and recorded in the manifest: a crossover
    // inside the ladder of distances (or at its ends), with the pixels that follow from it.
    let switch = &v["hybrid_switch"];
    let radii = switch["crown_radii"].as_f64().unwrap();
    let pixels = switch["finest_quad_pixels"].as_f64().unwrap();
    assert!((1.25..=6.0).contains(&radii), "{switch}");
    // 400×300 at 60° (focal 259.8 px), 5 levels: finest quads 2R/16.
    assert!(
        (pixels - 2.0 * 259.8076 / (16.0 * radii)).abs() < 1e-3,
        "{switch}"
    );
    // The rungs the bisection measured: 3 to 5 of the 9 distances, nearest first.
    let ladder = v["hybrid_switch_ladder"].as_array().unwrap();
    assert!((3..=5).contains(&ladder.len()), "{v}");
    let radii: Vec<f64> = ladder
        .iter()
        .map(|r| r["crown_radii"].as_f64().unwrap())
        .collect();
    assert!(radii.windows(2).all(|w| w[0] < w[1]), "{v}");
    assert!(
        ladder
            .iter()
            .all(|r| r["flip_geometry"].as_f64().unwrap() > 0.0
                && r["flip_quads"].as_f64().unwrap() > 0.0
                && r["flip_lods"]
                    .as_array()
                    .is_some_and(|l| l.len() == 2 && l.iter().all(|x| x.as_f64().unwrap() > 0.0))),
        "{v}"
    );
    // Measured at the default tolerance, which the record keeps.
    assert_eq!(switch["tolerance"].as_f64(), Some(0.0), "{switch}");
    let recorded = forest_format::Atlas::load(&atlas)
        .unwrap()
        .manifest
        .hybrid_switch
        .unwrap();
    assert!((f64::from(recorded.finest_quad_pixels) - pixels).abs() < 1e-6);
    let img = image::open(&sheet).unwrap();
    assert!(img.width() > 64 && img.height() > 64);
    assert!(exr.is_file());

    let info = forest(&["info", atlas.to_str().unwrap(), "--json"]);
    assert!(info.status.success());
    let v2: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    assert_eq!(v2["node_count"], v["node_count"]);
    assert_eq!(v2["gpu_bytes"], v["gpu_bytes"]);
    assert_eq!(v2["hybrid_switch"], v["hybrid_switch"]);
    // Every file but the manifest, with its bytes on disk; the channels named.
    let files = v2["files"].as_object().unwrap();
    let manifest = std::fs::metadata(atlas.join("manifest.json"))
        .unwrap()
        .len();
    // The prepared model (model.bin) among them, with its triangles.
    assert_eq!(files.len(), 6, "{files:?}");
    let lods = v2["model_lod_triangles"].as_array().unwrap();
    assert_eq!(lods[0].as_u64(), v["triangles"].as_u64(), "{v2}");
    assert_eq!(
        files.values().map(|b| b.as_u64().unwrap()).sum::<u64>() + manifest,
        on_disk
    );
    for name in ["surface.png", "opacity.png", "model.bin"] {
        let bytes = std::fs::metadata(atlas.join(name)).unwrap().len();
        assert_eq!(files[name].as_u64(), Some(bytes), "{name}");
    }
    let channels = v2["channels"].as_str().unwrap();
    assert!(
        channels.contains("sky visibility") && channels.contains("opacity volume of 32³"),
        "{channels}"
    );
    let text = forest(&["info", atlas.to_str().unwrap()]);
    assert!(
        String::from_utf8_lossy(&text.stdout).contains("hybrid switch: finest quads"),
        "{}",
        String::from_utf8_lossy(&text.stdout)
    );
}

#[test]
fn bad_parameters_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let b = bush();
    let cases: [(&[&str], &str); 7] = [
        (&["--resolution", "100"], "resolution = 100"),
        (
            &["--resolution", "64", "--min-quad", "64"],
            "smaller than the resolution",
        ),
        (&["--min-quad", "3"], "min-quad = 3"),
        (&["--directions", "0"], "directions = 0"),
        (&["--slabs", "0"], "slabs = 0"),
        (&["--spp", "0"], "spp = 0"),
        // The bake takes no sun: the light is a run-time input.
        (&["--sun", "30,55"], "forest render --sun"),
    ];
    for (extra, want) in cases {
        let err = fails(&b, extra, dir.path());
        assert!(err.contains(want), "{extra:?}: {err}");
    }
}

#[test]
fn bad_models_give_one_clear_error_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let write = |name: &str, text: &str| {
        let p = d.join(name);
        std::fs::write(&p, text).unwrap();
        p.display().to_string()
    };
    let missing = d.join("missing.obj").display().to_string();
    assert!(fails(&missing, &[], d).contains("missing.obj"));

    let garbage = write("garbage.obj", "v 1 2\nf 1 2 3\n");
    assert!(fails(&garbage, &[], d).contains("cannot parse OBJ"));

    let no_faces = write("nofaces.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    assert!(fails(&no_faces, &[], d).contains("no faces"));

    let nan = write("nan.obj", "v 0 0 0\nv 1 NaN 0\nv 0 1 0\nf 1 2 3\n");
    assert!(fails(&nan, &[], d).contains("non-finite"));

    let inf = write("inf.obj", "v 0 0 0\nv 1 inf 0\nv 0 1 0\nf 1 2 3\n");
    assert!(fails(&inf, &[], d).contains("non-finite"));

    // Coordinates whose triangle areas overflow f32 are named as such, not as degenerate.
    let huge = write("huge.obj", "v 0 0 0\nv 1e38 0 0\nv 0 1e38 0\nf 1 2 3\n");
    let err = fails(&huge, &[], d);
    assert!(err.contains("1e38") && err.contains("rescale"), "{err}");

    // A colour statement short of values (tobj 4 would panic on it) names the file and line.
    write("short.mtl", "newmtl leaf\nKd 0.3 0\n");
    let short = write(
        "short.obj",
        "mtllib short.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl leaf\nf 1 2 3\n",
    );
    let err = fails(&short, &[], d);
    assert!(err.contains("short.mtl") && err.contains("line 2"), "{err}");

    // Face indices naming nothing defined (tobj 4 overflows on them) name the line and index.
    let far = write(
        "far.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/9223372036854775807 2 3\n",
    );
    let err = fails(&far, &[], d);
    assert!(
        err.contains("line 5") && err.contains("texture coordinate index"),
        "{err}"
    );

    let degenerate = write("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
    assert!(fails(&degenerate, &[], d).contains("degenerate"));

    write("nomtl.mtl", "newmtl leaf\nKd 1 1 1\nmap_Kd nowhere.png\n");
    let missing_tex = write(
        "tex.obj",
        "mtllib nomtl.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl leaf\nf 1 2 3\n",
    );
    let err = fails(&missing_tex, &[], d);
    assert!(err.contains("nowhere.png") && err.contains("leaf"), "{err}");

    let missing_mtl = write(
        "lib.obj",
        "mtllib absent.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    );
    assert!(fails(&missing_mtl, &[], d).contains("material library"));

    write("one.mtl", "newmtl bark\nKd 0.3 0.2 0.1\n");
    let undefined = write(
        "undef.obj",
        "mtllib one.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl leaf\nf 1 2 3\n",
    );
    let err = fails(&undefined, &[], d);
    assert!(
        err.contains("line 5") && err.contains("usemtl leaf"),
        "{err}"
    );

    let device = write(
        "dev.obj",
        "mtllib /dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    );
    let err = fails(&device, &[], d);
    assert!(
        err.contains("/dev/zero") && err.contains("regular file"),
        "{err}"
    );

    // Cleanup of the fixtures is the tempdir's; the listing check in `fails` covers outputs.
}

#[test]
fn degenerate_triangles_are_skipped_and_counted() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("mixed.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n",
    )
    .unwrap();
    let atlas = dir.path().join("mixed.atlas");
    let mut args = vec![
        "bake",
        obj.to_str().unwrap(),
        "-o",
        atlas.to_str().unwrap(),
        "--json",
        "--no-hybrid-switch",
    ];
    args.extend_from_slice(&SMALL);
    let out = forest(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["triangles"], 1);
    assert_eq!(v["degenerate_triangles"], 1);
    // Not measured: nothing recorded, and the manifest has no switch.
    assert!(v["hybrid_switch"].is_null(), "{v}");
    assert_eq!(v["hybrid_switch_ladder"].as_array().map(Vec::len), Some(0));
    let manifest = std::fs::read_to_string(atlas.join("manifest.json")).unwrap();
    assert!(!manifest.contains("hybrid_switch"));
}

#[test]
fn outputs_that_cannot_be_written_are_refused_up_front() {
    let dir = tempfile::tempdir().unwrap();
    let b = bush();
    let not_atlas = dir.path().join("keep");
    std::fs::create_dir(&not_atlas).unwrap();
    std::fs::write(not_atlas.join("precious.txt"), "x").unwrap();
    let out = forest(&["bake", &b, "-o", not_atlas.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("refusing to overwrite"));
    assert!(not_atlas.join("precious.txt").is_file());

    let sheet = dir.path().join("no/such/dir/sheet.png");
    let err = fails(
        &b,
        &["--contact-sheet", sheet.to_str().unwrap()],
        dir.path(),
    );
    assert!(err.contains("does not exist"), "{err}");

    let info = forest(&["info", dir.path().join("nothing.atlas").to_str().unwrap()]);
    assert!(!info.status.success());
    assert!(String::from_utf8_lossy(&info.stderr).contains("no such atlas"));
}

#[test]
fn the_memory_estimate_bounds_a_measured_bake_and_refuses_what_cannot_fit() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b.atlas");
    let o = out.to_str().unwrap();
    let args = [
        "bake",
        &model("bush"),
        "-o",
        o,
        "--resolution",
        "256",
        "--directions",
        "5",
        "--below",
        "0",
        "--spp",
        "1",
        "--no-hybrid-switch",
    ];
    // Refused before any work, with the figure and the limit; nothing written.
    let mut small = args.to_vec();
    small.extend(["--memory-limit", "0.01"]);
    let refused = forest(&small);
    assert!(!refused.status.success());
    let e = String::from_utf8_lossy(&refused.stderr);
    assert!(
        e.contains("GiB at its peak") && e.contains("0.0 GiB available"),
        "{e}"
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    // The estimate is an upper bound of the measured peak, and not a loose one.
    let mut json = args.to_vec();
    json.push("--json");
    let v: serde_json::Value = serde_json::from_str(&ok(&forest(&json))).unwrap();
    let estimate = v["peak_estimate_bytes"].as_f64().unwrap();
    if let Some(measured) = v["peak_resident_bytes"].as_f64() {
        assert!(
            measured <= estimate && estimate <= 3.0 * measured,
            "estimate {estimate} vs measured peak {measured}"
        );
    }
}

/// The glTF corpus (`scripts/make_gltf_corpus.py`: trees stored as Blender, an interleaving
/// exporter and the Khronos sample models store them; `scripts/blender_corpus.py`: one
/// exported by Blender 5.0's own exporter) bakes, says what it left out, and renders as quads
/// and as geometry from its own model.
#[test]
fn the_gltf_corpus_bakes_and_renders() {
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/gltf-corpus");
    let dir = tempfile::tempdir().unwrap();
    let p = |s: &str| dir.path().join(s).display().to_string();
    // File, the notes its bake must print, its triangles (the generated tree has 12 of trunk
    // and 80 of leaf cards; Blender's cylinder has caps).
    for (file, notes, triangles) in [
        (
            "blender.glb",
            &["1 animation ignored", "KHR_materials_specular"][..],
            92,
        ),
        ("interleaved.gltf", &["COLOR_0"][..], 92),
        ("instanced.gltf", &["1 camera ignored"][..], 3 * 92),
        ("blender-5.glb", &["1 animation ignored"][..], 100),
    ] {
        let model = corpus.join(file);
        let before = std::fs::read(&model).unwrap();
        let atlas = p(&format!("{file}.atlas"));
        let mut args = vec!["bake", model.to_str().unwrap(), "-o", &atlas, "--json"];
        args.extend(SMALL);
        args.push("--no-hybrid-switch");
        let out = forest(&args);
        let report = ok(&out);
        let stderr = String::from_utf8_lossy(&out.stderr);
        for n in notes {
            assert!(
                stderr.contains(n),
                "{file}: expected the note {n:?} in: {stderr}"
            );
        }
        let v: serde_json::Value = serde_json::from_str(report.trim()).unwrap();
        assert_eq!(v["triangles"], triangles, "{file}: {v}");
        assert_eq!(std::fs::read(&model).unwrap(), before, "{file} changed");
        let forest_file = p(&format!("{file}.json"));
        ok(&forest(&[
            "scene",
            "--model-sizes",
            "--trees",
            "6",
            "--species",
            &atlas,
            "-o",
            &forest_file,
        ]));
        for method in ["quads", "geometry"] {
            let png = p(&format!("{file}-{method}.png"));
            let text = ok(&forest(&[
                "render",
                &forest_file,
                "-o",
                &png,
                "--view",
                "birds-eye",
                "--size",
                "64x48",
                "--method",
                method,
                "--models",
                model.to_str().unwrap(),
                "--transparent",
                "--json",
            ]));
            let img = image::open(&png).unwrap().to_rgba8();
            let covered = img.pixels().filter(|p| p[3] > 0).count();
            assert!(
                covered > 20,
                "{file} {method}: {covered} pixels covered ({text})"
            );
        }
    }
}
