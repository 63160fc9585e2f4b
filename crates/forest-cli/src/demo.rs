//! The bundled demo forest that `forest view` opens when given no forest: the five bundled tree
//! models (`assets/trees/`) baked into `out/atlases/` on first use, and again when a model's
//! files change, and a forest of [`TREES`] trees over them on seeded hills in
//! `out/forest-view.forest`. The same commands as `scripts/demo.sh`, so the two share their
//! cache.

use std::path::{Path, PathBuf};
use std::time::SystemTime;

use anyhow::{Context, Result, bail};

/// The bundled species, in the demo forest's species order.
pub const SPECIES: [&str; 5] = ["oak", "ash", "aspen", "pine", "bush"];

/// Trees in the viewer's demo forest.
pub const TREES: u32 = 20_000;

/// Ground per tree in the demo forests (m²): a closed stand of trees at their species'
/// heights (about 1.1 km across for [`TREES`]; `scripts/demo.sh` uses the same).
pub const AREA_PER_TREE: &str = "60";

/// The demo forest file and the OBJ models of its species (for the geometry-based methods).
pub struct Demo {
    /// The forest file.
    pub forest: PathBuf,
    /// One OBJ per species, in the forest's species order.
    pub models: Vec<PathBuf>,
}

/// Parse `args` as the sub-command `name` would, defaults included: one place for defaults.
fn parse_args<A: clap::Args + clap::FromArgMatches>(
    name: &'static str,
    args: &[&str],
) -> Result<A> {
    let cmd = A::augment_args(clap::Command::new(name));
    let m = cmd.try_get_matches_from(std::iter::once(name).chain(args.iter().copied()))?;
    Ok(A::from_arg_matches(&m)?)
}

/// The folder holding `assets/trees/`: the working folder only. (The source tree this binary
/// was built from is not used: the demo's cache would then be written into it, unasked, from
/// wherever the command ran.)
fn root() -> Result<PathBuf> {
    let here = PathBuf::from(".");
    if here.join("assets/trees/oak/oak.obj").is_file() {
        return Ok(here);
    }
    let built_from = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let hint = if built_from.join("assets/trees/oak/oak.obj").is_file() {
        format!(
            " (the repository this binary was built from is {})",
            built_from.display()
        )
    } else {
        String::new()
    };
    anyhow::bail!(
        "no forest given and the bundled tree models (assets/trees/) are not in the working \
         folder: run from the repository's folder{hint}, or give a forest file (forest view \
         FOREST)"
    )
}

fn modified(p: &Path) -> Option<SystemTime> {
    std::fs::metadata(p).and_then(|m| m.modified()).ok()
}

/// Newest modification time of the files directly in `dir`.
fn newest_in(dir: &Path) -> Result<SystemTime> {
    let mut newest = SystemTime::UNIX_EPOCH;
    for e in std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))? {
        let e = e?;
        if e.file_type()?.is_file()
            && let Some(t) = modified(&e.path())
        {
            newest = newest.max(t);
        }
    }
    Ok(newest)
}

/// Bake what is missing or stale and (re)generate the forest when an atlas is newer.
pub fn prepare() -> Result<Demo> {
    prepare_in(&root()?, &[])
}

/// [`prepare`] for the models in `root/assets/trees/`, caching in `root/out/`, with
/// `bake_args` added to every bake (the tests bake small atlases).
fn prepare_in(root: &Path, bake_args: &[&str]) -> Result<Demo> {
    let out = root.join("out");
    let atlases = out.join("atlases");
    std::fs::create_dir_all(&atlases)
        .with_context(|| format!("creating the demo cache {}", atlases.display()))?;
    let mut models = Vec::new();
    let mut atlas_paths = Vec::new();
    let mut newest_atlas = SystemTime::UNIX_EPOCH;
    for s in SPECIES {
        let dir = root.join("assets/trees").join(s);
        let model = dir.join(format!("{s}.obj"));
        let atlas = atlases.join(format!("{s}.atlas"));
        let manifest = atlas.join(forest_format::atlas::MANIFEST_FILE);
        let fresh = match modified(&manifest) {
            // Loadable by this version, its prepared model included.
            Some(t) => {
                t >= newest_in(&dir)?
                    && forest_format::Atlas::load(&atlas).is_ok_and(|a| {
                        forest_format::model::PreparedModel::load(&atlas).is_ok_and(|m| {
                            m.is_some_and(|m| m.check_atlas(&atlas, &a.manifest).is_ok())
                        })
                    })
            }
            None => false,
        };
        if !fresh {
            eprintln!(
                "forest view: baking the demo species {s} into {} (first use; cached)",
                atlas.display()
            );
            let (m, a) = (model.display().to_string(), atlas.display().to_string());
            let args: Vec<&str> = [m.as_str(), "-o", a.as_str()]
                .into_iter()
                .chain(bake_args.iter().copied())
                .collect();
            crate::bake::run(&parse_args("bake", &args)?)?;
        }
        newest_atlas = newest_atlas.max(modified(&manifest).unwrap_or(SystemTime::now()));
        atlas_paths.push(atlas.display().to_string());
        models.push(model);
    }
    let forest = out.join("forest-view.forest");
    // A forest from before the demo stood on hills is made again.
    let flat = || forest_format::forest::Forest::load(&forest).is_ok_and(|f| f.terrain.is_none());
    if modified(&forest).is_none_or(|t| t < newest_atlas) || flat() {
        let trees = TREES.to_string();
        let (species, f) = (atlas_paths.join(","), forest.display().to_string());
        let args = [
            "--trees",
            &trees,
            "--area-per-tree",
            AREA_PER_TREE,
            "--species",
            &species,
            "--seed",
            "1",
            "--terrain",
            "hills",
            "-o",
            &f,
        ];
        crate::scene::run(&parse_args("scene", &args)?)?;
    }
    if !forest.is_file() {
        bail!("the demo forest {} was not written", forest.display());
    }
    Ok(Demo { forest, models })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The repository's folder (the tests run in the crate's).
    fn repository() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
    }

    #[test]
    fn sub_command_defaults_come_from_their_own_definitions() {
        let b: crate::bake::BakeArgs = parse_args("bake", &["m.obj", "-o", "m.atlas"]).unwrap();
        assert_eq!((b.directions, b.slabs, b.resolution), (15, 2, 512));
        let s: crate::scene::SceneArgs =
            parse_args("scene", &["--species", "a.atlas", "-o", "f.forest"]).unwrap();
        assert_eq!(s.trees, 10_000);
        assert!(parse_args::<crate::scene::SceneArgs>("scene", &["-o", "f"]).is_err());
    }

    #[test]
    fn the_demo_bakes_once_and_again_only_what_changed() {
        let tmp = tempfile::tempdir().unwrap();
        let src = repository().join("assets/trees");
        for s in SPECIES {
            let d = tmp.path().join("assets/trees").join(s);
            std::fs::create_dir_all(&d).unwrap();
            for e in std::fs::read_dir(src.join(s)).unwrap() {
                let e = e.unwrap();
                std::fs::copy(e.path(), d.join(e.file_name())).unwrap();
            }
        }
        let small = [
            "--resolution",
            "32",
            "--directions",
            "3",
            "--spp",
            "1",
            "--no-hybrid-switch",
        ];
        let stamp = |p: &Path| modified(p).unwrap();
        let demo = prepare_in(tmp.path(), &small).unwrap();
        assert_eq!(demo.models.len(), SPECIES.len());
        let forest = forest_format::forest::Forest::load(&demo.forest).unwrap();
        assert_eq!(forest.instances.len(), TREES as usize);
        let terrain = forest.terrain.as_ref().expect("the demo stands on hills");
        // Every tree planted: on the lowest ground under its model's foot at its scale.
        let feet: Vec<f32> = SPECIES
            .iter()
            .map(|s| {
                let atlas = tmp.path().join(format!("out/atlases/{s}.atlas"));
                let model = forest_format::model::PreparedModel::load(&atlas).unwrap();
                model
                    .expect("the demo's atlases store their models")
                    .footprint_radius()
            })
            .collect();
        assert!(feet.iter().all(|&r| r > 0.0), "{feet:?}");
        let mut lowered = 0;
        for i in &forest.instances {
            let [x, y, z] = i.position;
            let foot = feet[i.species as usize] * i.scale;
            assert_eq!(y, terrain.lowest_under(x, z, foot), "{i:?}");
            assert!(y <= terrain.height(x, z));
            lowered += usize::from(y < terrain.height(x, z));
        }
        assert!(lowered > 0, "no tree stands on a slope");
        let manifest = |s: &str| {
            tmp.path()
                .join(format!("out/atlases/{s}.atlas/manifest.json"))
        };
        let before: Vec<_> = SPECIES.iter().map(|s| stamp(&manifest(s))).collect();
        let forest_before = stamp(&demo.forest);
        // Nothing changed: nothing is baked or generated again.
        prepare_in(tmp.path(), &small).unwrap();
        let same: Vec<_> = SPECIES.iter().map(|s| stamp(&manifest(s))).collect();
        assert_eq!(same, before);
        assert_eq!(stamp(&demo.forest), forest_before);
        // A changed model re-bakes its species alone, and the forest follows.
        std::thread::sleep(std::time::Duration::from_millis(20));
        let mtl = tmp.path().join("assets/trees/pine/pine.mtl");
        std::fs::write(&mtl, std::fs::read(&mtl).unwrap()).unwrap();
        prepare_in(tmp.path(), &small).unwrap();
        for (s, t) in SPECIES.iter().zip(&before) {
            assert_eq!(stamp(&manifest(s)) != *t, *s == "pine", "{s}");
        }
        assert!(stamp(&demo.forest) > forest_before);
    }

    #[test]
    fn the_bundled_models_are_found() {
        let r = repository();
        for s in SPECIES {
            assert!(r.join(format!("assets/trees/{s}/{s}.obj")).is_file(), "{s}");
        }
    }
}
