//! The mosaics' codecs: decoded layers, PNG encoding, blank-pixel filling, the smallest alpha
//! PNG.

/// Slab images decoded to RGBA8: layer-major, rows top to bottom, premultiplied sRGB-encoded RGB
/// and linear alpha (`layers × resolution² × 4` bytes).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Layers {
    /// Side of each layer in pixels.
    pub resolution: u32,
    /// Number of layers.
    pub count: u32,
    /// The pixels.
    pub rgba: Vec<u8>,
}

impl Layers {
    /// The RGBA8 pixels of one layer.
    pub fn layer(&self, layer: u32) -> &[u8] {
        let n = (self.resolution as usize).pow(2) * 4;
        &self.rgba[layer as usize * n..(layer as usize + 1) * n]
    }

    /// Tile the layers into a mosaic of `columns` columns; returns (width, height, pixels).
    pub fn mosaic(&self, columns: u32, channels: &[usize]) -> (u32, u32, Vec<u8>) {
        let r = self.resolution as usize;
        let rows = self.count.div_ceil(columns);
        let (w, h) = (columns * self.resolution, rows * self.resolution);
        let c = channels.len();
        let mut out = vec![0u8; w as usize * h as usize * c];
        for l in 0..self.count {
            let (tx, ty) = ((l % columns) as usize * r, (l / columns) as usize * r);
            let src = self.layer(l);
            for y in 0..r {
                for x in 0..r {
                    let s = (y * r + x) * 4;
                    let d = ((ty + y) * w as usize + tx + x) * c;
                    for (k, &ch) in channels.iter().enumerate() {
                        out[d + k] = src[s + ch];
                    }
                }
            }
        }
        (w, h, out)
    }
}

pub(crate) fn encode_png(w: u32, h: u32, data: &[u8], colour: image::ExtendedColorType) -> Vec<u8> {
    use image::ImageEncoder;
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new_with_quality(
        &mut out,
        image::codecs::png::CompressionType::Best,
        image::codecs::png::FilterType::Adaptive,
    )
    .write_image(data, w, h, colour)
    .expect("PNG encoding of an in-memory image of valid size cannot fail");
    out
}

/// Fill the colour of blank pixels (alpha 0) with the average of nearby fully covered ones
/// (push-pull over a 2×2 pyramid). Decoding clamps colour to alpha, so blank pixels read back
/// black whatever they hold; filling them keeps JPEG from ringing and darkening the
/// silhouettes against a black background, and makes the file smaller.
pub fn fill_blank(w: u32, h: u32, rgb: &mut [u8], alpha: &[u8]) {
    let (w, h) = (w as usize, h as usize);
    // Level 0: colour sums and weights of fully covered pixels.
    let mut levels: Vec<(usize, usize, Vec<[f32; 4]>)> = vec![(
        w,
        h,
        (0..w * h)
            .map(|i| {
                if alpha[i] == 255 {
                    let c = &rgb[i * 3..i * 3 + 3];
                    [f32::from(c[0]), f32::from(c[1]), f32::from(c[2]), 1.0]
                } else {
                    [0.0; 4]
                }
            })
            .collect(),
    )];
    while levels.last().is_some_and(|l| l.0 > 1 || l.1 > 1) {
        let (pw, ph, prev) = levels.last().unwrap();
        let (nw, nh) = (pw.div_ceil(2), ph.div_ceil(2));
        let mut next = vec![[0f32; 4]; nw * nh];
        for y in 0..*ph {
            for x in 0..*pw {
                let s = prev[y * pw + x];
                let d = &mut next[(y / 2) * nw + x / 2];
                for k in 0..4 {
                    d[k] += s[k];
                }
            }
        }
        levels.push((nw, nh, next));
    }
    // Pull, coarsest first: a cell becomes its average (weight 1) or, when empty, its
    // parent's (already pulled) value.
    let normalise = |c: &mut [f32; 4]| {
        if c[3] > 0.0 {
            *c = [c[0] / c[3], c[1] / c[3], c[2] / c[3], 1.0];
        }
    };
    levels.last_mut().unwrap().2.iter_mut().for_each(normalise);
    for k in (0..levels.len() - 1).rev() {
        let (upper, lower) = levels.split_at_mut(k + 1);
        let (lw, _, cells) = &mut upper[k];
        let (pw, _, parents) = &lower[0];
        for (i, cell) in cells.iter_mut().enumerate() {
            if cell[3] > 0.0 {
                normalise(cell);
            } else {
                let (x, y) = (i % *lw, i / *lw);
                *cell = parents[(y / 2) * pw + x / 2];
            }
        }
    }
    let (_, _, fine) = &levels[0];
    for i in 0..w * h {
        if alpha[i] == 0 {
            for c in 0..3 {
                rgb[i * 3 + c] = fine[i][c].round().clamp(0.0, 255.0) as u8;
            }
        }
    }
}

/// Encode 8-bit coverage as the smallest PNG: indexed with 1, 2 or 4 bits per pixel when it
/// has at most 2, 4 or 16 distinct values (as it does with up to 15 samples per pixel: coverage
/// takes `spp + 1` values), else 8-bit grey. The palette holds grey `(v, v, v)` entries.
pub fn encode_alpha_png(w: u32, h: u32, alpha: &[u8]) -> Vec<u8> {
    let mut seen = [false; 256];
    alpha.iter().for_each(|&a| seen[a as usize] = true);
    let values: Vec<u8> = (0..=255u8).filter(|&v| seen[v as usize]).collect();
    let bits = match values.len() {
        0..=2 => 1,
        3..=4 => 2,
        5..=16 => 4,
        _ => return encode_png(w, h, alpha, image::ExtendedColorType::L8),
    };
    let mut index = [0u8; 256];
    for (i, &v) in values.iter().enumerate() {
        index[v as usize] = i as u8;
    }
    let per_byte = 8 / bits;
    let row_bytes = (w as usize).div_ceil(per_byte);
    let mut packed = vec![0u8; row_bytes * h as usize];
    for y in 0..h as usize {
        for x in 0..w as usize {
            let i = index[alpha[y * w as usize + x] as usize];
            let shift = 8 - bits * (x % per_byte + 1);
            packed[y * row_bytes + x / per_byte] |= i << shift;
        }
    }
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, w, h);
    enc.set_color(png::ColorType::Indexed);
    enc.set_depth(match bits {
        1 => png::BitDepth::One,
        2 => png::BitDepth::Two,
        _ => png::BitDepth::Four,
    });
    enc.set_palette(values.iter().flat_map(|&v| [v, v, v]).collect::<Vec<u8>>());
    enc.set_deflate_compression(png::DeflateCompression::Level(9));
    // Filters only hurt packed low-bit indices.
    enc.set_filter(png::Filter::NoFilter);
    let mut writer = enc
        .write_header()
        .expect("PNG header of an in-memory image cannot fail");
    writer
        .write_image_data(&packed)
        .expect("PNG data of the declared size cannot fail");
    writer
        .finish()
        .expect("finishing an in-memory PNG cannot fail");
    out
}
