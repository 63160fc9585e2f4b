//! The layout checker shared by the runtime's and the baselines' layout tests: a WGSL
//! struct's size and member offsets (naga's layouter) against the Rust mirror's.

use std::mem::{offset_of, size_of};

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
                ("forward", offset_of!(GpuCamera, forward)),
                ("viewport", offset_of!(GpuCamera, viewport)),
                ("planes", offset_of!(GpuCamera, planes)),
                ("forms", offset_of!(GpuCamera, forms)),
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
                ("pad", offset_of!(GpuInstance, pad)),
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
                ("pad0", offset_of!(GpuSpecies, pad)),
                ("pad1", offset_of!(GpuSpecies, pad) + 4),
                ("pad2", offset_of!(GpuSpecies, pad) + 8),
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
                ("blocks0", offset_of!(GpuArgs, blocks0)),
                ("blocks1", offset_of!(GpuArgs, blocks1)),
                ("one", offset_of!(GpuArgs, one)),
                ("draw", offset_of!(GpuArgs, draw)),
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
        ("per_level", offset_of!(GpuState, per_level)),
    ]
}
