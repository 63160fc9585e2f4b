//! The species' opacity volumes on the GPU (see [`forest_format::opacity`]): one R8Unorm 3D
//! texture, species after species along z (species `k` at slices `k·R .. (k+1)·R`), with mip
//! levels down to [`COARSE_LEVEL`] (species `k` at slices `k·(R >> l)` of level `l`), which
//! `sun_transmittance` (level 0) and `sun_transmittance_coarse` in `shaders/common.wgsl` march
//! towards the sun. Shared by the quad stream and the triangle methods.

use forest_format::opacity::{COARSE_LEVEL, OpacityVolume, VOLUME_RESOLUTION};
use wgpu::util::DeviceExt;

use crate::context::RenderError;

/// Layout entry of the opacity texture at `binding`: a filterable 3D texture read by the
/// vertex stage (per-vertex sun visibility) and the fragment stage (billboards).
pub fn opacity_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: wgpu::TextureViewDimension::D3,
            multisampled: false,
        },
        count: None,
    }
}

/// Refuse, before anything is allocated, `species` opacity volumes stacked deeper than a 3D
/// texture of a device of `limits` may be ([`opacity_texture`] stacks them along z).
pub fn check_volumes(limits: &wgpu::Limits, species: usize) -> Result<(), RenderError> {
    let r = VOLUME_RESOLUTION;
    let depth = u64::from(r) * species.max(1) as u64;
    crate::error::within_limit(
        || format!("the opacity volumes ({species} species × {r} slices)"),
        depth,
        limits.max_texture_dimension_3d.into(),
        ": split the forest into scenes of fewer species",
    )
}

/// Upload `volumes` (every one [`VOLUME_RESOLUTION`] a side; one empty volume when there are
/// none) as one stacked 3D texture. Returns it and its bytes; the error names the device limit
/// a scene of too many species exceeds.
pub fn opacity_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    volumes: &[&OpacityVolume],
) -> Result<(wgpu::Texture, u64), RenderError> {
    let r = VOLUME_RESOLUTION;
    check_volumes(&device.limits(), volumes.len())?;
    let depth = r as u64 * volumes.len().max(1) as u64;
    for v in volumes {
        assert_eq!(
            v.resolution, r,
            "atlas loading checks the volume resolution"
        );
    }
    let mips: Vec<Vec<OpacityVolume>> = volumes.iter().map(|v| v.mips(COARSE_LEVEL)).collect();
    // Level after level (wgpu's order for one 3D layer), each species after species; an empty
    // scene's one volume stays zero.
    let mut data = Vec::new();
    for l in 0..=COARSE_LEVEL {
        let side = (r >> l) as usize;
        let start = data.len();
        for m in &mips {
            data.extend_from_slice(&m[l as usize].codes);
        }
        data.resize(start + side * side * (depth as usize >> l), 0);
    }
    let texture = device.create_texture_with_data(
        queue,
        &wgpu::TextureDescriptor {
            label: Some("opacity volumes"),
            size: wgpu::Extent3d {
                width: r,
                height: r,
                depth_or_array_layers: depth as u32,
            },
            mip_level_count: COARSE_LEVEL + 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: wgpu::TextureFormat::R8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        &data,
    );
    Ok((texture, data.len() as u64))
}

#[cfg(test)]
mod tests {
    use forest_format::opacity::{
        COARSE_LEVEL, COARSE_QUAD_LEVEL, COARSE_STEPS, MARCH_STEPS, MID_QUAD_LEVEL, MID_STEPS,
        START_VOXELS, VOLUME_RESOLUTION,
    };

    /// The WGSL march's constants are the CPU mirror's.
    #[test]
    fn the_shader_marches_as_the_format_says() {
        let src = crate::shaders::COMMON_WGSL;
        for line in [
            format!("const OPACITY_RES: f32 = {:.1};", VOLUME_RESOLUTION as f32),
            format!("const OPACITY_STEPS: u32 = {MARCH_STEPS}u;"),
            format!("const OPACITY_COARSE_LEVEL: u32 = {COARSE_LEVEL}u;"),
            format!("const OPACITY_COARSE_STEPS: u32 = {COARSE_STEPS}u;"),
            format!("const OPACITY_MID_STEPS: u32 = {MID_STEPS}u;"),
            format!("const OPACITY_COARSE_QUAD_LEVEL: u32 = {COARSE_QUAD_LEVEL}u;"),
            format!("const OPACITY_MID_QUAD_LEVEL: u32 = {MID_QUAD_LEVEL}u;"),
            format!("const OPACITY_START: f32 = {START_VOXELS:?};"),
        ] {
            assert!(src.contains(&line), "common.wgsl lacks `{line}`");
        }
    }
}
