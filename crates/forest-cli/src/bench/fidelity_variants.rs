//! The fidelity suite's variants: one change of the bake or the runtime at a time against the
//! baseline, the paper's method in one row, and full geometry at 1× as the yardstick.

use forest_format::{BakeParams, ColourEncoding, PlaneFit};
use forest_render::options::{AspectBlend, StreamOptions};

/// ε (pixels) of every variant but `min-quad=1`.
pub const EPS: f32 = 2.0;
/// ε of the `min-quad=1` variant (exact per-pixel depth).
pub const EPS_EXACT: f32 = 1.0;

/// A bake change: the parameters of a re-bake from the given atlas's ones.
pub(super) type BakeChange = fn(BakeParams) -> BakeParams;

/// One row of the comparison: a bake change (none: the atlas given) and run-time options.
pub(super) struct Variant {
    pub(super) name: &'static str,
    pub(super) bake: Option<BakeChange>,
    pub(super) options: StreamOptions,
    pub(super) epsilon: f32,
    /// Not the quad stream: full geometry at 1× (the yardstick of the stream's accuracy).
    pub(super) geometry: bool,
}

/// The yardstick row's name: full geometry at 1×, the same triangles as the reference.
pub(super) const GEOMETRY: &str = "full geometry 1x";

/// The comparison's rows: the baseline, one change of the bake or the runtime each, the
/// paper's method, and the yardstick (fewer in quick mode).
pub(super) fn variants(quick: bool) -> Vec<Variant> {
    let default = StreamOptions::default();
    let runtime = |name, options| Variant {
        name,
        bake: None,
        options,
        epsilon: EPS,
        geometry: false,
    };
    let baked = |name, bake: BakeChange| Variant {
        name,
        bake: Some(bake),
        options: default,
        epsilon: EPS,
        geometry: false,
    };
    let geometry = Variant {
        geometry: true,
        ..runtime(GEOMETRY, default)
    };
    let paper = Variant {
        name: "paper",
        bake: Some(|p| BakeParams {
            below: 0,
            plane_fit: PlaneFit::LeastSquares,
            ..p
        }),
        options: StreamOptions {
            blend: AspectBlend::Over,
            depth_error: false,
            trim: false,
            far_nearest: false,
            far_composite: false,
            far_span: 1,
            sharpen: 0,
            sharpen_reach: 1,
            opaque_first: false,
        },
        epsilon: EPS,
        geometry: false,
    };
    let dither = runtime(
        "blend=dither",
        StreamOptions {
            blend: AspectBlend::Dither,
            ..default
        },
    );
    if quick {
        return vec![runtime("baseline", default), dither, paper, geometry];
    }
    vec![
        runtime("baseline", default),
        dither,
        runtime(
            "blend=nearest",
            StreamOptions {
                blend: AspectBlend::Nearest,
                ..default
            },
        ),
        runtime(
            "depth-error refine",
            StreamOptions {
                depth_error: true,
                ..default
            },
        ),
        runtime(
            "untrimmed",
            StreamOptions {
                trim: false,
                ..default
            },
        ),
        runtime(
            "far trees blended",
            StreamOptions {
                far_nearest: false,
                ..default
            },
        ),
        runtime(
            "far slabs apart",
            StreamOptions {
                far_composite: false,
                ..default
            },
        ),
        baked("directions=31", |p| BakeParams {
            directions: 31,
            ..p
        }),
        baked("slabs=4", |p| BakeParams { slabs: 4, ..p }),
        // Texels twice and four times as fine (4× and 16× the memory): whether the close-up
        // error is the slab images' magnification.
        baked("resolution=1024", |p| BakeParams {
            resolution: 1024,
            ..p
        }),
        baked("resolution=2048", |p| BakeParams {
            resolution: 2048,
            ..p
        }),
        baked("lossless", |p| BakeParams {
            colour: ColourEncoding::Png,
            ..p
        }),
        Variant {
            epsilon: EPS_EXACT,
            ..baked("min-quad=1", |p| BakeParams { min_quad: 1, ..p })
        },
        baked("below=0", |p| BakeParams { below: 0, ..p }),
        baked("fit=least-squares", |p| BakeParams {
            plane_fit: PlaneFit::LeastSquares,
            ..p
        }),
        paper,
        geometry,
    ]
}
