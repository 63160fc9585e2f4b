//! The forest and its atlases as Bevy assets.
//!
//! - [`ForestAtlas`], loaded from an atlas folder (`NAME.atlas`, as `forest bake` writes it)
//!   by [`AtlasLoader`]: each of its files is read through Bevy's asset reader and checked by
//!   `forest-format` as `forest render` checks it, with the species' prepared model
//!   (`model.bin`, which the geometry methods and the hybrid draw) when the bake stored one.
//! - [`ForestAsset`], loaded from a `.forest` file by [`ForestLoader`], with the atlases it
//!   names (relative to its folder) loaded as its dependencies.
//!
//! A missing or corrupt file fails the load with one message naming it, which Bevy reports as
//! an `AssetLoadFailedEvent`; nothing panics. An atlas folder is opened as a path, so it
//! needs an asset source with real folders (the default file source on Linux and macOS).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use bevy::asset::io::Reader;
use bevy::asset::{Asset, AssetLoader, AssetPath, LoadContext};
use bevy::reflect::TypePath;
use forest_baselines::{GeometrySpecies, PreparedGeometry};
use forest_format::FormatError;
use forest_format::atlas::{ATLAS_FILES, Atlas, MANIFEST_FILE};
use forest_format::forest::Forest;
use forest_format::model::{MODEL_FILE, PreparedModel};
use forest_render::SpeciesData;

/// Why a forest or an atlas did not load. Its message names the file and the cause.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// A file was missing, unreadable or invalid (the message names it).
    #[error("{0}")]
    Format(#[from] FormatError),
    /// The atlas's images or volume did not decode.
    #[error("{0}")]
    Decode(String),
    /// An atlas the forest names did not load.
    #[error("{forest}: species {index} ({atlas}): {cause}")]
    Atlas {
        /// The forest file.
        forest: PathBuf,
        /// The species' index in the forest.
        index: usize,
        /// The atlas path as the forest names it.
        atlas: String,
        /// Why it did not load.
        cause: String,
    },
}

/// One species' baked atlas, decoded: quad hierarchy, slab images, surface attributes and
/// opacity volume. Shared by every forest that names it.
#[derive(Asset, TypePath, Clone)]
pub struct ForestAtlas {
    /// The decoded atlas.
    pub data: Arc<SpeciesData>,
    /// The species' prepared model (`model.bin`), when the bake stored one.
    pub model: Option<Arc<PreparedModel>>,
}

/// A forest: its trees (instances, presorted per direction), its terrain, and its species'
/// atlases. Place it in a scene with [`crate::ForestScene`].
#[derive(Asset, TypePath, Clone)]
pub struct ForestAsset {
    /// The instances and terrain.
    pub forest: Arc<Forest>,
    /// One atlas per species, in the forest's species order.
    pub species: Arc<[SpeciesData]>,
    /// Every species' prepared model gathered for the geometry methods and the hybrid, or
    /// why there is none (the atlases without a `model.bin`).
    pub geometry: Result<Arc<PreparedGeometry>, String>,
}

/// Loads atlas folders (`*.atlas`).
#[derive(Default, TypePath)]
pub struct AtlasLoader;

impl AssetLoader for AtlasLoader {
    type Asset = ForestAtlas;
    type Settings = ();
    type Error = LoadError;

    async fn load(
        &self,
        _reader: &mut dyn Reader,
        _settings: &(),
        load_context: &mut LoadContext<'_>,
    ) -> Result<ForestAtlas, LoadError> {
        let folder = load_context.path().clone();
        let shown = folder.path().to_path_buf();
        // Every file a bake may write, read through Bevy's reader; the manifest says which of
        // them the atlas uses, and `Atlas::from_files` refuses what is missing or wrong.
        let mut files = Vec::new();
        for name in ATLAS_FILES {
            let path = AssetPath::from_path(&shown.join(name))
                .with_source(folder.source().clone_owned())
                .into_owned();
            match load_context.read_asset_bytes(path).await {
                Err(e) if name == MANIFEST_FILE => {
                    return Err(FormatError::invalid(
                        &shown,
                        format!(
                            "no atlas here ({MANIFEST_FILE}: {e}); bake one with \
                             `forest bake MODEL.obj -o NAME.atlas`"
                        ),
                    )
                    .into());
                }
                // Kept with its cause: it matters only if the manifest names this file.
                read => files.push((name, read.map_err(|e| e.to_string()))),
            }
        }
        let read = |name: &str| match files.iter().find(|(n, _)| *n == name) {
            Some((_, Ok(bytes))) => Ok(bytes.clone()),
            Some((_, Err(cause))) => Err(FormatError::invalid(shown.join(name), cause.clone())),
            None => Err(FormatError::invalid(
                shown.join(name),
                "missing from the atlas",
            )),
        };
        let atlas = Atlas::from_files(&shown, &read)?;
        // The prepared model, when the bake stored one; one that is there must be sound.
        let model = match files.iter().find(|(n, _)| *n == MODEL_FILE) {
            Some((_, Ok(bytes))) => {
                let model = PreparedModel::decode(bytes, &shown.join(MODEL_FILE))?;
                model.check_atlas(&shown, &atlas.manifest)?;
                Some(Arc::new(model))
            }
            _ => None,
        };
        let data =
            SpeciesData::decode(atlas, &shown).map_err(|e| LoadError::Decode(e.to_string()))?;
        Ok(ForestAtlas {
            data: Arc::new(data),
            model,
        })
    }

    fn extensions(&self) -> &[&str] {
        &["atlas"]
    }
}

/// Loads forests (`*.forest`, as `forest scene` writes them) and the atlases they name.
#[derive(Default, TypePath)]
pub struct ForestLoader;

impl AssetLoader for ForestLoader {
    type Asset = ForestAsset;
    type Settings = ();
    type Error = LoadError;

    async fn load(
        &self,
        reader: &mut dyn Reader,
        _settings: &(),
        load_context: &mut LoadContext<'_>,
    ) -> Result<ForestAsset, LoadError> {
        let path = load_context.path().path().to_path_buf();
        let mut bytes = Vec::new();
        reader
            .read_to_end(&mut bytes)
            .await
            .map_err(|e| FormatError::invalid(&path, e.to_string()))?;
        let forest = Forest::parse(&path, &bytes)?;
        let mut species = Vec::with_capacity(forest.species.len());
        let mut models = Vec::with_capacity(forest.species.len());
        let mut without = Vec::new();
        for (index, name) in forest.species.iter().enumerate() {
            let fail = |cause: String| LoadError::Atlas {
                forest: path.clone(),
                index,
                atlas: name.clone(),
                cause,
            };
            // Named relative to the forest's folder (or absolute), as `forest scene` writes.
            let here = load_context.path();
            let folder = here.path().parent().unwrap_or(Path::new(""));
            let atlas_path = AssetPath::from_path(&folder.join(name))
                .with_source(here.source().clone_owned())
                .into_owned();
            let loaded = load_context
                .load_builder()
                .load_value::<ForestAtlas>(atlas_path)
                .await
                .map_err(|e| fail(cause_of(&e)))?;
            // The nested load's asset is this forest's alone: taken, not copied.
            let ForestAtlas { data, model } = loaded.take();
            match model {
                Some(m) => models.push(GeometrySpecies::new(m, &data.atlas.manifest)),
                None => without.push(name.clone()),
            }
            species.push(Arc::try_unwrap(data).unwrap_or_else(|shared| (*shared).clone()));
        }
        let geometry = if without.is_empty() {
            Ok(Arc::new(PreparedGeometry::new(&models)))
        } else {
            Err(format!(
                "{} of {} hold no prepared model ({MODEL_FILE}): bake {} again without \
                 --no-model to draw the geometry methods and the hybrid",
                without.join(", "),
                path.display(),
                if without.len() == 1 { "it" } else { "them" }
            ))
        };
        Ok(ForestAsset {
            forest: Arc::new(forest),
            species: species.into(),
            geometry,
        })
    }

    fn extensions(&self) -> &[&str] {
        &["forest"]
    }
}

/// The innermost cause of a nested load's error (Bevy wraps it with the dependency's path,
/// which the forest's message already names).
fn cause_of(e: &bevy::asset::LoadDirectError) -> String {
    match e {
        bevy::asset::LoadDirectError::LoadError { error, .. } => match error.as_ref() {
            bevy::asset::AssetLoadError::AssetLoaderError(inner) => inner.to_string(),
            other => other.to_string(),
        },
        other => other.to_string(),
    }
}
