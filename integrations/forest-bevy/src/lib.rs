//! Quad-stream forests inside Bevy's renderer.
//!
//! [`ForestPlugin`] loads `.forest` files and `.atlas` folders as assets, and draws every
//! [`ForestScene`] into every camera that has a [`ForestCamera`]: on Bevy's own wgpu device,
//! after the main opaque pass, into the view's target (HDR or LDR, MSAA 1 or 4), tested
//! against Bevy's reverse-Z depth and writing depth where the trees are opaque, so Bevy's
//! transparent objects and post-processing see them. Bevy's first visible
//! `DirectionalLight`, its ambient light and the camera's exposure light the trees
//! ([`light`]); a camera's `DistanceFog` becomes their haze. The trees cast into that light's
//! shadow cascades and receive them ([`shadows`]). A [`ForestWind`] resource sways them on
//! Bevy's clock. [`ForestStats`] holds each view's counters.
//!
//! ```no_run
//! use bevy::prelude::*;
//! use forest_bevy::{ForestCamera, ForestPlugin, ForestScene};
//!
//! fn setup(mut commands: Commands, assets: Res<AssetServer>) {
//!     commands.spawn(ForestScene(assets.load("demo.forest")));
//!     commands.spawn((
//!         Camera3d::default(),
//!         ForestCamera::default(),
//!         Transform::from_xyz(0.0, 1.7, 0.0).looking_at(Vec3::new(0.0, 3.0, -30.0), Vec3::Y),
//!     ));
//!     commands.spawn((
//!         DirectionalLight::default(),
//!         Transform::from_xyz(1.0, 2.0, 1.0).looking_at(Vec3::ZERO, Vec3::Y),
//!     ));
//! }
//!
//! App::new()
//!     .add_plugins((DefaultPlugins, ForestPlugin))
//!     .add_systems(Startup, setup)
//!     .run();
//! ```
//!
//! Each camera picks its method ([`ForestMethod`]): the quad stream, static impostors, or,
//! from the prepared models that `forest bake` stores in each atlas (`model.bin`), the
//! hybrid, the discrete LODs and full geometry.

#![deny(missing_docs)]

pub mod assets;
pub mod components;
pub mod light;
pub mod render;
pub mod shadows;
pub mod stats;
pub mod terrain;

use bevy::core_pipeline::core_3d::{main_opaque_pass_3d, main_transparent_pass_3d};
use bevy::core_pipeline::schedule::{Core3d, Core3dSystems};
use bevy::pbr::{LATE_SHADOW_PASS, per_view_shadow_pass, shared_shadow_pass};
use bevy::prelude::*;
use bevy::render::{ExtractSchedule, Render, RenderApp, RenderSystems};

pub use assets::{AtlasLoader, ForestAsset, ForestAtlas, ForestLoader, LoadError};
pub use components::{ForestCamera, ForestMethod, ForestScene, ForestSeason, ForestWind};
pub use stats::{ForestStats, ForestViewStats};
pub use terrain::{TerrainMeshError, terrain_mesh};

/// Registers the forest assets and their loaders, the statistics, and the render world's
/// systems (see [`render`]).
#[derive(Default)]
pub struct ForestPlugin;

impl Plugin for ForestPlugin {
    fn build(&self, app: &mut App) {
        let shared = stats::SharedStats::default();
        app.init_asset::<ForestAtlas>()
            .init_asset::<ForestAsset>()
            .init_asset_loader::<AtlasLoader>()
            .init_asset_loader::<ForestLoader>()
            .init_resource::<ForestStats>()
            .insert_resource(shared.clone())
            .add_systems(First, stats::copy_stats);
        let Some(render_app) = app.get_sub_app_mut(RenderApp) else {
            return;
        };
        render_app
            .insert_resource(shared)
            .init_resource::<render::Extracted>()
            .init_resource::<render::ForestRenderState>()
            .add_systems(ExtractSchedule, render::extract)
            .add_systems(
                Render,
                render::prepare_forests.in_set(RenderSystems::PrepareResources),
            )
            .add_systems(
                Core3d,
                render::cast_forests
                    .after(per_view_shadow_pass::<LATE_SHADOW_PASS>)
                    .after(shared_shadow_pass::<LATE_SHADOW_PASS>)
                    .before(Core3dSystems::MainPass),
            )
            .add_systems(
                Core3d,
                render::draw_forests
                    .after(main_opaque_pass_3d)
                    .before(main_transparent_pass_3d)
                    .in_set(Core3dSystems::MainPass),
            );
    }
}
