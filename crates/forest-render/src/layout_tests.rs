//! Host and WGSL struct layouts checked against each other by reflecting the WGSL with naga.

use std::mem::{offset_of, size_of};

use forest_render::gpu_types::*;
use forest_render::passes::{compute_source, draw_source};

#[path = "../tests/layout_check/mod.rs"]
mod layout_check;
use layout_check::{check, shared, state_members};

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
        "Environment",
        size_of::<GpuEnvironment>(),
        vec![
            ("ground", offset_of!(GpuEnvironment, ground)),
            ("horizon", offset_of!(GpuEnvironment, horizon)),
            ("zenith", offset_of!(GpuEnvironment, zenith)),
            ("sun", offset_of!(GpuEnvironment, sun)),
            ("albedo", offset_of!(GpuEnvironment, albedo)),
            ("terrain", offset_of!(GpuEnvironment, terrain)),
            ("terrain_size", offset_of!(GpuEnvironment, terrain_size)),
        ],
    ));
    check(&draw_source(), &e);
}

#[test]
fn counting_params_match_the_host() {
    use forest_render::fragments::CountParams;
    let counted = forest_render::passes::counting_draw_source();
    check(
        &counted,
        &[(
            "CountParams",
            size_of::<CountParams>(),
            vec![
                ("width", offset_of!(CountParams, width)),
                ("height", offset_of!(CountParams, height)),
                ("phase", offset_of!(CountParams, phase)),
                ("reverse_z", offset_of!(CountParams, reverse_z)),
            ],
        )],
    );
    assert_eq!(
        layout_check::wgsl_const(&counted, "COUNT_STRIDE"),
        forest_render::fragments::COUNT_STRIDE as f64
    );
}

#[test]
fn the_overdraw_view_matches_the_host() {
    use forest_render::passes::OVERDRAW_WGSL;
    use forest_render::passes::overdraw::{OVERDRAW_COLOURS, OverdrawParams};
    check(
        OVERDRAW_WGSL,
        &[(
            "OverdrawParams",
            size_of::<OverdrawParams>(),
            vec![
                ("width", offset_of!(OverdrawParams, width)),
                ("height", offset_of!(OverdrawParams, height)),
                ("legend", offset_of!(OverdrawParams, legend)),
                ("_pad", offset_of!(OverdrawParams, _pad)),
            ],
        )],
    );
    layout_check::check_layout(
        OVERDRAW_WGSL,
        &layout_check::layout_bindings(0, &forest_render::passes::overdraw::layout_entries()),
        |_| true,
    );
    assert_eq!(
        layout_check::wgsl_const(OVERDRAW_WGSL, "COUNT_STRIDE"),
        forest_render::fragments::COUNT_STRIDE as f64
    );
    assert_eq!(
        layout_check::wgsl_const(OVERDRAW_WGSL, "LABELLED_SIDE"),
        f64::from(forest_render::passes::overdraw::LABELLED_SIDE)
    );
    assert_eq!(
        layout_check::wgsl_const(OVERDRAW_WGSL, "BANDS"),
        OVERDRAW_COLOURS.len() as f64
    );
    // The colour table, as the WGSL writes it.
    let wgsl: String = OVERDRAW_WGSL
        .split("const OVERDRAW_COLOURS")
        .nth(1)
        .and_then(|t| t.split(");").next())
        .expect("OVERDRAW_COLOURS in the WGSL")
        .to_string();
    let numbers: Vec<f32> = wgsl
        .split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .filter(|t| t.contains('.'))
        .map(|t| t.parse().unwrap())
        .collect();
    assert_eq!(numbers, OVERDRAW_COLOURS.concat());
}

#[test]
fn shaders_validate() {
    layout_check::validated(forest_render::passes::OVERDRAW_WGSL);
    let counted = forest_render::passes::counting_draw_source();
    for src in [compute_source(), draw_source(), counted] {
        layout_check::validated(&src);
    }
}

#[test]
fn bind_group_layouts_match_the_wgsl() {
    use forest_render::passes::{COMPUTE_SLOTS, Slot, draw::bind_entries, layout_entries};
    let mut compute = layout_check::layout_bindings(
        0,
        &layout_entries(&COMPUTE_SLOTS, wgpu::ShaderStages::COMPUTE),
    );
    compute.extend(layout_check::layout_bindings(
        1,
        &layout_entries(&[Slot::ReadWrite], wgpu::ShaderStages::COMPUTE),
    ));
    // The compute layout is shared by every entry point and matches every binding the WGSL
    // declares.
    assert_eq!(layout_check::reflected_bindings(&compute_source()), compute);
    // The draw: its group 0 and the shadow maps' group 2.
    let mut draw = layout_check::layout_bindings(0, &bind_entries());
    draw.extend(layout_check::layout_bindings(
        2,
        &forest_render::extend::receiver_entries(),
    ));
    layout_check::check_layout(&draw_source(), &draw, |_| true);
    // The light views' casting pass reads group 0 alone.
    layout_check::check_layout(
        &forest_render::passes::cast_source(),
        &layout_check::layout_bindings(0, &bind_entries()),
        |e| ["vs_cast", "fs_cast"].contains(&e),
    );
    // The counting variant of the quad draws adds the counters as group 1.
    let mut counted = draw.clone();
    counted.extend(layout_check::layout_bindings(
        1,
        &forest_render::fragments::layout_entries(),
    ));
    layout_check::check_layout(
        &forest_render::passes::counting_draw_source(),
        &counted,
        |e| ["vs_quad", "fs_quad", "vs_composite", "fs_composite"].contains(&e),
    );
}

#[test]
fn constants_shared_with_the_wgsl_agree() {
    use forest_render::options::{self, DebugView, FLAG_DEPTH_ERROR, FLAG_DITHER, FLAG_NEAREST};
    let c = compute_source();
    let d = draw_source();
    let pairs: [(&str, &str, f64); 19] = [
        (&c, "WG", f64::from(forest_render::capacity::WG)),
        (&c, "BLOCK", f64::from(forest_render::capacity::BLOCK)),
        (&c, "WEIGHT_ONE", f64::from(WEIGHT_ONE)),
        (&c, "FLAG_DITHER", f64::from(FLAG_DITHER)),
        (&c, "FLAG_NEAREST", f64::from(FLAG_NEAREST)),
        (&c, "FLAG_DEPTH_ERROR", f64::from(FLAG_DEPTH_ERROR)),
        (&c, "FLAG_FAR_BLEND", f64::from(options::FLAG_FAR_BLEND)),
        (&c, "FLAG_FAR_SLABS", f64::from(options::FLAG_FAR_SLABS)),
        (&c, "SHARPEN_SHIFT", f64::from(options::SHARPEN_SHIFT)),
        (&c, "SHARPEN_MASK", f64::from(options::SHARPEN_MASK)),
        (&c, "SHARPEN_MAX", f64::from(options::SHARPEN_MAX)),
        (&c, "REACH_SHIFT", f64::from(options::REACH_SHIFT)),
        (&c, "REACH_MASK", f64::from(options::REACH_MASK)),
        (&c, "REACH_STEPS", f64::from(options::REACH_STEPS)),
        (&c, "REACH_STEP", f64::from(options::REACH_STEP)),
        (
            &c,
            "FAR_CLASS",
            f64::from(forest_render::reference::FAR_CLASS),
        ),
        (&c, "NONE", f64::from(u32::MAX)),
        (
            &c,
            "NODE_TEX_WIDTH",
            f64::from(forest_format::atlas::NODE_TEXTURE_WIDTH),
        ),
        (
            &c,
            "PRESORT_TEX_WIDTH",
            f64::from(forest_render::scene::PRESORT_TEXTURE_WIDTH),
        ),
    ];
    for (src, name, rust) in pairs {
        assert_eq!(layout_check::wgsl_const(src, name), rust, "{name}");
    }
    assert_eq!(
        layout_check::wgsl_const(&d, "DEPTH_WRITE_ALPHA"),
        f64::from(forest_render::options::DEPTH_WRITE_ALPHA),
        "DEPTH_WRITE_ALPHA"
    );
    assert_eq!(
        layout_check::wgsl_const(&d, "OPAQUE_SHARE_MIN"),
        f64::from(forest_render::options::OPAQUE_SHARE_MIN),
        "OPAQUE_SHARE_MIN"
    );
    for (name, view) in [
        ("DEBUG_LEVELS", DebugView::Levels),
        ("DEBUG_WEIGHTS", DebugView::Weights),
        ("DEBUG_WIREFRAME", DebugView::Wireframe),
    ] {
        assert_eq!(
            layout_check::wgsl_const(&d, name),
            f64::from(view as u32),
            "{name}"
        );
    }
    // Every compute entry point runs one invocation or a workgroup of WG (the indirect
    // arguments divide by WG).
    for (entry, size) in layout_check::workgroup_sizes(&c) {
        assert!(
            size == 1 || size == forest_render::capacity::WG,
            "{entry}: workgroup of {size}"
        );
    }
}
