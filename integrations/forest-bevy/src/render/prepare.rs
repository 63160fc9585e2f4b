//! Render/Prepare: one GPU scene per forest asset on Bevy's device, one stream per (camera,
//! forest) sized for the view, its camera and Bevy's cascades written.

use std::sync::Arc;

use bevy::asset::AssetId;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::pbr::{
    ExtractedDirectionalLight, LightEntity, ShadowView, ViewLightEntities, ViewShadowBindings,
};
use bevy::platform::collections::{HashMap, HashSet};
use bevy::prelude::*;
use bevy::render::camera::ExtractedCamera;
use bevy::render::renderer::{RenderAdapterInfo, RenderDevice, RenderQueue};
use bevy::render::view::{ExtractedView, Msaa, ViewDepthStencilTexture, ViewTarget};
use forest_baselines::{ForestRenderer, GeometryRenderer, GpuModels, PreparedGeometry};
use forest_format::forest::Forest;
use forest_render::{ForestView, FrameParams, GpuContext, GpuScene, QuadStream, RendererOptions};

use super::extract::Extracted;
use crate::assets::ForestAsset;
use crate::components::ForestMethod;
use crate::light;
use crate::shadows;
use crate::stats::{ForestViewStats, SharedStats};

/// One forest's renderer in one view: its quad stream, and the geometry renderer while the
/// view's method draws models.
pub(super) struct ViewStream {
    /// The asset its scene is of (it is rebuilt when that or its options change).
    asset: AssetId<ForestAsset>,
    renderer: ForestRenderer,
    /// Written this frame (only those are drawn).
    prepared: bool,
    /// The Bevy shadow map (and its cascade count) it reads, if any.
    receiving: Option<(wgpu::Texture, usize)>,
    /// The last counters read back.
    last: Option<ForestViewStats>,
}

/// A casting stream's key: (camera, forest, cascade layer).
pub(super) type CasterId = (Entity, Entity, u32);

/// One forest's stream casting into one of a view's cascades.
pub(super) struct Caster {
    /// The asset its scene is of (it is rebuilt when that or its options change).
    asset: AssetId<ForestAsset>,
    pub(super) stream: QuadStream,
    /// Quads it cast in a recent frame.
    quads: u32,
}

/// A forest asset's trees and its species' prepared models (or why it has none), and, once a
/// view has drawn a model method, those models on the GPU, shared by every view.
struct Models {
    forest: Arc<Forest>,
    /// Whether some atlas holds no prepared model (the asset was loaded without them).
    absent: bool,
    prepared: Result<Arc<PreparedGeometry>, String>,
    gpu: Option<Arc<GpuModels>>,
}

impl Models {
    /// The models on the GPU, uploaded at the first call; why not, if they cannot be (an
    /// upload that failed is not tried again).
    fn gpu(&mut self, ctx: &GpuContext) -> Result<Arc<GpuModels>, String> {
        if let Some(gpu) = &self.gpu {
            return Ok(gpu.clone());
        }
        let prepared = self.prepared.as_ref().map_err(Clone::clone)?;
        match GpuModels::new(ctx, prepared, &self.forest) {
            Ok(gpu) => Ok(self.gpu.insert(Arc::new(gpu)).clone()),
            Err(e) => {
                error!("forest models cannot be uploaded: {e}");
                self.prepared = Err(e.to_string());
                Err(e.to_string())
            }
        }
    }
}

/// The render world's forests: Bevy's device as a [`GpuContext`], one GPU scene per asset,
/// one stream per (camera, forest).
#[derive(Resource, Default)]
pub struct ForestRenderState {
    ctx: Option<GpuContext>,
    scenes: HashMap<AssetId<ForestAsset>, Arc<GpuScene>>,
    /// Per asset, its trees and its prepared models for the geometry methods (or why it has
    /// none), uploaded once for all views.
    models: HashMap<AssetId<ForestAsset>, Models>,
    failed: HashMap<AssetId<ForestAsset>, String>,
    streams: HashMap<(Entity, Entity), ViewStream>,
    /// (camera, forest, cascade layer) → the stream casting into that layer.
    pub(super) casters: HashMap<CasterId, Caster>,
    /// Per camera: the light views to cast into this frame, and their casters.
    pub(super) casts: HashMap<Entity, Vec<(Entity, CasterId)>>,
    /// Cameras warned about (once each).
    warned: HashSet<Entity>,
    /// (camera, forest) pairs warned that the hybrid falls back to the quad stream.
    warned_fallback: HashSet<(Entity, Entity)>,
}

impl ForestRenderState {
    /// Renderers prepared for the camera `main` this frame.
    pub(super) fn prepared(&self, main: Entity) -> impl Iterator<Item = &ForestRenderer> {
        self.streams
            .iter()
            .filter(move |((c, _), v)| *c == main && v.prepared)
            .map(|(_, v)| &v.renderer)
    }

    /// How many views' renderers hold the models of `asset`, uploaded once for all of them
    /// (0 while no view draws a model method of it: the upload is freed with its last
    /// renderer).
    pub fn views_sharing_models(&self, asset: AssetId<ForestAsset>) -> usize {
        self.models
            .get(&asset)
            .and_then(|m| m.gpu.as_ref())
            .map_or(0, |g| Arc::strong_count(g) - 1)
    }
}

/// The queries of Bevy's shadow views that a forest's cascades are read from.
type LightViews<'w, 's, 'a> = Query<'w, 's, (&'a ShadowView, &'a ExtractedView, &'a LightEntity)>;

/// One camera view as every forest in it is drawn: its settings, size and matrices.
struct ViewFrame<'a> {
    /// The camera's main entity.
    main: Entity,
    cam: &'a super::extract::ExtractedForestCamera,
    camera: &'a ExtractedCamera,
    viewport: (u32, u32),
    world_from_view: Mat4,
    clip_from_world: Mat4,
    /// The view's formats and sample count, as a stream's options take them.
    format: wgpu::TextureFormat,
    depth_format: wgpu::TextureFormat,
    samples: u32,
    /// Bevy's shadow maps of the view, if any.
    shadow_maps: Option<(&'a ViewLightEntities, &'a ViewShadowBindings)>,
}

/// Render/Prepare: build the GPU scenes of newly loaded forests, then per camera view and
/// forest (re)build the stream for the view's targets and write its camera.
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub fn prepare_forests(
    mut state: ResMut<ForestRenderState>,
    mut extracted: ResMut<Extracted>,
    device: Option<Res<RenderDevice>>,
    queue: Option<Res<RenderQueue>>,
    adapter: Option<Res<RenderAdapterInfo>>,
    shared: Res<SharedStats>,
    views: Query<(
        &ExtractedView,
        &ExtractedCamera,
        &ViewTarget,
        &ViewDepthStencilTexture,
        &Msaa,
        Option<(&ViewLightEntities, &ViewShadowBindings)>,
        Option<&Tonemapping>,
    )>,
    light_views: LightViews,
    directional: Query<&ExtractedDirectionalLight>,
) {
    // The renderer starts a few frames after the app.
    let (Some(device), Some(queue), Some(adapter)) = (device, queue, adapter) else {
        return;
    };
    let state = &mut *state;
    // Taken out for the frame (the state's maps are borrowed beside it), and put back.
    let ctx = state.ctx.take().unwrap_or_else(|| {
        GpuContext::from_device(
            (**adapter).clone(),
            device.wgpu_device().clone(),
            (**queue).clone(),
        )
    });
    state.apply_assets(&ctx, &mut extracted);
    let mut stats = shared.0.lock().unwrap_or_else(|e| e.into_inner());
    stats.clear();
    let mut live = HashSet::new();
    let mut live_casters = HashSet::new();
    for v in state.streams.values_mut() {
        v.prepared = false;
    }
    state.casts.clear();
    for (view, camera, target, depth, msaa, shadow_maps, tonemapping) in &views {
        let r = &view.retained_view_entity;
        if r.auxiliary_entity.is_some() || r.subview_index != 0 {
            continue;
        }
        let main = r.main_entity.id();
        let (Some(cam), Some(size)) = (extracted.cameras.get(&main), camera.physical_viewport_size)
        else {
            continue;
        };
        state.warn_untonemapped(main, camera, tonemapping);
        let world_from_view = view.world_from_view.to_matrix();
        let frame = ViewFrame {
            main,
            cam,
            camera,
            viewport: (size.x.max(1), size.y.max(1)),
            world_from_view,
            clip_from_world: view
                .clip_from_world
                .unwrap_or(view.clip_from_view * world_from_view.inverse()),
            format: drawn_format(target.main_texture_format()),
            depth_format: depth.texture().format(),
            samples: msaa.samples(),
            shadow_maps,
        };
        for forest in &extracted.forests {
            let key = (main, forest.entity);
            let Some(scene) = state.scenes.get(&forest.asset).cloned() else {
                if let Some(e) = state.failed.get(&forest.asset) {
                    let record = ForestViewStats {
                        error: Some(e.clone()),
                        ..Default::default()
                    };
                    stats.insert(key, record);
                }
                continue;
            };
            live.insert(key);
            // Bevy's shadow cascades for this view, in the forest's frame.
            let scale = forest
                .world_from_forest
                .to_scale_rotation_translation()
                .0
                .max_element();
            let cascades = shadow_maps.map_or_else(Vec::new, |(lights, _)| {
                shadows::view_cascades(
                    lights,
                    &light_views,
                    &directional,
                    forest.world_from_forest,
                    scale,
                )
            });
            let lit = Lit {
                sun: extracted.sun,
                cascades: &cascades,
                wind: extracted.wind,
                season: extracted.season,
            };
            let record =
                state.prepare_forest(&ctx, &frame, forest, &scene, &lit, &mut live_casters);
            if let Some(record) = record {
                stats.insert(key, record);
            }
        }
    }
    state.streams.retain(|k, _| live.contains(k));
    state.casters.retain(|k, _| live_casters.contains(k));
    // Models no view's renderer holds any more are freed (a later view uploads them again).
    for m in state.models.values_mut() {
        if m.gpu.as_ref().is_some_and(|g| Arc::strong_count(g) == 1) {
            m.gpu = None;
        }
    }
    state.ctx = Some(ctx);
}

/// A forest's light in a view: the sun, and Bevy's shadow cascades in the forest's frame.
struct Lit<'a> {
    sun: Option<light::Sun>,
    cascades: &'a [shadows::HostCascade],
    /// The wind, in world space.
    wind: forest_format::wind::Wind,
    /// The season (`None`: the models' own colours).
    season: Option<f32>,
}

impl ForestRenderState {
    /// Scenes of newly loaded assets built, those of removed assets dropped (with the streams
    /// drawing them, the casting ones too).
    fn apply_assets(&mut self, ctx: &GpuContext, extracted: &mut Extracted) {
        for id in extracted.removed_assets.drain(..) {
            self.scenes.remove(&id);
            self.models.remove(&id);
            self.failed.remove(&id);
        }
        for (id, asset) in extracted.new_assets.drain(..) {
            self.models.insert(
                id,
                Models {
                    forest: asset.forest.clone(),
                    absent: asset.geometry.is_err(),
                    prepared: asset.geometry.clone(),
                    gpu: None,
                },
            );
            match GpuScene::new(ctx, &asset.species, &asset.forest) {
                Ok(scene) => {
                    self.scenes.insert(id, Arc::new(scene));
                    self.failed.remove(&id);
                }
                Err(e) => {
                    error!("forest {id:?} cannot be drawn: {e}");
                    // A reload that failed leaves nothing of the old scene to draw.
                    self.scenes.remove(&id);
                    self.failed.insert(id, e.to_string());
                }
            }
            self.streams.retain(|_, v| v.asset != id);
            self.casters.retain(|_, c| c.asset != id);
        }
    }

    /// Bevy tonemaps LDR views inside each material's shader; the forest's shaders do not, so
    /// an LDR view with a tonemapper shows the trees untonemapped (HDR views are tonemapped by
    /// Bevy's pass, the trees with the rest). Said once per camera.
    fn warn_untonemapped(
        &mut self,
        main: Entity,
        camera: &ExtractedCamera,
        tonemapping: Option<&Tonemapping>,
    ) {
        let untonemapped = !camera.hdr && tonemapping.is_some_and(|t| *t != Tonemapping::None);
        if untonemapped && self.warned.insert(main) {
            warn!(
                "forest-bevy: camera {main} draws an LDR view with {tonemapping:?}: Bevy \
                 tonemaps LDR views in each material's shader and the forest's are not; add \
                 `Hdr` to the camera (or use `Tonemapping::None`)"
            );
        }
    }

    /// The method a view draws a forest with, and why not the one asked for: the hybrid (the
    /// default) over atlases baked without their models draws the quad stream, as `forest
    /// render` does, and says so; the other model methods report the missing models as an
    /// error.
    fn drawn_method(
        &mut self,
        key: (Entity, Entity),
        asset: AssetId<ForestAsset>,
        asked: ForestMethod,
    ) -> (ForestMethod, Option<String>) {
        if asked == ForestMethod::Hybrid
            && let Some(Err(why)) = self
                .models
                .get(&asset)
                .filter(|m| m.absent)
                .map(|m| m.prepared.as_ref())
        {
            let why = format!("drawing the quad stream, not the hybrid: {why}");
            if self.warned_fallback.insert(key) {
                warn!("forest-bevy: camera {}: {why}", key.0);
            }
            return (ForestMethod::QuadStream, Some(why));
        }
        (asked, None)
    }

    /// The view's renderer of a forest, (re)built for another asset or other targets, and
    /// when the method needs models the renderer has not uploaded (a quad-stream view uploads
    /// none), then set to `method`. None (after `record` says why) if it cannot be.
    #[allow(clippy::too_many_arguments)]
    fn renderer_for(
        &mut self,
        ctx: &GpuContext,
        key: (Entity, Entity),
        asset: AssetId<ForestAsset>,
        scene: &Arc<GpuScene>,
        opts: &RendererOptions,
        method: ForestMethod,
        record: &mut ForestViewStats,
    ) -> Option<&mut ViewStream> {
        let models = if method.needs_models() {
            let models = self.models.get_mut(&asset)?;
            match models.gpu(ctx) {
                Ok(gpu) => Some(gpu),
                Err(e) => {
                    self.streams.remove(&key);
                    record.error = Some(format!("{}: {e}", method.name()));
                    return None;
                }
            }
        } else {
            None
        };
        if self.streams.get(&key).is_none_or(|v| {
            v.asset != asset
                || v.renderer.stream.options_built() != opts
                || (models.is_some() && v.renderer.geometry.is_none())
        }) {
            let built = QuadStream::new(&ctx.device, scene.clone(), opts).and_then(|stream| {
                let geometry = models
                    .as_ref()
                    .map(|m| GeometryRenderer::with_models(ctx, m.clone(), opts))
                    .transpose()?;
                Ok(ForestRenderer::new(stream, geometry))
            });
            match built {
                Ok(renderer) => {
                    let view = ViewStream {
                        asset,
                        renderer,
                        prepared: false,
                        receiving: None,
                        last: None,
                    };
                    self.streams.insert(key, view);
                }
                Err(e) => {
                    self.streams.remove(&key);
                    record.error = Some(e.to_string());
                    return None;
                }
            }
        }
        let v = self.streams.get_mut(&key)?;
        let wanted = method.method();
        if v.renderer.method() != wanted {
            if let Err(e) = v.renderer.set_method(ctx, wanted) {
                record.error = Some(e.to_string());
                return None;
            }
            // The counters read back were of the other method.
            v.last = None;
        }
        Some(v)
    }

    /// One forest in one view: its renderer built and set to the view's method, its counters
    /// polled, Bevy's cascades received and cast into, its camera written. The view's record
    /// of it, None where a forest is not reported.
    fn prepare_forest(
        &mut self,
        ctx: &GpuContext,
        view: &ViewFrame,
        forest: &super::extract::ExtractedForest,
        scene: &Arc<GpuScene>,
        lit: &Lit,
        live_casters: &mut HashSet<CasterId>,
    ) -> Option<ForestViewStats> {
        let key = (view.main, forest.entity);
        let cam = view.cam;
        let opts = RendererOptions {
            format: view.format,
            depth_format: view.depth_format,
            sample_count: view.samples,
            reverse_z: true,
            viewport: view.viewport,
            min_epsilon: cam.settings.epsilon,
            atmosphere: light::atmosphere(cam.fog, cam.ambient, view.camera.exposure),
            write_depth: cam.settings.write_depth,
            ..Default::default()
        };
        let (method, note) = self.drawn_method(key, forest.asset, cam.settings.method);
        let mut record = ForestViewStats {
            note: note.clone(),
            ..Default::default()
        };
        if method.needs_models() && !self.models.contains_key(&forest.asset) {
            return None;
        }
        let Some(v) = self.renderer_for(ctx, key, forest.asset, scene, &opts, method, &mut record)
        else {
            return Some(record);
        };
        // The forest's frame: the camera moved into the forest's space, so that
        // clip = P·V·M; the sun turned with it.
        let forest_from_world = forest.world_from_forest.inverse();
        let sun = lit.sun.map(|s| light::Sun {
            to_light: forest_from_world.transform_vector3(s.to_light),
            ..s
        });
        let lighting = light::lighting(sun, cam.ambient, view.camera.exposure);
        let wind = light::wind_in_forest(lit.wind, forest_from_world);
        let view_from_world = view.world_from_view.inverse();
        let frame = FrameParams {
            view: light::mat_to_forest(view_from_world * forest.world_from_forest),
            proj: light::mat_to_forest(view.clip_from_world * view.world_from_view),
            viewport: view.viewport,
            epsilon: cam.settings.epsilon,
            light: lighting,
            wind,
            season: lit.season,
        };
        poll_counters(ctx, v, note);
        if let Some(last) = &v.last {
            record = last.clone();
        }
        // A season out of range is said (every frame: the record above is a late one), and
        // the models' own colours drawn.
        let frame = match forest_format::colour::check_season(frame.season) {
            Ok(()) => frame,
            Err(e) => {
                record.error = Some(format!("ForestSeason: {e}"));
                FrameParams {
                    season: None,
                    ..frame
                }
            }
        };
        // Bevy's shadow cascades for this view: received, and cast into.
        let cascades = lit.cascades;
        receive_cascades(ctx, v, view.shadow_maps, cascades, &mut record);
        let sharpen = method.method().quad_sharpen();
        for c in cascades {
            let key = (view.main, forest.entity, c.layer);
            let light = shadows::light_params(c, lighting.sun_dir, frame.eye());
            let (asset, res) = (forest.asset, c.resolution);
            if self.cast(
                ctx,
                key,
                asset,
                scene,
                res,
                sharpen,
                (&light, wind),
                &mut record,
            ) {
                live_casters.insert(key);
                self.casts
                    .entry(view.main)
                    .or_default()
                    .push((c.light_view, key));
            }
        }
        let v = self.streams.get_mut(&key)?;
        match v.renderer.prepare(&ctx.queue, &frame) {
            Ok(()) => v.prepared = true,
            Err(e) => record.error = Some(e.to_string()),
        }
        Some(record)
    }

    /// The stream casting a forest into one cascade layer (`key`) of a view, (re)built for
    /// another asset or map size, cast with the aspect sharpening the view draws its quads
    /// with, its light written and its trees moved by the view's wind. Whether it casts this frame; the quads it cast in a recent
    /// frame are added to `record`, and what went wrong is said there.
    #[allow(clippy::too_many_arguments)]
    fn cast(
        &mut self,
        ctx: &GpuContext,
        key: CasterId,
        asset: AssetId<ForestAsset>,
        scene: &Arc<GpuScene>,
        resolution: u32,
        sharpen: Option<u32>,
        (light, wind): (
            &forest_render::shadow::LightParams,
            forest_format::wind::Wind,
        ),
        record: &mut ForestViewStats,
    ) -> bool {
        let opts = RendererOptions {
            depth_format: wgpu::TextureFormat::Depth32Float,
            reverse_z: true,
            viewport: (resolution, resolution),
            min_epsilon: forest_render::shadow::ShadowOptions::default().epsilon,
            overdraw: 0.25,
            ..Default::default()
        };
        let built = self.casters.get(&key);
        if built.is_none_or(|k| k.asset != asset || *k.stream.options_built() != opts) {
            match QuadStream::new(&ctx.device, scene.clone(), &opts) {
                Ok(stream) => {
                    let caster = Caster {
                        asset,
                        stream,
                        quads: 0,
                    };
                    self.casters.insert(key, caster);
                }
                Err(e) => {
                    self.casters.remove(&key);
                    record.error = Some(format!("shadow caster: {e}"));
                    return false;
                }
            }
        }
        let Some(caster) = self.casters.get_mut(&key) else {
            return false;
        };
        if let Err(e) = caster.stream.set_wind(wind) {
            record.error = Some(format!("shadow caster: {e}"));
            return false;
        }
        if let Err(e) = caster.stream.set_sharpen_override(sharpen) {
            record.error = Some(format!("shadow caster: {e}"));
            return false;
        }
        if let Some(s) = caster.stream.poll_stats(&ctx.device, &ctx.queue) {
            if let Err(e) = caster.stream.fit(&ctx.device, &s) {
                record.error = Some(format!("shadow caster: {e}"));
            }
            caster.quads = s.quads;
        }
        record.cast_quads += caster.quads;
        match caster.stream.prepare_light(&ctx.device, &ctx.queue, light) {
            Ok(()) => true,
            Err(e) => {
                record.error = Some(format!("shadow caster: {e}"));
                false
            }
        }
    }
}

/// Counters of a recent frame read into the view's last record; a stream that overflowed
/// grows (the next frames draw everything).
fn poll_counters(ctx: &GpuContext, v: &mut ViewStream, note: Option<String>) {
    let Some(s) = v.renderer.poll_stats(&ctx.device, &ctx.queue) else {
        return;
    };
    let quads = s.stream.quads;
    let mut fresh = ForestViewStats {
        visible_trees: s.visible_trees,
        quads,
        triangles: s.primitives.saturating_sub(u64::from(quads)),
        geometry_trees: s.geometry_trees,
        cast_quads: 0,
        gpu_ms: s.times.map(|t| t.total_ms()),
        error: None,
        note,
    };
    if let Err(e) = v.renderer.fit(&ctx.device, &s) {
        fresh.error = Some(e.to_string());
    }
    v.last = Some(fresh);
}

/// Bevy's map bound again only when it is another texture or another cascade count; the
/// cascades' matrices are written every frame.
fn receive_cascades(
    ctx: &GpuContext,
    v: &mut ViewStream,
    shadow_maps: Option<(&ViewLightEntities, &ViewShadowBindings)>,
    cascades: &[shadows::HostCascade],
    record: &mut ForestViewStats,
) {
    let maps = shadow_maps
        .filter(|_| !cascades.is_empty())
        .map(|(_, b)| (&*b.directional_light_depth_texture, cascades.len()));
    if maps != v.receiving.as_ref().map(|(t, n)| (t, *n)) {
        match maps {
            Some((texture, n)) => {
                let array = texture.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2Array),
                    base_array_layer: 0,
                    array_layer_count: Some(n as u32),
                    ..Default::default()
                });
                let resolution = cascades[0].resolution;
                v.renderer
                    .receive_host_shadows(&ctx.device, Some((&array, resolution, true)));
            }
            None => v.renderer.receive_host_shadows(&ctx.device, None),
        }
        v.receiving = maps.map(|(t, n)| (t.clone(), n));
    }
    if v.receiving.is_some() {
        let host: Vec<_> = cascades.iter().map(|c| c.cascade).collect();
        if let Err(e) = v.renderer.set_host_cascades(&host) {
            record.error = Some(e.to_string());
        }
    }
}

/// The format the forest's pipelines draw a view of `format` in: its sRGB twin for the
/// 8-bit UNORM formats Bevy keeps sRGB-encoded colour in, else `format` itself.
pub(super) fn drawn_format(format: wgpu::TextureFormat) -> wgpu::TextureFormat {
    match format {
        wgpu::TextureFormat::Rgba8Unorm => wgpu::TextureFormat::Rgba8UnormSrgb,
        wgpu::TextureFormat::Bgra8Unorm => wgpu::TextureFormat::Bgra8UnormSrgb,
        other => other,
    }
}
