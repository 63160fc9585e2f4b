//! A model prepared for the geometry-based methods and the hybrid's near trees
//! ([`forest_format::model::PreparedModel`]): reference vertices with the traced sky
//! visibility, the LOD set, billboard images, material layers and the opacity volume. The bake
//! writes it into the atlas folder, so that renderers need neither the model nor this crate.

use forest_format::model::{
    BILLBOARD_RESOLUTION, BillboardPair, MATERIAL_TEXTURE_SIZE, ModelMaterial, NONE, PreparedModel,
};
use forest_format::opacity::VOLUME_RESOLUTION;

use crate::Mesh;
use crate::lod::LodParams;
use crate::sky::TriangleSky;

/// Samples per billboard texel.
const BILLBOARD_SPP: u32 = 4;

/// Prepare `mesh`, whose triangles' sky visibility is `sky` (one entry per triangle,
/// [`crate::sky::triangle_sky`]; traced here when `None` or of another length). Seconds per
/// model: the billboard rays and the simplifier.
pub fn prepare(mesh: &Mesh, sky: Option<&[TriangleSky]>) -> PreparedModel {
    let traced;
    let sky = match sky {
        Some(s) if s.len() == mesh.tris.len() => s,
        _ => {
            traced = crate::sky::triangle_sky(&crate::trace::Scene::new(mesh));
            &traced[..]
        }
    };
    let mut layers = Vec::new();
    let materials = mesh
        .materials
        .iter()
        .map(|m| {
            let layer = if m.colour.is_some() || m.alpha.is_some() {
                layers.push(material_layer(mesh, m.colour, m.alpha));
                layers.len() as u32 - 1
            } else {
                NONE
            };
            ModelMaterial {
                kd: m.kd.extend(m.translucency).to_array(),
                layer,
                alpha_tested: m.alpha.is_some(),
            }
        })
        .collect();
    let reference = crate::reference_vertices(mesh, sky);
    let leaf: Vec<bool> = reference
        .chunks_exact(3)
        .map(|t| mesh.materials[t[0].material as usize].alpha.is_some())
        .collect();
    let set = crate::lod::build_lods(&reference, &leaf, &LodParams::default());
    let mean = crate::lod::mean_leaf_colour(mesh, &set.lod0);
    let sphere = crate::bounding_sphere(mesh);
    // The bake's volume of the same model: the same self-shadowing as its quads.
    let opacity = crate::opacity::opacity_volume(mesh, &sphere, VOLUME_RESOLUTION);
    let billboards = crate::lod::billboard_images(mesh, sky, BILLBOARD_RESOLUTION, BILLBOARD_SPP)
        .into_iter()
        .map(|b| BillboardPair {
            albedo: b.albedo,
            surface: b.surface,
        })
        .collect();
    let lod_vertices = [
        set.lod0.len() as u32,
        set.lods[0].len() as u32,
        set.lods[1].len() as u32,
    ];
    let mut vertices = set.lod0;
    vertices.extend(&set.lods[0]);
    vertices.extend(&set.lods[1]);
    PreparedModel {
        source_hash: format!("{:016x}", mesh.hash),
        sphere: sphere.center.extend(sphere.radius).to_array(),
        vertices,
        lod_vertices,
        branch_vertices: set.branch_vertices,
        r: set.r,
        mean_leaf: mean.to_array(),
        materials,
        layers,
        leaf_end: set.leaf_end,
        leaf_centre: set.leaf_centre.iter().map(|c| c.to_array()).collect(),
        billboards,
        opacity,
    }
}

/// Combine a material's colour and alpha sources into one RGBA image of the layer size.
fn material_layer(
    mesh: &Mesh,
    colour: Option<usize>,
    alpha: Option<(usize, bool)>,
) -> image::RgbaImage {
    let s = MATERIAL_TEXTURE_SIZE;
    let resize = |t: usize| {
        let tex = &mesh.textures[t];
        let img = image::RgbaImage::from_raw(tex.width, tex.height, tex.rgba.clone())
            .expect("texture size");
        image::imageops::resize(&img, s, s, image::imageops::FilterType::Triangle)
    };
    let mut out = match colour {
        Some(c) => resize(c),
        None => image::RgbaImage::from_pixel(s, s, image::Rgba([255, 255, 255, 255])),
    };
    if let Some((a, channel)) = alpha {
        let src = if Some(a) == colour && channel {
            out.clone()
        } else {
            resize(a)
        };
        for (o, p) in out.pixels_mut().zip(src.pixels()) {
            o[3] = crate::mesh::texel_alpha(p.0, channel);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_prepared_model_passes_its_own_checks_and_survives_its_file() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/trees/bush/bush.obj");
        let mesh = Mesh::load(&path).unwrap();
        let m = prepare(&mesh, None);
        assert_eq!(m.vertices.len() as u32, m.lod_vertices.iter().sum::<u32>());
        assert_eq!(m.lod_vertices[0] as usize, 3 * mesh.tris.len());
        assert!(m.lod_vertices[1] < m.lod_vertices[0] && m.lod_vertices[2] < m.lod_vertices[1]);
        m.check_indices().unwrap();
        let back = PreparedModel::decode(&m.encode(), std::path::Path::new("m.bin")).unwrap();
        assert_eq!(back, m);
        // The traced sky is reused when given.
        let sky = crate::sky::triangle_sky(&crate::trace::Scene::new(&mesh));
        assert_eq!(prepare(&mesh, Some(&sky)).vertices, m.vertices);
    }
}
