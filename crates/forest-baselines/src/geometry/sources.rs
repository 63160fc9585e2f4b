//! Where the geometry-based methods' models come from: the model each atlas's bake stored
//! (`model.bin`), or OBJ/glTF files prepared here and checked to be the ones the atlases were
//! baked from.

use std::path::{Path, PathBuf};

use forest_format::AtlasManifest;
use forest_format::forest::Forest;
use forest_format::model::{MODEL_FILE, PreparedModel};
use forest_render::SpeciesData;

use super::params::GeometrySpecies;
use super::prepare::PreparedGeometry;

/// How far (a fraction of the atlas's bounding radius) a model's bounding sphere may lie from
/// its atlas's for the model to count as the one baked, when its bytes differ (re-exported,
/// or a texture edited).
pub const MODEL_SPHERE_TOLERANCE: f32 = 0.01;

/// Why a forest's models could not be prepared.
#[derive(Debug, thiserror::Error)]
pub enum ModelSourceError {
    /// An atlas's stored model could not be read, or is not its atlas's.
    #[error(transparent)]
    Format(#[from] forest_format::FormatError),
    /// A model file could not be loaded.
    #[error(transparent)]
    Bake(#[from] forest_bake::BakeError),
    /// An atlas baked without its model, and no model files were given.
    #[error(
        "{} holds no prepared model ({MODEL_FILE}): bake it again without --no-model, or pass \
         the species' models with --models",
        .0.display()
    )]
    NoModel(PathBuf),
    /// A model file that is not the one its atlas was baked from.
    #[error("{0} (--allow-other-models draws it anyway)")]
    OtherModel(String),
}

/// Every species' model, ready for [`super::GpuModels`], with the notes a front end shows
/// (a model drawn although its bytes differ from the baked one's).
pub struct SourcedModels {
    /// The prepared models, in the forest's species order.
    pub geometry: PreparedGeometry,
    /// What the user should know about the models drawn (one line each).
    pub notes: Vec<String>,
}

/// The species' models: the files `models` (in the forest's species order) prepared here
/// when given ([`prepare_models`]), else those the bake stored in each atlas of the forest
/// file `forest_file` (`model.bin`, checked to be its atlas's).
pub fn models_for(
    models: &[PathBuf],
    forest_file: &Path,
    forest: &Forest,
    species: &[SpeciesData],
    allow_other: bool,
) -> Result<SourcedModels, ModelSourceError> {
    if !models.is_empty() {
        return prepare_models(models, species, allow_other);
    }
    let dir = forest_file.parent().unwrap_or(Path::new("."));
    let geo_species = forest
        .species
        .iter()
        .zip(species)
        .map(|(name, s)| {
            let atlas = dir.join(name);
            let model = PreparedModel::load(&atlas)?
                .ok_or_else(|| ModelSourceError::NoModel(atlas.clone()))?;
            model.check_atlas(&atlas, &s.atlas.manifest)?;
            Ok(GeometrySpecies::new(model.into(), &s.atlas.manifest))
        })
        .collect::<Result<Vec<_>, ModelSourceError>>()?;
    Ok(SourcedModels {
        geometry: PreparedGeometry::new(&geo_species),
        notes: Vec::new(),
    })
}

/// Load the species' OBJ or glTF models and prepare them for the geometry-based methods, lit
/// as their atlases were baked; each is checked by [`check_model`].
pub fn prepare_models(
    models: &[PathBuf],
    species: &[SpeciesData],
    allow_other: bool,
) -> Result<SourcedModels, ModelSourceError> {
    let mut notes = Vec::new();
    let geo_species = models
        .iter()
        .zip(species)
        .map(|(m, s)| {
            let mesh = forest_bake::Mesh::load(m)?;
            notes.extend(check_model(m, &mesh, &s.atlas.manifest, allow_other)?);
            let model = forest_bake::model::prepare(&mesh, None);
            Ok(GeometrySpecies::new(model.into(), &s.atlas.manifest))
        })
        .collect::<Result<Vec<_>, ModelSourceError>>()?;
    Ok(SourcedModels {
        geometry: PreparedGeometry::new(&geo_species),
        notes,
    })
}

/// A model drawn for a species is the one its atlas was baked from: the same bytes (the hash
/// the bake recorded), or else the same bounding sphere within [`MODEL_SPHERE_TOLERANCE`]
/// (returned as a note). Anything else is an error naming both, unless `allow_other` (a
/// note again).
pub fn check_model(
    path: &Path,
    mesh: &forest_bake::Mesh,
    manifest: &AtlasManifest,
    allow_other: bool,
) -> Result<Option<String>, ModelSourceError> {
    if format!("{:016x}", mesh.hash) == manifest.source.hash {
        return Ok(None);
    }
    let baked = manifest.bounding_sphere;
    let sphere = forest_bake::bounding_sphere(mesh);
    let off = (sphere.center - baked.center).length() + (sphere.radius - baked.radius).abs();
    let close = off <= MODEL_SPHERE_TOLERANCE * baked.radius;
    let what = format!(
        "model {} is not the file its atlas was baked from ({}): its bytes differ, and its \
         bounding sphere (centre {:.3}, radius {:.3}) is {} the atlas's (centre {:.3}, radius \
         {:.3})",
        path.display(),
        manifest.source.file,
        sphere.center,
        sphere.radius,
        if close { "within 1 % of" } else { "not" },
        baked.center,
        baked.radius
    );
    if close || allow_other {
        Ok(Some(what))
    } else {
        Err(ModelSourceError::OtherModel(what))
    }
}
