//! Host mirrors of the geometry renderer's WGSL structs (`shaders/geometry_types.wgsl`);
//! sizes and offsets are checked against naga's reflection of the WGSL by a test.

use bytemuck::{Pod, Zeroable};

/// A species of the geometry-based methods (176 bytes; `GeoSpecies` in
/// `shaders/geometry_types.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuGeoSpecies {
    /// Bounding sphere (object space): centre, radius (metres).
    pub sphere: [f32; 4],
    /// First vertex of LOD 0, 1, 2; first billboard layer.
    pub lod_first: [u32; 4],
    /// Vertex counts of LOD 0, 1, 2; unused.
    pub lod_count: [u32; 4],
    /// Branch vertices at the start of LOD 0.
    pub branch_vertices: u32,
    /// Leaves (stochastic elements) N.
    pub leaves: u32,
    /// Offset of the species' leaves in the leaf-end and leaf-centre buffers.
    pub leaf_base: u32,
    /// `r` of the area-preservation factor.
    pub r: f32,
    /// Mean shaded leaf colour (linear RGB) for contrast preservation.
    pub mean_leaf: [f32; 3],
    /// The hybrid's switch unit ([`forest_render::extend::switch_unit`]).
    pub switch_unit: f32,
    /// Optical depth per voxel length of the species' opacity-volume code 255 (0: no
    /// self-shadowing; see [`forest_format::opacity`]).
    pub opacity_depth: f32,
    /// Where the hybrid's near trees are drawn in mesh LOD 1 and LOD 2, as fractions of the
    /// switch distance (0: never; [`crate::geometry::GeometrySpecies::lod_from`]).
    pub lod_from: [f32; 2],
    /// Padding to 16 bytes.
    pub pad: u32,
    /// The species' colours in the forest ([`forest_format::colour::TreeColour`]; set when the
    /// models are uploaded for a forest).
    pub colour: forest_format::colour::TreeColour,
}

/// The mip bias that makes every lookup read a texture's finest level (WGSL clamps biases to
/// [-16, 15.99], and no texture here has 2¹⁶ texels a side).
pub const FINEST_TEXTURES: f32 = -16.0;

/// The geometry method and its parameters (48 bytes; `Method` in
/// `shaders/geometry_types.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuMethod {
    /// 0 full geometry, 1 stochastic simplification, 2 discrete LODs + billboards.
    pub mode: u32,
    /// Full geometry: draw the nearest distance bands first (0/1). Full geometry and the
    /// LODs: draw each tree's triangles in the presorted order of its view direction (0/1;
    /// ignored under stochastic simplification).
    pub depth_sort: u32,
    /// Stochastic: area preservation on (0/1).
    pub area: u32,
    /// Stochastic: contrast preservation on (0/1).
    pub contrast: u32,
    /// Stochastic: full detail up to this object-space distance (metres).
    pub d0: f32,
    /// Stochastic: `ln ½ / ln h`.
    pub exponent: f32,
    /// Stochastic: fading width (fraction of λ).
    pub fade: f32,
    /// Mip bias of the material textures' lookups: 0, or [`FINEST_TEXTURES`] for the
    /// reference.
    pub texture_bias: f32,
    /// LODs: object-space distances where LOD 1, LOD 2 and billboards start; w unused.
    pub lod: [f32; 4],
}

/// A material of the geometry renderer (32 bytes; `GeoMaterial`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuGeoMaterial {
    /// Kd (linear RGB) and translucency.
    pub kd: [f32; 4],
    /// Texture layer (`u32::MAX`: none).
    pub layer: u32,
    /// Alpha tested (0/1).
    pub alpha_tested: u32,
    /// Padding.
    pub pad: [u32; 2],
}
