//! What a Bevy app puts on its entities: a forest placed by its `Transform`, and per camera
//! how the forest is drawn into that camera's view.

use bevy::prelude::*;

use crate::assets::ForestAsset;

/// A forest in the scene: its asset, placed by the entity's `Transform` (translation,
/// rotation and uniform scale; the forest's own +Y stays its up for haze and the sun).
#[derive(Component, Clone, Debug, Default)]
#[require(Transform, Visibility)]
pub struct ForestScene(pub Handle<ForestAsset>);

/// How the forests are drawn into a camera's view. A `Camera3d` without it draws no forest.
/// Each camera gets its own prepared stream, so split screens and minimaps may differ.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct ForestCamera {
    /// The method.
    pub method: ForestMethod,
    /// Refinement threshold ε, pixels (> 0): a quad is refined while its projected edge is
    /// longer. Smaller is finer and costs more.
    pub epsilon: f32,
    /// Write the trees' depth where they are at least half opaque (a second, depth-only draw
    /// of the quads), so that Bevy's transparent objects and post-processing see them. It
    /// costs about 40 % of the forest's frame on lavapipe (docs/bevy.md); a scene with
    /// nothing transparent behind its trees can turn it off.
    pub write_depth: bool,
}

impl Default for ForestCamera {
    /// The hybrid ([`ForestMethod::default`]) at ε = 4 pixels, writing depth.
    fn default() -> Self {
        Self {
            method: ForestMethod::default(),
            epsilon: 4.0,
            write_depth: true,
        }
    }
}

/// A rendering method available inside Bevy. The default is the hybrid: the most accurate
/// for its time, where the quad stream alone is poor within a few crown radii of the eye.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ForestMethod {
    /// The dynamic quad stream: cull, refine by ε, draw (Liu, Hua & Bao 2010), the paper's
    /// method.
    QuadStream,
    /// Static impostors: each tree's level-0 slab images, never refined.
    Impostors,
    /// The trees next to the camera as their full models, the rest as the quad stream, each
    /// species switching where its bake measured the quads as accurate as its triangles.
    /// Draws every species' prepared model (`model.bin`, which `forest bake` stores); over
    /// atlases without them the view draws the quad stream, and its
    /// [`crate::ForestViewStats::note`] says why.
    #[default]
    Hybrid,
    /// Discrete LODs (the full model, two simplified meshes, billboards) by distance. Needs
    /// the prepared models.
    DiscreteLods,
    /// Every tree as its full model. Needs the prepared models.
    FullGeometry,
}

impl ForestMethod {
    /// Every method, in the order a switch cycles through them.
    pub const ALL: [ForestMethod; 5] = [
        ForestMethod::QuadStream,
        ForestMethod::Hybrid,
        ForestMethod::Impostors,
        ForestMethod::DiscreteLods,
        ForestMethod::FullGeometry,
    ];

    /// Its short name.
    pub fn name(self) -> &'static str {
        match self {
            ForestMethod::QuadStream => "quad stream",
            ForestMethod::Impostors => "impostors",
            ForestMethod::Hybrid => "hybrid",
            ForestMethod::DiscreteLods => "discrete LODs",
            ForestMethod::FullGeometry => "full geometry",
        }
    }

    /// Whether it draws the species' models (and so needs their prepared models).
    pub fn needs_models(self) -> bool {
        !matches!(self, ForestMethod::QuadStream | ForestMethod::Impostors)
    }

    /// The renderer's method with its default parameters.
    pub fn method(self) -> forest_baselines::Method {
        use forest_baselines::{Hybrid, MeshMethod, Method};
        match self {
            ForestMethod::QuadStream => Method::Quads,
            ForestMethod::Impostors => Method::Impostor,
            ForestMethod::Hybrid => Method::Hybrid(Hybrid::default()),
            ForestMethod::DiscreteLods => Method::Mesh(MeshMethod::Lods(Default::default())),
            ForestMethod::FullGeometry => Method::Mesh(MeshMethod::Full { depth_sort: true }),
        }
    }
}

/// The wind the forests sway in: where it blows (an azimuth in Bevy's world, degrees from +Z
/// towards +X), its mean speed (m/s) and gustiness ([`forest_format::wind::Wind`]; its
/// `time` is ignored: Bevy's [`Time`] is the clock, wrapped within
/// [`forest_format::wind::MAX_TIME`]). Every method and every shadow caster moves its trees
/// by it. Without the resource the air is calm; a wind out of range is reported in
/// [`crate::ForestStats`] and the forest is drawn calm.
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct ForestWind(pub forest_format::wind::Wind);

/// The season the forests' leaves are drawn in: 0 (spring) to 1 (late autumn), through summer
/// (⅓) and autumn (⅔) ([`forest_format::colour`]); each tree of a varied forest is a little
/// ahead or behind. Without the resource the leaves keep their models' colours; a season out
/// of range is reported in [`crate::ForestStats`] and the models' colours are drawn.
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct ForestSeason(pub f32);
