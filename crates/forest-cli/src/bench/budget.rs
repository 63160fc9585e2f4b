//! Budget: model no more than a scene needs — the bake resolution, levels and quad capacity a
//! given scene (viewport, nearest viewing distance, ε) needs, against the defaults.

use anyhow::Result;
use forest_baselines::methods::Method;
use forest_render::Camera;
use forest_render::options::Background;
use forest_render::target::Target;
use glam::Vec3;

use super::accuracy::{nearest_tree, reference};
use super::chart::{Chart, Series};
use super::report::Section;
use super::{Bench, Table, ms};

/// The budget's scene: a forest seen from `near` metres at ε `epsilon` through a `fov`°
/// lens, the slab resolution it needs, and the camera at its nearest tree.
struct Scene {
    forest: forest_format::forest::Forest,
    side: f32,
    viewport: (u32, u32),
    near: f32,
    epsilon: f32,
    focal: f32,
    radius: f32,
    needed: u32,
    cam: Camera,
}

/// Run the budget suite: the bake resolution, levels and quad capacity a scene needs.
pub fn run(b: &Bench) -> Result<Section> {
    let sc = scene(b)?;
    let defaults = b.species[0].atlas.manifest.params;
    let mut geo = b.renderer(
        &sc.forest,
        sc.viewport,
        sc.epsilon,
        true,
        Background::Transparent,
    )?;
    let reference = reference(b, &mut geo, &sc.cam)?;
    drop(geo);
    let mut table = Table::new(&[
        "choice",
        "resolution",
        "levels",
        "disk_bytes",
        "gpu_bytes",
        "capacity_quads",
        "needed_quads",
        "capacity_bytes",
        "suggested_capacity_bytes",
        "flip_mean",
        "frame_ms",
    ]);
    let target = Target::new(&b.ctx, sc.viewport.0, sc.viewport.1);
    let points = resolution_rows(b, &sc, &reference, &target, &mut table)?;
    let (hybrid_rows, cascades) = hybrid_rows(b, &sc, &reference, &target, &mut table)?;
    let (near, epsilon, viewport, radius, needed) =
        (sc.near, sc.epsilon, sc.viewport, sc.radius, sc.needed);
    let focal = sc.focal;
    b.write("budget.csv", &table.csv())?;
    b.chart(
        "budget",
        &Chart {
            title: format!("Bake resolution for a scene: nearest tree {near} m, ε {epsilon}"),
            x_label: "atlas GPU MiB (all species)".into(),
            y_label: "mean FLIP at the nearest view".into(),
            series: vec![Series {
                name: "slab resolution (px)".into(),
                points,
                line: true,
                ..Default::default()
            }],
            ..Default::default()
        },
    )?;
    let text = format!(
        "Given a scene — {}x{} pixels, 60° field of view, nearest tree {near} m away, ε = \
         {epsilon} — a slab-image texel should cover at most a pixel at the nearest distance: \
         2·r·f/d = {:.0} px for the largest bounding radius r = {radius:.1} m, so {needed} px \
         (a power of two). The table bakes every species at half that, at that, and at the \
         default {} px, and measures storage, the most quads the scene's views draw against the \
         capacity the formula allocates (a quarter more than measured is suggested: \
         `RendererOptions::max_quads`), and mean FLIP against the reference at the nearest view. \
         Choosing the needed resolution instead of a larger default saves the difference in \
         the gpu_bytes column at the FLIP cost the table shows. The row \"no directions below\" \
         bakes the default resolution without the {} sampling directions below the horizon: \
         its storage columns are what those directions cost (views from under a crown: see \
         the fidelity suite). The \"hybrid\" rows draw trees nearer than the switch distance \
         as full geometry: their storage adds the models (disk: their folders; GPU: the \
         geometry renderer's vertices, textures and buffers) to the default atlases; at the \
         nearest view: {}.{cascades}",
        viewport.0,
        viewport.1,
        2.0 * radius * focal / near,
        defaults.resolution,
        defaults.below,
        hybrid_rows.join("; "),
    );
    Ok(Section {
        title: "Budget: model no more than a scene needs".into(),
        text,
        table,
        charts: vec!["budget".into()],
    })
}

/// The budget's scene: nearest viewing distance 10 m, ε 4, 60° fov, the camera `near` metres
/// from a tree whose viewpoint has no other tree closer.
fn scene(b: &Bench) -> Result<Scene> {
    let (trees, side, viewport) = super::accuracy::scene(b);
    let forest = b.forest(trees, side, 7)?;
    // The scene: nearest viewing distance 10 m, ε 4, 60° fov.
    let (near, epsilon, fov) = (10.0f32, 4.0f32, 60.0f32);
    let focal = viewport.1 as f32 / 2.0 / (fov.to_radians() / 2.0).tan();
    let radius = b
        .species
        .iter()
        .map(|s| s.atlas.manifest.bounding_sphere.radius)
        .fold(0.0f32, f32::max);
    // A slab image texel should not cover more than a pixel at the nearest distance.
    let needed = ((2.0 * radius * focal / near).ceil() as u32)
        .next_power_of_two()
        .clamp(32, 1024);
    // The nearest tree is `near` metres away: a tree whose viewpoint has no other tree closer
    // (the one nearest the centre that qualifies).
    let offset = Vec3::new(near * 0.6, 1.7, near * 0.8);
    let mut candidates: Vec<Vec3> = forest
        .instances
        .iter()
        .map(|i| Vec3::from_array(i.position))
        .collect();
    candidates.sort_by(|a, b| a.length().total_cmp(&b.length()));
    let tree = candidates
        .iter()
        .copied()
        .find(|t| {
            let (n, _) = nearest_tree(&forest, *t + offset);
            n.distance(*t) < 1e-3
        })
        .unwrap_or_else(|| nearest_tree(&forest, Vec3::ZERO).0);
    let cam = Camera {
        eye: tree + offset,
        target: tree + Vec3::new(0.0, 2.5, 0.0),
        fov_y_deg: fov,
        near: 0.1,
        far: side * 3.0,
        viewport,
        epsilon,
    };
    Ok(Scene {
        forest,
        side,
        viewport,
        near,
        epsilon,
        focal,
        radius,
        needed,
        cam,
    })
}

/// Bake every species at each resolution the scene asks about and draw it as the quad stream:
/// storage, the quads the scene's views need, and accuracy at the nearest view, a row each;
/// the chart's points (atlas GPU MiB, FLIP).
fn resolution_rows(
    b: &Bench,
    sc: &Scene,
    reference: &image::RgbaImage,
    target: &Target,
    table: &mut Table,
) -> Result<Vec<(f64, f64)>> {
    let (forest, side, viewport, epsilon, needed, cam) = (
        &sc.forest,
        sc.side,
        sc.viewport,
        sc.epsilon,
        sc.needed,
        &sc.cam,
    );
    let defaults = b.species[0].atlas.manifest.params;
    // (resolution, directions below the horizon): every resolution with the atlases' own
    // directions below, and the default resolution without any (what they cost).
    let mut resolutions: Vec<(u32, u32)> = if b.quick {
        vec![(32, defaults.below), (64, defaults.below)]
    } else {
        let mut r = vec![needed / 2, needed, defaults.resolution];
        r.sort_unstable();
        r.dedup();
        r.into_iter().map(|r| (r, defaults.below)).collect()
    };
    if !b.quick && defaults.below > 0 {
        resolutions.push((defaults.resolution, 0));
    }
    let mut points = Vec::new();
    let dir = tempfile_dir(&b.out)?;
    for &(res, below) in &resolutions {
        let params = forest_format::BakeParams {
            resolution: res,
            below,
            ..defaults
        };
        let mut species = Vec::new();
        let (mut disk, mut gpu) = (0u64, 0u64);
        for (k, obj) in b.models.iter().enumerate() {
            let out = forest_bake::bake_file(obj, &params, &|_, _| {})?;
            let path = dir.join(format!("{k}-{res}-{below}.atlas"));
            out.atlas.save(&path)?;
            disk += std::fs::read_dir(&path)?
                .filter_map(|e| e.ok()?.metadata().ok())
                .map(|m| m.len())
                .sum::<u64>();
            gpu += out.atlas.manifest.gpu_bytes();
            species.push(forest_render::scene::SpeciesData::load(&path)?);
        }
        let scene =
            forest_render::GpuScene::with_format(&b.ctx, &species, forest, crate::colour_format())?;
        let opts = forest_render::RendererOptions {
            viewport,
            min_epsilon: epsilon,
            background: Background::Transparent,
            ..Default::default()
        };
        let stream = forest_render::QuadStream::new(&b.ctx.device, scene, &opts)?;
        let mut r = b.shadowed(forest_baselines::methods::ForestRenderer::new(stream, None))?;
        // The quads the scene needs: the most any of its views (the nearest, and the accuracy
        // suite's mid-range and bird's-eye) draws; a quarter more is the suggested capacity.
        let mut most = 0u64;
        for (_, v) in super::accuracy::views(forest, side, viewport, b.clearance())
            .into_iter()
            .skip(1)
        {
            let mut v = v;
            v.epsilon = epsilon;
            most = most.max(
                b.measure(&mut r, Method::Quads, &v, target, 0)?
                    .0
                    .primitives,
            );
        }
        let (s, t) = b.measure(&mut r, Method::Quads, cam, target, b.frames)?;
        most = most.max(s.primitives);
        let m = forest_metrics::compare(reference, &target.read(&b.ctx))?;
        let suggested = forest_render::Capacity::new(&forest_render::CapacityInput {
            instances: forest.instances.len() as u32,
            quads_per_tree: 6,
            viewport,
            min_epsilon: epsilon,
            overdraw: 16.0,
            max_quads: Some((most as f64 * 1.25).ceil() as u32),
            grown: 0,
        });
        let levels = species[0].atlas.manifest.nodes_per_level.len();
        println!(
            "budget: {res} px, {levels} levels, {below} directions below: {disk} B disk, \
             {gpu} B GPU, FLIP {:.4}",
            m.flip_mean
        );
        if below == defaults.below {
            points.push((gpu as f64 / 1048576.0, f64::from(m.flip_mean)));
        }
        let choice = if below != defaults.below {
            "no directions below"
        } else if res == needed {
            "needed"
        } else if res == defaults.resolution {
            "default"
        } else if res < needed {
            "below need"
        } else {
            "above need"
        };
        table.push(vec![
            choice.into(),
            res.to_string(),
            levels.to_string(),
            disk.to_string(),
            gpu.to_string(),
            r.stream.capacity.quads.to_string(),
            most.to_string(),
            r.stream.capacity.bytes().to_string(),
            suggested.bytes().to_string(),
            format!("{:.5}", m.flip_mean),
            ms(t),
        ]);
    }
    let _ = std::fs::remove_dir_all(&dir);
    Ok(points)
}

/// The hybrid at each switch distance, at the nearest view: a row each; its lines for the
/// text, and what the last row's shadow cascades cost.
fn hybrid_rows(
    b: &Bench,
    sc: &Scene,
    reference: &image::RgbaImage,
    target: &Target,
    table: &mut Table,
) -> Result<(Vec<String>, String)> {
    let (forest, viewport, epsilon, near, cam) =
        (&sc.forest, sc.viewport, sc.epsilon, sc.near, &sc.cam);
    let defaults = b.species[0].atlas.manifest.params;
    // The hybrid: what each switch distance costs at the nearest view. Its storage is the
    // default atlases plus the models (disk: their folders; GPU: the geometry renderer).
    let folder_bytes = |p: &std::path::Path| -> u64 {
        std::fs::read_dir(p)
            .map(|d| {
                d.filter_map(|e| e.ok()?.metadata().ok())
                    .filter(|m| m.is_file())
                    .map(|m| m.len())
                    .sum()
            })
            .unwrap_or(0)
    };
    let atlas_disk: u64 = b.species_paths.iter().map(|p| folder_bytes(p)).sum();
    let atlas_gpu: u64 = b.species.iter().map(|s| s.atlas.manifest.gpu_bytes()).sum();
    let model_disk: u64 = b
        .models
        .iter()
        .filter_map(|m| m.parent())
        .map(folder_bytes)
        .sum();
    let mut r = b.renderer(forest, viewport, epsilon, true, Background::Transparent)?;
    let geometry_gpu = r.geometry.as_ref().map_or(0, |g| g.gpu_bytes);
    let levels = b.species[0].atlas.manifest.nodes_per_level.len();
    let mut hybrid_rows = Vec::new();
    for near in [
        forest_baselines::hybrid::Near::Auto,
        forest_baselines::hybrid::Near::Metres(5.0),
        forest_baselines::hybrid::Near::Metres(near),
        forest_baselines::hybrid::Near::Metres(near * 2.0),
    ] {
        let method = Method::Hybrid(forest_baselines::hybrid::Hybrid {
            near,
            ..Default::default()
        });
        let (s, t) = b.measure(&mut r, method, cam, target, b.frames)?;
        let m = forest_metrics::compare(reference, &target.read(&b.ctx))?;
        let name = match near {
            forest_baselines::hybrid::Near::Auto => "hybrid near=auto".to_string(),
            forest_baselines::hybrid::Near::Metres(x) => format!("hybrid near={x}m"),
        };
        println!(
            "budget: {name}: {} trees as geometry, FLIP {:.4}, {t:.2} ms",
            s.geometry_trees, m.flip_mean
        );
        hybrid_rows.push(format!(
            "{name}: {} trees as geometry, FLIP {:.4}, {t:.2} ms",
            s.geometry_trees, m.flip_mean
        ));
        table.push(vec![
            name,
            defaults.resolution.to_string(),
            levels.to_string(),
            (atlas_disk + model_disk).to_string(),
            (atlas_gpu + geometry_gpu).to_string(),
            r.stream.capacity.quads.to_string(),
            String::new(),
            r.stream.capacity.bytes().to_string(),
            String::new(),
            format!("{:.5}", m.flip_mean),
            ms(t),
        ]);
    }
    let cascades = cascade_costs(b, &r);
    Ok((hybrid_rows, cascades))
}

/// What each shadow cascade of `r`'s quad stream cost in the last frame, as a sentence (empty
/// without shadows).
fn cascade_costs(b: &Bench, r: &forest_baselines::methods::ForestRenderer) -> String {
    match r.stream.shadows() {
        Some(sh) => {
            let costs: Vec<String> = sh
                .stats(&b.ctx)
                .iter()
                .enumerate()
                .map(|(k, s)| {
                    format!(
                        "cascade {k}: {} trees, {} quads, cull + refine + cast {}",
                        s.visible_trees,
                        s.quads,
                        s.times.map_or("not timed".into(), |t| {
                            format!("{:.2} ms", t.total_ms())
                        })
                    )
                })
                .collect();
            println!("budget: shadows: {}", costs.join("; "));
            format!(
                " With the sun's shadows on, the last hybrid row's cascades cost: {}; the maps \
                 and light views take {:.1} MB.",
                costs.join("; "),
                sh.bytes() as f64 / 1e6
            )
        }
        None => String::new(),
    }
}

/// A scratch folder for the budget's bakes inside the results folder.
fn tempfile_dir(out: &std::path::Path) -> Result<std::path::PathBuf> {
    let d = out.join(".budget-atlases");
    std::fs::create_dir_all(&d)?;
    Ok(d)
}
