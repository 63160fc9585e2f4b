//! Property tests: every format the project writes reads back to what was written, for
//! arbitrary valid contents (forest binary and JSON, camera paths, node files, atlases with
//! random layers and random quad trees).

use forest_format::QuadNode;
use forest_format::atlas::{
    Atlas, BakeParams, ColourEncoding, Layers, SourceInfo, manifest_for, nodes_per_level,
};
use forest_format::camera_path::CameraPath;
use forest_format::forest::{Forest, Instance};
use forest_format::slab::Sphere;
use glam::Vec3;
use proptest::prelude::*;

fn coordinate() -> impl Strategy<Value = f32> {
    -1e6f32..1e6
}

fn forest() -> impl Strategy<Value = Forest> {
    let species = prop::collection::vec(
        prop::collection::vec(any::<char>(), 1..12).prop_map(|c| c.into_iter().collect::<String>()),
        1..4,
    );
    (species, 1u32..9, 0usize..40).prop_flat_map(|(species, presort, n)| {
        let count = species.len() as u32;
        let instance = (
            [coordinate(), coordinate(), coordinate()],
            -10.0f32..10.0,
            0.01f32..100.0,
            0..count,
        )
            .prop_map(|(position, rotation, scale, species)| Instance {
                position,
                rotation,
                scale,
                species,
            });
        prop::collection::vec(instance, n)
            .prop_map(move |instances| Forest::new(species.clone(), instances, presort))
    })
}

/// A level-ordered forest of quad trees over `roots` roots and at most `levels` levels, with
/// random child masks, depths and error codes.
fn quad_trees(roots: usize, levels: u32) -> impl Strategy<Value = Vec<QuadNode>> {
    prop::collection::vec((any::<u8>(), any::<[u8; 4]>(), 0u8..16), 1..400).prop_map(move |draws| {
        let mut draws = draws.into_iter().cycle();
        let mut nodes = Vec::new();
        let mut level_len = roots;
        for level in 0..levels {
            let next_start = nodes.len() + level_len;
            let mut next_len = 0usize;
            for _ in 0..level_len {
                let (m, depth, error) = draws.next().expect("a cycle never ends");
                // No children on the last level, and few once the trees are large.
                let mask = if level + 1 == levels || nodes.len() > 300 {
                    0
                } else {
                    m & 15
                };
                let first = (next_start + next_len) as u32;
                nodes.push(QuadNode::new(mask, first, depth).with_error(error));
                next_len += mask.count_ones() as usize;
            }
            level_len = next_len;
        }
        nodes
    })
}

/// An atlas of random layers and random trees, lossless colour: it saves, loads to the same
/// atlas, and decodes to the layers it was made from.
fn atlas_round_trip(params: BakeParams, pixels: &[(u8, [u8; 3])], nodes: Vec<QuadNode>) {
    let n = params.layers();
    let r = params.resolution as usize;
    let rgba: Vec<u8> = (0..n as usize * r * r)
        .flat_map(|i| {
            let (a, c) = pixels[i % pixels.len()];
            // Premultiplied: colour at most alpha (the stored form's invariant).
            let [r, g, b] = c.map(|v| v.min(a));
            [r, g, b, a]
        })
        .collect();
    let layers = Layers {
        resolution: params.resolution,
        count: n,
        rgba,
    };
    let per_level =
        nodes_per_level(&nodes, n as usize, params.levels()).expect("the trees fit the levels");
    let manifest = manifest_for(
        params,
        SourceInfo {
            file: "random.obj".into(),
            hash: "0".into(),
            triangles: 1,
            degenerate_triangles: 0,
            materials: vec![],
            top: Some(6.5),
            foot: Some(0.25),
        },
        Sphere {
            center: Vec3::new(0.5, 2.0, -1.0),
            radius: 3.0,
        },
        (0..n).map(Some).collect(),
        per_level,
    );
    // Surface attributes: the colour's bytes turned around, premultiplied (at most the alpha).
    let surface = Layers {
        rgba: layers
            .rgba
            .chunks_exact(4)
            .flat_map(|p| [p[2], p[1], p[0], p[3] / 2])
            .collect(),
        ..layers.clone()
    };
    let r = forest_format::opacity::VOLUME_RESOLUTION;
    let depths: Vec<f32> = (0..r.pow(3)).map(|i| (i % 11) as f32 * 0.07).collect();
    let volume = forest_format::opacity::OpacityVolume::from_depths(r, &depths);
    let atlas = Atlas::from_layers(manifest, &layers, &surface, &volume, nodes).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.atlas");
    atlas.save(&path).unwrap();
    let back = Atlas::load(&path).unwrap();
    assert_eq!(back, atlas);
    let decoded = back.decode_layers(&path).unwrap();
    assert_eq!((decoded.resolution, decoded.count), (layers.resolution, n));
    for (d, l) in decoded
        .rgba
        .chunks_exact(4)
        .zip(layers.rgba.chunks_exact(4))
    {
        // Alpha is lossless; lossless colour within the decoder's rounding.
        assert_eq!(d[3], l[3]);
        assert!(
            d.iter().zip(l).all(|(a, b)| a.abs_diff(*b) <= 1),
            "{d:?} vs {l:?}"
        );
    }
    // The surface mosaic is stored at 1/SURFACE_SCALE the resolution, losslessly.
    let scale = forest_format::atlas::SURFACE_SCALE;
    let expected = surface
        .surface_downsampled(&layers, scale)
        .surface_upsampled(&decoded, scale);
    assert!(back.decode_surface(&path, &decoded).unwrap() == expected);
    // So is the opacity volume, and its coding is in the manifest.
    assert_eq!(back.decode_opacity(&path).unwrap(), volume);
    assert_eq!(back.manifest.opacity.max_depth, volume.max_depth);
}

fn atlas_params() -> impl Strategy<Value = BakeParams> {
    (1u32..5, 0u32..3, 1u32..3, 2u32..5).prop_map(|(directions, below, slabs, log2)| BakeParams {
        directions,
        below,
        slabs,
        resolution: 1 << log2,
        min_quad: 2,
        colour: ColourEncoding::Png,
        ..BakeParams::default()
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn forest_binary_round_trips(f in forest()) {
        f.check(std::path::Path::new("generated")).unwrap();
        prop_assert_eq!(Forest::from_bytes(&f.to_bytes()).unwrap(), f);
    }

    #[test]
    fn forest_json_round_trips(f in forest()) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.json");
        f.save(&path).unwrap();
        let back = Forest::load(&path).unwrap();
        prop_assert_eq!(&back.species, &f.species);
        prop_assert_eq!(&back.presort, &f.presort);
        prop_assert_eq!(back.instances.len(), f.instances.len());
        for (a, b) in back.instances.iter().zip(&f.instances) {
            prop_assert_eq!((a.position, a.scale, a.species), (b.position, b.scale, b.species));
            // Rotations are stored in degrees: equal within the conversion's f32 rounding.
            prop_assert!((a.rotation - b.rotation).abs() <= 1e-6 * (1.0 + b.rotation.abs()));
        }
    }

    #[test]
    fn camera_paths_round_trip(
        fov in 1.0f32..179.0,
        keys in prop::collection::vec(
            ([coordinate(), coordinate(), coordinate()], [coordinate(), coordinate(), coordinate()]),
            1..20,
        ),
    ) {
        let mut p = CameraPath::new(fov);
        for (eye, target) in keys {
            let (eye, target) = (Vec3::from_array(eye), Vec3::from_array(target));
            p.push(eye, if target == eye { eye + Vec3::X } else { target });
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.json");
        p.save(&path).unwrap();
        prop_assert_eq!(CameraPath::load(&path).unwrap(), p);
    }

    #[test]
    fn node_files_round_trip(
        (roots, nodes) in (1usize..6, 1u32..6)
            .prop_flat_map(|(roots, levels)| (Just(roots), quad_trees(roots, levels)))
    ) {
        let bytes = forest_format::nodes_codec::encode(&nodes, roots);
        prop_assert_eq!(forest_format::nodes_codec::decode(&bytes).unwrap(), (nodes, roots));
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    #[test]
    fn atlases_round_trip(
        (params, pixels, nodes) in atlas_params().prop_flat_map(|p| (
            Just(p),
            prop::collection::vec((any::<u8>(), any::<[u8; 3]>()), 1..64),
            quad_trees(p.layers() as usize, p.levels()),
        ))
    ) {
        params.validate().expect("the strategy makes valid parameters");
        atlas_round_trip(params, &pixels, nodes);
    }
}
