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

/// A leaf card (MASK, textured, double-sided) under a node that moves it up, and a bark
/// triangle at the root: the buffer (positions, texture coordinates, 16-bit indices, then the
/// image when `embedded`) and the JSON naming it `model.bin` (or buffer 0 of a GLB).
fn gltf_parts(leaf: &[u8], embedded: bool) -> (String, Vec<u8>) {
    let positions: [f32; 15] = [
        -0.5, 0.0, 0.0, 0.5, 0.0, 0.0, 0.5, 1.0, 0.0, -0.5, 1.0, 0.0, 0.0, -1.0, 0.1,
    ];
    let uvs: [f32; 8] = [0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0];
    let indices: [u16; 6] = [0, 1, 2, 0, 2, 3];
    let mut bin: Vec<u8> = positions.iter().flat_map(|x| x.to_le_bytes()).collect();
    bin.extend(uvs.iter().flat_map(|x| x.to_le_bytes()));
    bin.extend(indices.iter().flat_map(|x| x.to_le_bytes()));
    let image_offset = bin.len();
    let (buffer, image) = if embedded {
        bin.extend_from_slice(leaf);
        (
            format!(r#"{{"byteLength":{}}}"#, bin.len()),
            r#"{"bufferView":3,"mimeType":"image/png"}"#.to_string(),
        )
    } else {
        (
            format!(r#"{{"uri":"model.bin","byteLength":{}}}"#, bin.len()),
            r#"{"uri":"leaf.png"}"#.to_string(),
        )
    };
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0,1]}}],
"nodes":[{{"mesh":0,"translation":[0,1,0]}},{{"mesh":1}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":1}},"indices":2,"material":0}}]}},
{{"primitives":[{{"attributes":{{"POSITION":3}},"material":1}}]}}],
"materials":[{{"name":"leaf","alphaMode":"MASK","alphaCutoff":0.4,"doubleSided":true,
"pbrMetallicRoughness":{{"baseColorFactor":[0.3,0.6,0.2,1],"baseColorTexture":{{"index":0}}}}}},
{{"name":"bark","pbrMetallicRoughness":{{"baseColorFactor":[0.4,0.3,0.2,1]}}}}],
"textures":[{{"source":0}}],"images":[{image}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[-0.5,0,0],"max":[0.5,1,0]}},
{{"bufferView":1,"componentType":5126,"count":4,"type":"VEC2"}},
{{"bufferView":2,"componentType":5123,"count":6,"type":"SCALAR"}},
{{"bufferView":0,"byteOffset":24,"componentType":5126,"count":3,"type":"VEC3","min":[-0.5,-1,0],"max":[0.5,1,0.1]}}],
"bufferViews":[{{"buffer":0,"byteLength":60}},{{"buffer":0,"byteOffset":60,"byteLength":32}},
{{"buffer":0,"byteOffset":92,"byteLength":12}},{{"buffer":0,"byteOffset":{image_offset},"byteLength":{}}}],
"buffers":[{buffer}]}}"#,
        leaf.len()
    );
    (json, bin)
}

/// A binary glTF: the 12-byte header, the JSON chunk padded with spaces, the BIN chunk padded
/// with zeros.
fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut j = json.as_bytes().to_vec();
    j.resize(j.len().next_multiple_of(4), b' ');
    let mut b = bin.to_vec();
    b.resize(b.len().next_multiple_of(4), 0);
    let total = 12 + 8 + j.len() + 8 + b.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    out.extend_from_slice(&(b.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&b);
    out
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

    // A forest on a terrain (format version 2), binary and JSON.
    let hills = sample_forest(4).with_terrain(forest_format::terrain::Terrain {
        size: [3, 2],
        origin: [-4.0, -2.0],
        spacing: 4.0,
        heights: vec![0.0, 1.0, 2.0, 3.0, 5.0, 8.0],
    });
    write("forest_binary", "seed-2", &hills.to_bytes());
    let json = saved(dir, "f.json", |p| hills.save(p).expect("forest saves"));
    write("forest_json", "seed-2.json", &json);

    // A coloured forest (format version 3) on the terrain, two trees given explicit values.
    let mut colouring = forest_format::colour::Colouring::new(
        1.0,
        vec![forest_format::colour::SpeciesColour::DECIDUOUS; hills.species.len()],
    );
    colouring.explicit = (0..hills.instances.len())
        .map(|k| if k < 2 { 0.25 * k as f32 } else { -1.0 })
        .collect();
    let tinted = hills.clone().with_colouring(colouring);
    write("forest_binary", "seed-3", &tinted.to_bytes());
    let json = saved(dir, "f.json", |p| tinted.save(p).expect("forest saves"));
    write("forest_json", "seed-3.json", &json);

    // Height fields: a 16-bit PNG and an EXR, behind the target's kind byte.
    let heights_png = saved(dir, "h.png", |p| {
        image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(5, 4, |x, y| {
            image::Luma([(x * 9000 + y * 2000) as u16])
        })
        .save(p)
        .expect("PNG saves")
    });
    write("terrain", "seed-0", &[&[0u8][..], &heights_png].concat());
    let heights_exr = saved(dir, "h.exr", |p| {
        image::DynamicImage::ImageRgb32F(image::ImageBuffer::from_fn(4, 3, |x, y| {
            image::Rgb([x as f32 - y as f32, 0.0, 0.0])
        }))
        .save(p)
        .expect("EXR saves")
    });
    write("terrain", "seed-1", &[&[1u8][..], &heights_exr].concat());

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

    // glTF: JSON with its buffer and image as files, and the same model as one GLB.
    let (json, bin) = gltf_parts(&leaf, false);
    write(
        "gltf",
        "seed-0",
        &join_files(&[json.as_bytes(), &bin, &leaf]),
    );
    let (json, bin) = gltf_parts(&leaf, true);
    write("gltf", "seed-1.glb", &glb(&json, &bin));
    // The glTF corpus's Blender-shaped GLB and its interleaved .gltf (its buffer and images
    // renamed to the files the target writes).
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/gltf-corpus");
    let read = |f: &str| std::fs::read(corpus.join(f)).expect("the glTF corpus is there");
    write("gltf", "seed-2.glb", &read("blender.glb"));
    let json = String::from_utf8(read("interleaved.gltf"))
        .expect("UTF-8 JSON")
        .replace("interleaved.bin", "model.bin")
        .replace("interleaved-bark.png", "leaf.png")
        .replace("interleaved-leaf.png", "leaf.png");
    write(
        "gltf",
        "seed-3",
        &join_files(&[
            json.as_bytes(),
            &read("interleaved.bin"),
            &read("interleaved-leaf.png"),
        ]),
    );

    // Atlases baked from the OBJ seed, JPEG and PNG colour, and from the plain OBJ with its
    // prepared model (the smallest model.bin: no textures, so its fixed-size billboards and
    // opacity volume compress to little and the fuzzer runs fast).
    for obj in ["model.obj", "model.mtl", "leaf.png", "plain.obj"]
        .iter()
        .zip([OBJ.as_bytes(), MTL.as_bytes(), &leaf, OBJ_PLAIN.as_bytes()])
    {
        std::fs::write(dir.join(obj.0), obj.1).expect("writing the model");
    }
    for (i, (source, colour)) in [
        ("model.obj", ColourEncoding::Jpeg { quality: 80 }),
        ("model.obj", ColourEncoding::Png),
        ("plain.obj", ColourEncoding::Png),
    ]
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
        let out = forest_bake::bake_file(&dir.join(source), &params, &|_, _| {})
            .expect("the seed model bakes");
        let atlas = dir.join(format!("s{i}.atlas"));
        out.atlas.save(&atlas).expect("the seed atlas saves");
        let read = |f: &str| std::fs::read(atlas.join(f)).expect("reading the seed atlas");
        let model = if source == "plain.obj" {
            let mesh = forest_bake::Mesh::load(&dir.join(source)).expect("the seed loads");
            let model = forest_bake::model::prepare(&mesh, None).encode();
            write("model_bin", "seed-0", &model);
            model
        } else {
            Vec::new()
        };
        write(
            "atlas",
            &format!("seed-{i}"),
            &join_files(&[
                &read(forest_format::atlas::MANIFEST_FILE),
                &read(colour.file_name()),
                &read(forest_format::atlas::ALPHA_FILE),
                &read(forest_format::atlas::NODES_FILE),
                &read(forest_format::atlas::SURFACE_FILE),
                &read(forest_format::atlas::OPACITY_FILE),
                &model,
            ]),
        );
    }

    // Results tables as `bench accuracy --redraw` reads them: every layout it knows.
    let all = forest_format::results_csv::accuracy_columns();
    let row = |n: usize| {
        let mut cells: Vec<String> = (0..n).map(|k| format!("{}", k as f32 * 0.01)).collect();
        cells[0] = "quads".into();
        cells[1] = "eps=2".into();
        cells[2] = "inside".into();
        if n > 17 {
            cells[17] = "recorded commands".into();
        }
        cells.join(",")
    };
    for (i, n) in [all.len(), 18, 8].into_iter().enumerate() {
        let text = format!("{}\n{}\n{}\n", all[..n].join(","), row(n), row(n));
        write("results_csv", &format!("seed-{i}.csv"), text.as_bytes());
    }

    // Winds as the options give them, with a tree and points of it.
    for (i, text) in [
        "60,8\n0.5\n12.25\n3 -7 12 4 17\n0 12 0 3 8 1 -2 4 0",
        "270,30\n1\n-99999\n1e6 -1e6 40 10 4294967295\n4 40 -4 0 0 0 0 -1 0",
        "0,0\n0\n0\n",
    ]
    .into_iter()
    .enumerate()
    {
        write("wind", &format!("seed-{i}"), text.as_bytes());
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
