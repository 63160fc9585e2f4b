//! The geometry renderer's textures: material and billboard layers in one sRGB array each,
//! with coverage-preserving mip chains filtered in linear light (as the atlas's are).

use forest_bake::Mesh;
use forest_render::context::GpuContext;
use wgpu::util::DeviceExt;

/// Side of every material texture layer on the GPU.
pub const MATERIAL_TEXTURE_SIZE: u32 = 512;

/// Bytes of RGBA8 layers with their mip chains (a third more than level 0).
pub(super) fn layer_bytes(layers: &[image::RgbaImage]) -> u64 {
    layers.iter().map(|l| l.as_raw().len() as u64 * 4 / 3).sum()
}

/// Combine a material's colour and alpha sources into one RGBA image of the layer size.
pub(super) fn material_layer(
    mesh: &Mesh,
    colour: Option<usize>,
    alpha: Option<(usize, bool)>,
) -> image::RgbaImage {
    let s = MATERIAL_TEXTURE_SIZE;
    let resize = |t: usize| {
        let tex = &mesh.textures[t];
        let img = image::RgbaImage::from_raw(tex.width, tex.height, tex.rgba.clone())
            .expect("texture size");
        image::imageops::resize(&img, s, s, image::imageops::FilterType::Triangle)
    };
    let mut out = match colour {
        Some(c) => resize(c),
        None => image::RgbaImage::from_pixel(s, s, image::Rgba([255, 255, 255, 255])),
    };
    if let Some((a, channel)) = alpha {
        let src = if Some(a) == colour && channel {
            out.clone()
        } else {
            resize(a)
        };
        for (o, p) in out.pixels_mut().zip(src.pixels()) {
            o[3] = if channel {
                p[3]
            } else {
                ((u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2])) / 3) as u8
            };
        }
    }
    out
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
/// Alpha is rescaled per level so that the share of texels passing the 0.5 alpha test stays
/// that of level 0 (Castaño's coverage-preserving mips): plain averaging erodes alpha-tested
/// leaves into nothing at a distance.
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

pub(super) fn mip_chain(img: &image::RgbaImage) -> (Vec<u8>, u32) {
    use forest_format::shading::{srgb_decode_table, srgb_encode};
    let coverage = |m: &image::RgbaImage, scale: f32| {
        m.pixels()
            .filter(|p| f32::from(p[3]) * scale >= 127.5)
            .count() as f32
            / (m.width() * m.height()) as f32
    };
    let target = coverage(img, 1.0);
    let mut data = Vec::new();
    let mut dilated = img.clone();
    // Level 0's bilinear filter must not mix in the colour of failing texels either.
    forest_bake::lod::dilate_colour_from(&mut dilated, ALPHA_TEST_BYTE);
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
    let mips = img.width().max(img.height()).ilog2() + 1;
    data.extend_from_slice(dilated.as_raw());
    for level in 1..mips {
        let (w, h) = (
            (img.width() >> level).max(1),
            (img.height() >> level).max(1),
        );
        use image::imageops::{FilterType, resize};
        plain = resize(&plain, w, h, FilterType::Triangle);
        passing = resize(&passing, w, h, FilterType::Triangle);
        let mut m = encode(&plain, &passing);
        if target > 0.0 && target < 1.0 {
            // Bisect the alpha scale whose coverage matches level 0's.
            let (mut lo, mut hi) = (0.0f32, 8.0f32);
            for _ in 0..20 {
                let mid = 0.5 * (lo + hi);
                if coverage(&m, mid) < target {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            for p in m.pixels_mut() {
                p[3] = (f32::from(p[3]) * hi).round().min(255.0) as u8;
            }
        }
        data.extend_from_slice(m.as_raw());
    }
    (data, mips)
}

/// The smallest alpha byte that passes the geometry shaders' 0.5 alpha test.
const ALPHA_TEST_BYTE: u8 = 128;

/// An sRGB RGBA8 2D-array texture with mips from square layers of side `size`.
/// An array of `layers` with their mip chains: sRGB colour with coverage-preserving mips
/// ([`mip_chain`]), or with `linear` plain box-filtered linear data (the billboards' surface
/// attributes, whose blank texels were dilated).
pub(super) fn layered_texture(
    ctx: &GpuContext,
    label: &str,
    size: u32,
    layers: &[image::RgbaImage],
    linear: bool,
) -> (wgpu::TextureView, u64) {
    let white = [image::RgbaImage::from_pixel(
        size,
        size,
        image::Rgba([255; 4]),
    )];
    let layers = if layers.is_empty() {
        &white[..]
    } else {
        layers
    };
    let mut data = Vec::new();
    let mut mips = 1;
    for img in layers {
        let (d, m) = if linear {
            box_mip_chain(img)
        } else {
            mip_chain(img)
        };
        data.extend(d);
        mips = m;
    }
    let texture = ctx.device.create_texture_with_data(
        &ctx.queue,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: size,
                height: size,
                depth_or_array_layers: layers.len() as u32,
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
