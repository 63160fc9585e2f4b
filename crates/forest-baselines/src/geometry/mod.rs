//! The geometry-based methods in one renderer: full geometry (the ground-truth reference when
//! supersampled, the brute-force baseline at 1×, optionally depth-sorted by tree as in seed
//! 003), stochastic simplification (seeds 000/001) and discrete LODs + billboards (seed 004).
//!
//! ```text
//! per species, at bake: reference_vertices (per-vertex sky visibility, the bake's tracer)
//!   ─► lod::build_lods (LOD 0 = every triangle, leaves shuffled; LODs 1, 2) + billboards
//!   ─► the atlas's model.bin (forest_format::model), gathered by PreparedGeometry
//! per frame: geo_reset ─► geo_classify (frustum, distance band) ─► geo_args (offsets,
//!   indirect arguments per band × species) ─► geo_scatter ─► draw bands nearest first,
//!   each tree's triangles in the presorted order of its view direction (order.rs)
//! ```
//! The method is a uniform: [`GeometryRenderer::set_method`] switches at run time without
//! rebuilding anything. Every tree is shaded with `forest_format::shading` in its object
//! space, as the bake shades the atlases.

mod cards;
mod layout;
mod light;
mod models;
mod order;
mod params;
mod prepare;
mod renderer;
mod sources;
mod textures;
mod views;

pub use forest_format::model::BILLBOARD_RESOLUTION;
pub use layout::{COMPUTE_SLOTS, compute_entries, draw_entries};
pub use models::{GpuModels, check_limits};
pub use order::{
    ORDER_BINS, VIRTUAL_EYE_RADII, VISIBLE_ID_BITS, bin_direction, draw_orders, order_bin,
};
pub use params::{GeometrySpecies, GeometryStats, Lods, MeshMethod, SpeciesFigures, Stochastic};
pub use prepare::{Cards, PreparedGeometry};
pub use renderer::{GeometryRenderer, RESET_WG};
pub use sources::{
    MODEL_SPHERE_TOLERANCE, ModelSourceError, SourcedModels, check_model, models_for,
    prepare_models,
};
pub use textures::MATERIAL_TEXTURE_SIZE;

/// Box-filter an image rendered at `factor`× resolution down to its display size (in linear
/// space for colour, alpha averaged): the supersampled reference.
pub fn downsample(img: &image::RgbaImage, factor: u32) -> image::RgbaImage {
    let table = forest_format::shading::srgb_decode_table();
    let (w, h) = (img.width() / factor, img.height() / factor);
    image::RgbaImage::from_fn(w, h, |x, y| {
        let mut acc = [0f32; 4];
        for dy in 0..factor {
            for dx in 0..factor {
                let p = img.get_pixel(x * factor + dx, y * factor + dy);
                for c in 0..3 {
                    acc[c] += table[p[c] as usize];
                }
                acc[3] += f32::from(p[3]);
            }
        }
        let n = (factor * factor) as f32;
        let e = |v: f32| (forest_format::shading::srgb_encode(v / n) * 255.0).round() as u8;
        image::Rgba([e(acc[0]), e(acc[1]), e(acc[2]), (acc[3] / n).round() as u8])
    })
}
