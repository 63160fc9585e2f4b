//! The demo forest inside a Bevy app: a terrain mesh under it, a sun that moves, a fly
//! camera, a PBR sphere among the trees and a method switch.
//!
//! ```sh
//! bash scripts/demo.sh   # once, from the repository root: bakes and writes out/forest-100k.forest
//! cd integrations/forest-bevy
//! cargo run --release --ignore-rust-version --example forest [-- PATH.forest]
//! ```
//! Keys: W A S D fly, Q E down and up, arrows turn, shift faster; J L turn the sun, I K
//! raise and lower it; M switches method; [ ] halve and double ε. The title bar shows the
//! method, ε, quads and frame time. `--screenshot PATH` saves a frame once the forest is
//! drawn, and exits.

use std::path::PathBuf;

use bevy::asset::RenderAssetUsages;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::mesh::{Indices, PrimitiveTopology};
use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, save_to_disk};
use forest_bevy::{
    ForestAsset, ForestCamera, ForestMethod, ForestPlugin, ForestScene, ForestStats,
};

/// The sun's azimuth and elevation, degrees.
#[derive(Resource)]
struct SunAngles(f32, f32);

/// The forest asset, until its terrain is built.
#[derive(Resource)]
struct Pending(Handle<ForestAsset>);

#[derive(Component)]
struct Sun;

/// Where to save a screenshot before exiting, and the frames drawn so far.
#[derive(Resource)]
struct Shot(PathBuf, u32);

fn main() -> AppExit {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let args: Vec<String> = std::env::args().skip(1).collect();
    let shot = args
        .iter()
        .position(|a| a == "--screenshot")
        .and_then(|i| args.get(i + 1))
        .map(PathBuf::from);
    let forest = args
        .first()
        .filter(|a| !a.starts_with("--"))
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("out/forest-100k.forest"));
    if !forest.is_file() {
        eprintln!(
            "forest: no forest at {} (run `bash scripts/demo.sh` first)",
            forest.display()
        );
        return AppExit::error();
    }
    let folder = forest
        .parent()
        .unwrap_or(std::path::Path::new("."))
        .canonicalize()
        .unwrap();
    let name = forest.file_name().unwrap().to_string_lossy().into_owned();
    let mut app = App::new();
    if let Some(path) = shot {
        app.insert_resource(Shot(path, 0))
            .add_systems(Update, screenshot);
    }
    app.add_plugins(DefaultPlugins.set(AssetPlugin {
        file_path: folder.to_string_lossy().into_owned(),
        ..default()
    }))
    .add_plugins(ForestPlugin)
    .insert_resource(SunAngles(30.0, 35.0))
    .insert_resource(ClearColor(Color::srgb(0.62, 0.72, 0.84)))
    .insert_resource(GlobalAmbientLight {
        color: Color::srgb(0.75, 0.85, 1.0),
        brightness: 1500.0,
        ..default()
    })
    .add_systems(
        Startup,
        move |mut commands: Commands, assets: Res<AssetServer>| {
            setup(&mut commands, &assets, &name)
        },
    )
    .add_systems(Update, (terrain, fly, sun, switch, title))
    .run()
}

/// Once the forest has drawn for a while: a screenshot, then exit.
fn screenshot(
    mut commands: Commands,
    mut shot: ResMut<Shot>,
    stats: Res<ForestStats>,
    mut exit: MessageWriter<AppExit>,
) {
    if stats.views.values().any(|s| s.quads > 0) {
        shot.1 += 1;
    }
    if shot.1 == 4 {
        commands
            .spawn(Screenshot::primary_window())
            .observe(save_to_disk(shot.0.clone()));
    }
    if shot.1 > 4 && shot.0.exists() || shot.1 == 60 {
        exit.write(AppExit::Success);
    }
}

fn setup(commands: &mut Commands, assets: &AssetServer, name: &str) {
    let forest = assets.load::<ForestAsset>(name.to_owned());
    commands.insert_resource(Pending(forest.clone()));
    commands.spawn(ForestScene(forest));
    commands.spawn((
        Camera3d::default(),
        // HDR: Bevy's tonemapping pass then maps the trees with everything else.
        bevy::camera::Hdr,
        Tonemapping::AcesFitted,
        ForestCamera::default(),
        DistanceFog {
            color: Color::srgb(0.62, 0.72, 0.84),
            falloff: FogFalloff::Exponential {
                density: 3.912 / 2000.0,
            },
            ..default()
        },
        Transform::from_xyz(0.0, 4.0, 0.0).looking_to(Vec3::new(1.0, -0.05, 0.3), Vec3::Y),
    ));
    commands.spawn((
        Sun,
        DirectionalLight {
            illuminance: 20_000.0,
            shadow_maps_enabled: true,
            ..default()
        },
        Transform::default(),
    ));
}

/// Once the forest has loaded: a terrain mesh under it (its height field, or flat ground) and
/// a PBR sphere on the ground in front of the camera.
fn terrain(
    mut commands: Commands,
    pending: Option<Res<Pending>>,
    forests: Res<Assets<ForestAsset>>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    let Some(forest) = pending.and_then(|p| forests.get(&p.0)) else {
        return;
    };
    let f = &forest.forest;
    let (half, n) = (f.extent().min(3000.0), 256usize);
    let step = 2.0 * half / n as f32;
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, z) = (i as f32 * step - half, j as f32 * step - half);
            positions.push([x, f.ground_height(x, z) - 0.02, z]);
        }
    }
    let mut indices = Vec::new();
    let row = n as u32 + 1;
    for j in 0..n as u32 {
        for i in 0..n as u32 {
            let a = j * row + i;
            indices.extend([a, a + row, a + 1, a + 1, a + row, a + row + 1]);
        }
    }
    let mut mesh = Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_indices(Indices::U32(indices));
    mesh.compute_smooth_normals();
    commands.spawn((
        Mesh3d(meshes.add(mesh)),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::srgb(0.30, 0.27, 0.18),
            perceptual_roughness: 1.0,
            ..default()
        })),
    ));
    let at = Vec3::new(12.0, 0.0, 4.0);
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

fn fly(
    keys: Res<ButtonInput<KeyCode>>,
    time: Res<Time>,
    mut cams: Query<&mut Transform, With<Camera3d>>,
) {
    let Ok(mut t) = cams.single_mut() else { return };
    let dt = time.delta_secs();
    let speed = if keys.pressed(KeyCode::ShiftLeft) {
        60.0
    } else {
        8.0
    } * dt;
    let axis = |plus, minus| {
        f32::from(u8::from(keys.pressed(plus))) - f32::from(u8::from(keys.pressed(minus)))
    };
    let (forward, right) = (t.forward().as_vec3(), t.right().as_vec3());
    t.translation += speed
        * (forward * axis(KeyCode::KeyW, KeyCode::KeyS)
            + right * axis(KeyCode::KeyD, KeyCode::KeyA)
            + Vec3::Y * axis(KeyCode::KeyE, KeyCode::KeyQ));
    t.rotate_y(1.2 * dt * axis(KeyCode::ArrowLeft, KeyCode::ArrowRight));
    let pitch = 0.8 * dt * axis(KeyCode::ArrowUp, KeyCode::ArrowDown);
    t.rotate_local_x(pitch);
}

fn sun(
    keys: Res<ButtonInput<KeyCode>>,
    time: Res<Time>,
    mut angles: ResMut<SunAngles>,
    mut suns: Query<&mut Transform, With<Sun>>,
) {
    let rate = 40.0 * time.delta_secs();
    let axis = |plus, minus| {
        f32::from(u8::from(keys.pressed(plus))) - f32::from(u8::from(keys.pressed(minus)))
    };
    angles.0 += rate * axis(KeyCode::KeyL, KeyCode::KeyJ);
    angles.1 = (angles.1 + rate * axis(KeyCode::KeyI, KeyCode::KeyK)).clamp(2.0, 89.0);
    let (az, el) = (angles.0.to_radians(), angles.1.to_radians());
    let to_sun = Vec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
    for mut t in &mut suns {
        *t = Transform::from_translation(to_sun).looking_at(Vec3::ZERO, Vec3::Y);
    }
}

/// The methods M cycles through (full geometry left out: every tree of a large forest as its
/// model takes seconds a frame on a CPU).
const METHODS: [ForestMethod; 4] = [
    ForestMethod::QuadStream,
    ForestMethod::Hybrid,
    ForestMethod::DiscreteLods,
    ForestMethod::Impostors,
];

fn switch(keys: Res<ButtonInput<KeyCode>>, mut cams: Query<&mut ForestCamera>) {
    for mut c in &mut cams {
        if keys.just_pressed(KeyCode::KeyM) {
            let i = METHODS.iter().position(|m| *m == c.method).unwrap_or(0);
            c.method = METHODS[(i + 1) % METHODS.len()];
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
    cams: Query<(Entity, &ForestCamera)>,
    mut windows: Query<&mut Window>,
) {
    let (Ok((camera, c)), Ok(mut window)) = (cams.single(), windows.single_mut()) else {
        return;
    };
    // A method the forest cannot draw (atlases baked without models) says why.
    let error = stats
        .views
        .iter()
        .find_map(|((cam, _), s)| (*cam == camera).then_some(s.error.as_deref()).flatten());
    window.title = format!(
        "forest in Bevy: {} ε {} px, {} quads, {:.1} ms (M method, [ ] ε, IJKL sun){}",
        c.method.name(),
        c.epsilon,
        stats.quads(camera),
        time.delta_secs() * 1000.0,
        error.map(|e| format!(": {e}")).unwrap_or_default()
    );
}
