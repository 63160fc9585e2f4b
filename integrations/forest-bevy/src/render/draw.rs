//! Core3d: the forests cast into Bevy's shadow cascades, then drawn into the view.

use super::prepare::{ForestRenderState, drawn_format};
use bevy::pbr::ShadowView;
use bevy::prelude::*;
use bevy::render::camera::ExtractedCamera;
use bevy::render::renderer::{RenderContext, ViewQuery};
use bevy::render::view::{ExtractedView, ViewDepthStencilTexture, ViewTarget};
use forest_render::ForestView;

/// Core3d, after Bevy's shadow passes and before the main pass: each forest's casting stream
/// of this view culled and refined from the light, and drawn depth-only into its cascade's
/// layer of Bevy's directional shadow map.
pub fn cast_forests(
    view: ViewQuery<&ExtractedView>,
    light_views: Query<&ShadowView>,
    state: Res<ForestRenderState>,
    mut ctx: RenderContext,
) {
    let r = &view.into_inner().retained_view_entity;
    if r.auxiliary_entity.is_some() {
        return;
    }
    let Some(casts) = state.casts.get(&r.main_entity.id()) else {
        return;
    };
    for (light_view, key) in casts {
        let (Ok(shadow), Some(caster)) = (light_views.get(*light_view), state.casters.get(key))
        else {
            continue;
        };
        let encoder = ctx.command_encoder();
        caster.stream.encode_compute(encoder);
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("forest shadow cast"),
            color_attachments: &[],
            depth_stencil_attachment: Some(
                shadow.depth_attachment.get_attachment(wgpu::StoreOp::Store),
            ),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        caster.stream.render_depth(&mut pass);
    }
}

/// Core3d, after the main opaque pass: each forest prepared for this view, culled, refined
/// and drawn into the view's colour (blended) and depth (where opaque), so Bevy's
/// transparent pass and post-processing see it: the models first (the geometry methods, the
/// hybrid's near trees), depth written, then the quads.
pub fn draw_forests(
    view: ViewQuery<(
        &ExtractedView,
        &ExtractedCamera,
        &ViewTarget,
        &ViewDepthStencilTexture,
    )>,
    state: Res<ForestRenderState>,
    mut ctx: RenderContext,
) {
    let (view, camera, target, depth) = view.into_inner();
    let r = &view.retained_view_entity;
    if r.auxiliary_entity.is_some() {
        return;
    }
    let main = r.main_entity.id();
    // A main texture that holds sRGB-encoded bytes in a UNORM format (Bevy's sRGB
    // compositing space) is drawn through an sRGB view of it (Bevy allows that view format),
    // so the forest's linear colours are encoded as Bevy's own are.
    let format = target.main_texture_format();
    let srgb = drawn_format(format);
    let views = (srgb != format).then(|| {
        let view = |t: &wgpu::Texture| -> wgpu::TextureView {
            t.create_view(&wgpu::TextureViewDescriptor {
                format: Some(srgb),
                ..Default::default()
            })
        };
        (
            view(target.main_texture()),
            target.sampled_main_texture().map(|t| view(t)),
        )
    });
    for renderer in state.prepared(main) {
        let colour = match &views {
            Some((single, multi)) => wgpu::RenderPassColorAttachment {
                view: multi.as_ref().unwrap_or(single),
                depth_slice: None,
                resolve_target: multi.as_ref().map(|_| single),
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            },
            None => target.get_color_attachment(),
        };
        let encoder = ctx.command_encoder();
        renderer.encode_compute(encoder);
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("forest"),
                color_attachments: &[Some(colour)],
                depth_stencil_attachment: Some(depth.get_attachment(wgpu::StoreOp::Store)),
                timestamp_writes: renderer.draw_timestamps(),
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if let Some(vp) = &camera.viewport {
                pass.set_viewport(
                    vp.physical_position.x as f32,
                    vp.physical_position.y as f32,
                    vp.physical_size.x as f32,
                    vp.physical_size.y as f32,
                    vp.depth.start,
                    vp.depth.end,
                );
            }
            renderer.render(&mut pass);
        }
        renderer.resolve_times(encoder);
    }
}
