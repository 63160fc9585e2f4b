//! The interactive part of `forest view`: a winit window with a wgpu surface, walk/fly
//! controls, and an egui HUD (frame time, per-pass GPU times, counters, quads per level, ε,
//! method switch, debug views).
//!
//! Controls ([`KEYS`]): W/A/S/D move, Q/E down/up (fly mode), right mouse button + drag looks
//! around, Shift runs, mouse wheel changes speed, F toggles walk/fly, 1–6 pick a method, `[` and
//! `]` halve and double ε, V cycles the debug views, G and Shift+G make the wind stronger and
//! weaker, Y and Shift+Y step the season on and back, H hides the HUD, F12 saves a screenshot, R
//! starts and stops recording a camera path, P plays the `--path` back, Esc quits.
//!
//! On stdout the viewer says when its first frame is on screen and where each screenshot went
//! (one line each), so scripts and the tests can drive it.

mod frame;
mod hud;
mod screenshot;
mod steps;
mod walker;

use steps::{season_name, season_step, wind_step};

pub use walker::Walker;

use forest_render::ForestView;
use std::collections::HashSet;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result};
use forest_baselines::geometry::GeometryRenderer;
use forest_baselines::geometry::MeshMethod;
use forest_baselines::hybrid::Hybrid;
use forest_baselines::methods::{ForestRenderer, Method, MethodStats};
use forest_format::camera_path::CameraPath;
use forest_render::context::GpuContext;
use forest_render::options::DebugView;
use forest_render::target::DEPTH_FORMAT;
use forest_render::{Camera, QuadStream};
use glam::Vec3;
use winit::application::ApplicationHandler;
use winit::event::{DeviceEvent, ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

/// Eye height above the ground in walk mode (metres).
pub const EYE_HEIGHT: f32 = 1.7;

/// Range of the time-of-day slider and the T key (local solar hours: sunrise to sunset).
pub const HOURS: (f32, f32) = (6.0, 18.0);
/// The sun's elevation at noon under the time-of-day control (degrees).
pub const NOON_ELEVATION: f32 = 65.0;

/// Range of the ε slider and the [ / ] keys (pixels).
pub const EPSILON_RANGE: (f32, f32) = (0.5, 64.0);

/// The key list shown on screen.
pub const KEYS: [&str; 6] = [
    "W/A/S/D move · Q/E down/up (fly) · right drag: look · Shift: run · wheel: speed",
    "F: walk/fly · 1-6: method · [ / ]: halve / double ε · V: debug view · H: hide HUD",
    "T / Shift+T: time of day one hour later / earlier (sun, its colour and the sky)",
    "G / Shift+G: wind one step stronger / weaker (calm, breeze … gale)",
    "Y / Shift+Y: season on / back (own colours, spring, summer, autumn, late autumn)",
    "F12: screenshot · R: record path · P: play --path · Esc: quit",
];

/// Builds the quad stream once the window has a device: for a colour format, a largest
/// viewport (pixels) and a smallest ε (pixels), which size its buffers.
pub type BuildStream =
    Box<dyn Fn(&GpuContext, wgpu::TextureFormat, (u32, u32), f32) -> Result<QuadStream>>;

/// Builds the geometry renderer (None without models) once the window has a device.
pub type BuildGeometry =
    Box<dyn Fn(&GpuContext, wgpu::TextureFormat) -> Result<Option<GeometryRenderer>>>;

struct Gfx {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    depth: wgpu::TextureView,
    ctx: GpuContext,
    renderer: ForestRenderer,
    egui: egui::Context,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
    /// The overdraw view's counters (of the surface's size, attached to the renderer) and
    /// pass, while it is shown; made again after a resize.
    overdraw: Option<Overdraw>,
}

/// What the overdraw view draws with.
struct Overdraw {
    counter: forest_render::fragments::FragmentCounter,
    pass: forest_render::fragments::OverdrawPass,
    binding: forest_render::fragments::OverdrawBinding,
}

/// What a viewer starts with.
pub struct Settings {
    /// Builds the quad stream (again when the window or ε outgrows it).
    pub build_stream: BuildStream,
    /// Builds the geometry renderer.
    pub build_geometry: BuildGeometry,
    /// Starting window size in pixels.
    pub size: (u32, u32),
    /// Starting ε in pixels.
    pub epsilon: f32,
    /// The forest's extent (metres from the origin), for the far plane.
    pub extent: f32,
    /// The forest's terrain, which walking follows (`None`: flat ground at y = 0).
    pub terrain: Option<forest_format::terrain::Terrain>,
    /// Where the walker starts without a path: eye and a point looked at (`None`: the origin
    /// at eye height, looking along −Z).
    pub start: Option<(Vec3, Vec3)>,
    /// The methods offered (see [`offered`]).
    pub methods: Vec<Method>,
    /// Index of the starting method in `methods`.
    pub method: usize,
    /// Starting debug view.
    pub debug_view: DebugView,
    /// The time of day the HUD starts at (hours, 6–18): `--time`, else noon. The light is
    /// the one the renderers were built with until the time is first changed.
    pub hour: f32,
    /// The sun's shadows (`None`: off).
    pub shadows: Option<forest_render::shadow::ShadowOptions>,
    /// The wind the viewer starts in; its time is where the wind's clock starts (seconds),
    /// and the clock then runs in real time.
    pub wind: forest_format::wind::Wind,
    /// The season the viewer starts in (`None`: the models' own colours).
    pub season: Option<f32>,
    /// A camera path to play from the start (P replays it).
    pub path: Option<CameraPath>,
    /// Where R saves a recorded path.
    pub record_to: PathBuf,
    /// Folder of F12 screenshots.
    pub screenshots: PathBuf,
}

/// The viewer application.
pub struct Viewer {
    build_stream: BuildStream,
    build_geometry: BuildGeometry,
    /// Viewport and ε the stream's buffers were sized for.
    sized: ((u32, u32), f32),
    /// A size the stream could not grow to (not retried until the wish changes).
    grow_failed: Option<((u32, u32), f32)>,
    size: (u32, u32),
    walker: Walker,
    terrain: Option<forest_format::terrain::Terrain>,
    epsilon: f32,
    /// The time of day the HUD shows (hours); it lights the forest from its first change on
    /// (until then the light is the one the viewer was started with).
    hour: f32,
    /// Whether `hour` changed since the renderer's light was last set.
    hour_changed: bool,
    shadows: Option<forest_render::shadow::ShadowOptions>,
    /// The wind drawn (its time is the wind's clock, advanced each frame by the real time
    /// elapsed and wrapped within [`forest_format::wind::MAX_TIME`]).
    wind: forest_format::wind::Wind,
    /// The season drawn (`None`: the models' own colours).
    season: Option<f32>,
    extent: f32,
    fov_deg: f32,
    methods: Vec<Method>,
    method: usize,
    debug: DebugView,
    show_hud: bool,
    /// Whether frames gather pipeline statistics for the HUD.
    count_work: bool,
    path: Option<CameraPath>,
    /// Next key of `path` to show while playing.
    playing: Option<usize>,
    screenshots: PathBuf,
    first_frame: bool,
    keys: HashSet<KeyCode>,
    looking: bool,
    last: Instant,
    frame_ms: f64,
    stats: MethodStats,
    /// Each shadow cascade's light-view counters (the quad stream's), while shadows are on.
    shadow_stats: Vec<forest_render::FrameStats>,
    recording: Option<CameraPath>,
    record_to: PathBuf,
    shots: u32,
    message: String,
    gfx: Option<Gfx>,
    error: Option<anyhow::Error>,
}

impl Viewer {
    /// A viewer with these settings, standing at its start (or at the path's first key).
    pub fn new(st: Settings) -> Self {
        let ground = |x, z| forest_format::terrain::ground_height(st.terrain.as_ref(), x, z);
        let walker = match &st.path {
            Some(p) => Walker::looking_at(
                Vec3::from_array(p.keys[0].eye),
                Vec3::from_array(p.keys[0].target),
                5.0,
                ground(p.keys[0].eye[0], p.keys[0].eye[2]),
            ),
            None if st.start.is_some() => {
                let (eye, target) = st.start.unwrap_or_default();
                Walker::looking_at(eye, target, 5.0, ground(eye.x, eye.z))
            }
            None => Walker {
                eye: Vec3::new(0.0, ground(0.0, 0.0) + EYE_HEIGHT, 0.0),
                yaw: 0.0,
                pitch: 0.0,
                speed: 5.0,
                walk: true,
            },
        };
        Self {
            build_stream: st.build_stream,
            build_geometry: st.build_geometry,
            sized: (st.size, st.epsilon),
            grow_failed: None,
            size: st.size,
            walker,
            terrain: st.terrain,
            epsilon: st.epsilon,
            hour: st.hour.clamp(HOURS.0, HOURS.1),
            shadows: st.shadows,
            wind: st.wind,
            season: st.season,
            hour_changed: false,
            extent: st.extent,
            fov_deg: st.path.as_ref().map_or(60.0, |p| p.fov_deg),
            method: st.method.min(st.methods.len().saturating_sub(1)),
            methods: st.methods,
            debug: st.debug_view,
            show_hud: true,
            count_work: true,
            playing: st.path.as_ref().map(|_| 0),
            path: st.path,
            screenshots: st.screenshots,
            first_frame: true,
            keys: HashSet::new(),
            looking: false,
            last: Instant::now(),
            frame_ms: 0.0,
            stats: MethodStats::default(),
            shadow_stats: Vec::new(),
            recording: None,
            record_to: st.record_to,
            shots: 0,
            message: String::new(),
            gfx: None,
            error: None,
        }
    }

    /// Open the window and run until it closes.
    pub fn run(mut self) -> Result<()> {
        let event_loop = EventLoop::new().context(
            "cannot open a window (no display?): set DISPLAY or WAYLAND_DISPLAY, or use \
             --path FILE --frames DIR to render headless",
        )?;
        event_loop.run_app(&mut self)?;
        match self.error {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    fn camera(&self) -> Camera {
        let size = self
            .gfx
            .as_ref()
            .map(|g| (g.config.width, g.config.height))
            .unwrap_or(self.size);
        let (eye, target) = match (&self.path, self.playing) {
            (Some(p), Some(i)) => {
                let k = p.keys[i.min(p.keys.len() - 1)];
                (Vec3::from_array(k.eye), Vec3::from_array(k.target))
            }
            _ => (self.walker.eye, self.walker.eye + self.walker.forward()),
        };
        Camera {
            eye,
            target,
            fov_y_deg: self.fov_deg,
            near: 0.1,
            far: forest_format::forest::far_plane(self.extent, eye),
            viewport: size,
            epsilon: self.epsilon,
        }
    }

    fn init(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let window = Arc::new(
            event_loop.create_window(
                Window::default_attributes()
                    .with_title("forest view")
                    .with_inner_size(winit::dpi::PhysicalSize::new(self.size.0, self.size.1)),
            )?,
        );
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
                Box::new(event_loop.owned_display_handle()),
            ));
        let surface = instance.create_surface(window.clone())?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            compatible_surface: Some(&surface),
            ..Default::default()
        }))
        .context(
            "no GPU adapter can draw to this window: install a Vulkan driver (for example \
             `apt-get install mesa-vulkan-drivers`)",
        )?;
        let ctx = GpuContext::from_adapter(&adapter)?;
        let caps = surface.get_capabilities(&adapter);
        // A format screenshots can read back (sRGB first), else any sRGB one, else the first.
        let format = forest_render::target::READABLE_FORMATS
            .into_iter()
            .find(|f| caps.formats.contains(f))
            .or_else(|| caps.formats.iter().copied().find(|f| f.is_srgb()))
            .or_else(|| caps.formats.first().copied())
            .context("the window's surface offers no colour format")?;
        let inner = window.inner_size();
        let mut config = surface
            .get_default_config(&adapter, inner.width.max(1), inner.height.max(1))
            .context("the window's surface is not supported by the GPU adapter")?;
        config.format = format;
        surface.configure(&ctx.device, &config);
        let renderer = assemble(
            &ctx,
            self.methods[self.method],
            self.debug,
            (self.build_stream)(&ctx, format, self.sized.0, self.sized.1)?,
            (self.build_geometry)(&ctx, format)?,
            self.shadows,
        )?;
        let egui = egui::Context::default();
        // egui bundles no font by default: the HUD uses the one the charts embed.
        let mut fonts = egui::FontDefinitions::empty();
        fonts.font_data.insert(
            "DejaVuSans".into(),
            Arc::new(egui::FontData::from_static(crate::FONT)),
        );
        for family in [egui::FontFamily::Proportional, egui::FontFamily::Monospace] {
            fonts.families.insert(family, vec!["DejaVuSans".into()]);
        }
        egui.set_fonts(fonts);
        let egui_state = egui_winit::State::new(
            egui.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            None,
        );
        let egui_renderer =
            egui_wgpu::Renderer::new(&ctx.device, format, egui_wgpu::RendererOptions::default());
        let depth = depth_view(&ctx, &config);
        self.gfx = Some(Gfx {
            window,
            surface,
            config,
            depth,
            ctx,
            renderer,
            egui,
            egui_state,
            egui_renderer,
            overdraw: None,
        });
        Ok(())
    }

    fn set_method(&mut self, i: usize) -> Result<()> {
        if let (Some(g), Some(m)) = (&mut self.gfx, self.methods.get(i)) {
            g.renderer.set_method(&g.ctx, *m)?;
            self.method = i;
        }
        Ok(())
    }

    /// The stream overflowed: when the window is larger or ε smaller than its buffers were
    /// sized for, resize the stream's buffers (the scene and the geometry renderer are kept). If
    /// that fails (the device's limits), the HUD says so and the overflow counter stays the only
    /// effect.
    fn grow_stream(&mut self, viewport: (u32, u32)) -> Result<()> {
        let ((w, h), eps) = self.sized;
        let wish = (
            (viewport.0.max(w), viewport.1.max(h)),
            self.epsilon.min(eps),
        );
        if wish == self.sized || self.grow_failed == Some(wish) {
            return Ok(());
        }
        let Some(g) = &mut self.gfx else {
            return Ok(());
        };
        // The stream's own buffers grow; the scene on the GPU is kept as it is.
        match g.renderer.stream.resize_for(&g.ctx.device, wish.0, wish.1) {
            Ok(()) => {
                let quads = g.renderer.stream.capacity.quads;
                self.sized = wish;
                let ((w, h), eps) = wish;
                self.say(format!(
                    "stream resized for {w}x{h} at ε {eps:.1}: {quads} quads"
                ));
            }
            Err(e) => {
                self.grow_failed = Some(wish);
                self.say(format!("the stream cannot grow: {e:#}"));
            }
        }
        Ok(())
    }

    /// Show `text` in the HUD and print it as one stdout line (scripts and tests read these).
    fn say(&mut self, text: String) {
        println!("forest view: {text}");
        self.message = text;
    }

    fn set_debug(&mut self, v: DebugView) {
        self.debug = v;
        if let Some(g) = &mut self.gfx {
            g.renderer.stream.set_debug_view(v);
            if v != DebugView::Overdraw {
                detach_overdraw(g);
            }
        }
    }

    /// A key went down or up; `repeat`: the keyboard's auto-repeat of a held key, which moves
    /// but does not toggle again.
    fn key(
        &mut self,
        event_loop: &ActiveEventLoop,
        code: KeyCode,
        pressed: bool,
        repeat: bool,
    ) -> Result<()> {
        if pressed {
            self.keys.insert(code);
        } else {
            self.keys.remove(&code);
        }
        if !pressed || repeat {
            return Ok(());
        }
        match code {
            KeyCode::Escape => event_loop.exit(),
            KeyCode::KeyF => self.walker.walk = !self.walker.walk,
            KeyCode::KeyH => self.show_hud = !self.show_hud,
            KeyCode::BracketLeft => self.epsilon = (self.epsilon / 2.0).max(EPSILON_RANGE.0),
            KeyCode::BracketRight => self.epsilon = (self.epsilon * 2.0).min(EPSILON_RANGE.1),
            KeyCode::KeyV => {
                let i = DebugView::ALL.iter().position(|v| *v == self.debug);
                let next = DebugView::ALL[(i.unwrap_or(0) + 1) % DebugView::ALL.len()];
                self.set_debug(next);
            }
            KeyCode::KeyP if self.path.is_some() => self.playing = Some(0),
            KeyCode::KeyT => {
                let shift = self.keys.contains(&KeyCode::ShiftLeft)
                    || self.keys.contains(&KeyCode::ShiftRight);
                let step = if shift { -1.0 } else { 1.0 };
                self.hour = (self.hour + step).clamp(HOURS.0, HOURS.1);
                self.hour_changed = true;
            }
            KeyCode::KeyG => {
                let shift = self.keys.contains(&KeyCode::ShiftLeft)
                    || self.keys.contains(&KeyCode::ShiftRight);
                self.wind.speed = wind_step(self.wind.speed, !shift);
                self.say(format!("wind {:.0} m/s", self.wind.speed));
            }
            KeyCode::KeyY => {
                let shift = self.keys.contains(&KeyCode::ShiftLeft)
                    || self.keys.contains(&KeyCode::ShiftRight);
                self.season = season_step(self.season, !shift);
                self.say(format!("season: {}", season_name(self.season)));
            }
            KeyCode::Digit1 => self.set_method(0)?,
            KeyCode::Digit2 => self.set_method(1)?,
            KeyCode::Digit3 => self.set_method(2)?,
            KeyCode::Digit4 => self.set_method(3)?,
            KeyCode::Digit5 => self.set_method(4)?,
            KeyCode::Digit6 => self.set_method(5)?,
            KeyCode::F12 => {
                // A failed screenshot is reported in the HUD and on stderr; the walk goes on.
                if let Err(e) = self.screenshot() {
                    self.message = format!("screenshot failed: {e:#}");
                    eprintln!("forest view: {}", self.message);
                }
            }
            KeyCode::KeyR => match self.recording.take() {
                Some(p) if !p.keys.is_empty() => {
                    // A path saved earlier (or any file of that name) is kept: a new name.
                    let to = crate::guard::unused(&self.record_to);
                    let text = match p.save(&to) {
                        Ok(()) => format!("saved {} keys to {}", p.keys.len(), to.display()),
                        // Keep walking; the message says why nothing was saved.
                        Err(e) => format!("could not save the path: {e}"),
                    };
                    self.say(text);
                }
                Some(_) => {}
                None => self.recording = Some(CameraPath::new(self.fov_deg)),
            },
            _ => {}
        }
        Ok(())
    }
}

/// Stop counting fragments: the overdraw view's counters are dropped.
fn detach_overdraw(g: &mut Gfx) {
    if g.overdraw.take().is_some() {
        g.renderer.set_fragment_counter(&g.ctx.device, None);
    }
}

/// Make the overdraw view's counters for the surface's size and attach them to the renderer,
/// when missing.
fn overdraw(g: &mut Gfx) -> Result<()> {
    if g.overdraw.is_none() {
        let counter = forest_render::fragments::FragmentCounter::new(
            &g.ctx.device,
            g.config.width,
            g.config.height,
            g.renderer.stream.options_built().reverse_z,
        )?;
        let pass = forest_render::fragments::OverdrawPass::new(&g.ctx.device, g.config.format);
        let binding = pass.bind(&g.ctx.device, &counter, true);
        g.renderer
            .set_fragment_counter(&g.ctx.device, Some(&counter));
        g.overdraw = Some(Overdraw {
            counter,
            pass,
            binding,
        });
    }
    Ok(())
}

/// A renderer of `stream` and `geometry` showing `method` and `debug`.
fn assemble(
    ctx: &GpuContext,
    method: Method,
    debug: DebugView,
    stream: QuadStream,
    geometry: Option<GeometryRenderer>,
    shadows: Option<forest_render::shadow::ShadowOptions>,
) -> Result<ForestRenderer> {
    let mut r = ForestRenderer::new(stream, geometry);
    r.set_method(ctx, method)?;
    r.set_shadows(&ctx.device, shadows)?;
    r.stream.set_debug_view(debug);
    Ok(r)
}

fn depth_view(ctx: &GpuContext, config: &wgpu::SurfaceConfiguration) -> wgpu::TextureView {
    ctx.device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some("window depth"),
            size: wgpu::Extent3d {
                width: config.width,
                height: config.height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        })
        .create_view(&Default::default())
}

impl ApplicationHandler for Viewer {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_none()
            && let Err(e) = self.init(event_loop)
        {
            self.error = Some(e);
            event_loop.exit();
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        if let Some(g) = &mut self.gfx {
            let used = g.egui_state.on_window_event(&g.window, &event).consumed;
            if used && !matches!(event, WindowEvent::RedrawRequested) {
                return;
            }
        }
        let result = match event {
            WindowEvent::CloseRequested => {
                event_loop.exit();
                Ok(())
            }
            WindowEvent::Resized(size) => {
                if let Some(g) = &mut self.gfx {
                    g.config.width = size.width.max(1);
                    g.config.height = size.height.max(1);
                    g.surface.configure(&g.ctx.device, &g.config);
                    g.depth = depth_view(&g.ctx, &g.config);
                    detach_overdraw(g);
                }
                Ok(())
            }
            // Synthetic events (winit's replay of keys held when focus arrives) would toggle
            // twice what the real press toggles once.
            WindowEvent::KeyboardInput {
                event,
                is_synthetic: false,
                ..
            } => match event.physical_key {
                PhysicalKey::Code(code) => self.key(
                    event_loop,
                    code,
                    event.state == ElementState::Pressed,
                    event.repeat,
                ),
                _ => Ok(()),
            },
            WindowEvent::MouseInput {
                button: MouseButton::Right,
                state,
                ..
            } => {
                self.looking = state == ElementState::Pressed;
                Ok(())
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let d = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.walker.speed = (self.walker.speed * 1.2f32.powf(d)).clamp(0.5, 200.0);
                Ok(())
            }
            WindowEvent::RedrawRequested => self.frame(),
            _ => Ok(()),
        };
        if let Err(e) = result {
            self.error = Some(e);
            event_loop.exit();
        }
    }

    fn device_event(&mut self, _: &ActiveEventLoop, _: winit::event::DeviceId, event: DeviceEvent) {
        if let DeviceEvent::MouseMotion { delta } = event
            && self.looking
        {
            self.walker.yaw += delta.0 as f32 * 0.003;
            self.walker.pitch = (self.walker.pitch - delta.1 as f32 * 0.003).clamp(-1.48, 1.48);
        }
    }

    fn about_to_wait(&mut self, _: &ActiveEventLoop) {
        if let Some(g) = &self.gfx {
            g.window.request_redraw();
        }
    }
}

/// The methods a viewer offers, in a fixed order (keys 1–6): quads, impostor, and with models
/// LODs, stochastic, geometry, hybrid; the kind named on the command line (`chosen`) with its
/// parameters.
pub fn offered(chosen: Method, geometry: bool, hybrid: Hybrid) -> Vec<Method> {
    let mut m = vec![Method::Quads, Method::Impostor];
    if geometry {
        let mesh = match chosen {
            Method::Mesh(x) => Some(x),
            _ => None,
        };
        for default in [
            MeshMethod::Lods(Default::default()),
            MeshMethod::Stochastic(Default::default()),
            MeshMethod::Full { depth_sort: true },
        ] {
            let same_kind =
                |x: &MeshMethod| std::mem::discriminant(x) == std::mem::discriminant(&default);
            m.push(Method::Mesh(mesh.filter(same_kind).unwrap_or(default)));
        }
        m.push(match chosen {
            Method::Hybrid(h) => Method::Hybrid(h),
            _ => Method::Hybrid(hybrid),
        });
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offered_methods_keep_their_order_with_the_named_parameters() {
        assert_eq!(
            offered(Method::Quads, false, Hybrid::default()),
            vec![Method::Quads, Method::Impostor]
        );
        let names = |m: &[Method]| m.iter().map(|x| x.name()).collect::<Vec<_>>();
        let all = offered(Method::Quads, true, Hybrid::default());
        assert_eq!(
            names(&all),
            [
                "quads",
                "impostor",
                "lods",
                "stochastic",
                "geometry",
                "hybrid"
            ]
        );
        let unsorted = offered(
            Method::Mesh(MeshMethod::Full { depth_sort: false }),
            true,
            Hybrid::default(),
        );
        assert_eq!(names(&unsorted)[4], "geometry-unsorted");
        assert_eq!(unsorted.len(), 6);
        let lods = MeshMethod::Lods(forest_baselines::geometry::Lods {
            distances: [1.0, 2.0, 3.0],
        });
        assert_eq!(
            offered(Method::Mesh(lods), true, Hybrid::default())[2],
            Method::Mesh(lods)
        );
        let near = Method::Hybrid(forest_baselines::hybrid::Hybrid {
            near: forest_baselines::hybrid::Near::Metres(7.0),
            ..Default::default()
        });
        assert_eq!(offered(near, true, Hybrid::default())[5], near);
        // Beside another method, the hybrid offered is the template (--sharpen's).
        let sharp = Hybrid {
            sharpen: 100,
            ..Default::default()
        };
        assert_eq!(
            offered(Method::Quads, true, sharp)[5],
            Method::Hybrid(sharp)
        );
    }
}
