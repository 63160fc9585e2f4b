//! The rival methods, drawn by the same runtime as the quad stream (`forest-render`) so that
//! every comparison shares the scene, the camera and the targets:
//!
//! - [`geometry`]: full geometry (the ground-truth reference when supersampled, the
//!   brute-force baseline at 1×), stochastic simplification (Cook et al. 2007) and discrete
//!   LODs + billboards, with their CPU preparation (the bake's tracer and simplifier);
//! - [`hybrid`]: the nearest trees as geometry, the rest as the quad stream;
//! - [`methods`]: every method behind one run-time switch.
//!
//! The paper's method itself lives in `forest-render`, which depends on nothing here.

pub mod geometry;
pub mod gpu_types;
pub mod hybrid;
pub mod methods;
pub mod shaders;

pub use geometry::{GeometryRenderer, GeometrySpecies, MeshMethod, PreparedGeometry};
pub use hybrid::{Hybrid, Near};
pub use methods::{ForestRenderer, Method, MethodStats};
