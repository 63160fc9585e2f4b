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
        covers: "atlas folder: manifest, colour, alpha and surface mosaics, nodes (`Atlas::load`)",
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

/// Files: manifest, colour mosaic, alpha mosaic, nodes, surface mosaic, opacity volume.
fn atlas(data: &[u8]) -> bool {
    let files = crate::split_files(data, 6);
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
    Atlas::from_files(Path::new("fuzz.atlas"), &read).is_ok()
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
