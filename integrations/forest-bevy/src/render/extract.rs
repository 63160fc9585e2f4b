//! ExtractSchedule: the forests, the cameras that draw them, the sun and the ambient light,
//! gathered whole each frame.

use bevy::asset::AssetId;
use bevy::camera::Camera;
use bevy::light::{AmbientLight, DirectionalLight, GlobalAmbientLight};
use bevy::pbr::{DistanceFog, FogFalloff};
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::render::Extract;

use crate::assets::ForestAsset;
use crate::components::{ForestCamera, ForestScene, ForestSeason, ForestWind};
use crate::light;

/// A forest as extracted this frame.
#[derive(Clone)]
pub struct ExtractedForest {
    /// Its main-world entity.
    pub entity: Entity,
    /// Its asset.
    pub asset: AssetId<ForestAsset>,
    /// World ← forest.
    pub world_from_forest: Mat4,
}

/// A camera's forest settings as extracted this frame.
#[derive(Clone, Copy)]
pub struct ExtractedForestCamera {
    /// Method and ε.
    pub settings: ForestCamera,
    /// Ambient light, linear colour × brightness (cd/m²).
    pub ambient: Vec3,
    /// Its fog, if any: linear colour and falloff.
    pub fog: Option<(Vec3, light::Falloff)>,
}

/// What the extract system gathers each frame (rebuilt whole, so nothing stale remains).
#[derive(Resource, Default)]
pub struct Extracted {
    /// Forests with a loaded asset.
    pub forests: Vec<ExtractedForest>,
    /// Assets first seen (or changed) since the last frame: the render world builds their
    /// GPU scenes.
    pub new_assets: Vec<(AssetId<ForestAsset>, ForestAsset)>,
    /// Assets no longer loaded.
    pub removed_assets: Vec<AssetId<ForestAsset>>,
    /// Cameras with a [`ForestCamera`], by main-world entity.
    pub cameras: HashMap<Entity, ExtractedForestCamera>,
    /// The first directional light, in world space.
    pub sun: Option<light::Sun>,
    /// The wind at this frame's instant, in world space (calm without [`ForestWind`]).
    pub wind: forest_format::wind::Wind,
    /// The season (`None` without [`ForestSeason`]).
    pub season: Option<f32>,
}

fn linear(c: Color) -> Vec3 {
    let l = c.to_linear();
    Vec3::new(l.red, l.green, l.blue)
}

fn falloff(f: &FogFalloff) -> light::Falloff {
    match *f {
        FogFalloff::Linear { start, end } => light::Falloff::Linear { start, end },
        FogFalloff::Exponential { density } => light::Falloff::Exponential { density },
        FogFalloff::ExponentialSquared { density } => {
            light::Falloff::ExponentialSquared { density }
        }
        FogFalloff::Atmospheric { extinction, .. } => light::Falloff::Atmospheric {
            extinction: Vec3::from_array(extinction.to_array()).to_array().into(),
        },
    }
}

/// ExtractSchedule: the forests, the cameras that draw them, the sun and ambient light, the
/// wind on Bevy's clock.
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
pub fn extract(
    mut out: ResMut<Extracted>,
    forests: Extract<Query<(Entity, &ForestScene, &GlobalTransform, &InheritedVisibility)>>,
    assets: Extract<Res<Assets<ForestAsset>>>,
    mut events: Extract<MessageReader<AssetEvent<ForestAsset>>>,
    cameras: Extract<
        Query<(
            Entity,
            &Camera,
            &ForestCamera,
            Option<&AmbientLight>,
            Option<&DistanceFog>,
        )>,
    >,
    global_ambient: Extract<Option<Res<GlobalAmbientLight>>>,
    suns: Extract<Query<(&DirectionalLight, &GlobalTransform, &InheritedVisibility)>>,
    (wind, time, season): (
        Extract<Option<Res<ForestWind>>>,
        Extract<Res<Time>>,
        Extract<Option<Res<ForestSeason>>>,
    ),
) {
    out.forests.clear();
    out.cameras.clear();
    for event in events.read() {
        match *event {
            AssetEvent::LoadedWithDependencies { id } | AssetEvent::Modified { id } => {
                if let Some(a) = assets.get(id) {
                    out.new_assets.push((id, a.clone()));
                }
            }
            AssetEvent::Removed { id } | AssetEvent::Unused { id } => out.removed_assets.push(id),
            _ => {}
        }
    }
    for (entity, scene, transform, visible) in &forests {
        if visible.get() && assets.contains(scene.0.id()) {
            out.forests.push(ExtractedForest {
                entity,
                asset: scene.0.id(),
                world_from_forest: transform.to_matrix(),
            });
        }
    }
    let global = global_ambient
        .as_ref()
        .map_or(Vec3::splat(80.0), |a| linear(a.color) * a.brightness);
    for (entity, camera, settings, ambient, fog) in &cameras {
        if !camera.is_active {
            continue;
        }
        out.cameras.insert(
            entity,
            ExtractedForestCamera {
                settings: *settings,
                ambient: ambient.map_or(global, |a| linear(a.color) * a.brightness),
                fog: fog.map(|f| (linear(f.color), falloff(&f.falloff))),
            },
        );
    }
    out.wind = wind.as_ref().map_or(forest_format::wind::Wind::CALM, |w| {
        let clock = time.elapsed_secs_f64() % f64::from(forest_format::wind::MAX_TIME);
        w.0.at(clock as f32)
    });
    out.season = season.as_ref().map(|s| s.0);
    out.sun = suns
        .iter()
        .find(|(_, _, v)| v.get())
        .map(|(l, t, _)| light::Sun {
            to_light: t.back().as_vec3(),
            colour: linear(l.color),
            illuminance: l.illuminance,
        });
}
