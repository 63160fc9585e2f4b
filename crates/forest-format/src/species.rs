//! The one check of the species a forest is drawn with, which every command that reads a
//! forest and its atlases runs (`scene` before it writes one, `info`, `render`, `view`,
//! `bench`): each atlas's manifest is consistent in itself ([`crate::Atlas::load`] checks
//! that, hybrid-switch record and bounding sphere included), the forest names as many species
//! as it has atlases, and every tree, its model's bounding sphere scaled and placed, lies
//! within [`MAX_COORDINATE`] of the origin.

use std::path::Path;

use glam::Vec3;

use crate::atlas::AtlasManifest;
use crate::error::FormatError;
use crate::forest::{Forest, MAX_COORDINATE};

/// The largest vertex coordinate (absolute value, model units) a model may have, and so the
/// farthest an atlas's bounding sphere may reach from the model's origin: beyond it, areas of
/// the model's triangles (fourth powers of coordinates in the bake's zero-area test)
/// overflow `f32`.
pub const MAX_MODEL_COORDINATE: f32 = 1e6;

/// Check `forest` (read from `path`, which errors name) against the manifests of its
/// species' atlases, in its species order.
pub fn check(
    forest: &Forest,
    manifests: &[&AtlasManifest],
    path: &Path,
) -> Result<(), FormatError> {
    if manifests.len() != forest.species.len() {
        return Err(FormatError::invalid(
            path,
            format!(
                "{} species but {} atlases",
                forest.species.len(),
                manifests.len()
            ),
        ));
    }
    for (k, i) in forest.instances.iter().enumerate() {
        let m = manifests[i.species as usize];
        let s = &m.bounding_sphere;
        // The farthest point of the tree's sphere from the origin, on any axis.
        let centre = Vec3::from_array(i.position) + s.center * i.scale;
        let reach = centre.abs().max_element() + s.radius * i.scale;
        if reach.is_nan() || reach > MAX_COORDINATE {
            return Err(FormatError::invalid(
                path,
                format!(
                    "instance {k} ({}, scale {}) reaches {reach:e} m from the origin, beyond the \
                     ±{MAX_COORDINATE:e} m a forest may span",
                    forest.species[i.species as usize], i.scale
                ),
            ));
        }
    }
    Ok(())
}
