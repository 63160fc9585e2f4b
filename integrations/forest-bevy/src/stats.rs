//! The last frame's counters per camera and forest, handed from the render world to the
//! main world (a shared map the render world writes and [`ForestStats`] copies each frame).

use std::sync::{Arc, Mutex};

use bevy::platform::collections::HashMap;
use bevy::prelude::*;

/// One forest in one camera's view, as the GPU counted it a few frames ago (read back
/// without waiting).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ForestViewStats {
    /// Trees that passed the frustum test.
    pub visible_trees: u32,
    /// Quads drawn.
    pub quads: u32,
    /// Triangles drawn (the geometry methods, and the hybrid's near trees).
    pub triangles: u64,
    /// Trees the hybrid drew as their models.
    pub geometry_trees: u32,
    /// Quads cast into Bevy's shadow cascades, over all cascades.
    pub cast_quads: u32,
    /// Cull + refine + draw on the GPU, milliseconds (where the device has timestamps).
    pub gpu_ms: Option<f64>,
    /// Why the forest is not drawn into this view, if it is not (bad camera, a forest that
    /// did not reach the GPU).
    pub error: Option<String>,
    /// Why the view draws another method than its camera asks, if it does: the hybrid over
    /// atlases baked without their models draws the quad stream.
    pub note: Option<String>,
}

/// The frame statistics of every (camera, forest) pair drawn, keyed by the main world's
/// entities.
#[derive(Resource, Clone, Debug, Default)]
pub struct ForestStats {
    /// (camera, forest) → counters.
    pub views: HashMap<(Entity, Entity), ForestViewStats>,
}

impl ForestStats {
    /// The counters of `forest` in `camera`'s view.
    pub fn get(&self, camera: Entity, forest: Entity) -> Option<&ForestViewStats> {
        self.views.get(&(camera, forest))
    }

    /// The counters of every forest in `camera`'s view.
    fn of_camera(&self, camera: Entity) -> impl Iterator<Item = &ForestViewStats> {
        self.views
            .iter()
            .filter(move |((c, _), _)| *c == camera)
            .map(|(_, s)| s)
    }

    /// Quads drawn in `camera`'s view, over all forests.
    pub fn quads(&self, camera: Entity) -> u64 {
        self.of_camera(camera).map(|s| u64::from(s.quads)).sum()
    }

    /// Triangles drawn in `camera`'s view, over all forests.
    pub fn triangles(&self, camera: Entity) -> u64 {
        self.of_camera(camera).map(|s| s.triangles).sum()
    }

    /// A problem with a forest in `camera`'s view, if any forest there has one: why it is not
    /// drawn (e.g. a model method asked of atlases baked without models) or a fault while it
    /// still draws (a shadow caster). With several forests in error, any one of them.
    pub fn error(&self, camera: Entity) -> Option<&str> {
        self.of_camera(camera).find_map(|s| s.error.as_deref())
    }
}

/// The map both worlds hold: the render world writes it, the main world copies it.
#[derive(Resource, Clone, Default)]
pub struct SharedStats(pub Arc<Mutex<HashMap<(Entity, Entity), ForestViewStats>>>);

/// Main world, each frame: copy what the render world last wrote.
pub fn copy_stats(shared: Res<SharedStats>, mut stats: ResMut<ForestStats>) {
    let views = shared.0.lock().unwrap_or_else(|e| e.into_inner()).clone();
    if stats.views != views {
        stats.views = views;
    }
}
