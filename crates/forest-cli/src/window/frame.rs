//! One frame of the viewer: step the camera, record the forest into the surface texture, the
//! HUD over it, present, and poll the counters (never waiting for the GPU).

use forest_render::ForestView;
use std::time::Instant;

use anyhow::Result;
use forest_format::shading::Lighting;
use forest_render::options::DebugView;

use super::{Viewer, Walker};

impl Viewer {
    pub(super) fn frame(&mut self) -> Result<()> {
        let now = Instant::now();
        let elapsed = (now - self.last).as_secs_f32();
        self.frame_ms = f64::from(elapsed) * 1000.0;
        // Slow frames move the walker at most 0.1 s's worth (no leaps after a stall).
        let dt = elapsed.min(0.1);
        self.last = now;
        let terrain = self.terrain.as_ref();
        let ground = |x, z| forest_format::terrain::ground_height(terrain, x, z);
        self.walker.step(&self.keys, dt, ground);
        // The wind's clock runs in real time (a stall is not skipped: the trees catch up),
        // wrapped so that it stays within the wind's bound.
        let span = 2.0 * forest_format::wind::MAX_TIME;
        self.wind.time = (self.wind.time + elapsed + forest_format::wind::MAX_TIME)
            .rem_euclid(span)
            - forest_format::wind::MAX_TIME;
        let cam = self.camera();
        if let (Some(p), Some(i)) = (&self.path, self.playing) {
            // One key per frame; at the end, control returns at the last key.
            if i + 1 >= p.keys.len() {
                self.playing = None;
                let floor = ground(cam.eye.x, cam.eye.z);
                self.walker = Walker::looking_at(cam.eye, cam.target, self.walker.speed, floor);
            } else {
                self.playing = Some(i + 1);
            }
        }
        if let Some(p) = &mut self.recording {
            p.push(cam.eye, cam.target);
        }
        let Some(mut g) = self.gfx.take() else {
            return Ok(());
        };
        let result = (|| -> Result<(Option<usize>, Option<DebugView>)> {
            let output = match g.surface.get_current_texture() {
                wgpu::CurrentSurfaceTexture::Success(t)
                | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
                _ => {
                    g.surface.configure(&g.ctx.device, &g.config);
                    return Ok((None, None));
                }
            };
            let view = output.texture.create_view(&Default::default());
            let mut enc = g.ctx.device.create_command_encoder(&Default::default());
            if std::mem::take(&mut self.hour_changed) {
                // The time moves the sun, its colour and the sky; the exposure stays.
                let light = Lighting {
                    exposure: g.renderer.stream.light().exposure,
                    ..Lighting::at_hour(self.hour, super::NOON_ELEVATION)
                };
                g.renderer.set_light(light)?;
            }
            g.renderer.set_wind(self.wind)?;
            g.renderer.set_season(self.season)?;
            g.renderer.set_pipeline_statistics(self.count_work);
            // A counter the device cannot hold (a window past its storage limit) is said on
            // the HUD, and the view goes back to off.
            let mut refused = false;
            let counted = self.debug == DebugView::Overdraw
                && match super::overdraw(&mut g) {
                    Ok(()) => true,
                    Err(e) => {
                        self.say(format!("overdraw view: {e:#}"));
                        refused = true;
                        false
                    }
                };
            if counted {
                // The counted frame's two draws (forest_render::fragments), then the heat
                // map over the second.
                let o = g.overdraw.as_ref().expect("made above");
                o.counter.begin(&g.ctx);
                let mut first = g.ctx.device.create_command_encoder(&Default::default());
                g.renderer.set_camera(&g.ctx, &cam)?;
                g.renderer.encode_frame(&mut first, &view, &g.depth);
                g.ctx.queue.submit([first.finish()]);
                let o = g.overdraw.as_ref().expect("made above");
                o.counter
                    .set_phase(&g.ctx.queue, forest_render::fragments::Phase::Hidden);
                g.renderer.set_camera(&g.ctx, &cam)?;
                g.renderer.encode_frame(&mut enc, &view, &g.depth);
                let o = g.overdraw.as_ref().expect("made above");
                o.pass.encode(&mut enc, &view, &o.binding);
            } else {
                g.renderer.set_camera(&g.ctx, &cam)?;
                g.renderer.encode_frame(&mut enc, &view, &g.depth);
            }
            let (mut choice, extra) = self.draw_hud(&mut g, &mut enc, &view);
            if refused {
                choice.1 = Some(DebugView::Off);
            }
            g.ctx.queue.submit(extra.into_iter().chain([enc.finish()]));
            g.window.pre_present_notify();
            g.ctx.queue.present(output);
            self.poll_counters(&mut g)?;
            g.ctx.check_reported_errors()?;
            if self.first_frame {
                self.first_frame = false;
                // (Rust's stdout is line-buffered: each line reaches a pipe as it is printed.)
                println!(
                    "forest view: first frame on screen ({}, {:?}, {}x{})",
                    g.ctx.adapter_info.name, g.config.format, g.config.width, g.config.height
                );
            }
            Ok(choice)
        })();
        self.gfx = Some(g);
        let (method, debug) = result?;
        if let Some(i) = method {
            self.set_method(i)?;
        }
        if self.stats.overflow > 0 {
            self.grow_stream(cam.viewport)?;
        }
        if let Some(v) = debug {
            self.set_debug(v);
        }
        Ok(())
    }

    /// Record the HUD over `view`: the choices it returns (a method, a debug view) and the
    /// command buffers egui's uploads need before the frame's.
    fn draw_hud(
        &mut self,
        g: &mut super::Gfx,
        enc: &mut wgpu::CommandEncoder,
        view: &wgpu::TextureView,
    ) -> ((Option<usize>, Option<DebugView>), Vec<wgpu::CommandBuffer>) {
        let raw = g.egui_state.take_egui_input(&g.window);
        let ui_ctx = g.egui.clone();
        let mut choice = (None, None);
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
        let extra =
            g.egui_renderer
                .update_buffers(&g.ctx.device, &g.ctx.queue, enc, &jobs, &screen);
        {
            let mut pass =
                forest_render::target::begin_overlay_pass(enc, "hud", view).forget_lifetime();
            g.egui_renderer.render(&mut pass, &jobs, &screen);
        }
        for id in &free {
            g.egui_renderer.free_texture(id);
        }
        (choice, extra)
    }

    /// Take the counters of a recent frame, never waiting: grow the stream after one that
    /// overflowed, and keep the shadow cascades' for the HUD.
    fn poll_counters(&mut self, g: &mut super::Gfx) -> Result<()> {
        // Statistics arrive a few frames late and errors as wgpu reports them: the frame
        // loop never waits for the GPU.
        if let Some(stats) = g.renderer.poll_stats(&g.ctx.device, &g.ctx.queue) {
            // A view that overflows the stream grows it for the frames after.
            g.renderer.fit(&g.ctx.device, &stats)?;
            self.stats = stats;
        }
        // The shadow cascades' light views likewise (the HUD shows their work).
        match g.renderer.stream.shadows_mut() {
            Some(sh) => {
                let polled = sh.poll(&g.ctx.device, &g.ctx.queue)?;
                self.shadow_stats.resize(polled.len(), Default::default());
                for (k, s) in polled.into_iter().enumerate() {
                    if let Some(s) = s {
                        self.shadow_stats[k] = s;
                    }
                }
            }
            None => self.shadow_stats.clear(),
        }
        Ok(())
    }
}
