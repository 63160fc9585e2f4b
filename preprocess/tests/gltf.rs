//! glTF input: the same tree from OBJ and GLB bakes to the same atlas, node transforms and
//! alpha modes mean what the glTF specification says, unsupported features are named.

use std::path::{Path, PathBuf};

use forest_bake::Mesh;
use forest_format::{BakeParams, ColourEncoding};
use glam::Vec3;

fn tree(name: &str, ext: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../assets/trees/{name}/{name}.{ext}"))
}

/// All layers of an atlas, stacked into one image.
fn layers_image(atlas: &forest_format::Atlas) -> image::RgbaImage {
    let l = atlas.decode_layers(Path::new("unused")).unwrap();
    image::RgbaImage::from_raw(l.resolution, l.resolution * l.count, l.rgba).unwrap()
}

#[test]
fn the_bundled_glb_bakes_to_the_atlas_of_its_obj() {
    let params = BakeParams {
        directions: 5,
        resolution: 64,
        min_quad: 4,
        spp: 2,
        colour: ColourEncoding::Png,
        ..BakeParams::default()
    };
    let obj = forest_bake::bake_file(&tree("bush", "obj"), &params, &|_, _| {}).unwrap();
    let glb = forest_bake::bake_file(&tree("bush", "glb"), &params, &|_, _| {}).unwrap();
    let (a, b) = (&obj.atlas.manifest, &glb.atlas.manifest);
    assert_eq!(a.source.triangles, b.source.triangles);
    assert_eq!(a.source.materials, b.source.materials);
    assert!((a.bounding_sphere.radius - b.bounding_sphere.radius).abs() < 1e-4);
    let m = forest_metrics::compare(&layers_image(&obj.atlas), &layers_image(&glb.atlas)).unwrap();
    eprintln!("OBJ against GLB layers: mean FLIP {}", m.flip_mean);
    assert!(
        m.flip_mean <= 0.01,
        "FLIP {} between the OBJ's and the GLB's layers",
        m.flip_mean
    );
    // Node counts follow the images: a different alpha test would change them a lot.
    let (na, nb) = (a.node_count as f64, b.node_count as f64);
    assert!((na - nb).abs() / na < 0.01, "{na} nodes against {nb}");
}

#[test]
fn the_bundled_glb_loads_the_triangles_and_materials_of_its_obj() {
    for name in ["oak", "pine"] {
        let o = Mesh::load(&tree(name, "obj")).unwrap();
        let g = Mesh::load(&tree(name, "glb")).unwrap();
        assert_eq!(o.tris.len(), g.tris.len(), "{name}");
        let names = |m: &Mesh| {
            m.materials
                .iter()
                .map(|m| m.name.clone())
                .collect::<Vec<_>>()
        };
        assert_eq!(names(&o), names(&g));
        for (a, b) in o.materials.iter().zip(&g.materials) {
            assert!(
                (a.kd - b.kd).abs().max_element() < 1e-5,
                "{name} {}",
                a.name
            );
            assert_eq!(a.alpha.is_some(), b.alpha.is_some(), "{name} {}", a.name);
        }
        // Same triangles in the same order, texture coordinates in the OBJ's convention.
        for (a, b) in o.tris.iter().zip(&g.tris) {
            for k in 0..3 {
                assert!((a.p[k] - b.p[k]).abs().max_element() < 1e-5);
                assert!((a.uv[k] - b.uv[k]).abs().max_element() < 1e-5);
            }
            assert_eq!(a.material, b.material);
        }
    }
}

/// A glTF file (JSON, buffer as a file next to it) holding one triangle per given node.
fn write_gltf(dir: &Path, extra: &str, nodes: &str, material: &str) -> PathBuf {
    let tri: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    let bytes: Vec<u8> = tri.iter().flat_map(|x| x.to_le_bytes()).collect();
    std::fs::write(dir.join("tri.bin"), &bytes).unwrap();
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},{extra}"scene":0,"scenes":[{{"nodes":[0]}}],
        "nodes":[{nodes}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"material":0}}]}}],
        "materials":[{material}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}}],
        "buffers":[{{"uri":"tri.bin","byteLength":36}}]}}"#
    );
    let path = dir.join("t.gltf");
    std::fs::write(&path, json).unwrap();
    path
}

#[test]
fn node_transforms_are_applied_parent_first() {
    let dir = tempfile::tempdir().unwrap();
    // The parent moves up 2 m; its child scales by 2 and turns 90° about y.
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let nodes = format!(
        r#"{{"children":[1],"translation":[0,2,0]}},
           {{"mesh":0,"scale":[2,2,2],"rotation":[0,{s},0,{s}]}}"#
    );
    let path = write_gltf(dir.path(), "", &nodes, r#"{"name":"m"}"#);
    let mesh = Mesh::load(&path).unwrap();
    assert_eq!(mesh.tris.len(), 1);
    let p = mesh.tris[0].p;
    let want = [
        Vec3::new(0.0, 2.0, 0.0),
        Vec3::new(0.0, 2.0, -2.0),
        Vec3::new(0.0, 4.0, 0.0),
    ];
    for (a, b) in p.iter().zip(want) {
        assert!((*a - b).length() < 1e-5, "{a} against {b}");
    }
    // No NORMAL: the face normal, turned with the node (+z becomes +x).
    assert!(
        (mesh.tris[0].n[0] - Vec3::X).length() < 1e-5,
        "{}",
        mesh.tris[0].n[0]
    );
    assert_eq!(mesh.materials[0].name, "m");
    assert!(mesh.materials[0].alpha.is_none());
}

#[test]
fn unsupported_gltf_features_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let err = |extra: &str, nodes: &str| {
        let path = write_gltf(dir.path(), extra, nodes, "{}");
        Mesh::load(&path).unwrap_err().to_string()
    };
    let mesh = r#"{"mesh":0}"#;
    let e = err(
        r#""extensionsUsed":["KHR_draco_mesh_compression"],"extensionsRequired":["KHR_draco_mesh_compression"],"#,
        mesh,
    );
    assert!(
        e.contains("KHR_draco_mesh_compression") && e.contains("does not support"),
        "{e}"
    );
    let e = err(r#""extensionsUsed":["KHR_texture_transform"],"#, mesh);
    assert!(e.contains("KHR_texture_transform"), "{e}");
    let e = err("", r#"{"children":[]}"#);
    assert!(e.contains("no mesh"), "{e}");
    // Points, not triangles.
    let path = write_gltf(dir.path(), "", mesh, "{}");
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(
        &path,
        text.replace(r#""material":0"#, r#""material":0,"mode":0"#),
    )
    .unwrap();
    let e = Mesh::load(&path).unwrap_err().to_string();
    assert!(e.contains("only triangles"), "{e}");
    // A data: URI buffer.
    std::fs::write(
        &path,
        text.replace("tri.bin", "data:application/octet-stream;base64,AAAA"),
    )
    .unwrap();
    let e = Mesh::load(&path).unwrap_err().to_string();
    assert!(e.contains("data: URI"), "{e}");
    // A missing buffer file names the file.
    let tri_bytes = std::fs::read(dir.path().join("tri.bin")).unwrap();
    std::fs::remove_file(dir.path().join("tri.bin")).unwrap();
    std::fs::write(&path, &text).unwrap();
    let e = Mesh::load(&path).unwrap_err().to_string();
    assert!(e.contains("tri.bin"), "{e}");
    // Escapes in a URI are decoded: "tri%20%2B%C3%A9.bin" names "tri +é.bin".
    std::fs::write(dir.path().join("tri +é.bin"), &tri_bytes).unwrap();
    std::fs::write(&path, text.replace("tri.bin", "tri%20%2B%C3%A9.bin")).unwrap();
    assert_eq!(Mesh::load(&path).unwrap().tris.len(), 1);
    assert!(
        forest_bake::source_files(&path)
            .unwrap()
            .contains(&dir.path().join("tri +é.bin"))
    );
    // An escape that is not UTF-8 is named.
    std::fs::write(&path, text.replace("tri.bin", "tri%FF.bin")).unwrap();
    let e = Mesh::load(&path).unwrap_err().to_string();
    assert!(e.contains("UTF-8") && e.contains("tri%FF.bin"), "{e}");
    // Not glTF at all.
    std::fs::write(&path, "solid cube").unwrap();
    let e = Mesh::load(&path).unwrap_err().to_string();
    assert!(e.contains("glTF"), "{e}");
}

#[test]
fn malformed_gltf_is_refused_without_a_panic() {
    // Each once panicked the gltf crates (found by the fuzz target): refused with the cause.
    let dir = tempfile::tempdir().unwrap();
    let path = write_gltf(dir.path(), "", r#"{"mesh":0}"#, "{}");
    let text = std::fs::read_to_string(&path).unwrap();
    let refused = |from: &str, to: &str| {
        assert!(text.contains(from), "{from}");
        std::fs::write(&path, text.replace(from, to)).unwrap();
        let e = Mesh::load(&path).unwrap_err().to_string();
        // The file list the bake checks its output against must not panic either.
        let _ = forest_bake::source_files(&path);
        e
    };
    let e = refused(r#""POSITION":0"#, r#""POSITION":7"#);
    assert!(e.contains("POSITION names accessor 7"), "{e}");
    let e = refused(r#""material":0}"#, r#""material":0,"indices":0}"#);
    assert!(e.contains("the indices") && e.contains("Scalar"), "{e}");
    let e = refused(
        r#""materials":[{}]"#,
        r#""materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],
        "textures":[{"source":0}],"images":[{"name":"nowhere"}]"#,
    );
    assert!(
        e.contains("image 0 has neither a uri nor a buffer view"),
        "{e}"
    );
    let e = refused(
        r#""materials":[{}]"#,
        r#""materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],
        "textures":[{"source":0}],"images":[{"bufferView":0}]"#,
    );
    assert!(e.contains("no mimeType"), "{e}");
    let e = refused(r#"{"mesh":0}"#, r#"{"mesh":0,"children":[0]}"#);
    assert!(e.contains("not a tree"), "{e}");
    // A GLB whose header states a length below its own 12 bytes (the fuzz target's find).
    let glb = dir.path().join("short.glb");
    let mut bytes = b"glTF".to_vec();
    bytes.extend(2u32.to_le_bytes());
    bytes.extend(0u32.to_le_bytes());
    bytes.extend([0u8; 20]);
    std::fs::write(&glb, &bytes).unwrap();
    let e = Mesh::load(&glb).unwrap_err().to_string();
    assert!(e.contains("GLB header says the file is 0 bytes"), "{e}");
    assert!(forest_bake::source_files(&glb).is_err());
}

#[test]
fn a_mask_cutoff_keeps_exactly_the_texels_at_or_above_it() {
    // A textured quad whose texture's alpha runs 0, 1, …, 255 along x; the material's
    // alphaCutoff (divided by its factor's alpha) must pass exactly the texels at or above it.
    let dir = tempfile::tempdir().unwrap();
    let img = image::RgbaImage::from_fn(256, 2, |x, _| image::Rgba([90, 160, 60, x as u8]));
    img.save(dir.path().join("ramp.png")).unwrap();
    let floats: [f32; 20] = [
        0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0, // positions
        0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0, // texture coordinates
    ];
    let mut bin: Vec<u8> = floats.iter().flat_map(|x| x.to_le_bytes()).collect();
    bin.extend([0u16, 1, 2, 0, 2, 3].iter().flat_map(|i| i.to_le_bytes()));
    std::fs::write(dir.path().join("quad.bin"), &bin).unwrap();
    for (cutoff, factor_alpha) in [(0.3f32, 1.0f32), (0.5, 1.0), (0.77, 1.0), (0.35, 0.7)] {
        let json = format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":1}},"indices":2,"material":0}}]}}],
            "materials":[{{"alphaMode":"MASK","alphaCutoff":{cutoff},
              "pbrMetallicRoughness":{{"baseColorFactor":[1,1,1,{factor_alpha}],"baseColorTexture":{{"index":0}}}}}}],
            "textures":[{{"source":0}}],"images":[{{"uri":"ramp.png"}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
              {{"bufferView":1,"componentType":5126,"count":4,"type":"VEC2"}},
              {{"bufferView":2,"componentType":5123,"count":6,"type":"SCALAR"}}],
            "bufferViews":[{{"buffer":0,"byteLength":48}},{{"buffer":0,"byteOffset":48,"byteLength":32}},
              {{"buffer":0,"byteOffset":80,"byteLength":12}}],
            "buffers":[{{"uri":"quad.bin","byteLength":92}}]}}"#
        );
        let path = dir.path().join("quad.gltf");
        std::fs::write(&path, json).unwrap();
        let mesh = Mesh::load(&path).unwrap();
        assert_eq!(mesh.tris.len(), 2);
        let m = mesh.tris[0].material;
        // Texture alpha times the factor's, against the cutoff (glTF's rule).
        let want = |a: u32| (a as f32 / 255.0) * factor_alpha >= cutoff;
        let mut passing = 0;
        for a in 0..256u32 {
            // The texel's centre, in the OBJ convention the loader turned v into.
            let uv = glam::Vec2::new((a as f32 + 0.5) / 256.0, 0.5);
            let solid = mesh.alpha(m, uv) >= forest_bake::mesh::ALPHA_CUTOFF;
            assert_eq!(
                solid,
                want(a),
                "alpha {a}, cutoff {cutoff}, factor {factor_alpha}"
            );
            passing += u32::from(solid);
        }
        assert!(
            passing > 0 && passing < 256,
            "cutoff {cutoff}: {passing} texels pass"
        );
    }
}

/// A glTF file whose JSON is `json` (a template: `BIN` is replaced by the buffer's byte
/// length) and whose buffer file holds `bin`.
fn write_raw(dir: &Path, json: &str, bin: &[u8]) -> PathBuf {
    std::fs::write(dir.join("raw.bin"), bin).unwrap();
    let path = dir.join("raw.gltf");
    std::fs::write(&path, json.replace("BIN", &bin.len().to_string())).unwrap();
    path
}

fn floats(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// One triangle's positions (36 bytes from byte 0), then `tail`; `accessors` and `views`
/// are appended to a POSITION accessor 0 over view 0 (stride `stride`).
fn raw_json(attributes: &str, accessors: &str, views: &str, extra: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},{extra}"scene":0,"scenes":[{{"nodes":[0]}}],
        "nodes":[{{"mesh":0}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0{attributes}}}}}]}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}{accessors}],
        "bufferViews":[{{"buffer":0,"byteLength":36}}{views}],
        "buffers":[{{"uri":"raw.bin","byteLength":BIN}}]}}"#
    )
}

const TRI: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];

/// Loading `json` over `bin` fails with a message holding every one of `causes`, and leaves
/// both files as they were.
fn refused_with(dir: &Path, json: &str, bin: &[u8], causes: &[&str]) {
    let path = write_raw(dir, json, bin);
    let before = (
        std::fs::read(&path).unwrap(),
        std::fs::read(dir.join("raw.bin")).unwrap(),
    );
    let e = Mesh::load(&path).unwrap_err().to_string();
    for c in causes {
        assert!(e.contains(c), "expected {c:?} in: {e}");
    }
    let _ = forest_bake::source_files(&path);
    let after = (
        std::fs::read(&path).unwrap(),
        std::fs::read(dir.join("raw.bin")).unwrap(),
    );
    assert!(before == after, "the inputs changed");
}

#[test]
fn accessors_are_checked_against_their_views_and_buffers_before_reading() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bin = floats(&TRI);
    // A stride smaller than the element once panicked inside the gltf crate's reader.
    let json = raw_json("", "", "", "")
        .replace(r#""byteLength":36}"#, r#""byteLength":36,"byteStride":4}"#);
    refused_with(d, &json, &bin, &["accessor 0", "byteStride 4", "12-byte"]);
    // A view past its buffer: named as such, not as a missing POSITION.
    let json = raw_json("", "", "", "").replace(
        r#""buffer":0,"byteLength":36}"#,
        r#""buffer":0,"byteOffset":24,"byteLength":36}"#,
    );
    refused_with(
        d,
        &json,
        &bin,
        &["POSITION (accessor 0)", "reaches past the 36 bytes"],
    );
    // An accessor whose count reaches past its view.
    let json = raw_json("", "", "", "").replace(r#""count":3"#, r#""count":4"#);
    refused_with(d, &json, &bin, &["4 elements", "reach past the 36 bytes"]);
    // Indices, texture coordinates and normals past the buffer were cut short or dropped.
    let mut more = bin.clone();
    more.extend(floats(&[0.0; 6]));
    more.extend([0u8, 0, 1, 0, 2, 0]);
    let idx = raw_json(
        "",
        r#",{"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}"#,
        r#",{"buffer":0,"byteOffset":60,"byteLength":6}"#,
        "",
    )
    .replace(r#""POSITION":0}"#, r#""POSITION":0},"indices":1"#);
    refused_with(
        d,
        &idx,
        &more,
        &["the indices (accessor 1)", "6 elements", "reach past"],
    );
    let uv = raw_json(
        r#","TEXCOORD_0":1"#,
        r#",{"bufferView":1,"componentType":5126,"count":3,"type":"VEC2"}"#,
        r#",{"buffer":0,"byteOffset":36,"byteLength":16}"#,
        "",
    );
    refused_with(
        d,
        &uv,
        &more,
        &["TEXCOORD_0 (accessor 1)", "reach past the 16 bytes"],
    );
    let nrm = raw_json(
        r#","NORMAL":1"#,
        r#",{"bufferView":1,"componentType":5126,"count":2,"type":"VEC3"}"#,
        r#",{"buffer":0,"byteOffset":36,"byteLength":24}"#,
        "",
    );
    refused_with(d, &nrm, &more, &["NORMAL has 2 elements, POSITION 3"]);
    // Texture coordinates as bytes must be normalised.
    let uv8 = raw_json(
        r#","TEXCOORD_0":1"#,
        r#",{"bufferView":1,"componentType":5121,"count":3,"type":"VEC2"}"#,
        r#",{"buffer":0,"byteOffset":36,"byteLength":6}"#,
        "",
    );
    refused_with(d, &uv8, &more, &["TEXCOORD_0", "without normalized: true"]);
    // Indices that are not whole triangles, and an index past the vertices.
    let mut two = bin.clone();
    two.extend([0u8, 1, 2, 0]);
    let idx = raw_json(
        "",
        r#",{"bufferView":1,"componentType":5121,"count":4,"type":"SCALAR"}"#,
        r#",{"buffer":0,"byteOffset":36,"byteLength":4}"#,
        "",
    )
    .replace(r#""POSITION":0}"#, r#""POSITION":0},"indices":1"#);
    refused_with(d, &idx, &two, &["4 indices", "not whole triangles"]);
    let mut far = bin.clone();
    far.extend([0u8, 1, 9]);
    let idx = idx
        .replace(r#""count":4"#, r#""count":3"#)
        .replace(r#""byteLength":4}"#, r#""byteLength":3}"#);
    refused_with(d, &idx, &far, &["index 2 is 9, past its 3 vertices"]);
    // A non-finite normal.
    let mut bad = bin.clone();
    bad.extend(floats(&[0.0, 0.0, 1.0, f32::NAN, 0.0, 1.0, 0.0, 0.0, 1.0]));
    let nrm = raw_json(
        r#","NORMAL":1"#,
        r#",{"bufferView":1,"componentType":5126,"count":3,"type":"VEC3"}"#,
        r#",{"buffer":0,"byteOffset":36,"byteLength":36}"#,
        "",
    );
    refused_with(
        d,
        &nrm,
        &bad,
        &["NORMAL (accessor 1)", "element 1", "not finite"],
    );
}

#[test]
fn strided_and_normalised_data_read_as_the_specification_says() {
    let dir = tempfile::tempdir().unwrap();
    // Positions interleaved with 4 bytes of padding (stride 16), texture coordinates as
    // normalised u16.
    let mut bin = Vec::new();
    for v in TRI.chunks(3) {
        bin.extend(floats(v));
        bin.extend([0xffu8; 4]);
    }
    for uv in [[0u16, 0], [65535, 0], [0, 32768]] {
        bin.extend(uv.iter().flat_map(|x| x.to_le_bytes()));
    }
    let json = raw_json(
        r#","TEXCOORD_0":1"#,
        r#",{"bufferView":1,"componentType":5123,"normalized":true,"count":3,"type":"VEC2"}"#,
        r#",{"buffer":0,"byteOffset":48,"byteLength":12}"#,
        r#""extras":[1,2],"#,
    )
    .replace(r#""byteLength":36}"#, r#""byteLength":48,"byteStride":16}"#);
    let path = write_raw(dir.path(), &json, &bin);
    let mesh = Mesh::load(&path).unwrap();
    assert_eq!(mesh.tris.len(), 1);
    let t = &mesh.tris[0];
    assert_eq!(t.p, [Vec3::ZERO, Vec3::X, Vec3::Y]);
    // v = 1 − v (the OBJ convention).
    assert!((t.uv[1].x - 1.0).abs() < 1e-6 && (t.uv[1].y - 1.0).abs() < 1e-6);
    assert!((t.uv[2].y - (1.0 - 32768.0 / 65535.0)).abs() < 1e-6);
}

#[test]
fn node_transforms_and_materials_outside_the_specification_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bin = floats(&TRI);
    let node = |n: &str| raw_json("", "", "", "").replace(r#"{"mesh":0}"#, n);
    let cases: [(&str, &[&str]); 6] = [
        (
            r#"{"mesh":0,"rotation":[0,0,0,0]}"#,
            &["node 0", "not a unit quaternion", "length 0"],
        ),
        (
            r#"{"mesh":0,"rotation":[0,0,0,2]}"#,
            &["not a unit quaternion"],
        ),
        (r#"{"mesh":0,"scale":[1,0,1]}"#, &["scale", "has a 0"]),
        (
            r#"{"mesh":0,"matrix":[1,0,0,0, 0,1,0,0, 0,0,0,0, 0,0,0,1]}"#,
            &["singular"],
        ),
        (
            r#"{"mesh":0,"matrix":[1,0,0,0, 0,1,0,0, 0,0,1,1, 0,0,0,1]}"#,
            &["last row", "affine"],
        ),
        (
            r#"{"mesh":0,"translation":[1e39,0,0]}"#,
            &["node 0", "not finite"],
        ),
    ];
    for (n, causes) in cases {
        refused_with(d, &node(n), &bin, causes);
    }
    // A rotation rounded by an exporter (length 1 + 2e-4) is taken, normalised.
    let path = write_raw(d, &node(r#"{"mesh":0,"rotation":[0,0,0,1.0002]}"#), &bin);
    assert_eq!(Mesh::load(&path).unwrap().tris[0].p[1], Vec3::X);
    let material = |m: &str| {
        raw_json("", "", "", &format!(r#""materials":[{m}],"#))
            .replace(r#""POSITION":0}"#, r#""POSITION":0},"material":0"#)
    };
    refused_with(
        d,
        &material(r#"{"name":"leaf","alphaMode":"MASK","alphaCutoff":-0.5}"#),
        &bin,
        &["\"leaf\"", "alphaCutoff -0.5", "outside [0, 1]"],
    );
    refused_with(
        d,
        &material(r#"{"name":"bark","pbrMetallicRoughness":{"baseColorFactor":[2,0,0,1]}}"#),
        &bin,
        &["\"bark\"", "baseColorFactor"],
    );
}

#[test]
fn a_clamped_texture_is_refused_only_where_coordinates_leave_the_unit_square() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    image::RgbaImage::from_pixel(4, 4, image::Rgba([80, 150, 60, 255]))
        .save(d.join("leaf.png"))
        .unwrap();
    let json = |uv_max: f32| {
        let mut bin = floats(&TRI);
        bin.extend(floats(&[0.0, 0.0, uv_max, 0.0, 0.0, uv_max]));
        let json = raw_json(
            r#","TEXCOORD_0":1"#,
            r#",{"bufferView":1,"componentType":5126,"count":3,"type":"VEC2"}"#,
            r#",{"buffer":0,"byteOffset":36,"byteLength":24}"#,
            r#""materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],
            "textures":[{"source":0,"sampler":0}],"images":[{"uri":"leaf.png"}],
            "samplers":[{"wrapS":33071,"wrapT":33648}],"#,
        )
        .replace(r#"}}]}]"#, r#"},"material":0}]}]"#);
        (json, bin)
    };
    let (j, b) = json(1.0);
    let path = write_raw(d, &j, &b);
    assert_eq!(Mesh::load(&path).unwrap().tris.len(), 1);
    let (j, b) = json(2.5);
    refused_with(
        d,
        &j,
        &b,
        &["ClampToEdge", "MirroredRepeat", "reaches 2.5", "repeats"],
    );
}

#[test]
fn what_the_bake_leaves_out_is_noted_and_the_rest_loads() {
    let dir = tempfile::tempdir().unwrap();
    let bin = floats(&TRI);
    let json = raw_json(
        "",
        "",
        "",
        r#""extensionsUsed":["KHR_materials_emissive_strength"],
        "animations":[{"channels":[{"sampler":0,"target":{"node":0,"path":"translation"}}],
          "samplers":[{"input":0,"output":0}]}],
        "cameras":[{"type":"perspective","perspective":{"yfov":1.0,"znear":0.1}}],
        "materials":[{"name":"leaf","doubleSided":false,"normalTexture":{"index":0}}],
        "textures":[{"source":0}],"images":[{"uri":"n.png"}],
        "extras":{"exporter":"test"},"#,
    )
    .replace(r#""POSITION":0}"#, r#""POSITION":0},"material":0"#);
    let path = write_raw(dir.path(), &json, &bin);
    let mesh = Mesh::load(&path).unwrap();
    assert_eq!(mesh.tris.len(), 1);
    let notes = mesh.notes.join("\n");
    for n in [
        "1 animation ignored",
        "1 camera ignored",
        "single-sided",
        "normal",
        "KHR_materials_emissive_strength",
    ] {
        assert!(notes.contains(n), "expected {n:?} in the notes:\n{notes}");
    }
}
