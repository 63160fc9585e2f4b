//! Host and WGSL struct layouts checked against each other by reflecting the WGSL with naga.

use std::mem::{offset_of, size_of};

use forest_render::gpu_types::*;
use forest_render::passes::{compute_source, draw_source};

/// (WGSL struct name, Rust size, [(member, Rust offset)]).
type Expect = (&'static str, usize, Vec<(&'static str, usize)>);

fn check(source: &str, expected: &[Expect]) {
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

fn shared() -> Vec<Expect> {
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

fn state_members() -> Vec<(&'static str, usize)> {
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

#[test]
fn compute_structs_match_the_host() {
    let mut e = shared();
    e.push(("StateAtomic", size_of::<GpuState>(), state_members()));
    e.push((
        "SceneConsts",
        size_of::<SceneConsts>(),
        vec![
            ("instances", offset_of!(SceneConsts, instances)),
            ("presort_dirs", offset_of!(SceneConsts, presort_dirs)),
            ("capacity", offset_of!(SceneConsts, capacity)),
            ("species", offset_of!(SceneConsts, species)),
        ],
    ));
    check(&compute_source(), &e);
}

#[test]
fn draw_structs_match_the_host() {
    let mut e = shared();
    e.push((
        "Ground",
        size_of::<GpuGround>(),
        vec![("colour", offset_of!(GpuGround, colour))],
    ));
    check(&draw_source(), &e);
}

#[test]
fn geometry_structs_match_the_host() {
    use forest_bake::RefVertex;
    let expected: Vec<Expect> = vec![
        (
            "GeoVertex",
            size_of::<RefVertex>(),
            vec![
                ("pos", offset_of!(RefVertex, pos)),
                ("sun_visibility", offset_of!(RefVertex, sun_visibility)),
                ("normal", offset_of!(RefVertex, normal)),
                ("material", offset_of!(RefVertex, material)),
                ("uv", offset_of!(RefVertex, uv)),
                ("element", offset_of!(RefVertex, element)),
                ("pad", offset_of!(RefVertex, pad)),
            ],
        ),
        (
            "GeoSpecies",
            size_of::<GpuGeoSpecies>(),
            vec![
                ("sphere", offset_of!(GpuGeoSpecies, sphere)),
                ("lod_first", offset_of!(GpuGeoSpecies, lod_first)),
                ("lod_count", offset_of!(GpuGeoSpecies, lod_count)),
                (
                    "branch_vertices",
                    offset_of!(GpuGeoSpecies, branch_vertices),
                ),
                ("leaves", offset_of!(GpuGeoSpecies, leaves)),
                ("leaf_base", offset_of!(GpuGeoSpecies, leaf_base)),
                ("r", offset_of!(GpuGeoSpecies, r)),
                ("mean_leaf", offset_of!(GpuGeoSpecies, mean_leaf)),
            ],
        ),
        (
            "Method",
            size_of::<GpuMethod>(),
            vec![
                ("mode", offset_of!(GpuMethod, mode)),
                ("depth_sort", offset_of!(GpuMethod, depth_sort)),
                ("area", offset_of!(GpuMethod, area)),
                ("contrast", offset_of!(GpuMethod, contrast)),
                ("d0", offset_of!(GpuMethod, d0)),
                ("exponent", offset_of!(GpuMethod, exponent)),
                ("fade", offset_of!(GpuMethod, fade)),
                ("pad", offset_of!(GpuMethod, pad)),
                ("lod", offset_of!(GpuMethod, lod)),
            ],
        ),
        (
            "GeoMaterial",
            size_of::<GpuGeoMaterial>(),
            vec![
                ("kd", offset_of!(GpuGeoMaterial, kd)),
                ("layer", offset_of!(GpuGeoMaterial, layer)),
                ("alpha_tested", offset_of!(GpuGeoMaterial, alpha_tested)),
                ("pad", offset_of!(GpuGeoMaterial, pad)),
            ],
        ),
        (
            "Light",
            size_of::<GpuLight>(),
            vec![
                ("sun_dir", offset_of!(GpuLight, sun_dir)),
                ("sun", offset_of!(GpuLight, sun)),
                ("sky", offset_of!(GpuLight, sky)),
                ("ground", offset_of!(GpuLight, ground)),
            ],
        ),
    ];
    check(
        &forest_render::passes::GEOMETRY_DRAW_WGSL.concat(),
        &expected,
    );
    check(
        &forest_render::passes::GEOMETRY_CULL_WGSL.concat(),
        &expected[1..3],
    );
}

#[test]
fn shaders_validate() {
    let geometry = forest_render::passes::GEOMETRY_DRAW_WGSL.concat();
    let geometry_cull = forest_render::passes::GEOMETRY_CULL_WGSL.concat();
    for src in [compute_source(), draw_source(), geometry, geometry_cull] {
        let module = naga::front::wgsl::parse_str(&src).unwrap();
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{e:?}"));
    }
}
