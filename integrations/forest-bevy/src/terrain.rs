//! A Bevy mesh of a forest's ground, so that a scene can lay its own terrain (its own
//! material, shadows and collisions) exactly under the trees.

use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, Mesh, PrimitiveTopology};
use forest_format::forest::Forest;

/// The most cells a side of [`terrain_mesh`] takes: (4 097)² vertices, 400 MB of them.
pub const MAX_TERRAIN_CELLS: u32 = 4096;

/// Why [`terrain_mesh`] refused its parameters.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TerrainMeshError {
    /// The half extent is not a positive, finite length.
    #[error("terrain mesh: half extent {0} m is not a positive, finite length")]
    HalfExtent(f32),
    /// The grid has no cells, or more than [`MAX_TERRAIN_CELLS`] a side.
    #[error("terrain mesh: {0} cells a side is outside 1..={MAX_TERRAIN_CELLS}")]
    Cells(u32),
}

/// The forest's ground over the square `[-half_extent, half_extent]²` (metres, in the forest's
/// frame: place the mesh with the forest's `Transform`) as `cells` × `cells` quads of two
/// triangles, every vertex at [`Forest::ground_height`] (flat at 0 for a forest without
/// terrain), with smooth normals. Each cell is split along the same diagonal as the forest's
/// ground, so on the height field's own grid (`half_extent` and `cells` that put the mesh's
/// vertices on its samples) the mesh is exactly the ground the trees stand on; a coarser mesh
/// cuts across the field's bumps.
pub fn terrain_mesh(
    forest: &Forest,
    half_extent: f32,
    cells: u32,
) -> Result<Mesh, TerrainMeshError> {
    if !(half_extent.is_finite() && half_extent > 0.0) {
        return Err(TerrainMeshError::HalfExtent(half_extent));
    }
    if !(1..=MAX_TERRAIN_CELLS).contains(&cells) {
        return Err(TerrainMeshError::Cells(cells));
    }
    let row = cells + 1;
    let step = 2.0 * half_extent / cells as f32;
    let mut positions = Vec::with_capacity((row * row) as usize);
    for j in 0..row {
        for i in 0..row {
            let (x, z) = (i as f32 * step - half_extent, j as f32 * step - half_extent);
            positions.push([x, forest.ground_height(x, z), z]);
        }
    }
    let mut indices = Vec::with_capacity((cells * cells * 6) as usize);
    for j in 0..cells {
        for i in 0..cells {
            let a = j * row + i;
            // Split along (i, j)–(i + 1, j + 1), as the forest's ground is; counter-clockwise
            // seen from above (+Y).
            indices.extend([a, a + row + 1, a + 1, a, a + row, a + row + 1]);
        }
    }
    let mut mesh = Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_indices(Indices::U32(indices));
    mesh.compute_smooth_normals();
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use bevy::mesh::VertexAttributeValues;

    /// A forest with a sloped, bumpy height field: the mesh's vertices lie on its ground, its
    /// triangles face up, and bad parameters are refused.
    #[test]
    fn the_mesh_lies_on_the_ground() {
        let n = 9usize;
        let heights: Vec<f32> = (0..n * n)
            // A slope, bumps along z, and a twist (i·j) that makes every cell non-planar.
            .map(|k| {
                let (i, j) = ((k % n) as f32, (k / n) as f32);
                0.3 * i + j.sin() + 0.05 * i * j
            })
            .collect();
        let terrain = forest_format::terrain::Terrain {
            size: [n as u32, n as u32],
            origin: [-20.0, -20.0],
            spacing: 5.0,
            heights,
        };
        terrain.check().expect("terrain");
        let forest = Forest::new(Vec::new(), Vec::new(), 1).with_terrain(terrain);
        let mesh = terrain_mesh(&forest, 12.0, 6).expect("mesh");
        let Some(VertexAttributeValues::Float32x3(p)) = mesh.attribute(Mesh::ATTRIBUTE_POSITION)
        else {
            panic!("no positions");
        };
        assert_eq!(p.len(), 49);
        assert_eq!(p[0][0], -12.0);
        assert_eq!(p[48][2], 12.0);
        for v in p {
            assert!(
                (v[1] - forest.ground_height(v[0], v[2])).abs() < 1e-6,
                "{v:?}"
            );
        }
        let Some(VertexAttributeValues::Float32x3(normals)) =
            mesh.attribute(Mesh::ATTRIBUTE_NORMAL)
        else {
            panic!("no normals");
        };
        assert!(normals.iter().all(|n| n[1] > 0.0));
        assert_eq!(mesh.indices().map(|i| i.len()), Some(6 * 36));
        // On the field's own grid, every triangle lies on the ground: its centroid's height is
        // the ground's there (a cell split along the other diagonal would not be).
        let mesh = terrain_mesh(&forest, 20.0, 8).expect("mesh");
        let Some(VertexAttributeValues::Float32x3(p)) = mesh.attribute(Mesh::ATTRIBUTE_POSITION)
        else {
            panic!("no positions");
        };
        let indices: Vec<usize> = mesh.indices().expect("indices").iter().collect();
        for t in indices.chunks(3) {
            let c = t.iter().fold([0.0f32; 3], |c, &k| {
                [
                    c[0] + p[k][0] / 3.0,
                    c[1] + p[k][1] / 3.0,
                    c[2] + p[k][2] / 3.0,
                ]
            });
            let ground = forest.ground_height(c[0], c[2]);
            assert!(
                (c[1] - ground).abs() < 1e-4,
                "{t:?}: {} against {ground}",
                c[1]
            );
        }
        assert_eq!(
            terrain_mesh(&forest, 0.0, 6).err(),
            Some(TerrainMeshError::HalfExtent(0.0))
        );
        assert!(matches!(
            terrain_mesh(&forest, f32::NAN, 6),
            Err(TerrainMeshError::HalfExtent(_))
        ));
        assert_eq!(
            terrain_mesh(&forest, 1.0, 0).err(),
            Some(TerrainMeshError::Cells(0))
        );
        assert_eq!(
            terrain_mesh(&forest, 1.0, MAX_TERRAIN_CELLS + 1).err(),
            Some(TerrainMeshError::Cells(MAX_TERRAIN_CELLS + 1))
        );
    }
}
