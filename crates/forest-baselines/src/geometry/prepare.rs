//! The CPU preparation of the geometry-based methods: reference vertices with traced sky
//! visibility, the LOD set, billboard images, material layers and opacity volumes (the bake's
//! tracer, simplifier and voxeliser do the work). Nothing here depends on the light: renderers light at run time.

use forest_bake::RefVertex;
use forest_bake::lod::LodParams;
use forest_format::opacity::{OpacityVolume, VOLUME_RESOLUTION};

use super::params::{GeometrySpecies, SpeciesFigures};
use super::textures::{layer_bytes, material_layer};
use crate::gpu_types::{GpuGeoMaterial, GpuGeoSpecies};

/// Billboard image side (texels) and samples per texel.
pub const BILLBOARD_RESOLUTION: u32 = 256;
const BILLBOARD_SPP: u32 = 4;
const NONE: u32 = u32::MAX;

/// The CPU preparation of the species (reference vertices with traced sky visibility, LOD set,
/// billboard images), reusable for any forest of these species and any light.
#[derive(Clone)]
pub struct PreparedGeometry {
    pub(super) vertices: Vec<RefVertex>,
    pub(super) geo_species: Vec<GpuGeoSpecies>,
    pub(super) materials: Vec<GpuGeoMaterial>,
    pub(super) layers: Vec<image::RgbaImage>,
    pub(super) billboard_layers: Vec<image::RgbaImage>,
    pub(super) billboard_surface: Vec<image::RgbaImage>,
    pub(super) leaf_end: Vec<u32>,
    pub(super) leaf_centre: Vec<[f32; 4]>,
    pub(super) opacity: Vec<OpacityVolume>,
    /// Per-species figures.
    pub figures: Vec<SpeciesFigures>,
}

impl PreparedGeometry {
    /// Prepare every species (seconds per species: the sky-visibility and billboard rays).
    pub fn new(species: &[GeometrySpecies]) -> Self {
        let mut vertices: Vec<RefVertex> = Vec::new();
        let mut geo_species = Vec::new();
        let mut materials = Vec::new();
        let mut layers: Vec<image::RgbaImage> = Vec::new();
        let mut billboard_layers: Vec<image::RgbaImage> = Vec::new();
        let mut billboard_surface: Vec<image::RgbaImage> = Vec::new();
        let mut leaf_end: Vec<u32> = Vec::new();
        let mut leaf_centre: Vec<[f32; 4]> = Vec::new();
        let mut figures = Vec::new();
        let mut opacity = Vec::new();
        for s in species {
            let material_base = materials.len() as u32;
            let (layers_base, billboards_base, vertices_base, leaves_base) = (
                layers.len(),
                billboard_layers.len(),
                vertices.len(),
                leaf_end.len(),
            );
            for m in &s.mesh.materials {
                let layer = if m.colour.is_some() || m.alpha.is_some() {
                    layers.push(material_layer(&s.mesh, m.colour, m.alpha));
                    layers.len() as u32 - 1
                } else {
                    NONE
                };
                materials.push(GpuGeoMaterial {
                    kd: m.kd.extend(m.translucency).to_array(),
                    layer,
                    alpha_tested: u32::from(m.alpha.is_some()),
                    pad: [0; 2],
                });
            }
            let traced;
            let sky = match &s.sky {
                Some(sky) => sky,
                None => {
                    traced =
                        forest_bake::sky::triangle_sky(&forest_bake::trace::Scene::new(&s.mesh));
                    &traced
                }
            };
            let reference = forest_bake::reference_vertices(&s.mesh, sky);
            let leaf: Vec<bool> = reference
                .chunks_exact(3)
                .map(|t| s.mesh.materials[t[0].material as usize].alpha.is_some())
                .collect();
            let set = forest_bake::lod::build_lods(&reference, &leaf, &LodParams::default());
            let mean = forest_bake::lod::mean_leaf_colour(&s.mesh, &set.lod0);
            let sphere = forest_bake::bounding_sphere(&s.mesh);
            // The bake's volume of the same model: the same self-shadowing as its quads.
            let volume = forest_bake::opacity::opacity_volume(&s.mesh, &sphere, VOLUME_RESOLUTION);
            let first = vertices.len() as u32;
            let counts = [
                set.lod0.len() as u32,
                set.lods[0].len() as u32,
                set.lods[1].len() as u32,
            ];
            geo_species.push(GpuGeoSpecies {
                sphere: sphere.center.extend(sphere.radius).to_array(),
                lod_first: [
                    first,
                    first + counts[0],
                    first + counts[0] + counts[1],
                    billboard_layers.len() as u32,
                ],
                lod_count: [counts[0], counts[1], counts[2], 6],
                branch_vertices: set.branch_vertices,
                leaves: set.leaf_end.len() as u32,
                leaf_base: leaf_end.len() as u32,
                r: set.r,
                mean_leaf: mean.to_array(),
                switch_unit: s.switch_unit,
                opacity_depth: volume.max_depth,
                pad: [0; 3],
            });
            opacity.push(volume);
            leaf_end.extend(&set.leaf_end);
            leaf_centre.extend(set.leaf_centre.iter().map(|c| c.extend(0.0).to_array()));
            for b in forest_bake::lod::billboard_images(
                &s.mesh,
                sky,
                BILLBOARD_RESOLUTION,
                BILLBOARD_SPP,
            ) {
                billboard_layers.push(b.albedo);
                billboard_surface.push(b.surface);
            }
            for v in set.lod0.iter().chain(&set.lods[0]).chain(&set.lods[1]) {
                vertices.push(RefVertex {
                    material: v.material + material_base,
                    ..*v
                });
            }
            let leaves = leaf_end.len() - leaves_base;
            figures.push(SpeciesFigures {
                lod_triangles: counts.map(|c| u64::from(c) / 3),
                leaves: leaves as u32,
                r: set.r,
                model_bytes: (std::mem::size_of_val(&vertices[vertices_base..])
                    + std::mem::size_of::<GpuGeoSpecies>()
                    + std::mem::size_of_val(&materials[material_base as usize..])
                    + std::mem::size_of_val(&leaf_end[leaves_base..])
                    + std::mem::size_of_val(&leaf_centre[leaves_base..]))
                    as u64
                    + u64::from(VOLUME_RESOLUTION).pow(3)
                    + layer_bytes(&layers[layers_base..])
                    + 2 * layer_bytes(&billboard_layers[billboards_base..]),
            });
        }
        Self {
            vertices,
            geo_species,
            materials,
            layers,
            billboard_layers,
            billboard_surface,
            leaf_end,
            leaf_centre,
            opacity,
            figures,
        }
    }

    /// A copy without self-shadowing (every species' opacity volume left out): for measuring
    /// what the self-shadowing contributes (tests, experiments).
    pub fn without_self_shadowing(&self) -> Self {
        let mut out = self.clone();
        out.geo_species
            .iter_mut()
            .for_each(|s| s.opacity_depth = 0.0);
        out
    }

    /// A copy with every vertex's traced sky visibility (both sides) replaced by
    /// `f(visibility)`: for measuring what the occlusion contributes (tests, experiments).
    pub fn map_sky_visibility(&self, f: impl Fn(f32) -> f32) -> Self {
        let mut out = self.clone();
        out.vertices.iter_mut().for_each(|v| {
            v.sky_front = f(v.sky_front);
            v.sky_back = f(v.sky_back);
        });
        out
    }

    /// Bytes of the model data uploaded for all species: vertices, tables, material and
    /// billboard textures with mips (what the geometry methods store per species, not per tree).
    pub fn model_bytes(&self) -> u64 {
        self.figures.iter().map(|f| f.model_bytes).sum()
    }
}
