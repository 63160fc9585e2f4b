//! A perspective camera and its GPU form (the only per-frame upload).

use glam::{Mat4, Vec3, Vec4};

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

pub use crate::error::CameraError;

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
        gpu_camera(
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
/// camera and its light views', see `shadow_maps.rs`).
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

/// The camera uniform from its parts: matrix, eye and ε, forward, viewport, frustum planes,
/// with the default stream options (what a stream writes unless given others).
pub(crate) fn gpu_camera(
    m: Mat4,
    eye: Vec3,
    forward: Vec3,
    viewport: (u32, u32),
    epsilon: f32,
) -> GpuCamera {
    let mut g = GpuCamera {
        view_proj: m.to_cols_array_2d(),
        eye: eye.to_array(),
        epsilon,
        form_eye: eye.extend(0.0).to_array(),
        forward: forward.to_array(),
        viewport: [viewport.0 as f32, viewport.1 as f32],
        planes: frustum_planes(m),
        forms: crate::forms::FORMS_QUADS,
        ..Default::default()
    };
    crate::options::StreamOptions::default().apply(&mut g);
    g
}

/// The six frustum planes of a clip matrix (`xyz · p + w ≥ 0` inside, unit normals, metres):
/// left, right, bottom, top, and the two depth planes `z ≥ 0`, `z ≤ w`, whichever is near.
/// A plane at infinity (the far plane of an infinite projection) has no normal and becomes
/// `(0, 0, 0, 1)`: everything is inside it.
pub fn frustum_planes(m: Mat4) -> [[f32; 4]; 6] {
    let rows = [m.row(0), m.row(1), m.row(2), m.row(3)];
    [
        rows[3] + rows[0],
        rows[3] - rows[0],
        rows[3] + rows[1],
        rows[3] - rows[1],
        rows[2],
        rows[3] - rows[2],
    ]
    .map(|p: Vec4| {
        let n = p.truncate().length();
        if n > 1e-12 * p.w.abs().max(1.0) {
            (p / n).to_array()
        } else {
            [0.0, 0.0, 0.0, 1.0]
        }
    })
}

/// The camera uniform a stream holds before its first [`FrameParams`]: every plane rejects
/// everything, so a frame encoded before the first `prepare` draws nothing.
pub(crate) fn nothing_visible() -> GpuCamera {
    GpuCamera {
        view_proj: Mat4::IDENTITY.to_cols_array_2d(),
        eye: [0.0; 3],
        epsilon: 1.0,
        forward: [0.0, 0.0, -1.0],
        viewport: [1.0, 1.0],
        planes: [[0.0, 0.0, 0.0, -3.0e38]; 6],
        forms: crate::forms::FORMS_QUADS,
        ..Default::default()
    }
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
