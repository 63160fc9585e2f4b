//! Write the seed corpora of the fuzz targets into `crates/forest-fuzz/corpus/` (run once
//! after a format changes: `cargo run -p forest-fuzz --bin forest-fuzz-seeds`). Every seed is
//! a small valid input made by the project's own writers, so the fuzzer starts from files the
//! loaders accept.

use std::path::Path;

use forest_format::QuadNode;
use forest_format::atlas::{BakeParams, ColourEncoding};
use forest_format::camera_path::CameraPath;
use forest_format::forest::{Forest, Instance};
use forest_fuzz::{corpus_dir, join_files};
use glam::Vec3;

/// A leaf card (alpha-textured quad) above a trunk quad, with normals and UVs.
const OBJ: &str = "mtllib model.mtl
v -0.5 1.0 0.0
v 0.5 1.0 0.0
v 0.5 2.0 0.0
v -0.5 2.0 0.0
v -0.1 0.0 0.1
v 0.1 0.0 0.1
v 0.1 1.0 -0.1
v -0.1 1.0 -0.1
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
usemtl leaf
f 1/1/1 2/2/1 3/3/1 4/4/1
usemtl bark
f 5 6 7
f -4 -2 -1
";

const MTL: &str = "newmtl leaf
Kd 0.3 0.6 0.2
map_Kd leaf.png
map_d leaf.png
newmtl bark
Kd 0.4 0.3 0.2
";

/// An OBJ without materials, with a polygon and a degenerate triangle.
const OBJ_PLAIN: &str = "o plain
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0.5 2 0
f 1 2 3 4 5
f 1 1 2
";

fn png(img: &image::DynamicImage) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .expect("PNG encodes");
    out.into_inner()
}

fn leaf_png() -> Vec<u8> {
    png(&image::DynamicImage::ImageRgba8(image::RgbaImage::from_fn(
        8,
        8,
        |x, y| {
            image::Rgba([
                40,
                120 + x as u8 * 10,
                30,
                if (x + y) % 3 == 0 { 0 } else { 255 },
            ])
        },
    )))
}

fn write(target: &str, name: &str, bytes: &[u8]) {
    let dir = corpus_dir(target);
    std::fs::create_dir_all(&dir).expect("corpus folder");
    std::fs::write(dir.join(name), bytes).expect("writing a seed");
    println!("{target}/{name}: {} bytes", bytes.len());
}

fn sample_forest(n: u32) -> Forest {
    let instances = (0..n)
        .map(|i| Instance {
            position: [i as f32 * 3.0, 0.0, (i % 4) as f32 * 5.0],
            rotation: i as f32,
            scale: 1.0 + 0.1 * (i % 3) as f32,
            species: i % 2,
        })
        .collect();
    Forest::new(vec!["a.atlas".into(), "b.atlas".into()], instances, 3)
}

fn saved(dir: &Path, name: &str, save: impl FnOnce(&Path)) -> Vec<u8> {
    let p = dir.join(name);
    save(&p);
    std::fs::read(&p).expect("reading what was saved")
}

fn main() {
    let tmp = tempfile::tempdir().expect("temporary folder");
    let dir = tmp.path();

    // Forests, binary and JSON.
    for (i, n) in [1u32, 12].into_iter().enumerate() {
        let f = sample_forest(n);
        write("forest_binary", &format!("seed-{i}"), &f.to_bytes());
        let json = saved(dir, "f.json", |p| f.save(p).expect("forest saves"));
        write("forest_json", &format!("seed-{i}.json"), &json);
    }

    // Camera paths.
    let mut path = CameraPath::new(60.0);
    path.push(Vec3::new(0.0, 1.7, 5.0), Vec3::ZERO);
    path.push(Vec3::new(2.0, 1.7, 5.0), Vec3::X);
    let json = saved(dir, "p.json", |p| path.save(p).expect("path saves"));
    write("camera_path", "seed-0.json", &json);

    // Node files: one root with three children.
    let nodes: Vec<QuadNode> = (0..4u32)
        .map(|k| QuadNode::new(if k == 0 { 0b0111 } else { 0 }, 1, [k as u8, 9, 80, 200]))
        .collect();
    write(
        "nodes",
        "seed-0",
        &forest_format::nodes_codec::encode(&nodes, 1),
    );

    // OBJ + MTL + texture.
    let leaf = leaf_png();
    write(
        "obj",
        "seed-0",
        &join_files(&[OBJ.as_bytes(), MTL.as_bytes(), &leaf]),
    );
    write("obj", "seed-1", OBJ_PLAIN.as_bytes());

    // Atlases baked from the OBJ seed, JPEG and PNG colour.
    for obj in
        ["model.obj", "model.mtl", "leaf.png"]
            .iter()
            .zip([OBJ.as_bytes(), MTL.as_bytes(), &leaf])
    {
        std::fs::write(dir.join(obj.0), obj.1).expect("writing the model");
    }
    for (i, colour) in [ColourEncoding::Jpeg { quality: 80 }, ColourEncoding::Png]
        .into_iter()
        .enumerate()
    {
        let params = BakeParams {
            directions: 2,
            below: 1,
            slabs: 1,
            resolution: 16,
            spp: 1,
            colour,
            ..BakeParams::default()
        };
        let out = forest_bake::bake_file(&dir.join("model.obj"), &params, &|_, _| {})
            .expect("the seed model bakes");
        let atlas = dir.join(format!("s{i}.atlas"));
        out.atlas.save(&atlas).expect("the seed atlas saves");
        let read = |f: &str| std::fs::read(atlas.join(f)).expect("reading the seed atlas");
        write(
            "atlas",
            &format!("seed-{i}"),
            &join_files(&[
                &read(forest_format::atlas::MANIFEST_FILE),
                &read(colour.file_name()),
                &read(forest_format::atlas::ALPHA_FILE),
                &read(forest_format::atlas::NODES_FILE),
            ]),
        );
    }

    // Images as `compare` reads them: RGBA and grey PNG, 16-bit PNG, JPEG.
    write("image", "seed-0.png", &leaf);
    let grey = image::DynamicImage::ImageLuma8(image::GrayImage::from_fn(12, 6, |x, y| {
        image::Luma([(x * 20 + y) as u8])
    }));
    write("image", "seed-1.png", &png(&grey));
    write(
        "image",
        "seed-2.png",
        &png(&image::DynamicImage::ImageRgb16(grey.to_rgb16())),
    );
    let mut jpeg = std::io::Cursor::new(Vec::new());
    grey.to_rgb8()
        .write_to(&mut jpeg, image::ImageFormat::Jpeg)
        .expect("JPEG encodes");
    write("image", "seed-3.jpg", &jpeg.into_inner());
}
