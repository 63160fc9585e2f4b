//! What a quad stream is asked to do: the host's target formats, the stream's sizing, and the
//! run-time choices (background, debug views, aspect blending) that travel in the camera
//! uniform.

use forest_format::shading::Lighting;

use crate::gpu_types::GpuGround;

/// What the trees are drawn over.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Background {
    /// Sky colour and a ground plane (the demo).
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
    /// Lighting for the ground (the atlases carry their own baked lighting).
    pub lighting: Lighting,
    /// Sky and ground, or transparent.
    pub background: Background,
    /// Refine the stream (the method). `false` draws the level-0 quads only: the static
    /// impostor baseline (each tree as its 1–3 blended slab images, never subdivided).
    pub refine: bool,
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
            refine: true,
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
}

impl DebugView {
    /// Every view, in the order the viewer cycles through them.
    pub const ALL: [DebugView; 4] = [
        DebugView::Off,
        DebugView::Levels,
        DebugView::Weights,
        DebugView::Wireframe,
    ];

    /// Short name for menus and file names.
    pub fn name(self) -> &'static str {
        match self {
            DebugView::Off => "off",
            DebugView::Levels => "levels",
            DebugView::Weights => "blend weights",
            DebugView::Wireframe => "wireframe",
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
    /// Draw a tree that spans less than ε pixels across (its level-0 quads are never refined)
    /// with its nearest aspect alone: one quad per slab instead of up to three. On (the
    /// default); off blends every tree's aspects, as the paper does.
    pub far_nearest: bool,
    /// Draw such a tree's slabs as one quad, composited in the fragment shader on the plane
    /// through the tree's centre (its slabs' parallax is below ε there), instead of one quad
    /// per slab. On (the default, with `far_nearest`); off draws each slab's quad.
    pub far_composite: bool,
}

impl Default for StreamOptions {
    fn default() -> Self {
        Self {
            blend: AspectBlend::Over,
            depth_error: false,
            trim: true,
            far_nearest: true,
            far_composite: true,
        }
    }
}

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

/// Background colour (sky) the demo clears to, linear RGB.
pub const SKY: wgpu::Color = wgpu::Color {
    r: 0.45,
    g: 0.62,
    b: 0.85,
    a: 1.0,
};

/// The ground's uniform: the ground albedo lit by the shared shading model (facing up, in sun),
/// and a square reaching 5 km beyond the farthest tree.
pub fn ground_uniform(
    lighting: &Lighting,
    instances: &[crate::gpu_types::GpuInstance],
) -> GpuGround {
    let extent = instances
        .iter()
        .map(|i| glam::Vec3::from_array(i.position).length())
        .fold(0.0f32, f32::max);
    let lit = lighting.shade(glam::Vec3::new(0.16, 0.14, 0.09), glam::Vec3::Y, 1.0, 0.0);
    GpuGround {
        colour: [lit.x, lit.y, lit.z, extent + 5000.0],
    }
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
