//! The species' prepared models ([`forest_format::model`], made by the bake's tracer,
//! simplifier and voxeliser) gathered into the arrays the geometry renderer uploads. Nothing
//! here depends on the light: renderers light at run time.

use forest_format::model::{NONE, RefVertex};
use forest_format::opacity::{OpacityVolume, VOLUME_RESOLUTION};

use super::cards::{card_quads, cut_cards};
use super::params::{GeometrySpecies, SpeciesFigures};
use super::textures::{MipChain, layer_bytes, mip_chain};
use crate::gpu_types::{GpuGeoMaterial, GpuGeoSpecies};
use forest_render::context::RenderError;

/// How the geometry methods draw their alpha-tested leaf cards.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Cards {
    /// Each card that spans its whole texture is cut to the quadrilateral around what that
    /// texture can show (the default; the vertex count is unchanged): a third to a half of
    /// the bundled leaf cards' area, all of it fragments that would be shaded and discarded.
    /// See `geometry/cards.rs`.
    #[default]
    Cut,
    /// Every card drawn whole, as the model has it (for comparison).
    Whole,
}

/// The species' models gathered (reference vertices with traced sky visibility, LOD set,
/// billboard images), reusable for any forest of these species and any light.
#[derive(Clone)]
pub struct PreparedGeometry {
    pub(super) vertices: Vec<RefVertex>,
    pub(super) geo_species: Vec<GpuGeoSpecies>,
    pub(super) materials: Vec<GpuGeoMaterial>,
    /// Every species' material layers as their mip chains, computed once here (they cut the
    /// leaf cards and are uploaded as they are).
    pub(super) layer_mips: Vec<MipChain>,
    pub(super) billboard_layers: Vec<image::RgbaImage>,
    pub(super) billboard_surface: Vec<image::RgbaImage>,
    pub(super) leaf_end: Vec<u32>,
    pub(super) leaf_centre: Vec<[f32; 4]>,
    pub(super) opacity: Vec<OpacityVolume>,
    /// The triangles' presorted draw orders ([`super::order::draw_orders`]): every species'
    /// LODs sorted within themselves for each view-direction bin.
    pub(super) draw_order: Vec<u32>,
    /// Per-species figures.
    pub figures: Vec<SpeciesFigures>,
}

impl PreparedGeometry {
    /// Gather every species' prepared model into the arrays the renderer uploads (no tracing:
    /// the bake prepared them, [`forest_format::model`]), with the leaf cards cut
    /// ([`Cards::Cut`]).
    pub fn new(species: &[GeometrySpecies]) -> Self {
        Self::with_cards(species, Cards::Cut)
    }

    /// Bytes of the vertex buffer, the largest storage buffer the models need: 48 per vertex,
    /// 3 vertices per triangle of every species' LODs (see [`super::check_limits`]).
    pub fn vertex_bytes(&self) -> u64 {
        std::mem::size_of_val(self.vertices.as_slice()) as u64
    }

    /// Per species, where the hybrid draws its near trees in mesh LOD 1 and LOD 2 (fractions
    /// of the switch distance, 0: never).
    pub fn lod_from(&self) -> Vec<[f32; 2]> {
        self.geo_species.iter().map(|s| s.lod_from).collect()
    }

    /// Set where the hybrid draws species `species`' near trees in mesh LOD 1 and LOD 2, as
    /// fractions of the switch distance (0: never), overriding its atlas's measurement
    /// ([`GeometrySpecies::lod_from`]). Refused, naming the value, outside [0, 1) or with LOD
    /// 2 starting before LOD 1 (the manifest's rule, [`forest_format::atlas::check_lod_from`]),
    /// or for a species the models do not have.
    pub fn set_lod_from(&mut self, species: usize, lod_from: [f32; 2]) -> Result<(), RenderError> {
        let n = self.geo_species.len();
        let sp = self.geo_species.get_mut(species).ok_or_else(|| {
            RenderError::Parameter(format!("species {species} of {n} has no model"))
        })?;
        // 0 is "never" here, an absent start in the manifest's record.
        let starts = lod_from.map(|f| (f != 0.0).then_some(f));
        forest_format::atlas::check_lod_from(&starts)
            .map_err(|e| RenderError::Parameter(format!("species {species}: {e}; 0: never")))?;
        sp.lod_from = lod_from;
        Ok(())
    }

    /// How many times the geometry renderer may list one tree per view: 3 when a species'
    /// near trees crossfade between mesh LODs in the hybrid (a tree in two overlapping
    /// crossfades is drawn in three LODs), else 1.
    pub fn listings(&self) -> u32 {
        if self
            .geo_species
            .iter()
            .any(|s| s.lod_from.iter().any(|&f| f > 0.0))
        {
            3
        } else {
            1
        }
    }

    /// Layers of the material texture array: every species' textures.
    pub fn material_layers(&self) -> usize {
        self.layer_mips.len()
    }

    /// As [`PreparedGeometry::new`], with the leaf cards cut or whole.
    pub fn with_cards(species: &[GeometrySpecies], cards: Cards) -> Self {
        let mut vertices: Vec<RefVertex> = Vec::new();
        let mut geo_species = Vec::new();
        let mut materials = Vec::new();
        let mut layer_mips: Vec<MipChain> = Vec::new();
        let mut billboard_layers: Vec<image::RgbaImage> = Vec::new();
        let mut billboard_surface: Vec<image::RgbaImage> = Vec::new();
        let mut leaf_end: Vec<u32> = Vec::new();
        let mut leaf_centre: Vec<[f32; 4]> = Vec::new();
        let mut figures = Vec::new();
        let mut opacity = Vec::new();
        let mut ranges = Vec::new();
        for s in species {
            let mut cards_cut = 0;
            let cut;
            let chains: Vec<MipChain> = s.model.layers.iter().map(mip_chain).collect();
            let m = match cards {
                Cards::Whole => &*s.model,
                Cards::Cut => {
                    let (model, n) = cut_cards(&s.model, &card_quads(&s.model, &chains));
                    cards_cut = n as u32;
                    cut = model;
                    &cut
                }
            };
            let material_base = materials.len() as u32;
            let layer_base = layer_mips.len() as u32;
            let (billboards_base, vertices_base, leaves_base) =
                (billboard_layers.len(), vertices.len(), leaf_end.len());
            materials.extend(m.materials.iter().map(|mat| GpuGeoMaterial {
                kd: mat.kd,
                layer: if mat.layer == NONE {
                    NONE
                } else {
                    mat.layer + layer_base
                },
                alpha_tested: u32::from(mat.alpha_tested),
                pad: [0; 2],
            }));
            layer_mips.extend(chains);
            let first = vertices.len() as u32;
            let counts = m.lod_vertices;
            geo_species.push(GpuGeoSpecies {
                sphere: m.sphere,
                lod_first: [
                    first,
                    first + counts[0],
                    first + counts[0] + counts[1],
                    billboard_layers.len() as u32,
                ],
                // w: a billboard's vertices (one quad).
                lod_count: [counts[0], counts[1], counts[2], 6],
                branch_vertices: m.branch_vertices,
                leaves: m.leaf_end.len() as u32,
                leaf_base: leaf_end.len() as u32,
                r: m.r,
                mean_leaf: m.mean_leaf,
                switch_unit: s.switch_unit,
                opacity_depth: m.opacity.max_depth,
                lod_from: s.lod_from,
                pad: 0,
                colour: forest_format::colour::TreeColour::NONE,
            });
            let mut start = first as usize;
            for c in counts {
                ranges.push((m.sphere, start..start + c as usize));
                start += c as usize;
            }
            opacity.push(m.opacity.clone());
            leaf_end.extend(&m.leaf_end);
            leaf_centre.extend(m.leaf_centre.iter().map(|c| [c[0], c[1], c[2], 0.0]));
            for b in &m.billboards {
                billboard_layers.push(b.albedo.clone());
                billboard_surface.push(b.surface.clone());
            }
            vertices.extend(m.vertices.iter().map(|v| RefVertex {
                material: v.material + material_base,
                ..*v
            }));
            let leaves = leaf_end.len() - leaves_base;
            figures.push(SpeciesFigures {
                lod_triangles: counts.map(|c| u64::from(c) / 3),
                leaves: leaves as u32,
                r: m.r,
                cards_cut,
                model_bytes: (std::mem::size_of_val(&vertices[vertices_base..])
                    + std::mem::size_of::<GpuGeoSpecies>()
                    + std::mem::size_of_val(&materials[material_base as usize..])
                    + std::mem::size_of_val(&leaf_end[leaves_base..])
                    + std::mem::size_of_val(&leaf_centre[leaves_base..]))
                    as u64
                    + u64::from(VOLUME_RESOLUTION).pow(3)
                    + layer_mips[layer_base as usize..]
                        .iter()
                        .map(|c| c.0.len() as u64)
                        .sum::<u64>()
                    + 2 * layer_bytes(&billboard_layers[billboards_base..])
                    // Its triangles' presorted draw orders, one u32 per bin.
                    + (vertices.len() - vertices_base) as u64 / 3
                        * u64::from(super::order::ORDER_BINS)
                        * 4,
            });
        }
        let draw_order = super::order::draw_orders(&vertices, &ranges);
        Self {
            draw_order,
            vertices,
            geo_species,
            materials,
            layer_mips,
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
