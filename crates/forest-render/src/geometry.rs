//! Full geometry: the ground-truth reference (supersampled) and the brute-force baseline.
//!
//! Every visible tree's triangles, instanced per species, frustum-culled on the GPU (one
//! compute pass appends visible instances into per-species segments, one writes the indirect
//! draw arguments), alpha-tested, shaded with `forest_format::shading` in object space using
//! per-vertex sun visibility traced by the bake (`forest_bake::reference_vertices`).

use forest_bake::{Mesh, RefVertex};
use forest_format::forest::Forest;
use forest_format::shading::Lighting;
use wgpu::util::DeviceExt;

use crate::camera::{Camera, CameraError};
use crate::context::{GpuContext, RenderError};
use crate::gpu_types::GpuCamera;
use crate::passes::draw::DEPTH_FORMAT;
use crate::renderer::Background;
use crate::target::Target;

/// Side of every material texture layer on the GPU.
pub const MATERIAL_TEXTURE_SIZE: u32 = 512;
const NONE: u32 = u32::MAX;

/// A species for the full-geometry renderer.
pub struct GeometrySpecies {
    /// The model.
    pub mesh: Mesh,
    /// The lighting its atlas was baked with (so both renderers shade alike).
    pub lighting: Lighting,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
struct GeoSpecies {
    sphere: [f32; 4],
    first_vertex: u32,
    vertex_count: u32,
    seg_base: u32,
    pad: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
struct GeoMaterial {
    kd: [f32; 4],
    layer: u32,
    alpha_tested: u32,
    pad: [u32; 2],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
struct Light {
    sun_dir: [f32; 4],
    sun: [f32; 4],
    sky: [f32; 4],
    ground: [f32; 4],
}

/// The full-geometry renderer of one forest.
pub struct GeometryRenderer {
    camera: wgpu::Buffer,
    reset: wgpu::ComputePipeline,
    cull: wgpu::ComputePipeline,
    args_pipeline: wgpu::ComputePipeline,
    draw: wgpu::RenderPipeline,
    ground_pipeline: wgpu::RenderPipeline,
    ground_bg: wgpu::BindGroup,
    compute_bg: wgpu::BindGroup,
    draw_bg: wgpu::BindGroup,
    args: wgpu::Buffer,
    species: u32,
    instances: u32,
    background: Background,
    /// Triangles of one copy of every species.
    pub triangles: Vec<u64>,
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

impl GeometryRenderer {
    /// Upload the species' geometry and the forest's instances.
    pub fn new(
        ctx: &GpuContext,
        species: &[GeometrySpecies],
        forest: &Forest,
        format: wgpu::TextureFormat,
        background: Background,
    ) -> Result<Self, RenderError> {
        if species.len() != forest.species.len() {
            return Err(RenderError::Scene(format!(
                "the forest names {} species but {} models were given",
                forest.species.len(),
                species.len()
            )));
        }
        if !ctx
            .device
            .features()
            .contains(wgpu::Features::INDIRECT_FIRST_INSTANCE)
        {
            return Err(RenderError::Scene(
                "the full-geometry renderer needs indirect draws with a first instance \
                 (INDIRECT_FIRST_INSTANCE), which this adapter lacks"
                    .into(),
            ));
        }
        let device = &ctx.device;
        let mut vertices: Vec<RefVertex> = Vec::new();
        let mut geo_species = Vec::new();
        let mut materials = Vec::new();
        let mut layers: Vec<image::RgbaImage> = Vec::new();
        let mut triangles = Vec::new();
        let mut per_species = vec![0u32; species.len()];
        for i in &forest.instances {
            per_species[i.species as usize] += 1;
        }
        let mut seg = 0u32;
        for (k, s) in species.iter().enumerate() {
            let material_base = materials.len() as u32;
            for m in &s.mesh.materials {
                let layer = if m.colour.is_some() || m.alpha.is_some() {
                    layers.push(material_layer(&s.mesh, m.colour, m.alpha));
                    layers.len() as u32 - 1
                } else {
                    NONE
                };
                materials.push(GeoMaterial {
                    kd: m.kd.extend(m.translucency).to_array(),
                    layer,
                    alpha_tested: u32::from(m.alpha.is_some()),
                    pad: [0; 2],
                });
            }
            let mut v = forest_bake::reference_vertices(&s.mesh, &s.lighting);
            v.iter_mut().for_each(|x| x.material += material_base);
            let sphere = forest_bake::bounding_sphere(&s.mesh);
            geo_species.push(GeoSpecies {
                sphere: sphere.center.extend(sphere.radius).to_array(),
                first_vertex: vertices.len() as u32,
                vertex_count: v.len() as u32,
                seg_base: seg,
                pad: 0,
            });
            triangles.push(v.len() as u64 / 3);
            seg += per_species[k];
            vertices.extend(v);
        }
        let l = species
            .first()
            .map(|s| s.lighting)
            .unwrap_or(Lighting::with_sun(30.0, 55.0));
        let light = Light {
            sun_dir: l.sun_dir.extend(0.0).to_array(),
            sun: l.sun.extend(0.0).to_array(),
            sky: l.sky.extend(0.0).to_array(),
            ground: l.ground.extend(0.0).to_array(),
        };
        let instances = crate::scene::gpu_instances(forest);
        use wgpu::BufferUsages as U;
        let init = |label: &str, bytes: &[u8], usage: U| {
            let pad = [0u8; 16];
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: if bytes.is_empty() { &pad } else { bytes },
                usage,
            })
        };
        let camera = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("geometry camera"),
            size: std::mem::size_of::<GpuCamera>() as u64,
            usage: U::UNIFORM | U::COPY_DST,
            mapped_at_creation: false,
        });
        let inst_buf = init(
            "geometry instances",
            bytemuck::cast_slice(&instances),
            U::STORAGE,
        );
        let species_buf = init(
            "geometry species",
            bytemuck::cast_slice(&geo_species),
            U::STORAGE,
        );
        let vertex_buf = init(
            "geometry vertices",
            bytemuck::cast_slice(&vertices),
            U::STORAGE,
        );
        let material_buf = init(
            "geometry materials",
            bytemuck::cast_slice(&materials),
            U::STORAGE,
        );
        let light_buf = init("geometry light", bytemuck::bytes_of(&light), U::UNIFORM);
        let consts = init(
            "geometry constants",
            bytemuck::cast_slice(&[instances.len() as u32, species.len() as u32, 0, 0]),
            U::UNIFORM,
        );
        let visible = init(
            "visible instances",
            &vec![0u8; instances.len().max(1) * 4],
            U::STORAGE,
        );
        let counts = init(
            "visible counts",
            &vec![0u8; species.len().max(1) * 4],
            U::STORAGE,
        );
        let args = init(
            "geometry draw args",
            &vec![0u8; species.len().max(1) * 16],
            U::STORAGE | U::INDIRECT,
        );

        // Material textures: one array layer per textured material, with mips.
        let mips = MATERIAL_TEXTURE_SIZE.trailing_zeros() + 1;
        let layer_count = layers.len().max(1) as u32;
        let mut data = Vec::new();
        if layers.is_empty() {
            layers.push(image::RgbaImage::from_pixel(
                MATERIAL_TEXTURE_SIZE,
                MATERIAL_TEXTURE_SIZE,
                image::Rgba([255; 4]),
            ));
        }
        for img in &layers {
            let mut m = img.clone();
            for level in 0..mips {
                if level > 0 {
                    let s = (MATERIAL_TEXTURE_SIZE >> level).max(1);
                    m = image::imageops::resize(&m, s, s, image::imageops::FilterType::Triangle);
                }
                data.extend_from_slice(m.as_raw());
            }
        }
        let texture = device.create_texture_with_data(
            &ctx.queue,
            &wgpu::TextureDescriptor {
                label: Some("material textures"),
                size: wgpu::Extent3d {
                    width: MATERIAL_TEXTURE_SIZE,
                    height: MATERIAL_TEXTURE_SIZE,
                    depth_or_array_layers: layer_count,
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
            source: wgpu::ShaderSource::Wgsl(crate::passes::GEOMETRY_CULL_WGSL.concat().into()),
        });
        let draw_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("geometry draw"),
            source: wgpu::ShaderSource::Wgsl(crate::passes::GEOMETRY_DRAW_WGSL.concat().into()),
        });
        // One explicit layout shared by the three compute entry points (one bind group).
        let entries: Vec<wgpu::BindGroupLayoutEntry> = crate::passes::layout_entries(
            &[
                crate::passes::Slot::Uniform,
                crate::passes::Slot::Read,
                crate::passes::Slot::Read,
                crate::passes::Slot::ReadWrite,
                crate::passes::Slot::ReadWrite,
                crate::passes::Slot::ReadWrite,
                crate::passes::Slot::Uniform,
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
        let (reset, cull, args_pipeline) = (cpl("geo_reset"), cpl("geo_cull"), cpl("geo_args"));
        let compute_bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("geometry cull"),
            layout: &compute_layout,
            entries: &crate::passes::numbered(vec![
                camera.as_entire_binding(),
                inst_buf.as_entire_binding(),
                species_buf.as_entire_binding(),
                visible.as_entire_binding(),
                counts.as_entire_binding(),
                args.as_entire_binding(),
                consts.as_entire_binding(),
            ]),
        });
        let render_pipeline = |vs: &str, fs: &str, topology| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(vs),
                layout: None,
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
        let draw = render_pipeline("vs_geo", "fs_geo", wgpu::PrimitiveTopology::TriangleList);
        let ground_pipeline = render_pipeline(
            "vs_ground",
            "fs_ground",
            wgpu::PrimitiveTopology::TriangleStrip,
        );
        let ground_buf = init(
            "geometry ground",
            bytemuck::bytes_of(&crate::renderer::ground_uniform(&l, &instances)),
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
        let draw_bg = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("geometry draw"),
            layout: &draw.get_bind_group_layout(0),
            entries: &crate::passes::numbered(vec![
                camera.as_entire_binding(),
                inst_buf.as_entire_binding(),
                vertex_buf.as_entire_binding(),
                visible.as_entire_binding(),
                material_buf.as_entire_binding(),
                wgpu::BindingResource::TextureView(&view),
                wgpu::BindingResource::Sampler(&sampler),
                light_buf.as_entire_binding(),
            ]),
        });
        Ok(Self {
            camera,
            reset,
            cull,
            args_pipeline,
            draw,
            ground_pipeline,
            ground_bg,
            compute_bg,
            draw_bg,
            args,
            species: species.len() as u32,
            instances: instances.len() as u32,
            background,
            triangles,
        })
    }

    /// Write the camera, cull, draw into `target`, and submit.
    pub fn render_frame(
        &self,
        ctx: &GpuContext,
        camera: &Camera,
        target: &Target,
    ) -> Result<(), CameraError> {
        camera.validate()?;
        ctx.queue
            .write_buffer(&self.camera, 0, bytemuck::bytes_of(&camera.to_gpu()));
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_bind_group(0, &self.compute_bg, &[]);
            pass.set_pipeline(&self.reset);
            pass.dispatch_workgroups(self.species.div_ceil(64).max(1), 1, 1);
            pass.set_pipeline(&self.cull);
            pass.dispatch_workgroups(self.instances.div_ceil(256).max(1), 1, 1);
            pass.set_pipeline(&self.args_pipeline);
            pass.dispatch_workgroups(self.species.div_ceil(64).max(1), 1, 1);
        }
        {
            let mut pass = crate::target::begin_pass(
                &mut enc,
                "geometry",
                &target.colour_view,
                &target.depth_view,
                self.background.clear_colour(),
                None,
            );
            if self.background == Background::Sky {
                pass.set_pipeline(&self.ground_pipeline);
                pass.set_bind_group(0, &self.ground_bg, &[]);
                pass.draw(0..4, 0..1);
            }
            pass.set_pipeline(&self.draw);
            pass.set_bind_group(0, &self.draw_bg, &[]);
            for s in 0..self.species {
                pass.draw_indirect(&self.args, u64::from(s) * 16);
            }
        }
        ctx.queue.submit([enc.finish()]);
        Ok(())
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
