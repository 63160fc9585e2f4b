//! The hybrid method: the trees next to the camera as geometry (any mesh method, full geometry
//! by default), the rest as the quad stream — the quad stream loses close up, where its finest
//! quads are magnified past ε, and the triangle methods lose far away and in frame time.
//!
//! Each tree's form is decided on the GPU every frame, in both cull passes, from the camera's
//! `forms` vector ([`forest_render::extend`]: the share, the band, the screen-door masks).
//! [`Hybrid::forms`] turns the parameters into that vector for a camera.
//!
//! Composition (see `methods::ForestRenderer`): both forms' compute passes, then one render
//! pass: the ground, the geometry (opaque, alpha-tested, depth written, nearest bands first),
//! then the quads back to front, depth-tested against it. A tree's quads are never emitted
//! while it is drawn as geometry alone.

use forest_render::camera::Camera;
use forest_render::extend::{FORMS_GEOMETRY, GEOMETRY_ALWAYS};
use forest_render::options::StreamOptions;

use crate::geometry::MeshMethod;
use forest_render::context::RenderError;

/// Where the near trees end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Near {
    /// Per species, where its quad stream becomes as accurate as its own triangles (within
    /// the tolerance the bake measured it at, [`forest_format::atlas::HybridSwitch::tolerance`]):
    /// the distance at which the species' finest quads project to the size its atlas records
    /// ([`forest_format::atlas::HybridSwitch`], measured by `forest bake` against a 4×4
    /// supersampled reference), else to [`forest_render::DEFAULT_SWITCH_PIXELS`]. It follows
    /// the tree's size, the viewport and the field of view ([`forest_render::extend::switch_unit`]);
    /// ε does not move it: a coarser ε makes the near trees' quads coarser still, not better (an
    /// ε-scaled switch left the hybrid at ε 8–32 less accurate than the discrete LODs at the
    /// same time). Measured on the five bundled species (400×300, 60°, ε 2) the crossover lies
    /// between 2.5 (pine) and 6 (oak, ash, bush: the ladder's end) crown radii, 1.3 to 3.5 with a
    /// 25 % tolerance: a single switch for every species
    /// draws some trees in their less accurate form.
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
    /// Aspect sharpening of the trees drawn as quads, in units of
    /// 1/[`forest_render::gpu_types::WEIGHT_ONE`] (0 to
    /// [`forest_render::options::SHARPEN_MAX`]): it replaces the stream's own
    /// ([`forest_render::options::StreamOptions::sharpen`]) while the hybrid draws. Default
    /// [`HYBRID_SHARPEN_DEFAULT`]: the hybrid's quads are trees beyond its switch, where a
    /// faint third aspect adds a layer of fragments and little to the image.
    pub sharpen: u32,
}

/// Default [`Hybrid::sharpen`]: 20 % of a weight of one, against the stream's 10 %
/// ([`forest_render::options::SHARPEN_DEFAULT`]). Chosen by the measurements under "The
/// hybrid's aspect sharpening" in docs/overdraw.md.
pub const HYBRID_SHARPEN_DEFAULT: u32 = 819;

impl Default for Hybrid {
    fn default() -> Self {
        Self {
            near: Near::Auto,
            band: 0.25,
            jitter: 0.25,
            near_form: MeshMethod::Full { depth_sort: true },
            sharpen: HYBRID_SHARPEN_DEFAULT,
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
        StreamOptions {
            sharpen: self.sharpen,
            ..Default::default()
        }
        .validate()
        .map_err(|e| RenderError::Parameter(format!("the hybrid's quads: {e}")))?;
        self.near_form.validate()
    }

    /// The camera's `forms` for a frame of `camera`: in [`Near::Auto`] its focal length in
    /// pixels, which each tree's switch unit turns into its switch distance.
    pub fn forms(&self, camera: &Camera) -> [f32; 4] {
        self.forms_for_focal(camera.focal_pixels())
    }

    /// [`Self::forms`] for a camera of focal length `focal_pixels` (a host's projection:
    /// [`forest_render::FrameParams::focal_pixels`]).
    pub fn forms_for_focal(&self, focal_pixels: f32) -> [f32; 4] {
        match self.near {
            Near::Auto => [0.0, focal_pixels, self.band, self.jitter],
            Near::Metres(m) if m >= GEOMETRY_ALWAYS => FORMS_GEOMETRY,
            Near::Metres(m) => [m, 0.0, self.band, self.jitter],
        }
    }
}

/// [`Near::Auto`]'s switch distance in crown radii for a species of `levels` hierarchy
/// levels whose finest quads switch at `pixels` pixels: `2 · focal / (2^(levels−1) · pixels)`.
pub fn auto_radii(camera: &Camera, levels: u32, pixels: f32) -> f32 {
    let finest = (1u64 << levels.clamp(1, 32).saturating_sub(1)) as f32;
    2.0 * camera.focal_pixels() / (finest * pixels)
}

#[cfg(test)]
mod tests {
    use super::*;
    use forest_render::DEFAULT_SWITCH_PIXELS;
    use forest_render::options::SHARPEN_MAX;
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

    /// A manifest of the default bake (8 levels) of a crown of radius `r` metres.
    fn manifest(r: f32, switch: Option<f32>) -> forest_format::AtlasManifest {
        let params = forest_format::BakeParams::default();
        let mut m = forest_format::atlas::manifest_for(
            params,
            forest_format::atlas::SourceInfo {
                file: "tree.obj".into(),
                hash: "0".into(),
                triangles: 1,
                degenerate_triangles: 0,
                materials: Vec::new(),
                top: None,
                foot: None,
            },
            forest_format::slab::Sphere {
                center: Vec3::ZERO,
                radius: r,
            },
            vec![None; params.layers() as usize],
            vec![0; params.levels() as usize],
        );
        m.hybrid_switch = switch.map(|p| forest_format::atlas::HybridSwitch {
            finest_quad_pixels: p,
            crown_radii: 0.0,
            viewport: [400, 300],
            fov_y_deg: 60.0,
            epsilon: 2.0,
            cameras: 1,
            tolerance: 0.0,
            lod_from: [None; 2],
            never_reached: false,
        });
        m
    }

    #[test]
    fn auto_switch_is_where_the_finest_quads_project_to_the_recorded_pixels() {
        let c = cam(2.0);
        for (recorded, pixels) in [(None, DEFAULT_SWITCH_PIXELS), (Some(2.25), 2.25)] {
            let m = manifest(5.0, recorded);
            assert_eq!(m.levels, 8);
            let unit = forest_render::extend::switch_unit(&m);
            // A tree of scale 2: crown radius 10 m, finest quads 20/128 m wide.
            let forms = Hybrid::default().forms(&c);
            let s = forms[0] + forms[1] * unit * 2.0;
            let px = (20.0 / 128.0) * c.focal_pixels() / s;
            assert!((px - pixels).abs() < 1e-4, "{px} against {pixels}");
            assert!((s / 10.0 - auto_radii(&c, 8, pixels)).abs() < 1e-4);
            // ε does not move it; the viewport does.
            for e in [0.5, 1.0, 4.0, 32.0] {
                assert_eq!(Hybrid::default().forms(&cam(e)), forms);
            }
            let mut wide = c;
            wide.viewport = (800, 600);
            assert!((Hybrid::default().forms(&wide)[1] - 2.0 * forms[1]).abs() < 1e-3);
        }
        // 400×300 at 60°: focal 259.8 px, so by default 2·259.8/(128·1.5) ≈ 2.71 crown radii.
        let k = auto_radii(&c, 8, DEFAULT_SWITCH_PIXELS);
        assert!((k - 2.0 * 259.8076 / (128.0 * 1.5)).abs() < 1e-3, "{k}");
        assert!((auto_radii(&c, 9, DEFAULT_SWITCH_PIXELS) - k / 2.0).abs() < 1e-5);
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
        let h = Hybrid {
            sharpen: SHARPEN_MAX + 1,
            ..Default::default()
        };
        let e = h.validate().unwrap_err().to_string();
        assert!(e.contains("hybrid") && e.contains("sharpening"), "{e}");
        assert!(Hybrid::default().validate().is_ok());
        let inf = Hybrid {
            near: Near::Metres(f32::INFINITY),
            ..Default::default()
        };
        assert_eq!(inf.forms(&cam(1.0)), FORMS_GEOMETRY);
    }
}
