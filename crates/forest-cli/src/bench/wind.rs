//! Wind: every method animated in one seeded wind, frame by frame against the animated 4×4
//! reference, on seeded cameras near, mid, far and at the hybrid's switch: the error of each
//! frame, the motion between frames (flicker, and frozen regions where the reference moves),
//! a tree at the switch drawn as geometry and as quads at the same instants, and the cost of
//! the wind.

use anyhow::Result;
use forest_baselines::geometry::MeshMethod;
use forest_baselines::methods::Method;
use forest_format::forest::{Forest, Instance};
use forest_format::noise::SplitMix64;
use forest_format::wind::Wind;
use forest_render::options::Background;
use forest_render::target::Target;
use forest_render::{Camera, ForestView};
use glam::Vec3;

use super::accuracy::{clear_eye, look_at, reference};
use super::chart::{Chart, Series};
use super::report::Section;
use super::stability::POP_MARGIN;
use super::{Bench, Table, ms};

/// Seed of the suite's wind and cameras.
pub const WIND_SEED: u64 = 0x5717_d0a5;
/// Frames per second of the animated sequences.
pub const RATE: f32 = 30.0;

/// A wind as users meet it, drawn from `rng`: any direction, a mean speed of 3 to 15 m/s
/// (a gentle to a strong breeze), gustiness 0.3 to 0.8, an instant in the first 100 s.
pub fn seeded_wind(rng: &mut SplitMix64) -> Wind {
    Wind {
        towards_deg: 360.0 * rng.next_f32(),
        speed: 3.0 + 12.0 * rng.next_f32(),
        gustiness: 0.3 + 0.5 * rng.next_f32(),
        time: 100.0 * rng.next_f32(),
    }
}

/// A case: name, its distance (metres from the eye to what it looks at) and its camera.
struct Case {
    name: &'static str,
    distance: f32,
    camera: Camera,
}

/// The crown's centre of instance `i` (world, metres).
fn crown(b: &Bench, i: &Instance) -> (Vec3, f32) {
    let s = &b.species[i.species as usize].atlas.manifest.bounding_sphere;
    (
        Vec3::from_array(i.position) + Vec3::Y * s.center.y * i.scale,
        s.radius * i.scale,
    )
}

/// The hybrid's switch distance of instance `i` seen by `cam` (metres from the crown's
/// centre): `focal · scale · unit` ([`forest_render::extend::switch_unit`]).
fn switch_distance(b: &Bench, i: &Instance, cam: &Camera) -> f32 {
    let m = &b.species[i.species as usize].atlas.manifest;
    cam.focal_pixels() * i.scale * forest_render::extend::switch_unit(m)
}

/// A unit vector at a random azimuth, `rise` up.
fn around(rng: &mut SplitMix64, rise: f32) -> Vec3 {
    let a = std::f32::consts::TAU * rng.next_f32();
    Vec3::new(a.sin(), rise, a.cos()).normalize()
}

/// The seeded cameras: near (a tree 2.5 to 4 crown radii away), mid (an eye inside the
/// forest looking 25 to 40 m across it), far (over the forest's edge, looking across it),
/// and switch (a tree at its hybrid switch distance).
fn cases(b: &Bench, forest: &Forest, side: f32, viewport: (u32, u32), seed: u64) -> Vec<Case> {
    let mut rng = SplitMix64(seed);
    let cam = |eye: Vec3, target: Vec3| look_at(eye, target, side, viewport, 4.0);
    // A tree near the middle of the forest, drawn by seed.
    let pick = |rng: &mut SplitMix64| {
        let mut near: Vec<&Instance> = forest
            .instances
            .iter()
            .filter(|i| Vec3::from_array(i.position).length() < side * 0.25)
            .collect();
        if near.is_empty() {
            near = forest.instances.iter().collect();
        }
        near[((rng.next_f32() * near.len() as f32) as usize).min(near.len() - 1)]
    };
    let tree = pick(&mut rng);
    let (centre, radius) = crown(b, tree);
    let d = radius * (2.5 + 1.5 * rng.next_f32());
    let near = cam(centre + around(&mut rng, 0.1) * d, centre);
    // An eye clear of crowns near the middle, looking across the forest past its centre.
    let dir = around(&mut rng, 0.0);
    let eye = clear_eye(forest, dir * side * 0.15, b.clearance()) + Vec3::Y * 1.7;
    let across = 25.0 + 15.0 * rng.next_f32();
    let towards = Vec3::new(-eye.x, 0.0, -eye.z).normalize_or(-dir);
    let mid = cam(eye, eye + towards * across + Vec3::Y * 0.3);
    let dir = around(&mut rng, 0.0);
    let far_eye = dir * side * 0.55 + Vec3::Y * side * 0.06;
    let far = cam(far_eye, Vec3::ZERO);
    let tree = pick(&mut rng);
    let (centre, _) = crown(b, tree);
    let probe = cam(centre + Vec3::X, centre);
    let s = switch_distance(b, tree, &probe);
    let switch = cam(centre + around(&mut rng, 0.05) * s, centre);
    vec![
        Case {
            name: "near",
            distance: d,
            camera: near,
        },
        Case {
            name: "mid",
            distance: across,
            camera: mid,
        },
        Case {
            name: "far",
            distance: far_eye.length(),
            camera: far,
        },
        Case {
            name: "switch",
            distance: s,
            camera: switch,
        },
    ]
}

fn mean(v: &[f32]) -> f32 {
    v.iter().sum::<f32>() / v.len().max(1) as f32
}

/// Side of the tiles [`motion`] follows (pixels).
const TILE: u32 = 16;

/// The most frames between the two images [`motion`] compares: 0.1 s at [`RATE`]. The wind
/// moves nothing faster than 3 Hz (the flutter; the sway is at most 2 Hz), which turns by at
/// most a third of a cycle in that time, so a shift over 3 frames is within 14 % of 3 frames'
/// motion.
pub const MAX_MOTION_STEP: usize = 3;

/// The shift (pixels) the reference's outlines should make between the two images [`motion`]
/// compares. Lucas–Kanade's linearisation holds for shifts well under a pixel (at a shift of
/// a pixel it measured the sharp 1x geometry's outlines moving 0.77 of the reference's,
/// against 0.94 between consecutive frames), while a shift of a few hundredths of a pixel is
/// the size of the 4×4 reference's sampling noise: far away its outlines moved 0.031 px
/// between consecutive frames but 0.016 px a frame over 3 frames (lengths of noisy shifts
/// add up, never cancel), where the impostor's moved 0.0118 and 0.0114 px a frame.
pub const MOTION_SHIFT_PX: f32 = 0.3;

/// Frames between the images [`motion`] compares for a sequence whose reference moves
/// `reference_px` pixels between consecutive frames: about [`MOTION_SHIFT_PX`], 1 to
/// [`MAX_MOTION_STEP`], and less than `frames`.
pub fn motion_step(reference_px: f32, frames: usize) -> usize {
    let step = (MOTION_SHIFT_PX / reference_px.max(1e-6)).round();
    (step.clamp(1.0, MAX_MOTION_STEP as f32) as usize).min(frames.saturating_sub(1).max(1))
}

/// How far the trees' outlines move in a frame (pixels), measured between frames `step`
/// apart (1 to the sequence's length − 1) and divided by `step`: in each 16×16-pixel tile,
/// the shift that best carries one image's coverage onto the other's (Lucas–Kanade: the
/// least-squares solution of `∇a · δ = −∂a/∂t` over the tile), its length averaged over the
/// tiles weighted by how well their edges pin it (the smaller eigenvalue of the tile's
/// structure tensor), then over the pairs. A shift, not a difference: a method whose edges
/// are softer or whose detail is finer changes its pixels by other amounts for the same
/// motion, but its outlines move as far.
fn motion(imgs: &[image::RgbaImage], step: usize) -> f32 {
    let step = step.clamp(1, imgs.len().saturating_sub(1).max(1));
    let per_pair: Vec<f32> = imgs
        .windows(step + 1)
        .map(|w| {
            let (a, b) = (&w[0], &w[step]);
            let (width, height) = a.dimensions();
            let at =
                |img: &image::RgbaImage, x: u32, y: u32| f64::from(img.get_pixel(x, y)[3]) / 255.0;
            let (mut sum, mut weight) = (0.0f64, 0.0f64);
            for ty in 0..height / TILE {
                for tx in 0..width / TILE {
                    let (mut xx, mut xy, mut yy, mut xt, mut yt) = (0.0, 0.0, 0.0, 0.0, 0.0);
                    for y in (ty * TILE).max(1)..((ty + 1) * TILE).min(height - 1) {
                        for x in (tx * TILE).max(1)..((tx + 1) * TILE).min(width - 1) {
                            // Gradients of the two frames' mean, the change between them.
                            let g = |dx: i32, dy: i32| {
                                let (x, y) = ((x as i32 + dx) as u32, (y as i32 + dy) as u32);
                                0.5 * (at(a, x, y) + at(b, x, y))
                            };
                            let ix = 0.5 * (g(1, 0) - g(-1, 0));
                            let iy = 0.5 * (g(0, 1) - g(0, -1));
                            let it = at(b, x, y) - at(a, x, y);
                            xx += ix * ix;
                            xy += ix * iy;
                            yy += iy * iy;
                            xt += ix * it;
                            yt += iy * it;
                        }
                    }
                    let det = xx * yy - xy * xy;
                    let half_trace = 0.5 * (xx + yy);
                    let low = half_trace - (half_trace * half_trace - det).max(0.0).sqrt();
                    // An edge in one direction only (or none) pins no shift along it.
                    if low < 1e-3 || det <= 0.0 {
                        continue;
                    }
                    let dx = -(yy * xt - xy * yt) / det;
                    let dy = -(xx * yt - xy * xt) / det;
                    sum += dx.hypot(dy) * low;
                    weight += low;
                }
            }
            if weight > 0.0 {
                (sum / weight / step as f64) as f32
            } else {
                0.0
            }
        })
        .collect();
    mean(&per_pair)
}

/// The coverage-weighted centre of a transparent render (pixels; alpha weights).
fn centroid(img: &image::RgbaImage) -> Option<(f32, f32)> {
    let (mut sx, mut sy, mut n) = (0.0f64, 0.0f64, 0.0f64);
    for (x, y, p) in img.enumerate_pixels() {
        let a = f64::from(p[3]);
        sx += a * f64::from(x);
        sy += a * f64::from(y);
        n += a;
    }
    (n > 0.0).then(|| ((sx / n) as f32, (sy / n) as f32))
}

/// One tree of `species` at the origin (instance 0).
fn lone_tree(b: &Bench, species: u32) -> Forest {
    Forest::new(
        b.species_paths
            .iter()
            .map(|p| p.display().to_string())
            .collect(),
        vec![Instance {
            position: [0.0; 3],
            rotation: 0.0,
            scale: 1.0,
            species,
        }],
        forest_format::forest::DEFAULT_PRESORT_DIRECTIONS,
    )
}

/// The suite's forest (trees, side in metres), viewport and frames per sequence: on a GPU the
/// accuracy suite's scene and 2 s at [`RATE`]; on a CPU rasteriser (lavapipe, where one 4×4
/// reference frame of 3 000 trees takes seconds) 1 200 trees at 320×240 and 1 s; quick: the
/// accuracy suite's quick scene and 4 frames.
fn scene(b: &Bench) -> (u32, f32, (u32, u32), usize) {
    let (trees, side, viewport) = super::accuracy::scene(b);
    if b.quick {
        (trees, side, viewport, 4)
    } else if b.cpu {
        (1200, 110.0, (320, 240), RATE as usize)
    } else {
        (trees, side, viewport, (2.0 * RATE) as usize)
    }
}

/// Run the wind suite.
pub fn run(b: &Bench) -> Result<Section> {
    let (trees, side, viewport, frames) = scene(b);
    let forest = b.forest(trees, side, 11)?;
    let mut rng = SplitMix64(WIND_SEED);
    // The wind asked for (--wind), else one drawn by seed.
    let wind = if b.wind.speed > 0.0 {
        b.wind
    } else {
        seeded_wind(&mut rng)
    };
    let at = |f: usize| wind.at(wind.time + f as f32 / RATE);
    let mut r = b.renderer(&forest, viewport, 4.0, true, Background::Transparent)?;
    let methods = super::every_method();
    let target = Target::new(&b.ctx, viewport.0, viewport.1);
    let mut table = Table::new(&[
        "case",
        "distance_m",
        "method",
        "flip_static",
        "flip_wind",
        "wind_over_static",
        "motion_step",
        "motion_px",
        "motion_over_reference",
        "motion_1_over_reference",
        "change_over_reference",
        "flicker_frames",
        "frame_ms_calm",
        "frame_ms_wind",
        "time_ratio",
    ]);
    let mut error_series: Vec<Series> = methods
        .iter()
        .map(|m| Series::line(m.name(), Vec::new()))
        .collect();
    let mut motion_series = error_series.clone();
    for case in cases(b, &forest, side, viewport, rng.next_u64()) {
        let cam = case.camera;
        // The animated reference, and the calm one.
        r.set_wind(Wind::CALM)?;
        let calm_ref = reference(b, &mut r, &cam)?;
        let mut refs = Vec::with_capacity(frames);
        for f in 0..frames {
            r.set_wind(at(f))?;
            refs.push(reference(b, &mut r, &cam)?);
        }
        let ref_changes = super::stability::consecutive_flips(&refs)?;
        let ref_motion_1 = motion(&refs, 1);
        let step = motion_step(ref_motion_1, refs.len());
        let ref_motion = motion(&refs, step);
        for (mi, &method) in methods.iter().enumerate() {
            r.set_wind(Wind::CALM)?;
            let (_, calm_ms) = b.measure(&mut r, method, &cam, &target, b.frames)?;
            let still = target.read(&b.ctx);
            let flip_static = forest_metrics::compare(&calm_ref, &still)?.flip_mean;
            r.set_wind(at(0))?;
            let (_, wind_ms) = b.measure(&mut r, method, &cam, &target, b.frames)?;
            let mut imgs = Vec::with_capacity(frames);
            let mut flips = Vec::with_capacity(frames);
            for (f, rf) in refs.iter().enumerate() {
                r.set_wind(at(f))?;
                b.measure(&mut r, method, &cam, &target, 0)?;
                let img = target.read(&b.ctx);
                flips.push(forest_metrics::compare(rf, &img)?.flip_mean);
                imgs.push(img);
            }
            let own = super::stability::consecutive_flips(&imgs)?;
            let flip_wind = mean(&flips);
            let moved = motion(&imgs, step);
            let motion_ratio = moved / ref_motion.max(1e-9);
            let motion_1 = motion(&imgs, 1) / ref_motion_1.max(1e-9);
            let change = mean(&own) / mean(&ref_changes).max(1e-9);
            let flicker = own
                .iter()
                .zip(&ref_changes)
                .filter(|(m, r)| **m - **r > POP_MARGIN)
                .count();
            println!(
                "wind, {} ({:.1} m), {}: FLIP {flip_static:.4} calm, {flip_wind:.4} in wind \
                 (×{:.3}); outlines move {moved:.3} px a frame, ×{motion_ratio:.2} the \
                 reference's ({ref_motion:.3} px, over {step} frames; between consecutive frames \
                 ×{motion_1:.2}), pixels change ×{change:.2} as much; {flicker} flicker frames",
                case.name,
                case.distance,
                method.name(),
                flip_wind / flip_static.max(1e-9)
            );
            error_series[mi]
                .points
                .push((f64::from(case.distance), f64::from(flip_wind)));
            motion_series[mi]
                .points
                .push((f64::from(case.distance), f64::from(motion_ratio)));
            table.push(vec![
                case.name.into(),
                format!("{:.1}", case.distance),
                method.name().into(),
                format!("{flip_static:.5}"),
                format!("{flip_wind:.5}"),
                format!("{:.3}", flip_wind / flip_static.max(1e-9)),
                step.to_string(),
                format!("{moved:.4}"),
                format!("{motion_ratio:.3}"),
                format!("{motion_1:.3}"),
                format!("{change:.3}"),
                flicker.to_string(),
                ms(calm_ms),
                ms(wind_ms),
                format!("{:.3}", wind_ms / calm_ms.max(1e-9)),
            ]);
        }
    }
    let switch = switch_agreement(b, &wind, frames, viewport, side)?;
    for s in [&mut error_series, &mut motion_series] {
        for series in s.iter_mut() {
            series.points.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
    }
    b.write("wind.csv", &table.csv())?;
    b.write("wind_switch.csv", &switch.csv())?;
    b.chart(
        "wind_error",
        &Chart {
            title: "Wind: mean FLIP per animated frame against the animated reference".into(),
            x_label: "distance (m)".into(),
            y_label: "mean FLIP".into(),
            log_x: true,
            series: error_series,
            ..Default::default()
        },
    )?;
    b.chart(
        "wind_motion",
        &Chart {
            title: "Wind: how far each method's outlines move in a frame, over the reference's"
                .into(),
            x_label: "distance (m)".into(),
            y_label: "motion ratio (1: as the reference; under 0.5: frozen)".into(),
            log_x: true,
            series: motion_series,
            ..Default::default()
        },
    )?;
    let text = summary(&table, &switch, &wind, (trees, frames), viewport, b.cpu);
    Ok(Section {
        title: "Wind: every method animated against the animated reference".into(),
        text,
        table,
        charts: vec!["wind_error".into(), "wind_motion".into()],
    })
}

/// One tree of each species at its switch distance, drawn as geometry and as quads at the
/// same instants: how far apart their crowns' screen motions get (pixels), per species.
fn switch_agreement(
    b: &Bench,
    wind: &Wind,
    frames: usize,
    viewport: (u32, u32),
    side: f32,
) -> Result<Table> {
    let mut table = Table::new(&[
        "species",
        "switch_m",
        "crown_motion_px",
        "worst_disagreement_px",
    ]);
    let target = Target::new(&b.ctx, viewport.0, viewport.1);
    for (k, path) in b.species_paths.iter().enumerate() {
        let forest = lone_tree(b, k as u32);
        let tree = &forest.instances[0];
        let (centre, _) = crown(b, tree);
        let probe = look_at(centre + Vec3::X, centre, side, viewport, 4.0);
        let s = switch_distance(b, tree, &probe);
        // Across the wind, so its lean shows on screen.
        let across = Vec3::new(wind.direction().y, 0.0, -wind.direction().x);
        let cam = look_at(centre + across * s, centre, side, viewport, 4.0);
        let mut r = b.renderer(&forest, viewport, 4.0, true, Background::Transparent)?;
        let mut tracks = Vec::new();
        for method in [
            Method::Mesh(MeshMethod::Full { depth_sort: true }),
            Method::Quads,
        ] {
            let mut track = Vec::with_capacity(frames);
            for f in 0..frames {
                r.set_wind(wind.at(wind.time + f as f32 / RATE))?;
                b.measure(&mut r, method, &cam, &target, 0)?;
                track.push(centroid(&target.read(&b.ctx)).unwrap_or_default());
            }
            tracks.push(track);
        }
        let moved = |t: &[(f32, f32)], f: usize| (t[f].0 - t[0].0, t[f].1 - t[0].1);
        let (mut motion, mut worst) = (0.0f32, 0.0f32);
        for f in 0..frames {
            let (g, q) = (moved(&tracks[0], f), moved(&tracks[1], f));
            motion = motion.max(g.0.hypot(g.1));
            worst = worst.max((g.0 - q.0).hypot(g.1 - q.1));
        }
        let name = path
            .file_stem()
            .map(|n| n.to_string_lossy().trim_end_matches(".atlas").to_string())
            .unwrap_or_default();
        println!(
            "wind at the switch, {name} ({s:.1} m): the crown moves up to {motion:.2} px; \
             geometry and quads disagree by at most {worst:.2} px"
        );
        table.push(vec![
            name,
            format!("{s:.1}"),
            format!("{motion:.3}"),
            format!("{worst:.3}"),
        ]);
    }
    Ok(table)
}

/// The report's reading of the figures.
fn summary(
    table: &Table,
    switch: &Table,
    wind: &Wind,
    (trees, frames): (u32, usize),
    viewport: (u32, u32),
    cpu: bool,
) -> String {
    let col = |name: &str| table.header.iter().position(|h| *h == name).unwrap_or(0);
    let num = |r: &Vec<String>, c: &str| r[col(c)].parse::<f64>().unwrap_or(f64::NAN);
    // "METHOD at CASE (×VALUE)" for a row and a column.
    let named = |r: &Vec<String>, c: &str| {
        format!(
            "{} at {} (×{})",
            r[col("method")],
            r[col("case")],
            r[col(c)]
        )
    };
    let worst = |c: &str| {
        table
            .rows
            .iter()
            .max_by(|a, b| num(a, c).total_cmp(&num(b, c)))
            .map(|r| named(r, c))
            .unwrap_or_default()
    };
    let worst_ratio = worst("wind_over_static");
    let frozen: Vec<String> = table
        .rows
        .iter()
        .filter(|r| num(r, "motion_over_reference") < 0.5)
        .map(|r| named(r, "motion_over_reference"))
        .collect();
    let slowest = worst("time_ratio");
    let switch_worst = switch
        .rows
        .iter()
        .map(|r| format!("{} {} px of {} px", r[0], r[3], r[2]))
        .collect::<Vec<_>>()
        .join(", ");
    format!(
        "A seeded wind (towards {:.0}°, {:.1} m/s, gustiness {:.2}, from t = {:.1} s) over \
         {frames} frames at {RATE} Hz{}, {trees} trees, on seeded cameras near a tree (2.5 to 4 \
         crown radii), inside the forest (mid), over its edge (far) and at a tree's hybrid \
         switch ({}x{}, ε 4). `flip_static` is each method's mean FLIP against the 4×4 reference in \
         calm air at the same camera, `flip_wind` its mean over the animated frames against the \
         reference animated alike; `wind_over_static` their ratio (target ≤ 1.15; worst: \
         {worst_ratio}). `motion_px` is how far the method's outlines move in a frame (the \
         Lucas–Kanade shift of 16-pixel tiles' coverage between frames `motion_step` apart, \
         over the step, which is chosen for the reference's outlines to move about \
         {MOTION_SHIFT_PX} px, 1 to {MAX_MOTION_STEP} frames: between consecutive frames the \
         far motion is as small as the reference's sampling noise), `motion_over_reference` \
         that over the reference's: under 0.5 a frozen band (frozen: {}); \
         `motion_1_over_reference` the same between consecutive frames, \
         `change_over_reference` the mean FLIP between consecutive frames over the \
         reference's. `flicker_frames` counts frames whose change exceeds the reference's by \
         more than {POP_MARGIN}. `time_ratio` is the median frame time in wind over calm, \
         measured in one run (target ≤ 1.15; the highest: {slowest}; on a CPU rasteriser the \
         frame times are noisy). A tree of each species at its switch distance, seen across \
         the wind, drawn as full geometry and as quads at the same instants: their crowns' \
         screen motions disagree by at most {switch_worst} (target under 1 px; \
         `wind_switch.csv`). Nothing is baked for the wind: atlases and models keep their \
         bytes, and the camera uniform grows by 32 bytes.",
        wind.towards_deg,
        wind.speed,
        wind.gustiness,
        wind.time,
        if cpu {
            " (1 s on a CPU rasteriser, where a 4×4 reference frame takes seconds; 2 s on a GPU)"
        } else {
            ""
        },
        viewport.0,
        viewport.1,
        if frozen.is_empty() {
            "none".to_string()
        } else {
            frozen.join(", ")
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Transparent images of soft-edged discs centred on a 16-pixel grid (coverage falling
    /// from 1 to 0 between 3.5 and 6.5 px from the centre), all moved by `(dx, dy)` pixels a
    /// frame: an outline motion known exactly.
    fn discs(frames: usize, dx: f32, dy: f32) -> Vec<image::RgbaImage> {
        (0..frames)
            .map(|f| {
                image::RgbaImage::from_fn(64, 48, |x, y| {
                    let (cx, cy) = (8.0 + dx * f as f32, 8.0 + dy * f as f32);
                    let (px, py) = (
                        (x as f32 - cx).rem_euclid(16.0),
                        (y as f32 - cy).rem_euclid(16.0),
                    );
                    let r = (px.min(16.0 - px)).hypot(py.min(16.0 - py));
                    let a = ((6.5 - r) / 3.0).clamp(0.0, 1.0);
                    image::Rgba([0, 0, 0, (a * 255.0).round() as u8])
                })
            })
            .collect()
    }

    #[test]
    fn motion_finds_a_known_shift_at_every_step() {
        for (dx, dy) in [(0.1, 0.0), (0.05, -0.08), (0.0, 0.2)] {
            let truth = f32::hypot(dx, dy);
            let imgs = discs(4, dx, dy);
            for step in 1..=3 {
                let m = motion(&imgs, step);
                assert!(
                    (m - truth).abs() < 0.1 * truth,
                    "({dx}, {dy}) px a frame over {step} frames: measured {m}"
                );
            }
        }
        assert_eq!(
            motion(&discs(4, 0.0, 0.0), 1),
            0.0,
            "still images move nothing"
        );
    }

    #[test]
    fn the_motion_step_spans_about_a_third_of_a_pixel_within_its_bounds() {
        assert_eq!(motion_step(0.5, 60), 1);
        assert_eq!(motion_step(0.15, 60), 2);
        assert_eq!(motion_step(0.03, 60), MAX_MOTION_STEP);
        assert_eq!(motion_step(0.0, 60), MAX_MOTION_STEP);
        assert_eq!(motion_step(0.03, 3), 2, "within the sequence");
        assert_eq!(motion_step(0.03, 1), 1);
    }
}
