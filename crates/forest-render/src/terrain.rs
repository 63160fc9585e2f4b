//! The terrain on the GPU: its heights in a storage buffer and its grid in the environment
//! uniform, drawn by `vs_terrain`/`fs_terrain` of `shaders/environment.wgsl` as a triangle mesh
//! generated from the vertex index (no vertex buffer). Every method records the same draw,
//! after the environment pass, whenever it draws the ground.

use forest_format::terrain::Terrain;
use wgpu::util::DeviceExt;

use crate::context::RenderError;

/// The terrain's grid as the shaders see it (the default: no terrain).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TerrainGrid {
    /// World x and z of sample (0, 0), metres.
    pub origin: [f32; 2],
    /// Metres between samples.
    pub spacing: f32,
    /// Samples along x and z; `[0, 0]` without a terrain.
    pub size: [u32; 2],
}

impl TerrainGrid {
    /// The grid of `terrain` (`None`: no terrain).
    pub fn of(terrain: Option<&Terrain>) -> Self {
        terrain.map_or(Self::default(), |t| Self {
            origin: t.origin,
            spacing: t.spacing,
            size: t.size,
        })
    }

    /// Whether there is a terrain to draw.
    pub fn present(&self) -> bool {
        self.size[0] >= 2 && self.size[1] >= 2
    }

    /// Vertices of the mesh `vs_terrain` generates: 6 per cell, then 6 per segment of the
    /// skirt around the border (0 without a terrain; at most 6·4096² + 12·8192 for the
    /// largest grid, well within `u32`).
    pub fn vertices(&self) -> u32 {
        if !self.present() {
            return 0;
        }
        let (a, b) = (self.size[0] - 1, self.size[1] - 1);
        6 * a * b + 12 * (a + b)
    }
}

/// The terrain's heights on the GPU (one zero when there is no terrain, so the binding
/// always holds a buffer).
pub struct GpuTerrain {
    /// The grid the environment uniform carries.
    pub grid: TerrainGrid,
    /// Heights in metres, row after row (`shaders/environment.wgsl`'s binding 13).
    pub heights: wgpu::Buffer,
}

impl GpuTerrain {
    /// Upload `terrain`'s heights, refused before allocating when the buffer would exceed
    /// the device's storage-binding limit.
    pub fn new(device: &wgpu::Device, terrain: Option<&Terrain>) -> Result<Self, RenderError> {
        let grid = TerrainGrid::of(terrain);
        let zero = [0.0f32];
        let heights: &[f32] = terrain.map_or(&zero, |t| &t.heights);
        let bytes = std::mem::size_of_val(heights) as u64;
        crate::error::within_limit(
            || "the terrain's heights (bytes)".into(),
            bytes,
            crate::error::storage_limit(&device.limits()),
            ": load the height field at a coarser spacing (fewer pixels)",
        )?;
        let heights = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("terrain heights"),
            contents: bytemuck::cast_slice(heights),
            usage: wgpu::BufferUsages::STORAGE,
        });
        Ok(Self { grid, heights })
    }

    /// Bytes on the GPU.
    pub fn bytes(&self) -> u64 {
        self.heights.size()
    }

    /// Record the ground into `pass`, whose bind group holds the environment uniform and the
    /// heights at binding 13: the caller's `vs_environment` pipeline (sky and plane, one
    /// triangle), then its `vs_terrain` pipeline over the mesh when there is a terrain. Every
    /// method records the ground through here, so all draw it alike. Returns the draws
    /// recorded (1 or 2).
    pub fn record_ground(
        &self,
        pass: &mut wgpu::RenderPass,
        environment: &wgpu::RenderPipeline,
        terrain: &wgpu::RenderPipeline,
    ) -> u32 {
        pass.set_pipeline(environment);
        pass.draw(0..3, 0..1);
        if !self.grid.present() {
            return 1;
        }
        pass.set_pipeline(terrain);
        pass.draw(0..self.grid.vertices(), 0..1);
        2
    }
}

/// The bind-group layout entry of the terrain's heights (binding 13, read in the vertex
/// stage), in every draw group that draws the ground.
pub fn heights_entry() -> wgpu::BindGroupLayoutEntry {
    crate::bindings::vertex_storage_entry(HEIGHTS_BINDING)
}

/// Binding of the terrain's heights in the draw groups (`shaders/environment.wgsl`).
pub const HEIGHTS_BINDING: u32 = 13;

/// The environment uniform: ground colour, sky, sun disc, haze and the terrain's grid (see
/// `shaders/environment.wgsl`).
pub fn environment_uniform(
    atmosphere: &crate::options::Atmosphere,
    terrain: &TerrainGrid,
) -> crate::gpu_types::GpuEnvironment {
    let g = crate::options::GROUND_MOSS;
    let [hr, hg, hb] = atmosphere.horizon;
    let [zr, zg, zb] = atmosphere.zenith;
    // A cosine above 1 draws no disc.
    let disc = if atmosphere.sun_disc {
        crate::options::SUN_DISC_DEGREES.to_radians().cos()
    } else {
        2.0
    };
    crate::gpu_types::GpuEnvironment {
        ground: [g.x, g.y, g.z, 0.0],
        horizon: [hr, hg, hb, atmosphere.haze_density()],
        zenith: [zr, zg, zb, atmosphere.haze_falloff()],
        sun: [disc, 0.0, 0.0, 0.0],
        albedo: crate::options::GROUND_ALBEDO.extend(0.0).to_array(),
        terrain: [
            terrain.origin[0],
            terrain.origin[1],
            terrain.spacing,
            if terrain.present() { 1.0 } else { 0.0 },
        ],
        terrain_size: [terrain.size[0], terrain.size[1], 0, 0],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mesh_has_two_triangles_a_cell_and_a_skirt_around() {
        assert_eq!(TerrainGrid::default().vertices(), 0);
        let g = TerrainGrid {
            size: [3, 2],
            ..Default::default()
        };
        // 2 cells, 6 border segments.
        assert_eq!(g.vertices(), 2 * 6 + 6 * 6);
        let big = TerrainGrid {
            size: [forest_format::terrain::MAX_SIDE; 2],
            ..Default::default()
        };
        assert_eq!(u64::from(big.vertices()), 6 * 4096 * 4096 + 12 * 8192);
    }
}
