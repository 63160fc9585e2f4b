//! Forests to draw, made and placed without a GPU or any file:
//! - [`generate`]: the clumped-forest generator (trees in natural clumps, on a terrain or flat);
//! - [`views`]: the named views of a forest and the rule that keeps them clear of every tree.
//!
//! The formats these read and write ([`forest_format::forest::Forest`], the terrain, the
//! atlas's manifest and opacity volume) live in `forest-format`; loading a forest with its
//! atlases for drawing lives in `forest-render` (`scene::load_scene`).
//!
//! A forest made and checked (the species are atlas names; `forest scene` writes the same with
//! `Forest::save`):
//!
//! ```
//! use forest_scene::generate::{GenerateParams, generate};
//!
//! let forest = generate(&GenerateParams {
//!     trees: 200,
//!     species: vec!["oak.atlas".into(), "pine.atlas".into()],
//!     area_per_tree: 40.0,
//!     ..GenerateParams::default()
//! })?;
//! assert_eq!(forest.instances.len(), 200);
//! forest.check(std::path::Path::new("example.forest"))?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![deny(missing_docs)]

pub mod generate;
pub mod views;
