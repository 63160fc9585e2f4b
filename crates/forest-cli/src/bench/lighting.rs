//! Lighting: every method against the 4×4 full-geometry reference, both lit by the same
//! run-time light, over seeded random suns (elevation 5°–90°, any azimuth) and seeded cameras
//! of four kinds (near a tree, mid-range inside the forest, far above it, from below a
//! crown). The default sun (30°, 55°), the one atlases used to have baked in, is measured on
//! the same cameras as the control: a method that relights well keeps its error there.

use anyhow::Result;
use forest_format::forest::Forest;
use forest_format::noise::SplitMix64;
use forest_format::shading::Lighting;
use forest_render::Camera;
use forest_render::ForestView;
use forest_render::options::Background;
use forest_render::target::Target;
use glam::Vec3;

use super::accuracy::{clear_eye, look_at, nearest_tree, reference};
use super::chart::{Chart, Series};
use super::report::Section;
use super::shadowing::seeded_suns;
use super::{Bench, Table};

/// Seed of the suns and of the cameras.
const SEED: u64 = 0x5eed_0029;

/// The seeded cameras: one of each kind, at a seeded azimuth about its subject.
fn cameras(
    forest: &Forest,
    side: f32,
    viewport: (u32, u32),
    clearance: f32,
) -> Vec<(&'static str, Camera)> {
    let mut rng = SplitMix64(SEED ^ 0xca3e);
    let mut heading = || rng.next_f32() * std::f32::consts::TAU;
    let cam = |eye: Vec3, target: Vec3| look_at(eye, target, side, viewport, 16.0);
    let (tree, scale) = nearest_tree(forest, Vec3::ZERO);
    let crown = tree + Vec3::Y * 2.5 * scale;
    let a = heading();
    let near = cam(
        crown + Vec3::new(a.sin(), 0.0, a.cos()) * 7.0 * scale - Vec3::Y,
        crown,
    );
    let a = heading();
    let start = Vec3::new(a.sin(), 0.0, a.cos()) * side * 0.25;
    let eye = clear_eye(forest, start, clearance);
    let eye = eye.with_y(forest.ground_height(eye.x, eye.z) + 1.7);
    let mid = cam(
        eye,
        Vec3::new(0.0, forest.ground_height(0.0, 0.0) + 3.0, 0.0),
    );
    let a = heading();
    let far = cam(
        Vec3::new(a.sin() * side * 0.6, side * 0.35, a.cos() * side * 0.6),
        Vec3::ZERO,
    );
    let a = heading();
    let under = tree + Vec3::new(0.5 * a.sin(), 0.3, 0.5 * a.cos());
    let below = cam(under, under + Vec3::new(0.3 * a.cos(), 1.0, -0.3 * a.sin()));
    vec![("near", near), ("mid", mid), ("far", far), ("below", below)]
}

/// Run the suite.
pub fn run(b: &Bench) -> Result<Section> {
    let (trees, side, viewport) = super::accuracy::scene(b);
    let forest = b.forest(trees, side, 11)?;
    let mut r = b.renderer(&forest, viewport, 4.0, true, Background::Transparent)?;
    let methods = super::every_method();
    let cams = cameras(&forest, side, viewport, b.clearance());
    // The control first, then the seeded suns.
    let mut suns = vec![(30.0, 55.0)];
    suns.extend(
        seeded_suns(if b.quick { 2 } else { 8 }, SEED)
            .into_iter()
            .map(|s| (s.0, s.1)),
    );
    let target = Target::new(&b.ctx, viewport.0, viewport.1);
    let mut table = Table::new(&[
        "sun_azimuth",
        "sun_elevation",
        "camera",
        "method",
        "flip_mean",
    ]);
    // flips[method][sun] over the cameras.
    let mut flips = vec![vec![Vec::new(); suns.len()]; methods.len()];
    for (si, &(az, el)) in suns.iter().enumerate() {
        r.set_light(Lighting::with_sun(az, el))?;
        for (name, cam) in &cams {
            let rf = reference(b, &mut r, cam)?;
            for (mi, &m) in methods.iter().enumerate() {
                b.measure(&mut r, m, cam, &target, 0)?;
                let f = forest_metrics::compare(&rf, &target.read(&b.ctx))?.flip_mean;
                println!("sun {az:.0},{el:.0}, {name}, {}: FLIP {f:.4}", m.name());
                flips[mi][si].push(f);
                table.push(vec![
                    format!("{az:.1}"),
                    format!("{el:.1}"),
                    (*name).into(),
                    m.name().into(),
                    format!("{f:.5}"),
                ]);
            }
        }
    }
    b.write("lighting.csv", &table.csv())?;
    let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len().max(1) as f32;
    let series: Vec<Series> = methods
        .iter()
        .zip(&flips)
        .map(|(m, f)| {
            let mut points: Vec<(f64, f64)> = suns
                .iter()
                .zip(f)
                .skip(1)
                .map(|(s, v)| (f64::from(s.1), f64::from(mean(v))))
                .collect();
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
            Series::line(m.name(), points)
        })
        .collect();
    b.chart(
        "lighting",
        &Chart {
            title: "Relit methods against the relit reference, by sun elevation".into(),
            x_label: "sun elevation (degrees)".into(),
            y_label: "mean FLIP over the cameras".into(),
            series,
            ..Default::default()
        },
    )?;
    let mut summary = Table::new(&["method", "default_sun_flip", "seeded_suns_flip", "ratio"]);
    let mut lines = Vec::new();
    for (m, f) in methods.iter().zip(&flips) {
        let control = mean(&f[0]);
        let seeded = mean(&f[1..].concat());
        let ratio = seeded / control.max(1e-9);
        lines.push(format!("{} {ratio:.2}×", m.name()));
        summary.push(vec![
            m.name().into(),
            format!("{control:.5}"),
            format!("{seeded:.5}"),
            format!("{ratio:.3}"),
        ]);
    }
    b.write("lighting_summary.csv", &summary.csv())?;
    let text = format!(
        "Every method and the 4×4 full-geometry reference lit alike (run-time sun, sky, \
         self-shadowing from the opacity volumes), over the default sun (30°, 55°: the one \
         atlases used to have baked in) and {} seeded suns (azimuth uniform, elevation \
         stratified uniformly in 5°–90°), each from four seeded cameras (near a tree, \
         mid-range inside the forest, far above it, below a crown), {} trees over {side:.0} m, {}×{} px, transparent \
         background. Mean FLIP over the seeded suns against that at the default sun: {}. The \
         chart gives each method's mean over the cameras per sun; `lighting.csv` every frame, \
         `lighting_summary.csv` the ratios.",
        suns.len() - 1,
        forest.instances.len(),
        viewport.0,
        viewport.1,
        lines.join(", ")
    );
    Ok(Section {
        title: "Lighting: relit methods over seeded suns".into(),
        text,
        table: summary,
        charts: vec!["lighting".into()],
    })
}
