//! Host and WGSL struct layouts checked against each other by reflecting the WGSL with naga.

use std::mem::{offset_of, size_of};

use forest_render::gpu_types::*;
use forest_render::passes::{compute_source, draw_source};

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
fn shaders_validate() {
    for src in [compute_source(), draw_source()] {
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
    layout_check::check_layout(
        &draw_source(),
        &layout_check::layout_bindings(0, &bind_entries()),
        |_| true,
    );
}

#[test]
fn constants_shared_with_the_wgsl_agree() {
    use forest_render::options::{DebugView, FLAG_DEPTH_ERROR, FLAG_DITHER, FLAG_NEAREST};
    let c = compute_source();
    let d = draw_source();
    let pairs: [(&str, &str, f64); 9] = [
        (&c, "WG", f64::from(forest_render::capacity::WG)),
        (&c, "BLOCK", f64::from(forest_render::capacity::BLOCK)),
        (&c, "WEIGHT_ONE", f64::from(WEIGHT_ONE)),
        (&c, "FLAG_DITHER", f64::from(FLAG_DITHER)),
        (&c, "FLAG_NEAREST", f64::from(FLAG_NEAREST)),
        (&c, "FLAG_DEPTH_ERROR", f64::from(FLAG_DEPTH_ERROR)),
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
