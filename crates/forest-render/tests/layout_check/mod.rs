//! The layout checker shared by the runtime's and the baselines' layout tests: a WGSL
//! struct's size and member offsets (naga's layouter) against the Rust mirror's.

use std::mem::{offset_of, size_of};

use forest_format::colour::TreeColour;
use forest_render::gpu_types::*;

/// (WGSL struct name, Rust size, [(member, Rust offset)]).
pub type Expect = (&'static str, usize, Vec<(&'static str, usize)>);

pub fn check(source: &str, expected: &[Expect]) {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(source)));
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    for (name, size, members) in expected {
        let (handle, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no WGSL struct {name}"));
        let naga::TypeInner::Struct {
            members: wgsl_members,
            span,
        } = &ty.inner
        else {
            panic!("{name} is not a struct");
        };
        assert_eq!(
            *span as usize, *size,
            "{name}: WGSL size {span} vs Rust {size}"
        );
        assert_eq!(
            layouter[handle].size as usize, *size,
            "{name}: layouter size"
        );
        assert_eq!(wgsl_members.len(), members.len(), "{name}: member count");
        for (m, (mname, off)) in wgsl_members.iter().zip(members) {
            assert_eq!(m.name.as_deref(), Some(*mname), "{name}: member order");
            assert_eq!(
                m.offset as usize, *off,
                "{name}.{mname}: WGSL offset {} vs Rust {off}",
                m.offset
            );
        }
    }
}

pub fn shared() -> Vec<Expect> {
    vec![
        (
            "Camera",
            size_of::<GpuCamera>(),
            vec![
                ("view_proj", offset_of!(GpuCamera, view_proj)),
                ("eye", offset_of!(GpuCamera, eye)),
                ("epsilon", offset_of!(GpuCamera, epsilon)),
                ("forward", offset_of!(GpuCamera, forward)),
                ("far_span", offset_of!(GpuCamera, far_span)),
                ("viewport", offset_of!(GpuCamera, viewport)),
                ("debug_view", offset_of!(GpuCamera, debug_view)),
                ("stream_flags", offset_of!(GpuCamera, stream_flags)),
                ("planes", offset_of!(GpuCamera, planes)),
                ("forms", offset_of!(GpuCamera, forms)),
                ("sun", offset_of!(GpuCamera, sun)),
                ("exposure", offset_of!(GpuCamera, exposure)),
                ("sun_colour", offset_of!(GpuCamera, sun_colour)),
                ("sky_light", offset_of!(GpuCamera, sky_light)),
                ("ground_light", offset_of!(GpuCamera, ground_light)),
                ("shadow", offset_of!(GpuCamera, shadow)),
                ("shadow_splits", offset_of!(GpuCamera, shadow_splits)),
                ("shadow_texel", offset_of!(GpuCamera, shadow_texel)),
                ("shadow_bias", offset_of!(GpuCamera, shadow_bias)),
                ("shadow_cascades", offset_of!(GpuCamera, shadow_cascades)),
                ("shadow_side", offset_of!(GpuCamera, shadow_side)),
                ("shadow_offset", offset_of!(GpuCamera, shadow_offset)),
                ("shadow_reverse_z", offset_of!(GpuCamera, shadow_reverse_z)),
                ("form_eye", offset_of!(GpuCamera, form_eye)),
                ("casters", offset_of!(GpuCamera, casters)),
                ("caster_floor", offset_of!(GpuCamera, caster_floor)),
                ("wind", offset_of!(GpuCamera, wind)),
                ("wind_time", offset_of!(GpuCamera, wind_time)),
                ("season", offset_of!(GpuCamera, season)),
            ],
        ),
        (
            "Instance",
            size_of::<GpuInstance>(),
            vec![
                ("position", offset_of!(GpuInstance, position)),
                ("scale", offset_of!(GpuInstance, scale)),
                ("cos_rot", offset_of!(GpuInstance, cos_rot)),
                ("sin_rot", offset_of!(GpuInstance, sin_rot)),
                ("species", offset_of!(GpuInstance, species)),
                ("colour", offset_of!(GpuInstance, colour)),
            ],
        ),
        (
            "Species",
            size_of::<GpuSpecies>(),
            vec![
                ("sphere", offset_of!(GpuSpecies, sphere)),
                ("directions", offset_of!(GpuSpecies, directions)),
                ("slabs", offset_of!(GpuSpecies, slabs)),
                ("levels", offset_of!(GpuSpecies, levels)),
                ("dir_base", offset_of!(GpuSpecies, dir_base)),
                ("tri_base", offset_of!(GpuSpecies, tri_base)),
                ("tri_count", offset_of!(GpuSpecies, tri_count)),
                ("layer_base", offset_of!(GpuSpecies, layer_base)),
                ("node_base", offset_of!(GpuSpecies, node_base)),
                ("lower_tri_count", offset_of!(GpuSpecies, lower_tri_count)),
                ("resolution", offset_of!(GpuSpecies, resolution)),
                ("switch_unit", offset_of!(GpuSpecies, switch_unit)),
                ("opacity_depth", offset_of!(GpuSpecies, opacity_depth)),
                ("colour", offset_of!(GpuSpecies, colour)),
            ],
        ),
        (
            "TreeColour",
            size_of::<TreeColour>(),
            vec![
                ("amplitude", offset_of!(TreeColour, amplitude)),
                ("phase", offset_of!(TreeColour, phase)),
                ("spring", offset_of!(TreeColour, spring)),
                ("autumn", offset_of!(TreeColour, autumn)),
                ("late_autumn", offset_of!(TreeColour, late_autumn)),
            ],
        ),
        (
            "Frame",
            size_of::<GpuFrame>(),
            vec![
                ("dir", offset_of!(GpuFrame, dir)),
                ("right", offset_of!(GpuFrame, right)),
                ("up", offset_of!(GpuFrame, up)),
            ],
        ),
        (
            "Quad",
            size_of::<Quad>(),
            vec![
                ("instance", offset_of!(Quad, instance)),
                ("node", offset_of!(Quad, node)),
                ("pos", offset_of!(Quad, pos)),
                ("dir_weight", offset_of!(Quad, dir_weight)),
            ],
        ),
        ("State", size_of::<GpuState>(), state_members()),
        (
            "Args",
            size_of::<GpuArgs>(),
            vec![
                ("items", offset_of!(GpuArgs, items)),
                ("blocks", offset_of!(GpuArgs, blocks)),
                ("draw", offset_of!(GpuArgs, draw)),
                ("draw_composite", offset_of!(GpuArgs, draw_composite)),
            ],
        ),
    ]
}

pub fn state_members() -> Vec<(&'static str, usize)> {
    vec![
        ("presort", offset_of!(GpuState, presort)),
        ("n", offset_of!(GpuState, n)),
        ("total", offset_of!(GpuState, total)),
        ("pmin", offset_of!(GpuState, pmin)),
        ("overflow_cull", offset_of!(GpuState, overflow_cull)),
        ("overflow_refine", offset_of!(GpuState, overflow_refine)),
        ("visible", offset_of!(GpuState, visible)),
        ("quads", offset_of!(GpuState, quads)),
        ("composites", offset_of!(GpuState, composites)),
        ("per_level", offset_of!(GpuState, per_level)),
    ]
}

/// Every resource binding a WGSL module declares, as `(group, binding) → kind`, from naga's
/// reflection: "uniform", "storage read", "storage read_write", "texture <sample> <dim>
/// [multisampled]", "sampler", "sampler comparison".
pub fn reflected_bindings(source: &str) -> std::collections::BTreeMap<(u32, u32), String> {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(source)));
    let mut out = std::collections::BTreeMap::new();
    for (_, g) in module.global_variables.iter() {
        let Some(b) = &g.binding else { continue };
        let kind = match g.space {
            naga::AddressSpace::Uniform => "uniform".to_string(),
            naga::AddressSpace::Storage { access } => {
                if access.contains(naga::StorageAccess::STORE) {
                    "storage read_write".into()
                } else {
                    "storage read".into()
                }
            }
            naga::AddressSpace::Handle => match &module.types[g.ty].inner {
                naga::TypeInner::Image {
                    dim,
                    arrayed,
                    class,
                } => {
                    let (sample, multi) = match class {
                        naga::ImageClass::Sampled { kind, multi } => (
                            match kind {
                                naga::ScalarKind::Float => "float",
                                naga::ScalarKind::Uint => "uint",
                                naga::ScalarKind::Sint => "sint",
                                _ => "other",
                            },
                            *multi,
                        ),
                        naga::ImageClass::Depth { multi } => ("depth", *multi),
                        _ => ("storage", false),
                    };
                    let dim = match (dim, arrayed) {
                        (naga::ImageDimension::D2, false) => "2d",
                        (naga::ImageDimension::D2, true) => "2d_array",
                        (naga::ImageDimension::D3, _) => "3d",
                        _ => "other",
                    };
                    format!(
                        "texture {sample} {dim}{}",
                        if multi { " multisampled" } else { "" }
                    )
                }
                naga::TypeInner::Sampler { comparison } => if *comparison {
                    "sampler comparison"
                } else {
                    "sampler"
                }
                .into(),
                other => format!("{other:?}"),
            },
            other => format!("{other:?}"),
        };
        out.insert((b.group, b.binding), kind);
    }
    out
}

/// The same description of a Rust bind-group layout used as group `group`.
pub fn layout_bindings(
    group: u32,
    entries: &[wgpu::BindGroupLayoutEntry],
) -> std::collections::BTreeMap<(u32, u32), String> {
    entries
        .iter()
        .map(|e| {
            let kind = match e.ty {
                wgpu::BindingType::Buffer { ty, .. } => match ty {
                    wgpu::BufferBindingType::Uniform => "uniform".to_string(),
                    wgpu::BufferBindingType::Storage { read_only: true } => "storage read".into(),
                    wgpu::BufferBindingType::Storage { read_only: false } => {
                        "storage read_write".into()
                    }
                },
                wgpu::BindingType::Texture {
                    sample_type,
                    view_dimension,
                    multisampled,
                } => {
                    let sample = match sample_type {
                        wgpu::TextureSampleType::Float { .. } => "float",
                        wgpu::TextureSampleType::Uint => "uint",
                        wgpu::TextureSampleType::Sint => "sint",
                        wgpu::TextureSampleType::Depth => "depth",
                    };
                    let dim = match view_dimension {
                        wgpu::TextureViewDimension::D2 => "2d",
                        wgpu::TextureViewDimension::D2Array => "2d_array",
                        wgpu::TextureViewDimension::D3 => "3d",
                        _ => "other",
                    };
                    format!(
                        "texture {sample} {dim}{}",
                        if multisampled { " multisampled" } else { "" }
                    )
                }
                wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison) => {
                    "sampler comparison".into()
                }
                wgpu::BindingType::Sampler(_) => "sampler".into(),
                other => format!("{other:?}"),
            };
            ((group, e.binding), kind)
        })
        .collect()
}

/// The value of a WGSL `const` (u32, i32 or f32 literal) in a module, as f64.
pub fn wgsl_const(source: &str, name: &str) -> f64 {
    let module = naga::front::wgsl::parse_str(source).unwrap();
    let (_, c) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no WGSL const {name}"));
    match module.global_expressions[c.init] {
        naga::Expression::Literal(naga::Literal::U32(v)) => f64::from(v),
        naga::Expression::Literal(naga::Literal::I32(v)) => f64::from(v),
        naga::Expression::Literal(naga::Literal::F32(v)) => f64::from(v),
        ref e => panic!("{name} is not a literal: {e:?}"),
    }
}

/// `(entry point, workgroup size x)` of every compute entry point of a module.
pub fn workgroup_sizes(source: &str) -> Vec<(String, u32)> {
    let module = naga::front::wgsl::parse_str(source).unwrap();
    module
        .entry_points
        .iter()
        .filter(|e| e.stage == naga::ShaderStage::Compute)
        .map(|e| {
            assert_eq!(e.workgroup_size[1..], [1, 1], "{}: 1-D workgroups", e.name);
            (e.name.clone(), e.workgroup_size[0])
        })
        .collect()
}

/// Parse and validate a WGSL module with every check naga has; panics with the message.
pub fn validated(source: &str) -> (naga::Module, naga::valid::ModuleInfo) {
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(source)));
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{e:?}"));
    (module, info)
}

/// Bindings used (read or written) by the entry points of a module that `entry` selects, from
/// naga's validation info.
pub fn used_bindings(source: &str, entry: impl Fn(&str) -> bool) -> Vec<(u32, u32)> {
    let (module, info) = validated(source);
    let mut used = std::collections::BTreeSet::new();
    for (i, ep) in module.entry_points.iter().enumerate() {
        if !entry(&ep.name) {
            continue;
        }
        let ep_info = info.get_entry_point(i);
        for (h, g) in module.global_variables.iter() {
            if let Some(b) = &g.binding
                && !ep_info[h].is_empty()
            {
                used.insert((b.group, b.binding));
            }
        }
    }
    used.into_iter().collect()
}

/// A layout matches a module when every binding it lists is declared there with the same
/// kind, and every binding the selected entry points use is in it.
pub fn check_layout(
    source: &str,
    layout: &std::collections::BTreeMap<(u32, u32), String>,
    entry: impl Fn(&str) -> bool,
) {
    let declared = reflected_bindings(source);
    for (b, kind) in layout {
        assert_eq!(declared.get(b), Some(kind), "binding {b:?}: WGSL vs layout");
    }
    for b in used_bindings(source, entry) {
        assert!(
            layout.contains_key(&b),
            "binding {b:?} is used but not in the layout"
        );
    }
}
