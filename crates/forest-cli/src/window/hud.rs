//! The viewer's egui HUD: frame and pass times, counters, quads per level, the ε slider, the
//! method and debug-view switches, the key list.

use forest_baselines::methods::Method;
use forest_render::options::DebugView;

use super::{EPSILON_RANGE, KEYS, Viewer};

impl Viewer {
    /// The HUD; returns the method and debug view picked with the mouse, if any.
    pub(super) fn hud(&mut self, ui_ctx: &egui::Context) -> (Option<usize>, Option<DebugView>) {
        let (mut method, mut debug) = (None, None);
        if !self.show_hud {
            return (method, debug);
        }
        let s = &self.stats;
        egui::Window::new("forest view")
            .default_width(440.0)
            .show(ui_ctx, |ui| {
                ui.label(format!(
                    "{:.1} ms/frame ({:.0} fps)",
                    self.frame_ms,
                    1000.0 / self.frame_ms.max(1e-3)
                ));
                let mesh = matches!(self.methods[self.method], Method::Mesh(_));
                match s.times {
                    Some(t) if mesh => ui.label(format!(
                        "GPU: cull {:.2} ms, draw {:.2} ms",
                        t.cull_ms, t.draw_ms
                    )),
                    Some(t) => ui.label(format!(
                        "GPU: cull {:.2} ms, refine {:.2} ms, draw {:.2} ms",
                        t.cull_ms, t.refine_ms, t.draw_ms
                    )),
                    None => ui.label("GPU pass times: no timestamp queries on this adapter"),
                };
                if matches!(self.methods[self.method], Method::Hybrid(_)) {
                    let quads: u32 = s.per_level.iter().sum();
                    ui.label(format!(
                        "{} visible trees, {} as geometry, {quads} quads + {} triangles, \
                         overflow {}",
                        s.visible_trees,
                        s.geometry_trees,
                        s.primitives - u64::from(quads),
                        s.overflow
                    ));
                } else {
                    let unit = if mesh { "triangles" } else { "quads" };
                    ui.label(format!(
                        "{} visible trees, {} {unit}, {} billboards, overflow {}",
                        s.visible_trees, s.primitives, s.billboards, s.overflow
                    ));
                }
                if !s.per_level.is_empty() {
                    let levels: Vec<String> = s
                        .per_level
                        .iter()
                        .enumerate()
                        .map(|(l, n)| format!("{l}: {n}"))
                        .collect();
                    ui.label(format!("quads per level: {}", levels.join(" · ")));
                }
                ui.add(
                    egui::Slider::new(&mut self.epsilon, EPSILON_RANGE.0..=EPSILON_RANGE.1)
                        .logarithmic(true)
                        .text("ε (px)"),
                );
                ui.add(egui::Slider::new(&mut self.walker.speed, 0.5..=200.0).text("speed (m/s)"));
                ui.checkbox(&mut self.walker.walk, "walk (follow the ground)");
                ui.label("method:");
                for (i, m) in self.methods.iter().enumerate() {
                    if ui
                        .radio(i == self.method, format!("{} {}", i + 1, m.name()))
                        .clicked()
                    {
                        method = Some(i);
                    }
                }
                ui.label("debug view (quad-stream methods):");
                ui.horizontal(|ui| {
                    for v in DebugView::ALL {
                        if ui.radio(v == self.debug, v.name()).clicked() {
                            debug = Some(v);
                        }
                    }
                });
                ui.separator();
                for k in KEYS {
                    ui.label(k);
                }
                if let Some(p) = &self.recording {
                    ui.label(format!("recording: {} keys", p.keys.len()));
                }
                if let (Some(p), Some(i)) = (&self.path, self.playing) {
                    ui.label(format!(
                        "playing the path: key {} of {}",
                        i + 1,
                        p.keys.len()
                    ));
                }
                if !self.message.is_empty() {
                    ui.label(&self.message);
                }
            });
        (method, debug)
    }
}
