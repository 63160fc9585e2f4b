//! Which form draws each tree: the quad stream's share of a tree, decided on the GPU every
//! frame from the camera's `forms` vector (the camera stays the only per-frame upload).
//!
//! [`quad_share`] gives the quad stream's share of a tree: 0 (another form alone) nearer than
//! the tree's switch distance, [`WEIGHT_ONE`] (quads alone) past its transition band, and in
//! between the fraction of the tree's pixels the quads draw. Inside the band both forms draw
//! the tree through complementary screen-door masks ([`form_threshold`]), so every pixel comes
//! from exactly one of them and nothing pops; the band's start is jittered per instance so
//! that a ring of trees at one distance does not change form in the same frame. The quad
//! stream on its own uses [`FORMS_QUADS`]; the hybrid method (`forest-baselines`) sets
//! others, and its near trees are drawn by the geometry renderer with the same functions in
//! `shaders/common.wgsl`.

use forest_format::AtlasManifest;

use crate::gpu_types::WEIGHT_ONE;

/// `forms` of the quad stream on its own: every tree as quads.
pub const FORMS_QUADS: [f32; 4] = [0.0; 4];
/// `forms` of a geometry method on its own: every tree as geometry.
pub const FORMS_GEOMETRY: [f32; 4] = [f32::MAX, 0.0, 0.0, 0.0];
/// A switch distance at or past this (metres) draws every tree as geometry (`common.wgsl`).
pub const GEOMETRY_ALWAYS: f32 = 3.0e38;

/// A per-instance number in `[0, 1)` (`instance_hash` in `shaders/common.wgsl`).
pub fn instance_hash(instance: u32) -> f32 {
    let mut h = instance
        .wrapping_mul(747_796_405)
        .wrapping_add(2_891_336_453);
    h = ((h >> ((h >> 28) + 4)) ^ h).wrapping_mul(277_803_737);
    (h >> 8) as f32 / 16_777_216.0
}

/// Where a model's atlas records no measured switch ([`forest_format::atlas::HybridSwitch`]), the
/// hybrid switches where the model's finest quads project this many pixels (2.7 crown radii at
/// 400×300, 60° and 8 levels).
pub const DEFAULT_SWITCH_PIXELS: f32 = 1.5;

/// A species' switch unit (metres per pixel of focal length, at tree scale 1): the width of
/// its finest quads, `2R / 2^(levels−1)`, over the pixels they project to where the hybrid
/// switches to them (the atlas's measured
/// [`forest_format::atlas::HybridSwitch::finest_quad_pixels`], else [`DEFAULT_SWITCH_PIXELS`]). A
/// tree of scale `k` seen with focal length `f` pixels switches at `f · k · unit` metres from its
/// crown's centre.
pub fn switch_unit(m: &AtlasManifest) -> f32 {
    let finest = 2.0 * m.bounding_sphere.radius / (1u64 << (m.levels.clamp(1, 32) - 1)) as f32;
    let pixels = m
        .hybrid_switch
        .map_or(DEFAULT_SWITCH_PIXELS, |h| h.finest_quad_pixels);
    finest / pixels
}

/// The quad stream's share of a tree, in units of 1/[`WEIGHT_ONE`] (`quad_share` in
/// `shaders/common.wgsl`, the same operations in the same order): 0 while the eye is nearer
/// than the tree's switch distance `s = forms.x + forms.y · unit`, [`WEIGHT_ONE`] past its
/// band `[start, start · (1 + forms.z)]` with `start = s · (1 + forms.w · hash)`, linear in
/// between. `distance`: eye to the bounding-sphere centre (metres); `unit`: the species'
/// [`switch_unit`] times the tree's scale.
pub fn quad_share(forms: [f32; 4], distance: f32, unit: f32, instance: u32) -> u32 {
    let s = forms[0] + forms[1] * unit;
    if s <= 0.0 {
        return WEIGHT_ONE;
    }
    if s >= GEOMETRY_ALWAYS {
        return 0;
    }
    let start = s * (1.0 + forms[3] * instance_hash(instance));
    let width = start * forms[2];
    if width <= 0.0 {
        return if distance >= start { WEIGHT_ONE } else { 0 };
    }
    ((((distance - start) / width).clamp(0.0, 1.0) * 4095.0 + 0.5).floor()) as u32
}

/// Ordered-dither threshold of pixel `(x, y)` for a tree, in `[0, WEIGHT_ONE)`
/// (`dither_threshold` in `shaders/common.wgsl`).
pub fn dither_threshold(x: u32, y: u32, instance: u32) -> u32 {
    let (x, y) = (x & 7, y & 7);
    let xy = x ^ y;
    let b = ((xy & 1) << 5)
        | ((y & 1) << 4)
        | ((xy & 2) << 2)
        | ((y & 2) << 1)
        | ((xy & 4) >> 1)
        | ((y & 4) >> 2);
    let u = ((b as f32 + 0.5) / 64.0 + instance_hash(instance)).fract();
    ((u * WEIGHT_ONE as f32) as u32).min(WEIGHT_ONE - 1)
}

/// The screen-door threshold that splits a tree in its band between the forms
/// (`form_threshold` in `shaders/common.wgsl`): the quads draw pixel `(x, y)` when it is below
/// the tree's [`quad_share`], the geometry otherwise.
pub fn form_threshold(x: u32, y: u32, instance: u32) -> u32 {
    dither_threshold(y, x, instance ^ 0x5bd1_e995)
}

/// The hybrid's share of a tree given to its mesh LOD that starts at `from` (a fraction of
/// the switch distance, 0: the species has no such LOD) and the coarser ones, in units of
/// 1/[`WEIGHT_ONE`] (`lod_share` in `shaders/common.wgsl`): the [`quad_share`] of a switch
/// `from` times nearer, with the same band and jitter, so LODs crossfade as the forms do.
/// 0 without such a LOD or without a switch (the quad stream alone, geometry alone).
pub fn lod_share(forms: [f32; 4], distance: f32, unit: f32, instance: u32, from: f32) -> u32 {
    let s = forms[0] + forms[1] * unit;
    if from <= 0.0 || s <= 0.0 || s >= GEOMETRY_ALWAYS {
        return 0;
    }
    quad_share(
        [forms[0] * from, forms[1] * from, forms[2], forms[3]],
        distance,
        unit,
        instance,
    )
}

/// The shares of a tree's mesh LODs 1 and 2 and coarser, `[c1, c2]` with `c1 ≥ c2`, for a
/// species whose LODs start at `lod_from` (fractions of the switch, 0: none): mesh LOD `k`
/// (0, 1, 2) draws the pixels whose [`lod_threshold`] lies in `[c(k+1), c(k))`, with
/// `c0 = WEIGHT_ONE` and `c3 = 0`; a LOD without a start takes no pixels.
pub fn lod_shares(
    forms: [f32; 4],
    distance: f32,
    unit: f32,
    instance: u32,
    lod_from: [f32; 2],
) -> [u32; 2] {
    let c2 = lod_share(forms, distance, unit, instance, lod_from[1]);
    let c1 = lod_share(forms, distance, unit, instance, lod_from[0]).max(c2);
    [c1, c2]
}

/// The screen-door threshold that splits a tree in a crossfade between its mesh LODs
/// (`lod_threshold` in `shaders/common.wgsl`), salted apart from [`form_threshold`].
pub fn lod_threshold(x: u32, y: u32, instance: u32) -> u32 {
    dither_threshold(x, y, instance ^ 0x27d4_eb2f)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shares_run_from_geometry_to_quads_across_the_band() {
        let forms = [10.0, 0.0, 0.5, 0.0];
        assert_eq!(quad_share(forms, 9.99, 3.0, 7), 0);
        assert_eq!(quad_share(forms, 12.5, 3.0, 7), WEIGHT_ONE / 2 + 1);
        assert_eq!(quad_share(forms, 15.0, 3.0, 7), WEIGHT_ONE);
        assert_eq!(quad_share(FORMS_QUADS, 0.0, 3.0, 7), WEIGHT_ONE);
        assert_eq!(quad_share(FORMS_GEOMETRY, 1e30, 3.0, 7), 0);
        // Focal length times the tree's unit: 2 px × 3 m/px.
        assert_eq!(quad_share([0.0, 2.0, 0.0, 0.0], 5.9, 3.0, 7), 0);
        assert_eq!(quad_share([0.0, 2.0, 0.0, 0.0], 6.0, 3.0, 7), WEIGHT_ONE);
    }

    #[test]
    fn jitter_spreads_the_band_start_over_instances() {
        let forms = [10.0, 0.0, 0.0, 0.5];
        let starts: Vec<f32> = (0..1000)
            .map(|i| 10.0 * (1.0 + 0.5 * instance_hash(i)))
            .collect();
        assert!(starts.iter().all(|s| (10.0..15.0).contains(s)));
        // At 12.5 m about half of the trees have switched.
        let quads = (0..1000)
            .filter(|&i| quad_share(forms, 12.5, 1.0, i) == WEIGHT_ONE)
            .count();
        assert!((400..600).contains(&quads), "{quads}");
    }

    #[test]
    fn mesh_lods_split_the_near_trees_by_fractions_of_the_switch() {
        // Switch at 20 m, band 0.5, no jitter: LOD 1 from 0.5 (10 to 15 m), LOD 2 from 0.75
        // (15 to 22.5 m).
        let forms = [20.0, 0.0, 0.5, 0.0];
        let from = [0.5, 0.75];
        let half = WEIGHT_ONE / 2 + 1;
        assert_eq!(lod_shares(forms, 9.9, 1.0, 3, from), [0, 0]);
        assert_eq!(lod_shares(forms, 12.5, 1.0, 3, from), [half, 0]);
        assert_eq!(lod_shares(forms, 15.0, 1.0, 3, from), [WEIGHT_ONE, 0]);
        assert_eq!(lod_shares(forms, 18.75, 1.0, 3, from), [WEIGHT_ONE, half]);
        assert_eq!(lod_shares(forms, 22.5, 1.0, 3, from), [WEIGHT_ONE; 2]);
        // Without LOD 1, LOD 2 takes its pixels straight from LOD 0.
        assert_eq!(lod_shares(forms, 18.75, 1.0, 3, [0.0, 0.75]), [half; 2]);
        assert_eq!(lod_shares(forms, 18.75, 1.0, 3, [0.0, 0.0]), [0, 0]);
        // No switch, no LODs: the quad stream or full geometry alone.
        for f in [FORMS_QUADS, FORMS_GEOMETRY] {
            assert_eq!(lod_shares(f, 15.0, 1.0, 3, from), [0, 0]);
        }
        // The focal-length switch scales the same way.
        let auto = [0.0, 2.0, 0.5, 0.0];
        assert_eq!(
            lod_shares(auto, 12.5, 10.0, 3, from),
            lod_shares(forms, 12.5, 1.0, 3, from)
        );
        // With band 1 the crossfades overlap: at 17.5 m LOD 1 and coarser have 3/4 (3071.25),
        // LOD 2 1/6 (682.5).
        let forms = [20.0, 0.0, 1.0, 0.0];
        // Every pixel of a tree goes to exactly one LOD, in proportion to the shares.
        let [c1, c2] = lod_shares(forms, 17.5, 1.0, 9, from);
        assert_eq!([c1, c2], [3071, 683]);
        let mut per_lod = [0u32; 3];
        for y in 0..8 {
            for x in 0..8 {
                let t = lod_threshold(x, y, 9);
                per_lod[2 - usize::from(t >= c2) - usize::from(t >= c1)] += 1;
            }
        }
        let want = |c: u32| c as f32 / WEIGHT_ONE as f32 * 64.0;
        assert!((per_lod[2] as f32 - want(c2)).abs() <= 1.0, "{per_lod:?}");
        assert!(
            (per_lod[1] as f32 - (want(c1) - want(c2))).abs() <= 1.0,
            "{per_lod:?}"
        );
        assert_eq!(per_lod.iter().sum::<u32>(), 64);
    }

    #[test]
    fn the_forms_split_every_pixel_and_cover_their_share() {
        for share in [0, 1, 1000, 2048, 4000, WEIGHT_ONE] {
            for inst in [0, 1, 99] {
                let mut quads = 0;
                for y in 0..8 {
                    for x in 0..8 {
                        let t = form_threshold(x, y, inst);
                        assert!(t < WEIGHT_ONE);
                        // The quads draw the pixel, or the geometry does: never both, never none.
                        quads += u32::from(t < share);
                    }
                }
                let want = share as f32 / WEIGHT_ONE as f32 * 64.0;
                assert!(
                    (quads as f32 - want).abs() <= 1.0,
                    "share {share}: {quads}/64"
                );
            }
        }
    }
}
