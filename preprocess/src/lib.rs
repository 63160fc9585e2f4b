//! The offline bake: a tree model (OBJ) → slab images from sampling directions over the upper
//! hemisphere → a quad hierarchy per slab image → an [`Atlas`].
//!
//! ```text
//! Mesh::load ─► Scene::new (BVH) ─► ldi::trace_layers ─► quadtree::build_layer (per layer)
//!            ─► number nodes level by level ─► Atlas::from_layers ─► Atlas::save (atomic)
//! ```
//! Everything is deterministic: the same input gives a byte-identical atlas.
//!
//! Baking a model (OBJ or glTF) into an atlas folder, as `forest bake` does:
//!
//! ```no_run
//! use forest_format::BakeParams;
//!
//! let params = BakeParams { resolution: 128, ..BakeParams::default() };
//! let out = forest_bake::bake_file(
//!     std::path::Path::new("tree.glb"),
//!     &params,
//!     &|done, total| eprintln!("{done}/{total} rows"),
//! )?;
//! for note in &out.notes {
//!     eprintln!("note: {note}");
//! }
//! out.atlas.save(std::path::Path::new("tree.atlas"))?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![deny(missing_docs)]

pub mod contact_sheet;
pub mod cutout;
pub mod error;
pub mod gltf_accessor;
mod gltf_checks;
pub mod gltf_mesh;
pub mod ldi;
mod load;
pub mod lod;
pub mod mesh;
pub mod model;
mod obj_mesh;
pub mod opacity;
pub mod quadtree;
mod sampling;
pub mod shadowing;
pub mod sky;
pub mod texture;
pub mod trace;

use std::path::Path;
use std::time::Instant;

use forest_format::atlas::{Layers, SourceInfo, manifest_for};
use forest_format::node::{MAX_NODES, QuadNode};
use forest_format::slab::{Sphere, sphere_to_slab_depth};
use forest_format::{Atlas, BakeParams, FormatError};
use glam::Vec3;
use rayon::prelude::*;

pub use error::BakeError;
pub use load::source_files;
pub use mesh::Mesh;

/// Memory the bake may use for its images before it refuses (bytes).
pub const MAX_BAKE_MEMORY: u64 = 12 << 30;

/// What a bake produced, with the figures the CLI reports.
pub struct BakeOutput {
    /// The atlas (not yet saved).
    pub atlas: Atlas,
    /// The traced slab images, including per-pixel depth.
    pub images: ldi::SlabImages,
    /// Sky visibility of the mesh's triangles, in its order ([`sky::triangle_sky`]), which
    /// the geometry methods' preparation can reuse.
    pub sky: Vec<sky::TriangleSky>,
    /// Triangles baked.
    pub triangles: u64,
    /// Seconds spent (load, BVH, trace, hierarchy, encode).
    pub seconds: f64,
    /// The model loader's notes on what it left out ([`Mesh::notes`]).
    pub notes: Vec<String>,
}

/// Bounding sphere of the triangles: the centre of their box and the farthest vertex from it
/// (grown by a millionth so every vertex is strictly inside).
pub fn bounding_sphere(mesh: &Mesh) -> Sphere {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for t in &mesh.tris {
        for p in t.p {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    let center = 0.5 * (lo + hi);
    let radius = mesh
        .tris
        .iter()
        .flat_map(|t| t.p)
        .map(|p| p.distance(center))
        .fold(0.0f32, f32::max);
    Sphere {
        center,
        radius: (radius * (1.0 + 1e-6)).max(1e-6),
    }
}

/// Bake a model file. `progress(done, total)` reports traced image rows.
pub fn bake_file(
    path: &Path,
    params: &BakeParams,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<BakeOutput, BakeError> {
    params.validate()?;
    check_memory(params)?;
    let start = Instant::now();
    let mesh = Mesh::load(path)?;
    let file = path
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut out = bake_mesh(&mesh, &file, params, progress)?;
    out.seconds = start.elapsed().as_secs_f64();
    Ok(out)
}

fn check_memory(params: &BakeParams) -> Result<(), BakeError> {
    // RGBA8 + f32 depth per layer pixel, twice over (rows, then layers), plus the mosaics.
    let pixels = u64::from(params.layers()) * u64::from(params.resolution).pow(2);
    let bytes = pixels * (8 + 8 + 4);
    if bytes > MAX_BAKE_MEMORY {
        return Err(FormatError::Param(format!(
            "{} layers of {}² pixels need about {} GiB of memory, above the bake's {} GiB: lower \
             --resolution, --directions or --slabs",
            params.layers(),
            params.resolution,
            bytes >> 30,
            MAX_BAKE_MEMORY >> 30
        ))
        .into());
    }
    Ok(())
}

/// Bake an already loaded mesh (`file` is recorded in the manifest).
pub fn bake_mesh(
    mesh: &Mesh,
    file: &str,
    params: &BakeParams,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<BakeOutput, BakeError> {
    params.validate()?;
    check_memory(params)?;
    mesh.check_drawable(Path::new(file))?;
    let start = Instant::now();
    let sphere = bounding_sphere(mesh);
    let scene = trace::Scene::new(mesh);
    let dirs = forest_format::directions::sampling_directions(params.directions, params.below);
    let frames: Vec<_> = dirs
        .iter()
        .map(|&d| forest_format::slab::DirectionFrame::new(d))
        .collect();
    let setup = ldi::SlabSetup {
        sphere,
        frames: &frames,
        slabs: params.slabs,
        resolution: params.resolution,
        spp: params.spp,
    };
    let sky = sky::triangle_sky(&scene);
    let images = ldi::trace_layers(&scene, &sky, &setup, progress);

    // Quad hierarchies, one per layer, in parallel.
    let r2 = (params.resolution as usize).pow(2);
    let trees: Vec<quadtree::LayerTree> = (0..params.layers())
        .into_par_iter()
        .map(|layer| {
            let slab = layer % params.slabs;
            let range = layer as usize * r2..(layer as usize + 1) * r2;
            let alpha: Vec<u8> = images.rgba[range.start * 4..range.end * 4]
                .iter()
                .skip(3)
                .step_by(4)
                .copied()
                .collect();
            let depth: Vec<f32> = images.depth[range]
                .iter()
                .map(|&d| sphere_to_slab_depth(d, slab, params.slabs).clamp(0.0, 1.0))
                .collect();
            quadtree::build_layer(
                &alpha,
                &depth,
                params.resolution,
                params.min_quad,
                params.slabs,
                params.plane_fit,
            )
        })
        .collect();

    // Number the nodes level by level across layers; first children follow from the masks.
    let levels = params.levels() as usize;
    let total: u64 = trees
        .iter()
        .map(|t| t.levels.iter().map(|l| l.len() as u64).sum::<u64>())
        .sum();
    if total == 0 {
        return Err(BakeError::Model {
            path: file.into(),
            what: format!(
                "no texel of any of the {} layers is covered: the model draws nothing at \
                 --resolution {} (its surfaces are thinner than a texel, or their textures \
                 transparent where the rays hit them)",
                params.layers(),
                params.resolution
            ),
        });
    }
    if total > MAX_NODES {
        return Err(FormatError::Param(format!(
            "the bake produced {total} nodes, more than the format's {MAX_NODES}: lower \
             --resolution or raise --min-quad"
        ))
        .into());
    }
    let mut layer_roots = Vec::with_capacity(trees.len());
    let mut roots = 0u32;
    for t in &trees {
        layer_roots.push((!t.levels.is_empty()).then(|| {
            roots += 1;
            roots - 1
        }));
    }
    let mut nodes = Vec::with_capacity(total as usize);
    let mut nodes_per_level = vec![0u64; levels];
    let mut next_child = u64::from(roots);
    for (k, count) in nodes_per_level.iter_mut().enumerate() {
        for t in &trees {
            if let Some(level) = t.levels.get(k) {
                for n in level {
                    nodes.push(
                        QuadNode::new(n.mask, next_child as u32, n.depth).with_error(n.error),
                    );
                    next_child += u64::from(n.mask.count_ones());
                }
                *count += level.len() as u64;
            }
        }
    }
    debug_assert_eq!(next_child, total);

    let source = SourceInfo {
        file: file.into(),
        hash: format!("{:016x}", mesh.hash),
        triangles: mesh.tris.len() as u64,
        degenerate_triangles: mesh.degenerate,
        materials: mesh.materials.iter().map(|m| m.name.clone()).collect(),
        top: Some(
            mesh.tris
                .iter()
                .flat_map(|t| t.p)
                .map(|p| p.y)
                .fold(f32::NEG_INFINITY, f32::max),
        )
        .filter(|t| t.is_finite()),
        foot: Some(forest_format::model::footprint_radius(
            mesh.tris.iter().flat_map(|t| t.p).map(|p| p.to_array()),
        )),
    };
    let manifest = manifest_for(*params, source, sphere, layer_roots, nodes_per_level);
    let layers = Layers {
        resolution: params.resolution,
        count: params.layers(),
        rgba: images.rgba.clone(),
    };
    let surface = Layers {
        resolution: params.resolution,
        count: params.layers(),
        rgba: images.surface.clone(),
    };
    let volume = opacity::opacity_volume(mesh, &sphere, forest_format::opacity::VOLUME_RESOLUTION);
    let atlas = Atlas::from_layers(manifest, &layers, &surface, &volume, nodes)?;
    Ok(BakeOutput {
        atlas,
        images,
        sky,
        triangles: mesh.tris.len() as u64,
        seconds: start.elapsed().as_secs_f64(),
        notes: mesh.notes.clone(),
    })
}

/// Write per-pixel sphere depth (RGB) and coverage (A) of every layer as one EXR mosaic, laid
/// out like the colour mosaic. Written to a temporary name, then renamed.
pub fn write_depth_exr(path: &Path, out: &BakeOutput) -> Result<(), BakeError> {
    let p = &out.atlas.manifest.params;
    let (cols, res) = (p.mosaic_columns(), p.resolution as usize);
    let (w, h) = (cols as usize * res, p.mosaic_rows() as usize * res);
    let images = &out.images;
    let write = |tmp: &Path| {
        exr::prelude::write_rgba_file(tmp, w, h, |x, y| {
            let (tx, ty) = (x / res, y / res);
            let layer = ty * cols as usize + tx;
            if layer >= images.layers as usize {
                return (0.0f32, 0.0f32, 0.0f32, 0.0f32);
            }
            let i = (layer * res + y % res) * res + x % res;
            let d = images.depth[i];
            (d, d, d, f32::from(images.rgba[i * 4 + 3]) / 255.0)
        })
    };
    Ok(forest_format::atomic::write_with(path, write)?)
}

/// One vertex of the full-geometry reference (the prepared model's vertex).
pub use forest_format::model::RefVertex;

/// The full-geometry reference's vertices: the model's triangles, non-indexed (three vertices
/// per triangle, in the mesh's order), each corner with the sky visibility of both sides from
/// `sky` ([`sky::triangle_sky`] of the mesh, the same values the slab images are baked with).
/// No light: the renderers light them at run time.
///
/// # Panics
/// If `sky` does not have one entry per triangle of `mesh`.
pub fn reference_vertices(mesh: &Mesh, sky: &[sky::TriangleSky]) -> Vec<RefVertex> {
    assert_eq!(sky.len(), mesh.tris.len(), "one sky entry per triangle");
    mesh.tris
        .iter()
        .zip(sky)
        .flat_map(|(t, s)| {
            // Vertex normals turned to the front side, so that "the side the normal faces"
            // is the front one on the GPU as in the bake.
            let front = sky::front_normal(t);
            (0..3).map(move |k| {
                let n = if t.n[k].dot(front) >= 0.0 {
                    t.n[k]
                } else {
                    -t.n[k]
                };
                RefVertex {
                    pos: t.p[k].to_array(),
                    sky_front: s[0][k],
                    normal: n.to_array(),
                    material: t.material,
                    uv: t.uv[k].to_array(),
                    element: lod::NONE,
                    sky_back: s[1][k],
                }
            })
        })
        .collect()
}

/// An upper estimate of a bake's peak memory (bytes) for a model of `model_bytes` bytes of
/// OBJ text, built from what the bake holds at once and checked against measured peaks
/// (`forest bake --json` reports both; 1.1–1.5× the measured peak on the bundled models at
/// 128–1024 px, 1.37× on the 280k-triangle oak-dense; without the hybrid-switch measurement,
/// which `forest bake` adds its own estimate for): 52 B per layer pixel (the tracer's tiles
/// and the assembled slab images, RGBA8 + f32 depth each, the atlas's mosaics, decoded copies and
/// codec buffers), the quad-tree moments of the layers built at once (`threads` of them, 72 B per
/// finest quad and a third more for the coarser levels), about 10 B per byte of OBJ text for the
/// mesh and its BVH and 2 B more for one direction's piece footprints and tile bins (21 B per
/// piece), and 16 MiB for the program itself.
pub fn peak_bytes_estimate(
    params: &forest_format::BakeParams,
    model_bytes: u64,
    threads: u64,
) -> u64 {
    let r = u64::from(params.resolution);
    let layer_pixels = u64::from(params.layers()) * r * r;
    let finest = (r / u64::from(params.min_quad.max(1))).pow(2);
    let trees = threads.max(1).min(u64::from(params.layers())) * finest * 72 * 4 / 3;
    52 * layer_pixels + trees + 12 * model_bytes + (16 << 20)
}
