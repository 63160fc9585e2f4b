//! Exact fragment counts: a diagnostic mode in which every tree fragment invocation of every
//! method adds one to a per-pixel counter (`shaders/count_on.wgsl`, bind group 1 of the
//! counting pipelines). Lavapipe's pipeline statistics count its 4×4 stamps; these count
//! pixels, with the 2×2-quad lanes a GPU runs beside them.
//!
//! A counted frame is drawn twice with the same camera: [`Phase::Count`] counts invocations,
//! quad lanes and shown fragments and records each pixel's nearest opaque fragment, then
//! [`Phase::Hidden`] counts the shown fragments behind that front. The ground and sky are not
//! counted.

/// The overdraw view: the counts as a heat map with a legend (`passes/overdraw.rs`).
pub use crate::passes::overdraw::{
    LABELLED_SIDE, OVERDRAW_COLOURS, OverdrawBinding, OverdrawParams, OverdrawPass, band,
    band_floor, legend_side,
};
use crate::{GpuContext, RenderError};

/// Counters per pixel (see `shaders/count_on.wgsl`).
pub const COUNT_STRIDE: usize = 7;

/// Binding of the counters in group 1.
pub const COUNTS_BINDING: u32 = 0;
/// Binding of [`CountParams`] in group 1.
pub const PARAMS_BINDING: u32 = 1;

/// `CountParams` of `shaders/count_on.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CountParams {
    /// Target width (pixels).
    pub width: u32,
    /// Target height (pixels).
    pub height: u32,
    /// 0: [`Phase::Count`]; 1: [`Phase::Hidden`].
    pub phase: u32,
    /// 1 with reversed depth.
    pub reverse_z: u32,
}

/// Which of a counted frame's two draws is next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Count invocations, quad lanes and shown fragments; record the opaque front.
    Count,
    /// Count the shown fragments behind the recorded front (the same frame again).
    Hidden,
}

/// Layout of the counting pipelines' group 1: the counters and their parameters.
pub fn layout_entries() -> [wgpu::BindGroupLayoutEntry; 2] {
    [
        wgpu::BindGroupLayoutEntry {
            binding: COUNTS_BINDING,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: false },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        },
        wgpu::BindGroupLayoutEntry {
            binding: PARAMS_BINDING,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        },
    ]
}

/// The bind-group layout of [`layout_entries`].
pub fn bind_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("fragment counts"),
        entries: &layout_entries(),
    })
}

/// The per-pixel counters of one target size, and their bind group. Renderers draw with their
/// counting pipelines while one is attached (`set_fragment_counter`).
pub struct FragmentCounter {
    counts: wgpu::Buffer,
    params: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    width: u32,
    height: u32,
    reverse_z: bool,
}

impl FragmentCounter {
    /// The counters' size in bytes for a `width` × `height` target, checked against the
    /// device's storage-buffer limit: a front end calls it before drawing anything, so that a
    /// size too large is refused before the work, not after.
    pub fn check_size(device: &wgpu::Device, width: u32, height: u32) -> Result<u64, RenderError> {
        if width == 0 || height == 0 {
            return Err(RenderError::Parameter(format!(
                "fragment counts need a target of at least 1×1 pixels, not {width}×{height}"
            )));
        }
        let bytes = u64::from(width) * u64::from(height) * (COUNT_STRIDE * 4) as u64;
        crate::error::within_limit(
            || format!("fragment counts of a {width}×{height} target (bytes)"),
            bytes,
            crate::error::storage_limit(&device.limits()),
            ": count at a smaller size",
        )?;
        Ok(bytes)
    }

    /// Counters for a `width` × `height` target (the fragment positions of the draws counted;
    /// positions outside it are clamped onto its edge). Checks the size against the device's
    /// storage-buffer limit before allocating.
    pub fn new(
        device: &wgpu::Device,
        width: u32,
        height: u32,
        reverse_z: bool,
    ) -> Result<Self, RenderError> {
        let bytes = Self::check_size(device, width, height)?;
        use wgpu::BufferUsages as U;
        let counts = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fragment counts"),
            size: bytes,
            usage: U::STORAGE | U::COPY_SRC | U::COPY_DST,
            mapped_at_creation: false,
        });
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fragment count parameters"),
            size: std::mem::size_of::<CountParams>() as u64,
            usage: U::UNIFORM | U::COPY_DST,
            mapped_at_creation: false,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("fragment counts"),
            layout: &bind_layout(device),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: COUNTS_BINDING,
                    resource: counts.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: PARAMS_BINDING,
                    resource: params.as_entire_binding(),
                },
            ],
        });
        Ok(Self {
            counts,
            params,
            bind_group,
            width,
            height,
            reverse_z,
        })
    }

    /// The group-1 bind group of the counting pipelines.
    pub fn bind_group(&self) -> &wgpu::BindGroup {
        &self.bind_group
    }

    /// The counters, [`COUNT_STRIDE`] `u32`s per pixel, row-major from the top left.
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.counts
    }

    /// Target size (pixels).
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Zero the counters and set the phase to [`Phase::Count`] (before a counted frame's
    /// first draw).
    pub fn begin(&self, ctx: &GpuContext) {
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&self.counts, 0, None);
        ctx.queue.submit([enc.finish()]);
        self.set_phase(&ctx.queue, Phase::Count);
    }

    /// Set the phase of the draws submitted next.
    pub fn set_phase(&self, queue: &wgpu::Queue, phase: Phase) {
        let p = CountParams {
            width: self.width,
            height: self.height,
            phase: u32::from(phase == Phase::Hidden),
            reverse_z: u32::from(self.reverse_z),
        };
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
    }

    /// Count one frame: clear, `draw` it in [`Phase::Count`], `draw` the same frame again in
    /// [`Phase::Hidden`], and read the counts back (waits for the GPU). `draw` must submit
    /// the frame of the renderers this counter is attached to, into a target of
    /// [`Self::size`].
    pub fn count_frame<E>(
        &self,
        ctx: &GpuContext,
        mut draw: impl FnMut() -> Result<(), E>,
    ) -> Result<FragmentCounts, E> {
        self.begin(ctx);
        draw()?;
        self.set_phase(&ctx.queue, Phase::Hidden);
        draw()?;
        Ok(self.read(ctx))
    }

    /// The counts of the frames drawn since [`Self::begin`]; waits for the GPU.
    pub fn read(&self, ctx: &GpuContext) -> FragmentCounts {
        let bytes = ctx.read_buffer(&self.counts, self.counts.size());
        let words: &[u32] = bytemuck::cast_slice(&bytes);
        let pixels = words
            .chunks_exact(COUNT_STRIDE)
            .map(|c| PixelCounts {
                invocations: c[0],
                quad_lanes: c[1],
                shown: c[2],
                hidden: c[3],
            })
            .collect();
        FragmentCounts {
            width: self.width,
            height: self.height,
            pixels,
        }
    }
}

/// The exact fragment counts of one frame of `renderer` into `counter`: the counter is
/// attached with `attach`, the frame drawn twice by `draw` (see
/// [`FragmentCounter::count_frame`]) and then detached (`attach(None)`), also when `draw`
/// fails: a counter the caller had attached before is detached too. The renderer's own
/// pipelines are unchanged.
pub fn count_fragments<R, E>(
    ctx: &GpuContext,
    counter: &FragmentCounter,
    renderer: &mut R,
    attach: fn(&mut R, &wgpu::Device, Option<&FragmentCounter>),
    mut draw: impl FnMut(&mut R) -> Result<(), E>,
) -> Result<FragmentCounts, E> {
    attach(renderer, &ctx.device, Some(counter));
    let counts = counter.count_frame(ctx, || draw(renderer));
    attach(renderer, &ctx.device, None);
    counts
}

/// One pixel's counts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PixelCounts {
    /// Fragment invocations (helper lanes excluded).
    pub invocations: u32,
    /// 2×2-quad lanes (4 per quad with a live lane), at the quad's first live lane.
    pub quad_lanes: u32,
    /// Fragments that returned alpha ≥ 0.5/255.
    pub shown: u32,
    /// Shown fragments behind an opaque (alpha ≥ 1 − 0.5/255) fragment at the pixel.
    pub hidden: u32,
}

/// A counted frame's per-pixel counts, row-major from the top left.
#[derive(Clone, Debug, PartialEq)]
pub struct FragmentCounts {
    /// Width (pixels).
    pub width: u32,
    /// Height (pixels).
    pub height: u32,
    /// Counts per pixel.
    pub pixels: Vec<PixelCounts>,
}

/// What a counted frame's fragments cost, per covered pixel (a pixel with at least one shown
/// tree fragment).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FragmentSummary {
    /// Covered pixels.
    pub covered_pixels: u64,
    /// Fragment invocations in all.
    pub fragments: u64,
    /// Mean invocations per covered pixel (1 is the limit of one shaded fragment per pixel).
    pub per_covered_mean: f64,
    /// Median of invocations over covered pixels.
    pub per_covered_median: u32,
    /// 95th percentile of invocations over covered pixels.
    pub per_covered_p95: u32,
    /// 2×2-quad lanes per covered pixel (what a GPU that shades in quads runs).
    pub quad_lanes_per_covered: f64,
    /// Share of invocations that showed nothing (discarded, or alpha < 0.5/255).
    pub transparent_share: f64,
    /// Share of invocations that were shown but hidden behind an opaque fragment.
    pub hidden_share: f64,
}

impl FragmentSummary {
    /// The summary of several counted frames' pixels pooled together (a walkthrough's views):
    /// means and shares are ratios of sums, the median and 95th percentile those of every
    /// covered pixel of every frame.
    pub fn pooled(frames: &[FragmentCounts]) -> Self {
        let pixels = || frames.iter().flat_map(|f| f.pixels.iter());
        let mut covered: Vec<u32> = pixels()
            .filter(|p| p.shown > 0)
            .map(|p| p.invocations)
            .collect();
        covered.sort_unstable();
        let sum = |f: fn(&PixelCounts) -> u32| -> u64 { pixels().map(|p| u64::from(f(p))).sum() };
        let fragments = sum(|p| p.invocations);
        let lanes = sum(|p| p.quad_lanes);
        let shown = sum(|p| p.shown);
        let hidden = sum(|p| p.hidden);
        let n = covered.len() as u64;
        let ratio = |a: u64, b: u64| if b == 0 { 0.0 } else { a as f64 / b as f64 };
        let rank = |q: f64| -> u32 {
            if covered.is_empty() {
                0
            } else {
                covered[((covered.len() - 1) as f64 * q).round() as usize]
            }
        };
        FragmentSummary {
            covered_pixels: n,
            fragments,
            per_covered_mean: ratio(fragments, n),
            per_covered_median: rank(0.5),
            per_covered_p95: rank(0.95),
            quad_lanes_per_covered: ratio(lanes, n),
            transparent_share: ratio(fragments - shown.min(fragments), fragments),
            hidden_share: ratio(hidden, fragments),
        }
    }
}

impl FragmentCounts {
    /// The frame's summary.
    pub fn summary(&self) -> FragmentSummary {
        FragmentSummary::pooled(std::slice::from_ref(self))
    }

    /// Invocations per pixel, row-major.
    pub fn invocations(&self) -> Vec<u32> {
        self.pixels.iter().map(|p| p.invocations).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn counts(pixels: &[(u32, u32, u32, u32)]) -> FragmentCounts {
        FragmentCounts {
            width: pixels.len() as u32,
            height: 1,
            pixels: pixels
                .iter()
                .map(|&(invocations, quad_lanes, shown, hidden)| PixelCounts {
                    invocations,
                    quad_lanes,
                    shown,
                    hidden,
                })
                .collect(),
        }
    }

    #[test]
    fn the_summary_is_per_covered_pixel() {
        // Five pixels: one uncovered but shaded (transparent), one empty, three covered with
        // 1, 3 and 8 invocations.
        let c = counts(&[
            (2, 4, 0, 0),
            (0, 0, 0, 0),
            (1, 4, 1, 0),
            (3, 8, 2, 1),
            (8, 12, 8, 4),
        ]);
        let s = c.summary();
        assert_eq!(s.covered_pixels, 3);
        assert_eq!(s.fragments, 14);
        assert_eq!(s.per_covered_mean, 14.0 / 3.0);
        assert_eq!((s.per_covered_median, s.per_covered_p95), (3, 8));
        assert_eq!(s.quad_lanes_per_covered, 28.0 / 3.0);
        assert_eq!(s.transparent_share, 3.0 / 14.0);
        assert_eq!(s.hidden_share, 5.0 / 14.0);
        assert_eq!(c.invocations(), vec![2, 0, 1, 3, 8]);
    }

    #[test]
    fn pooled_frames_summarise_their_pixels_together() {
        let a = counts(&[(1, 4, 1, 0), (3, 8, 2, 1)]);
        let b = counts(&[(8, 12, 8, 4), (2, 4, 0, 0), (0, 0, 0, 0)]);
        let joined = counts(&[
            (1, 4, 1, 0),
            (3, 8, 2, 1),
            (8, 12, 8, 4),
            (2, 4, 0, 0),
            (0, 0, 0, 0),
        ]);
        assert_eq!(FragmentSummary::pooled(&[a, b]), joined.summary());
        assert_eq!(FragmentSummary::pooled(&[]), FragmentSummary::default());
    }

    #[test]
    fn an_empty_frame_summarises_to_zero() {
        let s = counts(&[(0, 0, 0, 0); 4]).summary();
        assert_eq!(s, FragmentSummary::default());
    }
}
