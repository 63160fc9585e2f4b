//! Embedding the forest in a host's own wgpu renderer: a plain winit + wgpu program that draws
//! its sky and ground and then the trees through the public API of `forest-render` and
//! `forest-baselines` (see `host.rs`): the hybrid where the atlases hold their models, else
//! the quad stream.
//!
//! ```sh
//! cargo run --release -p forest-baselines --example embed -- out/forest-100k.forest
//! cargo run --release -p forest-baselines --example embed -- out/forest-100k.forest --headless shot.png
//! ```
//! Options: `--eye X,Y,Z`, `--target X,Y,Z` (default: the forest's `inside` view,
//! `forest_scene::views::start`, standing clear of every tree), `--size WxH`, `--epsilon PX`.
//! The window slowly turns the view around the eye; Escape quits.

mod host;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use forest_baselines::{GeometrySpecies, PreparedGeometry};
use forest_format::forest::Forest;
use forest_format::model::PreparedModel;
use forest_render::target::Target;
use forest_render::{GpuContext, GpuScene, SpeciesData};
use glam::Vec3;
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::window::{Window, WindowId};

type Error = Box<dyn std::error::Error>;

/// What the host draws: the forest, its species' atlases on the GPU (named relative to the
/// forest's folder) and, where every atlas holds one, their models for the hybrid.
struct Loaded {
    forest: Forest,
    scene: Arc<GpuScene>,
    models: Option<PreparedGeometry>,
    /// The forest's start view (eye, target): on its ground, clear of every tree.
    start: (Vec3, Vec3),
}

/// The eye and target to draw from: those given, the start view's for the rest.
fn view(l: &Loaded, eye: Option<Vec3>, target: Option<Vec3>) -> (Vec3, Vec3) {
    (eye.unwrap_or(l.start.0), target.unwrap_or(l.start.1))
}

fn load(ctx: &GpuContext, path: &Path) -> Result<Loaded, Error> {
    let forest = Forest::load(path)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let species = forest
        .species
        .iter()
        .map(|s| SpeciesData::load(&dir.join(s)))
        .collect::<Result<Vec<_>, _>>()?;
    let mut models = Vec::new();
    for (name, s) in forest.species.iter().zip(&species) {
        match PreparedModel::load(&dir.join(name))? {
            Some(m) => models.push(GeometrySpecies::new(m.into(), &s.atlas.manifest)),
            None => {
                eprintln!("embed: {name} holds no model: drawing the quad stream alone");
                break;
            }
        }
    }
    let models = (models.len() == species.len()).then(|| PreparedGeometry::new(&models));
    let scene = Arc::new(GpuScene::new(ctx, &species, &forest)?);
    let start = forest_render::start_view(&forest, &species);
    Ok(Loaded {
        forest,
        scene,
        models,
        start,
    })
}

/// Render one frame offscreen into a target the host clears itself, and read it back.
pub fn headless(
    forest: &Path,
    eye: Vec3,
    target: Vec3,
    size: (u32, u32),
    epsilon: f32,
) -> Result<image::RgbaImage, Error> {
    headless_with(forest, Some(eye), Some(target), size, epsilon, false)
}

/// [`headless`], with the host's sun shadow map (the forest casting into it and receiving it)
/// when `shadows`, and the start view's eye or target where one is not given.
pub fn headless_with(
    forest: &Path,
    eye: Option<Vec3>,
    target: Option<Vec3>,
    size: (u32, u32),
    epsilon: f32,
    shadows: bool,
) -> Result<image::RgbaImage, Error> {
    let ctx = GpuContext::headless()?;
    let l = load(&ctx, forest)?;
    let (eye, target) = view(&l, eye, target);
    let out = Target::new(&ctx, size.0, size.1);
    let mut host = host::Host::new(
        &ctx,
        l.scene,
        &l.forest,
        l.models.as_ref(),
        out.format,
        size,
        epsilon,
        shadows,
    )?;
    let frame = host::frame(eye, target, size, epsilon, forest_format::wind::Wind::CALM);
    host.draw(&ctx.device, &ctx.queue, &out.colour_view, &frame)?;
    let img = out.read(&ctx);
    ctx.check_errors()?;
    Ok(img)
}

struct App {
    forest: PathBuf,
    eye: Option<Vec3>,
    target: Option<Vec3>,
    size: (u32, u32),
    epsilon: f32,
    shadows: bool,
    start: std::time::Instant,
    gfx: Option<(
        Arc<Window>,
        wgpu::Surface<'static>,
        wgpu::SurfaceConfiguration,
        GpuContext,
        host::Host,
    )>,
    error: Option<Error>,
}

impl App {
    fn init(&mut self, event_loop: &ActiveEventLoop) -> Result<(), Error> {
        let attrs = Window::default_attributes()
            .with_title("forest-render embedded")
            .with_inner_size(winit::dpi::PhysicalSize::new(self.size.0, self.size.1));
        let window = Arc::new(event_loop.create_window(attrs)?);
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
                Box::new(event_loop.owned_display_handle()),
            ));
        let surface = instance.create_surface(window.clone())?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            compatible_surface: Some(&surface),
            ..Default::default()
        }))?;
        let ctx = GpuContext::from_adapter(&adapter)?;
        let inner = window.inner_size();
        let config = surface
            .get_default_config(&adapter, inner.width.max(1), inner.height.max(1))
            .ok_or("the window's surface is not supported by the adapter")?;
        surface.configure(&ctx.device, &config);
        let l = load(&ctx, &self.forest)?;
        (self.eye, self.target) = {
            let (eye, target) = view(&l, self.eye, self.target);
            (Some(eye), Some(target))
        };
        let host = host::Host::new(
            &ctx,
            l.scene,
            &l.forest,
            l.models.as_ref(),
            config.format,
            (config.width, config.height),
            self.epsilon,
            self.shadows,
        )?;
        self.gfx = Some((window, surface, config, ctx, host));
        Ok(())
    }

    fn redraw(&mut self) -> Result<(), Error> {
        let Some((window, surface, config, ctx, host)) = &mut self.gfx else {
            return Ok(());
        };
        let texture = match surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            _ => {
                surface.configure(&ctx.device, config);
                return Ok(());
            }
        };
        let view = texture.texture.create_view(&Default::default());
        let (Some(eye), Some(target)) = (self.eye, self.target) else {
            return Ok(());
        };
        let seconds = self.start.elapsed().as_secs_f32();
        let target = eye + glam::Quat::from_rotation_y(seconds * 0.1) * (target - eye);
        // A fresh breeze on the host's clock (wrapped within the wind's range): the trees sway.
        let wind =
            forest_format::wind::Wind::new(60.0, 8.0).at(seconds % forest_format::wind::MAX_TIME);
        let frame = host::frame(
            eye,
            target,
            (config.width, config.height),
            self.epsilon,
            wind,
        );
        host.draw(&ctx.device, &ctx.queue, &view, &frame)?;
        window.pre_present_notify();
        ctx.queue.present(texture);
        ctx.check_reported_errors()?;
        window.request_redraw();
        Ok(())
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_none()
            && let Err(e) = self.init(event_loop)
        {
            self.error = Some(e);
            event_loop.exit();
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let result = match event {
            WindowEvent::CloseRequested => {
                event_loop.exit();
                Ok(())
            }
            WindowEvent::KeyboardInput { event, .. }
                if event.logical_key
                    == winit::keyboard::Key::Named(winit::keyboard::NamedKey::Escape) =>
            {
                event_loop.exit();
                Ok(())
            }
            WindowEvent::Resized(size) => match &mut self.gfx {
                Some((_, surface, config, ctx, host)) => {
                    config.width = size.width.max(1);
                    config.height = size.height.max(1);
                    surface.configure(&ctx.device, config);
                    host.resize(&ctx.device, (config.width, config.height))
                        .map_err(Error::from)
                }
                None => Ok(()),
            },
            WindowEvent::RedrawRequested => self.redraw(),
            _ => Ok(()),
        };
        if let Err(e) = result {
            self.error = Some(e);
            event_loop.exit();
        }
    }
}

fn vec3(s: &str) -> Result<Vec3, Error> {
    let v: Vec<f32> = s.split(',').map(str::parse).collect::<Result<_, _>>()?;
    match v[..] {
        [x, y, z] => Ok(Vec3::new(x, y, z)),
        _ => Err(format!("{s:?} is not X,Y,Z").into()),
    }
}

fn run() -> Result<(), Error> {
    let mut args = std::env::args().skip(1);
    let mut forest = None;
    let (mut eye, mut target) = (None, None);
    let (mut size, mut epsilon, mut headless_out, mut shadows) = ((960, 540), 4.0, None, false);
    while let Some(a) = args.next() {
        let mut value = || args.next().ok_or(format!("{a} needs a value"));
        match a.as_str() {
            "--eye" => eye = Some(vec3(&value()?)?),
            "--target" => target = Some(vec3(&value()?)?),
            "--epsilon" => epsilon = value()?.parse()?,
            "--headless" => headless_out = Some(PathBuf::from(value()?)),
            // The host's sun shadow map, which the forest casts into and receives.
            "--shadows" => shadows = true,
            "--size" => {
                let v = value()?;
                let (w, h) = v.split_once('x').ok_or(format!("{v:?} is not WxH"))?;
                size = (w.parse()?, h.parse()?);
            }
            _ if forest.is_none() && !a.starts_with("--") => forest = Some(PathBuf::from(a)),
            _ => return Err(format!("unexpected argument {a:?}").into()),
        }
    }
    let forest =
        forest.ok_or("usage: embed FOREST [--headless OUT.png] [--shadows] [--eye X,Y,Z] …")?;
    if let Some(out) = headless_out {
        headless_with(&forest, eye, target, size, epsilon, shadows)?.save(&out)?;
        println!("wrote {}", out.display());
        return Ok(());
    }
    let mut app = App {
        forest,
        eye,
        target,
        size,
        epsilon,
        shadows,
        start: std::time::Instant::now(),
        gfx: None,
        error: None,
    };
    EventLoop::new()?.run_app(&mut app)?;
    app.error.map_or(Ok(()), Err)
}

fn main() -> std::process::ExitCode {
    match run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("embed: error: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}
