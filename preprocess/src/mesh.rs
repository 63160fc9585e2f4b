//! Loading a tree model (OBJ + MTL + textures; glTF in [`crate::gltf_mesh`]) into flat
//! triangles for the ray tracer.
//!
//! Polygons are triangulated by tobj. Texture alpha comes from `map_d` (its alpha channel, or
//! its grey level when it has none) or else from the alpha channel of `map_Kd`; a material with
//! either is *alpha-tested* at 0.5 and shaded as a leaf (translucent, see
//! [`forest_format::shading`]). A missing or unreadable texture is an error naming the material
//! and the file: silently drawing leaf cards as opaque squares would ruin the bake.

use std::path::Path;

use glam::{Vec2, Vec3};

use crate::error::BakeError;
use crate::texture::Texture;

/// Alpha below this is a hole in an alpha-tested material.
pub const ALPHA_CUTOFF: f32 = 0.5;

/// A material as the bake uses it.
#[derive(Clone, Debug)]
pub struct Material {
    /// Name from the MTL.
    pub name: String,
    /// `Kd` as a linear multiplier (sRGB-decoded; white when absent).
    pub kd: Vec3,
    /// Index of the colour texture (`map_Kd`).
    pub colour: Option<usize>,
    /// Index of the texture giving alpha, and whether to read its alpha channel (else grey).
    pub alpha: Option<(usize, bool)>,
    /// Translucency of the shading model (leaves: [`forest_format::shading::LEAF_TRANSLUCENCY`]).
    pub translucency: f32,
}

/// One triangle with its attributes.
#[derive(Clone, Copy, Debug)]
pub struct Tri {
    /// Object-space positions (metres).
    pub p: [Vec3; 3],
    /// Texture coordinates (zero when the model has none).
    pub uv: [Vec2; 3],
    /// Vertex normals (the face normal when the model has none), unit length.
    pub n: [Vec3; 3],
    /// Material index.
    pub material: u32,
}

/// A loaded model.
#[derive(Clone, Debug)]
pub struct Mesh {
    /// Usable triangles.
    pub tris: Vec<Tri>,
    /// Materials (at least one: a grey default when the OBJ names none).
    pub materials: Vec<Material>,
    /// Textures referenced by materials.
    pub textures: Vec<Texture>,
    /// Zero-area triangles skipped.
    pub degenerate: u64,
    /// FNV-1a 64 hash of the OBJ, MTL and texture bytes.
    pub hash: u64,
    /// What the loader read past without using, for the user to see (a glTF's animations,
    /// cameras, morph targets, …); empty when nothing was left out.
    pub notes: Vec<String>,
}

/// FNV-1a 64-bit hash, continued from `h`.
pub fn fnv1a(mut h: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}
/// FNV-1a 64-bit offset basis.
pub(crate) const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

/// The squared-area threshold below which a triangle of a model reaching `extent` model units
/// from the origin counts as degenerate (relative to the model's size).
pub(crate) fn min_area2(extent: f32) -> f32 {
    (extent * 1e-7).powi(4)
}

impl Tri {
    /// A triangle, or None when it is degenerate (squared cross product at most `min_area2`,
    /// or not finite). Missing normals (`n` None) and normals that do not normalise take the
    /// face normal.
    pub(crate) fn new(
        p: [Vec3; 3],
        uv: [Vec2; 3],
        n: Option<[Vec3; 3]>,
        material: u32,
        min_area2: f32,
    ) -> Option<Self> {
        let cross = (p[1] - p[0]).cross(p[2] - p[0]);
        if cross.length_squared() <= min_area2 || !cross.is_finite() {
            return None;
        }
        let face_n = cross.normalize();
        let n = n
            .unwrap_or([face_n; 3])
            .map(|v| v.try_normalize().unwrap_or(face_n));
        Some(Self { p, uv, n, material })
    }
}

/// The error of a model left with no triangle (none at all, or `degenerate` of zero area).
pub(crate) fn no_triangles(path: &Path, degenerate: u64) -> BakeError {
    BakeError::Model {
        path: path.into(),
        what: if degenerate > 0 {
            format!("all {degenerate} triangles are degenerate (zero area)")
        } else {
            "no faces: the model has no triangles to bake".into()
        },
    }
}

/// The largest vertex coordinate (absolute value, model units) a model may have (NaN and
/// infinities are refused by the same test).
pub use forest_format::species::MAX_MODEL_COORDINATE;

impl Mesh {
    /// Names of the materials whose alpha texture is transparent at every texel (alpha below
    /// [`ALPHA_CUTOFF`]), in material order: their triangles draw nothing.
    pub fn transparent_materials(&self) -> Vec<&str> {
        self.materials
            .iter()
            .filter(|m| {
                m.alpha.is_some_and(|(t, channel)| {
                    let cut = (ALPHA_CUTOFF * 255.0).ceil() as u8;
                    self.textures[t]
                        .rgba
                        .chunks_exact(4)
                        .all(|p| texel_alpha([p[0], p[1], p[2], p[3]], channel) < cut)
                })
            })
            .map(|m| m.name.as_str())
            .collect()
    }

    /// Refuses a mesh whose every triangle uses a material transparent at every texel: its
    /// bake would draw nothing. The error names those materials.
    pub fn check_drawable(&self, path: &Path) -> Result<(), BakeError> {
        let clear = self.transparent_materials();
        let names: Vec<&str> = self.materials.iter().map(|m| m.name.as_str()).collect();
        let all_clear = self
            .tris
            .iter()
            .all(|t| clear.contains(&names[t.material as usize]));
        if self.tris.is_empty() || !all_clear {
            return Ok(());
        }
        Err(BakeError::Model {
            path: path.into(),
            what: format!(
                "every texel of the alpha texture of material{} {} is transparent (alpha below                  {ALPHA_CUTOFF}), and every triangle uses {}: the model draws nothing",
                if clear.len() == 1 { "" } else { "s" },
                clear
                    .iter()
                    .map(|n| format!("{n:?}"))
                    .collect::<Vec<_>>()
                    .join(", "),
                if clear.len() == 1 { "it" } else { "them" },
            ),
        })
    }

    /// Whether barycentric point `b` of triangle `t` is solid: not a hole of an alpha-tested
    /// material (alpha below [`ALPHA_CUTOFF`]).
    pub fn solid_at(&self, t: &Tri, b: [f32; 3]) -> bool {
        self.materials[t.material as usize].alpha.is_none()
            || self.alpha(t.material, t.uv[0] * b[0] + t.uv[1] * b[1] + t.uv[2] * b[2])
                >= ALPHA_CUTOFF
    }

    /// Alpha of material `m` at `uv` (1 for materials without alpha).
    pub fn alpha(&self, m: u32, uv: Vec2) -> f32 {
        match self.materials[m as usize].alpha {
            None => 1.0,
            Some((t, channel)) => {
                f32::from(texel_alpha(self.textures[t].fetch(uv), channel)) / 255.0
            }
        }
    }
}

/// The alpha byte a material reads from an RGBA8 texel: its alpha channel when `channel`,
/// else its grey (the mean of R, G and B).
pub fn texel_alpha(texel: [u8; 4], channel: bool) -> u8 {
    if channel {
        texel[3]
    } else {
        ((u32::from(texel[0]) + u32::from(texel[1]) + u32::from(texel[2])) / 3) as u8
    }
}
