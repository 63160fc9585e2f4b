//! Alpha-tested triangles cut to the opaque part of their texture, for the ray tracer only.
//!
//! Leaf cards are mostly transparent (a quarter of the bundled oak's leaf texture passes the
//! alpha test), and every ray through a crown tests, and rejects, the transparent part of
//! many cards. Cutting each card to the convex hull of its texture's opaque texels, as
//! engines cut billboards to their silhouette, halves its area and tightens its BVH box.
//! The cut is exact for the tracer: every point of an opaque texel lies inside the hull, so
//! every hit that passes the alpha test is still found, and each piece keeps its triangle's
//! barycentric frame, so what a hit reads (texture, normal, sky visibility) is unchanged.
//!
//! Pure functions over texture-space polygons; [`crate::trace::Scene`] uses them.

use glam::Vec2;

use crate::mesh::{ALPHA_CUTOFF, Mesh, Tri, texel_alpha};

/// Most vertices a hull keeps: a triangle cut by it is at most `MAX_HULL_VERTICES + 1`
/// pieces. Fewer vertices add area (measured on the bundled leaf textures: a few per cent).
pub const MAX_HULL_VERTICES: usize = 6;

pub use forest_format::cutout::{Polygon, WHOLE, clip_convex, convex_hull, simplify_outward};

/// The convex hull, simplified outward to at most [`MAX_HULL_VERTICES`] vertices, of the
/// texels of texture `t` of `mesh` that pass the alpha test as [`Mesh::alpha`] reads them
/// (its alpha channel when `channel`, else its grey), each texel taken whole and grown by a
/// quarter texel. `None` when no texel passes (every triangle on it is transparent).
pub fn opaque_hull(mesh: &Mesh, t: usize, channel: bool) -> Option<Polygon> {
    let tex = &mesh.textures[t];
    let (w, h) = (tex.width as usize, tex.height as usize);
    let pass = |x: usize, y: usize| {
        let i = (y * w + x) * 4;
        let texel = [
            tex.rgba[i],
            tex.rgba[i + 1],
            tex.rgba[i + 2],
            tex.rgba[i + 3],
        ];
        f32::from(texel_alpha(texel, channel)) / 255.0 >= ALPHA_CUTOFF
    };
    // Texel (x, y) covers u ∈ [x/w, (x+1)/w] and v ∈ [1 − (y+1)/h, 1 − y/h] (row 0 on top;
    // `Texture::texel`): the corners of each row's outermost passing texels, grown by a
    // quarter texel.
    let grow = 0.25;
    let mut points = Vec::new();
    for y in 0..h {
        let first = (0..w).find(|&x| pass(x, y));
        let Some(first) = first else { continue };
        let last = (first..w).rev().find(|&x| pass(x, y)).unwrap_or(first);
        for x in [first as f32 - grow, last as f32 + 1.0 + grow] {
            for yy in [y as f32 - grow, y as f32 + 1.0 + grow] {
                points.push(Vec2::new(x / w as f32, 1.0 - yy / h as f32));
            }
        }
    }
    if points.is_empty() {
        return None;
    }
    Some(simplify_outward(convex_hull(points), MAX_HULL_VERTICES))
}

/// The pieces of triangle `t` that may pass the alpha test, as barycentric corners
/// `[(b1, b2); 3]` of `t`: `t` cut by the hull of its texture
/// ([`forest_format::cutout::pieces_in`]). No hull (no texel passes): no piece.
pub fn pieces(t: &Tri, hull: Option<&Polygon>) -> Vec<[Vec2; 3]> {
    match hull {
        Some(hull) => forest_format::cutout::pieces_in(t.uv, hull),
        None => Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_triangle_without_a_hull_has_no_piece_and_one_with_it_is_cut() {
        let t = Tri {
            p: [glam::Vec3::ZERO, glam::Vec3::X, glam::Vec3::Y],
            uv: [Vec2::ZERO, Vec2::X, Vec2::Y],
            n: [glam::Vec3::Z; 3],
            material: 0,
        };
        assert!(pieces(&t, None).is_empty());
        let hull = vec![
            Vec2::new(0.1, 0.1),
            Vec2::new(0.3, 0.1),
            Vec2::new(0.3, 0.3),
            Vec2::new(0.1, 0.3),
        ];
        assert_eq!(
            pieces(&t, Some(&hull)).len(),
            2,
            "a square inside the triangle: two pieces"
        );
    }
}
