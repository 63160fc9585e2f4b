//! Accuracy of an image against a reference, as every benchmark of the project reports it:
//!
//! - **mean FLIP** (NVIDIA FLIP, LDR, through the nv-flip crate; 0 = identical, higher =
//!   more visible difference), at 67 pixels per degree (a 0.7 m wide 4K display seen from 0.7 m);
//! - **SSIM** on luma (image-compare's 8×8-window mean SSIM; 1 = identical);
//! - **PSNR** over the RGB channels of the 8-bit images, in dB, capped at [`PSNR_CAP`] for
//!   identical images;
//! - **coverage IoU**: intersection over union of the pixels at least half covered
//!   (alpha ≥ 128; tree coverage when rendered over a transparent background), so faint
//!   filtering fringes do not count; `None` when both images are fully opaque, since coverage
//!   is then unknown.
//!
//! Colour is compared as stored (the project's renders over a transparent background are
//! premultiplied), except where a pixel's alpha is 0: no compositing shows that colour, and
//! images with straight alpha leave anything there, so it is taken as black in both images.
//!
//! ```
//! use image::{Rgba, RgbaImage};
//!
//! let reference = RgbaImage::from_pixel(64, 48, Rgba([40, 90, 30, 255]));
//! let mut test = reference.clone();
//! test.put_pixel(10, 10, Rgba([200, 90, 30, 255]));
//! let m = forest_metrics::compare(&reference, &test)?;
//! assert!(m.flip_mean > 0.0 && m.flip_mean < 0.01);
//! assert_eq!(forest_metrics::compare(&reference, &reference)?.flip_mean, 0.0);
//! # Ok::<(), forest_metrics::MetricsError>(())
//! ```

#![deny(missing_docs)]

use image::RgbaImage;

/// PSNR reported for identical images (dB).
pub const PSNR_CAP: f64 = 100.0;
/// Pixels per degree used for FLIP.
pub const FLIP_PIXELS_PER_DEGREE: f32 = 67.0;

/// Why two images cannot be compared.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MetricsError {
    /// Sizes differ.
    #[error("image sizes differ: {0:?} vs {1:?}")]
    Size((u32, u32), (u32, u32)),
    /// An empty image.
    #[error("the images are empty")]
    Empty,
}

/// The metrics of a test image against a reference.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Metrics {
    /// Mean FLIP error in [0, 1].
    pub flip_mean: f32,
    /// Mean SSIM of luma.
    pub ssim: f64,
    /// PSNR of RGB in dB.
    pub psnr: f64,
    /// Coverage intersection over union, when an alpha channel tells coverage.
    pub coverage_iou: Option<f64>,
}

/// The image as compared: RGB black wherever alpha is 0 (see the module documentation);
/// borrowed when no colour hides under alpha 0 (premultiplied renders), copied otherwise.
fn visible(img: &RgbaImage) -> std::borrow::Cow<'_, RgbaImage> {
    let hidden = |p: &image::Rgba<u8>| p[3] == 0 && p.0 != [0, 0, 0, 0];
    if !img.pixels().any(hidden) {
        return std::borrow::Cow::Borrowed(img);
    }
    let mut out = img.clone();
    for p in out.pixels_mut() {
        if p[3] == 0 {
            *p = image::Rgba([0, 0, 0, 0]);
        }
    }
    std::borrow::Cow::Owned(out)
}

fn rgb(img: &RgbaImage) -> image::RgbImage {
    image::DynamicImage::ImageRgba8(visible(img).into_owned()).to_rgb8()
}

/// Mean FLIP and the per-pixel error map (magma colours).
pub fn flip(
    reference: &RgbaImage,
    test: &RgbaImage,
) -> Result<(f32, image::RgbImage), MetricsError> {
    check(reference, test)?;
    let (w, h) = reference.dimensions();
    let r = nv_flip::FlipImageRgb8::with_data(w, h, &rgb(reference));
    let t = nv_flip::FlipImageRgb8::with_data(w, h, &rgb(test));
    let err = nv_flip::flip(r, t, FLIP_PIXELS_PER_DEGREE);
    let mean = nv_flip::FlipPool::from_image(&err).mean();
    let map = err.apply_color_lut(&nv_flip::magma_lut());
    let map = image::RgbImage::from_raw(w, h, map.to_vec()).expect("FLIP map has the image's size");
    Ok((mean, map))
}

/// PSNR of the RGB channels (dB, capped at [`PSNR_CAP`]).
pub fn psnr(reference: &RgbaImage, test: &RgbaImage) -> Result<f64, MetricsError> {
    check(reference, test)?;
    let mut se = 0f64;
    for (a, b) in visible(reference).pixels().zip(visible(test).pixels()) {
        for c in 0..3 {
            se += (f64::from(a[c]) - f64::from(b[c])).powi(2);
        }
    }
    let mse = se / (3.0 * f64::from(reference.width()) * f64::from(reference.height()));
    Ok(if mse == 0.0 {
        PSNR_CAP
    } else {
        (10.0 * (255f64.powi(2) / mse).log10()).min(PSNR_CAP)
    })
}

/// Mean SSIM of luma.
pub fn ssim(reference: &RgbaImage, test: &RgbaImage) -> Result<f64, MetricsError> {
    check(reference, test)?;
    let luma = |i: &RgbaImage| image::DynamicImage::ImageRgba8(visible(i).into_owned()).to_luma8();
    let s = image_compare::gray_similarity_structure(
        &image_compare::Algorithm::MSSIMSimple,
        &luma(reference),
        &luma(test),
    )
    .map_err(|_| MetricsError::Size(reference.dimensions(), test.dimensions()))?;
    Ok(s.score)
}

/// Intersection over union of half-covered pixels (alpha ≥ 128); `None` when both are fully
/// opaque.
pub fn coverage_iou(reference: &RgbaImage, test: &RgbaImage) -> Result<Option<f64>, MetricsError> {
    check(reference, test)?;
    let opaque = |i: &RgbaImage| i.pixels().all(|p| p[3] == 255);
    if opaque(reference) && opaque(test) {
        return Ok(None);
    }
    let (mut inter, mut union) = (0u64, 0u64);
    for (a, b) in reference.pixels().zip(test.pixels()) {
        let (ca, cb) = (a[3] >= 128, b[3] >= 128);
        inter += u64::from(ca && cb);
        union += u64::from(ca || cb);
    }
    Ok(Some(if union == 0 {
        1.0
    } else {
        inter as f64 / union as f64
    }))
}

fn check(a: &RgbaImage, b: &RgbaImage) -> Result<(), MetricsError> {
    if a.dimensions() != b.dimensions() {
        return Err(MetricsError::Size(a.dimensions(), b.dimensions()));
    }
    if a.width() == 0 || a.height() == 0 {
        return Err(MetricsError::Empty);
    }
    Ok(())
}

/// All metrics of `test` against `reference`.
pub fn compare(reference: &RgbaImage, test: &RgbaImage) -> Result<Metrics, MetricsError> {
    Ok(Metrics {
        flip_mean: flip(reference, test)?.0,
        ssim: ssim(reference, test)?,
        psnr: psnr(reference, test)?,
        coverage_iou: coverage_iou(reference, test)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn noise(w: u32, h: u32, seed: u32) -> RgbaImage {
        RgbaImage::from_fn(w, h, |x, y| {
            let v = (x.wrapping_mul(2_654_435_761) ^ y.wrapping_mul(40_503) ^ seed) % 251;
            image::Rgba([v as u8, (v * 3 % 256) as u8, (255 - v) as u8, 255])
        })
    }

    #[test]
    fn identical_images_score_perfectly() {
        let a = noise(64, 48, 1);
        let m = compare(&a, &a).unwrap();
        assert_eq!(m.flip_mean, 0.0);
        assert!((m.ssim - 1.0).abs() < 1e-9);
        assert_eq!(m.psnr, PSNR_CAP);
        assert_eq!(m.coverage_iou, None);
    }

    #[test]
    fn colour_under_zero_alpha_does_not_count() {
        // Straight-alpha images that differ only where nothing is covered.
        let a = RgbaImage::from_fn(32, 32, |x, _| {
            if x < 16 {
                image::Rgba([200, 40, 90, 0])
            } else {
                image::Rgba([60, 120, 30, 255])
            }
        });
        let b = RgbaImage::from_fn(32, 32, |x, _| {
            if x < 16 {
                image::Rgba([5, 250, 250, 0])
            } else {
                image::Rgba([60, 120, 30, 255])
            }
        });
        let m = compare(&a, &b).unwrap();
        assert_eq!(m.flip_mean, 0.0);
        assert_eq!(m.psnr, PSNR_CAP);
        assert!((m.ssim - 1.0).abs() < 1e-9);
        assert_eq!(m.coverage_iou, Some(1.0));
        // Where alpha is above 0 colour still counts.
        let mut c = b.clone();
        c.put_pixel(20, 20, image::Rgba([250, 0, 0, 255]));
        assert!(compare(&a, &c).unwrap().flip_mean > 0.0);
    }

    #[test]
    fn psnr_of_a_one_level_offset_is_analytic() {
        let a = RgbaImage::from_pixel(16, 16, image::Rgba([100, 100, 100, 255]));
        let b = RgbaImage::from_pixel(16, 16, image::Rgba([101, 99, 101, 255]));
        // MSE = 1: PSNR = 20·log10(255) = 48.1308 dB.
        assert!((psnr(&a, &b).unwrap() - 20.0 * 255f64.log10()).abs() < 1e-9);
    }

    #[test]
    fn coverage_iou_of_overlapping_halves() {
        // Reference covers columns 0..8, test columns 4..12 of 16: IoU = 4/12.
        let mk = |x0: u32, x1: u32| {
            RgbaImage::from_fn(16, 4, |x, _| {
                image::Rgba([0, 0, 0, if (x0..x1).contains(&x) { 200 } else { 0 }])
            })
        };
        let iou = coverage_iou(&mk(0, 8), &mk(4, 12)).unwrap().unwrap();
        assert!((iou - 1.0 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn different_images_score_worse_and_sizes_must_match() {
        let a = noise(64, 48, 1);
        let b = noise(64, 48, 7);
        let m = compare(&a, &b).unwrap();
        assert!(m.flip_mean > 0.1 && m.ssim < 0.9 && m.psnr < 20.0, "{m:?}");
        let small = noise(32, 48, 1);
        assert_eq!(
            compare(&a, &small).unwrap_err(),
            MetricsError::Size((64, 48), (32, 48))
        );
    }
}
