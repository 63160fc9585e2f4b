//! What a host gives a stream each frame: its view and projection matrices, viewport and ε
//! ([`FrameParams`]), and the targets to draw into with their load operations ([`Targets`]).

use glam::{Mat4, Vec3, Vec4};

pub use crate::camera::frustum_planes;
use crate::camera::{Camera, CameraError, gpu_camera};
use crate::gpu_types::GpuCamera;

/// One view of one frame, in the host's own matrices.
///
/// `proj` may be any perspective projection into wgpu's clip space (depth 0..1): standard or
/// reverse-Z, finite or infinite far plane, either handedness. The eye, the view direction and
/// the frustum are recovered from `proj · view`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameParams {
    /// World → view.
    pub view: Mat4,
    /// View → clip (wgpu: y up, depth 0..1).
    pub proj: Mat4,
    /// Viewport size in pixels (the target the stream draws into).
    pub viewport: (u32, u32),
    /// Refinement threshold ε: a quad is refined while a projected edge is longer (pixels).
    pub epsilon: f32,
    /// The frame's light: sun (world direction, colour), sky, ground and exposure. It rides in
    /// the camera uniform, so the camera stays the frame's only upload.
    pub light: forest_format::shading::Lighting,
    /// The frame's wind, which moves every tree ([`forest_format::wind`]); it rides in the
    /// camera uniform too.
    pub wind: forest_format::wind::Wind,
    /// The frame's season, 0 (spring) to 1 (late autumn), which turns the leaves of every
    /// tree ([`forest_format::colour`]); `None`: the models' own colours. It rides in the
    /// camera uniform too.
    pub season: Option<f32>,
}

impl From<&Camera> for FrameParams {
    /// The camera's matrices with the default light ([`forest_format::shading::Lighting`]'s
    /// `Default`), in calm air.
    fn from(c: &Camera) -> Self {
        Self {
            view: c.view(),
            proj: c.proj(),
            viewport: c.viewport,
            epsilon: c.epsilon,
            light: Default::default(),
            wind: forest_format::wind::Wind::CALM,
            season: None,
        }
    }
}

impl FrameParams {
    /// Check the matrices, viewport and ε; the error names the bad one.
    pub fn validate(&self) -> Result<(), CameraError> {
        let bad = |s: &str| Err(CameraError(s.to_string()));
        if !(self.view.is_finite() && self.proj.is_finite()) {
            return bad("view and projection matrices must be finite");
        }
        let m = self.proj * self.view;
        if m.determinant().abs() < f32::MIN_POSITIVE || !m.inverse().is_finite() {
            return bad("projection × view is singular: no perspective view");
        }
        if self.viewport.0 == 0 || self.viewport.1 == 0 {
            return Err(CameraError(format!(
                "viewport {:?} is empty",
                self.viewport
            )));
        }
        if !(self.epsilon.is_finite() && self.epsilon > 0.0) {
            return Err(CameraError(format!(
                "epsilon {} must be positive",
                self.epsilon
            )));
        }
        if !self.eye().is_finite() || !self.forward().is_finite() {
            return bad("the view matrix has no eye position (not invertible)");
        }
        self.light
            .validate()
            .map_err(|e| CameraError(format!("light: {e}")))?;
        self.wind.validate().map_err(CameraError)?;
        forest_format::colour::check_season(self.season).map_err(CameraError)?;
        Ok(())
    }

    /// Eye position (world, metres): the view matrix's inverse translation.
    pub fn eye(&self) -> Vec3 {
        self.view.inverse().w_axis.truncate()
    }

    /// Unit view direction: towards the point the viewport's centre shows (any handedness,
    /// standard or reverse-Z, finite or infinite far plane).
    pub fn forward(&self) -> Vec3 {
        let h = (self.proj * self.view).inverse() * Vec4::new(0.0, 0.0, 0.5, 1.0);
        let d = h.truncate() - self.eye() * h.w;
        (if h.w < 0.0 { -d } else { d }).normalize()
    }

    /// Vertical focal length in pixels: a length `l` at distance `d` projects to
    /// `l · focal / d` pixels.
    pub fn focal_pixels(&self) -> f32 {
        self.proj.y_axis.y.abs() * self.viewport.1 as f32 * 0.5
    }

    /// The GPU form with the frame's light (every tree drawn as quads; renderers set `forms`,
    /// debug view and flags).
    pub fn to_gpu(&self) -> GpuCamera {
        let mut g = gpu_camera(
            self.proj * self.view,
            self.eye(),
            self.forward(),
            self.viewport,
            self.epsilon,
        );
        g.set_light(&self.light);
        g.set_season(self.season);
        g
    }
}

/// The host's targets for a frame and what to do with their contents first.
#[derive(Clone, Copy, Debug)]
pub struct Targets<'a> {
    /// Colour attachment (multisampled when the stream was built with `sample_count > 1`).
    pub colour: &'a wgpu::TextureView,
    /// Where a multisampled colour attachment resolves to, if anywhere.
    pub resolve: Option<&'a wgpu::TextureView>,
    /// Depth attachment.
    pub depth: &'a wgpu::TextureView,
    /// Keep the host's colour ([`wgpu::LoadOp::Load`], the default of [`Targets::over`]) or
    /// clear it.
    pub colour_load: wgpu::LoadOp<wgpu::Color>,
    /// Keep the host's depth (trees are then hidden behind what the host drew) or clear it.
    pub depth_load: wgpu::LoadOp<f32>,
}

impl<'a> Targets<'a> {
    /// Draw over what the host's targets hold: colour and depth loaded, nothing cleared.
    pub fn over(colour: &'a wgpu::TextureView, depth: &'a wgpu::TextureView) -> Self {
        Self {
            colour,
            resolve: None,
            depth,
            colour_load: wgpu::LoadOp::Load,
            depth_load: wgpu::LoadOp::Load,
        }
    }

    /// Clear both targets first (colour to `clear`, depth to `depth`).
    pub fn cleared(
        colour: &'a wgpu::TextureView,
        depth: &'a wgpu::TextureView,
        clear: wgpu::Color,
        depth_clear: f32,
    ) -> Self {
        Self {
            colour,
            resolve: None,
            depth,
            colour_load: wgpu::LoadOp::Clear(clear),
            depth_load: wgpu::LoadOp::Clear(depth_clear),
        }
    }

    /// Begin a render pass on these targets.
    pub fn begin<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        label: &str,
        timestamp_writes: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> wgpu::RenderPass<'e> {
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: self.colour,
                depth_slice: None,
                resolve_target: self.resolve,
                ops: wgpu::Operations {
                    load: self.colour_load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: self.depth,
                depth_ops: Some(wgpu::Operations {
                    load: self.depth_load,
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes,
            occlusion_query_set: None,
            multiview_mask: None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> Camera {
        Camera {
            eye: Vec3::new(3.0, 2.0, 10.0),
            target: Vec3::new(0.0, 1.0, 0.0),
            fov_y_deg: 60.0,
            near: 0.1,
            far: 100.0,
            viewport: (800, 600),
            epsilon: 4.0,
        }
    }

    #[test]
    fn host_matrices_give_the_cameras_eye_direction_and_focal_length() {
        let c = cam();
        let f = FrameParams::from(&c);
        assert!((f.eye() - c.eye).length() < 1e-4, "{}", f.eye());
        assert!((f.forward() - c.forward()).length() < 1e-5);
        assert!((f.focal_pixels() - c.focal_pixels()).abs() < 1e-2);
        assert!(f.validate().is_ok());
    }

    #[test]
    fn reverse_infinite_projection_keeps_the_frustum_and_direction() {
        let c = cam();
        let view = c.view();
        let proj = glam::camera::rh::proj::directx::perspective_infinite_reverse(
            60f32.to_radians(),
            800.0 / 600.0,
            0.1,
        );
        let f = FrameParams {
            view,
            proj,
            viewport: (800, 600),
            epsilon: 4.0,
            light: Default::default(),
            wind: forest_format::wind::Wind::CALM,
            season: None,
        };
        assert!(f.validate().is_ok());
        assert!((f.forward() - c.forward()).length() < 1e-5);
        let g = f.to_gpu();
        let inside = |p: Vec3| {
            g.planes
                .iter()
                .all(|pl| Vec4::from_array(*pl).dot(p.extend(1.0)) >= 0.0)
        };
        assert!(inside(c.target));
        assert!(inside(c.eye + c.forward() * 1e6), "no far plane");
        assert!(!inside(c.eye - c.forward()), "behind the eye");
        assert!(!inside(c.eye + c.forward() * 0.05), "before the near plane");
        // The planes are the standard projection's, less the far one.
        let std = FrameParams::from(&c).to_gpu();
        for k in 0..4 {
            let (a, b) = (Vec4::from(g.planes[k]), Vec4::from(std.planes[k]));
            assert!((a - b).length() < 1e-4, "plane {k}: {a} vs {b}");
        }
    }

    #[test]
    fn nothing_is_visible_before_the_first_frame() {
        let g = crate::camera::nothing_visible();
        for p in [Vec3::ZERO, Vec3::splat(1e6), Vec3::splat(-1e6)] {
            assert!(
                g.planes
                    .iter()
                    .any(|pl| Vec4::from_array(*pl).dot(p.extend(1.0)) < -1e30)
            );
        }
    }

    #[test]
    fn bad_matrices_are_named() {
        let mut f = FrameParams::from(&cam());
        f.proj = Mat4::ZERO;
        assert!(f.validate().unwrap_err().0.contains("singular"));
        let mut f = FrameParams::from(&cam());
        f.view.x_axis.x = f32::NAN;
        assert!(f.validate().unwrap_err().0.contains("finite"));
        let mut f = FrameParams::from(&cam());
        f.epsilon = 0.0;
        assert!(f.validate().unwrap_err().0.contains("epsilon"));
        let mut f = FrameParams::from(&cam());
        f.light.exposure = -1.0;
        assert!(f.validate().unwrap_err().0.contains("exposure"));
    }

    #[test]
    fn the_light_rides_in_the_camera_uniform() {
        let mut f = FrameParams::from(&cam());
        f.light = forest_format::shading::Lighting::with_sun(90.0, 0.0);
        f.light.exposure = 2.0;
        let g = f.to_gpu();
        assert!((Vec3::from_slice(&g.sun[..]) - Vec3::X).length() < 1e-6);
        assert_eq!(g.exposure, 2.0);
        assert_eq!(g.sky_light[..3], f.light.sky.to_array());
        assert_eq!(g.ground_light[..3], f.light.ground.to_array());
        assert_eq!(g.sun_colour[..3], f.light.sun.to_array());
    }
}
