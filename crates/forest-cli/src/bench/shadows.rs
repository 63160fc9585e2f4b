//! Shadows: what the sun's cascaded shadow maps cost. For the demo's three views (inside the
//! forest, from the hill, bird's-eye) and the quad stream and the hybrid, frames with shadows
//! off and on are drawn alternately in one run and timed whole (submission to completion, on
//! the CPU's clock: the shadow passes are part of the frame), and each cascade's light view
//! reports its work (trees, quads). The maps' memory is stated.

use anyhow::Result;
use forest_baselines::methods::{ForestRenderer, Method};
use forest_render::ForestView;
use forest_render::options::Background;
use forest_render::shadow::ShadowOptions;
use forest_render::target::Target;
use forest_render::{Camera, GpuContext};

use super::chart::{Chart, Series};
use super::report::Section;
use super::{Bench, Table, median};

/// One frame of `r` for `cam`, timed from submission to completion (milliseconds).
fn timed_frame(
    ctx: &GpuContext,
    r: &mut ForestRenderer,
    cam: &Camera,
    target: &Target,
) -> Result<f64> {
    let start = std::time::Instant::now();
    r.render_frame(ctx, cam, target)?;
    ctx.device.poll(wgpu::PollType::wait_indefinitely())?;
    Ok(start.elapsed().as_secs_f64() * 1e3)
}

pub fn run(b: &Bench) -> Result<Section> {
    let (trees, side, viewport) = if b.quick {
        (150, 40.0, (160, 120))
    } else {
        (3000, 170.0, (800, 600))
    };
    let forest = b.forest(trees, side, 12)?;
    let geometry = !b.models.is_empty();
    let mut r = b.renderer(&forest, viewport, 16.0, geometry, Background::Sky)?;
    let opts = ShadowOptions::default();
    let mut methods = vec![("quads", Method::Quads)];
    if geometry {
        methods.push(("hybrid", Method::Hybrid(Default::default())));
    }
    let mut table = Table::new(&[
        "view",
        "method",
        "frame_ms_off",
        "frame_ms_on",
        "ratio",
        "view_trees",
        "view_primitives",
        "cascade_trees",
        "cascade_quads",
        "maps_mb",
    ]);
    let mut ratios: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    let frames = b.frames.max(1);
    for (name, method) in &methods {
        let mut points = Vec::new();
        for (i, view) in ["inside", "hill", "birds-eye"].iter().enumerate() {
            let (eye, target) = forest_render::named_view(view, &forest, &b.species)?;
            let cam = super::accuracy::look_at(eye, target, side, viewport, 16.0);
            let tgt = Target::new(&b.ctx, viewport.0, viewport.1);
            r.set_method(&b.ctx, *method)?;
            // Warm both (pipelines, stream sizes), then alternate.
            let mut times = (Vec::new(), Vec::new());
            for on in [false, true] {
                r.set_shadows(&b.ctx.device, on.then_some(opts))?;
                r.render_fitted(&b.ctx, &cam, &tgt)?;
            }
            for _ in 0..frames {
                for on in [false, true] {
                    r.set_shadows(&b.ctx.device, on.then_some(opts))?;
                    let t = timed_frame(&b.ctx, &mut r, &cam, &tgt)?;
                    if on { &mut times.1 } else { &mut times.0 }.push(t);
                }
            }
            b.ctx.check_errors()?;
            // The view's own work in the last (shadowed) frame, beside the cascades'.
            let view_stats = r.read_stats(&b.ctx);
            let cascades = r
                .stream
                .shadows()
                .map(|s| s.stats(&b.ctx))
                .unwrap_or_default();
            let mb = r.stream.shadows().map_or(0.0, |s| s.bytes() as f64 / 1e6);
            let join = |f: &dyn Fn(&forest_render::FrameStats) -> u32| {
                cascades
                    .iter()
                    .map(|c| f(c).to_string())
                    .collect::<Vec<_>>()
                    .join("/")
            };
            let (off, on) = (median(times.0), median(times.1));
            let ratio = on / off.max(1e-9);
            points.push((i as f64, ratio));
            table.push(vec![
                view.to_string(),
                name.to_string(),
                format!("{off:.1}"),
                format!("{on:.1}"),
                format!("{ratio:.2}"),
                view_stats.visible_trees.to_string(),
                view_stats.primitives.to_string(),
                join(&|c| c.visible_trees),
                join(&|c| c.quads),
                format!("{mb:.1}"),
            ]);
            println!(
                "shadows {view} {name}: {off:.1} -> {on:.1} ms ({ratio:.2}x), cascades {} quads",
                join(&|c| c.quads)
            );
        }
        ratios.push((name.to_string(), points));
    }
    r.set_shadows(&b.ctx.device, None)?;
    b.write("shadows.csv", &table.csv())?;
    b.chart(
        "shadows",
        &Chart {
            title: "Frame time with the sun's shadows over without".into(),
            x_label: "view (0 inside, 1 hill, 2 bird's-eye)".into(),
            y_label: "frame time ratio, shadows on / off".into(),
            series: ratios
                .into_iter()
                .map(|(name, points)| Series::line(name, points))
                .collect(),
            ..Default::default()
        },
    )?;
    let text = format!(
        "The sun's shadows at the defaults ({} cascades of {}² texels over the first {} m, \
         light views refined to ε {} texels): frames with shadows off and on drawn alternately \
         in one run, {frames} of each per view after a warm-up, timed from submission to \
         completion (the cascades' cull, refine and casting passes are inside the frame), \
         medians. `view_trees` and `view_primitives` are the view's own work (its visible \
         trees; quads, or for the hybrid quads and triangles), `cascade_trees` and \
         `cascade_quads` each cascade's light-view work (the quad stream's; the hybrid's near \
         trees cast as geometry besides). The maps take \
         `maps_mb` (with the light views' stream buffers).",
        opts.cascades, opts.resolution, opts.distance, opts.epsilon
    );
    Ok(Section {
        title: "Shadows: what the sun's shadow maps cost".into(),
        text,
        table,
        charts: vec!["shadows".into()],
    })
}
