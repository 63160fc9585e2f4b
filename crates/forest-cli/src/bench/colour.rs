//! Colour: each tree's mean colour as each method draws it, against the 4×4 reference's mean
//! colour of the same tree (CIELAB ΔE of the coverage-weighted mean of its pixels), over the
//! accuracy suite's cameras. Each camera's largest trees on screen are drawn alone from that
//! camera, so that no other tree's pixels mix in: in the models' own colours, and varied in
//! autumn (each tree its own value).

use anyhow::Result;
use forest_baselines::methods::Method;
use forest_format::colour::{self, Colouring, SpeciesColour};
use forest_format::forest::Forest;
use forest_render::options::Background;
use forest_render::target::Target;
use forest_render::{Camera, ForestView};
use glam::Vec3;

use super::accuracy::{reference, scene, views, walkthrough};
use super::chart::{Chart, Series};
use super::report::Section;
use super::{Bench, Table};

/// The ΔE a tree's mean colour should keep within (the target).
pub const TARGET_DELTA_E: f64 = 2.0;
/// A tree is measured when its crown spans at least this many pixels of radius on screen.
pub const MIN_RADIUS_PX: f32 = 6.0;

/// How many of each camera's largest trees are measured.
fn per_view(quick: bool) -> usize {
    if quick { 2 } else { 5 }
}

/// The instances `cam` shows largest (crown radius in pixels, at least [`MIN_RADIUS_PX`]),
/// whole crowns in front of the eye with their centres on screen, largest first, at most
/// `k`: (index, distance in metres, radius in pixels).
fn largest_trees(b: &Bench, forest: &Forest, cam: &Camera, k: usize) -> Vec<(usize, f32, f32)> {
    let view_proj = cam.proj() * cam.view();
    let focal = cam.focal_pixels();
    let mut found: Vec<(usize, f32, f32)> = forest
        .instances
        .iter()
        .enumerate()
        .filter_map(|(n, i)| {
            let s = &b.species[i.species as usize].atlas.manifest.bounding_sphere;
            let centre = Vec3::from_array(i.position) + s.center * i.scale;
            let r = s.radius * i.scale;
            let d = centre.distance(cam.eye);
            let clip = view_proj * centre.extend(1.0);
            if d <= r * 1.2 || clip.w <= 0.0 {
                return None;
            }
            let ndc = clip.truncate() / clip.w;
            let px = r * focal / d;
            (ndc.x.abs() < 1.0 && ndc.y.abs() < 1.0 && px >= MIN_RADIUS_PX).then_some((n, d, px))
        })
        .collect();
    found.sort_by(|a, b| b.2.total_cmp(&a.2));
    found.truncate(k);
    found
}

/// The coverage-weighted mean colour (linear RGB) of a frame drawn over transparent black
/// (premultiplied, sRGB-encoded), or `None` where nothing is covered.
pub fn mean_colour(img: &image::RgbaImage) -> Option<Vec3> {
    let decode = |v: u8| forest_format::shading::srgb_decode(f32::from(v) / 255.0);
    let (mut sum, mut cover) = (Vec3::ZERO, 0.0f64);
    for p in img.pixels() {
        if p[3] > 0 {
            sum += Vec3::new(decode(p[0]), decode(p[1]), decode(p[2]));
            cover += f64::from(p[3]) / 255.0;
        }
    }
    (cover > 1.0).then(|| sum / cover as f32)
}

/// A case of the suite: its name, whether the trees vary (each its own value), the season.
struct Case {
    name: &'static str,
    varied: bool,
    season: Option<f32>,
}

const CASES: [Case; 2] = [
    Case {
        name: "own colours",
        varied: false,
        season: None,
    },
    Case {
        name: "varied, autumn",
        varied: true,
        season: Some(2.0 / 3.0),
    },
];

/// Instance `n` of `forest` alone, coloured as `case` asks (varied: the amount 1, the species'
/// colours by name, and the tree's own value from the hash of its index in `forest`).
fn alone(forest: &Forest, n: usize, case: &Case) -> Forest {
    let lone = Forest::new(
        forest.species.clone(),
        vec![forest.instances[n]],
        forest_format::forest::DEFAULT_PRESORT_DIRECTIONS,
    );
    if !case.varied {
        return lone;
    }
    let mut c = Colouring::new(
        1.0,
        forest
            .species
            .iter()
            .map(|s| SpeciesColour::by_name(s))
            .collect(),
    );
    c.explicit = vec![colour::hash(n as u32)];
    lone.with_colouring(c)
}

/// Run the suite.
pub fn run(b: &Bench) -> Result<Section> {
    let (trees, side, viewport) = scene(b);
    let forest = b.forest(trees, side, 7)?;
    let mut cams: Vec<(String, Camera)> = views(&forest, side, viewport, b.clearance())
        .into_iter()
        .map(|(n, c)| (n.to_string(), c))
        .collect();
    let walks = if b.quick { 1 } else { 3 };
    cams.extend(
        walkthrough(&forest, side, viewport, walks)
            .into_iter()
            .enumerate()
            .map(|(k, c)| (format!("walkthrough {k}"), c)),
    );
    let methods = super::every_method();
    let target = Target::new(&b.ctx, viewport.0, viewport.1);
    let mut trees_table = Table::new(&[
        "view",
        "case",
        "instance",
        "species",
        "distance_m",
        "radius_px",
        "method",
        "delta_e",
        "delta_l",
    ]);
    // Per case and method: every tree's (radius in pixels, ΔE, ΔL*).
    let mut found: Vec<Vec<Vec<(f64, f64, f64)>>> = vec![vec![Vec::new(); methods.len()]; 2];
    // Per method, in the models' own colours: the worst tree's ΔE, its frame and the
    // reference's, side by side.
    let mut worst: Vec<(f64, Option<image::RgbaImage>)> = vec![(-1.0, None); methods.len()];
    for (view, cam) in &cams {
        for (n, distance, px) in largest_trees(b, &forest, cam, per_view(b.quick)) {
            for (c, case) in CASES.iter().enumerate() {
                let lone = alone(&forest, n, case);
                let mut r = b.renderer(&lone, viewport, 1.0, true, Background::Transparent)?;
                r.set_season(case.season)?;
                let reference_frame = reference(b, &mut r, cam)?;
                let Some(want) = mean_colour(&reference_frame) else {
                    continue;
                };
                for (k, m) in methods.iter().enumerate() {
                    let cam = Camera {
                        epsilon: EPSILON,
                        ..*cam
                    };
                    b.measure(&mut r, *m, &cam, &target, 0)?;
                    let frame = target.read(&b.ctx);
                    let Some(got) = mean_colour(&frame) else {
                        continue;
                    };
                    let de = f64::from(colour::delta_e(got, want));
                    if c == 0 && de > worst[k].0 {
                        worst[k] = (de, Some(side_by_side(&frame, &reference_frame)));
                    }
                    let dl = f64::from(colour::lab(got).x - colour::lab(want).x);
                    found[c][k].push((f64::from(px), de, dl));
                    let species = forest.instances[n].species as usize;
                    trees_table.push(vec![
                        view.clone(),
                        case.name.into(),
                        n.to_string(),
                        species_label(&forest.species[species]),
                        format!("{distance:.1}"),
                        format!("{px:.1}"),
                        m.name().into(),
                        format!("{de:.3}"),
                        format!("{dl:.3}"),
                    ]);
                }
            }
        }
    }
    let mut table = Table::new(&[
        "case",
        "method",
        "trees",
        "mean_delta_e",
        "worst_delta_e",
        "within_2",
        "mean_delta_l",
    ]);
    for (c, case) in CASES.iter().enumerate() {
        for (k, m) in methods.iter().enumerate() {
            let v = &found[c][k];
            let n = v.len().max(1) as f64;
            table.push(vec![
                case.name.into(),
                m.name().into(),
                v.len().to_string(),
                format!("{:.3}", v.iter().map(|t| t.1).sum::<f64>() / n),
                format!("{:.3}", v.iter().map(|t| t.1).fold(0.0, f64::max)),
                format!(
                    "{:.2}",
                    v.iter().filter(|t| t.1 <= TARGET_DELTA_E).count() as f64 / n
                ),
                format!("{:.3}", v.iter().map(|t| t.2).sum::<f64>() / n),
            ]);
        }
    }
    for (m, (_, img)) in methods.iter().zip(&worst) {
        if let Some(img) = img {
            let path = b.out.join(format!("colour_worst_{}.png", m.name()));
            img.save(&path)?;
            println!(
                "wrote {} (the method's worst tree | the reference)",
                path.display()
            );
        }
    }
    let cost = cost(b, &forest, &cams, viewport)?;
    b.write("colour.csv", &table.csv())?;
    b.write("colour_trees.csv", &trees_table.csv())?;
    b.write("colour_cost.csv", &cost.csv())?;
    let series = |c: usize| {
        methods
            .iter()
            .enumerate()
            .map(|(k, m)| {
                let mut points: Vec<(f64, f64)> = found[c][k].iter().map(|t| (t.0, t.1)).collect();
                points.sort_by(|a, b| a.0.total_cmp(&b.0));
                Series {
                    name: m.name().into(),
                    points,
                    ..Default::default()
                }
            })
            .collect()
    };
    for (c, stem) in [(0, "colour_own"), (1, "colour_autumn")] {
        b.chart(
            stem,
            &Chart {
                title: format!(
                    "Each tree's mean colour against the reference's ({})",
                    CASES[c].name
                ),
                x_label: "crown radius on screen (px)".into(),
                y_label: "ΔE (CIELAB)".into(),
                log_x: true,
                series: series(c),
                ..Default::default()
            },
        )?;
    }
    let text = summary(&table, &cost, viewport);
    Ok(Section {
        title: "Colour: each tree's mean colour against the reference's".into(),
        text,
        table,
        charts: vec!["colour_own".into(), "colour_autumn".into()],
    })
}

/// `a` and `b` (the same size) side by side, over grey so that coverage shows.
fn side_by_side(a: &image::RgbaImage, b: &image::RgbaImage) -> image::RgbaImage {
    let (w, h) = a.dimensions();
    image::RgbaImage::from_fn(2 * w, h, |x, y| {
        let p = if x < w {
            a.get_pixel(x, y)
        } else {
            b.get_pixel(x - w, y)
        };
        // Premultiplied over mid grey.
        let over = |c: u8| (u16::from(c) + (255 - u16::from(p[3])) * 128 / 255).min(255) as u8;
        image::Rgba([over(p[0]), over(p[1]), over(p[2]), 255])
    })
}

/// Every method's ε (pixels; the impostor refines nothing).
const EPSILON: f32 = 4.0;

/// A species' name: its atlas folder's, without `.atlas`.
fn species_label(path: &str) -> String {
    let name = std::path::Path::new(path)
        .file_name()
        .map_or(path.to_string(), |n| n.to_string_lossy().into_owned());
    name.trim_end_matches(".atlas").to_string()
}

/// Rounds of interleaved measurements per camera in [`cost`]: few for the methods that draw
/// every tree as geometry (seconds a frame on a CPU rasteriser), more for the others.
fn cost_rounds(m: Method) -> usize {
    if matches!(m, Method::Mesh(_)) { 2 } else { 6 }
}

/// What variation and a season cost: every method's median frame time at the accuracy
/// forest's mid-range view and first walkthrough camera with the forest varied (amount 1) in
/// autumn, over its time in the models' own colours, both measured in turn in one run (one
/// measured frame each time: a full-geometry frame of the accuracy forest takes seconds on a
/// CPU rasteriser).
fn cost(
    b: &Bench,
    forest: &Forest,
    cams: &[(String, Camera)],
    viewport: (u32, u32),
) -> Result<Table> {
    let mut table = Table::new(&["method", "frame_ms_plain", "frame_ms_varied", "time_ratio"]);
    let species = forest
        .species
        .iter()
        .map(|s| SpeciesColour::by_name(s))
        .collect();
    // The plain forest in the models' own colours whatever --variation and --season say.
    let plain = Forest {
        colouring: None,
        ..forest.clone()
    };
    let varied = plain.clone().with_colouring(Colouring::new(1.0, species));
    let target = Target::new(&b.ctx, viewport.0, viewport.1);
    let mut plain_r = b.renderer(&plain, viewport, 1.0, true, Background::Transparent)?;
    plain_r.set_season(None)?;
    let mut varied_r = b.renderer(&varied, viewport, 1.0, true, Background::Transparent)?;
    varied_r.set_season(Some(2.0 / 3.0))?;
    let timed: Vec<&Camera> = cams
        .iter()
        .filter(|(n, _)| n == "mid-range" || n == "walkthrough 0")
        .map(|(_, c)| c)
        .collect();
    for m in super::every_method() {
        let (mut plain, mut tinted) = (Vec::new(), Vec::new());
        for cam in &timed {
            let cam = Camera {
                epsilon: EPSILON,
                ..**cam
            };
            for _ in 0..cost_rounds(m) {
                plain.push(b.measure(&mut plain_r, m, &cam, &target, 1)?.1);
                tinted.push(b.measure(&mut varied_r, m, &cam, &target, 1)?.1);
            }
        }
        let (p, v) = (super::median(plain), super::median(tinted));
        table.push(vec![
            m.name().into(),
            super::ms(p),
            super::ms(v),
            format!("{:.3}", v / p.max(1e-9)),
        ]);
    }
    Ok(table)
}

/// The report's reading of the figures.
fn summary(table: &Table, cost: &Table, viewport: (u32, u32)) -> String {
    let col = |name: &str| table.header.iter().position(|h| *h == name).unwrap_or(0);
    let rows: Vec<String> = table
        .rows
        .iter()
        .filter(|r| r[col("case")] == "own colours")
        .map(|r| {
            format!(
                "{} {} (worst {}, {} within ΔE 2)",
                r[col("method")],
                r[col("mean_delta_e")],
                r[col("worst_delta_e")],
                r[col("within_2")]
            )
        })
        .collect();
    format!(
        "On the accuracy suite's cameras ({}x{}, ε 4) the trees each shows largest (crown \
         radius at least {MIN_RADIUS_PX} px) are drawn alone from that camera by every method \
         and by the 4×4 reference; each tree's colour is the coverage-weighted mean of its \
         pixels, and `delta_e` the CIELAB distance between the method's and the reference's \
         (target: within {TARGET_DELTA_E}; `delta_l` the method's L* minus the reference's). \
         In the models' own colours, mean ΔE per method: {}. The second case varies every tree \
         (amount 1, each its own value) in autumn; per tree in `colour_trees.csv`. Frame time \
         of the whole accuracy forest varied in autumn over its time in the models' own \
         colours, measured in turn in one run (`colour_cost.csv`, target ≤ 1.03): {}.",
        viewport.0,
        viewport.1,
        rows.join("; "),
        cost.rows
            .iter()
            .map(|r| format!("{} ×{}", r[0], r[3]))
            .collect::<Vec<_>>()
            .join(", ")
    )
}
