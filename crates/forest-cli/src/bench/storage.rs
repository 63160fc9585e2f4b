//! Storage: bytes on disk and on the GPU per species and method; forest memory against the
//! instance count (storage grows with models, not instances); quad-stream buffer bytes against
//! visible trees.

use std::path::Path;

use anyhow::Result;
use forest_baselines::geometry::GeometryRenderer;
use forest_baselines::methods::Method;
use forest_render::Camera;
use forest_render::options::Background;
use forest_render::target::{TARGET_FORMAT, Target};

use super::chart::{Chart, Series};
use super::report::Section;
use super::{Bench, Table};

fn folder_bytes(dir: &Path) -> u64 {
    std::fs::read_dir(dir)
        .map(|it| {
            it.filter_map(|e| e.ok()?.metadata().ok())
                .filter(|m| m.is_file())
                .map(|m| m.len())
                .sum()
        })
        .unwrap_or(0)
}

/// Bytes of a model on disk: the OBJ and the material libraries and images beside it.
fn model_bytes(obj: &Path) -> u64 {
    let dir = obj.parent().unwrap_or(Path::new("."));
    std::fs::read_dir(dir)
        .map(|it| {
            it.filter_map(|e| e.ok())
                .filter(|e| {
                    let p = e.path();
                    let ext = p.extension().and_then(|x| x.to_str()).unwrap_or("");
                    p == obj || ["mtl", "png", "jpg", "jpeg", "tga"].contains(&ext)
                })
                .filter_map(|e| e.metadata().ok())
                .map(|m| m.len())
                .sum()
        })
        .unwrap_or(0)
}

const MB: f64 = 1048576.0;

/// Run the suite.
pub fn run(b: &Bench) -> Result<Section> {
    let (table, quad_total, geo_total, files) = per_species(b)?;
    let viewport = (800, 600);
    let forest_table = per_forest(b, viewport)?;
    per_stream(b, viewport)?;
    // Marginal bytes per instance between the two largest forests.
    let per_instance = |m: &str| {
        let rows: Vec<(f64, f64)> = forest_table
            .rows
            .iter()
            .filter(|r| r[0] == m)
            .map(|r| (r[1].parse().unwrap_or(0.0), r[3].parse().unwrap_or(0.0)))
            .collect();
        match rows.as_slice() {
            [.., a, b] if b.0 > a.0 => format!("{:.1}", (b.1 - a.1) / (b.0 - a.0)),
            _ => "-".into(),
        }
    };
    let text = format!(
        "Per species, the quad stream stores its atlas ({:.2} MiB on disk, {:.2} MiB on the GPU \
         as BC7, all species together) and the geometry methods their models ({:.2} MiB on \
         disk, {:.2} MiB on the GPU with LODs, leaf tables and billboards). Static impostors \
         bind the same atlas. Between the two largest forests each added tree costs {} B of GPU \
         memory with the quad stream (instance, presorted orders, a scan slot) and {} B with \
         the geometry methods (instance, classification key, visible-list slot): memory grows \
         with the models, not the instances. The quad-stream buffers start from `Capacity`'s \
         estimate (the level-0 quads of the visible trees, at most a quarter of the screen's \
         pixels, plus what refinement can add) and grow when a frame overflows them \
         (`QuadStream::fit`, to the frame's need plus an eighth); the last chart compares the \
         allocation after the measured frames with what they needed. An atlas's files (MiB): \
         the colour mosaic (premultiplied albedo), alpha (coverage), surface (normal, sky \
         visibility and translucency at half the slab resolution), opacity (the 32³ \
         self-shadowing volume) and nodes: {}.",
        quad_total.0 as f64 / MB,
        quad_total.1 as f64 / MB,
        geo_total.0 as f64 / MB,
        geo_total.1 as f64 / MB,
        per_instance("quads"),
        per_instance("geometry"),
        files.join("; "),
    );
    let mut all = table;
    all.rows.sort_by(|a, b| a[0].cmp(&b[0]));
    Ok(Section {
        title: "Storage".into(),
        text,
        table: all,
        charts: vec!["storage_forest".into(), "storage_stream".into()],
    })
}

/// Per species and method: disk and GPU bytes; the quad stream's and the geometry methods'
/// totals (disk, GPU), and each atlas's files for the text.
#[allow(clippy::type_complexity)]
fn per_species(b: &Bench) -> Result<(Table, (u64, u64), (u64, u64), Vec<String>)> {
    let mut table = Table::new(&["method", "species", "disk_bytes", "gpu_bytes"]);
    let mut quad_total = (0u64, 0u64);
    // Each atlas's files (the channels it stores), for the text.
    let mut files = Vec::new();
    let mut geo_total = (0u64, 0u64);
    for (k, (path, data)) in b.species_paths.iter().zip(&b.species).enumerate() {
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let disk = folder_bytes(path);
        let gpu = data.atlas.manifest.gpu_bytes();
        files.push(format!(
            "{name}: {}",
            data.atlas
                .file_bytes()
                .iter()
                .map(|(f, b)| format!("{f} {:.2}", *b as f64 / MB))
                .collect::<Vec<_>>()
                .join(", ")
        ));
        quad_total.0 += disk;
        quad_total.1 += gpu;
        for m in ["quads", "impostor"] {
            table.push(vec![
                m.into(),
                name.clone(),
                disk.to_string(),
                gpu.to_string(),
            ]);
        }
        if let Some(obj) = b.models.get(k) {
            // The figures of the one preparation every geometry suite shares.
            let (disk, gpu) = (model_bytes(obj), b.prepared()?.figures[k].model_bytes);
            geo_total.0 += disk;
            geo_total.1 += gpu;
            for m in ["geometry", "stochastic", "lods"] {
                table.push(vec![
                    m.into(),
                    name.clone(),
                    disk.to_string(),
                    gpu.to_string(),
                ]);
            }
        }
    }
    b.write("storage.csv", &table.csv())?;
    Ok((table, quad_total, geo_total, files))
}

/// Forest memory against instances: the quad stream's, the geometry methods' and the forest
/// file's, a row and a chart point per forest size.
fn per_forest(b: &Bench, viewport: (u32, u32)) -> Result<Table> {
    let counts: Vec<u32> = if b.quick {
        vec![1000, 10_000]
    } else {
        vec![1000, 10_000, 100_000, 1_000_000]
    };
    let mut forest_table = Table::new(&["method", "instances", "disk_bytes", "gpu_bytes"]);
    let mut mem = [
        Series {
            name: "quad stream: GPU".into(),
            line: true,
            ..Default::default()
        },
        Series {
            name: "geometry methods: GPU".into(),
            line: true,
            ..Default::default()
        },
        Series {
            name: "forest file".into(),
            line: true,
            ..Default::default()
        },
    ];
    for &n in &counts {
        let side = (n as f32 * 10.0).sqrt();
        let forest = b.forest(n, side, 3)?;
        let disk = forest.to_bytes().len() as u64;
        let r = b.renderer(&forest, viewport, 8.0, false, Background::Sky)?;
        let quads = r.stream.scene.bytes + r.stream.capacity.bytes();
        forest_table.push(vec![
            "quads".into(),
            n.to_string(),
            disk.to_string(),
            quads.to_string(),
        ]);
        mem[0].points.push((f64::from(n), quads as f64 / MB));
        mem[2].points.push((f64::from(n), disk as f64 / MB));
        drop(r);
        if !b.models.is_empty() {
            let g = GeometryRenderer::new(
                &b.ctx,
                b.prepared()?,
                &forest,
                TARGET_FORMAT,
                Background::Sky,
            )?;
            forest_table.push(vec![
                "geometry".into(),
                n.to_string(),
                disk.to_string(),
                g.gpu_bytes.to_string(),
            ]);
            mem[1].points.push((f64::from(n), g.gpu_bytes as f64 / MB));
        }
        println!("{n} instances: file {disk} B, quad stream GPU {quads} B");
    }
    b.write("storage_forest.csv", &forest_table.csv())?;
    b.chart(
        "storage_forest",
        &Chart {
            title: "Memory against instances (800x600, ε ≥ 8)".into(),
            x_label: "tree instances".into(),
            y_label: "MiB".into(),
            log_x: true,
            log_y: true,
            series: mem.to_vec(),
        },
    )?;
    Ok(forest_table)
}

/// The quad-stream buffers against visible trees: what the frames needed and what the
/// capacity formula allocated.
fn per_stream(b: &Bench, viewport: (u32, u32)) -> Result<()> {
    let sizes: Vec<u32> = if b.quick {
        vec![300, 1000]
    } else {
        vec![5000, 20_000, 50_000, 100_000]
    };
    let mut stream_table = Table::new(&[
        "trees",
        "view",
        "visible_trees",
        "quads",
        "needed_bytes",
        "allocated_bytes",
    ]);
    let mut needed = Series {
        name: "needed (quads × 40 B: two stream buffers, two scan words)".into(),
        ..Default::default()
    };
    let mut allocated = Series {
        name: "allocated (capacity formula, all buffers)".into(),
        ..Default::default()
    };
    let target = Target::new(&b.ctx, viewport.0, viewport.1);
    let side = if b.quick { 100.0 } else { 1000.0 };
    for &n in &sizes {
        let forest = b.forest(n, side, 1)?;
        let mut r = b.renderer(&forest, viewport, 16.0, false, Background::Sky)?;
        for (view, eye, t) in super::table1::views(side) {
            let cam = Camera {
                eye,
                target: t,
                fov_y_deg: 60.0,
                near: 0.1,
                far: side * 3.0,
                viewport,
                epsilon: 16.0,
            };
            let (s, _) = b.measure(&mut r, Method::Quads, &cam, &target, 1)?;
            let need = s.primitives * (2 * 16 + 2 * 4);
            let alloc = r.stream.capacity.bytes();
            needed
                .points
                .push((f64::from(s.visible_trees), need as f64 / MB));
            allocated
                .points
                .push((f64::from(s.visible_trees), alloc as f64 / MB));
            stream_table.push(vec![
                n.to_string(),
                view.into(),
                s.visible_trees.to_string(),
                s.primitives.to_string(),
                need.to_string(),
                alloc.to_string(),
            ]);
        }
    }
    b.write("storage_stream.csv", &stream_table.csv())?;
    b.chart(
        "storage_stream",
        &Chart {
            title: "Quad-stream buffers against visible trees (800x600, ε 16)".into(),
            x_label: "visible trees".into(),
            y_label: "MiB".into(),
            log_x: true,
            log_y: true,
            series: vec![needed, allocated],
        },
    )?;
    Ok(())
}
