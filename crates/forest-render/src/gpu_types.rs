//! Host mirrors of the WGSL structs in `shaders/common.wgsl`, `bindings.wgsl` and `draw.wgsl`.
//! A test reflects the WGSL with naga and checks every size and member offset against these.

use bytemuck::{Pod, Zeroable};

/// The camera, the frame's light and its sun's shadow cascades: the only data written to the
/// GPU per frame (752 bytes; a stream with shadows writes one per light view after it, in the
/// same write, see [`crate::shadow`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuCamera {
    /// Projection × view, column-major.
    pub view_proj: [[f32; 4]; 4],
    /// Eye position (world, metres).
    pub eye: [f32; 3],
    /// The refinement threshold ε (pixels).
    pub epsilon: f32,
    /// Unit view direction (world).
    pub forward: [f32; 3],
    /// The quad stream's far span, in units of ε
    /// ([`crate::options::StreamOptions::far_span`]).
    pub far_span: f32,
    /// Viewport width and height in pixels.
    pub viewport: [f32; 2],
    /// The draw pass's debug view ([`crate::options::DebugView`] as a number, 0 = off).
    pub debug_view: f32,
    /// The quad stream's flags ([`crate::options::StreamOptions::flags`]).
    pub stream_flags: f32,
    /// Frustum planes `n·p + d ≥ 0` inside, unit normals: left, right, bottom, top, near, far.
    pub planes: [[f32; 4]; 6],
    /// Which form draws each tree (see [`crate::forms::quad_share`]): metres, focal pixels
    /// (times each tree's switch unit), band fraction, jitter fraction.
    pub forms: [f32; 4],
    /// Unit direction towards the sun (world).
    pub sun: [f32; 3],
    /// Scale of every outgoing radiance ([`forest_format::shading::Lighting::exposure`]).
    pub exposure: f32,
    /// Sun irradiance, linear RGB (`w` unused).
    pub sun_colour: [f32; 4],
    /// Sky irradiance on a surface facing up, linear RGB (`w` unused).
    pub sky_light: [f32; 4],
    /// Ground-bounce irradiance on a surface facing down, linear RGB (`w` unused).
    pub ground_light: [f32; 4],
    /// World → shadow clip of each sun cascade (orthographic, depth 0 towards the sun, 1
    /// away), column-major; the first `shadow_cascades` are used.
    pub shadow: [[[f32; 4]; 4]; 4],
    /// Where each cascade ends: view depth along `forward` (metres) of its far split.
    pub shadow_splits: [f32; 4],
    /// Each cascade's texel (metres across).
    pub shadow_texel: [f32; 4],
    /// Each cascade's depth bias (shadow-clip depth units, subtracted from a receiver's).
    pub shadow_bias: [f32; 4],
    /// Shadow cascades in use (0: no shadows).
    pub shadow_cascades: f32,
    /// The shadow maps' side in texels.
    pub shadow_side: f32,
    /// The receivers' offset towards the sun and along their normal, in texels.
    pub shadow_offset: f32,
    /// 1 when the maps are reverse-Z (a host's), else 0.
    pub shadow_reverse_z: f32,
    /// The eye (world) whose distances choose each tree's form and level of detail: the
    /// view's own eye, and in a light view the eye of the view it casts for, so that every
    /// tree casts with the form it is drawn in ([`crate::shadow::light_camera`]); `w` unused.
    pub form_eye: [f32; 4],
    /// A light view's receiver region (see [`crate::shadow::caster_planes`]): planes
    /// `n·p + d ≥ 0` of the view slice whose shadows this light view casts, unit normals. A
    /// tree casts only when its bounding sphere, swept away from the sun (`sun`) down to
    /// `caster_floor.x`, stays inside every one; all zero (a view camera, a host's light)
    /// passes every tree.
    pub casters: [[f32; 4]; 6],
    /// `x`: the lowest receiver (world height, metres): no shadow falls below it; `y`: the
    /// longest sweep (metres), whatever the sun's height; `z`, `w` unused.
    pub caster_floor: [f32; 4],
    /// The frame's wind ([`forest_format::wind::Wind::uniform`]): the unit direction it blows
    /// towards (world x, z), its mean speed (m/s; 0: calm, nothing moves) and gustiness.
    pub wind: [f32; 4],
    /// `x`: the wind's instant (seconds); `y`, `z`, `w` unused.
    pub wind_time: [f32; 4],
    /// The frame's season ([`forest_format::colour`]): `x` 1 when the leaves follow the
    /// seasons' ramp (0: the models' own colours), `y` where on it (0 spring to 1 late
    /// autumn); `z`, `w` unused.
    pub season: [f32; 4],
}

impl GpuCamera {
    /// Write the frame's wind into the camera.
    pub fn set_wind(&mut self, w: &forest_format::wind::Wind) {
        [self.wind, self.wind_time] = w.uniform();
    }

    /// The wind's uniform vectors, as [`forest_format::wind::swayed`] takes them.
    pub fn wind_uniform(&self) -> [[f32; 4]; 2] {
        [self.wind, self.wind_time]
    }

    /// Write the frame's season into the camera (`None`: the models' own colours).
    pub fn set_season(&mut self, season: Option<f32>) {
        self.season = match season {
            Some(s) => [1.0, s, 0.0, 0.0],
            None => [0.0; 4],
        };
    }

    /// The season the camera carries, as [`forest_format::colour::tree_albedo`] takes it
    /// (negative: none).
    pub fn season_position(&self) -> f32 {
        if self.season[0] > 0.0 {
            self.season[1]
        } else {
            -1.0
        }
    }

    /// Write the frame's light into the camera.
    pub fn set_light(&mut self, l: &forest_format::shading::Lighting) {
        let d = l.sun_dir.normalize_or(glam::Vec3::Y);
        self.sun = d.to_array();
        self.exposure = l.exposure;
        self.sun_colour = l.sun.extend(0.0).to_array();
        self.sky_light = l.sky.extend(0.0).to_array();
        self.ground_light = l.ground.extend(0.0).to_array();
    }
}

/// A tree instance on the GPU (32 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuInstance {
    /// Base position (world).
    pub position: [f32; 3],
    /// Uniform scale.
    pub scale: f32,
    /// cos of the rotation about +Y.
    pub cos_rot: f32,
    /// sin of the rotation about +Y.
    pub sin_rot: f32,
    /// Species index.
    pub species: u32,
    /// The tree's colour code: 0 for the hash of its index, else its explicit value's
    /// ([`forest_format::colour::explicit_code`]).
    pub colour: u32,
}

/// Per-species table entry (144 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuSpecies {
    /// Bounding sphere centre (object space) and radius.
    pub sphere: [f32; 4],
    /// Sampling directions.
    pub directions: u32,
    /// Slabs per direction.
    pub slabs: u32,
    /// Quad levels.
    pub levels: u32,
    /// First entry in the frame table.
    pub dir_base: u32,
    /// First entry in the direction-triangle table.
    pub tri_base: u32,
    /// Direction triangles for views from above (at `tri_base`).
    pub tri_count: u32,
    /// First layer in the colour array and the root table.
    pub layer_base: u32,
    /// First node in the node texture.
    pub node_base: u32,
    /// Direction triangles for views from below, right after the upper ones (0: views from
    /// below are clamped onto the horizon).
    pub lower_tri_count: u32,
    /// Slab image side in texels (the same for every species of a scene).
    pub resolution: u32,
    /// The hybrid's switch unit ([`crate::forms::switch_unit`], metres per focal pixel at
    /// scale 1).
    pub switch_unit: f32,
    /// Optical depth per voxel length of the species' opacity-volume code 255
    /// ([`forest_format::atlas::OpacityInfo::max_depth`]; 0: no self-shadowing).
    pub opacity_depth: f32,
    /// The species' colours in the forest ([`forest_format::colour::TreeColour`]).
    pub colour: forest_format::colour::TreeColour,
}

/// A sampling direction's frame (48 bytes; `w` unused).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuFrame {
    /// Towards the sampling camera.
    pub dir: [f32; 4],
    /// Image x axis.
    pub right: [f32; 4],
    /// Image up axis.
    pub up: [f32; 4],
}

/// One quad of the stream (16 bytes); see `shaders/common.wgsl` for the bit layout.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Pod, Zeroable)]
pub struct Quad {
    /// Instance index.
    pub instance: u32,
    /// Global node index.
    pub node: u32,
    /// level | x << 4 | y << 16 | slab << 28.
    pub pos: u32,
    /// direction (8 bits) | lo << 8 | hi << 20: the aspect's share `[lo, hi)` of the tree's
    /// blend, cumulative over its aspects in drawing order, in units of 1/[`WEIGHT_ONE`].
    pub dir_weight: u32,
}

/// The whole of a tree's blend in the units of [`Quad::dir_weight`]: 4095 (12 bits).
pub const WEIGHT_ONE: u32 = 4095;

impl Quad {
    /// Pack the position word.
    pub fn pack_pos(level: u32, x: u32, y: u32, slab: u32) -> u32 {
        level | (x << 4) | (y << 16) | (slab << 28)
    }
    /// The position word of a far tree's composited quad: level 0 at column 1, which level 0
    /// lacks, stands for all the tree's slabs drawn as one quad (see `StreamOptions::
    /// far_composite`); its node is the root of the front-most slab present.
    pub const COMPOSITE_POS: u32 = 1 << 4;
    /// Whether this is a far tree's composited quad ([`Self::COMPOSITE_POS`]).
    pub fn composite(&self) -> bool {
        self.pos == Self::COMPOSITE_POS
    }
    /// Quad level.
    pub fn level(&self) -> u32 {
        self.pos & 15
    }
    /// Quad column.
    pub fn x(&self) -> u32 {
        (self.pos >> 4) & 4095
    }
    /// Quad row.
    pub fn y(&self) -> u32 {
        (self.pos >> 16) & 4095
    }
    /// Slab.
    pub fn slab(&self) -> u32 {
        self.pos >> 28
    }
    /// Pack the direction word: direction `dir` (< 256) with share `[lo, hi)` (≤ 4095).
    pub fn pack_dir(dir: u32, lo: u32, hi: u32) -> u32 {
        dir | (lo << 8) | (hi << 20)
    }
    /// Direction index within the species.
    pub fn dir(&self) -> u32 {
        self.dir_weight & 255
    }
    /// The aspect's share `[lo, hi)` of its tree's blend, in 1/[`WEIGHT_ONE`].
    pub fn share(&self) -> (u32, u32) {
        ((self.dir_weight >> 8) & 4095, self.dir_weight >> 20)
    }
    /// Alpha of the aspect when composited "over" the earlier ones: `(hi − lo) / hi`.
    pub fn weight(&self) -> f32 {
        let (lo, hi) = self.share();
        if hi == 0 {
            0.0
        } else {
            (hi - lo) as f32 / hi as f32
        }
    }
}

/// Composited quads leading a stream whose level 0 had `composites` of them and dropped its
/// first `overflow_cull` quads for room (`kept_composites` in common.wgsl).
pub fn kept_composites(composites: u32, overflow_cull: u32) -> u32 {
    composites.saturating_sub(overflow_cull)
}

/// Frame state written by the GPU (100 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct GpuState {
    /// Chosen presort direction.
    pub presort: u32,
    /// Quads in the stream being refined; after the frame, in the final stream.
    pub n: u32,
    /// Last scan total.
    pub total: u32,
    /// Refine bookkeeping.
    pub pmin: u32,
    /// Level-0 quads dropped because the stream was full.
    pub overflow_cull: u32,
    /// Quads left unrefined because the stream was full (summed over iterations).
    pub overflow_refine: u32,
    /// Trees passing the frustum test.
    pub visible: u32,
    /// Quads drawn.
    pub quads: u32,
    /// Far trees' composited quads at level 0 (before any were dropped for room); those kept
    /// lead the stream.
    pub composites: u32,
    /// Quads per level in the final stream.
    pub per_level: [u32; 16],
}

/// Indirect arguments (64 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct GpuArgs {
    /// Per-item dispatches: one workgroup per 256 plain quads.
    pub items: [u32; 4],
    /// Per-block dispatches: one workgroup per 512 plain quads.
    pub blocks: [u32; 4],
    /// Draw of the plain quads: vertex count, instance count, first vertex, first instance.
    pub draw: [u32; 4],
    /// Draw of the composited quads (the stream's first).
    pub draw_composite: [u32; 4],
}

/// Scene constants (16 bytes), written once.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct SceneConsts {
    /// Instances.
    pub instances: u32,
    /// Presort directions.
    pub presort_dirs: u32,
    /// Quad capacity of each stream buffer.
    pub capacity: u32,
    /// Species.
    pub species: u32,
}

/// The environment (160 bytes), written once: what `shaders/environment.wgsl` draws behind the
/// trees (sky, ground, terrain) and the haze every method applies (see
/// [`crate::options::Atmosphere`] and the terrain, `terrain.rs`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuEnvironment {
    /// The ground's second albedo, moss (linear RGB); `w` unused.
    pub ground: [f32; 4],
    /// Sky colour at the horizon and haze colour (linear RGB); `w`: haze extinction per metre
    /// (0: no haze).
    pub horizon: [f32; 4],
    /// Sky colour at the zenith (linear RGB); `w`: the haze's falloff per metre of height
    /// (0: homogeneous).
    pub zenith: [f32; 4],
    /// `x`: cosine of the sun disc's angular radius (above 1: no disc); `yzw` unused. The
    /// sun's direction and colour are the frame's light, in [`GpuCamera`].
    pub sun: [f32; 4],
    /// The ground's first albedo, soil (linear RGB); `w` unused.
    pub albedo: [f32; 4],
    /// The terrain's grid: world x and z of sample (0, 0), metres between samples, and 1 when
    /// there is a terrain (0: flat ground only).
    pub terrain: [f32; 4],
    /// Samples along x and z of the terrain's grid; `zw` unused.
    pub terrain_size: [u32; 4],
}
