//! The project's one shading model. The bake, the full-geometry reference and every rival
//! method use exactly this, so that accuracy differences come from the level-of-detail method
//! alone. Light is applied at run time, in world space: the bake stores what light needs
//! (albedo, normal, sky visibility, translucency), never the light itself.
//!
//! For a surface point with linear albedo `a` (material `Kd` × texture colour, sRGB-decoded),
//! unit normal `n` turned towards the viewer (every surface is two-sided), sun direction `L`
//! (unit, towards the sun), sun visibility `V ∈ [0,1]` (1 = lit) and sky visibility
//! `S ∈ [0,1]` (the cosine-weighted share of the hemisphere around `n` that the tree itself
//! does not hide; 1 = open sky, traced at bake or preparation):
//!
//! ```text
//! direct   = max(n·L, 0) + τ·max(−n·L, 0)        τ = translucency: 0 bark, 0.35 leaves
//! hemi     = 0.5 + 0.5·n.y
//! ambient  = (sky·hemi + ground·(1 − hemi)) · S
//! radiance = exposure · a · (ambient + sun · V · direct)    linear RGB, not tone-mapped
//! ```
//!
//! Colours are stored sRGB-encoded. Baked slab albedos are premultiplied by coverage in linear
//! space and then sRGB-encoded, so that an `*Srgb` texture decodes them back to linear
//! premultiplied values before filtering. The slabs' other surface attributes (octahedral
//! normal, sky visibility, translucency) are stored linear and premultiplied too, so a
//! filtered texel divided by its filtered coverage is the coverage-weighted mean.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Translucency `τ` of alpha-textured materials (leaf cards): the share of sunlight hitting the
/// back of a leaf that reaches the viewer on its front.
pub const LEAF_TRANSLUCENCY: f32 = 0.35;

/// Light environment: one sun and a two-colour sky dome, linear RGB, and the exposure every
/// radiance is scaled by. It is a run-time input of every renderer (the camera uniform carries
/// it), never baked.
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
    /// Scale of every outgoing radiance (1: none), as a host's camera exposure.
    #[serde(default = "one")]
    pub exposure: f32,
}

fn one() -> f32 {
    1.0
}

impl Default for Lighting {
    /// The default sun: azimuth 30°, elevation 55°.
    fn default() -> Self {
        Self::with_sun(30.0, 55.0)
    }
}

impl Lighting {
    /// Daylight with the sun at the given azimuth and elevation (degrees; elevation clamped
    /// to [0.5°, 90°]): the sun reddens and dims through the air mass it crosses
    /// (Kasten–Young's air mass, per-channel extinction), the sky dims and warms as the sun
    /// sinks, and the ground bounce follows both. Close to [`Lighting::with_sun`] at 55°.
    pub fn daylight(azimuth_deg: f32, elevation_deg: f32) -> Self {
        let el = elevation_deg.clamp(0.5, 90.0);
        let s = el.to_radians().sin();
        let air_mass = 1.0 / (s + 0.505_72 * (el + 6.079_95).powf(-1.6364));
        let extinction = Vec3::new(0.06, 0.12, 0.27);
        let sun = Vec3::splat(1.08) * (-extinction * air_mass).exp();
        let h = s.sqrt();
        let sky = Vec3::new(0.40, 0.34, 0.30).lerp(Vec3::new(0.32, 0.38, 0.48), h)
            * ((0.25 + 0.75 * h) / (0.25 + 0.75 * 0.905));
        let ground = (sun * s + sky) * Vec3::new(0.062, 0.056, 0.044);
        Self {
            sun_dir: sun_direction(azimuth_deg, el),
            sun,
            sky,
            ground,
            exposure: 1.0,
        }
    }

    /// [`Lighting::daylight`] at a local solar hour in [6, 18] (clamped): the sun rises at 6
    /// in the east (azimuth 90°), culminates at 12 in the south (180°) at `max_elevation_deg`,
    /// and sets at 18 in the west (270°).
    pub fn at_hour(hour: f32, max_elevation_deg: f32) -> Self {
        let t = ((hour.clamp(6.0, 18.0) - 6.0) / 12.0).clamp(0.0, 1.0);
        let el = max_elevation_deg * (std::f32::consts::PI * t).sin();
        Self::daylight(90.0 + 180.0 * t, el)
    }

    /// The default sun colour, sky and ground with the sun at the given azimuth (degrees from
    /// +Z towards +X) and elevation (degrees above the horizon).
    pub fn with_sun(azimuth_deg: f32, elevation_deg: f32) -> Self {
        Self {
            sun_dir: sun_direction(azimuth_deg, elevation_deg),
            sun: Vec3::new(1.0, 0.95, 0.85),
            sky: Vec3::new(0.32, 0.38, 0.48),
            ground: Vec3::new(0.10, 0.09, 0.07),
            exposure: 1.0,
        }
    }

    /// Check every value: a unit-length sun direction (within 1e-3), finite non-negative
    /// colours and a finite positive exposure. The error names the bad one.
    pub fn validate(&self) -> Result<(), String> {
        if !(self.sun_dir.is_finite() && (self.sun_dir.length() - 1.0).abs() < 1e-3) {
            return Err(format!(
                "sun direction {} is not a unit vector",
                self.sun_dir
            ));
        }
        for (name, c) in [
            ("sun", self.sun),
            ("sky", self.sky),
            ("ground", self.ground),
        ] {
            if !(c.is_finite() && c.min_element() >= 0.0) {
                return Err(format!("{name} colour {c} must be finite and non-negative"));
            }
        }
        if !(self.exposure.is_finite() && self.exposure > 0.0) {
            return Err(format!(
                "exposure {} must be finite and positive",
                self.exposure
            ));
        }
        Ok(())
    }

    /// Outgoing radiance (linear RGB) of a point: see the module documentation.
    pub fn shade(
        &self,
        albedo: Vec3,
        n: Vec3,
        sun_visibility: f32,
        sky_visibility: f32,
        translucency: f32,
    ) -> Vec3 {
        let ndl = n.dot(self.sun_dir);
        let direct = ndl.max(0.0) + translucency * (-ndl).max(0.0);
        let hemi = 0.5 + 0.5 * n.y;
        let ambient = (self.sky * hemi + self.ground * (1.0 - hemi)) * sky_visibility;
        albedo * (ambient + self.sun * (sun_visibility * direct)) * self.exposure
    }

    /// [`Self::shade`] of a [`Surface`] (object-space normal turned into world space by a
    /// rotation of `rotation` radians about +Y, the instance's).
    pub fn shade_surface(&self, s: &Surface, rotation: f32, sun_visibility: f32) -> Vec3 {
        let n = glam::Quat::from_rotation_y(rotation) * s.normal;
        self.shade(
            s.albedo,
            n,
            sun_visibility,
            s.sky_visibility,
            s.translucency,
        )
    }
}

/// What a surface point gives the shading model, as the bake stores it per slab texel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// Linear albedo.
    pub albedo: Vec3,
    /// Unit normal (object space), turned towards the viewer.
    pub normal: Vec3,
    /// Sky visibility `S ∈ [0,1]`.
    pub sky_visibility: f32,
    /// Translucency `τ ∈ [0,1]`.
    pub translucency: f32,
}

/// Hemispherical octahedral encoding (Meyer et al. 2010, the upper half) of a unit vector `n`
/// with `n.z ≥ 0` (given in a frame whose +Z is the hemisphere's pole) into `[0,1]²`: the
/// hemisphere folded onto `|x| + |y| + z = 1`, the diamond turned by 45° to fill the square.
/// Continuous everywhere, so filtered codes decode to blends of their normals. Vectors with
/// `z < 0` are first mirrored into the hemisphere. Inverse: [`hemi_oct_decode`]; the WGSL
/// mirror is `hemi_oct_decode` in the draw shaders.
pub fn hemi_oct_encode(n: Vec3) -> glam::Vec2 {
    let n = Vec3::new(n.x, n.y, n.z.abs());
    let p = glam::Vec2::new(n.x, n.y) / (n.x.abs() + n.y.abs() + n.z).max(f32::MIN_POSITIVE);
    glam::Vec2::new(p.x + p.y, p.x - p.y) * 0.5 + 0.5
}

/// Unit vector (`z ≥ 0`) of a hemispherical octahedral code `e ∈ [0,1]²` (see
/// [`hemi_oct_encode`]).
pub fn hemi_oct_decode(e: glam::Vec2) -> Vec3 {
    let a = e * 2.0 - 1.0;
    let p = glam::Vec2::new(a.x + a.y, a.x - a.y) * 0.5;
    Vec3::new(p.x, p.y, (1.0 - p.x.abs() - p.y.abs()).max(0.0)).normalize_or(Vec3::Z)
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
    fn daylight_reddens_and_dims_as_the_sun_sinks() {
        let noon = Lighting::daylight(180.0, 60.0);
        let low = Lighting::daylight(250.0, 8.0);
        assert!(noon.validate().is_ok() && low.validate().is_ok());
        // Near the default light at 55°.
        let d = Lighting::daylight(30.0, 55.0);
        assert!(
            (d.sun - Lighting::default().sun).abs().max_element() < 0.08,
            "{}",
            d.sun
        );
        assert!(
            (d.sky - Lighting::default().sky).abs().max_element() < 0.02,
            "{}",
            d.sky
        );
        // Low sun: dimmer, and red over blue far more than at noon.
        assert!(low.sun.length() < noon.sun.length());
        assert!(low.sun.x / low.sun.z > 2.0 * noon.sun.x / noon.sun.z);
        assert!(low.sky.length() < noon.sky.length());
        // The hours: sunrise east, noon south at the given height, sunset west.
        let rise = Lighting::at_hour(6.0, 65.0).sun_dir;
        assert!(rise.x > 0.99 && rise.y > 0.0 && rise.y < 0.01, "{rise}");
        let n = Lighting::at_hour(12.0, 65.0).sun_dir;
        assert!(
            (n.y - 65f32.to_radians().sin()).abs() < 1e-4 && n.z < 0.0,
            "{n}"
        );
        assert!(Lighting::at_hour(18.0, 65.0).sun_dir.x < -0.99);
    }

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
        assert!((l.shade(white, Vec3::Y, 1.0, 1.0, 0.0) - (l.sky + l.sun)).length() < 1e-6);
        // Shadowed: sky only; with the sky hidden, black.
        assert!((l.shade(white, Vec3::Y, 0.0, 1.0, 0.0) - l.sky).length() < 1e-6);
        assert_eq!(l.shade(white, Vec3::Y, 0.0, 0.0, 0.0), Vec3::ZERO);
        // Facing away: ground only, plus translucency of the sun.
        let back = l.shade(white, -Vec3::Y, 1.0, 1.0, 0.5);
        assert!((back - (l.ground + l.sun * 0.5)).length() < 1e-6);
        // Sideways: half sky, half ground, no direct sun; a quarter of the sky seen.
        let side = l.shade(white, Vec3::X, 1.0, 0.25, 0.0);
        assert!((side - (l.sky + l.ground) * 0.125).length() < 1e-6);
        // Exposure scales everything.
        let e = Lighting { exposure: 2.0, ..l };
        assert!((e.shade(white, Vec3::Y, 1.0, 1.0, 0.0) - (l.sky + l.sun) * 2.0).length() < 1e-6);
        // A rotated instance turns its normal, not the sun: a +X normal of an instance turned
        // by 90° about +Y faces −Z, the sun of azimuth 180°.
        let south = Lighting::with_sun(180.0, 0.0);
        let s = Surface {
            albedo: white,
            normal: Vec3::X,
            sky_visibility: 0.0,
            translucency: 0.0,
        };
        let lit = south.shade_surface(&s, std::f32::consts::FRAC_PI_2, 1.0);
        assert!((lit - south.sun).length() < 1e-5, "{lit}");
        assert_eq!(
            south.shade_surface(&s, -std::f32::consts::FRAC_PI_2, 1.0),
            Vec3::ZERO
        );
    }

    #[test]
    fn hemispherical_octahedral_codes_round_trip() {
        for i in 0..200 {
            let t = i as f32 * 0.7;
            let n = Vec3::new(
                t.sin() * (t * 0.3).cos(),
                (t * 1.3).cos(),
                (t * 0.3).sin().abs(),
            )
            .normalize();
            let e = hemi_oct_encode(n);
            assert!(e.min_element() >= 0.0 && e.max_element() <= 1.0);
            assert!((hemi_oct_decode(e) - n).length() < 1e-5, "{n}");
            // 8 bits per component keeps it within about a degree.
            let q = (e * 255.0).round() / 255.0;
            assert!(hemi_oct_decode(q).dot(n) > 0.999, "{n}");
        }
        for n in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z] {
            assert!(
                (hemi_oct_decode(hemi_oct_encode(n)) - n).length() < 1e-6,
                "{n}"
            );
        }
        // The code is continuous: the midpoint of two codes decodes between their normals.
        let (a, b) = (
            Vec3::new(0.9, 0.0, 0.1).normalize(),
            Vec3::new(0.0, 0.9, 0.1).normalize(),
        );
        let m = hemi_oct_decode((hemi_oct_encode(a) + hemi_oct_encode(b)) * 0.5);
        assert!(m.dot(a) > 0.5 && m.dot(b) > 0.5, "{m}");
    }

    #[test]
    fn lighting_validation_names_the_bad_value() {
        assert!(Lighting::default().validate().is_ok());
        let bad = Lighting {
            exposure: 0.0,
            ..Default::default()
        };
        assert!(bad.validate().unwrap_err().contains("exposure"));
        let bad = Lighting {
            sun_dir: Vec3::new(0.0, 2.0, 0.0),
            ..Default::default()
        };
        assert!(bad.validate().unwrap_err().contains("sun direction"));
        let bad = Lighting {
            sky: Vec3::new(f32::NAN, 0.0, 0.0),
            ..Default::default()
        };
        assert!(bad.validate().unwrap_err().contains("sky"));
    }
}
