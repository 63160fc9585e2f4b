//! The fuzz targets: one per loader of user files. Each runs the loader exactly as the
//! command line does (the same functions, the same checks) on bytes instead of a path.

use std::path::Path;

use forest_format::atlas::{
    ALPHA_FILE, Atlas, MANIFEST_FILE, NODES_FILE, OPACITY_FILE, SURFACE_FILE,
};
use forest_format::camera_path::CameraPath;
use forest_format::forest::Forest;

/// A fuzz target: a name (its corpus folder), what it loads and the most bytes it may have
/// live at once on inputs up to [`MAX_INPUT`] bytes.
pub struct Target {
    /// Name: the corpus folder under `corpus/` and the driver's argument.
    pub name: &'static str,
    /// The loader, on arbitrary bytes; true when it accepted them. Errors are expected;
    /// panics, hangs and allocations past `bound` are failures.
    pub run: fn(&[u8]) -> bool,
    /// Allocation bound (bytes live at once, on top of what was live before).
    pub bound: usize,
    /// What the target covers, for the fuzzing table in docs/robustness.md.
    pub covers: &'static str,
}

/// The largest input the fuzzer feeds (AFL++'s own default maximum).
pub const MAX_INPUT: usize = 1 << 20;

/// Bound of the targets that decode images: the decoder's limit
/// ([`forest_format::bounded::limit::IMAGE_ALLOC`]) for the pixels as decoded and again for
/// their 8-bit RGBA copy, twice over for an atlas (colour and alpha mosaic, then the layers),
/// and 256 MiB for everything else.
const IMAGE_BOUND: usize = 4 * forest_format::bounded::limit::IMAGE_ALLOC as usize + (256 << 20);
/// Bound of the targets without images.
const DATA_BOUND: usize = 256 << 20;

/// Every target.
pub const TARGETS: &[Target] = &[
    Target {
        name: "forest_binary",
        run: forest_binary,
        bound: DATA_BOUND,
        covers: "forest file, binary (`Forest::load` of a `.forest`)",
    },
    Target {
        name: "forest_json",
        run: forest_json,
        bound: DATA_BOUND,
        covers: "forest file, JSON (`Forest::load` of a `.json`)",
    },
    Target {
        name: "camera_path",
        run: camera_path,
        bound: DATA_BOUND,
        covers: "camera path JSON (`render --path`, `bench`)",
    },
    Target {
        name: "nodes",
        run: nodes,
        bound: DATA_BOUND,
        covers: "an atlas's `nodes.bin` alone",
    },
    Target {
        name: "atlas",
        run: atlas,
        bound: IMAGE_BOUND,
        covers: "atlas folder: manifest, colour, alpha and surface mosaics, nodes, opacity volume (`Atlas::load`), and its `model.bin` checked against it (`PreparedModel::check_atlas`)",
    },
    Target {
        name: "obj",
        run: obj,
        bound: IMAGE_BOUND,
        covers: "OBJ + MTL + texture through the bake's loader (`Mesh::load`, `source_files`)",
    },
    Target {
        name: "gltf",
        run: gltf,
        bound: IMAGE_BOUND,
        covers: "glTF 2.0 (`.gltf` with its buffer and image files, or one `.glb`) through the bake's loader (`Mesh::load`, `source_files`)",
    },
    Target {
        name: "terrain",
        run: terrain,
        bound: IMAGE_BOUND,
        covers: "height field for `scene --terrain` (first byte: 0 a 16-bit PNG, else an EXR; then the file)",
    },
    Target {
        name: "model_bin",
        run: model_bin,
        bound: DATA_BOUND,
        covers: "an atlas's `model.bin` alone (`PreparedModel::decode`)",
    },
    Target {
        name: "results_csv",
        run: results_csv,
        bound: DATA_BOUND,
        covers: "`accuracy.csv` as `bench accuracy --redraw` reads it (`results_csv::read_accuracy`)",
    },
    Target {
        name: "wind",
        run: wind,
        bound: DATA_BOUND,
        covers: "`--wind`, `--wind-gustiness`, `--wind-time` and the displacement they give (`wind::parse_towards_speed`, `Wind::validate`, `Wind::swayed` within `Wind::reach_now`, itself within `Wind::reach`)",
    },
    Target {
        name: "image",
        run: image,
        bound: IMAGE_BOUND,
        covers: "images given to `compare` (PNG, JPEG), decoded and compared",
    },
];

/// The target called `name`.
pub fn target(name: &str) -> Option<&'static Target> {
    TARGETS.iter().find(|t| t.name == name)
}

fn forest_binary(data: &[u8]) -> bool {
    Forest::parse(Path::new("fuzz.forest"), data).is_ok()
}

fn forest_json(data: &[u8]) -> bool {
    Forest::parse(Path::new("fuzz.json"), data).is_ok()
}

fn camera_path(data: &[u8]) -> bool {
    CameraPath::parse(Path::new("fuzz.path.json"), data).is_ok()
}

fn nodes(data: &[u8]) -> bool {
    forest_format::nodes_codec::decode(data).is_ok()
}

/// Files: manifest, colour mosaic, alpha mosaic, nodes, surface mosaic, opacity volume, and
/// `model.bin` (none when empty), which must be the atlas's.
fn atlas(data: &[u8]) -> bool {
    let files = crate::split_files(data, 7);
    let read = |name: &str| -> Result<Vec<u8>, forest_format::FormatError> {
        Ok(match name {
            MANIFEST_FILE => files[0],
            ALPHA_FILE => files[2],
            NODES_FILE => files[3],
            SURFACE_FILE => files[4],
            OPACITY_FILE => files[5],
            _ => files[1],
        }
        .to_vec())
    };
    let Ok(atlas) = Atlas::from_files(Path::new("fuzz.atlas"), &read) else {
        return false;
    };
    if files[6].is_empty() {
        return true;
    }
    forest_format::model::PreparedModel::decode(files[6], Path::new("fuzz.atlas/model.bin"))
        .and_then(|m| m.check_atlas(Path::new("fuzz.atlas"), &atlas.manifest))
        .is_ok()
}

thread_local! {
    /// A folder per thread for the model targets' files (the loaders read paths; each run
    /// writes every file it names).
    static MODEL_DIR: tempfile::TempDir = tempfile::Builder::new()
        .prefix("forest-fuzz-model")
        .tempdir()
        .expect("a temporary folder for the model targets");
}

/// Files: `model.obj`, `model.mtl`, `leaf.png` (the names the seeds refer to).
fn obj(data: &[u8]) -> bool {
    let files = crate::split_files(data, 3);
    MODEL_DIR.with(|dir| {
        let path = dir.path().join("model.obj");
        for (name, bytes) in ["model.obj", "model.mtl", "leaf.png"].iter().zip(&files) {
            std::fs::write(dir.path().join(name), bytes).expect("writing a fuzz input file");
        }
        let _ = forest_bake::source_files(&path);
        forest_bake::Mesh::load(&path).is_ok()
    })
}

/// A binary glTF alone when the input starts with its magic (`model.glb`); else files
/// `model.gltf`, `model.bin`, `leaf.png` (the names the seeds refer to).
fn gltf(data: &[u8]) -> bool {
    MODEL_DIR.with(|dir| {
        let path = if data.starts_with(b"glTF") {
            let path = dir.path().join("model.glb");
            std::fs::write(&path, data).expect("writing a fuzz input file");
            path
        } else {
            let files = crate::split_files(data, 3);
            for (name, bytes) in ["model.gltf", "model.bin", "leaf.png"].iter().zip(&files) {
                std::fs::write(dir.path().join(name), bytes).expect("writing a fuzz input file");
            }
            dir.path().join("model.gltf")
        };
        let _ = forest_bake::source_files(&path);
        forest_bake::Mesh::load(&path).is_ok()
    })
}

/// A height field as `forest scene --terrain FILE` reads it: a PNG when the first byte is 0,
/// else an EXR.
fn terrain(data: &[u8]) -> bool {
    let Some((&kind, file)) = data.split_first() else {
        return false;
    };
    let name = if kind == 0 { "fuzz.png" } else { "fuzz.exr" };
    forest_format::terrain::Terrain::parse_image(Path::new(name), file, 2.0, 50.0).is_ok()
}

/// An image as `compare` reads it, then compared with itself when small (the metrics check
/// sizes and coverage; a large image only costs time).
fn image(data: &[u8]) -> bool {
    let Ok(img) = forest_format::bounded::decode_image(data, None, Path::new("fuzz.png")) else {
        return false;
    };
    let img = img.into_rgba8();
    img.width() as u64 * img.height() as u64 > 1 << 16
        || forest_metrics::compare(&img, &img).is_ok()
}

/// An atlas's `model.bin` alone (the atlas target checks one against its atlas).
fn model_bin(data: &[u8]) -> bool {
    forest_format::model::PreparedModel::decode(data, Path::new("fuzz.atlas/model.bin")).is_ok()
}

/// An `accuracy.csv` (the command line reads it as UTF-8 text).
fn results_csv(data: &[u8]) -> bool {
    std::str::from_utf8(data)
        .is_ok_and(|text| forest_format::results_csv::read_accuracy(text).is_ok())
}

/// Lines: `--wind`'s value, `--wind-gustiness`, `--wind-time`, then a tree and points as
/// numbers (foot x z, height, crown radius, seed, then x y z of each point). A wind that
/// passes its checks must move every point of the tree by a finite amount within the reach
/// its culls grow bounds by; a violation panics (a crash the fuzzer records).
fn wind(data: &[u8]) -> bool {
    use forest_format::wind::{SwayedTree, Wind, parse_towards_speed};
    let Ok(text) = std::str::from_utf8(data) else {
        return false;
    };
    let mut lines = text.lines();
    let Ok((towards_deg, speed)) = parse_towards_speed(lines.next().unwrap_or_default()) else {
        return false;
    };
    let mut number = || lines.next().and_then(|l| l.trim().parse::<f32>().ok());
    let (Some(gustiness), Some(time)) = (number(), number()) else {
        return false;
    };
    let w = Wind {
        towards_deg,
        speed,
        gustiness,
        time,
    };
    if w.validate().is_err() {
        return false;
    }
    let rest: Vec<f32> = lines
        .flat_map(str::split_whitespace)
        .filter_map(|v| v.parse().ok())
        .filter(|v: &f32| v.is_finite())
        .take(3 * 64 + 5)
        .collect();
    let at = |i: usize, default: f32| rest.get(i).copied().unwrap_or(default);
    // A tree as forests hold them: feet within the coordinate bound, sizes in metres.
    let bound = forest_format::limits::MAX_COORDINATE;
    let foot = glam::Vec3::new(
        at(0, 0.0).clamp(-bound, bound),
        0.0,
        at(1, 0.0).clamp(-bound, bound),
    );
    let height = at(2, 10.0).abs().clamp(0.01, 200.0);
    let radius = at(3, 4.0).abs().clamp(0.01, 200.0);
    let tree = SwayedTree {
        foot,
        height,
        radius,
        seed: at(4, 0.0).abs().min(u32::MAX as f32) as u32,
    };
    // The instant's reach, which the culls use, is within the static one.
    let reach = w.reach_now(&tree);
    assert!(
        reach <= w.reach(height) * (1.0 + 1e-4),
        "{w:?}, {tree:?}: reach now {reach} m over the static {} m",
        w.reach(height)
    );
    for p in rest.get(5..).unwrap_or_default().chunks_exact(3) {
        // Points of the tree: within its bounding sphere about the foot.
        let local = glam::Vec3::new(p[0], p[1], p[2]).clamp_length_max(height.max(radius));
        let q = foot + local;
        let moved = w.swayed(q, &tree);
        let d = (moved - q).length();
        // Rounding: a few ulps of the coordinates (1 m at 1e7 m from the origin).
        let ulps = 4.0 * f32::EPSILON * q.abs().max_element().max(moved.abs().max_element());
        assert!(
            moved.is_finite() && d <= reach * (1.0 + 1e-3) + 1e-3 + ulps,
            "{w:?}, {tree:?}: {q} moved {d} m, reach {reach} m"
        );
    }
    true
}
