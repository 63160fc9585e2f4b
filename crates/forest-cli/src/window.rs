//! The interactive part of `forest view`: a winit window with a wgpu surface, walk/fly
//! controls, and an egui HUD (frame time, per-pass GPU times, counters, ε, method switch).
//!
//! Controls: W/A/S/D move, Q/E down/up (fly mode), right mouse button + drag looks around,
//! Shift runs, mouse wheel changes speed, F toggles walk/fly, F12 saves a screenshot, R starts
//! and stops recording a camera path, Esc quits.

use std::collections::HashSet;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result};
use forest_format::camera_path::CameraPath;
use forest_render::Camera;
use forest_render::context::GpuContext;
use forest_render::geometry::MeshMethod;
use forest_render::methods::{ForestRenderer, Method, MethodStats};
use forest_render::passes::draw::DEPTH_FORMAT;
use glam::Vec3;
use winit::application::ApplicationHandler;
use winit::event::{DeviceEvent, ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

/// Eye height above the ground in walk mode (metres).
pub const EYE_HEIGHT: f32 = 1.7;

/// What the window needs to build its renderer once it has a device.
pub type Build = Box<dyn Fn(&GpuContext, wgpu::TextureFormat) -> Result<ForestRenderer>>;

/// The walker: position, yaw and pitch (radians), speed (m/s), walk or fly.
#[derive(Clone, Copy, Debug)]
pub struct Walker {
    /// Eye position.
    pub eye: Vec3,
    /// Heading about +Y (0 looks along −Z).
    pub yaw: f32,
    /// Elevation of the view (clamped to ±85°).
    pub pitch: f32,
    /// Speed in metres per second.
    pub speed: f32,
    /// Follow the ground at eye height.
    pub walk: bool,
}

impl Walker {
    /// Unit view direction.
    pub fn forward(&self) -> Vec3 {
        Vec3::new(
            self.yaw.sin() * self.pitch.cos(),
            self.pitch.sin(),
            -self.yaw.cos() * self.pitch.cos(),
        )
    }

    /// Move for `dt` seconds with the pressed keys.
    pub fn step(&mut self, keys: &HashSet<KeyCode>, dt: f32) {
        let flat = Vec3::new(self.yaw.sin(), 0.0, -self.yaw.cos());
        let right = Vec3::new(self.yaw.cos(), 0.0, self.yaw.sin());
        let ahead = if self.walk { flat } else { self.forward() };
        let mut v = Vec3::ZERO;
        let k = |c| keys.contains(&c);
        if k(KeyCode::KeyW) {
            v += ahead;
        }
        if k(KeyCode::KeyS) {
            v -= ahead;
        }
        if k(KeyCode::KeyD) {
            v += right;
        }
        if k(KeyCode::KeyA) {
            v -= right;
        }
        if !self.walk && k(KeyCode::KeyE) {
            v += Vec3::Y;
        }
        if !self.walk && k(KeyCode::KeyQ) {
            v -= Vec3::Y;
        }
        let run = if k(KeyCode::ShiftLeft) || k(KeyCode::ShiftRight) {
            4.0
        } else {
            1.0
        };
        self.eye += v.normalize_or_zero() * self.speed * run * dt;
        if self.walk {
            self.eye.y = EYE_HEIGHT;
        }
        self.eye.y = self.eye.y.max(0.2);
    }
}

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
}

/// The viewer application.
pub struct Viewer {
    build: Build,
    size: (u32, u32),
    walker: Walker,
    epsilon: f32,
    far: f32,
    methods: Vec<Method>,
    method: usize,
    keys: HashSet<KeyCode>,
    looking: bool,
    last: Instant,
    frame_ms: f64,
    stats: MethodStats,
    recording: Option<CameraPath>,
    record_to: PathBuf,
    shots: u32,
    message: String,
    gfx: Option<Gfx>,
    error: Option<anyhow::Error>,
}

impl Viewer {
    /// A viewer starting at `walker`, offering `methods` (the first is shown first).
    pub fn new(
        build: Build,
        size: (u32, u32),
        walker: Walker,
        epsilon: f32,
        far: f32,
        methods: Vec<Method>,
        record_to: PathBuf,
    ) -> Self {
        Self {
            build,
            size,
            walker,
            epsilon,
            far,
            methods,
            method: 0,
            keys: HashSet::new(),
            looking: false,
            last: Instant::now(),
            frame_ms: 0.0,
            stats: MethodStats::default(),
            recording: None,
            record_to,
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
        Camera {
            eye: self.walker.eye,
            target: self.walker.eye + self.walker.forward(),
            fov_y_deg: 60.0,
            near: 0.1,
            far: self.far,
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
        // The offscreen target's format when the surface offers it (screenshots render into
        // one with the same pipelines), else any sRGB format.
        let format = if caps.formats.contains(&forest_render::target::TARGET_FORMAT) {
            forest_render::target::TARGET_FORMAT
        } else {
            caps.formats
                .iter()
                .copied()
                .find(|f| f.is_srgb())
                .unwrap_or(caps.formats[0])
        };
        let inner = window.inner_size();
        let mut config = surface
            .get_default_config(&adapter, inner.width.max(1), inner.height.max(1))
            .context("the window's surface is not supported by the GPU adapter")?;
        config.format = format;
        surface.configure(&ctx.device, &config);
        let renderer = (self.build)(&ctx, format)?;
        renderer.set_method(&ctx, self.methods[self.method])?;
        let egui = egui::Context::default();
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
        });
        Ok(())
    }

    fn hud(&mut self, ui_ctx: &egui::Context) -> Option<usize> {
        let mut choice = None;
        let s = &self.stats;
        egui::Window::new("forest").show(ui_ctx, |ui| {
            ui.label(format!(
                "{:.1} ms/frame ({:.0} fps)",
                self.frame_ms,
                1000.0 / self.frame_ms.max(1e-3)
            ));
            if let Some(t) = s.times {
                ui.label(format!(
                    "GPU: cull {:.2} ms, refine {:.2} ms, draw {:.2} ms",
                    t.cull_ms, t.refine_ms, t.draw_ms
                ));
            }
            ui.label(format!(
                "{} visible trees, {} primitives, {} billboards, overflow {}",
                s.visible_trees, s.primitives, s.billboards, s.overflow
            ));
            ui.add(egui::Slider::new(&mut self.epsilon, 0.5..=64.0).text("ε (px)"));
            ui.add(egui::Slider::new(&mut self.walker.speed, 0.5..=200.0).text("speed (m/s)"));
            ui.checkbox(&mut self.walker.walk, "walk (follow the ground)");
            for (i, m) in self.methods.iter().enumerate() {
                if ui.radio(i == self.method, m.name()).clicked() {
                    choice = Some(i);
                }
            }
            ui.separator();
            ui.label("W/A/S/D move · Q/E down/up (fly) · right drag: look · Shift: run");
            ui.label("wheel: speed · F: walk/fly · F12: screenshot · R: record path · Esc: quit");
            if let Some(p) = &self.recording {
                ui.label(format!("recording: {} keys", p.keys.len()));
            }
            if !self.message.is_empty() {
                ui.label(&self.message);
            }
        });
        choice
    }

    fn frame(&mut self) -> Result<()> {
        let now = Instant::now();
        let dt = (now - self.last).as_secs_f32().min(0.1);
        self.frame_ms = f64::from(dt) * 1000.0;
        self.last = now;
        self.walker.step(&self.keys, dt);
        let cam = self.camera();
        if let Some(p) = &mut self.recording {
            p.push(cam.eye, cam.target);
        }
        let Some(mut g) = self.gfx.take() else {
            return Ok(());
        };
        let result = (|| -> Result<()> {
            let output = match g.surface.get_current_texture() {
                wgpu::CurrentSurfaceTexture::Success(t)
                | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
                _ => {
                    g.surface.configure(&g.ctx.device, &g.config);
                    return Ok(());
                }
            };
            let view = output.texture.create_view(&Default::default());
            let mut enc = g.ctx.device.create_command_encoder(&Default::default());
            g.renderer.encode(&g.ctx, &cam, &mut enc, &view, &g.depth)?;
            let raw = g.egui_state.take_egui_input(&g.window);
            let ui_ctx = g.egui.clone();
            let mut choice = None;
            let mut out = ui_ctx.run_pass(raw, |c| choice = self.hud(c));
            // egui insists that texture updates are consumed: take them out now.
            let set: Vec<_> = out.textures_delta.set.drain().collect();
            let free: Vec<_> = out.textures_delta.free.drain().collect();
            g.egui_state
                .handle_platform_output(&g.window, out.platform_output);
            let jobs = g.egui.tessellate(out.shapes, out.pixels_per_point);
            let screen = egui_wgpu::ScreenDescriptor {
                size_in_pixels: [g.config.width, g.config.height],
                pixels_per_point: out.pixels_per_point,
            };
            for (id, deltas) in &set {
                for delta in deltas {
                    g.egui_renderer
                        .update_texture(&g.ctx.device, &g.ctx.queue, *id, delta);
                }
            }
            let extra = g.egui_renderer.update_buffers(
                &g.ctx.device,
                &g.ctx.queue,
                &mut enc,
                &jobs,
                &screen,
            );
            {
                let mut pass = enc
                    .begin_render_pass(&wgpu::RenderPassDescriptor {
                        label: Some("hud"),
                        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                            view: &view,
                            depth_slice: None,
                            resolve_target: None,
                            ops: wgpu::Operations {
                                load: wgpu::LoadOp::Load,
                                store: wgpu::StoreOp::Store,
                            },
                        })],
                        depth_stencil_attachment: None,
                        timestamp_writes: None,
                        occlusion_query_set: None,
                        multiview_mask: None,
                    })
                    .forget_lifetime();
                g.egui_renderer.render(&mut pass, &jobs, &screen);
            }
            for id in &free {
                g.egui_renderer.free_texture(id);
            }
            g.ctx.queue.submit(extra.into_iter().chain([enc.finish()]));
            g.window.pre_present_notify();
            g.ctx.queue.present(output);
            self.stats = g.renderer.read_stats(&g.ctx);
            if let Some(i) = choice {
                g.renderer.set_method(&g.ctx, self.methods[i])?;
                self.method = i;
            }
            let errors = g.ctx.take_errors();
            if !errors.is_empty() {
                anyhow::bail!("the GPU reported: {}", errors.join("; "));
            }
            Ok(())
        })();
        self.gfx = Some(g);
        result
    }

    fn screenshot(&mut self) -> Result<()> {
        let Some(g) = &self.gfx else { return Ok(()) };
        if g.config.format != forest_render::target::TARGET_FORMAT {
            self.message = format!(
                "screenshots need an {:?} surface; this one is {:?} (use --path/--frames)",
                forest_render::target::TARGET_FORMAT,
                g.config.format
            );
            return Ok(());
        }
        let cam = self.camera();
        let target = forest_render::target::Target::new(&g.ctx, cam.viewport.0, cam.viewport.1);
        g.renderer.render_frame(&g.ctx, &cam, &target)?;
        let out = PathBuf::from(format!("screenshot-{:03}.png", self.shots));
        crate::render::write_png(&target.read(&g.ctx), &out)?;
        self.shots += 1;
        self.message = format!("saved {}", out.display());
        Ok(())
    }

    fn key(&mut self, event_loop: &ActiveEventLoop, code: KeyCode, pressed: bool) -> Result<()> {
        if pressed {
            self.keys.insert(code);
        } else {
            self.keys.remove(&code);
        }
        if !pressed {
            return Ok(());
        }
        match code {
            KeyCode::Escape => event_loop.exit(),
            KeyCode::KeyF => self.walker.walk = !self.walker.walk,
            KeyCode::F12 => self.screenshot()?,
            KeyCode::KeyR => match self.recording.take() {
                Some(p) if !p.keys.is_empty() => {
                    p.save(&self.record_to)?;
                    self.message = format!(
                        "saved {} keys to {}",
                        p.keys.len(),
                        self.record_to.display()
                    );
                }
                Some(_) => {}
                None => self.recording = Some(CameraPath::new(60.0)),
            },
            _ => {}
        }
        Ok(())
    }
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
                }
                Ok(())
            }
            WindowEvent::KeyboardInput { event, .. } => match event.physical_key {
                PhysicalKey::Code(code) => {
                    self.key(event_loop, code, event.state == ElementState::Pressed)
                }
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

/// The methods a viewer offers: the quad stream and impostors, and with models the geometry
/// methods (with the parameters given).
pub fn offered(mesh: Option<MeshMethod>, geometry: bool) -> Vec<Method> {
    let mut m = vec![Method::Quads, Method::Impostor];
    if geometry {
        m.push(Method::Mesh(MeshMethod::Lods(Default::default())));
        m.push(Method::Mesh(MeshMethod::Stochastic(Default::default())));
        m.push(Method::Mesh(MeshMethod::Full { depth_sort: true }));
        if let Some(x) = mesh {
            // The method named on the command line, with its parameters, first.
            m.retain(|y| y.name() != Method::Mesh(x).name());
            m.insert(0, Method::Mesh(x));
        }
    }
    m
}
