//! A contact sheet: every slab image side by side over a checkerboard, for people to look at.

use std::path::Path;

use forest_format::atlas::Layers;
use forest_format::shading::{srgb_decode_table, srgb_encode};

use crate::BakeError;

/// Largest tile side on the sheet; larger layers are box-filtered down by a power of two.
pub const MAX_TILE: u32 = 256;
const GAP: u32 = 4;

/// Compose the sheet: layers in rows of `columns` (direction-major, slabs side by side when
/// `columns` is a multiple of the slab count), composited over a grey checkerboard.
pub fn compose(layers: &Layers, columns: u32) -> image::RgbImage {
    let scale = (layers.resolution / MAX_TILE).max(1);
    let tile = layers.resolution / scale;
    let rows = layers.count.div_ceil(columns);
    let (w, h) = (columns * (tile + GAP) + GAP, rows * (tile + GAP) + GAP);
    let mut img = image::RgbImage::from_pixel(w, h, image::Rgb([40, 40, 40]));
    let table = srgb_decode_table();
    let r = layers.resolution as usize;
    for l in 0..layers.count {
        let src = layers.layer(l);
        let (ox, oy) = (
            GAP + (l % columns) * (tile + GAP),
            GAP + (l / columns) * (tile + GAP),
        );
        for ty in 0..tile {
            for tx in 0..tile {
                // Box filter in linear premultiplied space.
                let mut acc = [0f32; 4];
                for sy in 0..scale {
                    for sx in 0..scale {
                        let (x, y) = ((tx * scale + sx) as usize, (ty * scale + sy) as usize);
                        let p = &src[(y * r + x) * 4..(y * r + x) * 4 + 4];
                        for c in 0..3 {
                            acc[c] += table[p[c] as usize];
                        }
                        acc[3] += f32::from(p[3]) / 255.0;
                    }
                }
                let n = (scale * scale) as f32;
                let check = if ((tx / 16) + (ty / 16)) % 2 == 0 {
                    0.55
                } else {
                    0.35
                };
                let bg = table[(check * 255.0) as usize];
                let px = std::array::from_fn(|c| {
                    let v = acc[c] / n + bg * (1.0 - acc[3] / n);
                    (srgb_encode(v) * 255.0).round() as u8
                });
                img.put_pixel(ox + tx, oy + ty, image::Rgb(px));
            }
        }
    }
    img
}

/// Write the sheet as PNG (temporary name, then rename).
pub fn write(path: &Path, layers: &Layers, columns: u32) -> Result<(), BakeError> {
    let img = compose(layers, columns);
    Ok(forest_format::atomic::write_with(path, |tmp| {
        img.save_with_format(tmp, image::ImageFormat::Png)
    })?)
}
