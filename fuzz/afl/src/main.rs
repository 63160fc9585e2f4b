//! AFL++ driver: `forest-fuzz-afl TARGET`, run by `cargo afl fuzz` (see scripts/fuzz.sh).
//! Runs one target of `forest_fuzz::TARGETS` in AFL++'s persistent mode, with the target's
//! allocation bound enforced by aborting (which AFL++ records as a crash).

#[global_allocator]
static ALLOC: forest_fuzz::alloc::Counting = forest_fuzz::alloc::Counting;

fn main() {
    let name = std::env::args().nth(1).unwrap_or_default();
    let Some(target) = forest_fuzz::targets::target(&name) else {
        let names: Vec<_> = forest_fuzz::TARGETS.iter().map(|t| t.name).collect();
        eprintln!("usage: forest-fuzz-afl TARGET (one of {})", names.join(", "));
        std::process::exit(2);
    };
    afl::fuzz!(|data: &[u8]| {
        let base = forest_fuzz::alloc::live();
        forest_fuzz::alloc::abort_above(Some(base + target.bound));
        let _ = (target.run)(data);
        forest_fuzz::alloc::abort_above(None);
    });
}
