//! Textures as the ray tracer samples them: RGBA8, nearest texel, repeat wrap.

use glam::{Vec2, Vec3};

/// An RGBA8 texture (rows top to bottom) with its sRGB decode table.
#[derive(Clone, Debug)]
pub struct Texture {
    /// Width in texels (> 0).
    pub width: u32,
    /// Height in texels (> 0).
    pub height: u32,
    /// `width × height × 4` bytes: sRGB-encoded RGB, linear alpha.
    pub rgba: Vec<u8>,
    /// Whether any texel has alpha below 255.
    pub has_alpha: bool,
}

impl Texture {
    /// A texture from decoded RGBA8 pixels.
    pub fn new(width: u32, height: u32, rgba: Vec<u8>) -> Self {
        assert_eq!(rgba.len(), width as usize * height as usize * 4);
        assert!(width > 0 && height > 0);
        let has_alpha = rgba.chunks_exact(4).any(|p| p[3] < 255);
        Self {
            width,
            height,
            rgba,
            has_alpha,
        }
    }

    /// Texel index of texture coordinate `uv` (OBJ convention: v = 0 is the bottom row),
    /// repeating outside `[0,1)`.
    fn texel(&self, uv: Vec2) -> usize {
        // `x − ⌊x⌋` rounds the same real number as `x.rem_euclid(1.0)` (whose fmod is exact)
        // without the fmod call, which the bake's alpha tests made a visible cost.
        let fract = |x: f32| x - x.floor();
        let fx = fract(uv.x);
        let fy = fract(1.0 - uv.y);
        let x = ((fx * self.width as f32) as u32).min(self.width - 1);
        let y = ((fy * self.height as f32) as u32).min(self.height - 1);
        (y * self.width + x) as usize * 4
    }

    /// sRGB-encoded RGB and linear alpha at `uv` (non-finite `uv` reads texel 0).
    pub fn fetch(&self, uv: Vec2) -> [u8; 4] {
        let i = if uv.is_finite() { self.texel(uv) } else { 0 };
        [
            self.rgba[i],
            self.rgba[i + 1],
            self.rgba[i + 2],
            self.rgba[i + 3],
        ]
    }

    /// Linear RGB at `uv`.
    pub fn linear_rgb(&self, uv: Vec2, table: &[f32; 256]) -> Vec3 {
        let t = self.fetch(uv);
        Vec3::new(
            table[t[0] as usize],
            table[t[1] as usize],
            table[t[2] as usize],
        )
    }
}

/// Decode a texture file's bytes (PNG or JPEG, within the decoder's limits) to RGBA8: the
/// reason it cannot be, in the words both model loaders' texture errors use.
pub fn decode_rgba(bytes: &[u8], file: &std::path::Path) -> Result<image::RgbaImage, String> {
    let img = forest_format::bounded::decode_image(bytes, None, file)
        .map_err(|e| match e {
            forest_format::FormatError::Image { what, .. } => what,
            other => other.to_string(),
        })?
        .into_rgba8();
    if img.width() == 0 || img.height() == 0 {
        return Err("empty image".into());
    }
    Ok(img)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn v_zero_is_the_bottom_row_and_uv_repeats() {
        // 2×2: top row red, green; bottom row blue, white.
        let t = Texture::new(
            2,
            2,
            vec![
                255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 0, 255, 255, 255, 128,
            ],
        );
        assert!(t.has_alpha);
        assert_eq!(t.fetch(Vec2::new(0.25, 0.75)), [255, 0, 0, 255]);
        assert_eq!(t.fetch(Vec2::new(0.75, 0.25)), [255, 255, 255, 128]);
        assert_eq!(t.fetch(Vec2::new(1.25, 1.25)), [0, 0, 255, 0]);
        assert_eq!(t.fetch(Vec2::new(-0.75, -0.25)), [255, 0, 0, 255]);
        assert_eq!(t.fetch(Vec2::new(f32::NAN, 0.0)), [255, 0, 0, 255]);
    }
}
