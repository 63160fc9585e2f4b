//! Forest scenes: tree instances, their species (atlases), and presorted back-to-front orders.
//!
//! Two file forms:
//! - **binary** (`.forest`): magic `FRST`, version, species names, instances as raw
//!   little-endian [`Instance`] records, then the presort directions and orders. Compact enough
//!   for 1M instances (24 bytes per instance plus 4 bytes per instance per presort direction).
//!   Version 2 appends the terrain (see [`Terrain::write_to`]); a forest without terrain is
//!   written as version 1, which both versions' readers read. Version 3, written only for a
//!   forest with a colouring ([`Colouring`]), appends a flags word (1: terrain, 2: colouring),
//!   the terrain if flagged, then `TINT`: the amount, per species 16 `f32`s
//!   ([`SpeciesColour`]: hue, saturation, brightness, bark, then spring's, autumn's and late
//!   autumn's tint and strength), a count (0 or the instances) and that many explicit values.
//! - **JSON** (`.json`), for small hand-made scenes: `{"species": [...], "instances": [{"species":
//!   0, "position": [x, y, z], "rotation_deg": 0, "scale": 1}]}`, optionally `"terrain": {"size":
//!   [nx, nz], "origin": [x, z], "spacing": s, "heights": [...]}`, and `"colour": {"amount": 1,
//!   "species": [...]}` (each a [`SpeciesColour`]) with an instance's explicit value as its
//!   `"colour": 0.42`; presorts are computed on load.
//!
//! Writers go through a temporary name and a rename; readers check every count and value.

use std::path::Path;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::colour::{Colouring, SpeciesColour};
use crate::directions::hemisphere_directions;
use crate::error::FormatError;
use crate::terrain::Terrain;

/// Binary forest format version (3: with a colouring; 2: with a terrain and no colouring; a
/// forest with neither is written as 1).
pub const FOREST_VERSION: u32 = 3;
const TERRAIN_MAGIC: &[u8; 4] = b"TERR";
const COLOUR_MAGIC: &[u8; 4] = b"TINT";
/// Version 3's flags word: a terrain follows.
const FLAG_TERRAIN: u32 = 1;
/// Version 3's flags word: a colouring follows.
const FLAG_COLOUR: u32 = 2;
const MAGIC: &[u8; 4] = b"FRST";
/// Default number of presort directions.
pub const DEFAULT_PRESORT_DIRECTIONS: u32 = 15;
/// Most instances a forest may hold (indices must fit the GPU's quad records).
pub const MAX_INSTANCES: usize = 1 << 24;

/// One tree: 24 bytes, uploaded as is.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable, Serialize, Deserialize)]
pub struct Instance {
    /// Base of the tree in world space (metres); the model's origin goes here.
    pub position: [f32; 3],
    /// Rotation about +Y in radians (counter-clockwise seen from above).
    pub rotation: f32,
    /// Uniform scale, in [`MIN_SCALE`, `MAX_SCALE`].
    pub scale: f32,
    /// Index into [`Forest::species`].
    pub species: u32,
}

/// Back-to-front instance orders along fixed directions.
#[derive(Clone, Debug, PartialEq)]
pub struct Presort {
    /// Unit directions over the upper hemisphere (towards the viewer).
    pub directions: Vec<Vec3>,
    /// For each direction, every instance index once, farthest from a viewer in that direction
    /// first (ascending `position · direction`, ties by index).
    pub orders: Vec<Vec<u32>>,
}

impl Presort {
    /// Presort `instances` along `count` hemisphere directions.
    pub fn new(instances: &[Instance], count: u32) -> Self {
        let directions = hemisphere_directions(count);
        let orders = directions
            .iter()
            .map(|&d| {
                let key: Vec<f32> = instances
                    .iter()
                    .map(|i| Vec3::from_array(i.position).dot(d))
                    .collect();
                let mut order: Vec<u32> = (0..instances.len() as u32).collect();
                order.sort_by(|&a, &b| key[a as usize].total_cmp(&key[b as usize]).then(a.cmp(&b)));
                order
            })
            .collect();
        Self { directions, orders }
    }

    /// Index of the presort direction nearest `towards_viewer` (largest dot product; the first
    /// on ties), as the GPU chooses it.
    pub fn nearest(directions: &[Vec3], towards_viewer: Vec3) -> usize {
        let mut best = 0;
        let mut best_dot = f32::NEG_INFINITY;
        for (i, d) in directions.iter().enumerate() {
            let c = d.dot(towards_viewer);
            if c > best_dot {
                best = i;
                best_dot = c;
            }
        }
        best
    }
}

pub use crate::limits::MAX_COORDINATE;

/// Smallest instance scale: a model shrunk more than this many times is no tree.
pub const MIN_SCALE: f32 = 1e-4;
/// Largest instance scale (models in centimetres scaled to metres are 100 times).
pub const MAX_SCALE: f32 = 1e4;

/// A forest: species (atlas names), instances and presorts.
#[derive(Clone, Debug, PartialEq)]
pub struct Forest {
    /// Atlas of each species: a path, relative to the forest file's folder unless absolute.
    pub species: Vec<String>,
    /// The trees.
    pub instances: Vec<Instance>,
    /// Presorted orders (one per presort direction).
    pub presort: Presort,
    /// The ground the trees stand on (`None`: flat at y = 0).
    pub terrain: Option<Terrain>,
    /// How the trees' colours vary, per tree and through the seasons (`None`: every tree
    /// keeps its model's colours; a season still turns the leaves, by the species' names,
    /// without a spread).
    pub colouring: Option<Colouring>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonInstance {
    species: u32,
    position: [f32; 3],
    #[serde(default)]
    rotation_deg: f32,
    #[serde(default = "one")]
    scale: f32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    colour: Option<f32>,
}
fn one() -> f32 {
    1.0
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonForest {
    species: Vec<String>,
    instances: Vec<JsonInstance>,
    #[serde(default)]
    presort_directions: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    terrain: Option<JsonTerrain>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    colour: Option<JsonColour>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonColour {
    amount: f32,
    species: Vec<SpeciesColour>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonTerrain {
    size: [u32; 2],
    origin: [f32; 2],
    spacing: f32,
    heights: Vec<f32>,
}

impl Forest {
    /// A forest with presorts computed along `presort_directions` directions.
    pub fn new(species: Vec<String>, instances: Vec<Instance>, presort_directions: u32) -> Self {
        let presort = Presort::new(&instances, presort_directions);
        Self {
            species,
            instances,
            presort,
            terrain: None,
            colouring: None,
        }
    }

    /// The forest with its trees coloured by `colouring`.
    pub fn with_colouring(mut self, colouring: Colouring) -> Self {
        self.colouring = Some(colouring);
        self
    }

    /// Species `k`'s colours as every method's shaders read them: its colouring at the
    /// forest's amount; without a colouring, no variation and the seasons of its name
    /// ([`SpeciesColour::by_name`]).
    pub fn tree_colour(&self, k: usize) -> crate::colour::TreeColour {
        match &self.colouring {
            Some(c) => c
                .species
                .get(k)
                .map_or(crate::colour::TreeColour::NONE, |s| s.gpu(c.amount)),
            None => self
                .species
                .get(k)
                .map_or(crate::colour::TreeColour::NONE, |n| {
                    SpeciesColour::by_name(n).gpu(0.0)
                }),
        }
    }

    /// The forest standing on `terrain`.
    pub fn with_terrain(mut self, terrain: Terrain) -> Self {
        self.terrain = Some(terrain);
        self
    }

    /// Check values: species indices in range, finite positions, scales in [`MIN_SCALE`,
    /// `MAX_SCALE`],
    /// presort orders that are permutations sorted along finite unit directions, and trees
    /// within [`MAX_COORDINATE`] of the origin.
    pub fn check(&self, path: &Path) -> Result<(), FormatError> {
        let bad = |what: String| Err(FormatError::invalid(path, what));
        if self.species.is_empty() && !self.instances.is_empty() {
            return bad("instances but no species".into());
        }
        if self.instances.len() > MAX_INSTANCES {
            return bad(format!(
                "{} instances, more than the supported {MAX_INSTANCES}",
                self.instances.len()
            ));
        }
        for (k, i) in self.instances.iter().enumerate() {
            if i.species as usize >= self.species.len() {
                return bad(format!(
                    "instance {k} has species {} but there are {} species",
                    i.species,
                    self.species.len()
                ));
            }
            if !(i.position.iter().all(|x| x.is_finite()) && i.rotation.is_finite()) {
                return bad(format!(
                    "instance {k} has a non-finite position or rotation"
                ));
            }
            if i.position.iter().any(|x| x.abs() > MAX_COORDINATE) {
                return bad(format!(
                    "instance {k} lies at {:?}, farther than {MAX_COORDINATE} m from the origin \
                     (cameras and far planes in single precision need a forest within that)",
                    i.position
                ));
            }
            if !(MIN_SCALE..=MAX_SCALE).contains(&i.scale) {
                return bad(format!(
                    "instance {k} has scale {:e}, outside [{MIN_SCALE:e}, {MAX_SCALE:e}]",
                    i.scale
                ));
            }
        }
        if let Some(t) = &self.terrain {
            t.check()
                .map_err(|e| FormatError::invalid(path, format!("terrain: {e}")))?;
        }
        if let Some(c) = &self.colouring {
            c.check(self.species.len(), self.instances.len())
                .map_err(|e| FormatError::invalid(path, e))?;
        }
        let p = &self.presort;
        if p.directions.is_empty() || p.directions.len() != p.orders.len() {
            return bad(format!(
                "{} presort directions with {} orders",
                p.directions.len(),
                p.orders.len()
            ));
        }
        for (k, d) in p.directions.iter().enumerate() {
            if !(d.is_finite() && (d.length() - 1.0).abs() < 1e-3) {
                return bad(format!(
                    "presort direction {k} {d} is not a finite unit vector"
                ));
            }
        }
        let n = self.instances.len();
        for (k, order) in p.orders.iter().enumerate() {
            let mut seen = vec![false; n];
            let ok = order.len() == n
                && order
                    .iter()
                    .all(|&i| (i as usize) < n && !std::mem::replace(&mut seen[i as usize], true));
            if !ok {
                return bad(format!(
                    "presort order {k} is not a permutation of the {n} instances"
                ));
            }
            // Sorted along its direction (back to front for a viewer on that side), as the
            // draw order needs it: a reversed order would draw front to back without a word.
            let d = p.directions[k];
            let key = |i: u32| Vec3::from_array(self.instances[i as usize].position).dot(d);
            if let Some(w) = order.windows(2).position(|w| key(w[0]) > key(w[1])) {
                return bad(format!(
                    "presort order {k} is not sorted along its direction {d} (entries {w} and {})",
                    w + 1
                ));
            }
        }
        Ok(())
    }

    /// Read a forest: JSON when the name ends in `.json`, else binary.
    pub fn load(path: &Path) -> Result<Self, FormatError> {
        let bytes = crate::bounded::read(path, crate::bounded::limit::DATA)?;
        Self::parse(path, &bytes)
    }

    /// [`Forest::load`] from the file's bytes: JSON when `path` ends in `.json`, else binary;
    /// errors name `path`.
    pub fn parse(path: &Path, bytes: &[u8]) -> Result<Self, FormatError> {
        let forest = if path.extension().is_some_and(|e| e == "json") {
            let j: JsonForest = serde_json::from_slice(bytes)
                .map_err(|e| FormatError::invalid(path, format!("not a valid forest JSON: {e}")))?;
            let instances = j
                .instances
                .iter()
                .map(|i| Instance {
                    position: i.position,
                    rotation: i.rotation_deg.to_radians(),
                    scale: i.scale,
                    species: i.species,
                })
                .collect();
            let k = j.presort_directions.unwrap_or(DEFAULT_PRESORT_DIRECTIONS);
            if !(1..=256).contains(&k) {
                return Err(FormatError::invalid(
                    path,
                    format!("presort_directions = {k}: must be 1 to 256"),
                ));
            }
            let explicit: Vec<f32> = j
                .instances
                .iter()
                .map(|i| i.colour.unwrap_or(-1.0))
                .collect();
            let any_explicit = j.instances.iter().any(|i| i.colour.is_some());
            let mut forest = Self::new(j.species, instances, k);
            match (j.colour, any_explicit) {
                (Some(c), _) => {
                    forest.colouring = Some(Colouring {
                        amount: c.amount,
                        species: c.species,
                        explicit: if any_explicit { explicit } else { Vec::new() },
                    })
                }
                (None, true) => {
                    return Err(FormatError::invalid(
                        path,
                        "instances give a \"colour\" but the forest has no \"colour\" section",
                    ));
                }
                (None, false) => {}
            }
            match j.terrain {
                Some(t) => forest.with_terrain(Terrain {
                    size: t.size,
                    origin: t.origin,
                    spacing: t.spacing,
                    heights: t.heights,
                }),
                None => forest,
            }
        } else {
            Self::from_bytes(bytes).map_err(|e| FormatError::invalid(path, e))?
        };
        forest.check(path)?;
        Ok(forest)
    }

    /// Write a forest (JSON when the name ends in `.json`, else binary), atomically, once it
    /// passes [`Forest::check`] (a forest its reader would refuse is not written).
    pub fn save(&self, path: &Path) -> Result<(), FormatError> {
        self.check(path)?;
        let bytes = if path.extension().is_some_and(|e| e == "json") {
            let j = JsonForest {
                species: self.species.clone(),
                instances: self
                    .instances
                    .iter()
                    .enumerate()
                    .map(|(k, i)| JsonInstance {
                        species: i.species,
                        position: i.position,
                        rotation_deg: i.rotation.to_degrees(),
                        scale: i.scale,
                        colour: self.colouring.as_ref().and_then(|c| c.value(k)),
                    })
                    .collect(),
                presort_directions: Some(self.presort.directions.len() as u32),
                terrain: self.terrain.as_ref().map(|t| JsonTerrain {
                    size: t.size,
                    origin: t.origin,
                    spacing: t.spacing,
                    heights: t.heights.clone(),
                }),
                colour: self.colouring.as_ref().map(|c| JsonColour {
                    amount: c.amount,
                    species: c.species.clone(),
                }),
            };
            serde_json::to_vec_pretty(&j).expect("a forest serialises")
        } else {
            self.to_bytes()
        };
        write_atomic(path, &bytes)
    }

    /// The binary form.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::new();
        out.extend_from_slice(MAGIC);
        let version: u32 = match (&self.colouring, &self.terrain) {
            (Some(_), _) => 3,
            (None, Some(_)) => 2,
            (None, None) => 1,
        };
        out.extend_from_slice(&version.to_le_bytes());
        out.extend_from_slice(&(self.species.len() as u32).to_le_bytes());
        for s in &self.species {
            out.extend_from_slice(&(s.len() as u32).to_le_bytes());
            out.extend_from_slice(s.as_bytes());
        }
        out.extend_from_slice(&(self.instances.len() as u32).to_le_bytes());
        out.extend_from_slice(bytemuck::cast_slice(&self.instances));
        out.extend_from_slice(&(self.presort.directions.len() as u32).to_le_bytes());
        for d in &self.presort.directions {
            out.extend_from_slice(bytemuck::cast_slice(&d.to_array()));
        }
        for o in &self.presort.orders {
            out.extend_from_slice(bytemuck::cast_slice(o));
        }
        if version == 3 {
            let flags = if self.terrain.is_some() {
                FLAG_TERRAIN | FLAG_COLOUR
            } else {
                FLAG_COLOUR
            };
            out.extend_from_slice(&flags.to_le_bytes());
        }
        if let Some(t) = &self.terrain {
            out.extend_from_slice(TERRAIN_MAGIC);
            t.write_to(&mut out);
        }
        if let Some(c) = &self.colouring {
            out.extend_from_slice(COLOUR_MAGIC);
            out.extend_from_slice(&c.amount.to_le_bytes());
            for s in &c.species {
                out.extend_from_slice(bytemuck::cast_slice(&species_colour_words(s)));
            }
            out.extend_from_slice(&(c.explicit.len() as u32).to_le_bytes());
            out.extend_from_slice(bytemuck::cast_slice(&c.explicit));
        }
        out
    }

    /// Parse the binary form; the error says what is wrong.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, String> {
        let mut r = Reader { bytes, at: 0 };
        if r.take(4)? != MAGIC {
            return Err("not a forest file (missing the FRST header)".into());
        }
        let version = r.u32()?;
        if !(1..=FOREST_VERSION).contains(&version) {
            return Err(format!(
                "forest version {version} but this program reads versions 1 to {FOREST_VERSION}"
            ));
        }
        let ns = r.u32()? as usize;
        let mut species = Vec::with_capacity(ns.min(1024));
        for _ in 0..ns {
            let len = r.u32()? as usize;
            let s = std::str::from_utf8(r.take(len)?)
                .map_err(|_| "a species name is not UTF-8".to_string())?;
            species.push(s.to_string());
        }
        let n = r.u32()? as usize;
        if n > MAX_INSTANCES {
            return Err(format!(
                "{n} instances, more than the supported {MAX_INSTANCES}"
            ));
        }
        let instances: Vec<Instance> = bytemuck::pod_collect_to_vec(r.take(n * 24)?);
        let k = r.u32()? as usize;
        if k == 0 || k > 256 {
            return Err(format!("{k} presort directions (must be 1 to 256)"));
        }
        let dirs: Vec<f32> = bytemuck::pod_collect_to_vec(r.take(k * 12)?);
        let directions = dirs.chunks_exact(3).map(Vec3::from_slice).collect();
        let mut orders = Vec::with_capacity(k);
        for _ in 0..k {
            orders.push(bytemuck::pod_collect_to_vec(r.take(n * 4)?));
        }
        let flags = match version {
            1 => 0,
            2 => FLAG_TERRAIN,
            _ => {
                let f = r.u32()?;
                if f & !(FLAG_TERRAIN | FLAG_COLOUR) != 0 || f & FLAG_COLOUR == 0 {
                    return Err(format!(
                        "version 3 flags {f:#x}: 1 (terrain) and 2 (colouring, required) are the \
                         only ones"
                    ));
                }
                f
            }
        };
        let terrain = if flags & FLAG_TERRAIN != 0 {
            if r.take(4)? != TERRAIN_MAGIC {
                return Err(format!(
                    "a version {version} forest without its TERR section"
                ));
            }
            let t = Terrain::read_from(|n| r.take(n).map(<[u8]>::to_vec))
                .map_err(|e| format!("terrain: {e}"))?;
            Some(t)
        } else {
            None
        };
        let colouring = if flags & FLAG_COLOUR != 0 {
            if r.take(4)? != COLOUR_MAGIC {
                return Err("a version 3 forest without its TINT section".into());
            }
            let amount = r.f32()?;
            let words: Vec<f32> = bytemuck::pod_collect_to_vec(r.take(ns * 64)?);
            let species = words.chunks_exact(16).map(species_colour).collect();
            let m = r.u32()? as usize;
            if m != 0 && m != n {
                return Err(format!(
                    "{m} explicit colour values for {n} instances (must be 0 or one each)"
                ));
            }
            let explicit = bytemuck::pod_collect_to_vec(r.take(m * 4)?);
            Some(Colouring {
                amount,
                species,
                explicit,
            })
        } else {
            None
        };
        if r.at != bytes.len() {
            return Err(format!(
                "{} bytes of trailing data after the {}",
                bytes.len() - r.at,
                if colouring.is_some() {
                    "colouring"
                } else if terrain.is_some() {
                    "terrain"
                } else {
                    "presorts"
                }
            ));
        }
        Ok(Self {
            species,
            instances,
            presort: Presort { directions, orders },
            terrain,
            colouring,
        })
    }

    /// Largest distance from the origin (metres) of any instance position, and of the
    /// terrain's corners at its highest and lowest heights.
    pub fn extent(&self) -> f32 {
        let trees = self
            .instances
            .iter()
            .map(|i| Vec3::from_array(i.position).length())
            .fold(0.0, f32::max);
        let ground = self.terrain.as_ref().map_or(0.0, |t| {
            let ([x0, z0], [x1, z1]) = t.bounds();
            let (lo, hi) = t.height_range();
            let (x, z) = (x0.abs().max(x1.abs()), z0.abs().max(z1.abs()));
            Vec3::new(x, lo.abs().max(hi.abs()), z).length()
        });
        trees.max(ground)
    }

    /// Height of the ground at world (x, z): the terrain's, or 0 without one (metres).
    pub fn ground_height(&self, x: f32, z: f32) -> f32 {
        crate::terrain::ground_height(self.terrain.as_ref(), x, z)
    }

    /// The far-plane distance (metres) every front end uses for a camera at `eye`: three
    /// extents plus 100 m, or twice the eye's distance from the origin plus 100 m when that is
    /// farther, so that every tree and the ground around it are inside the frustum.
    pub fn far_plane(&self, eye: Vec3) -> f32 {
        far_plane(self.extent(), eye)
    }
}

/// [`Forest::far_plane`] for a forest of extent `extent` (metres from the origin).
pub fn far_plane(extent: f32, eye: Vec3) -> f32 {
    (extent * 3.0 + 100.0).max(eye.length() * 2.0 + 100.0)
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or_else(|| {
            format!(
                "truncated: needs {n} bytes at offset {}, the file has {}",
                self.at,
                self.bytes.len()
            )
        })?;
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }
    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().unwrap()))
    }
    fn f32(&mut self) -> Result<f32, String> {
        self.u32().map(f32::from_bits)
    }
}

/// A species' colours as the binary form's 16 words.
fn species_colour_words(s: &SpeciesColour) -> [f32; 16] {
    let k = |k: crate::colour::SeasonKey| [k.tint[0], k.tint[1], k.tint[2], k.strength];
    let mut w = [0.0; 16];
    w[..4].copy_from_slice(&[s.hue_deg, s.saturation, s.brightness, s.bark]);
    w[4..8].copy_from_slice(&k(s.spring));
    w[8..12].copy_from_slice(&k(s.autumn));
    w[12..].copy_from_slice(&k(s.late_autumn));
    w
}

/// [`species_colour_words`] read back (`w` holds 16 words).
fn species_colour(w: &[f32]) -> SpeciesColour {
    let k = |o: usize| crate::colour::SeasonKey {
        tint: [w[o], w[o + 1], w[o + 2]],
        strength: w[o + 3],
    };
    SpeciesColour {
        hue_deg: w[0],
        saturation: w[1],
        brightness: w[2],
        bark: w[3],
        spring: k(4),
        autumn: k(8),
        late_autumn: k(12),
    }
}

/// Write `bytes` to `path` through a temporary sibling and a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), FormatError> {
    crate::atomic::write_bytes(path, bytes)
}

#[cfg(test)]
mod tests;
