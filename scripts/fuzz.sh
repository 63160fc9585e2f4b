#!/usr/bin/env bash
# Coverage-guided fuzzing of every loader of user files (crates/forest-fuzz), with cargo-afl
# and AFL++ on stable Rust.
#
#   bash scripts/fuzz.sh [EXECS] [TARGET...]
#
# runs each target (default: all) for EXECS executions (default 1000000) from its seed corpus
# in crates/forest-fuzz/corpus/TARGET, writes AFL++'s findings under out/fuzz/TARGET and a
# table of executions, speed, crashes, hangs and coverage to results/fuzz.md. Exits non-zero
# when any target crashed (a panic, or an allocation past the target's bound) or hung.
set -euo pipefail
cd "$(dirname "$0")/.."

execs=${1:-1000000}
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(forest_binary forest_json camera_path nodes atlas obj image)
fi

if ! command -v cargo-afl >/dev/null; then
  echo "fuzz: installing cargo-afl (AFL++ is built from its sources once)"
  cargo install --locked cargo-afl
fi
cargo afl config --build >/dev/null 2>&1 || true
(cd fuzz/afl && cargo afl build --release --locked)

export AFL_SKIP_CPUFREQ=1 AFL_I_DONT_CARE_ABOUT_MISSING_CRASHES=1 AFL_NO_UI=1 AFL_NO_AFFINITY=1
mkdir -p out/fuzz results
table=results/fuzz.md.tmp
{
  echo "| target | executions | execs/s | crashes | hangs | corpus | edge coverage | seconds |"
  echo "|---|---|---|---|---|---|---|---|"
} >"$table"
failed=0
for t in "${targets[@]}"; do
  echo "fuzz: $t for $execs executions"
  rm -rf "out/fuzz/$t"
  cargo afl fuzz -i "crates/forest-fuzz/corpus/$t" -o "out/fuzz/$t" -E "$execs" -t 1000 -m none \
    -- fuzz/afl/target/release/forest-fuzz-afl "$t" >"out/fuzz/$t.log" 2>&1 || {
    echo "fuzz: afl-fuzz failed on $t (see out/fuzz/$t.log)"
    failed=1
    continue
  }
  stats="out/fuzz/$t/default/fuzzer_stats"
  get() { awk -F' *: *' -v k="$1" '$1 == k { print $2 }' "$stats"; }
  echo "| $t | $(get execs_done) | $(get execs_per_sec) | $(get saved_crashes) | $(get saved_hangs) | $(get corpus_count) | $(get bitmap_cvg) | $(get run_time) |" >>"$table"
  if [ "$(get saved_crashes)" != 0 ] || [ "$(get saved_hangs)" != 0 ]; then
    echo "fuzz: $t: crashes or hangs in out/fuzz/$t/default/{crashes,hangs}"
    failed=1
  fi
done
{
  echo "Fuzzed $(date -u +%Y-%m-%d) on $(nproc) cores, $execs executions per target, inputs up to 1 MiB,"
  echo "1 s timeout, allocation bounds as in crates/forest-fuzz/src/targets.rs."
  echo
  cat "$table"
} >results/fuzz.md
rm -f "$table"
cat results/fuzz.md
exit $failed
