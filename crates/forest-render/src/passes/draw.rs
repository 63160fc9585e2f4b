//! Pass 3, draw (`shaders/draw.wgsl`): the environment (sky and ground), then the final stream as
//! an indirect, instanced triangle strip per quad, blended back to front.

pub use crate::bindings::vertex_storage_entry;

use super::{args, draw_source};

/// Layout of the draw group (checked against naga's reflection of `shaders/draw.wgsl` by a
/// test): camera, instances, species, frames, final stream, nodes, colour layers, sampler,
/// environment, layer roots, the frame's state (where the plain quads start), the surface
/// layers, the terrain's heights at [`crate::terrain::HEIGHTS_BINDING`] and the opacity
/// volumes at [`OPACITY_BINDING`].
pub fn bind_entries() -> Vec<wgpu::BindGroupLayoutEntry> {
    let vf = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
    let storage = vertex_storage_entry;
    let uniform = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: vf,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    // The colour (6) and surface (11) layers, sampled filtered by the fragment stage.
    let layer_array = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        },
        count: None,
    };
    // The instances and species, read by the fragment stage too for each tree's colour
    // (tint.wgsl).
    let both = |binding| wgpu::BindGroupLayoutEntry {
        visibility: vf,
        ..storage(binding)
    };
    vec![
        uniform(0),
        both(1),
        both(2),
        storage(3),
        storage(4),
        wgpu::BindGroupLayoutEntry {
            binding: 5,
            visibility: wgpu::ShaderStages::VERTEX,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Uint,
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        },
        layer_array(6),
        // Also read by the vertex stage's march through the opacity volumes.
        wgpu::BindGroupLayoutEntry {
            binding: 7,
            visibility: vf,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        },
        uniform(8),
        storage(9),
        storage(10),
        layer_array(11),
        crate::terrain::heights_entry(),
        crate::opacity::opacity_entry(OPACITY_BINDING),
    ]
}

/// Binding of the opacity volumes in the draw group.
pub const OPACITY_BINDING: u32 = 14;

/// The draw pass's pipelines.
pub struct DrawPass {
    /// Bind-group layout (camera, scene tables, final stream, textures, environment).
    pub bind_layout: wgpu::BindGroupLayout,
    /// Layout of group 2, the sun's shadow maps ([`crate::receivers::receiver_layout`]).
    pub shadow_layout: wgpu::BindGroupLayout,
    environment: wgpu::RenderPipeline,
    terrain: wgpu::RenderPipeline,
    /// Far trees' composited quads (drawn first).
    composite: wgpu::RenderPipeline,
    quads: wgpu::RenderPipeline,
    /// The opaque pass: each tree's opaque front, front to back, depth written.
    opaque: wgpu::RenderPipeline,
    /// The depth-writing draws (composited, plain) when the host asks for the trees' depth
    /// ([`crate::options::RendererOptions::write_depth`]).
    depth: Option<[wgpu::RenderPipeline; 2]>,
}

/// The opaque pass ([`crate::options::StreamOptions::opaque_first`]) draws a node when at least
/// this share of its covered box's texels is opaque, in 1/255 steps (`OPAQUE_SHARE_MIN` in
/// draw.wgsl; the share is [`forest_format::trim::node_trims`]'). Its other fragments are
/// shaded in both draws: in the model-size walkthrough at ε 16 the stream shaded 13.55
/// fragments per covered pixel at 64, 12.99 at 128 and 13.34 at 192 (at ε 4: 14.22, 13.59,
/// 13.44).
pub const OPAQUE_SHARE_MIN: u32 = 128;

/// Coverage from which [`crate::options::RendererOptions::write_depth`] writes a quad
/// fragment's depth (`DEPTH_WRITE_ALPHA` in draw.wgsl).
pub const DEPTH_WRITE_ALPHA: f32 = 0.5;

impl DrawPass {
    /// Create the pipelines for the host's targets: colour and depth formats, sample count
    /// and depth test from `opts`. Group 1 is the fragment counters' (when counting), group 2
    /// the shadow maps'.
    pub fn new(device: &wgpu::Device, opts: &crate::options::RendererOptions) -> Self {
        let bind_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("draw"),
            entries: &bind_entries(),
        });
        let shadow_layout = crate::receivers::receiver_layout(device);
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("draw"),
            bind_group_layouts: &[Some(&bind_layout), None, Some(&shadow_layout)],
            immediate_size: 0,
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("draw"),
            source: wgpu::ShaderSource::Wgsl(draw_source().into()),
        });
        let pipeline_of = |topology, vs: &str, fs: &str, blend, depth_write| {
            draw_pipeline(
                device,
                opts,
                &layout,
                &module,
                topology,
                [vs, fs],
                blend,
                depth_write,
            )
        };
        let pipeline = |vs: &str, fs: &str, blend: Option<wgpu::BlendState>, depth_write: bool| {
            pipeline_of(
                wgpu::PrimitiveTopology::TriangleStrip,
                vs,
                fs,
                blend,
                depth_write,
            )
        };
        Self {
            environment: pipeline("vs_environment", "fs_environment", None, true),
            terrain: pipeline_of(
                wgpu::PrimitiveTopology::TriangleList,
                "vs_terrain",
                "fs_terrain",
                None,
                true,
            ),
            composite: pipeline(
                "vs_composite",
                "fs_composite",
                Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
                false,
            ),
            quads: pipeline(
                "vs_quad",
                "fs_quad",
                Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
                false,
            ),
            opaque: pipeline(
                "vs_quad_opaque",
                "fs_quad_opaque",
                Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
                true,
            ),
            depth: opts.write_depth.then(|| {
                [
                    ["vs_composite", "fs_composite_depth"],
                    ["vs_quad", "fs_quad_depth"],
                ]
                .map(|entries| {
                    render_pipeline(
                        device,
                        &layout,
                        &module,
                        wgpu::PrimitiveTopology::TriangleStrip,
                        entries,
                        opts.depth_stencil(true),
                        opts.multisample(),
                        &[Some(wgpu::ColorTargetState {
                            format: opts.format,
                            blend: None,
                            write_mask: wgpu::ColorWrites::empty(),
                        })],
                    )
                })
            }),
            bind_layout,
            shadow_layout,
        }
    }

    /// The counting variants of the quad pipelines (see [`crate::fragments`]): the same
    /// draws with the counting hooks, and the counters as group 1.
    pub fn counting(
        &self,
        device: &wgpu::Device,
        opts: &crate::options::RendererOptions,
    ) -> CountingDraw {
        let counts = crate::fragments::bind_layout(device);
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("counted draw"),
            bind_group_layouts: &[
                Some(&self.bind_layout),
                Some(&counts),
                Some(&self.shadow_layout),
            ],
            immediate_size: 0,
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("counted draw"),
            source: wgpu::ShaderSource::Wgsl(super::counting_draw_source().into()),
        });
        let blend = Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING);
        let strip = wgpu::PrimitiveTopology::TriangleStrip;
        CountingDraw {
            composite: draw_pipeline(
                device,
                opts,
                &layout,
                &module,
                strip,
                ["vs_composite", "fs_composite"],
                blend,
                false,
            ),
            quads: draw_pipeline(
                device,
                opts,
                &layout,
                &module,
                strip,
                ["vs_quad", "fs_quad"],
                blend,
                false,
            ),
            opaque: draw_pipeline(
                device,
                opts,
                &layout,
                &module,
                strip,
                ["vs_quad_opaque", "fs_quad_opaque"],
                blend,
                true,
            ),
        }
    }

    /// Record the environment (sky, ground and the terrain `ground` holds, when given) and
    /// the indirect quad draws, the latter measured as `measured` asks (so the counts are the
    /// trees' alone): the composited far trees' draw when `composite` (the stream's options
    /// can make such quads), then the others'. `shadows` is the receivers' group 2. Returns
    /// the draws recorded.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        pass: &mut wgpu::RenderPass,
        bind_group: &wgpu::BindGroup,
        shadows: &wgpu::BindGroup,
        args_buf: &wgpu::Buffer,
        ground: Option<&crate::terrain::GpuTerrain>,
        composite: bool,
        opaque_first: bool,
        measured: Measured,
    ) -> u32 {
        let Measured {
            statistics,
            counted,
        } = measured;
        pass.set_bind_group(0, bind_group, &[]);
        pass.set_bind_group(2, shadows, &[]);
        let environment = ground.map_or(0, |t| {
            t.record_ground(pass, &self.environment, &self.terrain)
        });
        if let Some(set) = statistics {
            pass.begin_pipeline_statistics_query(set, crate::work::DRAW);
        }
        // The stream's two lists, each drawn alone: far trees' composited quads at its
        // front, then the others (see draw.wgsl).
        let (composite_pipeline, quads_pipeline, opaque_pipeline) = match counted {
            Some((c, counts)) => {
                pass.set_bind_group(1, counts, &[]);
                (&c.composite, &c.quads, &c.opaque)
            }
            None => (&self.composite, &self.quads, &self.opaque),
        };
        // The opaque pass first: what it hides fails the later draws' depth test.
        if opaque_first {
            pass.set_pipeline(opaque_pipeline);
            pass.draw_indirect(args_buf, args::DRAW);
        }
        let draws = [
            (composite_pipeline, args::DRAW_COMPOSITE),
            (quads_pipeline, args::DRAW),
        ];
        let drawn = &draws[usize::from(!composite)..];
        for (pipeline, offset) in drawn {
            pass.set_pipeline(pipeline);
            pass.draw_indirect(args_buf, *offset);
        }
        if statistics.is_some() {
            pass.end_pipeline_statistics_query();
        }
        // The host's depth: the same draws again, depth written where the trees are opaque
        // (not while counting: the counts are of the colour draws).
        let mut depth_draws = 0;
        if let (Some(depth), None) = (&self.depth, counted) {
            for (pipeline, (_, offset)) in depth.iter().zip(draws).skip(usize::from(!composite)) {
                pass.set_pipeline(pipeline);
                pass.draw_indirect(args_buf, offset);
                depth_draws += 1;
            }
        }
        drawn.len() as u32 + environment + depth_draws + u32::from(opaque_first)
    }
}

/// How the tree draws of [`DrawPass::record`] are measured.
#[derive(Clone, Copy, Default)]
pub struct Measured<'a> {
    /// Inside this pipeline-statistics query.
    pub statistics: Option<&'a wgpu::QuerySet>,
    /// With these counting pipelines and the counters' bind group (group 1).
    pub counted: Option<(&'a CountingDraw, &'a wgpu::BindGroup)>,
}

/// The quad pipelines that count fragments ([`DrawPass::counting`]).
pub struct CountingDraw {
    composite: wgpu::RenderPipeline,
    quads: wgpu::RenderPipeline,
    opaque: wgpu::RenderPipeline,
}

/// A tree draw's pipeline: `entries` (vertex, fragment) of `module`, into the host's targets
/// of `opts` (format, sample count, depth convention), no face culling. The quad stream's and
/// the geometry renderer's pipelines are all built here.
#[allow(clippy::too_many_arguments)]
pub fn draw_pipeline(
    device: &wgpu::Device,
    opts: &crate::options::RendererOptions,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    topology: wgpu::PrimitiveTopology,
    [vs, fs]: [&str; 2],
    blend: Option<wgpu::BlendState>,
    depth_write: bool,
) -> wgpu::RenderPipeline {
    render_pipeline(
        device,
        layout,
        module,
        topology,
        [vs, fs],
        opts.depth_stencil(depth_write),
        opts.multisample(),
        &[Some(wgpu::ColorTargetState {
            format: opts.format,
            blend,
            write_mask: wgpu::ColorWrites::ALL,
        })],
    )
}

/// A pipeline of `entries` (vertex, fragment) of `module` with no vertex buffers and no face
/// culling, into `targets` and the depth `depth` (every draw and casting pipeline).
#[allow(clippy::too_many_arguments)]
pub fn render_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    topology: wgpu::PrimitiveTopology,
    [vs, fs]: [&str; 2],
    depth: wgpu::DepthStencilState,
    multisample: wgpu::MultisampleState,
    targets: &[Option<wgpu::ColorTargetState>],
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(vs),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some(vs),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState {
            topology,
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: Some(depth),
        multisample,
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(fs),
            compilation_options: Default::default(),
            targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}
