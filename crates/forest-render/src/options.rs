//! What a quad stream is asked to do: the host's target formats, the stream's sizing, and the
//! run-time choices (background, debug views, aspect blending) that travel in the camera
//! uniform.

/// The draw's thresholds: the coverage from which a quad fragment writes depth, and the
/// opaque share from which a node's quad is drawn in the opaque pass.
pub use crate::passes::draw::{DEPTH_WRITE_ALPHA, OPAQUE_SHARE_MIN};
use forest_format::shading::Lighting;

use crate::gpu_types::WEIGHT_ONE;

/// What the trees are drawn over.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Background {
    /// The sky and an endless ground plane at y = 0 ([`Atmosphere`]; the demo).
    #[default]
    Sky,
    /// Transparent black, no ground: the alpha channel is the trees' coverage (for metrics).
    Transparent,
}

impl Background {
    /// The colour a frame is cleared to.
    pub fn clear_colour(self) -> wgpu::Color {
        match self {
            Background::Sky => SKY,
            Background::Transparent => wgpu::Color::TRANSPARENT,
        }
    }
}

/// Options of a renderer: the host's targets and what sizes the stream.
#[derive(Clone, Debug, PartialEq)]
pub struct RendererOptions {
    /// Colour target format.
    pub format: wgpu::TextureFormat,
    /// Depth target format (any depth format; the stream tests against it and writes it only
    /// in the ground).
    pub depth_format: wgpu::TextureFormat,
    /// Samples per pixel of the colour and depth targets (1, or the host's MSAA count).
    pub sample_count: u32,
    /// Reverse-Z depth (near at 1, far at 0, as with an infinite reversed projection): the
    /// depth test becomes `GreaterEqual` and [`Background`]'s clear writes 0.
    pub reverse_z: bool,
    /// Largest viewport the renderer will draw (sizes the stream).
    pub viewport: (u32, u32),
    /// Smallest ε that will be used (sizes the stream).
    pub min_epsilon: f32,
    /// Layers of refined quads per pixel the stream's first sizing affords (see
    /// [`crate::capacity::Capacity::new`]; [`crate::QuadStream::fit`] grows it to what frames
    /// need).
    pub overdraw: f32,
    /// Explicit quad capacity (overrides the formula and is never grown; tests use small ones
    /// to force overflow).
    pub max_quads: Option<u32>,
    /// The light frames start with (the sun, sky and exposure every method shades with):
    /// `set_light` changes it for the next frames, and [`crate::FrameParams::light`] sets it
    /// per frame. Nothing of it is baked.
    pub lighting: Lighting,
    /// Sky and ground, or transparent.
    pub background: Background,
    /// Sky colours, sun disc and distance haze (no haze by default).
    pub atmosphere: Atmosphere,
    /// Refine the stream (the method). `false` draws the level-0 quads only: the static
    /// impostor baseline (each tree as its 1–3 blended slab images, never subdivided).
    pub refine: bool,
    /// After the blended quads, draw them again with colour writes off to write the depth of
    /// their fragments at least [`crate::passes::draw::DEPTH_WRITE_ALPHA`] opaque, so that
    /// a host's later passes (transparent objects, depth-of-field, fog) see the trees. Off by
    /// default: the stream itself needs no depth, and the second draw costs fill.
    pub write_depth: bool,
}

impl Default for RendererOptions {
    fn default() -> Self {
        Self {
            format: wgpu::TextureFormat::Rgba8UnormSrgb,
            depth_format: wgpu::TextureFormat::Depth32Float,
            sample_count: 1,
            reverse_z: false,
            viewport: (800, 600),
            min_epsilon: 8.0,
            overdraw: 4.0,
            max_quads: None,
            lighting: Lighting::with_sun(30.0, 55.0),
            background: Background::Sky,
            atmosphere: Atmosphere::CLEAR,
            refine: true,
            write_depth: false,
        }
    }
}

/// What the draw pass shows: the stream's colours, or one of the viewer's debug views.
/// Takes effect with the next camera write (it travels in the camera uniform's `viewport.z`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DebugView {
    /// The textured quads (the product).
    #[default]
    Off,
    /// Every quad in the colour of its hierarchy level ([`LEVEL_COLOURS`]), times its coverage.
    Levels,
    /// Every quad in the colour of its sampling direction, blended with its aspect weight, so
    /// the mix of directions at a pixel shows the blend.
    Weights,
    /// The textured quads with their outlines drawn over them.
    Wireframe,
    /// A heat map of the tree fragments shaded per pixel, for every method: the host counts
    /// the frame ([`crate::fragments`]) and draws [`crate::fragments::OverdrawPass`] over it; the
    /// stream itself draws as [`DebugView::Off`].
    Overdraw,
}

impl DebugView {
    /// Every view, in the order the viewer cycles through them.
    pub const ALL: [DebugView; 5] = [
        DebugView::Off,
        DebugView::Levels,
        DebugView::Weights,
        DebugView::Wireframe,
        DebugView::Overdraw,
    ];

    /// The number the draw pass reads (the camera uniform's `viewport.z`); the host-drawn
    /// overdraw view is 0, the stream's own colours.
    pub fn shader_value(self) -> u32 {
        match self {
            DebugView::Overdraw => 0,
            v => v as u32,
        }
    }

    /// Short name for menus and file names.
    pub fn name(self) -> &'static str {
        match self {
            DebugView::Off => "off",
            DebugView::Levels => "levels",
            DebugView::Weights => "blend weights",
            DebugView::Wireframe => "wireframe",
            DebugView::Overdraw => "overdraw",
        }
    }
}

/// How the 1–3 aspects (sampling directions) of a tree are combined where they overlap.
///
/// The default is [`AspectBlend::Over`], chosen by measurement (`forest bench fidelity`): with
/// the gap-aware bake its union of silhouettes covers about as many pixels as the reference
/// (1.02× at 14 m from a bundled oak), while each single aspect misses what its two slabs
/// could not see from its own direction, so the dither's weighted mean of coverages falls
/// short (0.95×) and its FLIP is no better anywhere we looked.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AspectBlend {
    /// Alpha-composited "over" each other with alpha `w_a / Σ_{b ≤ a} w_b`: the weighted mean
    /// where every aspect is opaque, the union of their silhouettes elsewhere (the paper's
    /// blending).
    #[default]
    Over,
    /// Every pixel shows exactly one aspect, chosen by an ordered dither with probability equal
    /// to its weight (per tree), so the blended coverage is the weighted mean of the aspects'
    /// coverages.
    Dither,
    /// The aspect of largest weight alone (pops where the view crosses a direction).
    Nearest,
}

impl AspectBlend {
    /// Every blend, the default first.
    pub const ALL: [AspectBlend; 3] =
        [AspectBlend::Over, AspectBlend::Dither, AspectBlend::Nearest];

    /// The blend named `name` ([`AspectBlend::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|b| b.name() == name)
    }

    /// Short name for the CLI and the benchmark tables.
    pub fn name(self) -> &'static str {
        match self {
            AspectBlend::Dither => "dither",
            AspectBlend::Over => "over",
            AspectBlend::Nearest => "nearest",
        }
    }
}

/// Run-time choices of the quad stream. They travel in the camera uniform's `viewport.w` as
/// bit flags ([`StreamOptions::flags`]), so the camera stays the only per-frame upload.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StreamOptions {
    /// How overlapping aspects combine.
    pub blend: AspectBlend,
    /// Refine a quad also when its depth error (the largest distance between its drawn
    /// surface and its pixels, as a displacement along its sampling direction projected to
    /// the screen from the current view) exceeds ε. Off (the default): the paper's metric
    /// alone (projected edge length). Measured on a bundled oak at 14–30 m, the error metric
    /// buys 1–3 % lower FLIP for 2–6× the quads, where a smaller ε buys as much for fewer
    /// quads, so it is off unless asked for.
    pub depth_error: bool,
    /// Draw each quad over its node's covered box (widened by two pixels for the texture
    /// filter) instead of its whole square (see `forest_format::trim`). On (the default);
    /// off draws the untrimmed quads, for comparison.
    pub trim: bool,
    /// Draw a tree that spans less than [`Self::far_span`] × ε pixels across (a far tree: its
    /// level-0 quads are never refined) with its nearest aspect alone: one quad per slab
    /// instead of up to three. On (the default); off blends every tree's aspects and refines
    /// every tree, as the paper does.
    pub far_nearest: bool,
    /// The width below which a tree may be far, in units of ε (1 to [`FAR_SPAN_MAX`]): a tree
    /// S pixels wide with S < far_span · ε and S · sin θ < ε (θ from the view to its nearest
    /// aspect) is drawn as one aspect, its slabs composited, unrefined. Default
    /// [`FAR_SPAN_DEFAULT`], chosen by the measurements under "The far span and aspect
    /// sharpening" in docs/overdraw.md. 1 is the stream before this option: only trees
    /// narrower than ε are far.
    pub far_span: u32,
    /// Draw such a tree's slabs as one quad, composited in the fragment shader on the plane
    /// through the tree's centre (its slabs' parallax is below ε there), instead of one quad
    /// per slab. On (the default, with `far_nearest`); off draws each slab's quad.
    pub far_composite: bool,
    /// Aspect sharpening, in units of 1/[`WEIGHT_ONE`] (0 to
    /// [`SHARPEN_MAX`]): each of a tree's 1–3 blend weights loses this much (to no less than
    /// 0) and the rest are scaled back to a sum of one, so an aspect of small weight fades out
    /// continuously (no pop) instead of adding a faint layer of quads. Default
    /// [`SHARPEN_DEFAULT`] (10 %), chosen by the measurements under "The far span and aspect
    /// sharpening" in docs/overdraw.md. 0 is the paper's barycentric blend. The hybrid
    /// draws its quads with its own (`QuadStream::set_sharpen_override`).
    pub sharpen: u32,
    /// How far beyond the far span the sharpening grows, in units of the far span (1 to
    /// [`SHARPEN_REACH_MAX`]; 1: not at all): a tree narrower than `sharpen_reach` × far
    /// span × ε pixels is sharpened more the narrower it is, in [`REACH_STEPS`] steps from
    /// [`Self::sharpen`] up to [`SHARPEN_MAX`] just outside the far span, where it becomes
    /// far and keeps its nearest aspect alone. So a tree's faint aspects fade out as it
    /// recedes instead of all at once at the far span, and the small trees, which make most
    /// of a forest's layers, shade fewer. Default [`SHARPEN_REACH_DEFAULT`], chosen by the
    /// measurements under "The sharpening reach" in docs/overdraw.md. Off with
    /// [`Self::far_nearest`] off (the paper's blend of every tree).
    pub sharpen_reach: u32,
    /// The opaque pass (on by default; with [`AspectBlend::Over`] only): before the blended
    /// quads, each tree's first aspect in its front slab draws its mostly opaque nodes front to
    /// back, their opaque fragments with depth written a slab's thickness behind their
    /// surface, so that the depth test rejects what lies further behind (the tree's back
    /// slab, the trees behind), which those fragments would cover. The blended draw moves
    /// nothing, so it draws the same image as without the pass (the same fragments shaded
    /// again, over what is left behind them). It writes that depth into the host's depth
    /// target; see "The opaque pass" in docs/overdraw.md.
    pub opaque_first: bool,
}

impl Default for StreamOptions {
    fn default() -> Self {
        Self {
            blend: AspectBlend::Over,
            depth_error: false,
            trim: true,
            far_nearest: true,
            far_composite: true,
            far_span: FAR_SPAN_DEFAULT,
            sharpen: SHARPEN_DEFAULT,
            sharpen_reach: SHARPEN_REACH_DEFAULT,
            opaque_first: true,
        }
    }
}

/// Default [`StreamOptions::sharpen`]: 10 % of a weight of one.
pub const SHARPEN_DEFAULT: u32 = 410;
/// Largest [`StreamOptions::sharpen`]: below a third of one, so the largest of three weights
/// summing to one always keeps a share.
pub const SHARPEN_MAX: u32 = 1364;
/// First bit of [`StreamOptions::sharpen`] in the flags of `viewport.w`.
pub const SHARPEN_SHIFT: u32 = 8;
/// Mask of [`StreamOptions::sharpen`]'s 12 bits once shifted down by [`SHARPEN_SHIFT`].
pub const SHARPEN_MASK: u32 = 0xfff;

/// Default [`StreamOptions::sharpen_reach`].
pub const SHARPEN_REACH_DEFAULT: u32 = 8;
/// Largest [`StreamOptions::sharpen_reach`] (its 4 bits in the flags).
pub const SHARPEN_REACH_MAX: u32 = 15;
/// First bit of [`StreamOptions::sharpen_reach`] in the flags of `viewport.w` (bits 20–23:
/// the flags stay below 2²⁴, exact in the f32 that carries them).
pub const REACH_SHIFT: u32 = 20;
/// Mask of [`StreamOptions::sharpen_reach`]'s 4 bits once shifted down by [`REACH_SHIFT`].
pub const REACH_MASK: u32 = 0xf;
/// Steps of the sharpening reach: the widths span · (1 + (R − 1) · i / `REACH_STEPS`).
pub const REACH_STEPS: u32 = 16;
/// 1 / [`REACH_STEPS`], exact in binary (the GPU and the CPU reference multiply by it;
/// derived here, mirrored as a literal in `shaders/common.wgsl`).
pub const REACH_STEP: f32 = 1.0 / REACH_STEPS as f32;

/// Default [`StreamOptions::far_span`].
pub const FAR_SPAN_DEFAULT: u32 = 4;
/// Largest [`StreamOptions::far_span`].
pub const FAR_SPAN_MAX: u32 = 64;

/// Flag bits of [`StreamOptions`] in `viewport.w`; mirrored in `shaders/common.wgsl`.
pub const FLAG_DITHER: u32 = 1;
/// See [`FLAG_DITHER`].
pub const FLAG_NEAREST: u32 = 2;
/// See [`FLAG_DITHER`].
pub const FLAG_DEPTH_ERROR: u32 = 4;
/// See [`FLAG_DITHER`].
pub const FLAG_UNTRIMMED: u32 = 8;
/// See [`FLAG_DITHER`].
pub const FLAG_FAR_BLEND: u32 = 16;
/// See [`FLAG_DITHER`].
pub const FLAG_FAR_SLABS: u32 = 32;

impl StreamOptions {
    /// Write these options into a camera uniform: the flags to `viewport.w`, the far span to
    /// `forward.w` (what the stream does with every camera it is given; the CPU reference
    /// reads them from there too).
    pub fn apply(self, g: &mut crate::gpu_types::GpuCamera) {
        g.stream_flags = self.flags() as f32;
        g.far_span = self.far_span as f32;
    }

    /// Refuse options out of their ranges, naming the option.
    pub fn validate(self) -> Result<(), crate::RenderError> {
        if self.sharpen > SHARPEN_MAX {
            return Err(crate::RenderError::Parameter(format!(
                "aspect sharpening {}/{WEIGHT_ONE}: expected at most {SHARPEN_MAX}/{WEIGHT_ONE} \
                 (a third of one)",
                self.sharpen
            )));
        }
        if !(1..=SHARPEN_REACH_MAX).contains(&self.sharpen_reach) {
            return Err(crate::RenderError::Parameter(format!(
                "sharpening reach {}: expected 1 to {SHARPEN_REACH_MAX} (a multiple of the \
                 far span; 1: the sharpening does not grow)",
                self.sharpen_reach
            )));
        }
        if !(1..=FAR_SPAN_MAX).contains(&self.far_span) {
            return Err(crate::RenderError::Parameter(format!(
                "far span {}: expected 1 to {FAR_SPAN_MAX} (a multiple of ε)",
                self.far_span
            )));
        }
        Ok(())
    }

    /// Whether frames run the opaque pass: [`Self::opaque_first`] with the "over" blend, the
    /// only one it serves.
    pub fn opaque_pass(self) -> bool {
        self.opaque_first && self.blend == AspectBlend::Over
    }

    /// The flag bits written to the camera uniform's `viewport.w`.
    pub fn flags(self) -> u32 {
        let blend = match self.blend {
            AspectBlend::Dither => FLAG_DITHER,
            AspectBlend::Over => 0,
            AspectBlend::Nearest => FLAG_NEAREST,
        };
        blend
            | if self.depth_error {
                FLAG_DEPTH_ERROR
            } else {
                0
            }
            | if self.trim { 0 } else { FLAG_UNTRIMMED }
            | if self.far_nearest { 0 } else { FLAG_FAR_BLEND }
            | if self.far_composite {
                0
            } else {
                FLAG_FAR_SLABS
            }
            | self.sharpen.min(SHARPEN_MAX) << SHARPEN_SHIFT
            | self.sharpen_reach.clamp(1, SHARPEN_REACH_MAX) << REACH_SHIFT
    }
}

/// Colours of levels 0, 1, … in the [`DebugView::Levels`] view (linear RGB; level `l` uses
/// entry `l % 8`). Mirrored by `level_colour` in `shaders/draw.wgsl`.
pub const LEVEL_COLOURS: [[f32; 3]; 8] = [
    [0.9, 0.1, 0.1],
    [0.95, 0.55, 0.05],
    [0.9, 0.9, 0.1],
    [0.1, 0.8, 0.1],
    [0.1, 0.8, 0.8],
    [0.1, 0.2, 0.95],
    [0.6, 0.1, 0.9],
    [0.95, 0.95, 0.95],
];

/// Colour of sampling direction `dir` in the [`DebugView::Weights`] view (linear RGB): hues
/// spaced by the golden ratio, softened. Mirrors `direction_colour` in `shaders/draw.wgsl`.
pub fn direction_colour(dir: u32) -> [f32; 3] {
    let h = (dir as f32 * 0.618034).fract();
    [0.0, 2.0 / 3.0, 1.0 / 3.0].map(|k: f32| {
        let v = (((h + k).fract() * 6.0 - 3.0).abs() - 1.0).clamp(0.0, 1.0);
        0.15 + 0.8 * v
    })
}

/// Colour a frame over [`Background::Sky`] is cleared to (linear RGB), before the environment
/// pass draws the sky and ground over every pixel; hosts drawing their own sky may use it.
pub const SKY: wgpu::Color = wgpu::Color {
    r: 0.45,
    g: 0.62,
    b: 0.85,
    a: 1.0,
};

/// Koschmieder's constant: haze of extinction `σ` per metre leaves `exp(−σ·V) = 2 %` of a
/// surface's contrast at the visibility `V = 3.912 / σ`.
pub const KOSCHMIEDER: f32 = 3.912;

/// The sky, the sun's disc and distance haze (aerial perspective), drawn and applied the same
/// way by every method, so images of different methods stay comparable.
///
/// Haze thins out with height (exponential height fog): its extinction at height `y` is
/// `σ(y) = σ₀·exp(−y / haze_height)`, `σ₀ = KOSCHMIEDER / visibility`, so a surface keeps
/// `T = exp(−τ)` of its colour and takes `1 − T` of the horizon colour (times its coverage, for
/// premultiplied colour), `τ` being `σ` integrated along the segment from the eye
/// ([`Self::optical_depth`]). Looking down from high above crosses less haze than looking
/// along the ground. The sky is drawn only over [`Background::Sky`]; haze applies over either
/// background.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Atmosphere {
    /// Meteorological visibility in metres (> 0) along the ground (y = 0): where haze leaves
    /// 2 % of a surface's contrast. `f32::INFINITY`: no haze.
    pub visibility: f32,
    /// Height in metres (> 0) over which the haze thins by a factor e. `f32::INFINITY`:
    /// homogeneous haze.
    pub haze_height: f32,
    /// Sky colour at the horizon, which is also the haze's colour (linear RGB, ≥ 0).
    pub horizon: [f32; 3],
    /// Sky colour at the zenith (linear RGB, ≥ 0).
    pub zenith: [f32; 3],
    /// Draw the sun's disc and the glow around it in the sky, in the lighting's sun direction.
    pub sun_disc: bool,
}

impl Atmosphere {
    /// Clear air: the sky gradient and the sun's disc, no haze (what metrics use).
    pub const CLEAR: Atmosphere = Atmosphere {
        visibility: f32::INFINITY,
        haze_height: Self::DEMO_HAZE_HEIGHT,
        horizon: [0.62, 0.72, 0.84],
        zenith: [0.20, 0.38, 0.72],
        sun_disc: true,
    };

    /// Visibility along the ground of the demo and viewer's haze, metres: a 2–3 km forest
    /// fades into the horizon.
    pub const DEMO_VISIBILITY: f32 = 2000.0;

    /// Scale height of the demo and viewer's haze, metres: a view from a few hundred metres
    /// up still shows the forest below.
    pub const DEMO_HAZE_HEIGHT: f32 = 200.0;

    /// [`Self::CLEAR`] with haze of the given visibility along the ground (metres).
    pub fn hazy(visibility: f32) -> Self {
        Self {
            visibility,
            ..Self::CLEAR
        }
    }

    /// Haze extinction σ₀ per metre at y = 0 (0 without haze).
    pub fn haze_density(&self) -> f32 {
        if self.visibility.is_finite() {
            KOSCHMIEDER / self.visibility
        } else {
            0.0
        }
    }

    /// `1 / haze_height` (0: homogeneous).
    pub fn haze_falloff(&self) -> f32 {
        if self.haze_height.is_finite() {
            1.0 / self.haze_height
        } else {
            0.0
        }
    }

    /// The haze's optical depth between `eye` and `point` (world, metres): σ integrated along
    /// the segment, `σ₀·|p − e|·exp(−k·e.y)·(1 − exp(−k·Δy)) / (k·Δy)` with `k` the falloff
    /// (the limit `σ₀·|p − e|·exp(−k·e.y)` as `k·Δy → 0`). Mirrors `optical_depth` in
    /// `shaders/environment.wgsl`.
    pub fn optical_depth(&self, eye: glam::Vec3, point: glam::Vec3) -> f32 {
        optical_depth(self.haze_density(), self.haze_falloff(), eye, point)
    }

    /// The fraction of the colour of a surface at `point` left at `eye`, `exp(−τ)`.
    pub fn transmittance(&self, eye: glam::Vec3, point: glam::Vec3) -> f32 {
        (-self.optical_depth(eye, point)).exp()
    }

    /// Check the parameters: one message naming the first bad one.
    pub fn validate(&self) -> Result<(), String> {
        if self.visibility.is_nan() || self.visibility <= 0.0 {
            return Err(format!(
                "haze visibility {} m must be positive (infinite for no haze)",
                self.visibility
            ));
        }
        if self.haze_height.is_nan() || self.haze_height <= 0.0 {
            return Err(format!(
                "haze height {} m must be positive (infinite for homogeneous haze)",
                self.haze_height
            ));
        }
        for (name, c) in [("horizon", self.horizon), ("zenith", self.zenith)] {
            if c.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
                return Err(format!(
                    "the {name} colour {c:?} must be finite and non-negative"
                ));
            }
        }
        Ok(())
    }
}

impl Default for Atmosphere {
    fn default() -> Self {
        Self::CLEAR
    }
}

/// See [`Atmosphere::optical_depth`]: extinction `sigma` per metre at y = 0, falloff `k` per
/// metre of height.
fn optical_depth(sigma: f32, k: f32, eye: glam::Vec3, point: glam::Vec3) -> f32 {
    let x = k * (point.y - eye.y);
    // exp(−k·e.y)·(1 − e^−x) / x, written so that neither exponential overflows for eyes and
    // points above the ground; by its series where x is small.
    let f = if x.abs() < 1e-3 {
        (-k * eye.y).exp() * (1.0 - 0.5 * x)
    } else {
        ((-k * eye.y).exp() - (-k * point.y).exp()) / x
    };
    sigma * eye.distance(point) * f
}

/// Angular radius of the sun's disc in degrees (the real sun's is 0.27°; drawn larger so that
/// it shows at a few hundred pixels across).
pub const SUN_DISC_DEGREES: f32 = 0.6;

/// The ground's first albedo (linear RGB): dry soil and leaf litter.
pub const GROUND_ALBEDO: glam::Vec3 = glam::Vec3::new(0.16, 0.14, 0.09);

/// The ground's second albedo (linear RGB): moss and grass, in patches among the soil.
pub const GROUND_MOSS: glam::Vec3 = glam::Vec3::new(0.075, 0.105, 0.04);

/// Soil ([`GROUND_ALBEDO`]) lit by the shared shading model (facing up, in sun), linear RGB:
/// the ground's colour where no moss grows, for hosts that draw their own ground.
pub fn ground_colour(lighting: &Lighting) -> glam::Vec3 {
    lighting.shade(GROUND_ALBEDO, glam::Vec3::Y, 1.0, 1.0, 0.0)
}

/// One of 2²⁴ values in [0, 1) per integer lattice point: a 32-bit integer hash (after
/// Chris Wellons' "lowbias32"). Mirrors `ground_hash` in `shaders/ground.wgsl`.
fn ground_hash(ix: i32, iz: i32) -> f32 {
    let mut h = (ix as u32).wrapping_mul(0x8da6_b343) ^ (iz as u32).wrapping_mul(0xd816_3841);
    h = (h ^ (h >> 16)).wrapping_mul(0x7feb_352d);
    h = (h ^ (h >> 15)).wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    (h >> 8) as f32 / 16_777_216.0
}

/// Smooth value noise in [0, 1) with unit lattice spacing (mirrors `ground_noise`).
fn ground_noise(x: f32, z: f32) -> f32 {
    let (fx, fz) = (x.floor(), z.floor());
    let (ix, iz) = (fx as i32, fz as i32);
    let s = |t: f32| t * t * (3.0 - 2.0 * t);
    let (tx, tz) = (s(x - fx), s(z - fz));
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let (jx, jz) = (ix.wrapping_add(1), iz.wrapping_add(1));
    let a = lerp(ground_hash(ix, iz), ground_hash(jx, iz), tx);
    let b = lerp(ground_hash(ix, jz), ground_hash(jx, jz), tx);
    lerp(a, b, tz)
}

/// How much moss covers the ground at world (x, z), in [0, 1]: two octaves of value noise
/// (23 m and 6.1 m) through a smooth step, the same on the plane and on the terrain. Mirrors
/// `ground_moss` in `shaders/ground.wgsl` ([`crate::passes::GROUND_WGSL`]).
pub fn ground_moss(x: f32, z: f32) -> f32 {
    let m = 0.65 * ground_noise(x / 23.0, z / 23.0) + 0.35 * ground_noise(x / 6.1, z / 6.1);
    let t = ((m - 0.3) / 0.4).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The ground's albedo at world (x, z): [`GROUND_ALBEDO`] (soil) towards [`GROUND_MOSS`] by
/// [`ground_moss`].
pub fn ground_albedo(x: f32, z: f32) -> glam::Vec3 {
    GROUND_ALBEDO.lerp(GROUND_MOSS, ground_moss(x, z))
}

impl RendererOptions {
    /// The depth a cleared target starts at: the far end of the depth range.
    pub fn depth_clear(&self) -> f32 {
        if self.reverse_z { 0.0 } else { 1.0 }
    }

    /// The depth test that keeps nearer fragments.
    pub fn depth_compare(&self) -> wgpu::CompareFunction {
        if self.reverse_z {
            wgpu::CompareFunction::GreaterEqual
        } else {
            wgpu::CompareFunction::LessEqual
        }
    }

    /// The depth state of a pipeline drawing into these targets: their depth format and
    /// test, depth written or not.
    pub fn depth_stencil(&self, write: bool) -> wgpu::DepthStencilState {
        wgpu::DepthStencilState {
            format: self.depth_format,
            depth_write_enabled: Some(write),
            depth_compare: Some(self.depth_compare()),
            stencil: Default::default(),
            bias: Default::default(),
        }
    }

    /// The multisample state of a pipeline drawing into these targets.
    pub fn multisample(&self) -> wgpu::MultisampleState {
        wgpu::MultisampleState {
            count: self.sample_count,
            ..Default::default()
        }
    }
}

#[cfg(test)]
mod tests;
