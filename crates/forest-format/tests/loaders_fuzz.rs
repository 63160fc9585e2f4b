//! A mutation smoke run of the loaders that read user files (forest binary and JSON, node
//! files, camera paths): seeded random byte flips, overwrites with extreme values, truncations
//! and splices of valid seeds. No input may panic, and none may allocate more than a bound
//! (a counting global allocator measures each call's peak). This is not coverage-guided
//! fuzzing; it keeps the loaders' refusals honest in every test run.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use forest_format::QuadNode;
use forest_format::camera_path::CameraPath;
use forest_format::forest::{Forest, Instance};
use forest_format::generate::SplitMix64;
use glam::Vec3;

struct Counting;
static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let now = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
        PEAK.fetch_max(now, Ordering::Relaxed);
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        // SAFETY: `ptr` came from `alloc` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOC: Counting = Counting;

/// Bytes a loader may allocate on top of what was live when it started, for inputs of a few
/// kilobytes.
const BOUND: usize = 64 << 20;

/// Run `f` on `input`, requiring no panic and an allocation peak within [`BOUND`].
fn bounded_call(what: &str, input: &[u8], f: &dyn Fn(&[u8])) {
    // One measured call at a time (the tests run on several threads; the others' allocations
    // between calls only add to a peak, never hide one).
    static ONE: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _one = ONE.lock().unwrap_or_else(|e| e.into_inner());
    let base = LIVE.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    if std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| f(input))).is_err() {
        panic!("{what}: panicked on input {input:?}");
    }
    let peak = PEAK.load(Ordering::Relaxed).saturating_sub(base);
    assert!(
        peak <= BOUND,
        "{what}: allocated {peak} bytes on a {}-byte input",
        input.len()
    );
}

/// One mutation of `seed`.
fn mutate(seed: &[u8], rng: &mut SplitMix64) -> Vec<u8> {
    let mut b = seed.to_vec();
    let pick = |rng: &mut SplitMix64, n: usize| (rng.next_u64() % n.max(1) as u64) as usize;
    for _ in 0..1 + pick(rng, 4) {
        match pick(rng, 6) {
            0 if !b.is_empty() => {
                let i = pick(rng, b.len());
                b[i] ^= 1 << pick(rng, 8);
            }
            1 if b.len() >= 4 => {
                // A length or count field set to an extreme value.
                let i = pick(rng, b.len() - 3);
                let v = [u32::MAX, 1 << 31, 1 << 24, 0x00ff_ffff, 0][pick(rng, 5)];
                b[i..i + 4].copy_from_slice(&v.to_le_bytes());
            }
            2 => b.truncate(pick(rng, b.len() + 1)),
            3 if !b.is_empty() => {
                let i = pick(rng, b.len());
                let j = pick(rng, b.len());
                let chunk = b[i..(i + 16).min(b.len())].to_vec();
                b.splice(j..j, chunk);
            }
            4 if !b.is_empty() => {
                let i = pick(rng, b.len());
                b[i] = [b'0', b'9', b'-', b'e', b'"', b'{', b']', b'.', 0xff][pick(rng, 9)];
            }
            _ => b.push(rng.next_u64() as u8),
        }
    }
    b
}

fn sample_forest() -> Forest {
    let instances = (0..12)
        .map(|i| Instance {
            position: [i as f32 * 3.0, 0.0, (i % 4) as f32 * 5.0],
            rotation: i as f32,
            scale: 1.0,
            species: i % 2,
        })
        .collect();
    Forest::new(vec!["a.atlas".into(), "b.atlas".into()], instances, 3)
}

#[test]
fn forest_binary() {
    let seed = sample_forest().to_bytes();
    let mut rng = SplitMix64(1);
    for _ in 0..20_000 {
        let input = mutate(&seed, &mut rng);
        bounded_call("Forest::from_bytes", &input, &|b| {
            let _ = Forest::from_bytes(b);
        });
    }
}

#[test]
fn node_files() {
    let nodes: Vec<QuadNode> = (0..4u32)
        .map(|k| QuadNode::new(if k == 0 { 0b0111 } else { 0 }, 1, [k as u8, 9, 80, 200]))
        .collect();
    let seed = forest_format::nodes_codec::encode(&nodes, 1);
    assert!(forest_format::nodes_codec::decode(&seed).is_ok());
    let mut rng = SplitMix64(2);
    for _ in 0..20_000 {
        let input = mutate(&seed, &mut rng);
        bounded_call("nodes_codec::decode", &input, &|b| {
            let _ = forest_format::nodes_codec::decode(b);
        });
    }
}

/// Mutations written to a file with `ext` and loaded by `load` (the loaders that read paths).
fn through_files(seed: &[u8], ext: &str, runs: usize, salt: u64, load: &dyn Fn(&std::path::Path)) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(format!("input.{ext}"));
    let mut rng = SplitMix64(salt);
    for _ in 0..runs {
        let input = mutate(seed, &mut rng);
        std::fs::write(&path, &input).unwrap();
        bounded_call(ext, &input, &|_| load(&path));
    }
}

#[test]
fn forest_json_and_camera_paths() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("f.json");
    sample_forest().save(&json).unwrap();
    through_files(&std::fs::read(&json).unwrap(), "json", 3_000, 3, &|p| {
        let _ = Forest::load(p);
    });
    let mut path = CameraPath::new(60.0);
    path.push(Vec3::new(0.0, 1.7, 5.0), Vec3::ZERO);
    path.push(Vec3::new(2.0, 1.7, 5.0), Vec3::X);
    let cam = dir.path().join("p.json");
    path.save(&cam).unwrap();
    through_files(&std::fs::read(&cam).unwrap(), "path.json", 3_000, 4, &|p| {
        let _ = CameraPath::load(p);
    });
}
