//! The demo forest inside a Bevy app: a terrain mesh under it, a sun that moves, a fly
//! camera, a PBR sphere among the trees and a method switch. The forest is drawn by the
//! hybrid (`ForestCamera::default()`), and the camera starts where the viewer and `forest
//! render --view inside` start: standing on the ground, clear of every tree
//! (`forest_render::start_view`).
//!
//! ```sh
//! bash scripts/demo.sh   # once, from the repository root: bakes and writes out/forest-100k.forest
//! cd integrations/forest-bevy
//! cargo run --release --ignore-rust-version --example forest [-- PATH.forest]
//! ```
//! Keys: W A S D fly, Q E down and up, arrows turn, shift faster; J L turn the sun, I K
//! raise and lower it; G and Shift+G make the wind stronger and weaker (it starts at a
//! breeze, 5 m/s); Y steps the season on (spring, summer, autumn, late autumn); M switches method; [ ] halve and double ε. The title bar shows the
//! method, ε, quads, triangles and frame time (or why the method cannot draw). With
//! `SCREENSHOT=PATH.png` in the environment it saves a frame once the forest is drawn, and
//! exits (0) as soon as the file is written.

use std::path::PathBuf;

use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured, save_to_disk};
use forest_bevy::{
    ForestAsset, ForestCamera, ForestMethod, ForestPlugin, ForestScene, ForestSeason, ForestStats,
    ForestWind, terrain_mesh,
};

/// The sun's azimuth and elevation, degrees.
#[derive(Resource)]
struct SunAngles(f32, f32);

/// The forest asset, until its terrain is built.
#[derive(Resource)]
struct Pending(Handle<ForestAsset>);

/// Where to save a screenshot before exiting, the frames that drew the forest, all frames.
#[derive(Resource)]
struct Shot(PathBuf, u32, u32);

/// Set by the screenshot's observer once its file is written.
#[derive(Resource, Default)]
struct Saved(bool);

fn main() -> AppExit {
    let forest = std::env::args_os().nth(1).map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../out/forest-100k.forest"),
        PathBuf::from,
    );
    let Some((folder, name)) = forest
        .canonicalize()
        .ok()
        .filter(|f| f.is_file())
        .and_then(|f| {
            let name = f.file_name()?.to_string_lossy().into_owned();
            Some((f.parent()?.to_string_lossy().into_owned(), name))
        })
    else {
        eprintln!(
            "forest: no forest at {} (run `bash scripts/demo.sh`)",
            forest.display()
        );
        return AppExit::error();
    };
    let mut app = App::new();
    if let Some(path) = std::env::var_os("SCREENSHOT") {
        app.insert_resource(Shot(path.into(), 0, 0))
            .init_resource::<Saved>()
            .add_systems(Update, screenshot);
    }
    let fog = Color::srgb(0.62, 0.72, 0.84);
    app.add_plugins(DefaultPlugins.set(AssetPlugin {
        file_path: folder,
        ..default()
    }))
    .add_plugins(ForestPlugin)
    .insert_resource(SunAngles(30.0, 35.0))
    // Every tree moves in it, in every method and in its shadows, on Bevy's clock.
    .insert_resource(ForestWind(forest_format::wind::Wind::new(60.0, 5.0)))
    // Summer; Y turns the leaves through the year, each tree a little ahead or behind.
    .insert_resource(ForestSeason(1.0 / 3.0))
    .insert_resource(ClearColor(fog))
    .insert_resource(GlobalAmbientLight {
        color: Color::srgb(0.75, 0.85, 1.0),
        brightness: 1500.0,
        ..default()
    })
    .add_systems(
        Startup,
        move |mut commands: Commands, assets: Res<AssetServer>| {
            let forest = assets.load::<ForestAsset>(name.clone());
            commands.insert_resource(Pending(forest.clone()));
            commands.spawn(ForestScene(forest));
            commands.spawn((
                Camera3d::default(),
                // HDR: Bevy's tonemapping pass then maps the trees with everything else.
                bevy::camera::Hdr,
                Tonemapping::AcesFitted,
                ForestCamera::default(),
                DistanceFog {
                    color: fog,
                    falloff: FogFalloff::Exponential {
                        density: 3.912 / 2000.0,
                    },
                    ..default()
                },
                // Placed where the forest has loaded (see `terrain`).
                Transform::from_xyz(0.0, 4.0, 0.0).looking_to(Vec3::new(1.0, -0.05, 0.3), Vec3::Y),
            ));
            commands.spawn(DirectionalLight {
                illuminance: 20_000.0,
                shadow_maps_enabled: true,
                ..default()
            });
        },
    )
    .add_systems(Update, (terrain, fly, sun, switch, title))
    .run()
}

/// Once the forest has drawn for a few frames: a screenshot, then exit as soon as its file
/// is written (with an error if nothing was drawn in 600 frames).
fn screenshot(
    mut commands: Commands,
    mut shot: ResMut<Shot>,
    saved: Res<Saved>,
    stats: Res<ForestStats>,
    mut exit: MessageWriter<AppExit>,
) {
    shot.2 += 1;
    if saved.0 {
        exit.write(AppExit::Success);
        return;
    }
    if stats.views.values().any(|s| s.quads > 0 || s.triangles > 0) {
        shot.1 += 1;
        if shot.1 == 4 {
            // `save_to_disk` writes the file before the next observer runs.
            commands
                .spawn(Screenshot::primary_window())
                .observe(save_to_disk(shot.0.clone()))
                .observe(|_: On<ScreenshotCaptured>, mut saved: ResMut<Saved>| saved.0 = true);
        }
    }
    if shot.2 == 600 {
        eprintln!("forest: no forest drawn in 600 frames, no screenshot");
        exit.write(AppExit::error());
    }
}

/// Once the forest has loaded: the camera at the forest's start view, a terrain mesh under it
/// (its height field, or flat ground) and a PBR sphere on the ground in front of the camera.
fn terrain(
    mut commands: Commands,
    pending: Option<Res<Pending>>,
    forests: Res<Assets<ForestAsset>>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut cams: Query<&mut Transform, With<Camera3d>>,
) {
    let Some(forest) = pending.and_then(|p| forests.get(&p.0)) else {
        return;
    };
    let f = &forest.forest;
    // forest-format's glam is not Bevy's: the points cross as arrays.
    let (eye, target) = forest_render::start_view(f, &forest.species);
    let (eye, target) = (
        Vec3::from_array(eye.to_array()),
        Vec3::from_array(target.to_array()),
    );
    for mut t in &mut cams {
        *t = Transform::from_translation(eye).looking_at(target, Vec3::Y);
    }
    let ground = terrain_mesh(f, f.extent().clamp(1.0, 3000.0), 256).expect("a valid grid");
    commands.spawn((
        Mesh3d(meshes.add(ground)),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::srgb(0.30, 0.27, 0.18),
            perceptual_roughness: 1.0,
            ..default()
        })),
        // 2 cm down, so that the trunks' bases do not fight it.
        Transform::from_xyz(0.0, -0.02, 0.0),
    ));
    // 8 m ahead of the camera, on the ground.
    let at = eye + (target - eye).with_y(0.0).normalize_or(Vec3::X) * 8.0;
    commands.spawn((
        Mesh3d(meshes.add(Sphere::new(1.0))),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::srgb(0.8, 0.1, 0.1),
            metallic: 0.6,
            perceptual_roughness: 0.3,
            ..default()
        })),
        Transform::from_xyz(at.x, f.ground_height(at.x, at.z) + 1.0, at.z),
    ));
    commands.remove_resource::<Pending>();
}

/// +1 while `plus` is held, -1 while `minus` is, 0 for both or neither.
fn axis(keys: &ButtonInput<KeyCode>, plus: KeyCode, minus: KeyCode) -> f32 {
    f32::from(u8::from(keys.pressed(plus))) - f32::from(u8::from(keys.pressed(minus)))
}

fn fly(
    keys: Res<ButtonInput<KeyCode>>,
    time: Res<Time>,
    mut cams: Query<&mut Transform, With<Camera3d>>,
) {
    let Ok(mut t) = cams.single_mut() else { return };
    let dt = time.delta_secs();
    let speed = dt * [8.0, 60.0][usize::from(keys.pressed(KeyCode::ShiftLeft))];
    let k = |plus, minus| axis(&keys, plus, minus);
    let (forward, right) = (t.forward().as_vec3(), t.right().as_vec3());
    t.translation += speed
        * (forward * k(KeyCode::KeyW, KeyCode::KeyS)
            + right * k(KeyCode::KeyD, KeyCode::KeyA)
            + Vec3::Y * k(KeyCode::KeyE, KeyCode::KeyQ));
    t.rotate_y(1.2 * dt * k(KeyCode::ArrowLeft, KeyCode::ArrowRight));
    t.rotate_local_x(0.8 * dt * k(KeyCode::ArrowUp, KeyCode::ArrowDown));
}

fn sun(
    keys: Res<ButtonInput<KeyCode>>,
    time: Res<Time>,
    mut angles: ResMut<SunAngles>,
    mut suns: Query<&mut Transform, With<DirectionalLight>>,
) {
    let rate = 40.0 * time.delta_secs();
    angles.0 += rate * axis(&keys, KeyCode::KeyL, KeyCode::KeyJ);
    angles.1 = (angles.1 + rate * axis(&keys, KeyCode::KeyI, KeyCode::KeyK)).clamp(2.0, 89.0);
    let (az, el) = (angles.0.to_radians(), angles.1.to_radians());
    let to_sun = Vec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
    for mut t in &mut suns {
        *t = Transform::from_translation(to_sun).looking_at(Vec3::ZERO, Vec3::Y);
    }
}

/// The wind speeds G and Shift+G step through (m/s): calm, light air, breeze, fresh breeze,
/// strong breeze, gale.
const WIND_STEPS: [f32; 6] = [0.0, 2.0, 5.0, 9.0, 13.0, 18.0];

fn switch(
    keys: Res<ButtonInput<KeyCode>>,
    mut cams: Query<&mut ForestCamera>,
    (mut wind, mut season): (ResMut<ForestWind>, ResMut<ForestSeason>),
) {
    if keys.just_pressed(KeyCode::KeyY) {
        // Spring, summer, autumn, late autumn, and round again.
        season.0 = ((season.0 * 3.0).round() + 1.0) % 4.0 / 3.0;
    }
    if keys.just_pressed(KeyCode::KeyG) {
        let i = WIND_STEPS
            .iter()
            .position(|s| *s >= wind.0.speed)
            .unwrap_or(WIND_STEPS.len() - 1);
        let weaker = keys.pressed(KeyCode::ShiftLeft) || keys.pressed(KeyCode::ShiftRight);
        let next = if weaker {
            i.saturating_sub(1)
        } else {
            (i + 1).min(WIND_STEPS.len() - 1)
        };
        wind.0.speed = WIND_STEPS[next];
    }
    for mut c in &mut cams {
        // Every method but full geometry (every tree of a large forest as its model takes
        // seconds a frame on a CPU).
        let methods = &ForestMethod::ALL[..4];
        if keys.just_pressed(KeyCode::KeyM) {
            let i = methods.iter().position(|m| *m == c.method).unwrap_or(0);
            c.method = methods[(i + 1) % methods.len()];
        }
        if keys.just_pressed(KeyCode::BracketLeft) {
            c.epsilon = (c.epsilon * 0.5).max(1.0);
        }
        if keys.just_pressed(KeyCode::BracketRight) {
            c.epsilon = (c.epsilon * 2.0).min(64.0);
        }
    }
}

fn title(
    stats: Res<ForestStats>,
    time: Res<Time>,
    (wind, season): (Res<ForestWind>, Res<ForestSeason>),
    cams: Query<(Entity, &ForestCamera)>,
    mut windows: Query<&mut Window>,
) {
    let (Ok((camera, c)), Ok(mut window)) = (cams.single(), windows.single_mut()) else {
        return;
    };
    window.title = format!(
        "forest in Bevy: {} ε {} px, {} quads, {} triangles, {:.1} ms, wind {} m/s (M method, \
         [ ] ε, IJKL sun, G wind, Y season {:.2}){}",
        c.method.name(),
        c.epsilon,
        stats.quads(camera),
        stats.triangles(camera),
        time.delta_secs() * 1000.0,
        wind.0.speed,
        season.0,
        // A method the forest cannot draw (atlases baked without models) says why.
        stats
            .error(camera)
            .map(|e| format!(": {e}"))
            .unwrap_or_default()
    );
}
