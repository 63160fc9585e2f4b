//! Progress on stderr for the long steps of the front ends: loading a forest and its atlases,
//! and preparing the colour layers for the GPU (BC7 encoding on GPUs that have it). Drawn
//! only when stderr is a terminal (indicatif hides itself otherwise).

use std::time::Duration;

use anyhow::Result;
use forest_format::forest::Forest;
use forest_render::scene::SpeciesData;
use forest_render::{GpuContext, GpuScene};
use indicatif::{ProgressBar, ProgressStyle};

/// A spinner saying `what` is under way, ticking until dropped or finished.
pub fn spinner(what: String) -> ProgressBar {
    let s = ProgressBar::new_spinner();
    s.set_message(what);
    s.enable_steady_tick(Duration::from_millis(200));
    s
}

/// A bar saying `what` is under way, counting `unit` (hidden when `hidden`, e.g. for JSON
/// output).
pub fn bar(what: String, unit: &str, hidden: bool) -> ProgressBar {
    let bar = ProgressBar::new(0);
    if hidden {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{{msg}} [{{bar:40}}] {{pos}}/{{len}} {unit}, {{elapsed}} elapsed, ~{{eta}} left"
        ))
        .expect("a valid template")
        .progress_chars("=> "),
    );
    bar.set_message(what);
    bar
}

/// Upload a scene with a bar over its colour layers.
pub fn upload(ctx: &GpuContext, species: &[SpeciesData], forest: &Forest) -> Result<GpuScene> {
    let format = crate::colour_format();
    let bc7 = ctx.use_bc7(format);
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} layers ({eta})")
            .expect("a valid template")
            .progress_chars("=> "),
    );
    bar.set_message(if bc7 {
        "BC7-encoding colour layers"
    } else {
        "preparing colour layers"
    });
    let scene = GpuScene::with_progress(ctx, species, forest, format, &|done, total| {
        bar.set_length(total);
        bar.set_position(done);
    })?;
    bar.finish_and_clear();
    Ok(scene)
}
