//! The viewer's egui HUD: frame and pass times, counters, quads per level, the ε slider, the
//! time-of-day slider, the wind's speed, direction and gustiness, the season, the method and debug-view switches, the key list.

use forest_baselines::methods::Method;
use forest_render::options::DebugView;

use super::{EPSILON_RANGE, HOURS, KEYS, Viewer};

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
                // The work counts (pipeline statistics where the adapter has them).
                let w = &s.work;
                let counts = match w.total() {
                    Some(t) => format!(
                        "{} vertices, {} primitives, {} fragments, {} compute threads",
                        si(t.vertex_invocations),
                        si(t.primitives),
                        si(t.fragment_invocations),
                        si(t.compute_invocations)
                    ),
                    None if self.count_work => "no pipeline statistics on this adapter".into(),
                    None => "shader counts off".into(),
                };
                ui.label(format!(
                    "work: {} dispatches, {} draws, {:.0} MB; {counts}",
                    w.dispatches,
                    w.draws,
                    w.bytes as f64 / 1e6
                ));
                if !self.shadow_stats.is_empty() {
                    let c = &self.shadow_stats;
                    let join = |f: &dyn Fn(&forest_render::FrameStats) -> String| {
                        c.iter().map(f).collect::<Vec<_>>().join(" / ")
                    };
                    ui.label(format!(
                        "shadows, {} cascades: quads {}; cull + refine + cast {} ms",
                        c.len(),
                        join(&|s| s.quads.to_string()),
                        join(&|s| s
                            .times
                            .map_or("?".into(), |t| { format!("{:.1}", t.total_ms()) })),
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
                let hours = ui.add(
                    egui::Slider::new(&mut self.hour, HOURS.0..=HOURS.1)
                        .step_by(0.25)
                        .text("time of day (h): sun, its colour, the sky"),
                );
                if hours.changed() {
                    self.hour_changed = true;
                }
                ui.add(
                    egui::Slider::new(&mut self.wind.speed, 0.0..=30.0)
                        .text("wind (m/s, mean; G / Shift+G)"),
                );
                ui.add(
                    egui::Slider::new(&mut self.wind.towards_deg, 0.0..=360.0)
                        .text("wind towards (° from +Z to +X)"),
                );
                ui.add(egui::Slider::new(&mut self.wind.gustiness, 0.0..=1.0).text("gustiness"));
                let mut seasons = self.season.is_some();
                ui.horizontal(|ui| {
                    ui.checkbox(&mut seasons, "season (Y / Shift+Y)");
                    let mut s = self.season.unwrap_or(1.0 / 3.0);
                    ui.add_enabled(
                        seasons,
                        egui::Slider::new(&mut s, 0.0..=1.0)
                            .text("spring · summer · autumn · late"),
                    );
                    self.season = seasons.then_some(s);
                });
                ui.add(egui::Slider::new(&mut self.walker.speed, 0.5..=200.0).text("speed (m/s)"));
                ui.checkbox(&mut self.walker.walk, "walk (follow the ground)");
                ui.checkbox(
                    &mut self.count_work,
                    "count shader work (pipeline statistics)",
                );
                ui.label("method:");
                for (i, m) in self.methods.iter().enumerate() {
                    if ui
                        .radio(i == self.method, format!("{} {}", i + 1, m.name()))
                        .clicked()
                    {
                        method = Some(i);
                    }
                }
                ui.label("debug view (levels, weights, wireframe: quad-stream methods):");
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

/// A count with an SI suffix (k, M, G) and one decimal.
fn si(n: u64) -> String {
    let x = n as f64;
    match n {
        0..1_000 => n.to_string(),
        1_000..1_000_000 => format!("{:.1}k", x / 1e3),
        1_000_000..1_000_000_000 => format!("{:.1}M", x / 1e6),
        _ => format!("{:.1}G", x / 1e9),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn counts_get_si_suffixes() {
        assert_eq!(super::si(999), "999");
        assert_eq!(super::si(12_345), "12.3k");
        assert_eq!(super::si(708_320_000), "708.3M");
        assert_eq!(super::si(2_500_000_000), "2.5G");
    }
}
