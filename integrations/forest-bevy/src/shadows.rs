//! Bevy's directional shadow cascades and the forest: the trees receive Bevy's maps, and cast
//! into them, through `forest-render`'s host shadow-map API.
//!
//! - **Receive**: per camera view, the shadow-casting directional light's cascades (Bevy lays
//!   them out as consecutive layers of the view's directional depth array, in the order its
//!   `ViewLightEntities` lists them) become the stream's host cascades: each cascade's
//!   world → clip matrix, far bound, texel and depth range, taken into the forest's frame.
//! - **Cast**: per cascade, a second stream of the forest culls and refines from the light
//!   (ε in texels) and draws depth-only into the cascade's layer after Bevy's own shadow
//!   passes, before the main pass that reads them.
//!
//! Bevy's maps are reverse-Z orthographic boxes, as `forest-render`'s host API expects with
//! `reverse_z`.

use bevy::pbr::{ExtractedDirectionalLight, LightEntity, ShadowView, ViewLightEntities};
use bevy::prelude::*;
use bevy::render::view::ExtractedView;
use forest_render::shadow::{Cascade, LightParams, ShadowOptions};

/// One of Bevy's cascades for a view, in the forest's frame.
#[derive(Clone, Copy)]
pub struct HostCascade {
    /// The render world's light view entity (its `ShadowView` is the layer to cast into).
    pub light_view: Entity,
    /// Its index among the light's cascades (= its layer in the view's directional array).
    pub layer: u32,
    /// The cascade as the forest's receivers read it.
    pub cascade: Cascade,
    /// Map side, texels.
    pub resolution: u32,
}

/// The shadow-casting directional light's cascades of a camera view, in the forest's frame
/// (`world_from_forest`, whose uniform scale is `scale`); empty when no directional light
/// casts shadows there.
pub fn view_cascades(
    lights: &ViewLightEntities,
    light_views: &Query<(&ShadowView, &ExtractedView, &LightEntity)>,
    directional: &Query<&ExtractedDirectionalLight>,
    world_from_forest: Mat4,
    scale: f32,
) -> Vec<HostCascade> {
    let mut out = Vec::new();
    let mut light = None;
    let mut layer = 0u32;
    for &entity in &lights.lights {
        let Ok((
            _,
            view,
            LightEntity::Directional {
                light_entity,
                cascade_index,
            },
        )) = light_views.get(entity)
        else {
            continue;
        };
        // The first light's cascades only (its layers come first).
        if *light.get_or_insert(*light_entity) != *light_entity {
            break;
        }
        let Ok(l) = directional.get(*light_entity) else {
            break;
        };
        let Some(&far) = l.cascade_shadow_config.bounds.get(*cascade_index) else {
            break;
        };
        let clip_from_world = view
            .clip_from_world
            .unwrap_or(view.clip_from_view * view.world_from_view.to_matrix().inverse());
        // Bevy's reverse-Z box: depth = 1 + r·z, so its depth range is 1 / r.
        let r = view.clip_from_view.z_axis.z.abs().max(f32::MIN_POSITIVE);
        let resolution = view.viewport.z.max(1);
        let texel =
            2.0 / view.clip_from_view.x_axis.x.abs().max(f32::MIN_POSITIVE) / resolution as f32;
        let near = if *cascade_index == 0 {
            0.0
        } else {
            l.cascade_shadow_config.bounds[*cascade_index - 1]
        };
        out.push(HostCascade {
            light_view: entity,
            layer,
            resolution,
            cascade: Cascade {
                split: (near / scale, far / scale),
                centre: glam::Vec3::ZERO,
                radius: 0.5 * texel * resolution as f32 / scale,
                view_proj: crate::light::mat_to_forest(clip_from_world * world_from_forest),
                texel: texel / scale,
                depth_range: r.recip() / scale,
            },
        });
        layer += 1;
        if out.len() == forest_render::shadow::MAX_CASCADES as usize {
            break;
        }
    }
    out
}

/// The light view the forest casts into `c` from: the cascade's matrix, the sun, ε in texels
/// (`forest-render`'s default light-view ε), and the camera's eye (all in the forest's frame).
pub fn light_params(c: &HostCascade, to_light: glam::Vec3, view_eye: glam::Vec3) -> LightParams {
    LightParams {
        view_proj: c.cascade.view_proj,
        to_light,
        resolution: (c.resolution, c.resolution),
        epsilon: ShadowOptions::default().epsilon,
        view_eye,
    }
}
