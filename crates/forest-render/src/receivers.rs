//! The draw's shadow receivers (group 2): the layout, the group over a depth array (the
//! forest's own maps or a host's), and a host's cascades as receivers read them.

use crate::context::RenderError;
use crate::gpu_types::GpuCamera;
use crate::shadow::ShadowOptions;

/// Depth format of the shadow maps.
pub const SHADOW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Layout entries of the receivers' group (group 2 of the draw, `shaders/shadow_on.wgsl`):
/// the maps as a depth array and their comparison sampler.
pub fn receiver_entries() -> [wgpu::BindGroupLayoutEntry; 2] {
    [
        wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Depth,
                view_dimension: wgpu::TextureViewDimension::D2Array,
                multisampled: false,
            },
            count: None,
        },
        wgpu::BindGroupLayoutEntry {
            binding: 1,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
            count: None,
        },
    ]
}

/// The receivers' bind-group layout.
pub fn receiver_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("shadow receivers"),
        entries: &receiver_entries(),
    })
}

/// A depth array of `layers` layers of `side`² texels, sampled and drawn into.
pub(crate) fn depth_array(device: &wgpu::Device, side: u32, layers: u32) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("shadow maps"),
        size: wgpu::Extent3d {
            width: side,
            height: side,
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: SHADOW_FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    })
}

/// The receivers' group over `texture` (all its layers).
pub(crate) fn receiver_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    texture: &wgpu::Texture,
) -> wgpu::BindGroup {
    let view = texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..Default::default()
    });
    receivers_of(device, layout, &view, false)
}

/// A host engine's shadow maps as a forest's receivers read them: the group over its depth
/// array and the cascades of the next frames (shared by the quad stream and the geometry
/// renderer, so that the hybrid's two forms receive the same shadows).
pub struct HostShadows {
    group: wgpu::BindGroup,
    resolution: u32,
    reverse_z: bool,
    offset_texels: f32,
    cascades: Vec<crate::shadow::Cascade>,
}

impl HostShadows {
    /// The receivers of `view`, a depth array (a layer per cascade, `resolution`² texels,
    /// standard depth or `reverse_z`), bound with `layout` (the draw's group 2); no cascade
    /// until [`Self::set_cascades`].
    pub fn new(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        view: &wgpu::TextureView,
        resolution: u32,
        reverse_z: bool,
    ) -> Self {
        Self {
            group: receivers_of(device, layout, view, reverse_z),
            resolution,
            reverse_z,
            offset_texels: ShadowOptions::default().offset_texels,
            cascades: Vec::new(),
        }
    }

    /// The host's cascades: each one's world → shadow clip matrix, the view depth where it
    /// ends (`split.1`), its texel and its depth range (metres); at most
    /// [`crate::shadow::MAX_CASCADES`], finite. Refused, with nothing changed, otherwise.
    pub fn set_cascades(&mut self, cascades: &[crate::shadow::Cascade]) -> Result<(), RenderError> {
        if cascades.len() > crate::shadow::MAX_CASCADES as usize {
            return Err(RenderError::Parameter(format!(
                "{} shadow cascades: at most {}",
                cascades.len(),
                crate::shadow::MAX_CASCADES
            )));
        }
        if cascades.iter().any(|c| {
            !(c.view_proj.is_finite()
                && c.split.1.is_finite()
                && c.texel > 0.0
                && c.depth_range > 0.0)
        }) {
            return Err(RenderError::Parameter(
                "a shadow cascade's matrix, split, texel or depth range is not finite and \
                 positive"
                    .into(),
            ));
        }
        self.cascades = cascades.to_vec();
        Ok(())
    }

    /// Write the cascades into a camera uniform's receiver fields.
    pub fn write(&self, g: &mut GpuCamera) {
        crate::shadow::write_receivers_of(
            g,
            &self.cascades,
            self.resolution,
            self.offset_texels,
            self.reverse_z,
        );
    }

    /// The receivers' group (the draw's group 2).
    pub fn group(&self) -> &wgpu::BindGroup {
        &self.group
    }
}

/// The receivers' group over a depth array `view` (a host's maps too), compared as
/// standard depth or reverse-Z.
pub fn receivers_of(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    view: &wgpu::TextureView,
    reverse_z: bool,
) -> wgpu::BindGroup {
    let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("shadow compare"),
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        compare: Some(if reverse_z {
            wgpu::CompareFunction::GreaterEqual
        } else {
            wgpu::CompareFunction::LessEqual
        }),
        ..Default::default()
    });
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("shadow receivers"),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(view),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::Sampler(&sampler),
            },
        ],
    })
}

/// The receivers' group of a view without shadows: a 1×1 map that is never read (the camera
/// says no cascades are in use).
pub fn no_shadows(device: &wgpu::Device, layout: &wgpu::BindGroupLayout) -> wgpu::BindGroup {
    receiver_group(device, layout, &depth_array(device, 1, 1))
}
