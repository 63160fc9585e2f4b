//! The hybrid method: the trees next to the camera as geometry (any mesh method, full geometry
//! by default), the rest as the quad stream — the quad stream loses close up, where its finest
//! quads are magnified past ε, and the triangle methods lose far away and in frame time.
//!
//! Each tree's form is decided on the GPU every frame, in both cull passes, from the camera's
//! `forms` vector ([`forest_render::forms`]: the share, the band, the screen-door masks).
//! [`Hybrid::forms`] turns the parameters into that vector for a camera.
//!
//! Composition (see `methods::ForestRenderer`): both forms' compute passes, then one render
//! pass: the ground, the geometry (opaque, alpha-tested, depth written, nearest bands first),
//! then the quads back to front, depth-tested against it. A tree's quads are never emitted
//! while it is drawn as geometry alone.

use forest_render::camera::Camera;
use forest_render::forms::{FORMS_GEOMETRY, GEOMETRY_ALWAYS};

use crate::geometry::MeshMethod;
use forest_render::context::RenderError;

/// [`Near::Auto`] switches where a tree's finest quads project this many pixels: nearer, the
/// quad stream is less accurate than full geometry at 1× at every ε.
pub const AUTO_MIN_PIXELS: f32 = 1.5;

/// Where the near trees end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Near {
    /// Where the quad stream, out of levels, becomes less accurate than the tree's own
    /// triangles: the distance below which a tree's finest quads project longer than
    /// [`AUTO_MIN_PIXELS`], `2 R · focal / (2^(levels−1) · 1.5)` for a crown of radius `R` (it
    /// follows the tree's size, the viewport and the field of view; 2.7 crown radii at
    /// 400×300 and 60° with 8 levels). Measured on the bundled oak, pine and aspen (400×300,
    /// 60°, 8 levels), the quad stream's FLIP against the 4×4 reference falls below that of
    /// full geometry at 1× beyond 3, 2 and 2.2 crown radii: where the finest quads project
    /// 1.35–2 px. Re-measured for all five bundled species (`scripts/crossover.py`, against
    /// the quad stream at ε 2) the crossover lies at 1.8 (pine) to 3.0 (oak, ash) crown
    /// radii, median 2.5: one switch for every species is a compromise that a per-species
    /// switch would remove. ε does not move the switch: a coarser ε makes the near trees' quads
    /// coarser still, not better, and the walkthrough's error is theirs (an ε-scaled switch,
    /// 2.7 radii / max(ε/1.5, 1), left the hybrid at ε 8–32 less accurate than the discrete
    /// LODs at the same time).
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
            return Err(RenderError::Parameter(format!(
                "the hybrid's switch distance {m} m must be 0 or more"
            )));
        }
        for (name, v) in [("band", self.band), ("jitter", self.jitter)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(RenderError::Parameter(format!(
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
/// `levels` levels, `2R / 2^(levels−1)` wide, project to [`AUTO_MIN_PIXELS`] pixels.
pub fn auto_radii(camera: &Camera, levels: u32) -> f32 {
    let finest = (1u64 << levels.clamp(1, 32).saturating_sub(1)) as f32;
    2.0 * camera.focal_pixels() / (finest * AUTO_MIN_PIXELS)
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
    fn auto_switch_is_where_the_finest_quads_project_to_one_and_a_half_pixels() {
        let c = cam(2.0);
        let k = auto_radii(&c, 8);
        // A crown of radius 5 m: finest quads 10/128 m wide, seen from k·5 m away.
        let px = (10.0 / 128.0) * c.focal_pixels() / (k * 5.0);
        assert!((px - AUTO_MIN_PIXELS).abs() < 1e-4, "{px}");
        // 400×300 at 60°: focal 259.8 px, so 2·259.8/(128·1.5) ≈ 2.71 crown radii.
        assert!((k - 2.0 * 259.8076 / (128.0 * 1.5)).abs() < 1e-3, "{k}");
        // ε does not move it; the viewport and the levels do.
        for e in [0.5, 1.0, 4.0, 32.0] {
            assert_eq!(auto_radii(&cam(e), 8), k);
        }
        assert!((auto_radii(&c, 9) - k / 2.0).abs() < 1e-5);
        let mut wide = c;
        wide.viewport = (800, 600);
        assert!((auto_radii(&wide, 8) - 2.0 * k).abs() < 1e-4);
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
