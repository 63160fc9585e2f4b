//! The atlas format on a synthetic atlas (no bake needed): save → load round trip, atomic
//! replacement, and a loader that names what is wrong.

use super::*;
use crate::slab::Sphere;

/// Premultiplied surface attributes for `layers`: every channel at most the coverage.
fn synthetic_surface(layers: &Layers) -> Layers {
    Layers {
        resolution: layers.resolution,
        count: layers.count,
        rgba: layers
            .rgba
            .chunks_exact(4)
            .enumerate()
            .flat_map(|(i, p)| [(i % 7) as u8 * 30, 128, 200, 90].map(|c| c.min(p[3])))
            .collect(),
    }
}

/// 5 directions × 2 slabs of 8×8 pixels, two levels, every layer a single root node with no
/// children.
fn synthetic(colour: ColourEncoding) -> (Atlas, Layers) {
    let params = BakeParams {
        directions: 5,
        below: 0,
        slabs: 2,
        resolution: 8,
        min_quad: 4,
        colour,
        ..BakeParams::default()
    };
    params.validate().unwrap();
    let n = params.layers();
    let rgba = (0..n * 64)
        .flat_map(|i| {
            let a = if i % 3 == 0 { 0u8 } else { 255 };
            let v = if a == 0 { 0 } else { (i % 251) as u8 };
            [v, v / 2, 255 - v, a].map(|c| c.min(a))
        })
        .collect();
    let layers = Layers {
        resolution: 8,
        count: n,
        rgba,
    };
    let surface = synthetic_surface(&layers);
    let nodes: Vec<QuadNode> = (0..n)
        .map(|l| QuadNode::new(0, 0, [l as u8, 10, 20, 30]))
        .collect();
    let manifest = manifest_for(
        params,
        SourceInfo {
            file: "synthetic.obj".into(),
            hash: "0".into(),
            triangles: 1,
            degenerate_triangles: 0,
            materials: vec!["leaf".into()],
            top: Some(6.5),
            foot: Some(0.25),
        },
        Sphere {
            center: glam::Vec3::Y,
            radius: 1.0,
        },
        (0..n).map(Some).collect(),
        vec![u64::from(n), 0],
    );
    (
        Atlas::from_layers(
            manifest,
            &layers,
            &surface,
            &crate::opacity::OpacityVolume::from_depths(
                crate::opacity::VOLUME_RESOLUTION,
                &(0..crate::opacity::VOLUME_RESOLUTION.pow(3))
                    .map(|i| (i % 5) as f32 * 0.1)
                    .collect::<Vec<_>>(),
            ),
            nodes,
        )
        .unwrap(),
        layers,
    )
}

#[test]
fn save_then_load_round_trips_and_replaces_atomically() {
    let (atlas, layers) = synthetic(ColourEncoding::Png);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.atlas");
    atlas.save(&path).unwrap();
    let back = Atlas::load(&path).unwrap();
    assert_eq!(back, atlas);
    // Lossless colour decodes to the layers, within one step (the decoder's rounding).
    let decoded = back.decode_layers(&path).unwrap();
    assert_eq!(
        (decoded.resolution, decoded.count),
        (layers.resolution, layers.count)
    );
    let worst = decoded
        .rgba
        .iter()
        .zip(&layers.rgba)
        .map(|(a, b)| a.abs_diff(*b))
        .max();
    assert_eq!(worst.map(|w| w <= 1), Some(true), "{worst:?}");
    // The surface mosaic is stored at 1/SURFACE_SCALE the resolution, losslessly: the
    // attributes come back as its filters give them back, within the coverage.
    let surface = back.decode_surface(&path, &decoded).unwrap();
    let expected = synthetic_surface(&layers)
        .surface_downsampled(&layers, SURFACE_SCALE)
        .surface_upsampled(&decoded, SURFACE_SCALE);
    assert!(
        surface.rgba == expected.rgba,
        "the surface round trip differs"
    );
    atlas.save(&path).unwrap();
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("s.atlas")]);
}

/// The synthetic atlas saved as `x.atlas` in a temporary folder (kept while the guard lives).
fn saved_synthetic() -> (Atlas, tempfile::TempDir, std::path::PathBuf) {
    let (atlas, _) = synthetic(ColourEncoding::Png);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.atlas");
    atlas.save(&path).unwrap();
    (atlas, dir, path)
}

#[test]
fn the_loader_names_what_is_wrong() {
    let (atlas, _dir, path) = saved_synthetic();
    let reset = || atlas.save(&path).unwrap();
    let err = |p: &Path| Atlas::load(p).unwrap_err().to_string();
    let manifest = path.join(MANIFEST_FILE);
    let text = std::fs::read_to_string(&manifest).unwrap();
    std::fs::write(&manifest, text.replace("\"version\": 4", "\"version\": 7")).unwrap();
    assert!(err(&path).contains("atlas version 7"), "{}", err(&path));
    // An atlas with baked light (version 2: a `lighting` field, the sun in its parameters) is
    // refused for what it is, not for its unknown fields.
    let old = text.replace("\"version\": 4", "\"version\": 2").replacen(
        "\"params\": {",
        "\"lighting\": {}, \"params\": {\"sun_azimuth_deg\": 30.0,",
        1,
    );
    std::fs::write(&manifest, old).unwrap();
    let e = err(&path);
    assert!(
        e.contains("atlas version 2") && e.contains("bake the model again"),
        "{e}"
    );
    assert!(e.contains("--sun"), "{e}");
    // Version 3 had run-time light but no opacity volume.
    let v3 =
        text.replace("\"version\": 4", "\"version\": 3")
            .replacen("\"opacity\"", "\"unknown\"", 1);
    std::fs::write(&manifest, v3).unwrap();
    let e = err(&path);
    assert!(
        e.contains("atlas version 3") && e.contains("opacity volume") && e.contains("bake"),
        "{e}"
    );
    reset();
    std::fs::remove_file(path.join(SURFACE_FILE)).unwrap();
    assert!(err(&path).contains(SURFACE_FILE), "{}", err(&path));
    reset();
    std::fs::write(path.join(OPACITY_FILE), b"not a png").unwrap();
    assert!(err(&path).contains(OPACITY_FILE), "{}", err(&path));
    reset();
    let bad_depth = text.replacen("\"max_depth\": ", "\"max_depth\": -", 1);
    std::fs::write(&manifest, bad_depth).unwrap();
    assert!(err(&path).contains("opacity.max_depth"), "{}", err(&path));
    reset();
    std::fs::write(&manifest, &text[..text.len() / 2]).unwrap();
    assert!(
        err(&path).contains("not a valid atlas manifest"),
        "{}",
        err(&path)
    );
    reset();
    let nodes = path.join(NODES_FILE);
    let bytes = std::fs::read(&nodes).unwrap();
    std::fs::write(&nodes, &bytes[..bytes.len() - 3]).unwrap();
    assert!(err(&path).contains(NODES_FILE), "{}", err(&path));
    reset();
    // A header claiming 16.7 M nodes (within the format) is refused by the manifest's count,
    // before anything is inflated.
    let mut forged = bytes.clone();
    forged[4..8].copy_from_slice(&((1u32 << 24) - 1).to_le_bytes());
    std::fs::write(&nodes, &forged).unwrap();
    assert!(err(&path).contains("claims"), "{}", err(&path));
    reset();
    std::fs::remove_file(path.join(ALPHA_FILE)).unwrap();
    assert!(err(&path).contains(ALPHA_FILE), "{}", err(&path));
}

/// The manifest's measured figures (the hybrid's switch, its tolerance, mesh-LOD bands, the
/// foot) round-trip, and out of their ranges are named.
#[test]
fn the_loader_names_bad_measured_figures() {
    let (atlas, dir, path) = saved_synthetic();
    let err = |p: &Path| Atlas::load(p).unwrap_err().to_string();
    let manifest = path.join(MANIFEST_FILE);
    // A measured hybrid switch round-trips; one outside its range is named.
    let mut measured = atlas.clone();
    measured.manifest.hybrid_switch = Some(HybridSwitch {
        finest_quad_pixels: 2.0,
        crown_radii: 2.03,
        viewport: [400, 300],
        fov_y_deg: 60.0,
        epsilon: 2.0,
        cameras: 6,
        tolerance: 0.25,
        lod_from: [Some(0.5), Some(0.75)],
        never_reached: true,
    });
    measured.save(&path).unwrap();
    assert_eq!(Atlas::load(&path).unwrap(), measured);
    let text = std::fs::read_to_string(&manifest).unwrap();
    std::fs::write(
        &manifest,
        text.replace(
            "\"finest_quad_pixels\": 2.0",
            "\"finest_quad_pixels\": -1.0",
        ),
    )
    .unwrap();
    assert!(
        err(&path).contains("finest_quad_pixels = -1"),
        "{}",
        err(&path)
    );
    // A tolerance out of its range is named; a record without one (older atlases) reads as 0.
    std::fs::write(
        &manifest,
        text.replace("\"tolerance\": 0.25", "\"tolerance\": -0.5"),
    )
    .unwrap();
    assert!(err(&path).contains("tolerance = -0.5"), "{}", err(&path));
    std::fs::write(&manifest, text.replace(",\n    \"tolerance\": 0.25", "")).unwrap();
    let older = Atlas::load(&path).unwrap();
    assert_eq!(older.manifest.hybrid_switch.map(|h| h.tolerance), Some(0.0));
    // Mesh-LOD bands outside (0, 1), or LOD 2 before LOD 1, are named; a record without
    // them (none measured, or an older atlas) reads as none.
    let with_lods = |from: serde_json::Value| {
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        v["hybrid_switch"]["lod_from"] = from;
        std::fs::write(&manifest, v.to_string()).unwrap();
    };
    for (from, cause) in [
        (serde_json::json!([0.5, 1.5]), "lod_from[1] = 1.5"),
        (serde_json::json!([0.0, null]), "lod_from[0] = 0"),
        (serde_json::json!([0.5, 0.25]), "LOD 2 starts before LOD 1"),
    ] {
        with_lods(from);
        assert!(err(&path).contains(cause), "{}", err(&path));
    }
    // A foot that is not a finite radius is named; one absent (older atlases) reads as none.
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["source"]["foot"] = serde_json::json!(-1.0);
    std::fs::write(&manifest, v.to_string()).unwrap();
    assert!(err(&path).contains("source.foot = -1"), "{}", err(&path));
    v["source"].as_object_mut().unwrap().remove("foot");
    std::fs::write(&manifest, v.to_string()).unwrap();
    assert_eq!(Atlas::load(&path).unwrap().manifest.source.foot, None);
    // A top at or below the foot, and an opacity volume denser than any crown, are named
    // (they once fell back to the sphere's top, and drew every crown black).
    for (field, value, cause) in [
        ("top", -2.0, "source.top = -2"),
        ("top", 0.0, "source.top = 0"),
        ("max_depth", 1e30, "optical depth per voxel of 0 to 100"),
        ("max_depth", -1.0, "opacity.max_depth = -1"),
    ] {
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        let section = if field == "top" { "source" } else { "opacity" };
        v[section][field] = serde_json::json!(value);
        std::fs::write(&manifest, v.to_string()).unwrap();
        assert!(err(&path).contains(cause), "{}", err(&path));
    }
    std::fs::write(&manifest, &text).unwrap();
    let lods = |path: &std::path::Path| {
        Atlas::load(path)
            .unwrap()
            .manifest
            .hybrid_switch
            .map(|h| h.lod_from)
    };
    with_lods(serde_json::json!([null, 0.25]));
    assert_eq!(lods(&path), Some([None, Some(0.25)]));
    let mut none = measured.clone();
    if let Some(h) = none.manifest.hybrid_switch.as_mut() {
        h.lod_from = [None; 2];
    }
    none.save(&path).unwrap();
    assert!(
        !std::fs::read_to_string(&manifest)
            .unwrap()
            .contains("lod_from")
    );
    assert_eq!(lods(&path), Some([None; 2]));
    // A switch the stream reached is written without `never_reached`, which reads as false.
    assert!(
        std::fs::read_to_string(&manifest)
            .unwrap()
            .contains("\"never_reached\": true")
    );
    if let Some(h) = none.manifest.hybrid_switch.as_mut() {
        h.never_reached = false;
    }
    none.save(&path).unwrap();
    assert!(
        !std::fs::read_to_string(&manifest)
            .unwrap()
            .contains("never_reached")
    );
    assert_eq!(Atlas::load(&path).unwrap(), none);
    assert!(err(&dir.path().join("none.atlas")).contains("no such atlas"));
}

#[test]
fn blank_pixels_are_filled_and_alpha_is_packed() {
    // 4×1: two covered pixels, two blank: the blanks take the covered pixels' colour.
    let mut rgb = vec![200, 100, 50, 0, 0, 0, 0, 0, 0, 100, 50, 200];
    let alpha = [255, 0, 0, 255];
    fill_blank(4, 1, &mut rgb, &alpha);
    assert!(rgb[3..9].iter().all(|&c| c > 0), "{rgb:?}");
    assert_eq!(
        (&rgb[..3], &rgb[9..]),
        (&[200, 100, 50][..], &[100, 50, 200][..])
    );
    // Two distinct values: a 1-bit indexed PNG (IHDR bit depth 1, colour type 3) that decodes
    // to the same coverage.
    let a: Vec<u8> = (0..64).map(|i| if i % 2 == 0 { 0 } else { 255 }).collect();
    let png = encode_alpha_png(8, 8, &a);
    let back = image::load_from_memory(&png).unwrap().to_luma8();
    assert_eq!(back.into_raw(), a);
    assert_eq!((png[24], png[25]), (1, 3));
}

#[test]
fn the_manifest_loads_alone_and_is_checked_as_in_a_full_load() {
    let (atlas, _) = synthetic(ColourEncoding::Png);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.atlas");
    atlas.save(&path).unwrap();
    // The images and nodes are not read: the manifest loads without them.
    std::fs::remove_file(path.join(NODES_FILE)).unwrap();
    std::fs::remove_file(path.join(ALPHA_FILE)).unwrap();
    assert_eq!(Atlas::load_manifest(&path).unwrap(), atlas.manifest);
    assert!(Atlas::load(&path).is_err());
    let manifest = path.join(MANIFEST_FILE);
    let text = std::fs::read_to_string(&manifest).unwrap();
    std::fs::write(&manifest, text.replace("\"version\": 4", "\"version\": 7")).unwrap();
    let e = Atlas::load_manifest(&path).unwrap_err().to_string();
    assert!(e.contains("atlas version 7"), "{e}");
    let e = Atlas::load_manifest(&dir.path().join("none.atlas"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("no such atlas"), "{e}");
}
