//! Golden frames: every method, from the test cameras and at the hybrid's switch, with the
//! default light and no shadows, and under a low sun with shadows, drawn headless and through
//! a host's pass (`prepare`, `encode_compute`, `render`). Each image must equal the one stored
//! in `golden/` up to the rounding of the host CPU's code ([`ROUNDING`]), and each frame's
//! counters the stored figures exactly, so that a change of structure is proven to change no
//! pixel beyond rounding.
//!
//! The stored images hold for the adapter that recorded them (its name is in
//! `golden/figures.json`); on another adapter the images are compared by FLIP instead, and the
//! test says so. `FOREST_BLESS=1` records them again (only after a change meant to alter
//! pixels, with the reason in the commit).

mod common;

use forest_render::ForestView;
use std::collections::BTreeMap;
use std::path::PathBuf;

use forest_baselines::geometry::MeshMethod;
use forest_baselines::methods::{ForestRenderer, Method, MethodStats};
use forest_format::shading::Lighting;
use forest_render::options::{Atmosphere, Background};
use forest_render::shadow::ShadowOptions;
use forest_render::target::Target;
use forest_render::{Camera, FrameParams, GpuContext, Targets};
use glam::Vec3;
use serde::{Deserialize, Serialize};

const SIZE: (u32, u32) = (96, 72);

/// The most one channel of a frame may differ from its stored image on the adapter that
/// recorded it (of 255). llvmpipe compiles the shaders for the host's CPU, and its code rounds
/// differently from one CPU generation to the next: the frames recorded on one Xeon differed on
/// a Sapphire Rapids in up to 9 % of their pixels, by 1 or 2 of 255 each, and nowhere else. A
/// change of structure that moved anything would move whole edges and light by more; the
/// counters must still equal the stored ones exactly.
const ROUNDING: u8 = 2;

/// What a stored frame's counters must equal.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Figures {
    visible_trees: u32,
    primitives: u64,
    billboards: u32,
    geometry_trees: u32,
    per_level: Vec<u32>,
    overflow: u32,
    dispatches: u32,
    draws: u32,
}

impl From<&MethodStats> for Figures {
    fn from(s: &MethodStats) -> Self {
        Self {
            visible_trees: s.visible_trees,
            primitives: s.primitives,
            billboards: s.billboards,
            geometry_trees: s.geometry_trees,
            per_level: s.per_level.clone(),
            overflow: s.overflow,
            dispatches: s.work.dispatches,
            draws: s.work.draws,
        }
    }
}

/// How far a frame is from its stored image: FLIP's mean, the pixels that differ and the
/// largest difference of one channel (of 255).
struct Difference {
    flip: f32,
    pixels: usize,
    largest: u8,
}

impl Difference {
    fn of(expected: &image::RgbaImage, actual: &image::RgbaImage) -> Self {
        let flip = forest_metrics::flip(expected, actual).map_or(f32::INFINITY, |f| f.0);
        let mut pixels = 0;
        let mut largest = 0;
        for (e, a) in expected.pixels().zip(actual.pixels()) {
            let d =
                e.0.iter()
                    .zip(a.0)
                    .map(|(e, a)| e.abs_diff(a))
                    .max()
                    .unwrap_or(0);
            pixels += usize::from(d > 0);
            largest = largest.max(d);
        }
        Self {
            flip,
            pixels,
            largest,
        }
    }
}

impl std::fmt::Display for Difference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "FLIP {:.2e}, {} pixels differ, by at most {}/255",
            self.flip, self.pixels, self.largest
        )
    }
}

#[derive(Debug, Default, Serialize, Deserialize)]
struct Golden {
    /// The adapter that drew the stored images.
    adapter: String,
    /// Per frame name.
    frames: BTreeMap<String, Figures>,
}

fn folder() -> PathBuf {
    common::root().join("crates/forest-gpu-tests/golden")
}

/// Every method, with full geometry drawn unsorted too, after the sorted.
fn methods(switch: f32) -> Vec<(&'static str, Method)> {
    let mut methods = common::every_method_switching_at(switch);
    let sorted = methods.iter().position(|(n, _)| *n == "geometry").unwrap();
    methods.insert(
        sorted + 1,
        (
            "geometry-unsorted",
            Method::Mesh(MeshMethod::Full { depth_sort: false }),
        ),
    );
    methods
}

/// The test cameras at the golden size, and one whose view centre lies at `switch` metres.
fn cameras(extent: f32, switch: f32) -> Vec<(&'static str, Camera)> {
    let mut cams = common::cameras(extent);
    cams.push((
        "switch",
        common::camera(Vec3::new(0.0, 4.0, switch), Vec3::new(0.0, 3.0, 0.0), 4.0),
    ));
    for (_, c) in &mut cams {
        c.viewport = SIZE;
    }
    cams
}

/// One frame drawn by `r` into `target` as a host draws it: its matrices, its pass.
fn host_frame(ctx: &GpuContext, r: &mut ForestRenderer, cam: &Camera, target: &Target) {
    r.prepare(&ctx.queue, &FrameParams::from(cam)).unwrap();
    let mut enc = ctx.device.create_command_encoder(&Default::default());
    r.encode_compute(&mut enc);
    {
        let bg = r.background();
        let targets = Targets::cleared(
            &target.colour_view,
            &target.depth_view,
            bg.clear_colour(),
            r.stream.options_built().depth_clear(),
        );
        let mut pass = targets.begin(&mut enc, "host", r.draw_timestamps());
        r.render(&mut pass);
    }
    r.resolve_times(&mut enc);
    ctx.queue.submit([enc.finish()]);
}

/// Every golden frame: name, image, counters.
fn frames(ctx: &GpuContext) -> Vec<(String, image::RgbaImage, Figures)> {
    let species = common::species();
    let forest = common::forest(40);
    let extent = forest.extent();
    let switch = extent * 0.5;
    let mut r = common::forest_renderer(
        ctx,
        &species,
        common::prepared(),
        &forest,
        SIZE,
        Background::default(),
        Atmosphere::default(),
    );
    let target = Target::new(ctx, SIZE.0, SIZE.1);
    let low_sun = Lighting::with_sun(200.0, 20.0);
    let shadows = ShadowOptions {
        resolution: 256,
        ..Default::default()
    };
    let mut out = Vec::new();
    for (lit, light, shadow) in [
        ("plain", Lighting::default(), None),
        ("shadowed", low_sun, Some(shadows)),
    ] {
        r.set_light(light).unwrap();
        r.set_shadows(&ctx.device, shadow).unwrap();
        for (m, method) in methods(switch) {
            r.set_method(ctx, method).unwrap();
            for (c, cam) in cameras(extent, switch) {
                if m == "hybrid-at-switch" && c != "switch" {
                    continue;
                }
                let stats = r.render_fitted(ctx, &cam, &target).unwrap();
                out.push((
                    format!("{lit}-{m}-{c}"),
                    target.read(ctx),
                    Figures::from(&stats),
                ));
            }
            // The host's path, from the first camera.
            let (c, cam) = &cameras(extent, switch)[0];
            host_frame(ctx, &mut r, cam, &target);
            let stats = r.read_stats(ctx);
            out.push((
                format!("{lit}-{m}-{c}-host"),
                target.read(ctx),
                Figures::from(&stats),
            ));
        }
    }
    assert_eq!(ctx.take_errors(), Vec::<String>::new());
    out
}

/// Every method's frames equal the stored ones, pixel for pixel and counter for counter.
#[test]
fn every_method_draws_its_golden_frames() {
    let ctx = common::ctx();
    let frames = frames(&ctx);
    let dir = folder();
    let adapter = ctx.adapter_info.name.clone();
    if std::env::var_os("FOREST_BLESS").is_some() {
        std::fs::create_dir_all(&dir).unwrap();
        let mut golden = Golden {
            adapter,
            ..Default::default()
        };
        for (name, img, fig) in &frames {
            img.save(dir.join(format!("{name}.png"))).unwrap();
            golden.frames.insert(name.clone(), fig.clone());
        }
        let json = serde_json::to_string_pretty(&golden).unwrap();
        std::fs::write(dir.join("figures.json"), json + "\n").unwrap();
        return;
    }
    let golden: Golden =
        serde_json::from_str(&std::fs::read_to_string(dir.join("figures.json")).unwrap()).unwrap();
    assert_eq!(
        golden.frames.len(),
        frames.len(),
        "a frame was added or removed: record again with FOREST_BLESS=1"
    );
    let same_adapter = golden.adapter == adapter;
    if !same_adapter {
        eprintln!(
            "golden frames were drawn by {:?}, this adapter is {:?}: comparing by FLIP",
            golden.adapter, adapter
        );
    }
    let mut failed = Vec::new();
    for (name, img, fig) in &frames {
        let expected = image::open(dir.join(format!("{name}.png")))
            .unwrap()
            .to_rgba8();
        let differs = if same_adapter {
            Difference::of(&expected, img).largest > ROUNDING
        } else {
            forest_metrics::flip(&expected, img).unwrap().0 > 0.02
        };
        if differs {
            common::failure_images(&format!("golden-{name}"), &expected, img);
            failed.push(format!("{name}: image, {}", Difference::of(&expected, img)));
        }
        if golden.frames.get(name) != Some(fig) {
            failed.push(format!(
                "{name}: figures {fig:?}, stored {:?}",
                golden.frames.get(name)
            ));
        }
    }
    assert!(
        failed.is_empty(),
        "{} of {} golden frames differ (images in target/test-output):\n{}",
        failed.len(),
        frames.len(),
        failed.join("\n")
    );
}
