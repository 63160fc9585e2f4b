//! The sun's shadow cascades, on the CPU: the options, the split of a view's depth range,
//! each cascade's orthographic light view fitted around its slice of the view frustum, and
//! the light-view cameras the quad stream culls, refines and draws for (one per cascade).
//!
//! Fitting follows the usual stable scheme (practical split, after Zhang et al.'s parallel-split
//! shadow maps): each slice of the view frustum is enclosed by a sphere whose radius depends only
//! on the slice (not on where the camera looks), and the sphere's centre is snapped to the
//! cascade's texel grid in a light frame that depends only on the sun. Moving or turning the
//! camera therefore moves every cascade by whole texels and never rescales it: the shadows do not
//! swim.
//!
//! No wgpu here: `shadow_maps.rs` owns the maps and their passes.

use glam::{Mat4, Vec3, Vec4};

use crate::gpu_types::GpuCamera;

/// Most cascades (the camera uniform holds four matrices).
pub const MAX_CASCADES: u32 = 4;
/// Smallest and largest shadow-map side (texels).
pub const RESOLUTION_RANGE: (u32, u32) = (64, 8192);

/// How the sun's shadows are made and looked up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowOptions {
    /// Cascades, 1 to [`MAX_CASCADES`].
    pub cascades: u32,
    /// Side of each cascade's map, texels (a power of two is not required).
    pub resolution: u32,
    /// Shadows end this far from the eye along the view (metres), or at the view's far plane
    /// if that is nearer.
    pub distance: f32,
    /// Where the splits lie between uniform (0) and logarithmic (1) spacing.
    pub split_lambda: f32,
    /// The light views' refinement threshold ε, in texels.
    pub epsilon: f32,
    /// How far towards the sun beyond a cascade's sphere casters are still drawn (metres):
    /// at least the tallest tree's height over the sine of the lowest sun wanted.
    pub reach: f32,
    /// Receivers look their shadow up this many texels towards the sun and along their normal
    /// (the bias against acne; it also bounds the peter-panning, see `docs/shadows.md`).
    pub offset_texels: f32,
    /// Cast, into each cascade, only the trees whose shadow can reach that cascade's slice of
    /// the view ([`caster_planes`]); off, every tree in the cascade's box casts. The maps'
    /// lookups are the same either way; off is for checking that.
    pub cull_casters: bool,
}

impl Default for ShadowOptions {
    /// Three cascades of 1024² over the first 300 m, refined to 32 texels.
    fn default() -> Self {
        Self {
            cascades: 3,
            resolution: 1024,
            distance: 300.0,
            split_lambda: 0.8,
            epsilon: 32.0,
            reach: 120.0,
            offset_texels: 1.5,
            cull_casters: true,
        }
    }
}

impl ShadowOptions {
    /// Refuse options out of their ranges, naming the option.
    pub fn validate(&self) -> Result<(), String> {
        if !(1..=MAX_CASCADES).contains(&self.cascades) {
            return Err(format!(
                "shadow cascades {}: expected 1 to {MAX_CASCADES}",
                self.cascades
            ));
        }
        let (lo, hi) = RESOLUTION_RANGE;
        if !(lo..=hi).contains(&self.resolution) {
            return Err(format!(
                "shadow resolution {}: expected {lo} to {hi} texels",
                self.resolution
            ));
        }
        let positive = [
            ("shadow distance", self.distance),
            ("shadow epsilon", self.epsilon),
        ];
        for (what, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("{what} {v}: expected a positive number"));
            }
        }
        if !(self.reach.is_finite() && self.reach >= 0.0) {
            return Err(format!(
                "shadow reach {}: expected 0 or more metres",
                self.reach
            ));
        }
        if !(0.0..=1.0).contains(&self.split_lambda) {
            return Err(format!(
                "shadow split lambda {}: expected 0 (uniform) to 1 (logarithmic)",
                self.split_lambda
            ));
        }
        if !(0.0..=16.0).contains(&self.offset_texels) {
            return Err(format!(
                "shadow offset {} texels: expected 0 to 16",
                self.offset_texels
            ));
        }
        Ok(())
    }
}

/// One cascade: the slice of the view it covers and its light view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cascade {
    /// View depths (metres along the view direction) where the slice begins and ends.
    pub split: (f32, f32),
    /// Centre of the sphere enclosing the slice (world), after snapping.
    pub centre: Vec3,
    /// The sphere's radius (metres): the map spans 2·radius across.
    pub radius: f32,
    /// World → shadow clip (orthographic; depth 0 at the sun's end of the box, 1 at the other).
    pub view_proj: Mat4,
    /// One texel's width (metres).
    pub texel: f32,
    /// Depth of the box (metres), from its sun end to its far end.
    pub depth_range: f32,
}

/// The view a cascade set is fitted to: its clip matrix, eye and unit view direction.
#[derive(Clone, Copy, Debug)]
pub struct ViewSlice {
    /// Projection × view (any perspective projection into wgpu's clip space).
    pub view_proj: Mat4,
    /// Eye (world).
    pub eye: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
}

impl ViewSlice {
    /// The near and far distances of the view along its direction (the far one may be
    /// infinite), and the widest lateral offset of the frustum's edges per metre of depth.
    fn extent(&self) -> (f32, f32, f32) {
        let inv = self.view_proj.inverse();
        let (d0, _) = self.depth_at(inv, 0.0, 0.0, 0.0);
        let (d1, _) = self.depth_at(inv, 0.0, 0.0, 1.0);
        let near = d0.min(d1).max(1e-3);
        let far = d0.max(d1);
        let k = self
            .corner_rays(inv)
            .iter()
            .map(|r| (*r - self.forward).length())
            .fold(0.0f32, f32::max);
        (near, far, k)
    }

    /// The view depth of clip point (x, y, z) and its offset from the eye (for a point at
    /// infinity, an infinite depth and its direction); `inv` is the inverse of `view_proj`.
    fn depth_at(&self, inv: Mat4, x: f32, y: f32, z: f32) -> (f32, Vec3) {
        let h = inv * Vec4::new(x, y, z, 1.0);
        if h.w.abs() < 1e-12 {
            return (f32::INFINITY, h.truncate());
        }
        let p = h.truncate() / h.w;
        (self.forward.dot(p - self.eye), p - self.eye)
    }

    /// The frustum's four corner rays, each scaled to advance one metre along the view
    /// (those that do not advance are left out); `inv` is the inverse of `view_proj`.
    fn corner_rays(&self, inv: Mat4) -> Vec<Vec3> {
        [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)]
            .iter()
            .filter_map(|&(x, y)| {
                // A point halfway through the depth range lies on the corner's ray.
                let (d, r) = self.depth_at(inv, x, y, 0.5);
                let r = if d < 0.0 { -r } else { r };
                let along = r.dot(self.forward);
                (along > 1e-9).then(|| r / along)
            })
            .collect()
    }

    /// The view depths within `[near, end]` where the view's cross-section meets `band`
    /// (widened by 0.5 m and 1 %), or `[near, end]` when it never does. Each corner ray's
    /// height is linear in depth, so the set's bounds are among the depths where a corner ray
    /// crosses the band's edges.
    fn band_depths(&self, band: ReceiverBand, near: f32, end: f32) -> (f32, f32) {
        if band == ReceiverBand::ANY {
            return (near, end);
        }
        let pad = |h: f32| 0.5 + 0.01 * h.abs();
        let (floor, top) = (band.floor - pad(band.floor), band.top + pad(band.top));
        // Each corner ray's height gained per metre of depth.
        let slopes: Vec<f32> = self
            .corner_rays(self.view_proj.inverse())
            .iter()
            .map(|r| r.y)
            .collect();
        if slopes.len() < 4 {
            return (near, end);
        }
        let y = self.eye.y;
        let meets = |d: f32| {
            let (lo, hi) = slopes.iter().fold((f32::MAX, f32::MIN), |(lo, hi), s| {
                (lo.min(y + d * s), hi.max(y + d * s))
            });
            lo <= top && hi >= floor
        };
        let mut candidates = vec![near, end];
        for s in &slopes {
            if s.abs() > 1e-9 {
                for h in [floor, top] {
                    candidates.push(((h - y) / s).clamp(near, end));
                }
            }
        }
        let hits: Vec<f32> = candidates.into_iter().filter(|&d| meets(d)).collect();
        let lo = hits.iter().copied().fold(f32::MAX, f32::min);
        let hi = hits.iter().copied().fold(f32::MIN, f32::max);
        if hi > lo { (lo, hi) } else { (near, end) }
    }
}

/// The heights (world y, metres) between which anything can receive a shadow: the lowest
/// ground and the highest tree top or ground. Cascades cover only the part of the view between
/// them, and nothing casts below `floor`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReceiverBand {
    /// The lowest ground: the terrain's lowest sample, or the flat ground's 0 around it.
    pub floor: f32,
    /// The highest point of a tree's bounding sphere or of the ground.
    pub top: f32,
}

impl ReceiverBand {
    /// Every height: cascades cover the whole view up to the shadow distance.
    pub const ANY: Self = Self {
        floor: f32::MIN,
        top: f32::MAX,
    };

    /// The band of a forest: its trees (`instances`, with their species' object-space
    /// bounding `spheres`, centre and radius) over its `terrain`.
    pub fn of(
        instances: &[crate::gpu_types::GpuInstance],
        spheres: &[[f32; 4]],
        terrain: Option<&forest_format::terrain::Terrain>,
    ) -> Self {
        let (lo, hi) = terrain.map_or((0.0, 0.0), |t| t.height_range());
        let top = instances
            .iter()
            .filter_map(|i| {
                let s = spheres.get(i.species as usize)?;
                Some(i.position[1] + (s[1] + s[3]) * i.scale)
            })
            .fold(hi.max(0.0), f32::max);
        Self {
            floor: lo.min(0.0),
            top,
        }
    }
}

/// The view depths where the cascades split: `n + 1` values from `near` to `end`, blending
/// logarithmic and uniform spacing by `lambda`.
pub fn split_depths(near: f32, end: f32, n: u32, lambda: f32) -> Vec<f32> {
    (0..=n)
        .map(|i| {
            let t = i as f32 / n as f32;
            let log = near * (end / near).powf(t);
            let uni = near + (end - near) * t;
            lambda * log + (1.0 - lambda) * uni
        })
        .collect()
}

/// The smallest sphere about the view axis enclosing the frustum slice between depths `a` and
/// `b` whose edges spread `k` metres laterally per metre of depth: its centre's depth and its
/// radius. It depends on the slice alone, not on where the view looks.
pub fn slice_sphere(a: f32, b: f32, k: f32) -> (f32, f32) {
    let k2 = 1.0 + k * k;
    let z = (0.5 * (a + b) * k2).clamp(a, b);
    let r = ((z - a).powi(2) + (a * k).powi(2))
        .sqrt()
        .max(((b - z).powi(2) + (b * k).powi(2)).sqrt());
    (z, r)
}

/// A light frame that depends on the sun alone: world → light view (a rotation; the light
/// looks along −`sun`).
pub fn light_rotation(sun: Vec3) -> Mat4 {
    let up = if sun.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    glam::camera::rh::view::look_at_mat4(Vec3::ZERO, -sun, up)
}

/// The cascades of `view` under a sun in unit direction `sun` (towards the sun), over the
/// part of the view (up to the shadow distance) where receivers in `band` can be.
pub fn fit_cascades(
    view: &ViewSlice,
    sun: Vec3,
    opts: &ShadowOptions,
    band: ReceiverBand,
) -> Vec<Cascade> {
    let sun = sun.normalize_or(Vec3::Y);
    let (near, far, k) = view.extent();
    let end = opts.distance.min(far).max(near * 1.001);
    let (near, end) = view.band_depths(band, near, end);
    let splits = split_depths(near, end, opts.cascades, opts.split_lambda);
    let rot = light_rotation(sun);
    let res = opts.resolution as f32;
    splits
        .windows(2)
        .map(|s| {
            let (z, radius) = slice_sphere(s[0], s[1], k);
            // Round the radius up to a 1/64 of its power of two, so that rounding noise in
            // the view's matrices cannot rescale the map from frame to frame.
            let quantum = radius.max(1e-3).log2().ceil().exp2() / 64.0;
            let radius = (radius / quantum).ceil() * quantum;
            let texel = 2.0 * radius / res;
            let c = rot.transform_point3(view.eye + view.forward * z);
            // Whole texels in the sun's frame: the map moves without swimming.
            let cx = (c.x / texel).round() * texel;
            let cy = (c.y / texel).round() * texel;
            let centre = rot.inverse().transform_point3(Vec3::new(cx, cy, c.z));
            // The box runs from `reach` beyond the sphere on the sun's side to its far side.
            let near_l = -c.z - radius - opts.reach;
            let far_l = -c.z + radius;
            let proj = glam::camera::rh::proj::directx::orthographic(
                cx - radius,
                cx + radius,
                cy - radius,
                cy + radius,
                near_l,
                far_l,
            );
            Cascade {
                split: (s[0], s[1]),
                centre,
                radius,
                view_proj: proj * rot,
                texel,
                depth_range: far_l - near_l,
            }
        })
        .collect()
}

/// Write the cascades into the view's camera uniform (what its receivers look up).
pub fn write_receivers(g: &mut GpuCamera, cascades: &[Cascade], opts: &ShadowOptions) {
    write_receivers_of(g, cascades, opts.resolution, opts.offset_texels, false);
}

/// [`write_receivers`] for any maps (a host's): each cascade's matrix, far split, texel and
/// depth range are read; `resolution` is the maps' side in texels, `offset_texels` the
/// receivers' offset, `reverse_z` the maps' depth convention.
pub fn write_receivers_of(
    g: &mut GpuCamera,
    cascades: &[Cascade],
    resolution: u32,
    offset_texels: f32,
    reverse_z: bool,
) {
    let n = cascades.len().min(MAX_CASCADES as usize);
    for (i, c) in cascades.iter().take(n).enumerate() {
        g.shadow[i] = c.view_proj.to_cols_array_2d();
        g.shadow_splits[i] = c.split.1;
        g.shadow_texel[i] = c.texel;
        // Half a texel of slope at 45° plus the depth quantum: the comparison's own rounding.
        g.shadow_bias[i] = 0.5 * c.texel / c.depth_range + 1e-6;
    }
    g.shadow_cascades = n as f32;
    g.shadow_side = resolution as f32;
    g.shadow_offset = offset_texels;
    g.shadow_reverse_z = if reverse_z { 1.0 } else { 0.0 };
}

/// A host's light view, for the forest to cast into the host's own shadow map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightParams {
    /// World → the host's shadow clip (orthographic for a sun; wgpu depth 0..1, standard or
    /// reverse-Z as the casting stream's [`crate::RendererOptions`] say).
    pub view_proj: Mat4,
    /// Unit direction towards the light (world): it picks each tree's aspects.
    pub to_light: Vec3,
    /// The map's size in texels.
    pub resolution: (u32, u32),
    /// The refinement threshold ε, in texels.
    pub epsilon: f32,
    /// The eye of the view the shadows are for: each tree casts in the form that view draws
    /// it in (the hybrid's forms are measured from it).
    pub view_eye: Vec3,
}

impl LightParams {
    /// Check every field; the error names the bad one.
    pub fn validate(&self) -> Result<(), String> {
        if !(self.view_proj.is_finite() && self.view_proj.determinant().abs() > f32::MIN_POSITIVE) {
            return Err("the light's view-projection must be finite and invertible".into());
        }
        if !self.to_light.is_finite() || (self.to_light.length() - 1.0).abs() >= 1e-3 {
            return Err(format!(
                "the direction towards the light {} must be a unit vector",
                self.to_light
            ));
        }
        if self.resolution.0 == 0 || self.resolution.1 == 0 {
            return Err(format!("the light's map {:?} is empty", self.resolution));
        }
        if !(self.epsilon.is_finite() && self.epsilon > 0.0) {
            return Err(format!("light epsilon {} must be positive", self.epsilon));
        }
        if !self.view_eye.is_finite() {
            return Err("the view's eye must be finite".into());
        }
        Ok(())
    }

    /// The light camera a stream casts with: the host's matrix, the eye far along the light
    /// from the middle of the light's box (so every tree is seen from the light's direction),
    /// ε in texels, forms chosen from the view's eye, far trees as the stream's options say.
    pub fn camera(&self, stream: crate::options::StreamOptions) -> GpuCamera {
        let inv = self.view_proj.inverse();
        let centre = inv.project_point3(Vec3::new(0.0, 0.0, 0.5));
        let reach = [
            (-1.0, -1.0, 0.0),
            (1.0, 1.0, 1.0),
            (-1.0, 1.0, 0.0),
            (1.0, -1.0, 1.0),
        ]
        .iter()
        .map(|&(x, y, z)| inv.project_point3(Vec3::new(x, y, z)).distance(centre))
        .fold(1.0f32, f32::max);
        let mut g = towards(
            self.view_proj,
            (centre, reach),
            self.to_light,
            self.resolution,
            self.epsilon,
            stream,
        );
        g.form_eye = self.view_eye.extend(0.0).to_array();
        g
    }
}

/// The camera a cascade's light-view stream culls, refines and draws with: the cascade's
/// matrix, the eye far along the sun (so every tree is seen from the sun's direction and
/// picks its aspects by it), ε in texels, and the stream's options (far trees, narrower than
/// the far span in texels, cast as one composited quad of their nearest aspect).
pub fn light_camera(
    c: &Cascade,
    sun: Vec3,
    opts: &ShadowOptions,
    stream: crate::options::StreamOptions,
) -> GpuCamera {
    towards(
        c.view_proj,
        (c.centre, (c.radius + opts.reach).max(1.0)),
        sun,
        (opts.resolution, opts.resolution),
        opts.epsilon,
        stream,
    )
}

/// A light view's camera: matrix `view_proj`, the eye 10⁴ × `reach` along `to_light` from
/// `centre` (far enough that the direction to any tree within `reach` of it is the light's
/// within 1e-4 rad), ε in texels, the stream's options.
fn towards(
    view_proj: Mat4,
    (centre, reach): (Vec3, f32),
    to_light: Vec3,
    resolution: (u32, u32),
    epsilon: f32,
    stream: crate::options::StreamOptions,
) -> GpuCamera {
    let to_light = to_light.normalize_or(Vec3::Y);
    let mut g = crate::camera::gpu_camera(
        view_proj,
        centre + to_light * (1e4 * reach),
        -to_light,
        resolution,
        epsilon,
    );
    stream.apply(&mut g);
    g
}

/// [`light_camera`] for the view `view`: its forms, and the distances that choose them
/// measured from its eye, so that each tree casts in the form the view draws it in; and the
/// cascade's receiver region ([`caster_planes`]) over ground no lower than `floor` (metres).
pub fn light_camera_for(
    view: &GpuCamera,
    c: &Cascade,
    light: &forest_format::shading::Lighting,
    opts: &ShadowOptions,
    stream: crate::options::StreamOptions,
    floor: f32,
) -> GpuCamera {
    let mut l = light_camera(c, light.sun_dir, opts, stream);
    l.set_light(light);
    l.forms = view.forms;
    l.form_eye = view.form_eye;
    // The trees cast where the view draws them, moved by the same wind.
    (l.wind, l.wind_time) = (view.wind, view.wind_time);
    (l.casters, l.caster_floor) = caster_planes(view, c, opts, floor);
    l
}

/// The region whose shadows cascade `c` of `view` serves, for culling its casters: the
/// view's four side planes and the slice's two depth planes, each moved out by 4 of the
/// cascade's texels (the receivers' offset and filter taps reach less far); receivers no
/// lower than `floor` (world height, metres); sweeps of at most the cascade box's own reach
/// (`opts.reach` plus the sphere's diameter), so that nothing the box holds and a receiver
/// can see is ever dropped. A tree's receivers look up at most its sphere's diameter towards
/// the sun from a visible point, on the ray a caster's shadow follows, so they are covered.
pub fn caster_planes(
    view: &GpuCamera,
    c: &Cascade,
    opts: &ShadowOptions,
    floor: f32,
) -> ([[f32; 4]; 6], [f32; 4]) {
    if !opts.cull_casters {
        return Default::default();
    }
    let eye = Vec3::from_slice(&view.eye[..]);
    let forward = Vec3::from_slice(&view.forward[..]).normalize_or(Vec3::NEG_Z);
    let margin = 4.0 * c.texel;
    let at = forward.dot(eye);
    let planes = [
        view.planes[0],
        view.planes[1],
        view.planes[2],
        view.planes[3],
        forward.extend(-at - c.split.0).to_array(),
        (-forward).extend(at + c.split.1).to_array(),
    ]
    .map(|p| [p[0], p[1], p[2], p[3] + margin]);
    (planes, [floor, opts.reach + 2.0 * c.radius, 0.0, 0.0])
}

/// Whether a caster's bounding sphere (world centre `c`, radius `r`) can shadow the receiver
/// region of light camera `cam` (its `casters` and `caster_floor`; every sphere when they are
/// zero): the CPU mirror of `casts_into` in `shaders/common.wgsl`.
pub fn casts_into(cam: &GpuCamera, c: Vec3, r: f32) -> bool {
    let sun = Vec3::from_slice(&cam.sun[..]);
    let mut sweep = cam.caster_floor[1];
    if sun.y > 1e-3 {
        sweep = sweep.min((c.y + r - cam.caster_floor[0]).max(0.0) / sun.y);
    }
    cam.casters.iter().all(|pl| {
        let n = Vec3::new(pl[0], pl[1], pl[2]);
        n.dot(c) + pl[3] + sweep * (-n.dot(sun)).max(0.0) >= -r
    })
}

/// The frame's cameras with shadows: `view` (the view's camera, light and options already in
/// it) with its cascades written in, then each cascade's light camera under `light`, for
/// receivers in `band`. What a stream with shadows writes in its one upload.
pub fn cameras(
    view: &GpuCamera,
    light: &forest_format::shading::Lighting,
    opts: &ShadowOptions,
    stream: crate::options::StreamOptions,
    band: ReceiverBand,
) -> Vec<GpuCamera> {
    let slice = ViewSlice {
        view_proj: Mat4::from_cols_array_2d(&view.view_proj),
        eye: Vec3::from_slice(&view.eye[..]),
        forward: Vec3::from_slice(&view.forward[..]),
    };
    let cascades = fit_cascades(&slice, light.sun_dir, opts, band);
    let floor = band.floor.max(-1e30);
    let mut out = vec![*view];
    write_receivers(&mut out[0], &cascades, opts);
    out.extend(
        cascades
            .iter()
            .map(|c| light_camera_for(view, c, light, opts, stream, floor)),
    );
    out
}

#[cfg(test)]
mod tests;
