//! `forest compare`: accuracy metrics of an image against a reference.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

/// Arguments of `forest compare`.
#[derive(Args, Debug)]
pub struct CompareArgs {
    /// Reference image.
    pub reference: PathBuf,
    /// Image to judge.
    pub test: PathBuf,
    /// Also write the FLIP error map (PNG).
    #[arg(long, value_name = "PNG")]
    pub flip_map: Option<PathBuf>,
    /// Print one JSON line.
    #[arg(long)]
    pub json: bool,
}

/// Run `forest compare`.
pub fn run(args: &CompareArgs) -> Result<()> {
    if let Some(p) = &args.flip_map {
        let inputs = [args.reference.clone(), args.test.clone()];
        crate::guard::output(p, "FLIP map", &inputs)?;
        crate::guard::extension(p, "FLIP map", "PNG", &["png"])?;
    }
    let open = |p: &PathBuf| -> Result<image::RgbaImage> {
        let bytes = forest_format::bounded::read(p, forest_format::bounded::limit::DATA)?;
        Ok(forest_format::bounded::decode_image(&bytes, None, p)?.into_rgba8())
    };
    let (a, b) = (open(&args.reference)?, open(&args.test)?);
    let m = forest_metrics::compare(&a, &b)?;
    if let Some(p) = &args.flip_map {
        let (_, map) = forest_metrics::flip(&a, &b)?;
        forest_format::atomic::write_with(p, |tmp| {
            map.save_with_format(tmp, image::ImageFormat::Png)
        })?;
    }
    if args.json {
        println!("{}", serde_json::to_string(&m)?);
    } else {
        let iou = m
            .coverage_iou
            .map_or("n/a (opaque images)".to_string(), |v| format!("{v:.4}"));
        println!(
            "FLIP {:.4}  SSIM {:.4}  PSNR {:.2} dB  coverage IoU {iou}",
            m.flip_mean, m.ssim, m.psnr
        );
        // Over transparent black: the covered pixels' mean colours, as `bench colour` takes
        // each tree's.
        let mean = crate::bench::colour::mean_colour;
        if let (Some(_), Some(r), Some(t)) = (m.coverage_iou, mean(&a), mean(&b)) {
            let lab = forest_format::colour::lab;
            println!(
                "mean colour ΔE {:.2} (CIELAB; L* {:.2} against {:.2})",
                forest_format::colour::delta_e(t, r),
                lab(t).x,
                lab(r).x
            );
        }
    }
    Ok(())
}
