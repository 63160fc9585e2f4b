//! The WGSL of every pass, composed from named modules: one file per stage under `shaders/`,
//! each naming the modules it needs on `#import NAME` lines at its top. [`Composer`] puts a
//! shader module together from its roots: every module a root imports, depth first, each
//! once and before the module that imports it, with the `#import` lines removed. Nothing here
//! touches the GPU.
//!
//! Two imports are slots that a module's user fills ([`Composer::fill`]): `shadow` (the sun's
//! shadow lookups: [`SHADOW_ON_WGSL`], the default, or [`SHADOW_OFF_WGSL`]) and `count` (the
//! fragment-count hooks: [`COUNT_OFF_WGSL`], the default, or [`COUNT_ON_WGSL`]).
//!
//! This is the import model of naga_oil (Bevy's composer) and WESL, written here because
//! neither can be used: naga_oil is not in this machine's registry, and the WESL there (0.6)
//! needs Rust 1.97, above the project's 1.95. A crate that adds modules (the baselines') calls
//! [`Composer::with_module`].

/// The WGSL every module starts with: the camera, the scene's structs, the shared helpers.
pub const COMMON_WGSL: &str = include_str!("../shaders/common.wgsl");
/// The ground's pattern (soil and moss) as pure WGSL functions of world (x, z), no bindings:
/// `ground_moss(xz) -> f32`. The environment uses it; a host drawing its own ground may too.
pub const GROUND_WGSL: &str = include_str!("../shaders/ground.wgsl");
/// The environment (sky, ground, terrain) and the haze every method's fragments go through
/// (in a module that declares `camera`).
pub const ENVIRONMENT_WGSL: &str = include_str!("../shaders/environment.wgsl");
/// The compute passes' bindings.
pub const BINDINGS_WGSL: &str = include_str!("../shaders/bindings.wgsl");
/// Where a quad lies on screen (refinement's edge lengths).
pub const QUAD_GEOMETRY_WGSL: &str = include_str!("../shaders/quad_geometry.wgsl");
/// The order-preserving prefix sums fused into the passes.
pub const SCAN_WGSL: &str = include_str!("../shaders/scan.wgsl");
/// Pass 1, cull.
pub const CULL_WGSL: &str = include_str!("../shaders/cull.wgsl");
/// Pass 2, refine.
pub const REFINE_WGSL: &str = include_str!("../shaders/refine.wgsl");
/// Pass 3, draw (the environment, then the stream's quads).
pub const DRAW_WGSL: &str = include_str!("../shaders/draw.wgsl");
/// The sun's shadow lookups against the cascades' maps, bound as group 2 (see
/// [`crate::shadow`]): `sun_shadow(world, normal)` and `tree_shadow(point, sphere)`.
pub const SHADOW_ON_WGSL: &str = include_str!("../shaders/shadow_on.wgsl");
/// The same lookups for a module drawn without shadow maps: every point lit.
pub const SHADOW_OFF_WGSL: &str = include_str!("../shaders/shadow_off.wgsl");
/// The light views' casting pass (imports the draw module).
pub const CAST_WGSL: &str = include_str!("../shaders/cast.wgsl");
/// The fragment-count hooks that do nothing.
pub const COUNT_OFF_WGSL: &str = include_str!("../shaders/count_off.wgsl");
/// The fragment-count hooks that count (group 1: see [`crate::fragments`]).
pub const COUNT_ON_WGSL: &str = include_str!("../shaders/count_on.wgsl");
/// The overdraw view's heat map (a module of its own).
pub const OVERDRAW_WGSL: &str = include_str!("../shaders/overdraw.wgsl");
/// Where the frame's wind moves a tree's points (`swayed`, `wind_reach_now`; in a module that
/// declares `camera`).
pub const WIND_WGSL: &str = include_str!("../shaders/wind.wgsl");
/// Each tree's own colour and the seasons (`tree_albedo`, `tint_key`; in a module that
/// declares `camera`; mirrors [`forest_format::colour`]).
pub const TINT_WGSL: &str = include_str!("../shaders/tint.wgsl");

/// The runtime's modules by the names `#import` lines give.
pub const MODULES: [(&str, &str); 17] = [
    ("common", COMMON_WGSL),
    ("ground", GROUND_WGSL),
    ("environment", ENVIRONMENT_WGSL),
    ("bindings", BINDINGS_WGSL),
    ("quad_geometry", QUAD_GEOMETRY_WGSL),
    ("scan", SCAN_WGSL),
    ("cull", CULL_WGSL),
    ("refine", REFINE_WGSL),
    ("draw", DRAW_WGSL),
    ("shadow_on", SHADOW_ON_WGSL),
    ("shadow_off", SHADOW_OFF_WGSL),
    ("cast", CAST_WGSL),
    ("count_off", COUNT_OFF_WGSL),
    ("count_on", COUNT_ON_WGSL),
    ("overdraw", OVERDRAW_WGSL),
    ("wind", WIND_WGSL),
    ("tint", TINT_WGSL),
];

/// Why a shader module could not be composed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ShaderError {
    /// An `#import` (or a root, or a slot's filling) names no module.
    #[error("WGSL module {module:?} imports {import:?}, which is no module (known: {known})")]
    UnknownImport {
        /// The module whose line it is ("" for a root).
        module: String,
        /// The name imported.
        import: String,
        /// The modules and slots known, comma-separated.
        known: String,
    },
    /// Modules that import each other in a circle.
    #[error("WGSL modules import each other in a circle: {0}")]
    Circle(String),
}

/// The modules `#import` lines of `source` name, in order.
pub fn imports(source: &str) -> impl Iterator<Item = &str> {
    source
        .lines()
        .filter_map(|l| l.trim().strip_prefix("#import "))
        .map(str::trim)
}

/// Named WGSL modules and the slots' fillings: composes shader modules ([`Composer::compose`]).
#[derive(Clone, Debug)]
pub struct Composer<'a> {
    modules: Vec<(&'a str, &'a str)>,
    slots: Vec<(&'a str, &'a str)>,
}

impl<'a> Composer<'a> {
    /// The runtime's [`MODULES`], the slots filled by default: `shadow` with `shadow_on`,
    /// `count` with `count_off`.
    pub fn runtime() -> Self {
        Composer {
            modules: MODULES.to_vec(),
            slots: vec![("shadow", "shadow_on"), ("count", "count_off")],
        }
    }

    /// With one more module `name` (replacing one of that name).
    pub fn with_module(mut self, name: &'a str, source: &'a str) -> Self {
        self.modules.retain(|(n, _)| *n != name);
        self.modules.push((name, source));
        self
    }

    /// With the slot `slot` filled by the module `module` (a module's `#import slot` then
    /// imports it).
    pub fn fill(mut self, slot: &'a str, module: &'a str) -> Self {
        self.slots.retain(|(s, _)| *s != slot);
        self.slots.push((slot, module));
        self
    }

    /// The module `name` is known by after the slots are filled.
    fn resolve<'n>(&self, name: &'n str) -> &'n str
    where
        'a: 'n,
    {
        self.slots
            .iter()
            .find(|(s, _)| *s == name)
            .map_or(name, |(_, m)| m)
    }

    fn source(&self, importer: &str, name: &str) -> Result<&'a str, ShaderError> {
        let resolved = self.resolve(name);
        self.modules
            .iter()
            .find(|(n, _)| *n == resolved)
            .map(|(_, s)| *s)
            .ok_or_else(|| ShaderError::UnknownImport {
                module: importer.to_string(),
                import: name.to_string(),
                known: self
                    .modules
                    .iter()
                    .map(|(n, _)| *n)
                    .chain(self.slots.iter().map(|(s, _)| *s))
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }

    /// The shader module of `roots`: each root after every module it imports (depth first,
    /// each module once), with the `#import` lines removed.
    pub fn compose(&self, roots: &[&str]) -> Result<String, ShaderError> {
        let mut order: Vec<&str> = Vec::new();
        let mut path: Vec<&str> = Vec::new();
        for root in roots {
            self.visit("", root, &mut order, &mut path)?;
        }
        let mut out = String::new();
        for name in order {
            let source = self.source("", name)?;
            for line in source.split_inclusive('\n') {
                if !line.trim().starts_with("#import ") {
                    out.push_str(line);
                }
            }
        }
        Ok(out)
    }

    fn visit<'n>(
        &self,
        importer: &str,
        name: &'n str,
        order: &mut Vec<&'n str>,
        path: &mut Vec<&'n str>,
    ) -> Result<(), ShaderError>
    where
        'a: 'n,
    {
        let resolved = self.resolve(name);
        let source = self.source(importer, name)?;
        if order.contains(&resolved) {
            return Ok(());
        }
        if path.contains(&resolved) {
            path.push(resolved);
            return Err(ShaderError::Circle(path.join(" → ")));
        }
        path.push(resolved);
        for import in imports(source) {
            self.visit(resolved, import, order, path)?;
        }
        path.pop();
        order.push(resolved);
        Ok(())
    }

    /// [`Composer::compose`] for a crate's own modules, fixed when it was built (its tests
    /// compose each one).
    ///
    /// # Panics
    /// On a [`ShaderError`]: an import that names no module, or a circle, in the crate's own
    /// WGSL files (never in its input).
    pub fn composed(&self, roots: &[&str]) -> String {
        self.compose(roots)
            .unwrap_or_else(|e| panic!("the runtime's WGSL modules compose: {e}"))
    }
}

/// The compute module's source (cull and refine, with the prefix sums and bindings).
pub fn compute_source() -> String {
    Composer::runtime().composed(&["cull", "refine"])
}

/// The draw module's source (without fragment counting, with the sun's shadow lookups).
pub fn draw_source() -> String {
    Composer::runtime().composed(&["draw"])
}

/// The draw module's source with the fragment-count hooks that count.
pub fn counting_draw_source() -> String {
    Composer::runtime()
        .fill("count", "count_on")
        .composed(&["draw"])
}

/// The light views' casting module's source (the draw module with the casting pass).
pub fn cast_source() -> String {
    Composer::runtime().composed(&["cast"])
}

#[cfg(test)]
mod tests;
