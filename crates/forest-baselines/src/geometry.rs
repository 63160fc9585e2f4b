//! The geometry-based methods in one renderer: full geometry (the ground-truth reference when
//! supersampled, the brute-force baseline at 1×, optionally depth-sorted by tree as in seed
//! 003), stochastic simplification (seeds 000/001) and discrete LODs + billboards (seed 004).
//!
//! ```text
//! per species, once: reference_vertices (per-vertex sun visibility, the bake's tracer)
//!   ─► lod::build_lods (LOD 0 = every triangle, leaves shuffled; LODs 1, 2) + billboards
//! per frame: geo_reset ─► geo_classify (frustum, distance band) ─► geo_args (offsets,
//!   indirect arguments per band × species) ─► geo_scatter ─► draw bands nearest first
//! ```
//! The method is a uniform: [`GeometryRenderer::set_method`] switches at run time without
//! rebuilding anything. Every tree is shaded with `forest_format::shading` in its object
//! space, as the bake shades the atlases.

use forest_bake::lod::{BANDS, LodParams};
use forest_bake::{Mesh, RefVertex};
use forest_format::forest::Forest;
use forest_format::shading::Lighting;
use wgpu::util::DeviceExt;

use forest_render::camera::{Camera, CameraError};
use forest_render::context::{GpuContext, RenderError};
use forest_render::gpu_types::GpuCamera;
use forest_render::options::Background;
use forest_render::passes::draw::DEPTH_FORMAT;
use forest_render::stats::PassTimes;
use forest_render::target::Target;

use crate::gpu_types::{GpuGeoMaterial, GpuGeoSpecies, GpuLight, GpuMethod};

/// Side of every material texture layer on the GPU.
pub const MATERIAL_TEXTURE_SIZE: u32 = 512;
const NONE: u32 = u32::MAX;

/// A species for the geometry-based methods.
pub struct GeometrySpecies {
    /// The model.
    pub mesh: Mesh,
    /// The lighting its atlas was baked with (so every method shades alike).
    pub lighting: Lighting,
}

/// Stochastic simplification parameters (Cook et al. 2007; seeds 000/001).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stochastic {
    /// Trees nearer than this (metres, divided by the instance scale) get every leaf.
    pub d0: f32,
    /// The `b = d0²/d²` at which half the leaves are drawn, in `(0, 1)`; ½ gives `λ = b`.
    pub h: f32,
    /// Fading band width as a fraction of λ, in `[0, 1]`.
    pub fade: f32,
    /// Enlarge kept leaves to preserve the visible area.
    pub area: bool,
    /// Pull leaf colours towards the species' mean by `√λ`.
    pub contrast: bool,
}

impl Default for Stochastic {
    fn default() -> Self {
        Self {
            d0: 15.0,
            h: 0.5,
            fade: 0.1,
            area: true,
            contrast: true,
        }
    }
}

/// Discrete LOD parameters (seed 004).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lods {
    /// Distances (metres, divided by the instance scale) where LOD 1, LOD 2 and billboards
    /// start; strictly increasing and positive.
    pub distances: [f32; 3],
}

impl Default for Lods {
    fn default() -> Self {
        Self {
            distances: [15.0, 40.0, 100.0],
        }
    }
}

/// What the geometry renderer draws for each tree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MeshMethod {
    /// Every tree's full model; with `depth_sort` the nearest distance bands are drawn first.
    Full {
        /// Draw near trees first (seed 003's tree depth sorting).
        depth_sort: bool,
    },
    /// Stochastic simplification of the leaves; branches drawn whole.
    Stochastic(Stochastic),
    /// Three mesh LODs and camera-facing multi-elevation billboards.
    Lods(Lods),
}

impl Default for MeshMethod {
    fn default() -> Self {
        MeshMethod::Full { depth_sort: true }
    }
}

impl MeshMethod {
    /// Check the parameters; the error names the bad one.
    pub fn validate(&self) -> Result<(), RenderError> {
        let bad = |s: String| Err(RenderError::Parameter(s));
        match self {
            MeshMethod::Full { .. } => Ok(()),
            MeshMethod::Stochastic(s) => {
                if !(s.d0.is_finite() && s.d0 > 0.0) {
                    return bad(format!(
                        "stochastic d0 {} must be a positive distance",
                        s.d0
                    ));
                }
                if !(s.h > 0.0 && s.h < 1.0) {
                    return bad(format!("stochastic h {} must be in (0, 1)", s.h));
                }
                if !(0.0..=1.0).contains(&s.fade) {
                    return bad(format!(
                        "stochastic fade width {} must be in [0, 1]",
                        s.fade
                    ));
                }
                Ok(())
            }
            MeshMethod::Lods(l) => {
                let d = l.distances;
                if !(d.iter().all(|x| x.is_finite() && *x > 0.0) && d[0] < d[1] && d[1] < d[2]) {
                    return bad(format!(
                        "LOD distances {d:?} must be positive and strictly increasing"
                    ));
                }
                Ok(())
            }
        }
    }

    /// The GPU form.
    pub fn to_gpu(&self) -> GpuMethod {
        match *self {
            MeshMethod::Full { depth_sort } => GpuMethod {
                mode: 0,
                depth_sort: u32::from(depth_sort),
                ..Default::default()
            },
            MeshMethod::Stochastic(s) => GpuMethod {
                mode: 1,
                area: u32::from(s.area),
                contrast: u32::from(s.contrast),
                d0: s.d0,
                exponent: 0.5f32.ln() / s.h.ln(),
                fade: s.fade,
                ..Default::default()
            },
            MeshMethod::Lods(l) => GpuMethod {
                mode: 2,
                lod: [l.distances[0], l.distances[1], l.distances[2], 0.0],
                ..Default::default()
            },
        }
    }

    /// First band drawn as billboards (`BANDS`: none).
    pub fn first_billboard_band(&self) -> u32 {
        match self {
            MeshMethod::Lods(_) => 12,
            _ => BANDS,
        }
    }

    /// The draw band of a tree at object-space distance `d` (CPU mirror of `method_band` in
    /// `shaders/geometry_types.wgsl`).
    pub fn band(&self, d: f32) -> u32 {
        let distance_band =
            |d: f32| ((2.0 * d.max(1.0).log2()).floor().max(0.0) as u32).min(BANDS - 1);
        match *self {
            MeshMethod::Full { depth_sort } => {
                if depth_sort {
                    distance_band(d)
                } else {
                    0
                }
            }
            MeshMethod::Stochastic(s) => {
                forest_bake::lod::lambda_band(forest_bake::lod::lambda(d, s.d0, s.h))
            }
            MeshMethod::Lods(l) => {
                let (mut lod, mut start) = (0, 1.0);
                for (k, &x) in l.distances.iter().enumerate() {
                    if d >= x {
                        lod = k as u32 + 1;
                        start = x;
                    }
                }
                let sub = ((2.0 * (d / start).max(1.0).log2()).floor().max(0.0) as u32).min(3);
                lod * 4 + sub
            }
        }
    }
}

/// Counters of the last frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GeometryStats {
    /// Trees that passed the frustum test.
    pub visible_trees: u32,
    /// Visible trees per draw band.
    pub per_band: Vec<u32>,
    /// Triangles submitted (billboards count two).
    pub triangles: u64,
    /// Trees drawn as billboards.
    pub billboards: u32,
    /// GPU pass times (refine is 0), where the adapter has timestamp queries.
    pub times: Option<PassTimes>,
}

/// What one species was prepared into, for reports.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SpeciesFigures {
    /// Triangles of LOD 0, 1, 2.
    pub lod_triangles: [u64; 3],
    /// Leaves (stochastic elements).
    pub leaves: u32,
    /// `r` of the area-preservation factor.
    pub r: f32,
    /// Bytes of the species' model data on the GPU: vertices, tables, material and billboard
    /// textures with mips.
    pub model_bytes: u64,
}

/// Bytes of RGBA8 layers with their mip chains (a third more than level 0).
fn layer_bytes(layers: &[image::RgbaImage]) -> u64 {
    layers.iter().map(|l| l.as_raw().len() as u64 * 4 / 3).sum()
}

/// Billboard image side (texels) and samples per texel.
pub const BILLBOARD_RESOLUTION: u32 = 256;
const BILLBOARD_SPP: u32 = 4;

/// The geometry-based renderer of one forest.
pub struct GeometryRenderer {
    camera: wgpu::Buffer,
    method_buf: wgpu::Buffer,
    method: MeshMethod,
    forms: [f32; 4],
    writes: (u64, u64),
    ring: forest_render::stats::StatsRing,
    reset: wgpu::ComputePipeline,
    classify: wgpu::ComputePipeline,
    args_pipeline: wgpu::ComputePipeline,
    scatter: wgpu::ComputePipeline,
    draw: wgpu::RenderPipeline,
    billboard: wgpu::RenderPipeline,
    ground_pipeline: wgpu::RenderPipeline,
    ground_bg: wgpu::BindGroup,
    compute_bg: wgpu::BindGroup,
    draw_bg: wgpu::BindGroup,
    args: wgpu::Buffer,
    queries: Option<(wgpu::QuerySet, wgpu::Buffer, f64)>,
    species: u32,
    instances: u32,
    background: Background,
    /// Per-species figures, in the forest's species order.
    pub figures: Vec<SpeciesFigures>,
    /// Bytes of GPU memory the renderer allocated (buffers and textures).
    pub gpu_bytes: u64,
}

/// Combine a material's colour and alpha sources into one RGBA image of the layer size.
fn material_layer(
    mesh: &Mesh,
    colour: Option<usize>,
    alpha: Option<(usize, bool)>,
) -> image::RgbaImage {
    let s = MATERIAL_TEXTURE_SIZE;
    let resize = |t: usize| {
        let tex = &mesh.textures[t];
        let img = image::RgbaImage::from_raw(tex.width, tex.height, tex.rgba.clone())
            .expect("texture size");
        image::imageops::resize(&img, s, s, image::imageops::FilterType::Triangle)
    };
    let mut out = match colour {
        Some(c) => resize(c),
        None => image::RgbaImage::from_pixel(s, s, image::Rgba([255, 255, 255, 255])),
    };
    if let Some((a, channel)) = alpha {
        let src = if Some(a) == colour && channel {
            out.clone()
        } else {
            resize(a)
        };
        for (o, p) in out.pixels_mut().zip(src.pixels()) {
            o[3] = if channel {
                p[3]
            } else {
                ((u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2])) / 3) as u8
            };
        }
    }
    out
}

/// Mip chain of an RGBA8 image down to 1×1 (triangle filter), level 0 first, concatenated.
/// Alpha is rescaled per level so that the share of texels passing the 0.5 alpha test stays
/// that of level 0 (Castaño's coverage-preserving mips): plain averaging erodes alpha-tested
/// leaves into nothing at a distance.
fn mip_chain(img: &image::RgbaImage) -> (Vec<u8>, u32) {
    let coverage = |m: &image::RgbaImage, scale: f32| {
        m.pixels()
            .filter(|p| f32::from(p[3]) * scale >= 127.5)
            .count() as f32
            / (m.width() * m.height()) as f32
    };
    let target = coverage(img, 1.0);
    let mut data = Vec::new();
    let mut m = img.clone();
    // Filtering must not mix in the colour of transparent texels (the bake never sees them).
    forest_bake::lod::dilate_colour(&mut m);
    let mips = img.width().max(img.height()).ilog2() + 1;
    for level in 0..mips {
        if level > 0 {
            let (w, h) = (
                (img.width() >> level).max(1),
                (img.height() >> level).max(1),
            );
            m = image::imageops::resize(&m, w, h, image::imageops::FilterType::Triangle);
            if target > 0.0 && target < 1.0 {
                // Bisect the alpha scale whose coverage matches level 0's.
                let (mut lo, mut hi) = (0.0f32, 8.0f32);
                for _ in 0..20 {
                    let mid = 0.5 * (lo + hi);
                    if coverage(&m, mid) < target {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let mut scaled = m.clone();
                for p in scaled.pixels_mut() {
                    p[3] = (f32::from(p[3]) * hi).round().min(255.0) as u8;
                }
                data.extend_from_slice(scaled.as_raw());
                continue;
            }
        }
        data.extend_from_slice(m.as_raw());
    }
    (data, mips)
}

/// An sRGB RGBA8 2D-array texture with mips from square layers of side `size`.
fn layered_texture(
    ctx: &GpuContext,
    label: &str,
    size: u32,
    layers: &[image::RgbaImage],
) -> (wgpu::TextureView, u64) {
    let white = [image::RgbaImage::from_pixel(
        size,
        size,
        image::Rgba([255; 4]),
    )];
    let layers = if layers.is_empty() {
        &white[..]
    } else {
        layers
    };
    let mut data = Vec::new();
    let mut mips = 1;
    for img in layers {
        let (d, m) = mip_chain(img);
        data.extend(d);
        mips = m;
    }
    let texture = ctx.device.create_texture_with_data(
        &ctx.queue,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: size,
                height: size,
                depth_or_array_layers: layers.len() as u32,
            },
            mip_level_count: mips,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8UnormSrgb,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        &data,
    );
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    (view, data.len() as u64)
}

/// Layout entries of the draw group (bindings as in `shaders/geometry_draw.wgsl`).
fn draw_layout_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
    use wgpu::ShaderStages as S;
    let buffer = |binding, visibility, ty| wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    let read = wgpu::BufferBindingType::Storage { read_only: true };
    let uniform = wgpu::BufferBindingType::Uniform;
    let texture = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: S::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        },
        count: None,
    };
    vec![
        buffer(0, S::VERTEX_FRAGMENT, uniform),
        buffer(1, S::VERTEX, read),
        buffer(2, S::VERTEX, read),
        buffer(3, S::VERTEX, read),
        buffer(4, S::FRAGMENT, read),
        texture(5),
        wgpu::BindGroupLayoutEntry {
            binding: 6,
            visibility: S::FRAGMENT,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        },
        buffer(7, S::FRAGMENT, uniform),
        buffer(9, S::VERTEX, read),
        buffer(10, S::VERTEX, uniform),
        buffer(11, S::VERTEX, read),
        texture(12),
    ]
}

/// The CPU preparation of the species (reference vertices with traced sun visibility, LOD set,
/// billboard images), reusable for any forest of these species.
#[derive(Clone)]
pub struct PreparedGeometry {
    vertices: Vec<RefVertex>,
    geo_species: Vec<GpuGeoSpecies>,
    materials: Vec<GpuGeoMaterial>,
    layers: Vec<image::RgbaImage>,
    billboard_layers: Vec<image::RgbaImage>,
    leaf_end: Vec<u32>,
    leaf_centre: Vec<[f32; 4]>,
    /// Per-species figures.
    pub figures: Vec<SpeciesFigures>,
    lighting: Lighting,
}

impl PreparedGeometry {
    /// Prepare every species (seconds per species: the sun-visibility and billboard rays).
    pub fn new(species: &[GeometrySpecies]) -> Self {
        let mut vertices: Vec<RefVertex> = Vec::new();
        let mut geo_species = Vec::new();
        let mut materials = Vec::new();
        let mut layers: Vec<image::RgbaImage> = Vec::new();
        let mut billboard_layers: Vec<image::RgbaImage> = Vec::new();
        let mut leaf_end: Vec<u32> = Vec::new();
        let mut leaf_centre: Vec<[f32; 4]> = Vec::new();
        let mut figures = Vec::new();
        for s in species {
            let material_base = materials.len() as u32;
            let (layers_base, billboards_base, vertices_base, leaves_base) = (
                layers.len(),
                billboard_layers.len(),
                vertices.len(),
                leaf_end.len(),
            );
            for m in &s.mesh.materials {
                let layer = if m.colour.is_some() || m.alpha.is_some() {
                    layers.push(material_layer(&s.mesh, m.colour, m.alpha));
                    layers.len() as u32 - 1
                } else {
                    NONE
                };
                materials.push(GpuGeoMaterial {
                    kd: m.kd.extend(m.translucency).to_array(),
                    layer,
                    alpha_tested: u32::from(m.alpha.is_some()),
                    pad: [0; 2],
                });
            }
            let reference = forest_bake::reference_vertices(&s.mesh, &s.lighting);
            let leaf: Vec<bool> = reference
                .chunks_exact(3)
                .map(|t| s.mesh.materials[t[0].material as usize].alpha.is_some())
                .collect();
            let set = forest_bake::lod::build_lods(&reference, &leaf, &LodParams::default());
            let mean = forest_bake::lod::mean_leaf_colour(&s.mesh, &set.lod0, &s.lighting);
            let sphere = forest_bake::bounding_sphere(&s.mesh);
            let first = vertices.len() as u32;
            let counts = [
                set.lod0.len() as u32,
                set.lods[0].len() as u32,
                set.lods[1].len() as u32,
            ];
            geo_species.push(GpuGeoSpecies {
                sphere: sphere.center.extend(sphere.radius).to_array(),
                lod_first: [
                    first,
                    first + counts[0],
                    first + counts[0] + counts[1],
                    billboard_layers.len() as u32,
                ],
                lod_count: [counts[0], counts[1], counts[2], 6],
                branch_vertices: set.branch_vertices,
                leaves: set.leaf_end.len() as u32,
                leaf_base: leaf_end.len() as u32,
                r: set.r,
                mean_leaf: mean.extend(0.0).to_array(),
            });
            leaf_end.extend(&set.leaf_end);
            leaf_centre.extend(set.leaf_centre.iter().map(|c| c.extend(0.0).to_array()));
            billboard_layers.extend(forest_bake::lod::billboard_images(
                &s.mesh,
                &s.lighting,
                BILLBOARD_RESOLUTION,
                BILLBOARD_SPP,
            ));
            for v in set.lod0.iter().chain(&set.lods[0]).chain(&set.lods[1]) {
                vertices.push(RefVertex {
                    material: v.material + material_base,
                    ..*v
                });
            }
            let leaves = leaf_end.len() - leaves_base;
            figures.push(SpeciesFigures {
                lod_triangles: counts.map(|c| u64::from(c) / 3),
                leaves: leaves as u32,
                r: set.r,
                model_bytes: (std::mem::size_of_val(&vertices[vertices_base..])
                    + std::mem::size_of::<GpuGeoSpecies>()
                    + std::mem::size_of_val(&materials[material_base as usize..])
                    + std::mem::size_of_val(&leaf_end[leaves_base..])
                    + std::mem::size_of_val(&leaf_centre[leaves_base..]))
                    as u64
                    + layer_bytes(&layers[layers_base..])
                    + layer_bytes(&billboard_layers[billboards_base..]),
            });
        }
        let lighting = species
            .first()
            .map(|s| s.lighting)
            .unwrap_or(Lighting::with_sun(30.0, 55.0));
        Self {
            vertices,
            geo_species,
            materials,
            layers,
            billboard_layers,
            leaf_end,
            leaf_centre,
            figures,
            lighting,
        }
    }

    /// A copy with every vertex's traced sun visibility replaced by `f(visibility)`: for
    /// measuring what self-shadowing contributes (tests, experiments).
    pub fn map_sun_visibility(&self, f: impl Fn(f32) -> f32) -> Self {
        let mut out = self.clone();
        out.vertices
            .iter_mut()
            .for_each(|v| v.sun_visibility = f(v.sun_visibility));
        out
    }

    /// Bytes of the model data uploaded for all species: vertices, tables, material and
    /// billboard textures with mips (what the geometry methods store per species, not per tree).
    pub fn model_bytes(&self) -> u64 {
        self.figures.iter().map(|f| f.model_bytes).sum()
    }
}

impl GeometryRenderer {
    /// Upload prepared species with the forest's instances (their species order must match).
    /// The method starts as [`MeshMethod::default`].
    pub fn new(
        ctx: &GpuContext,
        prepared: &PreparedGeometry,
        forest: &Forest,
        format: wgpu::TextureFormat,
        background: Background,
    ) -> Result<Self, RenderError> {
        let PreparedGeometry {
            vertices,
            geo_species,
            materials,
            layers,
            billboard_layers,
            leaf_end,
            leaf_centre,
            figures,
            lighting: l,
        } = prepared;
        let l = *l;
        if geo_species.len() != forest.species.len() {
            return Err(RenderError::SpeciesCount {
                forest: forest.species.len(),
                given: geo_species.len(),
                what: "models",
            });
        }
        if !ctx
            .device
            .features()
            .contains(wgpu::Features::INDIRECT_FIRST_INSTANCE)
        {
            return Err(RenderError::MissingFeature {
                method: "the geometry renderer",
                feature: "indirect draws with a first instance (INDIRECT_FIRST_INSTANCE)",
            });
        }
        let device = &ctx.device;
        let light = GpuLight {
            sun_dir: l.sun_dir.extend(0.0).to_array(),
            sun: l.sun.extend(0.0).to_array(),
            sky: l.sky.extend(0.0).to_array(),
            ground: l.ground.extend(0.0).to_array(),
        };
        let instances = forest_render::scene::gpu_instances(forest);
        let cap = forest_render::capacity::GeometryCapacity::new(
            instances.len() as u32,
            geo_species.len() as u32,
            BANDS,
        );
        let (segments, listed) = (cap.segments as usize, cap.instances as usize);
        let gpu_bytes = std::cell::Cell::new(0u64);
        use wgpu::BufferUsages as U;
        let init = |label: &str, bytes: &[u8], usage: U| {
            // Empty tables still bind one element of any of their types.
            let pad = [0u8; 256];
            let contents = if bytes.is_empty() { &pad[..] } else { bytes };
            gpu_bytes.set(gpu_bytes.get() + contents.len() as u64);
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let zeros = |label: &str, bytes: usize, usage: U| init(label, &vec![0u8; bytes], usage);
        let camera = zeros(
            "geometry camera",
            std::mem::size_of::<GpuCamera>(),
            U::UNIFORM | U::COPY_DST,
        );
        let method = MeshMethod::default();
        let method_buf = init(
            "geometry method",
            bytemuck::bytes_of(&method.to_gpu()),
            U::UNIFORM | U::COPY_DST,
        );
        let inst_buf = init(
            "geometry instances",
            bytemuck::cast_slice(&instances),
            U::STORAGE,
        );
        let species_buf = init(
            "geometry species",
            bytemuck::cast_slice(geo_species),
            U::STORAGE,
        );
        let vertex_buf = init(
            "geometry vertices",
            bytemuck::cast_slice(vertices),
            U::STORAGE,
        );
        let material_buf = init(
            "geometry materials",
            bytemuck::cast_slice(materials),
            U::STORAGE,
        );
        let leaf_end_buf = init("leaf ends", bytemuck::cast_slice(leaf_end), U::STORAGE);
        let leaf_centre_buf = init(
            "leaf centres",
            bytemuck::cast_slice(leaf_centre),
            U::STORAGE,
        );
        let light_buf = init("geometry light", bytemuck::bytes_of(&light), U::UNIFORM);
        let consts = init(
            "geometry constants",
            bytemuck::cast_slice(&[instances.len() as u32, geo_species.len() as u32, 0, 0]),
            U::UNIFORM,
        );
        let keys = zeros("segment keys", listed * 4, U::STORAGE);
        let counts = zeros("segment counts", segments * 4, U::STORAGE | U::COPY_SRC);
        let cursor = zeros("segment cursors", segments * 4, U::STORAGE);
        let visible = zeros("visible instances", listed * 4, U::STORAGE);
        let args = zeros(
            "geometry draw args",
            segments * 16,
            U::STORAGE | U::INDIRECT | U::COPY_SRC,
        );

        let (material_view, material_bytes) =
            layered_texture(ctx, "material textures", MATERIAL_TEXTURE_SIZE, layers);
        let (billboard_view, billboard_bytes) =
            layered_texture(ctx, "billboards", BILLBOARD_RESOLUTION, billboard_layers);
        gpu_bytes.set(gpu_bytes.get() + material_bytes + billboard_bytes);
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("material"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });

        let compute = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("geometry cull"),
            source: wgpu::ShaderSource::Wgsl(crate::shaders::GEOMETRY_CULL_WGSL.concat().into()),
        });
        let draw_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("geometry draw"),
            source: wgpu::ShaderSource::Wgsl(crate::shaders::GEOMETRY_DRAW_WGSL.concat().into()),
        });
        // One explicit layout shared by the four compute entry points (one bind group).
        use forest_render::passes::Slot;
        let entries = forest_render::passes::layout_entries(
            &[
                Slot::Uniform,   // 0 camera
                Slot::Read,      // 1 instances
                Slot::Read,      // 2 species
                Slot::ReadWrite, // 3 keys
                Slot::ReadWrite, // 4 counts
                Slot::ReadWrite, // 5 cursors
                Slot::ReadWrite, // 6 visible
                Slot::ReadWrite, // 7 args
                Slot::Uniform,   // 8 constants
                Slot::Uniform,   // 9 method
                Slot::Read,      // 10 leaf ends
            ],
            wgpu::ShaderStages::COMPUTE,
        );
        let compute_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("geometry cull"),
            entries: &entries,
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("geometry cull"),
            bind_group_layouts: &[Some(&compute_layout)],
            immediate_size: 0,
        });
        let cpl = |entry: &str| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&pl),
                module: &compute,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let compute_bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("geometry cull"),
            layout: &compute_layout,
            entries: &forest_render::passes::numbered(vec![
                camera.as_entire_binding(),
                inst_buf.as_entire_binding(),
                species_buf.as_entire_binding(),
                keys.as_entire_binding(),
                counts.as_entire_binding(),
                cursor.as_entire_binding(),
                visible.as_entire_binding(),
                args.as_entire_binding(),
                consts.as_entire_binding(),
                method_buf.as_entire_binding(),
                leaf_end_buf.as_entire_binding(),
            ]),
        });
        let draw_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("geometry draw"),
            entries: &draw_layout_entries(),
        });
        let draw_pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("geometry draw"),
            bind_group_layouts: &[Some(&draw_layout)],
            immediate_size: 0,
        });
        let render_pipeline =
            |vs: &str, fs: &str, topology, layout: Option<&wgpu::PipelineLayout>| {
                device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some(vs),
                    layout,
                    vertex: wgpu::VertexState {
                        module: &draw_module,
                        entry_point: Some(vs),
                        compilation_options: Default::default(),
                        buffers: &[],
                    },
                    primitive: wgpu::PrimitiveState {
                        topology,
                        cull_mode: None,
                        ..Default::default()
                    },
                    depth_stencil: Some(wgpu::DepthStencilState {
                        format: DEPTH_FORMAT,
                        depth_write_enabled: Some(true),
                        depth_compare: Some(wgpu::CompareFunction::LessEqual),
                        stencil: Default::default(),
                        bias: Default::default(),
                    }),
                    multisample: Default::default(),
                    fragment: Some(wgpu::FragmentState {
                        module: &draw_module,
                        entry_point: Some(fs),
                        compilation_options: Default::default(),
                        targets: &[Some(wgpu::ColorTargetState {
                            format,
                            blend: None,
                            write_mask: wgpu::ColorWrites::ALL,
                        })],
                    }),
                    multiview_mask: None,
                    cache: None,
                })
            };
        use wgpu::PrimitiveTopology as T;
        let draw = render_pipeline("vs_geo", "fs_geo", T::TriangleList, Some(&draw_pl));
        let billboard = render_pipeline(
            "vs_billboard",
            "fs_billboard",
            T::TriangleList,
            Some(&draw_pl),
        );
        let ground_pipeline = render_pipeline("vs_ground", "fs_ground", T::TriangleStrip, None);
        let ground_buf = init(
            "geometry ground",
            bytemuck::bytes_of(&forest_render::options::ground_uniform(&l, &instances)),
            U::UNIFORM,
        );
        let ground_bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("geometry ground"),
            layout: &ground_pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: camera.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 8,
                    resource: ground_buf.as_entire_binding(),
                },
            ],
        });
        let resources = vec![
            (0, camera.as_entire_binding()),
            (1, inst_buf.as_entire_binding()),
            (2, vertex_buf.as_entire_binding()),
            (3, visible.as_entire_binding()),
            (4, material_buf.as_entire_binding()),
            (5, wgpu::BindingResource::TextureView(&material_view)),
            (6, wgpu::BindingResource::Sampler(&sampler)),
            (7, light_buf.as_entire_binding()),
            (9, species_buf.as_entire_binding()),
            (10, method_buf.as_entire_binding()),
            (11, leaf_centre_buf.as_entire_binding()),
            (12, wgpu::BindingResource::TextureView(&billboard_view)),
        ];
        let draw_bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("geometry draw"),
            layout: &draw_layout,
            entries: &resources
                .into_iter()
                .map(|(binding, resource)| wgpu::BindGroupEntry { binding, resource })
                .collect::<Vec<_>>(),
        });
        let queries = device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY)
            .then(|| {
                let set = device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("geometry pass times"),
                    ty: wgpu::QueryType::Timestamp,
                    count: 4,
                });
                let resolve = zeros("geometry timestamps", 32, U::QUERY_RESOLVE | U::COPY_SRC);
                (set, resolve, f64::from(ctx.queue.get_timestamp_period()))
            });
        let mut sources = vec![(args.clone(), u64::from(cap.segments) * 16)];
        if let Some((_, resolve, _)) = &queries {
            sources.push((resolve.clone(), 32));
        }
        let ring = forest_render::stats::StatsRing::new(device, sources);
        Ok(Self {
            camera,
            method_buf,
            method,
            forms: forest_render::forms::FORMS_GEOMETRY,
            writes: (0, 0),
            ring,
            reset: cpl("geo_reset"),
            classify: cpl("geo_classify"),
            args_pipeline: cpl("geo_args"),
            scatter: cpl("geo_scatter"),
            draw,
            billboard,
            ground_pipeline,
            ground_bg,
            compute_bg,
            draw_bg,
            args,
            queries,
            species: geo_species.len() as u32,
            instances: instances.len() as u32,
            background,
            figures: figures.clone(),
            gpu_bytes: gpu_bytes.get(),
        })
    }

    /// Switch the method (a uniform write; nothing is rebuilt).
    pub fn set_method(&mut self, ctx: &GpuContext, method: MeshMethod) -> Result<(), RenderError> {
        method.validate()?;
        ctx.queue
            .write_buffer(&self.method_buf, 0, bytemuck::bytes_of(&method.to_gpu()));
        self.method = method;
        Ok(())
    }

    /// The current method.
    pub fn method(&self) -> MeshMethod {
        self.method
    }

    /// Which trees the renderer draws from the next camera write on (the camera's `forms`, see
    /// [`forest_render::forms`]); [`forest_render::forms::FORMS_GEOMETRY`], every tree, unless the hybrid
    /// method set it.
    pub fn set_forms(&mut self, forms: [f32; 4]) {
        self.forms = forms;
    }

    /// Write the camera and record the frame: classify, arguments, scatter, then draw the
    /// bands nearest first into `colour` and `depth`.
    pub fn encode(
        &mut self,
        ctx: &GpuContext,
        camera: &Camera,
        encoder: &mut wgpu::CommandEncoder,
        colour: &wgpu::TextureView,
        depth: &wgpu::TextureView,
    ) -> Result<(), CameraError> {
        self.set_camera(ctx, camera)?;
        self.encode_compute(encoder);
        {
            let mut pass = forest_render::target::begin_pass(
                encoder,
                "geometry draw",
                colour,
                depth,
                self.background.clear_colour(),
                self.queries
                    .as_ref()
                    .map(|(query_set, _, _)| wgpu::RenderPassTimestampWrites {
                        query_set,
                        beginning_of_pass_write_index: Some(2),
                        end_of_pass_write_index: Some(3),
                    }),
            );
            self.record_draw(&mut pass, true);
        }
        self.resolve_times(encoder, true);
        Ok(())
    }

    /// Write the camera (with the renderer's `forms`): the one upload of a frame.
    pub fn set_camera(&mut self, ctx: &GpuContext, camera: &Camera) -> Result<(), CameraError> {
        camera.validate()?;
        let mut g = camera.to_gpu();
        g.forms = self.forms;
        forest_render::camera::upload(&ctx.queue, &self.camera, &g, &mut self.writes);
        Ok(())
    }

    /// Camera writes made by this renderer since it was created: (count, bytes). The method
    /// uniform is written only by [`Self::set_method`].
    pub fn uploads(&self) -> (u64, u64) {
        self.writes
    }

    /// The compute pass of a frame: classify, arguments, scatter (after [`Self::set_camera`]).
    pub fn encode_compute(&self, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("geometry cull"),
            timestamp_writes: self.queries.as_ref().map(|(query_set, _, _)| {
                wgpu::ComputePassTimestampWrites {
                    query_set,
                    beginning_of_pass_write_index: Some(0),
                    end_of_pass_write_index: Some(1),
                }
            }),
        });
        pass.set_bind_group(0, &self.compute_bg, &[]);
        let segments = BANDS * self.species;
        pass.set_pipeline(&self.reset);
        pass.dispatch_workgroups(segments.div_ceil(64).max(1), 1, 1);
        pass.set_pipeline(&self.classify);
        pass.dispatch_workgroups(self.instances.div_ceil(256).max(1), 1, 1);
        pass.set_pipeline(&self.args_pipeline);
        pass.dispatch_workgroups(1, 1, 1);
        pass.set_pipeline(&self.scatter);
        pass.dispatch_workgroups(self.instances.div_ceil(256).max(1), 1, 1);
    }

    /// Record the draw into a render pass after [`Self::encode_compute`]: the ground (when
    /// `ground` and the background is the sky), then the bands nearest first.
    pub fn record_draw(&self, pass: &mut wgpu::RenderPass, ground: bool) {
        if ground && self.background == Background::Sky {
            pass.set_pipeline(&self.ground_pipeline);
            pass.set_bind_group(0, &self.ground_bg, &[]);
            pass.draw(0..4, 0..1);
        }
        pass.set_bind_group(0, &self.draw_bg, &[]);
        let first_billboard = self.method.first_billboard_band();
        for band in 0..BANDS {
            if band == 0 {
                pass.set_pipeline(&self.draw);
            }
            if band == first_billboard {
                pass.set_pipeline(&self.billboard);
            }
            for s in 0..self.species {
                pass.draw_indirect(&self.args, u64::from(band * self.species + s) * 16);
            }
        }
    }

    /// Resolve the frame's pass times: the cull pass's, and the draw pass's when `draw` (the
    /// render pass carried this renderer's timestamps).
    pub fn resolve_times(&self, encoder: &mut wgpu::CommandEncoder, draw: bool) {
        if let Some((set, resolve, _)) = &self.queries {
            encoder.resolve_query_set(set, 0..if draw { 4 } else { 2 }, resolve, 0);
        }
    }

    /// Write the camera, record the frame into `target`, and submit.
    pub fn render_frame(
        &mut self,
        ctx: &GpuContext,
        camera: &Camera,
        target: &Target,
    ) -> Result<(), CameraError> {
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        self.encode(
            ctx,
            camera,
            &mut enc,
            &target.colour_view,
            &target.depth_view,
        )?;
        ctx.queue.submit([enc.finish()]);
        Ok(())
    }

    /// Visible trees per segment (`band · species + s`) of the last submitted frame; waits.
    pub fn read_segment_counts(&self, ctx: &GpuContext) -> Vec<u32> {
        let n = (BANDS * self.species) as usize;
        let args: Vec<[u32; 4]> =
            bytemuck::pod_collect_to_vec(&ctx.read_buffer(&self.args, (n * 16) as u64)[..n * 16]);
        args.iter().map(|a| a[1]).collect()
    }

    /// Counters and pass times of the last submitted frame; waits for the GPU.
    pub fn read_stats(&self, ctx: &GpuContext) -> GeometryStats {
        let n = (BANDS * self.species) as usize;
        let args = ctx.read_buffer(&self.args, (n * 16) as u64);
        let times = self
            .queries
            .as_ref()
            .map(|(_, resolve, _)| ctx.read_buffer(resolve, 32));
        self.decode(&args, times.as_deref())
    }

    /// Counters of a recent frame without waiting (a few frames late; `None` until one has
    /// arrived): see [`forest_render::stats::StatsRing`].
    pub fn poll_stats(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Option<GeometryStats> {
        let parts = self.ring.poll(device, queue)?;
        Some(self.decode(&parts[0], parts.get(1).map(|t| t.as_slice())))
    }

    fn decode(&self, args: &[u8], times: Option<&[u8]>) -> GeometryStats {
        let n = ((BANDS * self.species) as usize).min(args.len() / 16);
        let args: Vec<[u32; 4]> = bytemuck::pod_collect_to_vec(&args[..n * 16]);
        let first_billboard = self.method.first_billboard_band();
        let mut stats = GeometryStats {
            per_band: vec![0; BANDS as usize],
            ..Default::default()
        };
        for (seg, a) in args.iter().enumerate() {
            let band = seg as u32 / self.species.max(1);
            stats.visible_trees += a[1];
            stats.per_band[band as usize] += a[1];
            stats.triangles += u64::from(a[0] / 3) * u64::from(a[1]);
            if band >= first_billboard {
                stats.billboards += a[1];
            }
        }
        let period = self.queries.as_ref().map_or(1.0, |q| q.2);
        stats.times = times.filter(|t| t.len() >= 32).map(|t| {
            let t: Vec<u64> = bytemuck::pod_collect_to_vec(&t[..32]);
            let ms = |a: usize| t[a + 1].saturating_sub(t[a]) as f64 * period / 1e6;
            PassTimes {
                cull_ms: ms(0),
                refine_ms: 0.0,
                draw_ms: ms(2),
            }
        });
        stats
    }
}

/// Box-filter an image rendered at `factor`× resolution down to its display size (in linear
/// space for colour, alpha averaged): the supersampled reference.
pub fn downsample(img: &image::RgbaImage, factor: u32) -> image::RgbaImage {
    let table = forest_format::shading::srgb_decode_table();
    let (w, h) = (img.width() / factor, img.height() / factor);
    image::RgbaImage::from_fn(w, h, |x, y| {
        let mut acc = [0f32; 4];
        for dy in 0..factor {
            for dx in 0..factor {
                let p = img.get_pixel(x * factor + dx, y * factor + dy);
                for c in 0..3 {
                    acc[c] += table[p[c] as usize];
                }
                acc[3] += f32::from(p[3]);
            }
        }
        let n = (factor * factor) as f32;
        let e = |v: f32| (forest_format::shading::srgb_encode(v / n) * 255.0).round() as u8;
        image::Rgba([e(acc[0]), e(acc[1]), e(acc[2]), (acc[3] / n).round() as u8])
    })
}
