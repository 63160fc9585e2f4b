//! The geometry renderer's textures: material and billboard layers in one sRGB array each,
//! with coverage-preserving mip chains filtered in linear light (as the atlas's are).

use forest_render::context::GpuContext;
use wgpu::util::DeviceExt;

pub use forest_format::model::MATERIAL_TEXTURE_SIZE;

/// The sizes (width, height) of a full mip chain's levels down to 1×1, level 0 first, as
/// [`mip_chain`] builds them (and [`box_mip_chain`] for square images).
pub(super) fn mip_sizes(width: u32, height: u32) -> impl Iterator<Item = (u32, u32)> {
    let levels = width.max(height).max(1).ilog2() + 1;
    (0..levels).map(move |k| ((width >> k).max(1), (height >> k).max(1)))
}

/// Bytes of square RGBA8 layers with their mip chains down to 1×1, as [`mip_chain`] and
/// [`box_mip_chain`] build them, from the layers' sizes alone.
pub(super) fn layer_bytes(layers: &[image::RgbaImage]) -> u64 {
    layers
        .iter()
        .flat_map(|l| mip_sizes(l.width(), l.height()))
        .map(|(w, h)| u64::from(w) * u64::from(h) * 4)
        .sum()
}

/// A layer's mip chain as uploaded: every level's RGBA8 bytes, level 0 first, concatenated,
/// and the number of levels ([`mip_chain`], [`box_mip_chain`]).
pub(super) type MipChain = (Vec<u8>, u32);

/// Every mip level of linear data down to 1×1, each the box filter of the one above (bytes and
/// level count, as [`mip_chain`]).
pub(super) fn box_mip_chain(img: &image::RgbaImage) -> (Vec<u8>, u32) {
    let mut data = img.as_raw().clone();
    let mut level = img.clone();
    let mut mips = 1;
    while level.width() > 1 && level.height() > 1 {
        let (w, h) = (level.width() / 2, level.height() / 2);
        level = image::RgbaImage::from_fn(w, h, |x, y| {
            let mut acc = [0u32; 4];
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let p = level.get_pixel(2 * x + dx, 2 * y + dy);
                (0..4).for_each(|c| acc[c] += u32::from(p[c]));
            }
            image::Rgba(acc.map(|a| ((a + 2) / 4) as u8))
        });
        data.extend_from_slice(level.as_raw());
        mips += 1;
    }
    (data, mips)
}

/// Mip chain of an RGBA8 (sRGB) image down to 1×1, level 0 first, concatenated.
///
/// The geometry methods alpha-test every texture at 0.5, so a texel either shows its own
/// colour or nothing. Each level's colour is therefore the mean, in linear light, of the
/// level-0 texels under it that pass the test (triangle-filtered level by level with those
/// texels as weights; the bake's point samples see the same colours), encoded back to sRGB;
/// where no passing texel lies under a texel, it keeps the filtered colour of the dilated
/// image (the nearest passing texel's). Averaging the colours of failing texels instead
/// (blank, or the faint fringe that leaf textures carry, often matted against white or sky
/// blue) tints distant foliage with them.
///
/// Alpha is rescaled per level, level 0 included, so that the share of the level's area that
/// passes the 0.5 alpha test *as the GPU's bilinear filter sees it* (4×4 points per texel,
/// wrapping as the sampler repeats) is the share of level-0 texels that pass it, which is what
/// the bake's point-sampling ray tracer sees (Castaño's coverage-preserving mips, with his
/// bilinear coverage estimate). Plain averaging erodes alpha-tested leaves into nothing at a
/// distance; counting texels instead of filtered area still thins needle-like leaves by 7 %
/// at the reference's resolution.
pub(super) fn mip_chain(img: &image::RgbaImage) -> (Vec<u8>, u32) {
    use forest_format::shading::{srgb_decode_table, srgb_encode};
    let target = img.pixels().filter(|p| p[3] >= ALPHA_TEST_BYTE).count() as f64
        / f64::from(img.width() * img.height());
    let mut data = Vec::new();
    let mut dilated = img.clone();
    // Level 0's bilinear filter must not mix in the colour of failing texels either.
    forest_format::model::dilate_colour_from(&mut dilated, ALPHA_TEST_BYTE);
    let table = srgb_decode_table();
    let linear = |x: u32, y: u32| {
        let p = dilated.get_pixel(x, y).0;
        [
            table[p[0] as usize],
            table[p[1] as usize],
            table[p[2] as usize],
        ]
    };
    // Colour and alpha as filtered; and colour × pass weight, with the weight in alpha.
    let mut plain = image::Rgba32FImage::from_fn(img.width(), img.height(), |x, y| {
        let [r, g, b] = linear(x, y);
        image::Rgba([r, g, b, f32::from(img.get_pixel(x, y)[3]) / 255.0])
    });
    let mut passing = image::Rgba32FImage::from_fn(img.width(), img.height(), |x, y| {
        let w = f32::from(u8::from(img.get_pixel(x, y)[3] >= ALPHA_TEST_BYTE));
        let [r, g, b] = linear(x, y);
        image::Rgba([r * w, g * w, b * w, w])
    });
    let encode = |plain: &image::Rgba32FImage, passing: &image::Rgba32FImage| {
        let byte = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
        image::RgbaImage::from_fn(plain.width(), plain.height(), |x, y| {
            let p = plain.get_pixel(x, y).0;
            let q = passing.get_pixel(x, y).0;
            let c = if q[3] > 1e-4 {
                [q[0] / q[3], q[1] / q[3], q[2] / q[3]]
            } else {
                [p[0], p[1], p[2]]
            };
            image::Rgba([
                byte(srgb_encode(c[0])),
                byte(srgb_encode(c[1])),
                byte(srgb_encode(c[2])),
                byte(p[3]),
            ])
        })
    };
    let mut level0 = dilated.clone();
    preserve_coverage(&mut level0, target);
    data.extend_from_slice(level0.as_raw());
    for (w, h) in mip_sizes(img.width(), img.height()).skip(1) {
        use image::imageops::{FilterType, resize};
        plain = resize(&plain, w, h, FilterType::Triangle);
        passing = resize(&passing, w, h, FilterType::Triangle);
        let mut m = encode(&plain, &passing);
        preserve_coverage(&mut m, target);
        data.extend_from_slice(m.as_raw());
    }
    (data, mip_sizes(img.width(), img.height()).count() as u32)
}

/// Scale `m`'s alpha so that a share of at least `target` of its bilinearly filtered area
/// (4×4 points per texel, wrapping) passes the 0.5 alpha test, with the smallest such scale
/// (at most 255, where every non-zero texel passes). Levels with no coverage or full coverage
/// are left as they are.
fn preserve_coverage(m: &mut image::RgbaImage, target: f64) {
    if !(target > 0.0 && target < 1.0) {
        return;
    }
    const SUB: u32 = 4;
    let (w, h) = (m.width(), m.height());
    let alpha = |x: i64, y: i64| {
        let x = x.rem_euclid(i64::from(w)) as u32;
        let y = y.rem_euclid(i64::from(h)) as u32;
        f32::from(m.get_pixel(x, y)[3])
    };
    let mut filtered = Vec::with_capacity((w * h * SUB * SUB) as usize);
    for y in 0..h * SUB {
        // The point's position in texel units, relative to texel centres.
        let fy = (y as f32 + 0.5) / SUB as f32 - 0.5;
        let (y0, ty) = (fy.floor() as i64, fy - fy.floor());
        for x in 0..w * SUB {
            let fx = (x as f32 + 0.5) / SUB as f32 - 0.5;
            let (x0, tx) = (fx.floor() as i64, fx - fx.floor());
            let top = alpha(x0, y0) * (1.0 - tx) + alpha(x0 + 1, y0) * tx;
            let bottom = alpha(x0, y0 + 1) * (1.0 - tx) + alpha(x0 + 1, y0 + 1) * tx;
            filtered.push(top * (1.0 - ty) + bottom * ty);
        }
    }
    // The k-th largest filtered alpha must reach 127.5 after scaling.
    let k = ((target * filtered.len() as f64).ceil() as usize).clamp(1, filtered.len());
    let (_, kth, _) = filtered.select_nth_unstable_by(k - 1, |a, b| b.total_cmp(a));
    let scale = if *kth > 0.0 {
        (127.5 / *kth).min(255.0)
    } else {
        255.0
    };
    for p in m.pixels_mut() {
        p[3] = (f32::from(p[3]) * scale).round().min(255.0) as u8;
    }
}

/// The smallest alpha byte that passes the geometry shaders' 0.5 alpha test.
pub(super) const ALPHA_TEST_BYTE: u8 = 128;

/// An array of square layers of side `size` with their mip chains: sRGB colour with
/// coverage-preserving mips ([`mip_chain`]), or with `linear` plain box-filtered linear data
/// (the billboards' surface attributes, whose blank texels were dilated).
pub(super) fn layered_texture(
    ctx: &GpuContext,
    label: &str,
    size: u32,
    layers: &[image::RgbaImage],
    linear: bool,
) -> (wgpu::TextureView, u64) {
    let chain = if linear { box_mip_chain } else { mip_chain };
    let chains: Vec<MipChain> = layers.iter().map(chain).collect();
    upload_layers(ctx, label, size, &chains, linear)
}

/// [`layered_texture`] from the layers' mip chains, computed once beforehand (the material
/// layers', which also cut the leaf cards). No layers upload one white layer.
pub(super) fn upload_layers(
    ctx: &GpuContext,
    label: &str,
    size: u32,
    chains: &[MipChain],
    linear: bool,
) -> (wgpu::TextureView, u64) {
    let white;
    let chains = if chains.is_empty() {
        let img = image::RgbaImage::from_pixel(size, size, image::Rgba([255; 4]));
        white = [if linear {
            box_mip_chain(&img)
        } else {
            mip_chain(&img)
        }];
        &white[..]
    } else {
        chains
    };
    let mut data = Vec::with_capacity(chains.iter().map(|c| c.0.len()).sum());
    for (d, _) in chains {
        data.extend_from_slice(d);
    }
    let mips = chains[0].1;
    let texture = ctx.device.create_texture_with_data(
        &ctx.queue,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: size,
                height: size,
                depth_or_array_layers: chains.len() as u32,
            },
            mip_level_count: mips,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: if linear {
                wgpu::TextureFormat::Rgba8Unorm
            } else {
                wgpu::TextureFormat::Rgba8UnormSrgb
            },
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        &data,
    );
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    (view, data.len() as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mips_average_in_linear_light() {
        // A checkerboard of black and white averages to linear 0.5: sRGB 188, not 128.
        let img = image::RgbaImage::from_fn(4, 4, |x, y| {
            let v = if (x + y) % 2 == 0 { 255 } else { 0 };
            image::Rgba([v, v, v, 255])
        });
        let (data, mips) = mip_chain(&img);
        assert_eq!(mips, 3);
        assert_eq!(data.len(), (16 + 4 + 1) * 4);
        let last = &data[data.len() - 4..];
        assert!((186..=190).contains(&last[0]), "{last:?}");
        assert_eq!(last[3], 255);
    }

    #[test]
    fn layer_bytes_are_the_chains_bytes() {
        for side in [1, 2, 5, 64] {
            let img = image::RgbaImage::from_pixel(side, side, image::Rgba([9, 8, 7, 200]));
            let layers = [img.clone(), img.clone()];
            let chains = 2 * mip_chain(&img).0.len() as u64;
            assert_eq!(layer_bytes(&layers), chains, "side {side}");
            assert_eq!(layer_bytes(&layers), 2 * box_mip_chain(&img).0.len() as u64);
        }
        assert_eq!(layer_bytes(&[]), 0);
    }

    #[test]
    fn mip_colour_is_that_of_the_texels_passing_the_alpha_test() {
        // Left half opaque red; then a faint white fringe (alpha 100, never drawn) and blank
        // sky-blue texels. Every level shows red alone, as the alpha-tested texels do.
        let img = image::RgbaImage::from_fn(4, 4, |x, _| match x {
            0 | 1 => image::Rgba([255, 0, 0, 255]),
            2 => image::Rgba([255, 255, 255, 100]),
            _ => image::Rgba([80, 110, 115, 0]),
        });
        let (data, mips) = mip_chain(&img);
        assert_eq!(mips, 3);
        for (level, texel) in data.chunks_exact(4).enumerate() {
            assert_eq!(texel[..3], [255, 0, 0], "texel {level}: {texel:?}");
        }
        // Half the texels pass at every level (Castaño), so the 1×1 level passes.
        let last = &data[data.len() - 4..];
        assert!(last[3] >= 128, "{last:?}");
    }
}
