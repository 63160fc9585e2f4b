//! Tests of `forest.rs`.

use super::*;

fn sample() -> Forest {
    let instances = (0..50)
        .map(|i| Instance {
            position: [(i % 7) as f32 * 3.0, 0.0, (i / 7) as f32 * 4.0 - 10.0],
            rotation: i as f32 * 0.3,
            scale: 0.8 + (i % 3) as f32 * 0.1,
            species: i % 2,
        })
        .collect();
    Forest::new(vec!["a.atlas".into(), "b.atlas".into()], instances, 15)
}

#[test]
fn presort_orders_are_back_to_front() {
    let f = sample();
    for (d, order) in f.presort.directions.iter().zip(&f.presort.orders) {
        let keys: Vec<f32> = order
            .iter()
            .map(|&i| Vec3::from_array(f.instances[i as usize].position).dot(*d))
            .collect();
        assert!(keys.windows(2).all(|w| w[0] <= w[1]));
    }
    // Seen from +Z (the horizon direction at azimuth 0), the first tree is the one with
    // the smallest z.
    let k = Presort::nearest(&f.presort.directions, Vec3::Z);
    assert!(f.presort.directions[k].z > 0.99);
    let first = f.instances[f.presort.orders[k][0] as usize];
    assert_eq!(first.position[2], -10.0);
}

#[test]
fn binary_and_json_round_trip() {
    let f = sample();
    let dir = tempfile::tempdir().unwrap();
    let bin = dir.path().join("f.forest");
    f.save(&bin).unwrap();
    assert_eq!(Forest::load(&bin).unwrap(), f);
    let json = dir.path().join("f.json");
    f.save(&json).unwrap();
    let back = Forest::load(&json).unwrap();
    assert_eq!(back.species, f.species);
    assert_eq!(back.instances.len(), f.instances.len());
    for (a, b) in back.instances.iter().zip(&f.instances) {
        assert!((a.rotation - b.rotation).abs() < 1e-5);
        assert_eq!(a.position, b.position);
    }
}

#[test]
fn a_colouring_round_trips_and_old_forests_keep_their_bytes() {
    use crate::colour::{Colouring, SpeciesColour};
    let plain = sample();
    let mut colouring = Colouring::new(
        0.7,
        vec![SpeciesColour::DECIDUOUS, SpeciesColour::EVERGREEN],
    );
    let f = plain.clone().with_colouring(colouring.clone());
    let bytes = f.to_bytes();
    assert_eq!(bytes[4..8], 3u32.to_le_bytes());
    // The colouring costs its species' records and no byte per tree.
    assert_eq!(bytes.len(), plain.to_bytes().len() + 4 + 4 + 4 + 2 * 64 + 4);
    assert_eq!(Forest::from_bytes(&bytes).unwrap(), f);
    // With a terrain and explicit values (4 bytes per tree), in both forms.
    colouring.explicit = (0..50)
        .map(|k| if k % 3 == 0 { 0.5 } else { -1.0 })
        .collect();
    let terrain = Terrain {
        size: [2, 2],
        origin: [-20.0, -15.0],
        spacing: 40.0,
        heights: vec![0.0, 1.0, 2.0, 3.0],
    };
    let f = plain.with_terrain(terrain).with_colouring(colouring);
    assert_eq!(Forest::from_bytes(&f.to_bytes()).unwrap(), f);
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("f.json");
    f.save(&json).unwrap();
    let back = Forest::load(&json).unwrap();
    assert_eq!(back.colouring, f.colouring);
    // Bad sections are named.
    let err = |b: &[u8]| Forest::from_bytes(b).unwrap_err();
    let bytes = f.to_bytes();
    assert!(err(&bytes[..bytes.len() - 3]).contains("truncated"));
    let mut extra = bytes.clone();
    extra.push(0);
    assert!(
        err(&extra).contains("after the colouring"),
        "{}",
        err(&extra)
    );
    let at = plain_len_with_presorts(&f);
    let mut flags = bytes.clone();
    flags[at..at + 4].copy_from_slice(&4u32.to_le_bytes());
    assert!(err(&flags).contains("flags 0x4"), "{}", err(&flags));
    let mut nan = f.clone();
    nan.colouring.as_mut().unwrap().species[1].hue_deg = f32::NAN;
    let path = dir.path().join("nan.forest");
    let e = Forest::parse(&path, &nan.to_bytes())
        .unwrap_err()
        .to_string();
    assert!(e.contains("species 1's colour: hue_deg is NaN"), "{e}");
    // An instance's value without a colouring is refused in JSON.
    let j = r#"{"species": ["a"], "instances": [{"species": 0, "position": [0, 0, 0],
        "colour": 0.5}]}"#;
    let e = Forest::parse(&json, j.as_bytes()).unwrap_err().to_string();
    assert!(e.contains("no \"colour\" section"), "{e}");
}

/// Where a forest's bytes after its presorts start.
fn plain_len_with_presorts(f: &Forest) -> usize {
    let names: usize = f.species.iter().map(|s| 4 + s.len()).sum();
    let n = f.instances.len();
    let k = f.presort.directions.len();
    12 + names + 4 + 24 * n + 4 + 12 * k + 4 * k * n
}

#[test]
fn a_terrain_round_trips_and_a_forest_without_one_stays_version_1() {
    let plain = sample();
    assert_eq!(plain.to_bytes()[4..8], 1u32.to_le_bytes());
    let terrain = Terrain {
        size: [3, 2],
        origin: [-20.0, -15.0],
        spacing: 20.0,
        heights: vec![0.0, 1.5, 3.0, 2.0, 4.0, 8.0],
    };
    let f = plain.with_terrain(terrain.clone());
    let bytes = f.to_bytes();
    assert_eq!(bytes[4..8], 2u32.to_le_bytes());
    assert_eq!(Forest::from_bytes(&bytes).unwrap(), f);
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("f.json");
    f.save(&json).unwrap();
    assert_eq!(Forest::load(&json).unwrap().terrain, Some(terrain));
    assert_eq!(f.ground_height(20.0, 5.0), 8.0);
    assert_eq!(f.ground_height(500.0, 5.0), 0.0);
    assert!(f.extent() >= Vec3::new(20.0, 8.0, 15.0).length());
    // Truncated, bad or trailing terrain data is named.
    let err = |b: &[u8]| Forest::from_bytes(b).unwrap_err();
    assert!(err(&bytes[..bytes.len() - 2]).contains("truncated"));
    let mut extra = bytes.clone();
    extra.push(0);
    assert!(err(&extra).contains("after the terrain"), "{}", err(&extra));
    let mut nan = bytes.clone();
    let n = nan.len();
    nan[n - 4..].copy_from_slice(&f32::NAN.to_le_bytes());
    assert!(err(&nan).contains("terrain: height NaN"), "{}", err(&nan));
    let mut huge = bytes;
    let at = huge.len() - 6 * 4 - 5 * 4;
    huge[at..at + 4].copy_from_slice(&100_000u32.to_le_bytes());
    assert!(err(&huge).contains("100000×2"), "{}", err(&huge));
}

#[test]
fn bad_forests_are_rejected_with_a_reason() {
    let f = sample();
    let bytes = f.to_bytes();
    assert!(
        Forest::from_bytes(&bytes[..bytes.len() - 1])
            .unwrap_err()
            .contains("truncated")
    );
    assert!(Forest::from_bytes(b"nope").unwrap_err().contains("FRST"));
    let mut g = f.clone();
    g.instances[3].species = 9;
    assert!(
        g.check(Path::new("x"))
            .unwrap_err()
            .to_string()
            .contains("species 9")
    );
    let mut g = f.clone();
    g.instances[1].scale = 0.0;
    assert!(g.check(Path::new("x")).is_err());
    let mut g = f.clone();
    g.presort.orders[2][0] = g.presort.orders[2][1];
    assert!(
        g.check(Path::new("x"))
            .unwrap_err()
            .to_string()
            .contains("permutation")
    );
    let err = |g: &Forest| g.check(Path::new("x")).unwrap_err().to_string();
    let mut g = f.clone();
    g.presort.orders[0].reverse();
    assert!(err(&g).contains("not sorted"), "{}", err(&g));
    let mut g = f.clone();
    g.presort.directions[1] *= 2.0;
    assert!(err(&g).contains("unit vector"), "{}", err(&g));
    let mut g = f.clone();
    g.presort.directions[1].x = f32::NAN;
    assert!(err(&g).contains("unit vector"), "{}", err(&g));
    let mut g = f.clone();
    g.instances[2].position[0] = 1e20;
    assert!(err(&g).contains("farther than"), "{}", err(&g));
    let mut g = f;
    g.instances[0].position[1] = f32::NAN;
    assert!(g.check(Path::new("x")).is_err());
}
