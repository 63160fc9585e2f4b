//! Fixtures of the plugin's tests: a small baked forest on disk, a headless Bevy app on
//! lavapipe rendering into images, read-backs, and the same frame drawn by `forest-render`
//! alone (what `forest render` runs).
#![allow(dead_code)]

use forest_render::ForestView;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use bevy::asset::AssetPlugin;
use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::{DebandDither, Tonemapping};
use bevy::image::Image;
use bevy::light::GlobalAmbientLight;
use bevy::prelude::*;
use bevy::render::RenderApp;
use bevy::render::render_asset::RenderAssets;
use bevy::render::renderer::{RenderDevice, RenderQueue};
use bevy::render::texture::GpuImage;
use bevy::render::view::Msaa;
use bevy::window::{ExitCondition, WindowPlugin};
use forest_baselines::{ForestRenderer, GeometryRenderer, GeometrySpecies, PreparedGeometry};
use forest_bevy::{ForestCamera, ForestMethod, ForestPlugin, ForestScene};
use forest_format::shading::Lighting;
use forest_render::{FrameParams, GpuContext, GpuScene, QuadStream, RendererOptions, Targets};

/// Image size of every test view (pixels).
pub const SIZE: (u32, u32) = (160, 120);
/// The camera's exposure (EV100 0: exposure 1 / 1.2).
pub const EV100: f32 = 0.0;
/// The sun's illuminance (lux): with EV100 0, a sun of irradiance 1.2/π·E = 1 in the forest's
/// units.
pub const LUX: f32 = std::f32::consts::PI;
/// Ambient brightness (cd/m²) of the white ambient light.
pub const AMBIENT: f32 = 0.3;
/// Towards the sun.
pub fn sun_dir() -> Vec3 {
    Vec3::new(0.4, 0.8, 0.3).normalize()
}
/// The views' clear colour (sRGB).
pub const CLEAR: [f32; 3] = [0.55, 0.65, 0.8];

/// Output folder of failing comparisons.
pub fn out_dir() -> PathBuf {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-output");
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A folder holding `bush.atlas` (small: 64 px, 5 directions) and `small.forest` (60 bushes
/// around the origin), baked once per test binary.
pub fn assets() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-assets");
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let obj = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/trees/bush/bush.obj");
        let params = forest_format::BakeParams {
            directions: 5,
            resolution: 64,
            min_quad: 4,
            spp: 2,
            ..Default::default()
        };
        let out = forest_bake::bake_file(&obj, &params, &|_, _| {}).unwrap();
        // With its prepared model, as `forest bake` stores it.
        let mesh = forest_bake::Mesh::load(&obj).unwrap();
        let model = forest_bake::model::prepare(&mesh, Some(&out.sky));
        out.atlas
            .save_with_model(&dir.join("bush.atlas"), Some(&model.encode()))
            .unwrap();
        let forest = forest_scene::generate::generate(&forest_scene::generate::GenerateParams {
            trees: 60,
            species: vec!["bush.atlas".into()],
            area_per_tree: 6.0,
            clump_size: 10.0,
            seed: 11,
            ..Default::default()
        })
        .unwrap();
        forest.save(&dir.join("small.forest")).unwrap();
        dir
    })
}

/// A headless app on lavapipe reading assets from `dir`, with the plugin, a white sun and
/// ambient light as the constants say.
pub fn app(dir: &Path) -> App {
    let mut app = App::new();
    app.add_plugins(
        DefaultPlugins
            .set(AssetPlugin {
                file_path: dir.to_string_lossy().into_owned(),
                ..default()
            })
            .set(WindowPlugin {
                primary_window: None,
                exit_condition: ExitCondition::DontExit,
                ..default()
            })
            .disable::<bevy::winit::WinitPlugin>()
            // The render world stays in the app, where the tests read its images back.
            .disable::<bevy::render::pipelined_rendering::PipelinedRenderingPlugin>()
            .disable::<bevy::log::LogPlugin>(),
    )
    .insert_resource(GlobalAmbientLight {
        color: Color::WHITE,
        brightness: AMBIENT,
        ..default()
    });
    if std::env::var("NO_FOREST").is_err() {
        app.add_plugins(ForestPlugin);
    }
    app.world_mut().spawn((
        DirectionalLight {
            illuminance: LUX,
            shadow_maps_enabled: false,
            ..default()
        },
        Transform::from_translation(sun_dir()).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    // What `App::run` does before the first update: wait for the plugins (the renderer
    // starts asynchronously), then finish them.
    while app.plugins_state() == bevy::app::PluginsState::Adding {
        bevy::tasks::tick_global_task_pools_on_main_thread();
    }
    app.finish();
    app.cleanup();
    app
}

/// How a test view is set up.
#[derive(Clone, Copy)]
pub struct View {
    pub eye: Vec3,
    pub target: Vec3,
    pub hdr: bool,
    pub msaa: Msaa,
    pub epsilon: f32,
    pub method: ForestMethod,
}

impl View {
    pub fn at(eye: Vec3, target: Vec3) -> Self {
        Self {
            eye,
            target,
            hdr: false,
            msaa: Msaa::Off,
            epsilon: 4.0,
            method: ForestMethod::QuadStream,
        }
    }
}

/// A camera drawing the forests into a new `SIZE` image; returns the camera and the image.
pub fn spawn_camera(app: &mut App, v: View) -> (Entity, Handle<Image>) {
    let mut image =
        Image::new_target_texture(SIZE.0, SIZE.1, wgpu::TextureFormat::Rgba8UnormSrgb, None);
    image.texture_descriptor.usage |= wgpu::TextureUsages::COPY_SRC;
    let handle = app.world_mut().resource_mut::<Assets<Image>>().add(image);
    let mut e = app.world_mut().spawn((
        Camera3d::default(),
        Camera {
            clear_color: ClearColorConfig::Custom(Color::srgb(CLEAR[0], CLEAR[1], CLEAR[2])),
            ..default()
        },
        RenderTarget::Image(handle.clone().into()),
        Tonemapping::None,
        DebandDither::Disabled,
        bevy::camera::Exposure { ev100: EV100 },
        v.msaa,
        ForestCamera {
            epsilon: v.epsilon,
            method: v.method,
            ..default()
        },
        Transform::from_translation(v.eye).looking_at(v.target, Vec3::Y),
    ));
    if v.hdr {
        e.insert(bevy::camera::Hdr);
    }
    (e.id(), handle)
}

/// Spawn the forest `small.forest` at `transform`.
pub fn spawn_forest(app: &mut App, transform: Transform) -> Entity {
    let handle = app
        .world()
        .resource::<AssetServer>()
        .load::<forest_bevy::ForestAsset>("small.forest");
    app.world_mut().spawn((ForestScene(handle), transform)).id()
}

/// Update until `done` holds (at most `frames` frames); panics naming `what` otherwise.
pub fn update_until(app: &mut App, frames: u32, what: &str, done: impl Fn(&mut App) -> bool) {
    for _ in 0..frames {
        app.update();
        if done(app) {
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    panic!("{what} did not happen in {frames} frames");
}

/// Frames until every camera draws quads, and a few more so that the image holds a frame
/// drawn after the stream was sized.
pub fn settle(app: &mut App, camera: Entity, forest: Entity) {
    update_until(app, 600, "the forest drawing quads", |app| {
        app.world()
            .resource::<forest_bevy::ForestStats>()
            .get(camera, forest)
            .is_some_and(|s| s.quads > 0)
    });
    for _ in 0..6 {
        app.update();
    }
}

/// Frames until `ready` holds for the camera's statistics of the forest, and a few more.
pub fn settle_on(
    app: &mut App,
    camera: Entity,
    forest: Entity,
    ready: impl Fn(&forest_bevy::ForestViewStats) -> bool,
) {
    let stats = |app: &App| {
        app.world()
            .resource::<forest_bevy::ForestStats>()
            .get(camera, forest)
            .cloned()
    };
    for _ in 0..600 {
        app.update();
        if stats(app).is_some_and(|s| ready(&s)) {
            for _ in 0..6 {
                app.update();
            }
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    panic!("the forest's statistics never got ready: {:?}", stats(app));
}

/// Read a render-target image back from the render world.
pub fn read(app: &mut App, image: &Handle<Image>) -> image::RgbaImage {
    let world = app.sub_app(RenderApp).world();
    let device = world.resource::<RenderDevice>().wgpu_device().clone();
    let queue: wgpu::Queue = (**world.resource::<RenderQueue>()).clone();
    let gpu = world
        .resource::<RenderAssets<GpuImage>>()
        .get(image.id())
        .expect("the image is on the GPU");
    let (w, h) = SIZE;
    let row = (w * 4).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let buf = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("read-back"),
        size: u64::from(row * h),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut enc = device.create_command_encoder(&Default::default());
    enc.copy_texture_to_buffer(
        gpu.texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buf,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: None,
            },
        },
        wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
    );
    queue.submit([enc.finish()]);
    buf.slice(..).map_async(wgpu::MapMode::Read, |_| {});
    device.poll(wgpu::PollType::wait_indefinitely()).unwrap();
    let data = buf.slice(..).get_mapped_range().unwrap();
    let mut out = image::RgbaImage::new(w, h);
    for y in 0..h {
        let src = &data[(y * row) as usize..(y * row + w * 4) as usize];
        out.as_mut()[(y * w * 4) as usize..((y + 1) * w * 4) as usize].copy_from_slice(src);
    }
    out
}

/// The forest's light the test's Bevy lights should give (Bevy's PBR units: sun E/π, ambient
/// colour × brightness, exposure 2^−EV100 / 1.2), written out here rather than taken from
/// the plugin.
pub fn expected_light(sun_in_forest: Vec3) -> Lighting {
    let sun_dir = glam::Vec3::from_array(sun_in_forest.normalize().to_array());
    Lighting {
        sun_dir,
        sun: glam::Vec3::splat(LUX / std::f32::consts::PI),
        sky: glam::Vec3::splat(AMBIENT),
        ground: glam::Vec3::splat(AMBIENT),
        exposure: 2f32.powf(-EV100) / 1.2,
    }
}

/// `small.forest` drawn by `forest-render` alone (its own device, no Bevy) over the clear
/// colour, from `eye` (in the forest's frame) with Bevy's default projection (45°, near
/// 0.1 m, infinite reverse-Z), at ε `epsilon`, `samples` samples per pixel.
pub fn reference(
    eye: Vec3,
    target: Vec3,
    epsilon: f32,
    light: Lighting,
    samples: u32,
) -> image::RgbaImage {
    reference_with(
        eye,
        target,
        epsilon,
        light,
        samples,
        ForestMethod::QuadStream,
    )
}

/// [`reference`] drawn with `method`.
pub fn reference_with(
    eye: Vec3,
    target: Vec3,
    epsilon: f32,
    light: Lighting,
    samples: u32,
    method: ForestMethod,
) -> image::RgbaImage {
    reference_in(eye, target, epsilon, light, samples, method, None)
}

/// [`reference_with`] in `season` (`None`: the models' own colours).
pub fn reference_in(
    eye: Vec3,
    target: Vec3,
    epsilon: f32,
    light: Lighting,
    samples: u32,
    method: ForestMethod,
    season: Option<f32>,
) -> image::RgbaImage {
    let clear = Color::srgb(CLEAR[0], CLEAR[1], CLEAR[2]).to_linear();
    let colour = wgpu::Color {
        r: f64::from(clear.red),
        g: f64::from(clear.green),
        b: f64::from(clear.blue),
        a: 1.0,
    };
    reference_over(
        eye,
        target,
        epsilon,
        light,
        samples,
        colour,
        (method, season),
    )
}

/// Save Bevy's frame and the reference as `view-NAME.png` and `view-NAME-reference.png`,
/// then [`assert_flip`] them.
pub fn compare_view(
    name: &str,
    reference: &image::RgbaImage,
    bevy: &image::RgbaImage,
    limit: f32,
) -> f32 {
    bevy.save(out_dir().join(format!("view-{name}.png")))
        .unwrap();
    reference
        .save(out_dir().join(format!("view-{name}-reference.png")))
        .unwrap();
    assert_flip(name, reference, bevy, limit)
}

/// The trees' coverage in [`reference`]'s frame (MSAA off): its alpha over transparent black.
pub fn coverage(eye: Vec3, target: Vec3, epsilon: f32) -> Vec<u8> {
    let img = reference_over(
        eye,
        target,
        epsilon,
        expected_light(sun_dir()),
        1,
        wgpu::Color::TRANSPARENT,
        (ForestMethod::QuadStream, None),
    );
    img.pixels().map(|p| p[3]).collect()
}

fn reference_over(
    eye: Vec3,
    target: Vec3,
    epsilon: f32,
    light: Lighting,
    samples: u32,
    colour: wgpu::Color,
    (method, season): (ForestMethod, Option<f32>),
) -> image::RgbaImage {
    let ctx = GpuContext::headless().expect("a GPU adapter (lavapipe)");
    let dir = assets();
    let forest = forest_format::forest::Forest::load(&dir.join("small.forest")).unwrap();
    let species = vec![forest_render::SpeciesData::load(&dir.join("bush.atlas")).unwrap()];
    let scene = std::sync::Arc::new(GpuScene::new(&ctx, &species, &forest).unwrap());
    let target_img = forest_render::target::Target::new(&ctx, SIZE.0, SIZE.1);
    let opts = RendererOptions {
        format: forest_render::target::TARGET_FORMAT,
        reverse_z: true,
        sample_count: samples,
        viewport: SIZE,
        min_epsilon: epsilon,
        atmosphere: forest_bevy::light::atmosphere(None, Vec3::ZERO, 1.0),
        ..Default::default()
    };
    let stream = QuadStream::new(&ctx.device, scene, &opts).unwrap();
    // The models, read back from the atlas as the plugin reads them.
    let geometry = method.needs_models().then(|| {
        let model = forest_format::model::PreparedModel::load(&dir.join("bush.atlas"))
            .unwrap()
            .expect("the test atlas holds its model");
        let prepared = PreparedGeometry::new(&[GeometrySpecies::new(
            model.into(),
            &species[0].atlas.manifest,
        )]);
        GeometryRenderer::with_targets(&ctx, &prepared, &forest, &opts).unwrap()
    });
    let mut renderer = ForestRenderer::new(stream, geometry);
    renderer.set_method(&ctx, method.method()).unwrap();
    // Bevy's own matrices (its glam release), as the forest crates' numbers.
    let g = |m: Mat4| glam::Mat4::from_cols_array(&m.to_cols_array());
    let frame = FrameParams {
        view: g(Transform::from_translation(eye)
            .looking_at(target, Vec3::Y)
            .to_matrix()
            .inverse()),
        proj: g(bevy::camera::CameraProjection::get_clip_from_view(
            &PerspectiveProjection {
                aspect_ratio: SIZE.0 as f32 / SIZE.1 as f32,
                ..default()
            },
        )),
        viewport: SIZE,
        epsilon,
        light,
        wind: forest_format::wind::Wind::CALM,
        season,
    };
    let msaa = (samples > 1).then(|| {
        let make = |format| {
            ctx.device
                .create_texture(&wgpu::TextureDescriptor {
                    label: None,
                    size: wgpu::Extent3d {
                        width: SIZE.0,
                        height: SIZE.1,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: samples,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                    view_formats: &[],
                })
                .create_view(&Default::default())
        };
        (make(opts.format), make(wgpu::TextureFormat::Depth32Float))
    });
    // Frames until the stream holds the whole view.
    for _ in 0..8 {
        renderer.prepare(&ctx.queue, &frame).unwrap();
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        renderer.encode_compute(&mut enc);
        let targets = match &msaa {
            Some((c, d)) => Targets {
                resolve: Some(&target_img.colour_view),
                ..Targets::cleared(c, d, colour, 0.0)
            },
            None => Targets::cleared(&target_img.colour_view, &target_img.depth_view, colour, 0.0),
        };
        {
            let mut pass = targets.begin(&mut enc, "reference", renderer.draw_timestamps());
            renderer.render(&mut pass);
        }
        renderer.resolve_times(&mut enc);
        ctx.queue.submit([enc.finish()]);
        let stats = renderer.read_stats(&ctx);
        if !renderer.fit(&ctx.device, &stats).unwrap() {
            break;
        }
    }
    ctx.check_errors().unwrap();
    target_img.read(&ctx)
}

/// Mean FLIP of `test` against `reference`; both and the error map are written to the test
/// output folder under `name` when it exceeds `limit`.
pub fn assert_flip(
    name: &str,
    reference: &image::RgbaImage,
    test: &image::RgbaImage,
    limit: f32,
) -> f32 {
    let (mean, map) = forest_metrics::flip(reference, test).unwrap();
    if mean > limit {
        let d = out_dir();
        reference
            .save(d.join(format!("{name}-reference.png")))
            .unwrap();
        test.save(d.join(format!("{name}-bevy.png"))).unwrap();
        map.save(d.join(format!("{name}-flip.png"))).unwrap();
        panic!(
            "{name}: mean FLIP {mean:.4} > {limit} (images in {})",
            d.display()
        );
    }
    mean
}
