//! Counters and pass times of a frame, and a ring of read-back buffers that returns them
//! without stalling: each [`StatsRing::poll`] copies the counters of the last submitted frame
//! into a free slot and maps it asynchronously; a later call returns the newest mapped slot,
//! so statistics arrive a few frames late and the CPU never waits for the GPU.

use std::sync::Arc;
use std::sync::atomic::{AtomicU8, AtomicU64, Ordering};

/// Slots in the ring: a frame's statistics are at most this many polls late.
pub const STATS_SLOTS: usize = 3;

const FREE: u8 = 0;
const MAPPING: u8 = 1;
const READY: u8 = 2;

/// Per-pass GPU times in milliseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PassTimes {
    /// Cull.
    pub cull_ms: f64,
    /// Refine (all iterations and statistics).
    pub refine_ms: f64,
    /// Draw (ground and quads).
    pub draw_ms: f64,
}

impl PassTimes {
    /// The three passes together (milliseconds).
    pub fn total_ms(&self) -> f64 {
        self.cull_ms + self.refine_ms + self.draw_ms
    }
}

/// Counters of the last frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameStats {
    /// Presort direction used.
    pub presort: u32,
    /// Trees that passed the frustum test.
    pub visible_trees: u32,
    /// Quads drawn.
    pub quads: u32,
    /// Of those, far trees' composited quads (the stream's first).
    pub composites: u32,
    /// Quads per level.
    pub per_level: Vec<u32>,
    /// Level-0 quads dropped for lack of room.
    pub overflow_cull: u32,
    /// Quads left unrefined for lack of room.
    pub overflow_refine: u32,
    /// GPU pass times, where the adapter has timestamp queries.
    pub times: Option<PassTimes>,
    /// The work the frame asked of the GPU (counts; see [`crate::work`]).
    pub work: crate::work::FrameWork,
}

/// The optional parts of a ring's read-back, for a ring whose sources are a renderer's
/// counters, then its resolved timestamps (when `times`), then its pipeline statistics (when
/// `statistics`): `(timestamps, statistics)`.
pub fn query_parts(
    parts: &[Vec<u8>],
    times: bool,
    statistics: bool,
) -> (Option<&[u8]>, Option<&[u8]>) {
    let at = |present: bool, k: usize| present.then(|| parts.get(k)).flatten().map(Vec::as_slice);
    (at(times, 1), at(statistics, 1 + usize::from(times)))
}

struct Slot {
    buffer: wgpu::Buffer,
    state: Arc<AtomicU8>,
    sequence: AtomicU64,
}

/// Read-back buffers for a set of GPU buffers (the sources), copied one after another.
pub struct StatsRing {
    slots: Vec<Slot>,
    sources: Vec<(wgpu::Buffer, u64)>,
    next: AtomicU64,
}

impl StatsRing {
    /// A ring reading the first `size` bytes of each source (`COPY_SRC` buffers; sizes are
    /// rounded up to 4 bytes).
    pub fn new(device: &wgpu::Device, sources: Vec<(wgpu::Buffer, u64)>) -> Self {
        let sources: Vec<(wgpu::Buffer, u64)> = sources
            .into_iter()
            .map(|(b, n)| (b, n.next_multiple_of(4)))
            .collect();
        let total: u64 = sources.iter().map(|(_, n)| n).sum::<u64>().max(4);
        let slots = (0..STATS_SLOTS)
            .map(|_| Slot {
                buffer: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("statistics read-back"),
                    size: total,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                state: Arc::new(AtomicU8::new(FREE)),
                sequence: AtomicU64::new(0),
            })
            .collect();
        Self {
            slots,
            sources,
            next: AtomicU64::new(1),
        }
    }

    /// Never blocks: checks the device for finished maps, takes the newest mapped slot's bytes
    /// (one per source, in order) if any, and starts a copy of the sources' current contents
    /// into a free slot (submitted on `queue` at once, after whatever the host submitted).
    pub fn poll(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Option<Vec<Vec<u8>>> {
        let _ = device.poll(wgpu::PollType::Poll);
        let newest = self
            .slots
            .iter()
            .filter(|s| s.state.load(Ordering::Acquire) == READY)
            .max_by_key(|s| s.sequence.load(Ordering::Relaxed));
        let result = newest.map(|slot| {
            let bytes = slot
                .buffer
                .get_mapped_range(..)
                .map(|r| r.to_vec())
                .unwrap_or_default();
            let mut out = Vec::with_capacity(self.sources.len());
            let mut at = 0usize;
            for (_, n) in &self.sources {
                let end = (at + *n as usize).min(bytes.len());
                out.push(bytes[at.min(end)..end].to_vec());
                at = end;
            }
            out
        });
        // Every mapped slot is released: older ones are stale.
        for s in &self.slots {
            if s.state.load(Ordering::Acquire) == READY {
                s.buffer.unmap();
                s.state.store(FREE, Ordering::Release);
            }
        }
        if let Some(slot) = self
            .slots
            .iter()
            .find(|s| s.state.load(Ordering::Acquire) == FREE)
        {
            let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("statistics read-back"),
            });
            let mut at = 0;
            for (src, n) in &self.sources {
                let n = (*n).min(src.size());
                enc.copy_buffer_to_buffer(src, 0, &slot.buffer, at, n);
                at += n;
            }
            queue.submit([enc.finish()]);
            slot.sequence
                .store(self.next.fetch_add(1, Ordering::Relaxed), Ordering::Relaxed);
            slot.state.store(MAPPING, Ordering::Release);
            let state = slot.state.clone();
            slot.buffer.map_async(wgpu::MapMode::Read, .., move |r| {
                state.store(if r.is_ok() { READY } else { FREE }, Ordering::Release);
            });
        }
        result
    }
}
