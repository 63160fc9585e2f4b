//! The embedding example (`crates/forest-render/examples/embed`) renders one frame headless
//! into targets it cleared itself, with its own sky and ground, a reverse-Z infinite projection
//! and the library's public API only; that frame matches `forest render` of the same camera.

use std::path::Path;

mod cli;

#[path = "../crates/forest-baselines/examples/embed/main.rs"]
#[allow(dead_code)]
mod embed;

use cli::{bake_small, forest, ok};
use glam::Vec3;

#[test]
fn the_example_matches_forest_render() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let p = |n: &str| d.join(n).display().to_string();
    for s in ["bush", "pine"] {
        bake_small(s, &d.join(format!("{s}.atlas")), 64, 5);
    }
    ok(&forest(&[
        "scene",
        "--model-sizes",
        "--trees",
        "60",
        "--species",
        &format!("{},{}", p("bush.atlas"), p("pine.atlas")),
        "--area-per-tree",
        "12",
        "-o",
        &p("f.forest"),
    ]));
    // Looking down, so that no horizon is in view: `forest render` ends its ground at a finite
    // far plane, the example's infinite projection does not.
    let (eye, target) = (Vec3::new(-6.0, 14.0, 12.0), Vec3::new(0.0, 1.0, 0.0));
    ok(&forest(&[
        "render",
        &p("f.forest"),
        "--eye",
        "-6,14,12",
        "--target",
        "0,1,0",
        "--size",
        "160x120",
        "--epsilon",
        "2",
        "--haze",
        "off",
        "-o",
        &p("cli.png"),
    ]));
    let cli = image::open(d.join("cli.png")).unwrap().to_rgba8();
    let example = embed::headless(&d.join("f.forest"), eye, target, (160, 120), 2.0).unwrap();
    let (flip, map) = forest_metrics::flip(&cli, &example).unwrap();
    if flip > 0.01 {
        let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("embed");
        std::fs::create_dir_all(&out).unwrap();
        cli.save(out.join("forest-render.png")).unwrap();
        example.save(out.join("example.png")).unwrap();
        map.save(out.join("flip.png")).unwrap();
        panic!("FLIP {flip} > 0.01: images in {}", out.display());
    }
    // The frame shows trees, not only the host's sky and ground.
    let (w, h) = example.dimensions();
    let (sky, ground) = (*example.get_pixel(0, 0), *example.get_pixel(w / 2, h - 1));
    let trees = example
        .pixels()
        .filter(|p| **p != sky && **p != ground)
        .count();
    assert!(trees > 200, "{trees} pixels other than sky and ground");
    eprintln!("FLIP {flip:.5}; {trees} tree pixels");
    // With the host's sun shadow map, which the forest casts into and receives: the host's
    // ground and the trees darken where shadowed, and nothing brightens.
    let shadowed = embed::headless_with(
        &d.join("f.forest"),
        Some(eye),
        Some(target),
        (160, 120),
        2.0,
        true,
    )
    .unwrap();
    let lum = |p: &image::Rgba<u8>| u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2]);
    let darker = shadowed
        .pixels()
        .zip(example.pixels())
        .filter(|(a, b)| lum(a) * 10 < lum(b) * 9)
        .count();
    let brighter = shadowed
        .pixels()
        .zip(example.pixels())
        .filter(|(a, b)| lum(a) > lum(b) + 6)
        .count();
    assert!(
        darker > 300 && brighter == 0,
        "host shadows: {darker} pixels darker, {brighter} brighter"
    );
}
