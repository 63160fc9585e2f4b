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
  targets=(forest_binary forest_json camera_path nodes atlas obj gltf image terrain model_bin results_csv wind)
fi

if ! command -v cargo-afl >/dev/null; then
  echo "fuzz: installing cargo-afl (AFL++ is built from its sources once)"
  cargo install --locked cargo-afl
fi
cargo afl config --build >/dev/null 2>&1 || true
(cd fuzz/afl && cargo afl build --release --locked)

export AFL_SKIP_CPUFREQ=1 AFL_I_DONT_CARE_ABOUT_MISSING_CRASHES=1 AFL_NO_UI=1 AFL_NO_AFFINITY=1
mkdir -p out/fuzz results
failed=0
for t in "${targets[@]}"; do
  # A hang is a run past the timeout: 1 s, or 10 s for the targets that decode images (an
  # input of 1 MiB may describe an image of up to 16384 pixels a side, legitimately slow).
  case "$t" in
    atlas | obj | image) timeout_ms=10000 ;;
    *) timeout_ms=1000 ;;
  esac
  echo "fuzz: $t for $execs executions"
  rm -rf "out/fuzz/$t" "out/fuzz/$t.row"
  cargo afl fuzz -i "crates/forest-fuzz/corpus/$t" -o "out/fuzz/$t" -E "$execs" -t "$timeout_ms" \
    -m none -- fuzz/afl/target/release/forest-fuzz-afl "$t" >"out/fuzz/$t.log" 2>&1 || {
    echo "fuzz: afl-fuzz failed on $t (see out/fuzz/$t.log)"
    failed=1
    continue
  }
  stats="out/fuzz/$t/default/fuzzer_stats"
  get() { awk -F' *: *' -v k="$1" '$1 == k { print $2 }' "$stats"; }
  echo "| $t | $(get execs_done) | $(get execs_per_sec) | $(get saved_crashes) | $(get saved_hangs) | $(get corpus_count) | $(get bitmap_cvg) | $((timeout_ms / 1000)) | $(get run_time) | $(date -u +%Y-%m-%d) |" >"out/fuzz/$t.row"
  if [ "$(get saved_crashes)" != 0 ] || [ "$(get saved_hangs)" != 0 ]; then
    echo "fuzz: $t: crashes or hangs in out/fuzz/$t/default/{crashes,hangs}"
    failed=1
  fi
done
# The table holds the latest run of every target.
{
  echo "Coverage-guided fuzzing (cargo-afl, AFL++) on $(nproc) cores: inputs up to 1 MiB, allocation"
  echo "bounds as in crates/forest-fuzz/src/targets.rs. Made by \`bash scripts/fuzz.sh $execs\`."
  echo
  echo "| target | executions | execs/s | crashes | hangs | corpus | edge coverage | timeout s | seconds | date |"
  echo "|---|---|---|---|---|---|---|---|---|---|"
  # A target run now gets its new row; one not run keeps its row from the last table.
  for t in forest_binary forest_json camera_path nodes atlas obj gltf image terrain model_bin results_csv wind; do
    if [ -f "out/fuzz/$t.row" ]; then
      cat "out/fuzz/$t.row"
    else
      grep "^| $t |" results/fuzz.md 2>/dev/null || true
    fi
  done
} >results/fuzz.md.new
mv results/fuzz.md.new results/fuzz.md
cat results/fuzz.md
exit $failed
