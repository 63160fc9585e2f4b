//! Self-shadowing candidates measured against traced rays: how well each predicts the sun
//! visibility of a model's own surface under suns it was not built for.
//!
//! The reference is exact: from stratified points on every triangle (opaque texels only), one
//! alpha-tested ray towards the sun. Each candidate predicts the same points' visibility, and
//! both are averaged per triangle, the footprint at which shading sees them (a leaf card is a
//! few pixels wide where self-shadowing shows). Errors are area-weighted means over triangles.
//! Candidates:
//! - none: visibility 1 everywhere (no self-shadowing);
//! - the opacity volume ([`crate::opacity`]) at a given resolution, what the renderers use;
//! - directional visibility in first-order spherical harmonics (4 coefficients, projected
//!   from `SH_RAYS` rays over the sphere), the "few coefficients per texel or vertex"
//!   alternative. It is projected and evaluated at the reference's own sample points, so its
//!   error is a lower bound on what storing it per vertex would give; its bytes are counted
//!   per vertex.

use glam::Vec3;
use rayon::prelude::*;

use forest_format::slab::Sphere;

use crate::sampling::{hash, stratified_barycentric, unit};
use crate::trace::Scene;

/// Points per triangle.
const POINTS: u32 = 4;
/// Rays over the sphere per point for the spherical-harmonics candidate.
pub const SH_RAYS: u32 = 64;

/// A self-shadowing candidate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Candidate {
    /// No self-shadowing.
    None,
    /// The opacity volume at this many voxels a side.
    Volume(u32),
    /// First-order spherical harmonics of each sample point's visibility.
    Harmonics,
}

impl Candidate {
    /// A short name for tables.
    pub fn name(&self) -> String {
        match self {
            Self::None => "none".into(),
            Self::Volume(r) => format!("volume {r}³"),
            Self::Harmonics => "SH L1 (per point; bytes per vertex)".into(),
        }
    }

    /// Bytes a model stores for it: one byte per voxel, or 4 half floats per vertex of
    /// `vertices` (the triangle methods' count; slab texels would need 4 more channels).
    pub fn bytes(&self, vertices: u64) -> u64 {
        match self {
            Self::None => 0,
            Self::Volume(r) => u64::from(*r).pow(3),
            Self::Harmonics => vertices * 8,
        }
    }
}

/// A candidate's figures over the suns measured.
#[derive(Clone, Debug)]
pub struct CandidateError {
    /// The candidate.
    pub candidate: Candidate,
    /// Area-weighted mean absolute error of the per-triangle visibility, per sun.
    pub mae: Vec<f32>,
    /// Area-weighted mean of (candidate − exact), per sun: > 0 where it lights too much.
    pub bias: Vec<f32>,
}

/// A point on a triangle that shading sees (an opaque texel), with its triangle and weight.
struct Point {
    tri: u32,
    p: Vec3,
    /// The triangle's area share of this point.
    weight: f32,
}

fn points(scene: &Scene) -> Vec<Point> {
    let mesh = scene.mesh;
    let side = (POINTS as f32).sqrt() as u32;
    let mut out = Vec::new();
    for (ti, t) in scene.tris.iter().enumerate() {
        let area = 0.5 * (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).length();
        for s in 0..side * side {
            let b = stratified_barycentric(ti as u32, s, side, 0x51f1_5e3d);
            if !mesh.solid_at(t, b) {
                continue;
            }
            out.push(Point {
                tri: ti as u32,
                p: t.p[0] * b[0] + t.p[1] * b[1] + t.p[2] * b[2],
                weight: area / (side * side) as f32,
            });
        }
    }
    out
}

/// Measure `candidates` under each unit direction of `suns` (towards the sun, object space).
pub fn measure(
    scene: &Scene,
    sphere: &Sphere,
    suns: &[Vec3],
    candidates: &[Candidate],
) -> Vec<CandidateError> {
    let pts = points(scene);
    let eps = sphere.radius * 1e-4;
    let exact: Vec<Vec<f32>> = suns
        .iter()
        .map(|&sun| {
            pts.par_iter()
                .map(|q| {
                    let o = q.p + sun * eps;
                    f32::from(u8::from(!scene.occluded(o, sun, eps, f32::INFINITY, q.tri)))
                })
                .collect()
        })
        .collect();
    candidates
        .iter()
        .map(|&c| {
            let predicted: Vec<Vec<f32>> = match c {
                Candidate::None => suns.iter().map(|_| vec![1.0; pts.len()]).collect(),
                Candidate::Volume(r) => {
                    let v = crate::opacity::opacity_volume(scene.mesh, sphere, r);
                    suns.iter()
                        .map(|&sun| {
                            pts.par_iter()
                                .map(|q| v.transmittance(sphere, q.p, sun))
                                .collect()
                        })
                        .collect()
                }
                Candidate::Harmonics => {
                    let sh = harmonics(scene, &pts, eps);
                    suns.iter()
                        .map(|&sun| sh.iter().map(|c| eval_sh(c, sun)).collect())
                        .collect()
                }
            };
            let (mae, bias) = exact
                .iter()
                .zip(&predicted)
                .map(|(e, p)| per_triangle_error(&pts, e, p))
                .unzip();
            CandidateError {
                candidate: c,
                mae,
                bias,
            }
        })
        .collect()
}

/// Area-weighted (mean |p − e|, mean p − e) of the per-triangle means.
fn per_triangle_error(pts: &[Point], e: &[f32], p: &[f32]) -> (f32, f32) {
    let (mut abs, mut signed, mut total) = (0f64, 0f64, 0f64);
    let mut i = 0;
    while i < pts.len() {
        let tri = pts[i].tri;
        let (mut se, mut sp, mut w) = (0f64, 0f64, 0f64);
        while i < pts.len() && pts[i].tri == tri {
            let wi = f64::from(pts[i].weight);
            se += wi * f64::from(e[i]);
            sp += wi * f64::from(p[i]);
            w += wi;
            i += 1;
        }
        if w > 0.0 {
            abs += (sp - se).abs();
            signed += sp - se;
            total += w;
        }
    }
    let t = total.max(1e-30);
    ((abs / t) as f32, (signed / t) as f32)
}

/// First-order SH coefficients (Y00, Y1-1, Y10, Y11 as y, z, x) of each point's visibility,
/// from `SH_RAYS` stratified directions over the sphere.
fn harmonics(scene: &Scene, pts: &[Point], eps: f32) -> Vec<[f32; 4]> {
    let side = (SH_RAYS as f32).sqrt() as u32;
    pts.par_iter()
        .enumerate()
        .map(|(i, q)| {
            let mut c = [0f32; 4];
            for s in 0..side * side {
                let h = hash(i as u32 ^ hash(s ^ 0x2b99_2ddf));
                let u = ((s % side) as f32 + unit(h)) / side as f32;
                let v = ((s / side) as f32 + unit(hash(h))) / side as f32;
                let z = 1.0 - 2.0 * u;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = std::f32::consts::TAU * v;
                let d = Vec3::new(r * phi.cos(), z, r * phi.sin());
                let seen = !scene.occluded(q.p + d * eps, d, eps, f32::INFINITY, q.tri);
                if seen {
                    let y = sh_basis(d);
                    for k in 0..4 {
                        c[k] += y[k];
                    }
                }
            }
            // Monte Carlo over the sphere: 4π / n per sample.
            let w = 4.0 * std::f32::consts::PI / (side * side) as f32;
            c.map(|x| x * w)
        })
        .collect()
}

fn sh_basis(d: Vec3) -> [f32; 4] {
    let c0 = 0.282_095;
    let c1 = 0.488_603;
    [c0, c1 * d.y, c1 * d.z, c1 * d.x]
}

fn eval_sh(c: &[f32; 4], d: Vec3) -> f32 {
    let y = sh_basis(d);
    (c[0] * y[0] + c[1] * y[1] + c[2] * y[2] + c[3] * y[3]).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_order_harmonics_reconstruct_a_constant_and_a_linear_function() {
        // The constant 1 projects to c0 = ∫Y00 dω = 4π·Y00.
        let c0 = 4.0 * std::f32::consts::PI * 0.282_095;
        assert!((eval_sh(&[c0, 0.0, 0.0, 0.0], Vec3::X) - 1.0).abs() < 1e-4);
        // ½(1 + y) projects to c0/2 and, on Y1 along y, ½∫y·(0.488603·y) dω = ½·0.488603·4π/3.
        let c1 = 4.0 * std::f32::consts::PI / 3.0 * 0.488_603 * 0.5;
        for d in [Vec3::Y, -Vec3::Y, Vec3::X, Vec3::new(0.0, 0.6, 0.8)] {
            let f = eval_sh(&[c0 * 0.5, c1, 0.0, 0.0], d);
            assert!((f - 0.5 * (1.0 + d.y)).abs() < 1e-3, "{d}: {f}");
        }
    }
}
