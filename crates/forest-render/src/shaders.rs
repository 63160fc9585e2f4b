//! The WGSL sources of every pass, as the modules are put together from them (one file per
//! stage under `shaders/`, `common.wgsl` first). Nothing here touches the GPU.

/// The WGSL every module starts with: the camera, the scene's structs, the shared helpers
/// (other crates' shaders that read the camera, such as the baselines', start with it too).
pub const COMMON_WGSL: &str = include_str!("../shaders/common.wgsl");
/// The ground's pattern (soil and moss) as pure WGSL functions of world (x, z), no bindings:
/// `ground_moss(xz) -> f32`. The environment uses it; a host drawing its own ground may too.
pub const GROUND_WGSL: &str = include_str!("../shaders/ground.wgsl");
/// The environment (sky, ground, terrain) and the haze every method's fragments go through
/// (after a module declaring `camera`, and [`GROUND_WGSL`]).
pub const ENVIRONMENT_WGSL: &str = include_str!("../shaders/environment.wgsl");

/// WGSL of the compute passes.
pub const COMPUTE_WGSL: [&str; 6] = [
    COMMON_WGSL,
    include_str!("../shaders/bindings.wgsl"),
    include_str!("../shaders/quad_geometry.wgsl"),
    include_str!("../shaders/scan.wgsl"),
    include_str!("../shaders/cull.wgsl"),
    include_str!("../shaders/refine.wgsl"),
];

/// WGSL of the draw pass (without fragment counting: [`COUNT_OFF_WGSL`] closes it), with the
/// sun's shadow lookups ([`SHADOW_ON_WGSL`]).
pub const DRAW_WGSL: [&str; 6] = [
    COMMON_WGSL,
    include_str!("../shaders/draw.wgsl"),
    GROUND_WGSL,
    ENVIRONMENT_WGSL,
    SHADOW_ON_WGSL,
    COUNT_OFF_WGSL,
];

/// The sun's shadow lookups against the cascades' maps, bound as group 2
/// (`shaders/shadow_on.wgsl`; see [`crate::shadow_maps`]): `sun_shadow(world, normal)` and
/// `tree_shadow(point, sphere)`.
pub const SHADOW_ON_WGSL: &str = include_str!("../shaders/shadow_on.wgsl");

/// The same lookups for a module drawn without shadow maps: every point lit
/// (`shaders/shadow_off.wgsl`). Every module that includes [`ENVIRONMENT_WGSL`] also includes
/// this or [`SHADOW_ON_WGSL`].
pub const SHADOW_OFF_WGSL: &str = include_str!("../shaders/shadow_off.wgsl");

/// The light views' casting pass (`shaders/cast.wgsl`), appended to [`DRAW_WGSL`].
pub const CAST_WGSL: &str = include_str!("../shaders/cast.wgsl");

/// The fragment-count hooks that do nothing (`shaders/count_off.wgsl`): every draw module
/// that shades tree fragments ends with this or [`COUNT_ON_WGSL`].
pub const COUNT_OFF_WGSL: &str = include_str!("../shaders/count_off.wgsl");

/// The fragment-count hooks that count (`shaders/count_on.wgsl`, group 1: see
/// [`crate::fragments`]).
pub const COUNT_ON_WGSL: &str = include_str!("../shaders/count_on.wgsl");

/// The module of `parts` (a draw module's sources, [`COUNT_OFF_WGSL`] among them) with the
/// counting hooks in place of the empty ones.
pub fn counting_source(parts: &[&str]) -> String {
    parts
        .iter()
        .map(|p| {
            if *p == COUNT_OFF_WGSL {
                COUNT_ON_WGSL
            } else {
                p
            }
        })
        .collect()
}

/// The compute module's source.
pub fn compute_source() -> String {
    COMPUTE_WGSL.concat()
}

/// The draw module's source.
pub fn draw_source() -> String {
    DRAW_WGSL.concat()
}
