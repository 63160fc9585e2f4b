//! The host side of the embedding example: a renderer with its own sky and ground that draws a
//! forest through the public API of `forest-render` and `forest-baselines`, into targets it
//! owns and clears itself. It uses reverse-Z with an infinite far plane, as many engines do.
//!
//! The forest is drawn by the hybrid (near trees as their models, the rest as the quad stream)
//! where every atlas holds a model, else by the quad stream. Per frame: the host writes its own
//! uniform, `ForestRenderer::prepare` writes the forest's cameras (its one upload per form),
//! `encode_compute` records the culls and the refinement, and the host's own render pass draws
//! the ground and then `render`s the trees into it.
//!
//! With its sun's shadows on, the host owns a reverse-Z shadow map (one cascade around the
//! view, fitted with the library's `fit_cascades`): a quad stream casts the forest into it
//! (`prepare_light`, `encode_compute`, `render_depth` in the host's depth-only pass), the
//! host's ground reads it, and the forest's trees receive it (`receive_host_shadows`,
//! `set_host_cascades`).

use forest_render::ForestView;
use std::sync::Arc;

use forest_baselines::{ForestRenderer, GeometryRenderer, Hybrid, Method, PreparedGeometry};
use forest_format::forest::Forest;
use forest_render::options::{GROUND_MOSS, RendererOptions, SKY, ground_colour};
use forest_render::{FrameParams, GpuContext, GpuScene, QuadStream, RenderError};
use glam::{Mat4, Vec3};
use wgpu::util::DeviceExt;

/// Depth format of the host's targets.
pub const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The host's ground: a square around the eye, soil and moss in the library's pattern
/// (`ground_moss`, imported from the runtime's `ground` module by the composer).
const HOST_GROUND_WGSL: &str = r#"
#import ground

struct Host {
    view_proj: mat4x4<f32>, colour: vec4<f32>, moss: vec4<f32>, eye: vec4<f32>,
    // The sun's shadow map (reverse-Z): its matrix, the shadowed soil and moss, and in
    // `shade.x` 1 when the map is in use.
    shadow: mat4x4<f32>, soil_shadowed: vec4<f32>, moss_shadowed: vec4<f32>, shade: vec4<f32>,
}
@group(0) @binding(0) var<uniform> host: Host;
@group(0) @binding(1) var shadow_map: texture_depth_2d_array;
@group(0) @binding(2) var shadow_compare: sampler_comparison;
struct Out { @builtin(position) clip: vec4<f32>, @location(0) xz: vec2<f32> }

@vertex
fn vs(@builtin(vertex_index) vi: u32) -> Out {
    let s = host.colour.w;
    let x = select(-s, s, (vi & 1u) == 1u) + host.eye.x;
    let z = select(-s, s, (vi >> 1u) == 1u) + host.eye.z;
    return Out(host.view_proj * vec4<f32>(x, 0.0, z, 1.0), vec2<f32>(x, z));
}

@fragment
fn fs(in: Out) -> @location(0) vec4<f32> {
    let m = ground_moss(in.xz);
    let lit = mix(host.colour.xyz, host.moss.xyz, m);
    var sun = 1.0;
    if (host.shade.x != 0.0) {
        let c = host.shadow * vec4<f32>(in.xz.x, 0.0, in.xz.y, 1.0);
        let uv = vec2<f32>(0.5 + 0.5 * c.x, 0.5 - 0.5 * c.y);
        if (all(uv > vec2<f32>(0.0)) && all(uv < vec2<f32>(1.0))) {
            sun = textureSampleCompareLevel(shadow_map, shadow_compare, uv, 0, c.z + 1e-4);
        }
    }
    let shadowed = mix(host.soil_shadowed.xyz, host.moss_shadowed.xyz, m);
    return vec4<f32>(mix(shadowed, lit, sun), 1.0);
}
"#;

/// The host's uniform: its view-projection, the ground's soil colour and half side, its moss
/// colour, the eye; its shadow map's matrix, the soil and moss in shadow, and whether the map
/// is in use.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct HostUniform {
    view_proj: [[f32; 4]; 4],
    colour: [f32; 4],
    moss: [f32; 4],
    eye: [f32; 4],
    shadow: [[f32; 4]; 4],
    soil_shadowed: [f32; 4],
    moss_shadowed: [f32; 4],
    shade: [f32; 4],
}

/// Side of the host's shadow map (texels).
const SHADOW_SIZE: u32 = 1024;

/// The host's sun shadow map: one reverse-Z layer, and the stream that casts the forest into it.
struct Sun {
    layer: wgpu::TextureView,
    caster: QuadStream,
    options: forest_render::shadow::ShadowOptions,
}

/// World → clip with depth 1 − z: reverse-Z.
fn reverse_z(m: Mat4) -> Mat4 {
    Mat4::from_cols(
        glam::Vec4::X,
        glam::Vec4::Y,
        glam::Vec4::new(0.0, 0.0, -1.0, 0.0),
        glam::Vec4::new(0.0, 0.0, 1.0, 1.0),
    ) * m
}

/// A host renderer: sky (its clear colour), ground (its own pipeline), then the forest.
pub struct Host {
    ground: wgpu::RenderPipeline,
    uniform: wgpu::Buffer,
    bind: wgpu::BindGroup,
    ground_colour: [f32; 4],
    moss_colour: [f32; 4],
    soil_shadowed: [f32; 4],
    moss_shadowed: [f32; 4],
    depth: wgpu::TextureView,
    sun: Option<Sun>,
    /// The forest of this view.
    pub forest: ForestRenderer,
}

/// A reverse-Z perspective with an infinite far plane (60° vertical field of view, 0.1 m near).
pub fn projection(size: (u32, u32)) -> Mat4 {
    let aspect = size.0 as f32 / size.1 as f32;
    glam::camera::rh::proj::directx::perspective_infinite_reverse(60f32.to_radians(), aspect, 0.1)
}

/// The frame parameters of a camera at `eye` looking at `target`, under the default sun (the
/// host's own light would go in `light`: the forest is lit at run time), in `wind` (its
/// `time` the host's clock: the trees move).
pub fn frame(
    eye: Vec3,
    target: Vec3,
    size: (u32, u32),
    epsilon: f32,
    wind: forest_format::wind::Wind,
) -> FrameParams {
    FrameParams {
        view: glam::camera::rh::view::look_at_mat4(eye, target, Vec3::Y),
        proj: projection(size),
        viewport: size,
        epsilon,
        light: Default::default(),
        wind,
        season: None,
    }
}

fn depth_view(device: &wgpu::Device, size: (u32, u32)) -> wgpu::TextureView {
    device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some("host depth"),
            size: wgpu::Extent3d {
                width: size.0,
                height: size.1,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        })
        .create_view(&Default::default())
}

impl Host {
    /// The host's pipelines and the forest's renderer over `scene` for `format` targets of
    /// `size`, refined down to `min_epsilon` pixels at most (both size the stream): the hybrid
    /// over `models` (the species' prepared models, in `forest`'s species order), or the quad
    /// stream without them; with `shadows`, the host's sun shadow map, which the forest casts
    /// into and receives.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        ctx: &GpuContext,
        scene: Arc<GpuScene>,
        forest: &Forest,
        models: Option<&PreparedGeometry>,
        format: wgpu::TextureFormat,
        size: (u32, u32),
        min_epsilon: f32,
        shadows: bool,
    ) -> Result<Self, RenderError> {
        let opts = RendererOptions {
            format,
            depth_format: DEPTH,
            reverse_z: true,
            viewport: size,
            min_epsilon,
            ..Default::default()
        };
        // The ground colour `forest render` uses, so that the two frames can be compared.
        // A 10 km square around the eye.
        let ground_colour = ground_colour(&opts.lighting).extend(5000.0).to_array();
        let moss_colour = opts
            .lighting
            .shade(GROUND_MOSS, Vec3::Y, 1.0, 1.0, 0.0)
            .extend(0.0)
            .to_array();
        let device = &ctx.device;
        let stream = QuadStream::new(device, scene.clone(), &opts)?;
        let geometry = models
            .map(|m| GeometryRenderer::with_targets(ctx, m, forest, &opts))
            .transpose()?;
        let hybrid = geometry.is_some();
        let mut forest = ForestRenderer::new(stream, geometry);
        if hybrid {
            forest.set_method(ctx, Method::Hybrid(Hybrid::default()))?;
        }
        let map = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("host shadow map"),
            size: wgpu::Extent3d {
                width: if shadows { SHADOW_SIZE } else { 1 },
                height: if shadows { SHADOW_SIZE } else { 1 },
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let array = map.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let sun = if shadows {
            forest.receive_host_shadows(device, Some((&array, SHADOW_SIZE, true)));
            let options = forest_render::shadow::ShadowOptions {
                cascades: 1,
                resolution: SHADOW_SIZE,
                distance: 120.0,
                ..Default::default()
            };
            // The caster draws into the host's map: its depth format and convention; its
            // quads are thinned as the view's are.
            let mut caster = QuadStream::new(
                device,
                scene,
                &RendererOptions {
                    depth_format: DEPTH,
                    reverse_z: true,
                    viewport: (SHADOW_SIZE, SHADOW_SIZE),
                    min_epsilon: options.epsilon,
                    overdraw: 0.25,
                    ..Default::default()
                },
            )?;
            caster.set_sharpen_override(forest.method().quad_sharpen())?;
            Some(Sun {
                layer: map.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    ..Default::default()
                }),
                caster,
                options,
            })
        } else {
            None
        };
        // Soil and moss out of the sun (sky light alone).
        let shadowed = |albedo| {
            opts.lighting
                .shade(albedo, Vec3::Y, 0.0, 1.0, 0.0)
                .extend(0.0)
                .to_array()
        };
        let soil_shadowed = shadowed(forest_render::options::GROUND_ALBEDO);
        let moss_shadowed = shadowed(GROUND_MOSS);
        let ground = ground_pipeline(device, format);
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("host uniform"),
            contents: bytemuck::bytes_of(&HostUniform {
                view_proj: Mat4::IDENTITY.to_cols_array_2d(),
                colour: ground_colour,
                moss: moss_colour,
                eye: [0.0; 4],
                shadow: Mat4::IDENTITY.to_cols_array_2d(),
                soil_shadowed,
                moss_shadowed,
                shade: [0.0; 4],
            }),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let compare = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("host shadow compare"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::GreaterEqual),
            ..Default::default()
        });
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("host"),
            layout: &ground.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&array),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(&compare),
                },
            ],
        });
        Ok(Self {
            ground,
            uniform,
            bind,
            ground_colour,
            moss_colour,
            soil_shadowed,
            moss_shadowed,
            depth: depth_view(device, size),
            sun,
            forest,
        })
    }

    /// A new window size: the host's depth target and the forest's per-view buffers (the
    /// scene is kept).
    pub fn resize(&mut self, device: &wgpu::Device, size: (u32, u32)) -> Result<(), RenderError> {
        self.depth = depth_view(device, size);
        self.forest.resize(device, size)
    }

    /// Draw one frame into `colour` and submit it.
    pub fn draw(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        colour: &wgpu::TextureView,
        frame: &FrameParams,
    ) -> Result<(), RenderError> {
        let eye = frame.eye();
        let mut encoder = device.create_command_encoder(&Default::default());
        let mut shadow = (Mat4::IDENTITY, 0.0);
        if let Some(sun) = &mut self.sun {
            // The host's cascade (fitted as the forest fits its own, over every height: the
            // host's ground and objects receive too), in reverse-Z.
            let view = forest_render::shadow::ViewSlice {
                view_proj: frame.proj * frame.view,
                eye,
                forward: frame.forward(),
            };
            let to_light = frame.light.sun_dir;
            let cascades: Vec<_> = forest_render::shadow::fit_cascades(
                &view,
                to_light,
                &sun.options,
                forest_render::shadow::ReceiverBand::ANY,
            )
            .into_iter()
            .map(|c| forest_render::shadow::Cascade {
                view_proj: reverse_z(c.view_proj),
                ..c
            })
            .collect();
            let light = forest_render::shadow::LightParams {
                view_proj: cascades[0].view_proj,
                to_light,
                resolution: (SHADOW_SIZE, SHADOW_SIZE),
                epsilon: sun.options.epsilon,
                view_eye: eye,
            };
            sun.caster.prepare_light(device, queue, &light)?;
            sun.caster.encode_compute(&mut encoder);
            let mut pass = forest_render::extend::depth_pass(&mut encoder, &sun.layer, 0.0, None);
            // The host's own casters would draw here too.
            sun.caster.render_depth(&mut pass);
            drop(pass);
            self.forest.set_host_cascades(&cascades)?;
            shadow = (cascades[0].view_proj, 1.0);
        }
        let host = HostUniform {
            view_proj: (frame.proj * frame.view).to_cols_array_2d(),
            colour: self.ground_colour,
            moss: self.moss_colour,
            eye: eye.extend(1.0).to_array(),
            shadow: shadow.0.to_cols_array_2d(),
            soil_shadowed: self.soil_shadowed,
            moss_shadowed: self.moss_shadowed,
            shade: [shadow.1, 0.0, 0.0, 0.0],
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&host));
        self.forest.prepare(queue, frame)?;
        self.forest.encode_compute(&mut encoder);
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("host frame"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: colour,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(SKY),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.ground);
            pass.set_bind_group(0, &self.bind, &[]);
            pass.draw(0..4, 0..1);
            self.forest.render(&mut pass);
        }
        queue.submit([encoder.finish()]);
        Ok(())
    }
}

/// The host's own ground: a strip over the whole view at the depth convention of its
/// target, into `format`.
fn ground_pipeline(device: &wgpu::Device, format: wgpu::TextureFormat) -> wgpu::RenderPipeline {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("host ground"),
        source: wgpu::ShaderSource::Wgsl(
            forest_render::shaders::Composer::runtime()
                .with_module("host_ground", HOST_GROUND_WGSL)
                .composed(&["host_ground"])
                .into(),
        ),
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("host ground"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleStrip,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::GreaterEqual),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(format.into())],
        }),
        multiview_mask: None,
        cache: None,
    })
}
