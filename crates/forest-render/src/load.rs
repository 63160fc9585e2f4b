//! A forest and its species' atlases, loaded from disk and checked against each other, and
//! the named views of it ([`forest_scene::views`]) with every tree shaped by its atlas.

use std::path::Path;

use forest_format::forest::Forest;
use forest_scene::views::{self, Clearances, TreeShape};
use glam::Vec3;

use crate::error::RenderError;
use crate::scene::SpeciesData;

/// Load the forest file `path` and the atlases of its species (resolved against the forest's
/// folder), then check that they agree ([`forest_format::species::check`]). `on_atlases` is
/// told the number of atlases before they load (a front end's progress).
pub fn load_scene(
    path: &Path,
    on_atlases: impl FnOnce(usize),
) -> Result<(Forest, Vec<SpeciesData>), RenderError> {
    let forest = Forest::load(path)?;
    on_atlases(forest.species.len());
    let dir = path.parent().unwrap_or(Path::new("."));
    let species = forest
        .species
        .iter()
        .map(|s| {
            SpeciesData::load(&dir.join(s)).map_err(|e| RenderError::Species {
                name: s.clone(),
                forest: path.to_path_buf(),
                source: Box::new(e),
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let manifests: Vec<_> = species.iter().map(|s| &s.atlas.manifest).collect();
    forest_format::species::check(&forest, &manifests, path)?;
    Ok((forest, species))
}

/// A species' trunk and crown for placing cameras clear of it: its atlas's bounding sphere
/// banded by its opacity volume ([`TreeShape::with_volume`]).
pub fn tree_shape(species: &SpeciesData) -> TreeShape {
    TreeShape::with_volume(&species.atlas.manifest, &species.opacity)
}

/// The named view `name` of `forest` (eye, target; [`views::named`]), every tree shaped by
/// its species' atlas ([`tree_shape`]; `species` in the forest's order). A name not in
/// [`views::NAMES`] is an error that lists them.
pub fn named_view(
    name: &str,
    forest: &Forest,
    species: &[SpeciesData],
) -> Result<(Vec3, Vec3), RenderError> {
    let shapes: Vec<TreeShape> = species.iter().map(tree_shape).collect();
    views::named(name, forest, &Clearances::new(forest, &shapes)).ok_or_else(|| {
        RenderError::Parameter(format!(
            "no view named {name:?}: give one of {:?}",
            views::NAMES
        ))
    })
}

/// The view a viewer or a host opens on ([`views::start`]), as [`named_view`] places it.
pub fn start_view(forest: &Forest, species: &[SpeciesData]) -> (Vec3, Vec3) {
    let shapes: Vec<TreeShape> = species.iter().map(tree_shape).collect();
    views::start(forest, &Clearances::new(forest, &shapes))
}
