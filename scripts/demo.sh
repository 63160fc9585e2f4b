#!/usr/bin/env bash
# The main job: bake the bundled tree models (cached), generate a 100k-tree forest on seeded
# hills, and render a view inside the forest, one from a hilltop over the valley and a bird's-eye
# view to PNG, headless (lavapipe or a real GPU).
# Outputs go to out/: atlases, contact sheets, the forest, the renders.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh

cargo build --release --locked -p forest-cli
forest=./target/release/forest
mkdir -p out/atlases out/contact out/render
species=()
for s in oak ash aspen pine bush; do
  atlas="out/atlases/$s.atlas"
  # Cached: re-bake only when the model, its materials or textures are newer than the atlas,
  # or the atlas predates the measured hybrid switch or the stored model (model.bin).
  if [ -f "$atlas/manifest.json" ] && [ -z "$(find "assets/trees/$s" -newer "$atlas/manifest.json" -type f)" ] \
     && grep -q '"hybrid_switch"' "$atlas/manifest.json" && [ -f "$atlas/model.bin" ] \
     && $forest info "$atlas" >/dev/null 2>&1; then
    echo "cached: $atlas"
  else
    $forest bake "assets/trees/$s/$s.obj" -o "$atlas" --contact-sheet "out/contact/$s.png"
  fi
  species+=("$atlas")
done
$forest scene --trees 100000 --area-per-tree 60 --species "$(IFS=,; echo "${species[*]}")" --seed 1 \
  --terrain hills -o out/forest-100k.forest
# The default method, the hybrid: the trees within a few crown radii as full geometry (the models the bake stored
# in the atlases), the rest as the quad stream, both casting the sun's shadows.
$forest render out/forest-100k.forest -o out/render/forest.png --view inside --view hill --view birds-eye \
  --size 800x600 --shadows on
# The same forest at two times of day: a low morning sun and noon.
for t in 7.5 12; do
  $forest render out/forest-100k.forest -o "out/render/forest-$t.png" --view hill --time "$t" \
    --size 800x600 --shadows on
done
# The forest in a breeze: 3 s at 12 frames per second from inside, an animated PNG. Every tree
# and its shadow move; the hybrid's two forms move alike.
$forest render out/forest-100k.forest -o out/render/forest-wind.png --view inside \
  --size 480x270 --shadows on --wind 60,9 --animate 3 --frame-rate 12
$forest render out/forest-100k.forest -o out/render/forest-autumn.png --view inside --time 10 \
  --size 800x600 --shadows on --season autumn
echo
echo "Renders: out/render/forest-inside.png, out/render/forest-hill.png, out/render/forest-birds-eye.png,"
echo "  at 7:30 and noon: out/render/forest-7.5.png, out/render/forest-12.png,"
echo "  in wind (an animated PNG): out/render/forest-wind.png, in autumn: out/render/forest-autumn.png"
echo "Atlases: out/atlases/, contact sheets: out/contact/"
