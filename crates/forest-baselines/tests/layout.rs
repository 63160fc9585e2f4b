//! The geometry renderer's host and WGSL struct layouts checked against each other by
//! reflecting the WGSL with naga (the checker is the runtime crate's, included).

use std::mem::{offset_of, size_of};

use forest_baselines::gpu_types::*;

#[path = "../../forest-render/tests/layout_check/mod.rs"]
#[allow(dead_code)]
mod layout_check;
#[allow(unused_imports)]
use layout_check::{Expect, check, shared};

#[test]
fn geometry_structs_match_the_host() {
    use forest_format::model::RefVertex;
    let expected: Vec<Expect> = vec![
        (
            "GeoVertex",
            size_of::<RefVertex>(),
            vec![
                ("pos", offset_of!(RefVertex, pos)),
                ("sky_front", offset_of!(RefVertex, sky_front)),
                ("normal", offset_of!(RefVertex, normal)),
                ("material", offset_of!(RefVertex, material)),
                ("uv", offset_of!(RefVertex, uv)),
                ("element", offset_of!(RefVertex, element)),
                ("sky_back", offset_of!(RefVertex, sky_back)),
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
                ("switch_unit", offset_of!(GpuGeoSpecies, switch_unit)),
                ("opacity_depth", offset_of!(GpuGeoSpecies, opacity_depth)),
                ("lod1_from", offset_of!(GpuGeoSpecies, lod_from)),
                ("lod2_from", offset_of!(GpuGeoSpecies, lod_from) + 4),
                ("pad0", offset_of!(GpuGeoSpecies, pad)),
                ("colour", offset_of!(GpuGeoSpecies, colour)),
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
                ("texture_bias", offset_of!(GpuMethod, texture_bias)),
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
    ];
    check(&forest_baselines::shaders::draw_source(), &expected);
    check(&forest_baselines::shaders::cull_source(), &expected[1..3]);
}

#[test]
fn shaders_validate() {
    use forest_baselines::shaders::{cast_source, counting_draw_source, cull_source, draw_source};
    for src in [
        draw_source(),
        cast_source(),
        counting_draw_source(),
        cull_source(),
    ] {
        layout_check::validated(&src);
    }
}

#[test]
fn bind_group_layouts_and_constants_match_the_wgsl() {
    use forest_baselines::geometry::{RESET_WG, compute_entries, draw_entries};
    use forest_baselines::shaders::{cast_source, counting_draw_source, cull_source, draw_source};
    let cull = cull_source();
    let draw = draw_source();
    assert_eq!(
        layout_check::reflected_bindings(&cull),
        layout_check::layout_bindings(0, &compute_entries())
    );
    // Every draw entry point, the environment's too, uses the one draw group and the shadow
    // maps' group 2.
    let mut drawn = layout_check::layout_bindings(0, &draw_entries());
    drawn.extend(layout_check::layout_bindings(
        2,
        &forest_render::extend::receiver_entries(),
    ));
    layout_check::check_layout(&draw, &drawn, |_| true);
    // The light views' casting pass reads the draw group alone.
    layout_check::check_layout(
        &cast_source(),
        &layout_check::layout_bindings(0, &draw_entries()),
        |e| e.ends_with("_cast") || e == "vs_billboard",
    );
    // The counting variant adds the counters as group 1.
    let mut counted = drawn.clone();
    counted.extend(layout_check::layout_bindings(
        1,
        &forest_render::fragments::layout_entries(),
    ));
    layout_check::check_layout(&counting_draw_source(), &counted, |e| {
        e == "fs_geo" || e == "fs_billboard" || e.starts_with("vs_")
    });
    assert_eq!(
        layout_check::wgsl_const(&cull, "BANDS"),
        f64::from(forest_format::model::BANDS)
    );
    let bits = forest_baselines::geometry::VISIBLE_ID_BITS;
    assert_eq!(
        layout_check::wgsl_const(&cull, "VISIBLE_ID_BITS"),
        f64::from(bits)
    );
    assert_eq!(
        layout_check::wgsl_const(&cull, "VISIBLE_ID_MASK"),
        f64::from((1u32 << bits) - 1)
    );
    for (entry, size) in layout_check::workgroup_sizes(&cull) {
        let want = match entry.as_str() {
            "geo_reset" => RESET_WG,
            "geo_args" => 1,
            _ => forest_render::extend::WG,
        };
        assert_eq!(size, want, "{entry}");
    }
}
