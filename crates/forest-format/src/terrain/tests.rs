//! Tests of `terrain.rs`.

use super::*;

fn plane(a: f32, b: f32, c: f32) -> Terrain {
    let (nx, nz) = (5u32, 4u32);
    let origin = [-10.0, 3.0];
    let spacing = 2.5;
    let heights = (0..nz)
        .flat_map(|j| {
            (0..nx).map(move |i| {
                a * (origin[0] + i as f32 * spacing) + b * (origin[1] + j as f32 * spacing) + c
            })
        })
        .collect();
    Terrain {
        size: [nx, nz],
        origin,
        spacing,
        heights,
    }
}

#[test]
fn lowest_under_a_disk_is_its_downhill_edge_or_a_sample_inside() {
    // On a plane the minimum is at the circle's downhill point: centre − r·|∇h|.
    let t = plane(0.3, -0.2, 4.0);
    let grad = (0.09f32 + 0.04).sqrt();
    let bound = |r: f32| r * grad * (1.0 - (std::f32::consts::PI / 32.0).cos()) + 1e-4;
    for (x, z, r) in [(-5.0, 6.0, 0.4), (-2.2, 8.1, 1.7), (-8.9, 4.4, 0.05)] {
        let want = t.height(x, z) - r * grad;
        let got = t.lowest_under(x, z, r);
        assert!(
            got >= want - 1e-4 && got <= want + bound(r),
            "{got} against {want}"
        );
    }
    for r in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        assert_eq!(t.lowest_under(-5.0, 6.0, r), t.height(-5.0, 6.0));
    }
    // A pit at one sample, inside the disk but between the circle's points: found.
    let mut pit = plane(0.0, 0.0, 1.0);
    pit.heights[2 * 5 + 2] = -3.0; // sample (2, 2) at x = −5, z = 8
    assert_eq!(pit.lowest_under(-5.3, 8.2, 1.0), -3.0);
    // With the sample outside the disk, only the pit's slopes reach the circle.
    let near = pit.lowest_under(-5.3, 8.2, 0.3);
    assert!(near > -3.0 && near < 1.0, "{near}");
    // Creases along a cell's diagonal (h = |x − z|) and along a grid line (h = |x − 4|),
    // crossed by disks whose circle points alone miss the bottom.
    let field = |h: &dyn Fn(f32, f32) -> f32| Terrain {
        size: [9, 9],
        origin: [0.0, 0.0],
        spacing: 1.0,
        heights: (0..9)
            .flat_map(|j| (0..9).map(move |i| (i as f32, j as f32)))
            .map(|(x, z)| h(x, z))
            .collect(),
    };
    let diagonal = field(&|x, z| (x - z).abs());
    assert!((diagonal.height(4.3, 3.6) - 0.7).abs() < 1e-5);
    assert!(diagonal.lowest_under(4.3, 3.6, 0.6).abs() < 1e-5);
    let line = field(&|x, _| (x - 4.0).abs());
    assert!(line.lowest_under(4.45, 2.3, 0.5).abs() < 1e-5);
    // Past the border the ground drops to the plane, which a foot does not stand on; a
    // huge radius takes the grid's lowest sample, and returns.
    let high = plane(0.0, 0.0, 50.0);
    assert_eq!(high.lowest_under(-9.9, 3.1, 2.0), 50.0);
    let lowest = t.heights.iter().copied().fold(f32::INFINITY, f32::min);
    assert_eq!(t.lowest_under(-5.0, 6.0, 1e30), lowest);
    assert_eq!(t.lowest_under(-5.0, 6.0, f32::MAX), lowest);
    // Independently: no point of the disk lies below the result.
    let hills = Terrain::generate(&TerrainParams::default()).unwrap();
    for k in 0..50 {
        let (x, z, r) = (
            k as f32 * 7.3 - 180.0,
            90.0 - k as f32 * 3.1,
            0.2 + k as f32 * 0.05,
        );
        let lo = hills.lowest_under(x, z, r);
        for a in 0..360 {
            for f in [0.25, 0.5, 0.75, 1.0] {
                let t = (a as f32).to_radians();
                let h = hills.height(x + f * r * t.cos(), z + f * r * t.sin());
                assert!(h >= lo - 0.01 * r, "({x}, {z}) r {r}: {h} below {lo}");
            }
        }
        assert!(lo <= hills.height(x, z));
    }
}

#[test]
fn a_planar_field_is_that_plane_everywhere_on_it() {
    let t = plane(0.3, -0.2, 4.0);
    t.check().unwrap();
    let ([x0, z0], [x1, z1]) = t.bounds();
    assert_eq!((x0, z0, x1, z1), (-10.0, 3.0, 0.0, 10.5));
    for k in 0..200 {
        let x = x0 + (x1 - x0) * ((k * 37) % 101) as f32 / 100.0;
        let z = z0 + (z1 - z0) * ((k * 61) % 103) as f32 / 102.0;
        let want = 0.3 * x - 0.2 * z + 4.0;
        assert!((t.height(x, z) - want).abs() < 1e-4, "({x}, {z})");
        let s = t.slope(x, z);
        assert!((s - (0.09f32 + 0.04).sqrt()).abs() < 1e-5, "slope {s}");
    }
    // Exact on both sides of a cell's diagonal and on its edges.
    let steep = plane(2.0, -1.5, 40.0);
    for (x, z) in [
        (-7.5, 5.5),
        (-7.5 + 1e-4, 5.5),
        (-7.5, 5.5 + 1e-4),
        (0.0, 10.5),
        (-10.0, 3.0),
    ] {
        assert!(
            (steep.slope(x, z) - 2.5).abs() < 1e-5,
            "({x}, {z}): {}",
            steep.slope(x, z)
        );
    }
    // Outside: the flat ground.
    assert_eq!(t.height(-10.5, 5.0), 0.0);
    assert_eq!(t.height(-5.0, 11.0), 0.0);
    assert_eq!(t.slope(20.0, 5.0), 0.0);
}

#[test]
fn cells_split_along_the_diagonal_from_their_first_corner() {
    // One cell, corner (1, 0) raised: the triangle (00, 10, 11) carries it, the other
    // triangle (00, 11, 01) stays flat.
    let t = Terrain {
        size: [2, 2],
        origin: [0.0, 0.0],
        spacing: 1.0,
        heights: vec![0.0, 4.0, 0.0, 0.0],
    };
    assert_eq!(t.height(1.0, 0.0), 4.0);
    assert!((t.height(0.75, 0.25) - 2.0).abs() < 1e-6);
    assert!((t.height(0.5, 0.5)).abs() < 1e-6);
    assert_eq!(t.height(0.25, 0.75), 0.0);
    // Samples are interpolated exactly at the grid's points.
    let p = plane(1.0, 2.0, 0.0);
    for j in 0..4 {
        for i in 0..5 {
            let (x, z) = (-10.0 + i as f32 * 2.5, 3.0 + j as f32 * 2.5);
            assert_eq!(p.height(x, z), p.heights[j * 5 + i]);
        }
    }
}

#[test]
fn generated_hills_are_seeded_bounded_and_meet_the_plain() {
    let p = TerrainParams {
        half_extent: 400.0,
        spacing: 10.0,
        relief: 60.0,
        hill_size: 300.0,
        fade: 0.125,
        seed: 3,
    };
    let a = Terrain::generate(&p).unwrap();
    assert_eq!(a, Terrain::generate(&p).unwrap());
    assert_ne!(
        a,
        Terrain::generate(&TerrainParams {
            seed: 4,
            ..p.clone()
        })
        .unwrap()
    );
    assert_eq!(a.size, [81, 81]);
    let (lo, hi) = a.height_range();
    assert!(lo >= 0.0 && hi <= 60.0, "{lo} {hi}");
    assert!(hi - lo > 15.0, "hills, not a plain: {lo}..{hi}");
    // The border is at the plain's height.
    for k in 0..81 {
        assert_eq!(a.heights[k], 0.0);
        assert_eq!(a.heights[80 * 81 + k], 0.0);
        assert_eq!(a.heights[k * 81], 0.0);
    }
    let err = Terrain::generate(&TerrainParams {
        spacing: 0.1,
        ..p.clone()
    })
    .unwrap_err();
    assert!(err.contains("raise the spacing"), "{err}");
    assert!(
        Terrain::generate(&TerrainParams { relief: -1.0, ..p })
            .unwrap_err()
            .contains("relief")
    );
}

#[test]
fn the_binary_form_round_trips_and_bad_grids_are_named() {
    let t = plane(0.1, 0.2, 1.0);
    let mut bytes = Vec::new();
    t.write_to(&mut bytes);
    let mut at = 0;
    let back = Terrain::read_from(|n| {
        let s = bytes.get(at..at + n).ok_or("truncated")?.to_vec();
        at += n;
        Ok(s)
    })
    .unwrap();
    assert_eq!(back, t);
    let mut bad = t.clone();
    bad.heights[7] = f32::NAN;
    assert!(bad.check().unwrap_err().contains("sample (2, 1)"));
    let mut bad = t.clone();
    bad.heights.pop();
    assert!(bad.check().unwrap_err().contains("19 heights"));
    let mut bad = t.clone();
    bad.size = [1, 20];
    assert!(bad.check().unwrap_err().contains("1×20"));
    let mut bad = t.clone();
    bad.origin[1] = f32::NAN;
    assert!(bad.check().unwrap_err().contains("origin"));
    // A grid centred on the origin is measured by its own reach, not its span added on.
    let wide = Terrain {
        size: [2, 2],
        origin: [-4.0e6, -4.0e6],
        spacing: 8.0e6,
        heights: vec![0.0; 4],
    };
    wide.check().unwrap();
    let far = Terrain {
        origin: [-4.0e6, 3.0e6],
        ..wide
    };
    assert!(far.check().unwrap_err().contains("farther than"));
}

fn write_png16(path: &Path, w: u32, h: u32, f: impl Fn(u32, u32) -> u16) {
    let img = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(w, h, |x, y| {
        image::Luma([f(x, y)])
    });
    img.save(path).unwrap();
}

#[test]
fn height_images_load_and_malformed_ones_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("h.png");
    write_png16(&png, 3, 2, |x, y| (x * 1000 + y * 30000) as u16);
    let t = Terrain::from_image(&png, 4.0, 65.535).unwrap();
    assert_eq!(t.size, [3, 2]);
    assert_eq!(t.origin, [-4.0, -2.0]);
    assert!((t.heights[1] - 1.0).abs() < 1e-5);
    assert!((t.heights[3] - 30.0).abs() < 1e-4);
    assert!((t.height(0.0, 2.0) - 31.0).abs() < 1e-4);

    // EXR height fields, with the feature that reads them (the runtime's build refuses
    // them by name).
    #[cfg(feature = "terrain-exr")]
    {
        let exr = dir.path().join("h.exr");
        let img = image::ImageBuffer::<image::Rgb<f32>, Vec<f32>>::from_fn(4, 3, |x, y| {
            image::Rgb([x as f32 - 0.5 * y as f32, 0.0, 0.0])
        });
        image::DynamicImage::ImageRgb32F(img).save(&exr).unwrap();
        let t = Terrain::from_image(&exr, 1.0, 0.0).unwrap();
        assert_eq!(t.size, [4, 3]);
        assert_eq!(t.heights[4 * 2 + 3], 2.0);

        // A single-channel EXR (the usual height-map export), half floats, channel "Y".
        let single = dir.path().join("y.exr");
        {
            use exr::prelude::*;
            let samples: Vec<f16> = (0..15).map(|k| f16::from_f32(k as f32 * 0.5)).collect();
            let channel = AnyChannel::new("Y", FlatSamples::F16(samples));
            let layer = Layer::new(
                (5, 3),
                LayerAttributes::named("heights"),
                Encoding::FAST_LOSSLESS,
                AnyChannels::sort(SmallVec::from_vec(vec![channel])),
            );
            Image::from_layer(layer).write().to_file(&single).unwrap();
        }
        let t = Terrain::from_image(&single, 2.0, 0.0).unwrap();
        assert_eq!(t.size, [5, 3]);
        assert_eq!(t.heights[14], 7.0);
    }
    #[cfg(not(feature = "terrain-exr"))]
    {
        let exr = dir.path().join("h.exr");
        std::fs::write(&exr, b"v/1\x01").unwrap();
        let e = Terrain::from_image(&exr, 1.0, 0.0).unwrap_err().to_string();
        assert!(e.contains("terrain-exr"), "{e}");
    }

    let err = |p: &Path| Terrain::from_image(p, 1.0, 10.0).unwrap_err().to_string();
    let eight = dir.path().join("8bit.png");
    image::GrayImage::from_pixel(4, 4, image::Luma([9]))
        .save(&eight)
        .unwrap();
    assert!(err(&eight).contains("16-bit greyscale"), "{}", err(&eight));
    let rgb = dir.path().join("rgb.png");
    image::RgbImage::from_pixel(4, 4, image::Rgb([9, 9, 9]))
        .save(&rgb)
        .unwrap();
    assert!(err(&rgb).contains("3 channel"), "{}", err(&rgb));
    let tiny = dir.path().join("tiny.png");
    write_png16(&tiny, 1, 5, |_, _| 0);
    assert!(err(&tiny).contains("1×5"), "{}", err(&tiny));
    let junk = dir.path().join("junk.png");
    std::fs::write(&junk, b"not a png at all").unwrap();
    assert!(err(&junk).contains("junk.png"), "{}", err(&junk));
    let cut = dir.path().join("cut.png");
    let full = std::fs::read(&png).unwrap();
    std::fs::write(&cut, &full[..full.len() / 2]).unwrap();
    assert!(err(&cut).contains("cut.png"), "{}", err(&cut));
    #[cfg(feature = "terrain-exr")]
    {
        let nan = dir.path().join("nan.exr");
        let img = image::ImageBuffer::<image::Rgb<f32>, Vec<f32>>::from_fn(2, 2, |x, _| {
            image::Rgb([if x == 1 { f32::NAN } else { 0.0 }, 0.0, 0.0])
        });
        image::DynamicImage::ImageRgb32F(img).save(&nan).unwrap();
        assert!(err(&nan).contains("sample (1, 0)"), "{}", err(&nan));
    }
    let tif = dir.path().join("h.tif");
    std::fs::write(&tif, b"x").unwrap();
    assert!(err(&tif).contains(".exr"), "{}", err(&tif));
    assert!(
        Terrain::from_image(&png, 0.0, 1.0)
            .unwrap_err()
            .to_string()
            .contains("spacing")
    );
}
