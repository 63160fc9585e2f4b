#!/usr/bin/env bash
# The main job: bake the bundled tree models into atlases and write their contact sheets.
# Outputs go to out/ (atlases, contact sheets, one JSON line of figures per model).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh

cargo build --release --locked -p forest-cli
mkdir -p out/atlases out/contact
: > out/bake.jsonl
for species in oak ash aspen pine bush; do
  ./target/release/forest bake "assets/trees/$species/$species.obj" \
    -o "out/atlases/$species.atlas" --contact-sheet "out/contact/$species.png"
  ./target/release/forest info "out/atlases/$species.atlas" --json >/dev/null
done
echo
echo "Atlases in out/atlases/, contact sheets in out/contact/ (open them: people look at these)."
