//! A forest's models and trees on the GPU: uploaded once, shared by every
//! [`super::GeometryRenderer`] that draws that forest (each camera's view, each target
//! format), as the quad stream's views share one `GpuScene`.

use forest_format::forest::Forest;
use forest_format::model::{BANDS, BILLBOARD_RESOLUTION};
use forest_render::context::{GpuContext, RenderError};
use forest_render::error::{storage_limit, within_limit};
use forest_render::extend::GeometryCapacity;
use forest_render::extend::GpuTerrain;
use forest_render::shadow::ReceiverBand;
use wgpu::util::DeviceExt;

use super::params::SpeciesFigures;
use super::prepare::PreparedGeometry;
use super::textures::{MATERIAL_TEXTURE_SIZE, layered_texture, upload_layers};

/// Every species' prepared model (vertices, materials and their textures, billboards, leaf
/// tables, opacity volumes) and the forest's instances and terrain on one device. Read-only
/// once built: renderers bind it and never write it. Share it with an `Arc`; a renderer
/// built from it must be on the same device.
pub struct GpuModels {
    pub(super) instances: wgpu::Buffer,
    pub(super) species: wgpu::Buffer,
    /// `[instances, species, 0, 0]`, the classification's constants.
    pub(super) consts: wgpu::Buffer,
    pub(super) leaf_end: wgpu::Buffer,
    pub(super) vertices: wgpu::Buffer,
    /// The triangles' presorted draw orders, one per view-direction bin
    /// ([`super::order::draw_orders`]).
    pub(super) draw_order: wgpu::Buffer,
    pub(super) materials: wgpu::Buffer,
    pub(super) material_view: wgpu::TextureView,
    pub(super) sampler: wgpu::Sampler,
    pub(super) billboard_surface_view: wgpu::TextureView,
    pub(super) leaf_centre: wgpu::Buffer,
    pub(super) billboard_view: wgpu::TextureView,
    pub(super) opacity_view: wgpu::TextureView,
    pub(super) opacity_sampler: wgpu::Sampler,
    pub(super) terrain: GpuTerrain,
    /// The lists' sizes: bands × species segments, every instance listed.
    pub(super) capacity: GeometryCapacity,
    pub(super) species_count: u32,
    pub(super) instance_count: u32,
    /// The heights between which the forest's receivers lie.
    pub(super) band: ReceiverBand,
    /// Per-species figures, in the forest's species order.
    pub(super) figures: Vec<SpeciesFigures>,
    /// Bytes of GPU memory uploaded (buffers and textures).
    bytes: u64,
}

/// Refuse, before anything is allocated, what a device of `limits` cannot bind: each storage
/// buffer above the storage-binding limit (or the largest buffer), each layered texture with
/// more layers than an array may have, and the species' opacity volumes stacked deeper than a
/// 3D texture may be. `instances` is the forest's tree count. The message names the buffer,
/// its size and the limit.
pub fn check_limits(
    limits: &wgpu::Limits,
    prepared: &PreparedGeometry,
    instances: usize,
) -> Result<(), RenderError> {
    let bytes = |n: usize, each: usize| (n as u64).saturating_mul(each as u64);
    let lighter = ": draw fewer species or lighter models (fewer triangles)";
    let storage = [
        (
            "the models' vertices, 3 per triangle of every LOD (bytes)",
            prepared.vertex_bytes(),
            lighter,
        ),
        (
            "the models' presorted draw orders, 4 bytes per triangle and view-direction bin \
             (bytes)",
            std::mem::size_of_val(prepared.draw_order.as_slice()) as u64,
            lighter,
        ),
        (
            "the leaves' centres (bytes)",
            std::mem::size_of_val(prepared.leaf_centre.as_slice()) as u64,
            lighter,
        ),
        (
            "the leaves' ends (bytes)",
            std::mem::size_of_val(prepared.leaf_end.as_slice()) as u64,
            lighter,
        ),
        (
            "the species' table (bytes)",
            std::mem::size_of_val(prepared.geo_species.as_slice()) as u64,
            ": draw fewer species",
        ),
        (
            "the models' materials (bytes)",
            std::mem::size_of_val(prepared.materials.as_slice()) as u64,
            ": draw fewer species or models with fewer materials",
        ),
        (
            "the forest's instances (bytes)",
            bytes(
                instances,
                std::mem::size_of::<forest_render::gpu_types::GpuInstance>(),
            ),
            ": draw fewer trees",
        ),
        (
            "the geometry methods' visible list, 4 bytes per tree and listing (bytes)",
            bytes(instances, 4).saturating_mul(u64::from(prepared.listings())),
            ": draw fewer trees",
        ),
    ];
    let limit = storage_limit(limits);
    for (what, needed, hint) in storage {
        within_limit(|| what.into(), needed, limit, hint)?;
    }
    let layers = [
        (
            "the models' material texture layers",
            prepared.material_layers(),
            ": draw fewer species or models with fewer textures",
        ),
        (
            "the billboards' texture layers",
            prepared.billboard_layers.len(),
            ": draw fewer species",
        ),
        (
            "the billboards' surface layers",
            prepared.billboard_surface.len(),
            ": draw fewer species",
        ),
    ];
    let limit = u64::from(limits.max_texture_array_layers);
    for (what, needed, hint) in layers {
        within_limit(|| what.into(), needed as u64, limit, hint)?;
    }
    forest_render::extend::check_volumes(limits, prepared.opacity.len())
}

impl GpuModels {
    /// Upload `prepared` (one entry per species of `forest`, in its order) with the forest's
    /// instances and terrain. Refused, before anything is allocated, when the species counts
    /// differ, the device cannot draw the geometry methods (no indirect draws with a first
    /// instance), or a buffer or texture exceeds the device's limits ([`check_limits`], and the
    /// terrain's).
    pub fn new(
        ctx: &GpuContext,
        prepared: &PreparedGeometry,
        forest: &Forest,
    ) -> Result<Self, RenderError> {
        let PreparedGeometry {
            vertices,
            geo_species,
            materials,
            layer_mips,
            billboard_layers,
            billboard_surface,
            leaf_end,
            leaf_centre,
            opacity,
            draw_order,
            figures,
        } = prepared;
        let capacity = checked_capacity(ctx, prepared, forest)?;
        // Each species in the forest's colours.
        let geo_species: &Vec<_> = &geo_species
            .iter()
            .enumerate()
            .map(|(k, s)| crate::gpu_types::GpuGeoSpecies {
                colour: forest.tree_colour(k),
                ..*s
            })
            .collect();
        let device = &ctx.device;
        let terrain = GpuTerrain::new(device, forest.terrain.as_ref())?;
        let instances = forest_render::scene::gpu_instances(forest);
        let mut bytes = terrain.bytes();
        use wgpu::BufferUsages as U;
        let mut init = |label: &str, contents: &[u8], usage: U| {
            // Empty tables still bind one element of any of their types.
            let pad = [0u8; 256];
            let contents = if contents.is_empty() {
                &pad[..]
            } else {
                contents
            };
            bytes += contents.len() as u64;
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let instance_buf = init(
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
        let draw_order_buf = init(
            "geometry draw orders",
            bytemuck::cast_slice(draw_order),
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
        let consts = init(
            "geometry constants",
            bytemuck::cast_slice(&[instances.len() as u32, geo_species.len() as u32, 0, 0]),
            U::UNIFORM,
        );
        let (material_view, material_bytes) = upload_layers(
            ctx,
            "material textures",
            MATERIAL_TEXTURE_SIZE,
            layer_mips,
            false,
        );
        let (billboard_view, billboard_bytes) = layered_texture(
            ctx,
            "billboards",
            BILLBOARD_RESOLUTION,
            billboard_layers,
            false,
        );
        let (billboard_surface_view, billboard_surface_bytes) = layered_texture(
            ctx,
            "billboard surfaces",
            BILLBOARD_RESOLUTION,
            billboard_surface,
            true,
        );
        let (opacity_texture, opacity_bytes) = forest_render::extend::opacity_texture(
            device,
            &ctx.queue,
            &opacity.iter().collect::<Vec<_>>(),
        )?;
        bytes += material_bytes + billboard_bytes + billboard_surface_bytes + opacity_bytes;
        let (sampler, opacity_sampler) = samplers(device);
        Ok(Self {
            instances: instance_buf,
            species: species_buf,
            consts,
            leaf_end: leaf_end_buf,
            vertices: vertex_buf,
            draw_order: draw_order_buf,
            materials: material_buf,
            material_view,
            sampler,
            billboard_surface_view,
            leaf_centre: leaf_centre_buf,
            billboard_view,
            opacity_view: opacity_texture.create_view(&Default::default()),
            opacity_sampler,
            capacity,
            species_count: geo_species.len() as u32,
            instance_count: instances.len() as u32,
            band: ReceiverBand::of(
                &instances,
                &geo_species.iter().map(|s| s.sphere).collect::<Vec<_>>(),
                forest.terrain.as_ref(),
            ),
            figures: figures.clone(),
            terrain,
            bytes,
        })
    }

    /// Bytes of GPU memory the upload took (buffers and textures).
    pub fn bytes(&self) -> u64 {
        self.bytes
    }

    /// Per-species figures, in the forest's species order.
    pub fn figures(&self) -> &[SpeciesFigures] {
        &self.figures
    }
}

/// The geometry renderer draws each segment with an indirect draw whose first instance is
/// the segment's offset in the visible list.
pub(super) fn require_indirect_first_instance(ctx: &GpuContext) -> Result<(), RenderError> {
    if ctx
        .device
        .features()
        .contains(wgpu::Features::INDIRECT_FIRST_INSTANCE)
    {
        Ok(())
    } else {
        Err(RenderError::MissingFeature {
            method: "the geometry renderer",
            feature: "indirect draws with a first instance (INDIRECT_FIRST_INSTANCE)",
        })
    }
}

/// The species counts agree, the device can draw the geometry methods and hold the
/// prepared geometry ([`check_limits`]): the visible list's capacity.
fn checked_capacity(
    ctx: &GpuContext,
    prepared: &PreparedGeometry,
    forest: &Forest,
) -> Result<GeometryCapacity, RenderError> {
    if prepared.geo_species.len() != forest.species.len() {
        return Err(RenderError::SpeciesCount {
            forest: forest.species.len(),
            given: prepared.geo_species.len(),
            what: "models",
        });
    }
    require_indirect_first_instance(ctx)?;
    check_limits(&ctx.device.limits(), prepared, forest.instances.len())?;
    GeometryCapacity::new(
        forest.instances.len() as u32,
        prepared.geo_species.len() as u32,
        BANDS,
        prepared.listings(),
    )
    .ok_or_else(|| {
        RenderError::Parameter(format!(
            "{} trees listed {} times overflow the geometry methods' visible list",
            forest.instances.len(),
            prepared.listings()
        ))
    })
}

/// The material textures' sampler (repeating, trilinear) and the opacity volumes'.
fn samplers(device: &wgpu::Device) -> (wgpu::Sampler, wgpu::Sampler) {
    let opacity_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("opacity"),
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        ..Default::default()
    });
    let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("material"),
        address_mode_u: wgpu::AddressMode::Repeat,
        address_mode_v: wgpu::AddressMode::Repeat,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        ..Default::default()
    });
    (sampler, opacity_sampler)
}
