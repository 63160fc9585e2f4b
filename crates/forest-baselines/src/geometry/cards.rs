//! Leaf cards cut to the part of their texture that can pass the alpha test as the GPU
//! samples it.
//!
//! A leaf card is a quad spanning its whole texture, and most of that texture is transparent
//! (the bundled leaf textures pass the 0.5 alpha test on 15–26 % of their texels): every
//! fragment of the rest is shaded and discarded. Before upload, each card is cut to the
//! smallest quadrilateral ([`forest_format::cutout::enclosing_quad`], inside the card) around
//! the convex hull of the texels that can pass ([`passable_hull`]): two triangles still, so
//! the vertex count, the leaf table and the LOD counts are unchanged, and what is left of the
//! card is 46–81 % of it on the bundled textures.
//!
//! The hull covers the finest [`CUT_LEVELS`] mip levels, as the sampler filters them. Coarser
//! levels (a card under about 8 pixels across) spread the leaves' coverage past their shape;
//! the cut trims that spread, which the reference (finest level) never shows. The new corners
//! are lit at their own positions (the crown's self-shadowing is evaluated per vertex), so
//! the shading within a card is sampled at other points than before.

use forest_format::cutout::{Polygon, clip_convex, convex_hull, enclosing_quad, simplify_outward};
use forest_format::model::{NONE, PreparedModel, RefVertex};
use glam::{Vec2, Vec3};

use super::textures::ALPHA_TEST_BYTE;

/// Mip levels, finest first, whose passing texels the cut keeps (levels 0–6: down to 8×8
/// texels of a 512-texel layer).
pub(super) const CUT_LEVELS: u32 = 7;

/// The quadrilateral each texture layer of `model` cuts its cards to (`None`: cards on it stay
/// whole): for the layers of alpha-tested materials, [`enclosing_quad`] of [`passable_hull`]
/// over the layer's mip chain as uploaded, `chains[i]` ([`super::textures::mip_chain`] of
/// layer `i`).
pub(super) fn card_quads(
    model: &PreparedModel,
    chains: &[super::textures::MipChain],
) -> Vec<Option<[Vec2; 4]>> {
    model
        .layers
        .iter()
        .zip(chains)
        .enumerate()
        .map(|(i, (img, (chain, _)))| {
            let tested = model
                .materials
                .iter()
                .any(|m| m.alpha_tested && m.layer as usize == i);
            if !tested || img.width() != img.height() || img.width() == 0 {
                return None;
            }
            // Simplifying outward can carry a corner past the card's edge; the card's square
            // clips it back (the clipped hull still holds every passing texel inside it).
            let square = [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y];
            passable_hull(chain, img.width(), CUT_LEVELS, HULL_VERTICES)
                .and_then(|h| enclosing_quad(&clip_convex(&h, &square)))
        })
        .collect()
}

/// Most corners [`passable_hull`] keeps for [`card_quads`] (the quad search's candidate lines
/// grow with them).
const HULL_VERTICES: usize = 24;

/// The convex hull of every texture point (`uv`, OBJ convention: `v = 0` is the bottom row)
/// where a sample of any of the first `levels` levels of mip chain `chain` (RGBA8 levels of a
/// square texture of side `side`, level 0 first) can pass the alpha test, simplified outward
/// to at most `max_vertices`. A bilinear sample is a convex combination of the four texels
/// whose centres lie within one texel of it, so it can pass only within half a texel of a
/// passing texel; the sampler repeats, so that half texel wraps around the edges. Trilinear
/// filtering blends two levels' samples, so it can pass only where one of them can. `None`
/// when no texel of those levels passes.
pub(super) fn passable_hull(
    chain: &[u8],
    side: u32,
    levels: u32,
    max_vertices: usize,
) -> Option<Polygon> {
    let mut points = Vec::new();
    let mut offset = 0usize;
    for (s, _) in super::textures::mip_sizes(side, side).take(levels as usize) {
        let s = s as usize;
        let bytes = s * s * 4;
        let Some(data) = chain.get(offset..offset + bytes) else {
            break;
        };
        offset += bytes;
        let pass = |x: usize, y: usize| data[(y * s + x) * 4 + 3] >= ALPHA_TEST_BYTE;
        let sf = s as f32;
        for y in 0..s {
            let Some(first) = (0..s).find(|&x| pass(x, y)) else {
                continue;
            };
            let last = (first..s).rev().find(|&x| pass(x, y)).unwrap_or(first);
            // Texel units: the two texels grown by half a texel, wrapped into [0, s]².
            let (x0, x1) = (first as f32 - 0.5, last as f32 + 1.5);
            let (y0, y1) = (y as f32 - 0.5, y as f32 + 1.5);
            for dy in [-sf, 0.0, sf] {
                for dx in [-sf, 0.0, sf] {
                    let (ax, bx) = ((x0 + dx).max(0.0), (x1 + dx).min(sf));
                    let (ay, by) = ((y0 + dy).max(0.0), (y1 + dy).min(sf));
                    if ax >= bx || ay >= by {
                        continue;
                    }
                    for (px, py) in [(ax, ay), (bx, ay), (ax, by), (bx, by)] {
                        points.push(glam::Vec2::new(px / sf, 1.0 - py / sf));
                    }
                }
            }
        }
    }
    if points.is_empty() {
        return None;
    }
    Some(simplify_outward(convex_hull(points), max_vertices))
}

/// `model` with every leaf card of an alpha-tested, textured material cut to `quads[layer]`
/// (one per texture layer; `None`: that layer's cards stay whole). A card is two consecutive
/// triangles of one material and leaf that together span the whole texture, their corners
/// at texture coordinates (0,0), (1,0), (0,1), (1,1), on a parallelogram (within 10⁻³ of its
/// size). Its two triangles become the quad's two: the vertex count, the leaf table and the
/// LOD counts are unchanged. Each new corner takes what the rasteriser interpolated there over
/// the card (position, normal, sky visibility) and the quad's texture coordinates, so every
/// fragment the quad shades lies on the card at the same position and texture point. Values
/// that are not affine over the card (per-corner sky visibility or normals) now vary linearly
/// between the new corners instead of over the card's own two triangles, and the vertex-lit
/// sun visibility is evaluated at the new corners. Two triangles that do not tile the card
/// (meeting along a diagonal) and pairs across a LOD's end stay as they are, as does
/// anything else. Returns the model and the number of cards cut.
pub(super) fn cut_cards(
    model: &PreparedModel,
    quads: &[Option<[Vec2; 4]>],
) -> (PreparedModel, usize) {
    let quad_of = |material: u32| -> Option<&[Vec2; 4]> {
        let m = model.materials.get(material as usize)?;
        if !m.alpha_tested || m.layer == NONE {
            return None;
        }
        quads.get(m.layer as usize)?.as_ref()
    };
    let v = &model.vertices;
    let [l0, l1, _] = model.lod_vertices.map(|n| n as usize);
    let lod_ends = [l0, l0 + l1];
    let mut vertices = Vec::with_capacity(v.len());
    let mut cut = 0;
    let mut i = 0;
    while i + 3 <= v.len() {
        let crosses = lod_ends.iter().any(|&e| i < e && e < i + 6);
        let pair = v.get(i..i + 6).filter(|p| {
            !crosses
                && (1..6).all(|k| p[k].material == p[0].material && p[k].element == p[0].element)
        });
        if let Some(pair) = pair
            && let Some(quad) = quad_of(pair[0].material)
            && let Some(card) = card(pair)
        {
            let corners = quad.map(|q| at(pair, q));
            let order = if card {
                [0, 1, 2, 0, 2, 3]
            } else {
                [0, 2, 1, 0, 3, 2]
            };
            vertices.extend(order.map(|k| corners[k]));
            cut += 1;
            i += 6;
        } else {
            vertices.extend_from_slice(&v[i..i + 3]);
            i += 3;
        }
    }
    (
        PreparedModel {
            vertices,
            ..model.clone()
        },
        cut,
    )
}

/// Whether two triangles (six vertices) form a whole-texture card: `Some(winding)`, true when
/// the first triangle turns counter-clockwise in texture space.
fn card(pair: &[RefVertex]) -> Option<bool> {
    let mut corner: [Option<Vec3>; 4] = [None; 4];
    // Corners each triangle has, as bits.
    let mut has = [0u8; 2];
    for (n, v) in pair.iter().enumerate() {
        let k = match v.uv {
            [0.0, 0.0] => 0,
            [1.0, 0.0] => 1,
            [0.0, 1.0] => 2,
            [1.0, 1.0] => 3,
            _ => return None,
        };
        has[n / 3] |= 1 << k;
        let p = Vec3::from(v.pos);
        match corner[k] {
            Some(q) if q != p => return None,
            _ => corner[k] = Some(p),
        }
    }
    let [Some(p00), Some(p10), Some(p01), Some(p11)] = corner else {
        return None;
    };
    let (eu, ev) = (p10 - p00, p01 - p00);
    let size = eu.length() + ev.length();
    if !size.is_finite() || size <= 0.0 || (p00 + eu + ev - p11).length() > 1e-3 * size {
        return None;
    }
    let uv = |k: usize| Vec2::from(pair[k].uv);
    // The two tile the square: three corners each, the corners they lack opposite (0 and 3,
    // or 1 and 2), so that they meet along a diagonal without overlapping.
    let lacks = has.map(|h| {
        if h.count_ones() == 3 {
            (!h & 0xf).trailing_zeros()
        } else {
            9
        }
    });
    if lacks[0] + lacks[1] != 3 {
        return None;
    }
    Some((uv(1) - uv(0)).perp_dot(uv(2) - uv(0)) > 0.0)
}

/// The vertex at texture point `q` of a card (two triangles, six vertices): interpolated over
/// the triangle that holds `q`, as the rasteriser interpolates.
fn at(pair: &[RefVertex], q: Vec2) -> RefVertex {
    let mut best = (f32::MIN, Vec2::ZERO, 0);
    for t in [0, 3] {
        let uv = |k: usize| Vec2::from(pair[t + k].uv);
        let (e1, e2, d) = (uv(1) - uv(0), uv(2) - uv(0), q - uv(0));
        let det = e1.perp_dot(e2);
        if det.abs() < 1e-12 {
            continue;
        }
        let b = Vec2::new(d.perp_dot(e2) / det, e1.perp_dot(d) / det);
        // The triangle q lies most inside of (its smallest barycentric the largest).
        let inside = b.x.min(b.y).min(1.0 - b.x - b.y);
        if inside > best.0 {
            best = (inside, b, t);
        }
    }
    let (_, b, t) = best;
    let mut out = interpolate(&pair[t..t + 3], b);
    out.uv = q.to_array();
    out
}

/// The vertex at barycentric `(b1, b2)` of triangle `t`, each attribute interpolated as the
/// rasteriser does; material and leaf copied.
fn interpolate(t: &[RefVertex], b: Vec2) -> RefVertex {
    let w = [1.0 - b.x - b.y, b.x, b.y];
    let mix3 = |f: fn(&RefVertex) -> [f32; 3]| {
        (0..3)
            .map(|i| Vec3::from(f(&t[i])) * w[i])
            .sum::<Vec3>()
            .to_array()
    };
    let mix = |f: fn(&RefVertex) -> f32| (0..3).map(|i| f(&t[i]) * w[i]).sum::<f32>();
    RefVertex {
        pos: mix3(|v| v.pos),
        sky_front: mix(|v| v.sky_front).clamp(0.0, 1.0),
        normal: mix3(|v| v.normal),
        material: t[0].material,
        uv: [mix(|v| v.uv[0]), mix(|v| v.uv[1])],
        element: t[0].element,
        sky_back: mix(|v| v.sky_back).clamp(0.0, 1.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use forest_format::model::ModelMaterial;

    fn contains(poly: &[Vec2], q: Vec2) -> bool {
        (0..poly.len())
            .all(|i| (poly[(i + 1) % poly.len()] - poly[i]).perp_dot(q - poly[i]) >= -1e-6)
    }

    fn area(p: &[Vec2]) -> f32 {
        (0..p.len())
            .map(|i| p[i].perp_dot(p[(i + 1) % p.len()]))
            .sum::<f32>()
            * 0.5
    }

    /// A chain of one 4×4 level with the given texels opaque.
    fn level(opaque: &[(usize, usize)]) -> Vec<u8> {
        let mut data = vec![0u8; 4 * 4 * 4];
        for &(x, y) in opaque {
            data[(y * 4 + x) * 4 + 3] = 255;
        }
        data
    }

    #[test]
    fn the_passable_hull_is_the_passing_texels_grown_by_half_a_texel_and_wrapped() {
        // Texel (1, 2): u over [0.5, 2.5]/4, rows 2 ± ½ from the top: v over [0.125, 0.625].
        let h = passable_hull(&level(&[(1, 2)]), 4, 1, 8).unwrap();
        assert!((area(&h) - 0.25).abs() < 1e-6, "{h:?}");
        assert!(contains(&h, Vec2::new(0.13, 0.13)) && contains(&h, Vec2::new(0.62, 0.62)));
        assert!(!contains(&h, Vec2::new(0.7, 0.3)));
        // A corner texel's half texel wraps around both edges (the sampler repeats).
        let h = passable_hull(&level(&[(0, 0)]), 4, 1, 8).unwrap();
        assert!(contains(&h, Vec2::new(0.95, 0.05)), "{h:?}");
        assert!(passable_hull(&level(&[]), 4, 1, 8).is_none());
        // Levels past the chain's end are ignored.
        assert!(passable_hull(&level(&[(1, 2)]), 4, 5, 8).is_some());
    }

    fn vertex(pos: [f32; 3], uv: [f32; 2], sky: f32, material: u32) -> RefVertex {
        RefVertex {
            pos,
            sky_front: sky,
            normal: [0.0, 0.0, 1.0],
            material,
            uv,
            element: 0,
            sky_back: 1.0 - sky,
        }
    }

    #[test]
    fn a_card_becomes_its_quad_and_everything_else_is_copied() {
        // A card on the parallelogram p(u, v) = o + u·a + v·b, its sky visibility affine in
        // (u, v) so that the interpolation is known everywhere.
        let (o, a, b) = (
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(2.0, 0.0, 0.5),
            Vec3::new(0.3, 1.0, 0.0),
        );
        let at = |u: f32, v: f32| {
            vertex(
                (o + a * u + b * v).to_array(),
                [u, v],
                0.2 + 0.3 * u + 0.4 * v,
                1,
            )
        };
        let bark = vertex([0.0; 3], [0.5, 0.5], 0.5, 0);
        let lone = [at(0.0, 0.0), at(1.0, 0.0), at(0.0, 1.0)];
        let mut vertices = vec![bark, bark, bark];
        vertices.extend([at(0.0, 0.0), at(1.0, 0.0), at(1.0, 1.0)]);
        vertices.extend([at(0.0, 0.0), at(1.0, 1.0), at(0.0, 1.0)]);
        vertices.extend(lone);
        let model = PreparedModel {
            vertices: vertices.clone(),
            lod_vertices: [vertices.len() as u32, 0, 0],
            materials: vec![
                ModelMaterial {
                    kd: [1.0; 4],
                    layer: NONE,
                    alpha_tested: false,
                },
                ModelMaterial {
                    kd: [1.0; 4],
                    layer: 0,
                    alpha_tested: true,
                },
            ],
            layers: vec![image::RgbaImage::new(4, 4)],
            leaf_end: vec![vertices.len() as u32],
            leaf_centre: vec![[0.0; 3]],
            branch_vertices: 3,
            source_hash: String::new(),
            sphere: [0.0, 0.0, 0.0, 5.0],
            r: 0.5,
            mean_leaf: [0.1; 3],
            billboards: Vec::new(),
            opacity: forest_format::opacity::OpacityVolume::empty(2),
        };
        let quad = [
            Vec2::new(0.25, 0.25),
            Vec2::new(0.75, 0.25),
            Vec2::new(0.75, 0.75),
            Vec2::new(0.25, 0.75),
        ];
        let (cut, n) = cut_cards(&model, &[Some(quad)]);
        assert_eq!(n, 1, "one card; the lone triangle is not one");
        cut.check_indices().unwrap();
        assert_eq!(cut.vertices.len(), vertices.len());
        assert_eq!(cut.vertices[..3], vertices[..3], "the bark is copied");
        assert_eq!(
            cut.vertices[9..],
            vertices[9..],
            "the lone triangle is copied"
        );
        let card = &cut.vertices[3..9];
        let uv_area: f32 = card
            .chunks(3)
            .map(|t| {
                0.5 * (Vec2::from(t[1].uv) - Vec2::from(t[0].uv))
                    .perp_dot(Vec2::from(t[2].uv) - Vec2::from(t[0].uv))
            })
            .sum();
        assert!(
            (uv_area - 0.25).abs() < 1e-6,
            "the quad's area, counter-clockwise: {uv_area}"
        );
        for v in card {
            let [u, w] = v.uv;
            assert!(quad.iter().any(|q| (q.x, q.y) == (u, w)), "{:?}", v.uv);
            let want = o + a * u + b * w;
            assert!(
                (Vec3::from(v.pos) - want).length() < 1e-5,
                "{:?} for {want}",
                v.pos
            );
            assert!((v.sky_front - (0.2 + 0.3 * u + 0.4 * w)).abs() < 1e-6);
            assert!((v.sky_back - (0.8 - 0.3 * u - 0.4 * w)).abs() < 1e-6);
            assert_eq!((v.material, v.element, v.normal), (1, 0, [0.0, 0.0, 1.0]));
        }
        // Whole without a quad, and a card whose corners leave a parallelogram stays whole.
        assert_eq!(cut_cards(&model, &[None]).0.vertices, vertices);
        let mut overlapping = model.clone();
        overlapping.vertices[8] = at(1.0, 0.0);
        overlapping.vertices[7] = at(0.0, 1.0);
        overlapping.vertices[6] = at(0.0, 0.0);
        let mut split = model.clone();
        split.lod_vertices = [6, 6, 0];
        split.leaf_end = vec![6];
        for other in [overlapping, split] {
            other.check_indices().unwrap();
            assert_eq!(cut_cards(&other, &[Some(quad)]).1, 0);
        }
        let mut bent = model.clone();
        bent.vertices[5].pos[2] += 1.0;
        bent.vertices[7].pos[2] += 1.0;
        assert_eq!(cut_cards(&bent, &[Some(quad)]).1, 0);
    }
}
