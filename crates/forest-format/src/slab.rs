//! Where a slab pixel lies in object space.
//!
//! A sampling direction `dir` (unit, pointing from the model towards the orthographic sampling
//! camera) has a frame `(right, up, dir)` with `right × up = dir`. Its slab images frame the
//! model's bounding sphere (centre `c`, radius `R`): image coordinate `u ∈ [0,1]` runs along
//! `right` from `−R` to `+R`, `v ∈ [0,1]` (downwards) along `up` from `+R` to `−R`. Sphere depth
//! `d ∈ [0,1]` runs along `−dir` from `+R` (`d = 0`, nearest the camera) to `−R` (`d = 1`).
//! Slab `s` of `S` keeps the hits with `d ∈ [s/S, (s+1)/S)`; a node stores depth relative to its
//! slab, `t = d·S − s ∈ [0,1]`.

use glam::Vec3;
use serde::{Deserialize, Serialize};

/// A sampling direction with its image frame, all unit vectors in the model's object space.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DirectionFrame {
    /// Towards the sampling camera.
    pub dir: Vec3,
    /// Image x axis.
    pub right: Vec3,
    /// Image up axis (image y runs the opposite way).
    pub up: Vec3,
}

impl DirectionFrame {
    /// The frame of a unit direction: `right` is horizontal (perpendicular to +Y) unless the
    /// direction is within ~0.06° of vertical, where `right` is +X.
    pub fn new(dir: Vec3) -> Self {
        let dir = dir.normalize();
        let right = if dir.y.abs() > 0.999_999 {
            Vec3::X
        } else {
            Vec3::Y.cross(dir).normalize()
        };
        let up = dir.cross(right);
        Self { dir, right, up }
    }
}

/// The bounding sphere that every slab image of an atlas frames.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sphere {
    /// Centre in object space (metres).
    pub center: Vec3,
    /// Radius in metres (> 0).
    pub radius: f32,
}

impl Sphere {
    /// Object-space point at image coordinates `(u, v)` (each in `[0,1]`) and sphere depth `d`.
    pub fn image_to_object(&self, frame: &DirectionFrame, u: f32, v: f32, d: f32) -> Vec3 {
        let r = self.radius;
        self.center
            + frame.right * ((2.0 * u - 1.0) * r)
            + frame.up * ((1.0 - 2.0 * v) * r)
            + frame.dir * ((1.0 - 2.0 * d) * r)
    }

    /// Image coordinates `(u, v)` and sphere depth `d` of an object-space point (inverse of
    /// [`Self::image_to_object`]).
    pub fn object_to_image(&self, frame: &DirectionFrame, p: Vec3) -> (f32, f32, f32) {
        let q = (p - self.center) / self.radius;
        (
            0.5 + 0.5 * q.dot(frame.right),
            0.5 - 0.5 * q.dot(frame.up),
            0.5 - 0.5 * q.dot(frame.dir),
        )
    }
}

/// Sphere depth `d` of slab-relative depth `t` in slab `slab` of `slabs`.
pub fn slab_to_sphere_depth(t: f32, slab: u32, slabs: u32) -> f32 {
    (slab as f32 + t) / slabs as f32
}

/// Slab-relative depth of sphere depth `d` in slab `slab` of `slabs` (not clamped).
pub fn sphere_to_slab_depth(d: f32, slab: u32, slabs: u32) -> f32 {
    d * slabs as f32 - slab as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal_and_right_handed() {
        for dir in [
            Vec3::Y,
            Vec3::X,
            Vec3::new(0.3, 0.5, -0.8),
            Vec3::new(0.0, 1.0, 1e-9),
        ] {
            let f = DirectionFrame::new(dir);
            assert!((f.right.length() - 1.0).abs() < 1e-6);
            assert!((f.up.length() - 1.0).abs() < 1e-6);
            assert!(f.right.dot(f.up).abs() < 1e-6);
            assert!((f.right.cross(f.up) - f.dir).length() < 1e-6);
        }
    }

    #[test]
    fn image_mapping_round_trips() {
        let s = Sphere {
            center: Vec3::new(1.0, 5.0, -2.0),
            radius: 4.0,
        };
        let f = DirectionFrame::new(Vec3::new(0.2, 0.7, 0.4));
        let p = s.image_to_object(&f, 0.25, 0.75, 0.1);
        let (u, v, d) = s.object_to_image(&f, p);
        assert!((u - 0.25).abs() < 1e-6 && (v - 0.75).abs() < 1e-6 && (d - 0.1).abs() < 1e-6);
        // The image centre at depth 0 is the point of the sphere nearest the camera.
        let front = s.image_to_object(&f, 0.5, 0.5, 0.0);
        assert!((front - (s.center + f.dir * 4.0)).length() < 1e-5);
        assert_eq!(slab_to_sphere_depth(0.5, 1, 2), 0.75);
        assert_eq!(sphere_to_slab_depth(0.75, 1, 2), 0.5);
    }
}
