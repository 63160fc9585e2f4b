//! The hybrid method: the trees next to the camera as geometry (any mesh method, full geometry
//! by default), the rest as the quad stream — the quad stream loses close up, where its finest
//! quads are magnified past ε, and the triangle methods lose far away and in frame time.
//!
//! Each tree's form is decided on the GPU every frame, in both cull passes, from the camera's
//! `forms` vector (the camera stays the only per-frame upload): [`quad_share`] gives the
//! quad stream's share of the tree, 0 (geometry alone) nearer than the tree's switch distance,
//! [`WEIGHT_ONE`] (quads alone) past its transition band, and in between the fraction of the
//! tree's pixels the quads draw. Inside the band both forms draw the tree through
//! complementary screen-door masks ([`form_threshold`]), so every pixel comes from exactly one
//! of them and nothing pops; the band's start is jittered per instance so that a ring of trees
//! at one distance does not change form in the same frame.
//!
//! Composition (see `methods::ForestRenderer`): both forms' compute passes, then one render
//! pass: the ground, the geometry (opaque, alpha-tested, depth written, nearest bands first),
//! then the quads back to front, depth-tested against it. A tree's quads are never emitted
//! while it is drawn as geometry alone.

use crate::camera::Camera;
use crate::context::RenderError;
use crate::geometry::MeshMethod;
use crate::gpu_types::WEIGHT_ONE;

/// `forms` of the quad stream on its own: every tree as quads.
pub const FORMS_QUADS: [f32; 4] = [0.0; 4];
/// `forms` of a geometry method on its own: every tree as geometry.
pub const FORMS_GEOMETRY: [f32; 4] = [f32::MAX, 0.0, 0.0, 0.0];
/// [`Near::Auto`] switches where the finest quads project longer than ε, but never below
/// this many pixels: nearer than that the quad stream is as accurate as full geometry at 1×.
pub const AUTO_MIN_PIXELS: f32 = 1.5;
/// A switch distance at or past this (metres) draws every tree as geometry (`common.wgsl`).
pub const GEOMETRY_ALWAYS: f32 = 3.0e38;

/// Where the near trees end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Near {
    /// Where the quad stream's error exceeds ε because it has run out of levels: the distance
    /// below which a tree's finest quads project longer than `max(ε, AUTO_MIN_PIXELS)`
    /// pixels, `2 R · focal / (2^(levels−1) · max(ε, 1.5))` for a crown of radius `R` (it
    /// follows the tree's size, the viewport, the field of view and ε). Measured on the
    /// bundled oak, pine and aspen (400×300, 60°, 8 levels, ε 1 and 2 alike, since the stream
    /// is out of levels there), the quad stream's FLIP against the 4×4 reference falls below
    /// that of full geometry at 1× beyond 3, 2 and 2.2 crown radii: where the finest quads
    /// project 1.35–2 px. At 400×300 the switch is 2.7 crown radii for ε ≤ 1.5, 2 at ε = 2,
    /// 1 at ε = 4.
    Auto,
    /// A fixed distance in metres from the eye to a tree's bounding-sphere centre: 0 draws
    /// every tree as quads, infinity every tree as geometry.
    Metres(f32),
}

/// Parameters of the hybrid method.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hybrid {
    /// The switch distance.
    pub near: Near,
    /// Width of the transition band as a fraction of the switch distance (≥ 0; 0: a hard
    /// switch).
    pub band: f32,
    /// The band's start is moved out by up to this fraction of the switch distance, per
    /// instance (≥ 0).
    pub jitter: f32,
    /// How the near trees are drawn.
    pub near_form: MeshMethod,
}

impl Default for Hybrid {
    fn default() -> Self {
        Self {
            near: Near::Auto,
            band: 0.25,
            jitter: 0.25,
            near_form: MeshMethod::Full { depth_sort: true },
        }
    }
}

impl Hybrid {
    /// Check the parameters; the error names the bad one.
    pub fn validate(&self) -> Result<(), RenderError> {
        if let Near::Metres(m) = self.near
            && (m.is_nan() || m < 0.0)
        {
            return Err(RenderError::Scene(format!(
                "the hybrid's switch distance {m} m must be 0 or more"
            )));
        }
        for (name, v) in [("band", self.band), ("jitter", self.jitter)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(RenderError::Scene(format!(
                    "the hybrid's {name} {v} must be a fraction of 0 or more"
                )));
            }
        }
        self.near_form.validate()
    }

    /// The camera's `forms` for a frame of `camera` over a scene whose coarsest species has
    /// `levels` hierarchy levels (its finest quads are the largest).
    pub fn forms(&self, camera: &Camera, levels: u32) -> [f32; 4] {
        match self.near {
            Near::Auto => [0.0, auto_radii(camera, levels), self.band, self.jitter],
            Near::Metres(m) if m >= GEOMETRY_ALWAYS => FORMS_GEOMETRY,
            Near::Metres(m) => [m, 0.0, self.band, self.jitter],
        }
    }
}

/// [`Near::Auto`]'s switch distance in crown radii: where the finest quads of a hierarchy of
/// `levels` levels, `2R / 2^(levels−1)` wide, project to `max(ε, AUTO_MIN_PIXELS)` pixels.
pub fn auto_radii(camera: &Camera, levels: u32) -> f32 {
    let finest = (1u64 << levels.clamp(1, 32).saturating_sub(1)) as f32;
    2.0 * camera.focal_pixels() / (finest * camera.epsilon.max(AUTO_MIN_PIXELS))
}

/// A per-instance number in `[0, 1)` (`instance_hash` in `shaders/common.wgsl`).
pub fn instance_hash(instance: u32) -> f32 {
    let mut h = instance
        .wrapping_mul(747_796_405)
        .wrapping_add(2_891_336_453);
    h = ((h >> ((h >> 28) + 4)) ^ h).wrapping_mul(277_803_737);
    (h >> 8) as f32 / 16_777_216.0
}

/// The quad stream's share of a tree, in units of 1/[`WEIGHT_ONE`] (`quad_share` in
/// `shaders/common.wgsl`, the same operations in the same order): 0 while the eye is nearer
/// than the tree's switch distance `s = forms.x + forms.y · radius`, [`WEIGHT_ONE`] past its
/// band `[start, start · (1 + forms.z)]` with `start = s · (1 + forms.w · hash)`, linear in
/// between. `distance`: eye to the bounding-sphere centre; `radius`: the crown's (metres).
pub fn quad_share(forms: [f32; 4], distance: f32, radius: f32, instance: u32) -> u32 {
    let s = forms[0] + forms[1] * radius;
    if s <= 0.0 {
        return WEIGHT_ONE;
    }
    if s >= GEOMETRY_ALWAYS {
        return 0;
    }
    let start = s * (1.0 + forms[3] * instance_hash(instance));
    let width = start * forms[2];
    if width <= 0.0 {
        return if distance >= start { WEIGHT_ONE } else { 0 };
    }
    ((((distance - start) / width).clamp(0.0, 1.0) * 4095.0 + 0.5).floor()) as u32
}

/// Ordered-dither threshold of pixel `(x, y)` for a tree, in `[0, WEIGHT_ONE)`
/// (`dither_threshold` in `shaders/common.wgsl`).
pub fn dither_threshold(x: u32, y: u32, instance: u32) -> u32 {
    let (x, y) = (x & 7, y & 7);
    let xy = x ^ y;
    let b = ((xy & 1) << 5)
        | ((y & 1) << 4)
        | ((xy & 2) << 2)
        | ((y & 2) << 1)
        | ((xy & 4) >> 1)
        | ((y & 4) >> 2);
    let u = ((b as f32 + 0.5) / 64.0 + instance_hash(instance)).fract();
    ((u * WEIGHT_ONE as f32) as u32).min(WEIGHT_ONE - 1)
}

/// The screen-door threshold that splits a tree in its band between the forms
/// (`form_threshold` in `shaders/common.wgsl`): the quads draw pixel `(x, y)` when it is below
/// the tree's [`quad_share`], the geometry otherwise.
pub fn form_threshold(x: u32, y: u32, instance: u32) -> u32 {
    dither_threshold(y, x, instance ^ 0x5bd1_e995)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn cam(epsilon: f32) -> Camera {
        Camera {
            eye: Vec3::new(0.0, 2.0, 10.0),
            target: Vec3::new(0.0, 2.0, 0.0),
            fov_y_deg: 60.0,
            near: 0.1,
            far: 100.0,
            viewport: (400, 300),
            epsilon,
        }
    }

    #[test]
    fn auto_switch_is_where_the_finest_quads_project_to_epsilon() {
        let c = cam(2.0);
        let k = auto_radii(&c, 8);
        // A crown of radius 5 m: finest quads 10/128 m wide, seen from k·5 m away.
        let px = (10.0 / 128.0) * c.focal_pixels() / (k * 5.0);
        assert!((px - 2.0).abs() < 1e-4, "{px}");
        // 400×300 at 60°: focal 259.8 px, so 2·259.8/(128·2) ≈ 2.03 crown radii at ε = 2.
        assert!((k - 259.8076 / 128.0).abs() < 1e-3, "{k}");
        assert!((auto_radii(&cam(4.0), 8) - k / 2.0).abs() < 1e-5);
        // Below AUTO_MIN_PIXELS, ε no longer moves the switch.
        let floor = auto_radii(&cam(AUTO_MIN_PIXELS), 8);
        assert_eq!(auto_radii(&cam(0.5), 8), floor);
        assert!((floor - k * 2.0 / AUTO_MIN_PIXELS).abs() < 1e-5);
    }

    #[test]
    fn shares_run_from_geometry_to_quads_across_the_band() {
        let forms = [10.0, 0.0, 0.5, 0.0];
        assert_eq!(quad_share(forms, 9.99, 3.0, 7), 0);
        assert_eq!(quad_share(forms, 12.5, 3.0, 7), WEIGHT_ONE / 2 + 1);
        assert_eq!(quad_share(forms, 15.0, 3.0, 7), WEIGHT_ONE);
        assert_eq!(quad_share(FORMS_QUADS, 0.0, 3.0, 7), WEIGHT_ONE);
        assert_eq!(quad_share(FORMS_GEOMETRY, 1e30, 3.0, 7), 0);
        // Crown radii: 2 radii of a 3 m crown.
        assert_eq!(quad_share([0.0, 2.0, 0.0, 0.0], 5.9, 3.0, 7), 0);
        assert_eq!(quad_share([0.0, 2.0, 0.0, 0.0], 6.0, 3.0, 7), WEIGHT_ONE);
    }

    #[test]
    fn jitter_spreads_the_band_start_over_instances() {
        let forms = [10.0, 0.0, 0.0, 0.5];
        let starts: Vec<f32> = (0..1000)
            .map(|i| 10.0 * (1.0 + 0.5 * instance_hash(i)))
            .collect();
        assert!(starts.iter().all(|s| (10.0..15.0).contains(s)));
        // At 12.5 m about half of the trees have switched.
        let quads = (0..1000)
            .filter(|&i| quad_share(forms, 12.5, 1.0, i) == WEIGHT_ONE)
            .count();
        assert!((400..600).contains(&quads), "{quads}");
    }

    #[test]
    fn the_forms_split_every_pixel_and_cover_their_share() {
        for share in [0, 1, 1000, 2048, 4000, WEIGHT_ONE] {
            for inst in [0, 1, 99] {
                let mut quads = 0;
                for y in 0..8 {
                    for x in 0..8 {
                        let t = form_threshold(x, y, inst);
                        assert!(t < WEIGHT_ONE);
                        // The quads draw the pixel, or the geometry does: never both, never none.
                        quads += u32::from(t < share);
                    }
                }
                let want = share as f32 / WEIGHT_ONE as f32 * 64.0;
                assert!(
                    (quads as f32 - want).abs() <= 1.0,
                    "share {share}: {quads}/64"
                );
            }
        }
    }

    #[test]
    fn bad_parameters_are_named() {
        let h = Hybrid {
            near: Near::Metres(-1.0),
            ..Default::default()
        };
        assert!(h.validate().unwrap_err().to_string().contains("switch"));
        let h = Hybrid {
            band: f32::NAN,
            ..Default::default()
        };
        assert!(h.validate().unwrap_err().to_string().contains("band"));
        assert!(Hybrid::default().validate().is_ok());
        let inf = Hybrid {
            near: Near::Metres(f32::INFINITY),
            ..Default::default()
        };
        assert_eq!(inf.forms(&cam(1.0), 8), FORMS_GEOMETRY);
    }
}
