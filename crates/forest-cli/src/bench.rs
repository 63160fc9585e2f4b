//! `forest bench`: benchmark suites. Figures are printed and written as CSV; nothing here is
//! an assertion.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Result, bail};
use clap::Args;
use forest_format::generate::{GenerateParams, generate};
use forest_render::renderer::RendererOptions;
use forest_render::scene::SpeciesData;
use forest_render::target::{TARGET_FORMAT, Target};
use forest_render::{Camera, GpuContext, GpuScene, QuadStream};
use glam::Vec3;

/// Arguments of `forest bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Suite: table1 (the paper's Table 1).
    #[arg(value_parser = ["table1"])]
    pub suite: String,
    /// Species atlases (comma-separated).
    #[arg(long, value_delimiter = ',', required = true)]
    pub species: Vec<PathBuf>,
    /// Results folder (CSV is written there).
    #[arg(long, default_value = "results")]
    pub out: PathBuf,
    /// Quick mode: tiny forests and viewport, two frames (for CI; the figures mean little).
    #[arg(long)]
    pub quick: bool,
    /// Frames measured per setting (the median is reported).
    #[arg(long, default_value_t = 5)]
    pub frames: u32,
}

/// Side of the square every Table 1 forest covers (metres): forests differ in density.
const TABLE1_SIDE: f32 = 1000.0;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() { 0.0 } else { v[v.len() / 2] }
}

/// Run `forest bench`.
pub fn run(args: &BenchArgs) -> Result<()> {
    let species = args
        .species
        .iter()
        .map(|p| SpeciesData::load(p).map_err(anyhow::Error::from))
        .collect::<Result<Vec<_>>>()?;
    std::fs::create_dir_all(&args.out)?;
    let (sizes, viewport, frames): (Vec<u32>, (u32, u32), u32) = if args.quick {
        (vec![500, 1000], (200, 150), 2)
    } else {
        (
            vec![20_000, 40_000, 60_000, 80_000, 100_000, 120_000],
            (800, 600),
            args.frames.max(1),
        )
    };
    let ctx = GpuContext::headless()?;
    if !ctx
        .device
        .features()
        .contains(wgpu::Features::TIMESTAMP_QUERY)
    {
        bail!(
            "the adapter {} has no timestamp queries: no pass times to report",
            ctx.adapter_info.name
        );
    }
    let device = format!("{} ({:?})", ctx.adapter_info.name, ctx.adapter_info.backend);
    println!(
        "Table 1 on {device}, {}x{}, epsilon 16, median of {frames} frames",
        viewport.0, viewport.1
    );
    println!(
        "| trees | view | visible trees | quads | overflow | cull ms | refine ms | draw ms | total ms |"
    );
    println!("|---:|---|---:|---:|---:|---:|---:|---:|---:|");
    let mut csv = String::from(
        "trees,view,visible_trees,quads,cull_ms,refine_ms,draw_ms,total_ms,overflow,device\n",
    );
    let target = Target::new(&ctx, viewport.0, viewport.1);
    for &trees in &sizes {
        let side = if args.quick { 100.0 } else { TABLE1_SIDE };
        let forest = generate(&GenerateParams {
            trees,
            species: args
                .species
                .iter()
                .map(|p| p.display().to_string())
                .collect(),
            area_per_tree: side * side / trees as f32,
            clump_size: side / 15.0,
            seed: 1,
            ..GenerateParams::default()
        })
        .map_err(anyhow::Error::msg)?;
        let scene = GpuScene::new(&ctx, &species, &forest)?;
        let opts = RendererOptions {
            format: TARGET_FORMAT,
            viewport,
            min_epsilon: 16.0,
            ..Default::default()
        };
        let stream = QuadStream::new(&ctx, scene, &opts)?;
        let views = [
            (
                "inside",
                Vec3::new(0.0, 1.7, 0.0),
                Vec3::new(-30.0, 4.0, -100.0),
            ),
            (
                "birds-eye",
                Vec3::new(0.0, side * 0.15, side * 0.5),
                Vec3::new(0.0, 0.0, 0.0),
            ),
        ];
        for (view, eye, target_pt) in views {
            let cam = Camera {
                eye,
                target: target_pt,
                fov_y_deg: 60.0,
                near: 0.1,
                far: side * 3.0,
                viewport,
                epsilon: 16.0,
            };
            stream.set_camera(&ctx, &cam)?;
            let mut t = (Vec::new(), Vec::new(), Vec::new());
            let mut stats = None;
            for f in 0..frames + 1 {
                let mut enc = ctx.device.create_command_encoder(&Default::default());
                stream.encode(&mut enc, &target.colour_view, &target.depth_view);
                ctx.queue.submit([enc.finish()]);
                let s = stream.read_stats(&ctx);
                if f > 0 {
                    // The first frame compiles pipelines on some drivers: not measured.
                    let p = s.times.unwrap_or_default();
                    t.0.push(p.cull_ms);
                    t.1.push(p.refine_ms);
                    t.2.push(p.draw_ms);
                }
                stats = Some(s);
            }
            let errors = ctx.take_errors();
            if !errors.is_empty() {
                bail!("the GPU reported: {}", errors.join("; "));
            }
            let s = stats.expect("at least one frame");
            let (c, r, d) = (median(t.0), median(t.1), median(t.2));
            println!(
                "| {trees} | {view} | {} | {} | {} | {c:.1} | {r:.1} | {d:.1} | {:.1} |",
                s.visible_trees,
                s.quads,
                s.overflow_cull + s.overflow_refine,
                c + r + d
            );
            csv.push_str(&format!(
                "{trees},{view},{},{},{c:.3},{r:.3},{d:.3},{:.3},{},\"{device}\"\n",
                s.visible_trees,
                s.quads,
                c + r + d,
                s.overflow_cull + s.overflow_refine
            ));
        }
    }
    let path = args.out.join("table1.csv");
    let tmp = forest_bake::tmp_name(&path);
    std::fs::File::create(&tmp)?.write_all(csv.as_bytes())?;
    std::fs::rename(&tmp, &path)?;
    println!("wrote {}", path.display());
    Ok(())
}
