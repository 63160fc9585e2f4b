//! The project's one shading model. The bake, the full-geometry reference and every rival
//! method use exactly this, so that accuracy differences come from the level-of-detail method
//! alone.
//!
//! For a surface point with linear albedo `a` (material `Kd` × texture colour, sRGB-decoded),
//! unit normal `n` turned towards the viewer (every surface is two-sided), sun direction `L`
//! (unit, towards the sun) and sun visibility `V ∈ [0,1]` (1 = lit; the bake traces one
//! alpha-tested shadow ray per sample):
//!
//! ```text
//! direct   = max(n·L, 0) + τ·max(−n·L, 0)        τ = translucency: 0 bark, 0.35 leaves
//! hemi     = 0.5 + 0.5·n.y
//! ambient  = sky·hemi + ground·(1 − hemi)        (not occluded: no ambient-occlusion rays)
//! radiance = a · (ambient + sun · V · direct)    linear RGB, not tone-mapped
//! ```
//!
//! Colours are stored sRGB-encoded. Baked slab colours are premultiplied by coverage in linear
//! space and then sRGB-encoded, so that an `*Srgb` texture decodes them back to linear
//! premultiplied values before filtering.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Translucency `τ` of alpha-textured materials (leaf cards): the share of sunlight hitting the
/// back of a leaf that reaches the viewer on its front.
pub const LEAF_TRANSLUCENCY: f32 = 0.35;

/// Light environment: one sun and a two-colour sky dome, linear RGB.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Lighting {
    /// Unit vector towards the sun (object/world space, +Y up).
    pub sun_dir: Vec3,
    /// Sun irradiance, linear RGB.
    pub sun: Vec3,
    /// Sky irradiance on a surface facing straight up, linear RGB.
    pub sky: Vec3,
    /// Ground-bounce irradiance on a surface facing straight down, linear RGB.
    pub ground: Vec3,
}

impl Lighting {
    /// The default sun colour, sky and ground with the sun at the given azimuth (degrees from
    /// +Z towards +X) and elevation (degrees above the horizon).
    pub fn with_sun(azimuth_deg: f32, elevation_deg: f32) -> Self {
        Self {
            sun_dir: sun_direction(azimuth_deg, elevation_deg),
            sun: Vec3::new(1.0, 0.95, 0.85),
            sky: Vec3::new(0.32, 0.38, 0.48),
            ground: Vec3::new(0.10, 0.09, 0.07),
        }
    }

    /// Outgoing radiance (linear RGB) of a point: see the module documentation.
    pub fn shade(&self, albedo: Vec3, n: Vec3, sun_visibility: f32, translucency: f32) -> Vec3 {
        let ndl = n.dot(self.sun_dir);
        let direct = ndl.max(0.0) + translucency * (-ndl).max(0.0);
        let hemi = 0.5 + 0.5 * n.y;
        let ambient = self.sky * hemi + self.ground * (1.0 - hemi);
        albedo * (ambient + self.sun * (sun_visibility * direct))
    }
}

/// Unit vector towards a sun at `azimuth_deg` (from +Z towards +X) and `elevation_deg`.
pub fn sun_direction(azimuth_deg: f32, elevation_deg: f32) -> Vec3 {
    let (az, el) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
    Vec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos()).normalize()
}

/// sRGB transfer function: linear `[0,1]` → encoded `[0,1]`.
pub fn srgb_encode(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// Inverse sRGB transfer function: encoded `[0,1]` → linear `[0,1]`.
pub fn srgb_decode(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.040_45 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// Table of [`srgb_decode`] for 8-bit values.
pub fn srgb_decode_table() -> [f32; 256] {
    std::array::from_fn(|i| srgb_decode(i as f32 / 255.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trips_all_bytes() {
        for i in 0..=255u32 {
            let x = i as f32 / 255.0;
            let y = srgb_encode(srgb_decode(x));
            assert!((x - y).abs() < 1e-5, "{i}");
        }
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn shading_terms_have_their_analytic_values() {
        let l = Lighting::with_sun(0.0, 90.0);
        assert!((l.sun_dir - Vec3::Y).length() < 1e-6);
        let white = Vec3::ONE;
        // Facing the sun, lit: ambient is pure sky (hemi = 1) plus the full sun.
        assert!((l.shade(white, Vec3::Y, 1.0, 0.0) - (l.sky + l.sun)).length() < 1e-6);
        // Shadowed: sky only.
        assert!((l.shade(white, Vec3::Y, 0.0, 0.0) - l.sky).length() < 1e-6);
        // Facing away: ground only, plus translucency of the sun.
        let back = l.shade(white, -Vec3::Y, 1.0, 0.5);
        assert!((back - (l.ground + l.sun * 0.5)).length() < 1e-6);
        // Sideways: half sky, half ground, no direct sun.
        let side = l.shade(white, Vec3::X, 1.0, 0.0);
        assert!((side - (l.sky + l.ground) * 0.5).length() < 1e-6);
    }
}
