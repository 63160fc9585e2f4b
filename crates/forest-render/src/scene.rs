//! Scene data uploaded once: atlas textures, direction tables, instances, presorted orders.

use forest_format::atlas::{Layers, NODE_TEXTURE_WIDTH};
use forest_format::forest::Forest;
use forest_format::shading::{srgb_decode_table, srgb_encode};
use forest_format::{Atlas, QuadNode};
use wgpu::util::DeviceExt;

use crate::context::{ColourFormat, GpuContext, RenderError};
use crate::gpu_types::{GpuFrame, GpuInstance, GpuSpecies};

/// Width of the presort texture (one instance index per texel, orders one after another).
pub const PRESORT_TEXTURE_WIDTH: u32 = 4096;

/// One species ready for upload: its atlas and decoded slab images.
#[derive(Clone)]
pub struct SpeciesData {
    /// The atlas.
    pub atlas: Atlas,
    /// Its decoded albedo and coverage layers.
    pub layers: Layers,
    /// Its decoded surface-attribute layers (see [`forest_format::atlas`]).
    pub surface: Layers,
    /// Its decoded opacity volume (see [`forest_format::opacity`]).
    pub opacity: forest_format::opacity::OpacityVolume,
}

impl SpeciesData {
    /// Load and decode an atlas folder.
    pub fn load(path: &std::path::Path) -> Result<Self, RenderError> {
        let atlas = Atlas::load(path)?;
        Self::decode(atlas, path)
    }

    /// Decode a loaded atlas's images (`path` names its folder in errors).
    pub fn decode(atlas: Atlas, path: &std::path::Path) -> Result<Self, RenderError> {
        let layers = atlas.decode_layers(path)?;
        let surface = atlas.decode_surface(path, &layers)?;
        let opacity = atlas.decode_opacity(path)?;
        Ok(Self {
            atlas,
            layers,
            surface,
            opacity,
        })
    }
}

/// CPU-side tables the GPU also gets; the CPU reference works on these.
#[derive(Clone, Debug, Default)]
pub struct SceneTables {
    /// Instances (rotation as cos/sin).
    pub instances: Vec<GpuInstance>,
    /// Species table.
    pub species: Vec<GpuSpecies>,
    /// All direction frames.
    pub frames: Vec<GpuFrame>,
    /// All direction triangles (xyz; w unused).
    pub tris: Vec<[u32; 4]>,
    /// Root node (global index) of every layer, `u32::MAX` when blank.
    pub roots: Vec<u32>,
    /// All nodes, species after species.
    pub nodes: Vec<QuadNode>,
    /// Each node's covered box and opaque share (see [`forest_format::trim::node_trims`]), in
    /// node order.
    pub trims: Vec<[u32; 2]>,
    /// Presort directions (xyz; w unused).
    pub presort_dirs: Vec<[f32; 4]>,
    /// Presort orders, one after another (`K × N`).
    pub presort: Vec<u32>,
    /// Largest level count over the species.
    pub max_levels: u32,
    /// Largest `3 × slabs` over the species.
    pub quads_per_tree: u32,
    /// Colour layers in all.
    pub layers: u32,
    /// Slab image side (the same for every species).
    pub resolution: u32,
}

impl SceneTables {
    /// Build the tables; the error says which species or instance is inconsistent.
    pub fn new(species: &[SpeciesData], forest: &Forest) -> Result<Self, RenderError> {
        if species.len() != forest.species.len() {
            return Err(RenderError::SpeciesCount {
                forest: forest.species.len(),
                given: species.len(),
                what: "atlases",
            });
        }
        let mut t = SceneTables::default();
        for (k, s) in species.iter().enumerate() {
            let m = &s.atlas.manifest;
            if t.resolution != 0 && m.params.resolution != t.resolution {
                return Err(RenderError::MixedResolution {
                    index: k,
                    name: forest.species[k].clone(),
                    resolution: m.params.resolution,
                    first: t.resolution,
                });
            }
            t.resolution = m.params.resolution;
            let node_base = t.nodes.len() as u32;
            t.species.push(GpuSpecies {
                sphere: m
                    .bounding_sphere
                    .center
                    .extend(m.bounding_sphere.radius)
                    .to_array(),
                directions: m.params.total_directions(),
                slabs: m.params.slabs,
                levels: m.levels,
                dir_base: t.frames.len() as u32,
                tri_base: t.tris.len() as u32,
                tri_count: m.direction_triangles.len() as u32,
                layer_base: t.layers,
                node_base,
                lower_tri_count: m.lower_triangles.len() as u32,
                resolution: m.params.resolution,
                switch_unit: crate::forms::switch_unit(m),
                opacity_depth: m.opacity.max_depth,
                colour: forest.tree_colour(k),
            });
            t.frames.extend(m.directions.iter().map(|f| GpuFrame {
                dir: f.dir.extend(0.0).to_array(),
                right: f.right.extend(0.0).to_array(),
                up: f.up.extend(0.0).to_array(),
            }));
            t.tris.extend(
                m.direction_triangles
                    .iter()
                    .chain(&m.lower_triangles)
                    .map(|x| [x[0], x[1], x[2], 0]),
            );
            t.roots.extend(
                m.layer_roots
                    .iter()
                    .map(|r| r.map_or(u32::MAX, |r| r + node_base)),
            );
            t.nodes.extend_from_slice(&s.atlas.nodes);
            t.trims.extend(forest_format::trim::node_trims(
                &s.atlas.nodes,
                &m.layer_roots,
                &s.layers,
                m.levels,
            ));
            t.layers += m.params.layers();
            t.max_levels = t.max_levels.max(m.levels);
            t.quads_per_tree = t.quads_per_tree.max(3 * m.params.slabs);
        }
        t.instances = gpu_instances(forest);
        t.presort_dirs = forest
            .presort
            .directions
            .iter()
            .map(|d| d.extend(0.0).to_array())
            .collect();
        t.presort = forest.presort.orders.concat();
        Ok(t)
    }
}

/// The forest's instances in their GPU form (rotation as cos/sin).
pub fn gpu_instances(forest: &Forest) -> Vec<GpuInstance> {
    forest
        .instances
        .iter()
        .enumerate()
        .map(|(k, i)| GpuInstance {
            position: i.position,
            scale: i.scale,
            cos_rot: i.rotation.cos(),
            sin_rot: i.rotation.sin(),
            species: i.species,
            colour: forest.colouring.as_ref().map_or(0, |c| c.code(k)),
        })
        .collect()
}

/// Box-filter a premultiplied RGBA8 image to half size, in linear space: its RGB is sRGB-encoded
/// when `table` decodes sRGB (and is encoded again), linear when `table` is `None`.
fn downsample(src: &[u8], side: usize, table: Option<&[f32; 256]>) -> Vec<u8> {
    let decode = |v: u8| table.map_or(f32::from(v) / 255.0, |t| t[v as usize]);
    let encode = |v: f32| {
        if table.is_some() {
            srgb_encode(v)
        } else {
            v.clamp(0.0, 1.0)
        }
    };
    let half = side / 2;
    let mut out = vec![0u8; half * half * 4];
    for y in 0..half {
        for x in 0..half {
            let mut acc = [0f32; 4];
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let i = ((2 * y + dy) * side + 2 * x + dx) * 4;
                for c in 0..3 {
                    acc[c] += decode(src[i + c]);
                }
                acc[3] += f32::from(src[i + 3]);
            }
            let o = (y * half + x) * 4;
            for c in 0..3 {
                out[o + c] = (encode(acc[c] / 4.0) * 255.0).round() as u8;
            }
            out[o + 3] = (acc[3] / 4.0).round() as u8;
        }
    }
    out
}

/// Mip levels of a colour layer: down to 4×4 (the BC block), at least one.
pub fn colour_mip_count(resolution: u32) -> u32 {
    resolution.trailing_zeros().saturating_sub(1).max(1)
}

/// Every layer's mip chain (layer-major), encoded as BC7 or kept as RGBA8; layers in parallel:
/// the albedo layers (sRGB) or, with `surface`, the surface layers (linear).
/// `progress(done, total)` is called as layers finish.
fn colour_data(
    species: &[SpeciesData],
    resolution: u32,
    bc7: bool,
    surface: bool,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Vec<u8> {
    use rayon::prelude::*;
    let srgb = srgb_decode_table();
    let table = (!surface).then_some(&srgb);
    let mips = colour_mip_count(resolution);
    let settings = intel_tex_2::bc7::alpha_very_fast_settings();
    let layers: Vec<&[u8]> = species
        .iter()
        .map(|s| if surface { &s.surface } else { &s.layers })
        .flat_map(|l| (0..l.count).map(|k| l.layer(k)))
        .collect();
    let done = std::sync::atomic::AtomicU64::new(0);
    let total = layers.len() as u64;
    let chains: Vec<Vec<u8>> = layers
        .par_iter()
        .map(|layer| {
            let mut out = Vec::new();
            let mut img = layer.to_vec();
            let mut side = resolution as usize;
            for m in 0..mips {
                if m > 0 {
                    img = downsample(&img, side, table);
                    side /= 2;
                }
                if bc7 && side >= 4 {
                    let surface = intel_tex_2::RgbaSurface {
                        data: &img,
                        width: side as u32,
                        height: side as u32,
                        stride: side as u32 * 4,
                    };
                    out.extend(intel_tex_2::bc7::compress_blocks(&settings, &surface));
                } else {
                    out.extend_from_slice(&img);
                }
            }
            progress(
                done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1,
                total,
            );
            out
        })
        .collect();
    chains.concat()
}

/// The uploaded scene.
pub struct GpuScene {
    /// CPU copies of the tables.
    pub tables: SceneTables,
    /// Colour layers (premultiplied albedo and coverage) of all species.
    pub colour: wgpu::Texture,
    /// Surface layers of all species, the same layout as `colour` (premultiplied octahedral
    /// normal, sky visibility, translucency; linear).
    pub surface: wgpu::Texture,
    /// Opacity volumes of all species, stacked ([`crate::extend::opacity_texture`]).
    pub opacity: wgpu::Texture,
    /// Node texture (`Rgba32Uint`, [`NODE_TEXTURE_WIDTH`] wide): the node's two words, its
    /// covered box and its opaque share ([`forest_format::trim::node_trims`]).
    pub nodes: wgpu::Texture,
    /// Presort texture (`R32Uint`, [`PRESORT_TEXTURE_WIDTH`] wide).
    pub presort: wgpu::Texture,
    /// Instance buffer.
    pub instances: wgpu::Buffer,
    /// Species table.
    pub species: wgpu::Buffer,
    /// Direction frames.
    pub frames: wgpu::Buffer,
    /// Direction triangles.
    pub tris: wgpu::Buffer,
    /// Layer roots.
    pub roots: wgpu::Buffer,
    /// Presort directions.
    pub presort_dirs: wgpu::Buffer,
    /// The forest's terrain (its heights; a single zero without one).
    pub terrain: crate::terrain::GpuTerrain,
    /// The heights between which the forest's shadow receivers lie (its trees over its
    /// ground; the shadow cascades are fitted to it).
    pub band: crate::shadow::ReceiverBand,
    /// Bytes of all the above on the GPU.
    pub bytes: u64,
    /// Whether colour is BC7 (else RGBA8).
    pub bc7: bool,
}

fn storage<T: bytemuck::Pod + Default>(ctx: &GpuContext, label: &str, data: &[T]) -> wgpu::Buffer {
    let one = [T::default()];
    let data: &[T] = if data.is_empty() { &one } else { data };
    ctx.device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytemuck::cast_slice(data),
            usage: wgpu::BufferUsages::STORAGE,
        })
}

fn u32_texture(
    ctx: &GpuContext,
    label: &str,
    format: wgpu::TextureFormat,
    width: u32,
    texel_bytes: usize,
    bytes: &[u8],
) -> Result<wgpu::Texture, RenderError> {
    let texels = bytes.len() / texel_bytes;
    let height = texels.div_ceil(width as usize).max(1) as u32;
    let max = ctx.device.limits().max_texture_dimension_2d;
    crate::error::within_limit(
        || format!("the {label} texture (rows)"),
        height.into(),
        max.into(),
        "",
    )?;
    let mut padded = bytes.to_vec();
    padded.resize(width as usize * height as usize * texel_bytes, 0);
    Ok(ctx.device.create_texture_with_data(
        &ctx.queue,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        &padded,
    ))
}

/// A texture array of every species' layers with their mip chains (`data` from
/// [`colour_data`]): BC7 or RGBA8, sRGB or linear; one blank layer when there are none. Returns
/// it and its bytes.
fn layer_texture(
    ctx: &GpuContext,
    label: &str,
    tables: &SceneTables,
    bc7: bool,
    srgb: bool,
    data: Vec<u8>,
) -> (wgpu::Texture, u64) {
    let format = match (bc7, srgb) {
        (true, true) => wgpu::TextureFormat::Bc7RgbaUnormSrgb,
        (true, false) => wgpu::TextureFormat::Bc7RgbaUnorm,
        (false, true) => wgpu::TextureFormat::Rgba8UnormSrgb,
        (false, false) => wgpu::TextureFormat::Rgba8Unorm,
    };
    let res = tables.resolution.max(1);
    let data = if tables.layers == 0 {
        vec![
            0u8;
            if bc7 {
                16
            } else {
                4 * res as usize * res as usize
            }
        ]
    } else {
        data
    };
    let texture = ctx.device.create_texture_with_data(
        &ctx.queue,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: res,
                height: res,
                depth_or_array_layers: tables.layers.max(1),
            },
            mip_level_count: if tables.layers == 0 {
                1
            } else {
                colour_mip_count(res)
            },
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        &data,
    );
    (texture, data.len() as u64)
}

impl GpuScene {
    /// Upload species and a forest, colour in the automatic format.
    pub fn new(
        ctx: &GpuContext,
        species: &[SpeciesData],
        forest: &Forest,
    ) -> Result<Self, RenderError> {
        Self::with_format(ctx, species, forest, ColourFormat::Auto)
    }

    /// Upload species and a forest with the given colour format.
    pub fn with_format(
        ctx: &GpuContext,
        species: &[SpeciesData],
        forest: &Forest,
        colour_format: ColourFormat,
    ) -> Result<Self, RenderError> {
        Self::with_progress(ctx, species, forest, colour_format, &|_, _| {})
    }

    /// [`GpuScene::with_format`], calling `progress(done, total)` as colour layers are
    /// prepared (mip chains, and BC7 encoding where the GPU has it: the long step of a
    /// scene with many species at high resolution).
    pub fn with_progress(
        ctx: &GpuContext,
        species: &[SpeciesData],
        forest: &Forest,
        colour_format: ColourFormat,
        progress: &(dyn Fn(u64, u64) + Sync),
    ) -> Result<Self, RenderError> {
        let tables = SceneTables::new(species, forest)?;
        let terrain = crate::terrain::GpuTerrain::new(&ctx.device, forest.terrain.as_ref())?;
        let limits = ctx.device.limits();
        crate::error::within_limit(
            || "the colour atlas (texture array layers)".into(),
            tables.layers.into(),
            limits.max_texture_array_layers.into(),
            "",
        )?;
        let bc7 = ctx.use_bc7(colour_format) && tables.resolution >= 4;
        let res = tables.resolution.max(1);
        // Progress counts the albedo and the surface layers.
        let total = 2 * u64::from(tables.layers);
        let half = u64::from(tables.layers);
        let data = colour_data(species, res, bc7, false, &|d, _| progress(d, total));
        let surface_data = colour_data(species, res, bc7, true, &|d, _| progress(half + d, total));
        let (colour, colour_bytes) = layer_texture(ctx, "colour layers", &tables, bc7, true, data);
        let (surface, surface_bytes) =
            layer_texture(ctx, "surface layers", &tables, bc7, false, surface_data);
        let node_texels: Vec<[u32; 4]> = tables
            .nodes
            .iter()
            .zip(&tables.trims)
            .map(|(n, &[t, opaque])| {
                let [child, depth]: [u32; 2] = bytemuck::cast(*n);
                [child, depth, t, opaque]
            })
            .collect();
        let nodes = u32_texture(
            ctx,
            "nodes",
            wgpu::TextureFormat::Rgba32Uint,
            NODE_TEXTURE_WIDTH,
            16,
            bytemuck::cast_slice(&node_texels),
        )?;
        let presort = u32_texture(
            ctx,
            "presort",
            wgpu::TextureFormat::R32Uint,
            PRESORT_TEXTURE_WIDTH,
            4,
            bytemuck::cast_slice(&tables.presort),
        )?;
        let volumes: Vec<_> = species.iter().map(|s| &s.opacity).collect();
        let (opacity, opacity_bytes) =
            crate::opacity::opacity_texture(&ctx.device, &ctx.queue, &volumes)?;
        let bytes = colour_bytes
            + surface_bytes
            + opacity_bytes
            + u64::from(nodes.height()) * u64::from(NODE_TEXTURE_WIDTH) * 16
            + u64::from(presort.height()) * u64::from(PRESORT_TEXTURE_WIDTH) * 4
            + (std::mem::size_of_val(tables.instances.as_slice())
                + std::mem::size_of_val(tables.species.as_slice())
                + std::mem::size_of_val(tables.frames.as_slice())
                + std::mem::size_of_val(tables.tris.as_slice())
                + std::mem::size_of_val(tables.roots.as_slice())
                + std::mem::size_of_val(tables.presort_dirs.as_slice())) as u64
            + terrain.bytes();
        let spheres: Vec<[f32; 4]> = tables.species.iter().map(|s| s.sphere).collect();
        let band =
            crate::shadow::ReceiverBand::of(&tables.instances, &spheres, forest.terrain.as_ref());
        Ok(Self {
            band,
            instances: storage(ctx, "instances", &tables.instances),
            species: storage(ctx, "species", &tables.species),
            frames: storage(ctx, "frames", &tables.frames),
            tris: storage(ctx, "direction triangles", &tables.tris),
            roots: storage(ctx, "roots", &tables.roots),
            presort_dirs: storage(ctx, "presort directions", &tables.presort_dirs),
            terrain,
            tables,
            colour,
            surface,
            opacity,
            nodes,
            presort,
            bytes,
            bc7,
        })
    }
}
