//! Tests of `gltf_mesh.rs`.

use super::*;

#[test]
fn alpha_remap_moves_the_cutoff_to_one_half() {
    for c in [0.1f32, 0.3, 0.5, 0.7, 0.95] {
        for a in 0..=255u8 {
            let passes = f32::from(a) / 255.0 >= c;
            assert_eq!(remap_alpha(a, c) >= 128, passes, "a {a} cutoff {c}");
        }
    }
    assert_eq!(remap_alpha(0, 0.5), 0);
    assert_eq!(remap_alpha(255, 0.5), 255);
    assert_eq!(remap_alpha(10, 0.0), 255);
}
