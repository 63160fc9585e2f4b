//! F12: the current view rendered offscreen with the window's pipelines, saved as PNG with
//! its camera as a one-key path beside it.

use anyhow::Result;
use forest_format::camera_path::CameraPath;
use forest_render::ForestView;

use super::Viewer;

impl Viewer {
    /// Render the current view (without the HUD) offscreen with the window's pipelines and
    /// save it, with its camera as a one-key path beside it.
    pub(super) fn screenshot(&mut self) -> Result<()> {
        let cam = self.camera();
        let Some(g) = &mut self.gfx else {
            return Ok(());
        };
        let target = forest_render::target::Target::with_format(
            &g.ctx,
            cam.viewport.0,
            cam.viewport.1,
            g.config.format,
        )?;
        g.renderer.render_fitted(&g.ctx, &cam, &target)?;
        if self.debug == forest_render::DebugView::Overdraw {
            // The view counted as the window counts it, the heat map over it.
            if g.overdraw.as_ref().map(|o| o.counter.size()) != Some(cam.viewport) {
                super::detach_overdraw(g);
            }
            super::overdraw(g)?;
            let o = g.overdraw.as_ref().expect("made above");
            o.counter
                .count_frame(&g.ctx, || g.renderer.render_frame(&g.ctx, &cam, &target))?;
            let mut enc = g.ctx.device.create_command_encoder(&Default::default());
            o.pass.encode(&mut enc, &target.colour_view, &o.binding);
            g.ctx.queue.submit([enc.finish()]);
        }
        let img = target.read(&g.ctx);
        g.ctx.check_errors()?;
        // The next number whose image and camera files are both free: earlier screenshots
        // (of this session or another) are never written over.
        let free = |n: &u32| {
            let base = self.screenshots.join(format!("screenshot-{n:03}"));
            !base.with_extension("png").exists() && !base.with_extension("json").exists()
        };
        self.shots = (self.shots..).find(free).expect("some number is free");
        let base = self
            .screenshots
            .join(format!("screenshot-{:03}", self.shots));
        let png = base.with_extension("png");
        crate::render::write_png(&img, &png)?;
        let mut key = CameraPath::new(cam.fov_y_deg);
        key.push(cam.eye, cam.target);
        key.save(&base.with_extension("json"))?;
        self.shots += 1;
        self.say(format!(
            "saved {} ({}, debug view {})",
            png.display(),
            self.methods[self.method].name(),
            self.debug.name()
        ));
        Ok(())
    }
}
