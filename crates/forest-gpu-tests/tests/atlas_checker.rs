//! The atlas checker under hostile single-field mutations of a good atlas: each mutated atlas
//! is either refused, or loads into exactly what the original loads into (the decoded images
//! and the tables every method draws from), so it renders the same. Never is a broken file
//! accepted into a different image. Mutations: every leaf of `manifest.json` set to values
//! of the wrong sign, size or type, removed, or (integers) moved by one; the words of the
//! `model.bin` header set to hostile values; and each image cut short, replaced by one of
//! another size, or by bytes that are no image. CPU only: nothing here needs the GPU.

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use forest_format::Atlas;
use forest_format::model::{MODEL_FILE, PreparedModel};
use forest_render::scene::{SceneTables, SpeciesData};
use proptest::prelude::*;
use serde_json::Value;

/// The bush's atlas as its files, with its prepared model.
fn files() -> &'static BTreeMap<String, Vec<u8>> {
    static F: std::sync::OnceLock<BTreeMap<String, Vec<u8>>> = std::sync::OnceLock::new();
    F.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bush.atlas");
        let mesh =
            forest_bake::Mesh::load(&common::root().join("assets/trees/bush/bush.obj")).unwrap();
        let model = forest_bake::model::prepare(&mesh, None).encode();
        common::atlases()[0]
            .save_with_model(&path, Some(&model))
            .unwrap();
        std::fs::read_dir(&path)
            .unwrap()
            .flatten()
            .map(|e| {
                let name = e.file_name().to_string_lossy().into_owned();
                (name, std::fs::read(e.path()).unwrap())
            })
            .collect()
    })
}

/// What the renderer gets from an atlas's files: the decoded species and the tables of a
/// small forest of it and the pine, as one comparable text; or the loader's error.
fn loaded(files: &BTreeMap<String, Vec<u8>>) -> Result<String, String> {
    let path = Path::new("bush.atlas");
    let read = |name: &str| {
        files
            .get(name)
            .cloned()
            .ok_or_else(|| forest_format::FormatError::invalid(path.join(name), "missing"))
    };
    let atlas = Atlas::from_files(path, &read).map_err(|e| e.to_string())?;
    // The prepared model, checked against its atlas as every loader checks it.
    let model = PreparedModel::decode(&files[MODEL_FILE], &path.join(MODEL_FILE))
        .map_err(|e| e.to_string())?;
    model
        .check_atlas(path, &atlas.manifest)
        .map_err(|e| e.to_string())?;
    let manifest = format!("{:?}", atlas.manifest.bounding_sphere);
    let bush = SpeciesData::decode(atlas, path).map_err(|e| e.to_string())?;
    let pine = common::species().swap_remove(1);
    let tables =
        SceneTables::new(&[bush.clone(), pine], &common::forest(6)).map_err(|e| e.to_string())?;
    Ok(format!(
        "{manifest}{:?}{:?}{:?}{:?}",
        bush.layers, bush.surface, bush.opacity, tables
    ))
}

/// The original's load, once.
fn original() -> &'static str {
    static O: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    O.get_or_init(|| loaded(files()).expect("the good atlas loads"))
}

/// Every leaf of `v` as a JSON pointer, with the keys that hold objects (removable).
fn leaves(v: &Value, at: String, out: &mut Vec<String>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                leaves(x, format!("{at}/{k}"), out);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                leaves(x, format!("{at}/{i}"), out);
            }
        }
        _ => out.push(at),
    }
}

/// The hostile values a leaf holding `v` is set to; `None` removes it.
fn hostile(v: &Value) -> Vec<Option<Value>> {
    let mut out = vec![
        None,
        Some(Value::Null),
        Some(serde_json::json!("x")),
        Some(serde_json::json!(-1)),
        Some(serde_json::json!(0)),
        Some(serde_json::json!(1e30)),
        Some(serde_json::json!(-1e30)),
        Some(serde_json::json!(4294967296u64)),
        Some(serde_json::json!([1])),
    ];
    if let Some(n) = v.as_u64() {
        out.push(Some(serde_json::json!(n + 1)));
        if n > 0 {
            out.push(Some(serde_json::json!(n - 1)));
        }
    }
    if v.is_string() {
        out.push(Some(serde_json::json!("")));
        out.push(Some(serde_json::json!("../../escaped")));
    }
    out
}

/// The manifest with the leaf at `pointer` set to `value` (removed when `None`).
fn mutated_manifest(pointer: &str, value: Option<Value>) -> Vec<u8> {
    let mut m: Value = serde_json::from_slice(&files()["manifest.json"]).unwrap();
    let (parent, key) = pointer.rsplit_once('/').unwrap();
    let holder = m.pointer_mut(parent).unwrap();
    match (holder, value) {
        (Value::Object(o), None) => {
            o.remove(key);
        }
        (Value::Array(a), None) => {
            a.remove(key.parse::<usize>().unwrap());
        }
        (h, Some(v)) => *h.pointer_mut(&format!("/{key}")).unwrap() = v,
        (_, None) => unreachable!("leaves sit in objects and arrays"),
    }
    serde_json::to_vec_pretty(&m).unwrap()
}

/// Refused, or loaded into exactly the original.
fn refused_or_same(files: &BTreeMap<String, Vec<u8>>, what: &str) -> Result<(), TestCaseError> {
    if let Ok(got) = loaded(files) {
        prop_assert!(got == original(), "{what}: accepted, and loads differently");
    }
    Ok(())
}

/// Every leaf of the manifest set to every hostile value, or removed: each refused, or
/// loaded into exactly the original (some are: the source file's name, say).
#[test]
fn every_manifest_field_made_hostile_is_refused_or_changes_nothing() {
    let manifest: Value = serde_json::from_slice(&files()["manifest.json"]).unwrap();
    let (mut refused, mut same) = (0, 0);
    for pointer in manifest_leaves() {
        for value in hostile(manifest.pointer(pointer).unwrap()) {
            let mut f = files().clone();
            f.insert(
                "manifest.json".into(),
                mutated_manifest(pointer, value.clone()),
            );
            match loaded(&f) {
                Err(_) => refused += 1,
                Ok(got) => {
                    assert!(
                        got == original(),
                        "manifest {pointer} = {value:?}: accepted, and loads differently"
                    );
                    same += 1;
                }
            }
        }
    }
    assert!(
        refused > 1000 && same > 0,
        "{refused} refused, {same} the same"
    );
}

fn manifest_leaves() -> &'static [String] {
    static L: std::sync::OnceLock<Vec<String>> = std::sync::OnceLock::new();
    L.get_or_init(|| {
        let m: Value = serde_json::from_slice(&files()["manifest.json"]).unwrap();
        let mut out = Vec::new();
        leaves(&m, String::new(), &mut out);
        out
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn a_model_header_word_made_hostile_is_refused_or_changes_nothing(
        // Magic and version (3 words), the 21 header words, the checksum (2 words).
        word in 0usize..26,
        value in prop_oneof![
            prop::sample::select(vec![
                0u32, 1, 2, 3, u32::MAX, 1 << 31, 0x7FC0_0000, 0x7F80_0000, 0xFF80_0000,
                (-1.0f32).to_bits(), 1e30f32.to_bits(), 1e-30f32.to_bits(),
            ]),
            any::<u32>(),
        ],
    ) {
        let mut f = files().clone();
        let bytes = f.get_mut(MODEL_FILE).unwrap();
        bytes[4 * word..4 * word + 4].copy_from_slice(&value.to_le_bytes());
        refused_or_same(&f, &format!("model.bin word {word} = {value:#x}"))?;
    }

    #[test]
    fn an_image_cut_short_resized_or_replaced_is_refused_or_changes_nothing(
        file in prop::sample::select(vec!["colour.jpg", "alpha.png", "surface.png", "opacity.png"]),
        how in 0u8..3,
        cut in 0.0f64..1.0,
    ) {
        let mut f = files().clone();
        let bytes = f[file].clone();
        let replaced = match how {
            // Cut short anywhere.
            0 => bytes[..(cut * bytes.len() as f64) as usize].to_vec(),
            // A good image of another size, in the file's own format.
            1 => {
                let img = image::RgbaImage::from_pixel(9, 7, image::Rgba([10, 200, 30, 255]));
                let format = image::ImageFormat::from_path(file).unwrap();
                let img = image::DynamicImage::ImageRgba8(img);
                let img = if format == image::ImageFormat::Jpeg {
                    image::DynamicImage::ImageRgb8(img.to_rgb8())
                } else {
                    img
                };
                let mut out = std::io::Cursor::new(Vec::new());
                img.write_to(&mut out, format).unwrap();
                out.into_inner()
            }
            // No image at all.
            _ => b"not an image".to_vec(),
        };
        f.insert(file.into(), replaced);
        refused_or_same(&f, &format!("{file} mutated by {how} at {cut}"))?;
    }
}
