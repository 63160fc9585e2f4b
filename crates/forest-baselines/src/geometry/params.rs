//! What the geometry-based methods are asked to draw: the species' models, the method and its
//! parameters, and the counters a frame reports.

use forest_format::model::{BANDS, PreparedModel};
use forest_render::context::RenderError;
use forest_render::stats::PassTimes;

use crate::gpu_types::GpuMethod;

/// A species for the geometry-based methods.
#[derive(Clone)]
pub struct GeometrySpecies {
    /// Its prepared model (the bake's, [`forest_format::model::PreparedModel`]).
    pub model: std::sync::Arc<PreparedModel>,
    /// The hybrid's switch unit of its atlas ([`forest_render::extend::switch_unit`]), so that
    /// both forms agree where each tree switches (any value when the hybrid is not used).
    pub switch_unit: f32,
    /// Where the hybrid draws its near trees in mesh LOD 1 and LOD 2 instead of the full
    /// model, as fractions of the switch distance in (0, 1); 0: never (the atlas's
    /// [`forest_format::atlas::HybridSwitch::lod_from`]).
    pub lod_from: [f32; 2],
}

impl GeometrySpecies {
    /// The prepared `model` of the species baked into the atlas of `manifest`: its hybrid
    /// switch comes from the atlas, so the geometry switches as its quads do.
    pub fn new(
        model: std::sync::Arc<PreparedModel>,
        manifest: &forest_format::AtlasManifest,
    ) -> Self {
        Self {
            model,
            switch_unit: forest_render::extend::switch_unit(manifest),
            lod_from: manifest
                .hybrid_switch
                .map_or([0.0; 2], |h| h.lod_from.map(|f| f.unwrap_or(0.0))),
        }
    }
}

/// Stochastic simplification parameters (Cook et al. 2007; seeds 000/001).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stochastic {
    /// Trees nearer than this (metres, divided by the instance scale) get every leaf.
    pub d0: f32,
    /// The `b = d0²/d²` at which half the leaves are drawn, in `(0, 1)`; ½ gives `λ = b`.
    pub h: f32,
    /// Fading band width as a fraction of λ, in `[0, 1]`.
    pub fade: f32,
    /// Enlarge kept leaves to preserve the visible area.
    pub area: bool,
    /// Pull leaf colours towards the species' mean by `√λ`.
    pub contrast: bool,
}

impl Default for Stochastic {
    fn default() -> Self {
        Self {
            d0: 15.0,
            h: 0.5,
            fade: 0.1,
            area: true,
            contrast: true,
        }
    }
}

/// Discrete LOD parameters (seed 004).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lods {
    /// Distances (metres, divided by the instance scale) where LOD 1, LOD 2 and billboards
    /// start; strictly increasing and positive.
    pub distances: [f32; 3],
}

impl Default for Lods {
    fn default() -> Self {
        Self {
            distances: [15.0, 40.0, 100.0],
        }
    }
}

/// What the geometry renderer draws for each tree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MeshMethod {
    /// Every tree's full model; with `depth_sort` the nearest distance bands are drawn first.
    Full {
        /// Draw near trees first (seed 003's tree depth sorting).
        depth_sort: bool,
    },
    /// The ground truth, to be drawn supersampled: every tree's full model, nearest bands
    /// first, with every texture read at its finest level, so that each sample is a point
    /// sample of the model as the bake's ray tracer takes it. Mip-mapped alpha tests thin
    /// needle-like leaves and darken them (the denser, darker parts of a leaf texture pass at
    /// coarse levels); supersampling does the filtering instead.
    Reference,
    /// Stochastic simplification of the leaves; branches drawn whole.
    Stochastic(Stochastic),
    /// Three mesh LODs and camera-facing multi-elevation billboards.
    Lods(Lods),
}

impl Default for MeshMethod {
    fn default() -> Self {
        MeshMethod::Full { depth_sort: true }
    }
}

impl MeshMethod {
    /// Check the parameters; the error names the bad one.
    pub fn validate(&self) -> Result<(), RenderError> {
        let bad = |s: String| Err(RenderError::Parameter(s));
        match self {
            MeshMethod::Full { .. } | MeshMethod::Reference => Ok(()),
            MeshMethod::Stochastic(s) => {
                if !(s.d0.is_finite() && s.d0 > 0.0) {
                    return bad(format!(
                        "stochastic d0 {} must be a positive distance",
                        s.d0
                    ));
                }
                if !(s.h > 0.0 && s.h < 1.0) {
                    return bad(format!("stochastic h {} must be in (0, 1)", s.h));
                }
                if !(0.0..=1.0).contains(&s.fade) {
                    return bad(format!(
                        "stochastic fade width {} must be in [0, 1]",
                        s.fade
                    ));
                }
                Ok(())
            }
            MeshMethod::Lods(l) => {
                let d = l.distances;
                if !(d.iter().all(|x| x.is_finite() && *x > 0.0) && d[0] < d[1] && d[1] < d[2]) {
                    return bad(format!(
                        "LOD distances {d:?} must be positive and strictly increasing"
                    ));
                }
                Ok(())
            }
        }
    }

    /// The GPU form.
    pub fn to_gpu(&self) -> GpuMethod {
        match *self {
            MeshMethod::Full { depth_sort } => GpuMethod {
                mode: 0,
                depth_sort: u32::from(depth_sort),
                ..Default::default()
            },
            MeshMethod::Reference => GpuMethod {
                mode: 0,
                depth_sort: 1,
                texture_bias: crate::gpu_types::FINEST_TEXTURES,
                ..Default::default()
            },
            MeshMethod::Stochastic(s) => GpuMethod {
                mode: 1,
                area: u32::from(s.area),
                contrast: u32::from(s.contrast),
                d0: s.d0,
                exponent: 0.5f32.ln() / s.h.ln(),
                fade: s.fade,
                ..Default::default()
            },
            MeshMethod::Lods(l) => GpuMethod {
                mode: 2,
                // Each tree's triangles in their presorted front-to-back order.
                depth_sort: 1,
                lod: [l.distances[0], l.distances[1], l.distances[2], 0.0],
                ..Default::default()
            },
        }
    }

    /// First band drawn as billboards (`BANDS`: none).
    pub fn first_billboard_band(&self) -> u32 {
        match self {
            MeshMethod::Lods(_) => 12,
            _ => BANDS,
        }
    }

    /// The draw band of a tree at object-space distance `d` (CPU mirror of `method_band` in
    /// `shaders/geometry_types.wgsl`).
    pub fn band(&self, d: f32) -> u32 {
        let distance_band =
            |d: f32| ((2.0 * d.max(1.0).log2()).floor().max(0.0) as u32).min(BANDS - 1);
        match *self {
            MeshMethod::Reference => distance_band(d),
            MeshMethod::Full { depth_sort } => {
                if depth_sort {
                    distance_band(d)
                } else {
                    0
                }
            }
            MeshMethod::Stochastic(s) => {
                forest_format::model::lambda_band(forest_format::model::lambda(d, s.d0, s.h))
            }
            MeshMethod::Lods(l) => {
                let (mut lod, mut start) = (0, 1.0);
                for (k, &x) in l.distances.iter().enumerate() {
                    if d >= x {
                        lod = k as u32 + 1;
                        start = x;
                    }
                }
                let sub = ((2.0 * (d / start).max(1.0).log2()).floor().max(0.0) as u32).min(3);
                lod * 4 + sub
            }
        }
    }
}

/// Counters of the last frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GeometryStats {
    /// Trees that passed the frustum test (the hybrid lists a tree in a crossfade between
    /// mesh LODs once per LOD, and each listing counts).
    pub visible_trees: u32,
    /// Visible trees per draw band.
    pub per_band: Vec<u32>,
    /// Triangles submitted (billboards count two).
    pub triangles: u64,
    /// Trees drawn as billboards.
    pub billboards: u32,
    /// GPU pass times (refine is 0), where the adapter has timestamp queries.
    pub times: Option<PassTimes>,
    /// The work the frame asked of the GPU (see [`forest_render::work`]).
    pub work: forest_render::work::FrameWork,
}

/// What one species was prepared into, for reports.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SpeciesFigures {
    /// Triangles of LOD 0, 1, 2.
    pub lod_triangles: [u64; 3],
    /// Leaves (stochastic elements).
    pub leaves: u32,
    /// `r` of the area-preservation factor.
    pub r: f32,
    /// Leaf cards cut to their texture's visible quadrilateral (all LODs; 0 with
    /// [`super::Cards::Whole`]).
    pub cards_cut: u32,
    /// Bytes of the species' model data on the GPU: vertices, tables, material and billboard
    /// textures with mips.
    pub model_bytes: u64,
}
