//! Tests of `model.rs`.

use super::*;

/// The dilation as first written, a whole-image scan per ring: the reference.
fn dilate_by_scans(img: &mut image::RgbaImage, min_alpha: u8) {
    let (w, h) = img.dimensions();
    let mut known: Vec<bool> = img.pixels().map(|p| p[3] >= min_alpha.max(1)).collect();
    if !known.iter().any(|k| *k) {
        return;
    }
    loop {
        let mut next = known.clone();
        let mut changed = false;
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                if known[i] {
                    continue;
                }
                let (mut acc, mut c) = ([0u32; 3], 0);
                for (dx, dy) in [(-1i32, 0i32), (1, 0), (0, -1), (0, 1)] {
                    let (nx, ny) = (x as i32 + dx, y as i32 + dy);
                    if nx < 0 || ny < 0 || nx >= w as i32 || ny >= h as i32 {
                        continue;
                    }
                    if known[(ny as u32 * w + nx as u32) as usize] {
                        let p = img.get_pixel(nx as u32, ny as u32);
                        (0..3).for_each(|k| acc[k] += u32::from(p[k]));
                        c += 1;
                    }
                }
                if c > 0 {
                    let p = img.get_pixel_mut(x, y);
                    (0..3).for_each(|k| p[k] = (acc[k] / c) as u8);
                    next[i] = true;
                    changed = true;
                }
            }
        }
        known = next;
        if !changed {
            break;
        }
    }
}

#[test]
fn dilation_equals_the_whole_image_scans_and_fills_from_one_texel() {
    let mut rng = crate::noise::SplitMix64(0x9e37_79b9_7f4a_7c15);
    let mut next = move || rng.next_u64();
    for (w, h, density) in [
        (64, 64, 2),
        (37, 11, 20),
        (1, 50, 10),
        (50, 1, 10),
        (128, 96, 1),
        (16, 16, 0),
        (16, 16, 100),
    ] {
        let img = image::RgbaImage::from_fn(w, h, |_, _| {
            let r = next();
            let [a, b, c, _, _, _, _, _] = r.to_le_bytes();
            let alpha = if (r >> 40) % 100 < density {
                200
            } else {
                (r >> 50) as u8 % 128
            };
            image::Rgba([a, b, c, alpha])
        });
        let (mut fast, mut slow) = (img.clone(), img.clone());
        dilate_colour_from(&mut fast, 128);
        dilate_by_scans(&mut slow, 128);
        assert!(fast == slow, "{w}x{h} at {density} %");
        // Alpha is never touched.
        assert!(fast.pixels().zip(img.pixels()).all(|(a, b)| a[3] == b[3]));
    }
    // One known texel colours the whole image.
    let mut one = image::RgbaImage::from_pixel(9, 7, image::Rgba([1, 2, 3, 0]));
    one.put_pixel(6, 2, image::Rgba([200, 100, 50, 255]));
    dilate_colour_from(&mut one, 128);
    assert!(one.pixels().all(|p| p.0[..3] == [200, 100, 50]));
}

#[test]
fn footprint_is_the_widest_point_of_the_foot() {
    // A trunk of radius 0.3 m standing at x = 0.1 (so up to 0.4 m from the axis), 10 m
    // tall, with a crown 3 m wide above 2 m and a branch tip 5 m out at 1 m.
    let mut pts = Vec::new();
    for k in 0..16 {
        let a = k as f32 * std::f32::consts::TAU / 16.0;
        for y in [0.0, 0.15, 2.0] {
            pts.push([0.1 + 0.3 * a.cos(), y, 0.3 * a.sin()]);
        }
        pts.push([3.0 * a.cos(), 2.0 + 4.0 * a.sin().abs(), 3.0 * a.sin()]);
    }
    pts.push([5.0, 1.0, 0.0]);
    pts.push([0.0, 10.0, 0.0]);
    let r = footprint_radius(pts.iter().copied());
    assert!((r - 0.4).abs() < 1e-6, "{r}");
    // The band is 2 % of the height above the lowest point, wherever that lies.
    let raised: Vec<_> = pts.iter().map(|p| [p[0], p[1] - 7.0, p[2]]).collect();
    assert_eq!(footprint_radius(raised.iter().copied()), r);
    // A point below the old foot makes a new one; non-finite points are skipped.
    pts.push([0.0, -1.0, 0.05]);
    pts.push([f32::NAN, -5.0, 9.0]);
    assert!((footprint_radius(pts.iter().copied()) - 0.05).abs() < 1e-6);
    assert_eq!(footprint_radius(std::iter::empty()), 0.0);
    // Only LOD 0 counts: the tiny model's LOD 1 lies lower and wider.
    let mut m = tiny();
    for v in &mut m.vertices[9..] {
        v.pos = [7.0, -3.0, 0.0];
    }
    let lod0 = footprint_radius(m.vertices[..9].iter().map(|v| v.pos));
    assert_eq!(m.footprint_radius(), lod0);
    assert!(lod0 < 7.0);
}

/// A small model: one branch triangle, two leaf triangles, two materials (one textured).
pub(crate) fn tiny() -> PreparedModel {
    let v = |x: f32, material: u32, element: u32| RefVertex {
        pos: [x, x * 0.5, 1.0],
        sky_front: 0.75,
        normal: [0.0, 0.0, 1.0],
        material,
        uv: [x, 1.0 - x],
        element,
        sky_back: 0.25,
    };
    let mut vertices = vec![v(0.0, 0, NONE), v(1.0, 0, NONE), v(2.0, 0, NONE)];
    vertices.extend((0..6).map(|i| v(i as f32, 1, i / 3)));
    vertices.extend((0..3).map(|i| v(i as f32, 1, NONE)));
    let img = |side: u32, seed: u8| {
        image::RgbaImage::from_fn(side, side, |x, y| {
            image::Rgba([x as u8 ^ seed, y as u8, seed, (x + y) as u8])
        })
    };
    PreparedModel {
        source_hash: "abc123".into(),
        sphere: [0.0, 1.0, 0.0, 2.5],
        vertices,
        lod_vertices: [9, 3, 0],
        branch_vertices: 3,
        r: 0.5,
        mean_leaf: [0.1, 0.3, 0.05],
        materials: vec![
            ModelMaterial {
                kd: [0.3, 0.2, 0.1, 0.0],
                layer: NONE,
                alpha_tested: false,
            },
            ModelMaterial {
                kd: [1.0, 1.0, 1.0, 0.4],
                layer: 0,
                alpha_tested: true,
            },
        ],
        layers: vec![img(MATERIAL_TEXTURE_SIZE, 7)],
        leaf_end: vec![6, 9],
        leaf_centre: vec![[1.0, 0.5, 1.0], [4.0, 2.0, 1.0]],
        billboards: (0..BILLBOARDS as u8)
            .map(|i| BillboardPair {
                albedo: img(BILLBOARD_RESOLUTION, i),
                surface: img(BILLBOARD_RESOLUTION, 100 + i),
            })
            .collect(),
        opacity: OpacityVolume {
            resolution: VOLUME_RESOLUTION,
            max_depth: 1.5,
            codes: (0..VOLUME_RESOLUTION.pow(3))
                .map(|i| (i % 256) as u8)
                .collect(),
        },
    }
}

#[test]
fn a_model_survives_encoding() {
    let m = tiny();
    let bytes = m.encode();
    assert_eq!(
        PreparedModel::decode(&bytes, Path::new("m.bin")).unwrap(),
        m
    );
    // Saved and loaded from a folder; a folder without one has none.
    let dir = tempfile::tempdir().unwrap();
    assert_eq!(PreparedModel::load(dir.path()).unwrap(), None);
    m.save(dir.path()).unwrap();
    assert_eq!(PreparedModel::load(dir.path()).unwrap(), Some(m.clone()));
    assert!(m.check_source(dir.path(), "abc123").is_ok());
    let e = m.check_source(dir.path(), "other").unwrap_err().to_string();
    assert!(e.contains("another model") && e.contains(MODEL_FILE), "{e}");
}

/// A model.bin that is a folder, or a link to a device, is named as not a file: never
/// taken for an atlas baked without its model.
#[test]
fn a_model_that_is_not_a_file_is_named() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join(MODEL_FILE)).unwrap();
    let e = PreparedModel::load(dir.path()).unwrap_err().to_string();
    assert!(
        e.contains(MODEL_FILE) && e.contains("not a regular file"),
        "{e}"
    );
    #[cfg(unix)]
    {
        let linked = tempfile::tempdir().unwrap();
        std::os::unix::fs::symlink("/dev/zero", linked.path().join(MODEL_FILE)).unwrap();
        let e = PreparedModel::load(linked.path()).unwrap_err().to_string();
        assert!(e.contains("not a regular file"), "{e}");
    }
}

/// `bytes` with its header's checksum made right again after an edit of the header.
fn resummed(mut bytes: Vec<u8>) -> Vec<u8> {
    let sum = fnv1a(&bytes[..SUMMED_BYTES]);
    bytes[SUMMED_BYTES..HEADER_BYTES].copy_from_slice(&sum.to_le_bytes());
    bytes
}

fn refused(bytes: &[u8]) -> String {
    PreparedModel::decode(bytes, Path::new("m.bin"))
        .unwrap_err()
        .to_string()
}

#[test]
fn bad_files_are_refused_with_their_cause() {
    let m = tiny();
    let good = m.encode();
    assert!(refused(&good[..5]).contains("not a prepared model"));
    let mut v = good.clone();
    v[8] = 9;
    assert!(refused(&v).contains("version 9"));
    assert!(refused(&good[..HEADER_BYTES - 1]).contains("header"));
    // Truncated arrays.
    let e = refused(&good[..good.len() - 10]);
    assert!(e.contains("inflate"), "{e}");
    // A header changed anywhere but its checksum not: refused, whatever the change.
    let mut changed = good.clone();
    changed[20] ^= 1;
    let e = refused(&changed);
    assert!(e.contains("checksum"), "{e}");
    // The header's counts are checked too (a file written with a wrong count, its checksum
    // right). A header claiming a huge count is refused before anything is allocated.
    let mut huge = good.clone();
    huge[12..16].copy_from_slice(&(u32::MAX / 3 * 3).to_le_bytes());
    let huge = resummed(huge);
    assert!(refused(&huge).contains("cannot hold"), "{}", refused(&huge));
    // Counts that do not make triangles, or disagree with the arrays.
    let mut odd = good.clone();
    odd[16..20].copy_from_slice(&4u32.to_le_bytes());
    let odd = resummed(odd);
    assert!(refused(&odd).contains("whole triangles"));
    let mut branches = good.clone();
    branches[24..28].copy_from_slice(&12u32.to_le_bytes());
    let branches = resummed(branches);
    assert!(refused(&branches).contains("12 branch vertices of LOD 0's 9"));
    let mut more = good.clone();
    more[16..20].copy_from_slice(&6u32.to_le_bytes());
    let more = resummed(more);
    assert!(refused(&more).contains("inflate to"), "{}", refused(&more));
    // A bounding sphere beyond a model's coordinates, or a volume denser than an atlas may
    // record, is named (a radius of 1e30 once drew every crown nearly black).
    let mut far = tiny();
    far.sphere[3] = 1e30;
    let e = refused(&far.encode());
    assert!(e.contains("reaches"), "{e}");
    let mut dense = tiny();
    dense.opacity.max_depth = 1e30;
    let e = refused(&dense.encode());
    assert!(e.contains("opacity depth"), "{e}");
}

#[test]
fn out_of_range_indices_are_refused() {
    type Break = fn(&mut PreparedModel);
    let cases: [(&str, Break); 6] = [
        ("material 5", |m| m.vertices[0].material = 5),
        ("leaf 7", |m| m.vertices[4].element = 7),
        ("branch vertices of", |m| m.branch_vertices = 12),
        ("layer 3", |m| m.materials[1].layer = 3),
        ("ends at vertex 12", |m| m.leaf_end[1] = 12),
        ("not finite", |m| m.vertices[2].pos[1] = f32::NAN),
    ];
    for (cause, break_it) in cases {
        let mut m = tiny();
        break_it(&mut m);
        let e = m.check_indices().unwrap_err();
        assert!(e.contains(cause), "{cause}: {e}");
        // The same through a file (the encoder checks the header's sizes only, among them
        // the branch count: that case is the header's, below).
        if m.branch_vertices <= m.lod_vertices[0] {
            let e = refused(&m.encode());
            assert!(e.contains(cause), "{cause}: {e}");
        }
    }
}
