//! Bake tests with answers known in advance.

use std::path::{Path, PathBuf};

use forest_bake::{Mesh, ldi, trace::Scene};
use forest_format::shading::{hemi_oct_decode, srgb_decode, srgb_encode};
use forest_format::slab::{DirectionFrame, Sphere};
use forest_format::{Atlas, BakeParams, ColourEncoding};
use glam::Vec3;

/// Write a 1×1-metre-per-unit quad model: a horizontal square `[-1,1]²` at height 0, its
/// texture opaque (white) for u ≥ 0.5 and transparent for u < 0.5.
fn alpha_quad(dir: &Path) -> PathBuf {
    let tex = image::RgbaImage::from_fn(2, 2, |x, _| {
        if x == 1 {
            image::Rgba([255, 255, 255, 255])
        } else {
            image::Rgba([255, 0, 0, 0])
        }
    });
    tex.save(dir.join("card.png")).unwrap();
    std::fs::write(
        dir.join("quad.mtl"),
        "newmtl card\nKd 0.5 0.5 0.5\nmap_Kd card.png\nmap_d card.png\n",
    )
    .unwrap();
    let obj = dir.join("quad.obj");
    std::fs::write(
        &obj,
        "mtllib quad.mtl\n\
         v -1 0 1\nv 1 0 1\nv 1 0 -1\nv -1 0 -1\n\
         vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
         vn 0 1 0\n\
         usemtl card\nf 1/1/1 2/2/1 3/3/1 4/4/1\n",
    )
    .unwrap();
    obj
}

#[test]
fn alpha_textured_quad_seen_head_on_covers_exactly_the_expected_pixels() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = Mesh::load(&alpha_quad(dir.path())).unwrap();
    assert_eq!(mesh.tris.len(), 2, "the quad is triangulated");
    let scene = Scene::new(&mesh);
    // The zenith view of a sphere of radius 2: 32 pixels span [-2, 2], 0.125 m each, so the
    // quad covers pixels 8..24 and its opaque half (x ≥ 0) pixels 16..24 in x.
    let sphere = Sphere {
        center: Vec3::ZERO,
        radius: 2.0,
    };
    let frames = [DirectionFrame::new(Vec3::Y)];
    let setup = ldi::SlabSetup {
        sphere,
        frames: &frames,
        slabs: 1,
        resolution: 32,
        spp: 4,
    };
    let img = ldi::trace_layers(
        &scene,
        &forest_bake::sky::triangle_sky(&scene),
        &setup,
        &|_, _| {},
    );
    // Expected colour: the albedo, Kd 0.5 (sRGB) × white texture; no light is baked.
    let albedo = Vec3::splat(srgb_decode(0.5));
    let want = albedo
        .to_array()
        .map(|c| (srgb_encode(c) * 255.0).round() as u8);
    // Expected surface: the normal +Y is the frame's pole (code ½, ½), an isolated card sees
    // all of its sky, and a leaf material's translucency.
    let tau = forest_format::shading::LEAF_TRANSLUCENCY;
    let want_surface = [128u8, 128, 255, (tau * 255.0).round() as u8];
    let frame = &frames[0];
    let mut covered = 0;
    for y in 0..32usize {
        for x in 0..32usize {
            let i = y * 32 + x;
            let px = &img.rgba[i * 4..i * 4 + 4];
            // Pixel centre in object space: image x runs along `right`, y down along `up`.
            let p = sphere.image_to_object(
                frame,
                (x as f32 + 0.5) / 32.0,
                (y as f32 + 0.5) / 32.0,
                0.5,
            );
            let inside_quad = p.x.abs() < 1.0 && p.z.abs() < 1.0;
            let u = 0.5 * (p.x + 1.0);
            if inside_quad && u >= 0.5 {
                covered += 1;
                assert_eq!(px[3], 255, "pixel ({x},{y}) at {p} is covered");
                for c in 0..3 {
                    assert!(
                        px[c].abs_diff(want[c]) <= 1,
                        "pixel ({x},{y}): {px:?} vs {want:?}"
                    );
                }
                assert_eq!(&img.surface[i * 4..i * 4 + 4], &want_surface, "({x},{y})");
                assert!((img.depth[i] - 0.5).abs() < 1e-6, "depth {}", img.depth[i]);
            } else {
                assert_eq!(px, &[0, 0, 0, 0], "pixel ({x},{y}) at {p} is blank");
            }
        }
    }
    assert_eq!(covered, 8 * 16);
}

#[test]
fn texel_normals_of_tilted_cards_match_the_geometry() {
    // A square tilted by 30° about +X, seen from the zenith and from +Z: the decoded normal of
    // every covered texel, in the direction's frame, is the card's normal turned towards the
    // viewer.
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("tilted.obj");
    let (s, c) = (30f32.to_radians().sin(), 30f32.to_radians().cos());
    std::fs::write(
        &obj,
        format!(
            "v -1 {y0} {z0}\nv 1 {y0} {z0}\nv 1 {y1} {z1}\nv -1 {y1} {z1}\nf 1 2 3 4\n",
            y0 = -s,
            z0 = c,
            y1 = s,
            z1 = -c
        ),
    )
    .unwrap();
    let mesh = Mesh::load(&obj).unwrap();
    let scene = Scene::new(&mesh);
    let normal = Vec3::new(0.0, c, s);
    let sphere = Sphere {
        center: Vec3::ZERO,
        radius: 1.5,
    };
    for view in [Vec3::Y, Vec3::Z, Vec3::new(0.3, 0.8, 0.5).normalize()] {
        let frames = [DirectionFrame::new(view)];
        let setup = ldi::SlabSetup {
            sphere,
            frames: &frames,
            slabs: 1,
            resolution: 16,
            spp: 1,
        };
        let img = ldi::trace_layers(
            &scene,
            &forest_bake::sky::triangle_sky(&scene),
            &setup,
            &|_, _| {},
        );
        let f = &frames[0];
        let facing = if normal.dot(view) >= 0.0 {
            normal
        } else {
            -normal
        };
        let want = Vec3::new(facing.dot(f.right), facing.dot(f.up), facing.dot(f.dir));
        let mut covered = 0;
        for p in img.surface.chunks_exact(4).zip(img.rgba.chunks_exact(4)) {
            let (g, a) = (p.0, p.1[3]);
            if a == 0 {
                continue;
            }
            covered += 1;
            let e = glam::Vec2::new(f32::from(g[0]), f32::from(g[1])) / f32::from(a);
            let n = hemi_oct_decode(e);
            assert!(n.dot(want) > 0.999, "view {view}: {n} vs {want}");
            // An isolated card sees all of its sky.
            assert_eq!(g[2], a);
        }
        assert!(covered > 20, "view {view}: {covered} texels");
    }
}

#[test]
fn the_piece_search_finds_the_ray_tracers_hits() {
    // Visiting each piece's samples must give the slab images that tracing every sample's ray
    // through the BVH gives: same hits, so byte-identical colour and surface and equal depth.
    // Alpha-tested leaves (oak), several slabs, the zenith and nadir (axis-aligned views), and
    // a sample count that shrinks the tiles.
    let trees = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/trees");
    for (model, slabs, resolution, spp) in [("oak/oak.obj", 2, 64, 4), ("bush/bush.obj", 3, 32, 64)]
    {
        let mesh = Mesh::load(&trees.join(model)).unwrap();
        let scene = Scene::new(&mesh);
        let sky = forest_bake::sky::triangle_sky(&scene);
        let frames: Vec<_> = forest_format::directions::sampling_directions(3, 2)
            .into_iter()
            .map(DirectionFrame::new)
            .collect();
        let setup = ldi::SlabSetup {
            sphere: forest_bake::bounding_sphere(&mesh),
            frames: &frames,
            slabs,
            resolution,
            spp,
        };
        assert!(ldi::tile_side(resolution, spp, slabs) < resolution);
        let by = |search| ldi::trace_layers_by(search, &scene, &sky, &setup, &|_, _| {});
        let (pieces, rays) = (by(ldi::HitSearch::Pieces), by(ldi::HitSearch::Rays));
        let covered = rays.rgba.chunks_exact(4).filter(|p| p[3] > 0).count();
        assert!(
            covered > rays.rgba.len() / 4 / 20,
            "{model}: {covered} covered texels"
        );
        let differ = pieces
            .rgba
            .chunks_exact(4)
            .zip(rays.rgba.chunks_exact(4))
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(differ, 0, "{model}: {differ} texels' colour differs");
        assert!(pieces.surface == rays.surface, "{model}: surface differs");
        assert!(pieces.depth == rays.depth, "{model}: depth differs");
    }
}

#[test]
fn sky_visibility_is_zero_inside_a_closed_box_and_one_outside() {
    // A cube: each face's inner side sees only the cube, its outer side the whole sky.
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("cube.obj");
    std::fs::write(
        &obj,
        "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
         f 1 4 3 2\nf 5 6 7 8\nf 1 5 8 4\nf 2 3 7 6\nf 1 2 6 5\nf 4 8 7 3\n",
    )
    .unwrap();
    let mesh = Mesh::load(&obj).unwrap();
    let scene = Scene::new(&mesh);
    let sky = forest_bake::sky::triangle_sky(&scene);
    assert_eq!(sky.len(), 12);
    for (t, s) in scene.tris.iter().zip(&sky) {
        let centre = (t.p[0] + t.p[1] + t.p[2]) / 3.0;
        let front = forest_bake::sky::front_normal(t);
        // The side facing the cube's centre is the inner one.
        let (inner, outer) = if front.dot(centre) < 0.0 {
            (s[0], s[1])
        } else {
            (s[1], s[0])
        };
        assert_eq!(inner, [0.0; 3], "inner side of {t:?}");
        assert_eq!(outer, [1.0; 3], "outer side of {t:?}");
    }
}

fn small_params() -> BakeParams {
    BakeParams {
        directions: 5,
        resolution: 64,
        min_quad: 4,
        spp: 2,
        ..BakeParams::default()
    }
}

fn bush() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/trees/bush/bush.obj")
}

#[test]
fn save_then_load_gives_identical_data() {
    let out = forest_bake::bake_file(&bush(), &small_params(), &|_, _| {}).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bush.atlas");
    out.atlas.save(&path).unwrap();
    let back = Atlas::load(&path).unwrap();
    assert_eq!(back, out.atlas);
    assert!(back.manifest.node_count > 0);
    assert_eq!(back.manifest.levels, 5);
    // Saving over an existing atlas replaces it and leaves no temporary folders.
    out.atlas.save(&path).unwrap();
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("bush.atlas")]);
}

#[test]
fn the_same_input_gives_a_byte_identical_atlas() {
    let dir = tempfile::tempdir().unwrap();
    let mut files = Vec::new();
    for name in ["a.atlas", "b.atlas"] {
        let out = forest_bake::bake_file(&bush(), &small_params(), &|_, _| {}).unwrap();
        let path = dir.path().join(name);
        out.atlas.save(&path).unwrap();
        let mut listing: Vec<(String, Vec<u8>)> = std::fs::read_dir(&path)
            .unwrap()
            .map(|e| {
                let e = e.unwrap();
                (
                    e.file_name().to_string_lossy().into(),
                    std::fs::read(e.path()).unwrap(),
                )
            })
            .collect();
        listing.sort();
        files.push(listing);
    }
    assert_eq!(files[0].len(), 6);
    assert_eq!(files[0], files[1]);
}

#[test]
fn jpeg_colour_decodes_close_to_the_lossless_bake() {
    // At a realistic resolution: JPEG on 64-pixel images is all edges.
    let jpeg = BakeParams {
        directions: 2,
        resolution: 256,
        ..small_params()
    };
    let lossless = BakeParams {
        colour: ColourEncoding::Png,
        ..jpeg
    };
    let a = forest_bake::bake_file(&bush(), &lossless, &|_, _| {}).unwrap();
    let b = forest_bake::bake_file(&bush(), &jpeg, &|_, _| {}).unwrap();
    let dir = Path::new("unused");
    let la = a.atlas.decode_layers(dir).unwrap();
    let lb = b.atlas.decode_layers(dir).unwrap();
    // Lossless is exact (the clamp to alpha changes nothing in a valid bake).
    assert_eq!(la.rgba, a.images.rgba);
    // JPEG: PSNR over fully covered pixels (edges against the black, premultiplied
    // background ring most); alpha is lossless.
    let (mut se, mut bias, mut n) = (0f64, [0f64; 3], 0u64);
    for (p, q) in la.rgba.chunks_exact(4).zip(lb.rgba.chunks_exact(4)) {
        assert_eq!(p[3], q[3]);
        if p[3] == 255 {
            for c in 0..3 {
                let d = f64::from(q[c]) - f64::from(p[c]);
                se += d * d;
                bias[c] += d;
            }
            n += 1;
        }
    }
    // Foliage is all high frequencies: q80 JPEG measures about 25 dB here (the loss is masked
    // by the texture; the benchmarks measure it with FLIP). A decoder that shifts colours (as
    // zune-jpeg did with optimised Huffman tables) gives a large bias.
    let psnr = 10.0 * (255f64.powi(2) / (se / (3 * n) as f64)).log10();
    let bias = bias.map(|b| b / n as f64);
    eprintln!("JPEG colour PSNR {psnr:.1} dB, bias {bias:.2?}");
    assert!(psnr > 20.0, "JPEG colour PSNR {psnr:.1} dB");
    // Noise clipped at 0 biases dark channels upwards by a few levels; a hue shift is tens.
    for (c, b) in bias.iter().enumerate() {
        assert!(b.abs() < 8.0, "channel {c} biased by {b:.2}");
    }
}

#[test]
fn the_loader_says_what_is_wrong() {
    let out = forest_bake::bake_file(&bush(), &small_params(), &|_, _| {}).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.atlas");
    let reset = || {
        out.atlas.save(&path).unwrap();
    };
    let err = |path: &Path| Atlas::load(path).unwrap_err().to_string();

    // (Version, truncated files and missing files: the format crate's own tests.) On a real
    // bake: a level count that disagrees with the parameters, an alpha mosaic of another size.
    reset();
    let manifest = path.join("manifest.json");
    let text = std::fs::read_to_string(&manifest).unwrap();
    std::fs::write(&manifest, text.replace("\"levels\": 5", "\"levels\": 6")).unwrap();
    assert!(err(&path).contains("levels = 6"), "{}", err(&path));

    reset();
    let small = image::GrayImage::new(8, 8);
    small.save(path.join("alpha.png")).unwrap();
    assert!(err(&path).contains("expected"), "{}", err(&path));
}
