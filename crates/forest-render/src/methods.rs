//! Every method behind one switch: the quad stream, static impostors (the stream without
//! refinement), and the geometry-based methods (full geometry, stochastic simplification,
//! discrete LODs + billboards). Switching is a uniform write or an iteration count: nothing is
//! rebuilt, so a viewer or a benchmark can compare methods frame by frame.

use std::cell::Cell;

use crate::camera::{Camera, CameraError};
use crate::context::{GpuContext, RenderError};
use crate::geometry::{GeometryRenderer, MeshMethod};
use crate::renderer::{PassTimes, QuadStream};
use crate::target::Target;

/// A rendering method.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// The dynamic quad stream (cull, refine by ε, draw).
    Quads,
    /// Static impostors: the quad stream's level-0 quads, no refinement.
    Impostor,
    /// A geometry-based method.
    Mesh(MeshMethod),
}

impl Method {
    /// Short name, as the CLI and the benchmark tables spell it.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Quads => "quads",
            Method::Impostor => "impostor",
            Method::Mesh(MeshMethod::Full { depth_sort: true }) => "geometry",
            Method::Mesh(MeshMethod::Full { depth_sort: false }) => "geometry-unsorted",
            Method::Mesh(MeshMethod::Stochastic(_)) => "stochastic",
            Method::Mesh(MeshMethod::Lods(_)) => "lods",
        }
    }
}

/// Counters of the last frame of whichever method drew it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MethodStats {
    /// Trees that passed the frustum test.
    pub visible_trees: u32,
    /// Quads (quad-stream methods) or triangles (geometry-based methods) drawn.
    pub primitives: u64,
    /// Trees drawn as billboards (discrete LODs).
    pub billboards: u32,
    /// Quads per hierarchy level (quad-stream methods; empty for the others).
    pub per_level: Vec<u32>,
    /// Quads dropped or left unrefined for lack of room (quad-stream methods).
    pub overflow: u32,
    /// GPU pass times, where the adapter has timestamp queries.
    pub times: Option<PassTimes>,
}

/// The quad stream and, when models were given, the geometry renderer of one forest.
pub struct ForestRenderer {
    /// The quad stream (also the static impostors).
    pub stream: QuadStream,
    /// The geometry-based methods, when the species' models were prepared.
    pub geometry: Option<GeometryRenderer>,
    method: Cell<Method>,
}

impl ForestRenderer {
    /// Start with the quad stream.
    pub fn new(stream: QuadStream, geometry: Option<GeometryRenderer>) -> Self {
        stream.set_refine(true);
        Self {
            stream,
            geometry,
            method: Cell::new(Method::Quads),
        }
    }

    /// The current method.
    pub fn method(&self) -> Method {
        self.method.get()
    }

    /// Switch the method; the geometry-based ones need the geometry renderer.
    pub fn set_method(&self, ctx: &GpuContext, method: Method) -> Result<(), RenderError> {
        match method {
            Method::Quads | Method::Impostor => self.stream.set_refine(method == Method::Quads),
            Method::Mesh(m) => self
                .geometry
                .as_ref()
                .ok_or_else(|| {
                    RenderError::Scene(format!(
                        "the {} method needs the species' OBJ models (none were loaded)",
                        method.name()
                    ))
                })?
                .set_method(ctx, m)?,
        }
        self.method.set(method);
        Ok(())
    }

    /// Write the camera and record one frame of the current method.
    pub fn encode(
        &self,
        ctx: &GpuContext,
        camera: &Camera,
        encoder: &mut wgpu::CommandEncoder,
        colour: &wgpu::TextureView,
        depth: &wgpu::TextureView,
    ) -> Result<(), CameraError> {
        match (self.method.get(), &self.geometry) {
            (Method::Mesh(_), Some(g)) => g.encode(ctx, camera, encoder, colour, depth),
            _ => {
                self.stream.set_camera(ctx, camera)?;
                self.stream.encode(encoder, colour, depth);
                Ok(())
            }
        }
    }

    /// Write the camera, record the frame into `target`, and submit.
    pub fn render_frame(
        &self,
        ctx: &GpuContext,
        camera: &Camera,
        target: &Target,
    ) -> Result<(), CameraError> {
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        self.encode(
            ctx,
            camera,
            &mut enc,
            &target.colour_view,
            &target.depth_view,
        )?;
        ctx.queue.submit([enc.finish()]);
        Ok(())
    }

    /// Counters and pass times of the last submitted frame; waits for the GPU.
    pub fn read_stats(&self, ctx: &GpuContext) -> MethodStats {
        match (self.method.get(), &self.geometry) {
            (Method::Mesh(_), Some(g)) => {
                let s = g.read_stats(ctx);
                MethodStats {
                    visible_trees: s.visible_trees,
                    primitives: s.triangles,
                    billboards: s.billboards,
                    per_level: Vec::new(),
                    overflow: 0,
                    times: s.times,
                }
            }
            _ => {
                let s = self.stream.read_stats(ctx);
                MethodStats {
                    visible_trees: s.visible_trees,
                    primitives: u64::from(s.quads),
                    billboards: 0,
                    per_level: s.per_level,
                    overflow: s.overflow_cull + s.overflow_refine,
                    times: s.times,
                }
            }
        }
    }
}
