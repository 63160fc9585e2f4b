//! A perspective camera and its GPU form (the only per-frame upload).

#[cfg(test)]
use glam::Vec4;
use glam::{Mat4, Vec3};

use crate::gpu_types::GpuCamera;

/// A perspective camera looking from `eye` towards `target`, +Y up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position (world, metres).
    pub eye: Vec3,
    /// A point the camera looks at.
    pub target: Vec3,
    /// Vertical field of view in degrees (0 < fov < 180).
    pub fov_y_deg: f32,
    /// Near plane distance (> 0).
    pub near: f32,
    /// Far plane distance (> near).
    pub far: f32,
    /// Viewport size in pixels.
    pub viewport: (u32, u32),
    /// Refinement threshold ε: a quad is refined while a projected edge is longer (pixels).
    pub epsilon: f32,
}

/// The farthest an eye or target may be from the origin on any axis (metres): ten times
/// [`forest_format::forest::MAX_COORDINATE`].
pub const MAX_CAMERA_COORDINATE: f32 = 10.0 * forest_format::forest::MAX_COORDINATE;

/// Why a camera cannot be used.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("invalid camera: {0}")]
pub struct CameraError(pub String);

impl Camera {
    /// Check every field; the error names the bad one.
    pub fn validate(&self) -> Result<(), CameraError> {
        let bad = |s: String| Err(CameraError(s));
        if !(self.eye.is_finite() && self.target.is_finite()) {
            return bad("eye and target must be finite".into());
        }
        for (what, p) in [("eye", self.eye), ("target", self.target)] {
            if p.abs().max_element() > MAX_CAMERA_COORDINATE {
                return bad(format!(
                    "{what} {p} lies beyond ±{MAX_CAMERA_COORDINATE:e} m (ten times the farthest \
                     a forest may reach; single-precision view matrices fail farther out)"
                ));
            }
        }
        let f = self.target - self.eye;
        if f.length_squared() < 1e-12 {
            return bad("target equals eye: no view direction".into());
        }
        if f.normalize().cross(Vec3::Y).length() < 1e-6 {
            return bad("looking straight up or down: the up vector is undefined".into());
        }
        if !(self.fov_y_deg > 0.0 && self.fov_y_deg < 180.0) {
            return bad(format!(
                "fov {} must be in (0, 180) degrees",
                self.fov_y_deg
            ));
        }
        if !(self.near > 0.0 && self.far > self.near && self.far.is_finite()) {
            return bad(format!(
                "near {} and far {} must satisfy 0 < near < far",
                self.near, self.far
            ));
        }
        if self.viewport.0 == 0 || self.viewport.1 == 0 {
            return bad(format!("viewport {:?} is empty", self.viewport));
        }
        if !(self.epsilon.is_finite() && self.epsilon > 0.0) {
            return bad(format!("epsilon {} must be positive", self.epsilon));
        }
        Ok(())
    }

    /// Focal length in pixels (vertical): a length `l` at distance `d` projects to
    /// `l · focal / d` pixels.
    pub fn focal_pixels(&self) -> f32 {
        self.viewport.1 as f32 * 0.5 / (self.fov_y_deg.to_radians() * 0.5).tan()
    }

    /// Unit view direction.
    pub fn forward(&self) -> Vec3 {
        (self.target - self.eye).normalize()
    }

    /// World → view (right-handed, +Y up).
    pub fn view(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.eye, self.target, Vec3::Y)
    }

    /// View → clip: wgpu's clip space, y up, depth 0..1 (glam's "directx" convention).
    pub fn proj(&self) -> Mat4 {
        let aspect = self.viewport.0 as f32 / self.viewport.1 as f32;
        glam::camera::rh::proj::directx::perspective(
            self.fov_y_deg.to_radians(),
            aspect,
            self.near,
            self.far,
        )
    }

    /// Projection × view.
    pub fn view_proj(&self) -> Mat4 {
        self.proj() * self.view()
    }

    /// The GPU form: matrix, eye and ε, forward, viewport, normalised frustum planes; every
    /// tree drawn as quads (renderers set `forms` for the method they draw).
    pub fn to_gpu(&self) -> GpuCamera {
        crate::frame::gpu_camera(
            self.view_proj(),
            self.eye,
            self.forward(),
            self.viewport,
            self.epsilon,
        )
    }
}

/// Write a renderer's camera uniform and count the write in `writes` (count, bytes): what
/// every renderer's `prepare` does once it has filled in its own fields.
pub fn upload(
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    camera: &GpuCamera,
    writes: &mut (u64, u64),
) {
    upload_all(queue, buffer, std::slice::from_ref(camera), writes);
}

/// [`upload`] of several cameras in one write, one after another from offset 0 (a view's
/// camera and its light views', see [`crate::shadow_maps`]).
pub fn upload_all(
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    cameras: &[GpuCamera],
    writes: &mut (u64, u64),
) {
    queue.write_buffer(buffer, 0, bytemuck::cast_slice(cameras));
    writes.0 += 1;
    writes.1 += std::mem::size_of_val(cameras) as u64;
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> Camera {
        Camera {
            eye: Vec3::new(0.0, 2.0, 10.0),
            target: Vec3::new(0.0, 2.0, 0.0),
            fov_y_deg: 60.0,
            near: 0.1,
            far: 100.0,
            viewport: (800, 600),
            epsilon: 16.0,
        }
    }

    #[test]
    fn frustum_planes_contain_what_the_camera_sees() {
        let g = cam().to_gpu();
        let inside = |p: Vec3| {
            g.planes
                .iter()
                .all(|pl| Vec4::from_array(*pl).dot(p.extend(1.0)) >= 0.0)
        };
        assert!(inside(Vec3::new(0.0, 2.0, 0.0)));
        assert!(!inside(Vec3::new(0.0, 2.0, 20.0)), "behind the eye");
        assert!(!inside(Vec3::new(50.0, 2.0, 0.0)), "far to the right");
        assert!(!inside(Vec3::new(0.0, 2.0, -200.0)), "beyond the far plane");
        // Plane distance is in metres: a point 1 m in front of the near plane.
        let near = Vec4::from_array(g.planes[4]).dot(Vec3::new(0.0, 2.0, 8.9).extend(1.0));
        assert!((near - 1.0).abs() < 1e-3, "{near}");
    }

    #[test]
    fn bad_cameras_are_named() {
        let mut c = cam();
        c.target = c.eye;
        assert!(c.validate().unwrap_err().0.contains("target"));
        let mut c = cam();
        c.target = c.eye + Vec3::Y;
        assert!(c.validate().is_err());
        let mut c = cam();
        c.epsilon = 0.0;
        assert!(c.validate().unwrap_err().0.contains("epsilon"));
        let mut c = cam();
        c.eye.x = f32::NAN;
        assert!(c.validate().is_err());
    }
}
