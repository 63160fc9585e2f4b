//! The fuzz targets' smoke run: every seed of every corpus must load, and seeded mutations of
//! each seed must neither panic nor allocate past the target's bound. Coverage-guided runs of
//! millions of executions are `scripts/fuzz.sh`'s; this keeps the targets alive in every
//! `cargo test`.

use forest_format::noise::SplitMix64;
use forest_fuzz::{TARGETS, Target, alloc, corpus_dir, mutate::mutate, regressions_dir};

#[global_allocator]
static ALLOC: alloc::Counting = alloc::Counting;

/// Mutations per seed.
const MUTATIONS: usize = 1_500;

/// Every file of `dir` (none when it does not exist), by name.
fn files(dir: &std::path::Path) -> Vec<(String, Vec<u8>)> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut out: Vec<_> = entries
        .map(|e| {
            let p = e.unwrap().path();
            (p.display().to_string(), std::fs::read(&p).unwrap())
        })
        .collect();
    out.sort();
    out
}

/// Run `target` on `input`: no panic, and at most its bound allocated at once. Returns
/// whether the loader accepted the input.
fn bounded_call(target: &Target, input: &[u8]) -> bool {
    // One measured call at a time: the test harness runs tests on several threads, whose
    // allocations can only add to a peak, never hide one.
    static ONE: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _one = ONE.lock().unwrap_or_else(|e| e.into_inner());
    let base = alloc::reset_peak();
    let accepted = std::panic::catch_unwind(|| (target.run)(input))
        .unwrap_or_else(|_| panic!("{}: panicked on input {input:?}", target.name));
    let peak = alloc::peak().saturating_sub(base);
    assert!(
        peak <= target.bound,
        "{}: {peak} bytes live at once on a {}-byte input (bound {})",
        target.name,
        input.len(),
        target.bound
    );
    accepted
}

fn smoke(name: &str, salt: u64) {
    let target = forest_fuzz::targets::target(name).expect("a target of that name");
    let mut rng = SplitMix64(salt);
    let (mut accepted, mut runs) = (0usize, 0usize);
    for (file, input) in files(&regressions_dir(name)) {
        bounded_call(target, &input);
        eprintln!("{name}: regression {file} replayed");
    }
    let seeds = files(&corpus_dir(name));
    assert!(!seeds.is_empty(), "{name} has no seeds");
    for (file, seed) in seeds {
        assert!(bounded_call(target, &seed), "{file}: the seed is refused");
        for _ in 0..MUTATIONS {
            let input = mutate(&seed, &mut rng);
            accepted += usize::from(bounded_call(target, &input));
            runs += 1;
        }
    }
    eprintln!("{name}: {runs} mutations, {accepted} accepted");
}

#[test]
fn every_target_has_a_smoke_test() {
    let here = include_str!("smoke.rs");
    for t in TARGETS {
        assert!(
            here.contains(&format!("fn {}()", t.name)),
            "no smoke test for {}",
            t.name
        );
    }
}

#[test]
fn forest_binary() {
    smoke("forest_binary", 1);
}

#[test]
fn forest_json() {
    smoke("forest_json", 2);
}

#[test]
fn camera_path() {
    smoke("camera_path", 3);
}

#[test]
fn nodes() {
    smoke("nodes", 4);
}

#[test]
fn atlas() {
    smoke("atlas", 5);
}

#[test]
fn obj() {
    smoke("obj", 6);
}

#[test]
fn image() {
    smoke("image", 7);
}

#[test]
fn gltf() {
    smoke("gltf", 8);
}

#[test]
fn terrain() {
    smoke("terrain", 9);
}

#[test]
fn model_bin() {
    smoke("model_bin", 10);
}

#[test]
fn results_csv() {
    smoke("results_csv", 11);
}

#[test]
fn wind() {
    smoke("wind", 12);
}
