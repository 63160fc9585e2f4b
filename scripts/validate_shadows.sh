#!/usr/bin/env bash
# Check where forest's sun shadows fall on the ground against Mitsuba 3's exact shadow rays
# (scripts/mitsuba_shadows.py): ten trees of the bundled species on flat ground, placed by a
# seeded draw, seen from straight above, under a sun at 25° and at 60° elevation (azimuths
# drawn from the same seed). The shadowed-ground mask of each method (the reference, the quad
# stream, the hybrid; default shadow options) is compared with Mitsuba's by IoU over the
# ground both see. Writes results/mitsuba-shadows/ (images, masks) and
# results/mitsuba-shadows.md (the table). Needs Python 3 with `pip install mitsuba numpy
# pillow` (set PYTHON to that interpreter). A few minutes.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/mitsuba_env.sh
out=results/mitsuba-shadows
mkdir -p "$out"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
species=(oak ash aspen pine bush)
models=()
for s in "${species[@]}"; do
  models+=("assets/trees/$s/$s.obj")
  "$forest" bake "assets/trees/$s/$s.obj" -o "$work/$s.atlas" --resolution 64 --directions 5 \
    --no-hybrid-switch >/dev/null
done
models_csv=$(IFS=,; echo "${models[*]}")
# Ten trees and the suns' azimuths, from one seed.
suns=$("$PYTHON" - "$work" <<'EOF'
import json, random, sys
rng = random.Random(20261203)
work = sys.argv[1]
names = ["oak", "ash", "aspen", "pine", "bush"]
inst = [{"species": rng.randrange(5), "position": [rng.uniform(-12, 12), 0.0, rng.uniform(-12, 12)],
         "rotation_deg": rng.uniform(0, 360), "scale": rng.uniform(0.8, 1.2)} for _ in range(10)]
json.dump({"species": [f"{n}.atlas" for n in names], "instances": inst, "presort_directions": 3},
          open(f"{work}/forest.json", "w"))
print(" ".join(f"{rng.uniform(0, 360):.0f},{el}" for el in (25, 60)))
EOF
)
view=(--eye 0,50,1 --target 0,0,0 --fov 45 --size 400x400 --supersample 4)
rows=()
for sun in $suns; do
  stem="$out/sun-${sun/,/-}"
  "$PYTHON" scripts/mitsuba_shadows.py "$work/forest.json" --models "$models_csv" --sun "$sun" \
    --eye 0,50,1 --target 0,0,0 --fov 45 --size 400x400 --spp 64 --cuts 24 -o "$stem-mitsuba" >/dev/null
  for method in reference quads hybrid; do
    for sh in on off; do
      "$forest" render "$work/forest.json" -o "$stem-$method-$sh.png" "${view[@]}" --sun "$sun" \
        --method "$method" --models "$models_csv" --shadows "$sh" --haze off >/dev/null
    done
    "$forest" render "$work/forest.json" -o "$stem-$method-trees.png" "${view[@]}" --sun "$sun" \
      --method "$method" --models "$models_csv" --transparent >/dev/null
    row=$("$PYTHON" - "$stem" "$method" "$sun" <<'EOF'
import sys
import numpy as np
from PIL import Image
stem, method, sun = sys.argv[1:4]
load = lambda p: np.asarray(Image.open(p).convert("RGBA"), dtype=np.float64) / 255
lin = lambda c: np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
lum = lambda im: lin(im[..., :3]) @ np.array([0.2126, 0.7152, 0.0722])
on, off = lum(load(f"{stem}-{method}-on.png")), lum(load(f"{stem}-{method}-off.png"))
ours_trees = load(f"{stem}-{method}-trees.png")[..., 3] > 0
mi_grey = np.asarray(Image.open(f"{stem}-mitsuba-ground.png"), dtype=np.float64) / 255
mi_trees = np.asarray(Image.open(f"{stem}-mitsuba-trees.png"), dtype=np.float64) / 255 > 0
ground = ~ours_trees & ~mi_trees
ratio = on / np.maximum(off, 1e-6)
# The fully shadowed ratio (sky light alone over sun and sky): that of the darkest
# twentieth of the ground the sun's shadow darkens.
dark = ratio[ground & (ratio < 0.97)]
r0 = np.percentile(dark, 5) if dark.size else 0.0
ours = ground & ((ratio - r0) / max(1 - r0, 1e-6) < 0.5)
theirs = ground & (mi_grey / 0.5 < 0.5)
iou = (ours & theirs).sum() / max((ours | theirs).sum(), 1)
# Masks side by side: red forest only, green Mitsuba only, yellow both, blue trees.
img = np.zeros(ours.shape + (3,), np.uint8)
img[ours] = (255, 0, 0)
img[theirs] = (0, 255, 0)
img[ours & theirs] = (255, 255, 0)
img[~ground] = (40, 40, 160)
Image.fromarray(img).save(f"{stem}-{method}-masks.png")
print(f"| {sun} | {method} | {iou:.3f} | {ours.sum() / ground.sum():.3f} | "
      f"{theirs.sum() / ground.sum():.3f} |")
EOF
)
    rows+=("$row")
    echo "$row"
  done
done
{
  echo "# Ground shadows against Mitsuba 3"
  echo
  echo "Ten trees of the bundled species on flat ground (placed by a seeded draw), seen from"
  echo "50 m straight above (400×400, 45° field of view; no haze), under a sun at 25° and at 60°"
  echo "elevation (azimuths from the same seed). Mitsuba 3: sun only, exact shadow rays, alpha"
  echo "test cut into geometry (24 cuts a side), 64 samples a pixel. forest: default shadow"
  echo "options (the reference's maps 8192², the others' 1024²), 4×4 supersampled, so that both"
  echo "average a pixel's area. A ground pixel is shadowed where less than half the sun reaches"
  echo "it (forest: from frames with shadows on and off). IoU over the ground neither sees a"
  echo "tree on."
  echo "\`bash scripts/validate_shadows.sh\`."
  echo
  echo "| sun (az,el) | method | IoU | shadowed share, forest | shadowed share, Mitsuba |"
  echo "|---|---|---|---|---|"
  printf '%s\n' "${rows[@]}"
} >results/mitsuba-shadows.md
echo "wrote results/mitsuba-shadows.md"
