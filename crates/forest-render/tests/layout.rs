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
        "Ground",
        size_of::<GpuGround>(),
        vec![("colour", offset_of!(GpuGround, colour))],
    ));
    check(&draw_source(), &e);
}

#[test]
fn shaders_validate() {
    for src in [compute_source(), draw_source()] {
        let module = naga::front::wgsl::parse_str(&src).unwrap();
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{e:?}"));
    }
}
