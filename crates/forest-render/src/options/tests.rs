//! Tests of `options.rs`.

use super::*;

/// Sharpening: weights (0.7, 0.25, 0.05) quantise to (2867, 1024, 205), whose sum's excess
/// the largest gives back; less 410 each, (2457, 614, 0), scaled to 4095 in integers
/// (3276, 818, 0), and the remainder to the largest. A sharpening past a third is refused; the
/// value rides in flag bits 8–19.
#[test]
fn sharpening_fades_the_faint_aspect_out_exactly() {
    let flags = |sharpen| {
        StreamOptions {
            sharpen,
            ..Default::default()
        }
        .flags()
    };
    use crate::reference::quantise;
    let w = [0.7, 0.25, 0.05];
    assert_eq!(
        crate::reference::aspect_weights(quantise(w), flags(0), 0),
        [2866, 1024, 205]
    );
    assert_eq!(
        crate::reference::aspect_weights(quantise(w), flags(410), 410),
        [3277, 818, 0]
    );
    assert_eq!((flags(410) >> SHARPEN_SHIFT) & SHARPEN_MASK, 410);
    assert_eq!((flags(0) >> SHARPEN_SHIFT) & SHARPEN_MASK, 0);
    let e = StreamOptions {
        sharpen: SHARPEN_MAX + 1,
        ..Default::default()
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(e.contains("sharpening"), "{e}");
    // The largest share a third of one can leave: the largest weight keeps the whole.
    let q = crate::reference::aspect_weights(
        quantise([0.34, 0.33, 0.33]),
        flags(SHARPEN_MAX),
        SHARPEN_MAX,
    );
    assert_eq!(q.iter().sum::<u32>(), WEIGHT_ONE);
    assert_eq!(q[0], WEIGHT_ONE);
}

/// The reach rides in flag bits 20–23 beside the sharpening, and a reach out of
/// 1..=SHARPEN_REACH_MAX is refused naming it. A tree's sharpening climbs from the flags'
/// own (class 0: wider than the reach) to the largest (class REACH_STEPS: just outside
/// the far span) in equal integer steps: 410 + 954 · k / 16.
#[test]
fn the_sharpening_reach_climbs_to_the_largest_in_steps() {
    use crate::reference::tree_sharpen;
    let o = StreamOptions::default();
    let f = o.flags();
    assert_eq!((f >> REACH_SHIFT) & REACH_MASK, SHARPEN_REACH_DEFAULT);
    assert_eq!((f >> SHARPEN_SHIFT) & SHARPEN_MASK, SHARPEN_DEFAULT);
    assert!(f < 1 << 24, "the flags ride in an f32");
    assert_eq!(f as f32 as u32, f);
    let steps: Vec<u32> = (0..=REACH_STEPS).map(|k| tree_sharpen(f, k)).collect();
    assert_eq!(
        steps,
        [
            410, 469, 529, 588, 648, 708, 767, 827, 887, 946, 1006, 1065, 1125, 1185, 1244, 1304,
            1364
        ]
    );
    // Past the last step (and for the far class) it stays at the largest.
    assert_eq!(tree_sharpen(f, crate::reference::FAR_CLASS), SHARPEN_MAX);
    // A sharpening already at the largest stays there.
    let max = StreamOptions {
        sharpen: SHARPEN_MAX,
        ..o
    };
    assert_eq!(tree_sharpen(max.flags(), 0), SHARPEN_MAX);
    for bad in [0, SHARPEN_REACH_MAX + 1] {
        let e = StreamOptions {
            sharpen_reach: bad,
            ..o
        }
        .validate()
        .unwrap_err()
        .to_string();
        assert!(e.contains("reach") && e.contains(&bad.to_string()), "{e}");
    }
    let widest = StreamOptions {
        sharpen_reach: SHARPEN_REACH_MAX,
        sharpen: SHARPEN_MAX,
        ..o
    };
    widest.validate().unwrap();
    assert_eq!(
        (widest.flags() >> REACH_SHIFT) & REACH_MASK,
        SHARPEN_REACH_MAX
    );
    assert!(widest.flags() < 1 << 24);
}

/// A far span out of 1..=FAR_SPAN_MAX is refused with a message naming it; the options
/// reach the camera uniform where the shaders read them.
#[test]
fn the_far_span_is_checked_and_written_to_forward_w() {
    for bad in [0, FAR_SPAN_MAX + 1] {
        let o = StreamOptions {
            far_span: bad,
            ..Default::default()
        };
        let e = o.validate().unwrap_err().to_string();
        assert!(
            e.contains("far span") && e.contains(&bad.to_string()),
            "{e}"
        );
    }
    for good in [1, FAR_SPAN_DEFAULT, FAR_SPAN_MAX] {
        let o = StreamOptions {
            far_span: good,
            blend: AspectBlend::Nearest,
            ..Default::default()
        };
        o.validate().unwrap();
        let mut g = crate::gpu_types::GpuCamera::default();
        o.apply(&mut g);
        assert_eq!(g.far_span, good as f32);
        assert_eq!(g.stream_flags as u32, o.flags());
        assert_eq!(o.flags() & 0xff, FLAG_NEAREST);
    }
    // A camera made without a stream carries the default options, as a stream would write.
    let cam = crate::Camera {
        eye: glam::Vec3::new(0.0, 2.0, 10.0),
        target: glam::Vec3::ZERO,
        fov_y_deg: 60.0,
        near: 0.1,
        far: 100.0,
        viewport: (64, 48),
        epsilon: 4.0,
    };
    let mut g = cam.to_gpu();
    assert_eq!(g.far_span, FAR_SPAN_DEFAULT as f32);
    assert_eq!(g.stream_flags as u32, StreamOptions::default().flags());
    StreamOptions::default().apply(&mut g);
    assert_eq!(g, cam.to_gpu());
}

/// The environment shader tints the atmosphere's sky by the frame's sky light over the
/// default light's: its reference is that sky.
#[test]
fn the_sky_is_tinted_relative_to_the_default_light() {
    let sky = forest_format::shading::Lighting::default().sky;
    let line = format!(
        "const REFERENCE_SKY: vec3<f32> = vec3<f32>({:?}, {:?}, {:?});",
        sky.x, sky.y, sky.z
    );
    assert!(
        crate::passes::ENVIRONMENT_WGSL.contains(&line),
        "environment.wgsl lacks `{line}`"
    );
}

#[test]
fn the_ground_mixes_soil_and_moss_in_patches() {
    let (mut soil, mut moss) = (0, 0);
    for k in 0..4000 {
        let (x, z) = ((k % 63) as f32 * 3.7 - 100.0, (k / 63) as f32 * 4.1 - 120.0);
        let a = ground_albedo(x, z);
        // On the segment from soil to moss.
        let t = (a - GROUND_ALBEDO).length() / (GROUND_MOSS - GROUND_ALBEDO).length();
        let back = GROUND_ALBEDO.lerp(GROUND_MOSS, t);
        assert!(
            (a - back).length() < 1e-5 && (0.0..=1.0).contains(&t),
            "{a}"
        );
        soil += usize::from(t < 0.1);
        moss += usize::from(t > 0.9);
        // Continuous: a centimetre away, nearly the same.
        assert!((ground_albedo(x + 0.01, z) - a).length() < 2e-3);
    }
    assert!(soil > 400 && moss > 400, "{soil} soil, {moss} moss of 4000");
    // Far from the origin the lattice still works (no overflow, values in range).
    let far = ground_albedo(9.9e6, -9.9e6);
    assert!(far.is_finite() && far.min_element() >= 0.0);
}
