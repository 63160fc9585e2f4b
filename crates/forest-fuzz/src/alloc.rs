//! A counting global allocator: the bytes live and their peak since the last
//! [`reset_peak`], and optionally a hard bound above which an allocation aborts the process
//! (so a fuzzer records the input as a crash instead of the machine running out of memory).
//!
//! A binary installs it with
//! `#[global_allocator] static A: forest_fuzz::alloc::Counting = forest_fuzz::alloc::Counting;`.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The counting allocator (forwards to the system allocator).
pub struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);
/// Live bytes above which an allocation aborts; `usize::MAX` for none.
static ABORT_ABOVE: AtomicUsize = AtomicUsize::new(usize::MAX);

/// Count an allocation of `size` bytes; abort past the bound.
fn count(size: usize) {
    let now = LIVE.fetch_add(size, Ordering::Relaxed) + size;
    PEAK.fetch_max(now, Ordering::Relaxed);
    if now > ABORT_ABOVE.load(Ordering::Relaxed) {
        // Stderr's lock and a static message: nothing here allocates.
        use std::io::Write;
        let _ = std::io::stderr()
            .lock()
            .write_all(b"forest-fuzz: allocation bound crossed\n");
        std::process::abort();
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count(layout.size());
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count(layout.size());
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        // SAFETY: `ptr` came from `alloc` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
}

/// Bytes live now.
pub fn live() -> usize {
    LIVE.load(Ordering::Relaxed)
}

/// Start measuring a peak from what is live now.
pub fn reset_peak() -> usize {
    let base = live();
    PEAK.store(base, Ordering::Relaxed);
    base
}

/// The highest live byte count since the last [`reset_peak`].
pub fn peak() -> usize {
    PEAK.load(Ordering::Relaxed)
}

/// Abort the process when more than `bytes` would be live (`None`: never).
pub fn abort_above(bytes: Option<usize>) {
    ABORT_ABOVE.store(bytes.unwrap_or(usize::MAX), Ordering::Relaxed);
}
