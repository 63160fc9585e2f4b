#!/usr/bin/env bash
# Check the project's reference (full geometry, 4×4 supersampled, lit by the run-time sun with
# its opacity-volume self-shadowing and traced sky visibility) against Mitsuba 3 rendering the
# same tree under the same light with exact shadow rays (scripts/mitsuba_reference.py).
# For each bundled model and sun: mean FLIP, coverage IoU, and the mean luminance of the
# crown's sunlit and shadowed pixels (split by Mitsuba's sun-only image) in both renders.
# Writes results/mitsuba/ (images) and results/mitsuba.md (the table). Needs Python 3 with
# `pip install mitsuba numpy pillow` (set PYTHON to that interpreter). About a minute.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/mitsuba_env.sh
out=results/mitsuba
mkdir -p "$out"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
rows=()
for s in bush pine oak; do
  model="assets/trees/$s/$s.obj"
  "$forest" bake "$model" -o "$work/$s.atlas" --resolution 64 --directions 5 --no-hybrid-switch >/dev/null
  echo "{\"species\":[\"$s.atlas\"],\"instances\":[{\"species\":0,\"position\":[0,0,0],\"rotation_deg\":0,\"scale\":1}],\"presort_directions\":3}" >"$work/$s.json"
  # The crown's centre and radius from the atlas: the camera frames it from 2.6 radii.
  read -r cx cy cz r < <("$PYTHON" -c "
import json; m = json.load(open('$work/$s.atlas/manifest.json'))['bounding_sphere']
print(*m['center'], m['radius'])")
  for sun in 250,25 30,55 100,10; do
    eye=$("$PYTHON" -c "print(f'{$cx + 2.0 * $r:.3f},{$cy + 0.4 * $r:.3f},{$cz + 1.7 * $r:.3f}')")
    target="$cx,$cy,$cz"
    stem="$out/$s-${sun/,/-}"
    "$forest" render "$work/$s.json" -o "$stem-forest.png" --eye "$eye" --target "$target" --fov 50 \
      --size 320x240 --sun "$sun" --transparent --method reference --models "$model" --supersample 4 >/dev/null
    "$PYTHON" scripts/mitsuba_reference.py "$model" --sun "$sun" --eye="$eye" --target="$target" \
      --fov 50 --size 320x240 --spp 64 -o "$stem-mitsuba" >/dev/null
    flip=$("$forest" compare "$stem-mitsuba.png" "$stem-forest.png" --json)
    row=$("$PYTHON" - "$s" "$sun" "$stem" "$flip" <<'EOF'
import json, sys
import numpy as np
from PIL import Image
s, sun, stem, flip = sys.argv[1], sys.argv[2], sys.argv[3], json.loads(sys.argv[4])
ours = np.asarray(Image.open(stem + "-forest.png"), dtype=np.float64) / 255
mi = np.asarray(Image.open(stem + "-mitsuba.png"), dtype=np.float64) / 255
sun_only = np.asarray(Image.open(stem + "-mitsuba-sun.png"), dtype=np.float64) / 255
lum = lambda im: im[..., :3] @ np.array([0.2126, 0.7152, 0.0722])
covered = (mi[..., 3] > 0.99) & (ours[..., 3] > 0.99)
lit = covered & (lum(sun_only) > 0.05)
shade = covered & (lum(sun_only) <= 0.05)
m = lambda im, k: lum(im)[k].mean() if k.any() else float("nan")
iou = flip.get("coverage_iou")
iou = "n/a" if iou is None else f"{iou:.3f}"
print(f"| {s} | {sun} | {flip['flip_mean']:.4f} | {iou} | "
      f"{lit.sum() / max(covered.sum(), 1):.2f} | {m(mi, lit):.3f} / {m(ours, lit):.3f} | "
      f"{m(mi, shade):.3f} / {m(ours, shade):.3f} |")
EOF
)
    rows+=("$row")
    echo "$row"
  done
done
{
  echo "# The reference against Mitsuba 3"
  echo
  echo "The reference (full geometry 4×4, textures at their finest level; forest) against Mitsuba 3 (direct light only, exact shadow rays,"
  echo "alpha test as geometry), same model, camera and light; 320×240, transparent."
  echo "Sunlit pixels are those Mitsuba's sun-only render lights (luminance > 0.05), of the"
  echo "pixels both cover fully; luminance is of the sRGB-encoded values. \`bash scripts/validate_reference.sh\`."
  echo
  echo "| model | sun (az,el) | FLIP | coverage IoU | sunlit share | sunlit luminance Mitsuba / forest | shadowed luminance Mitsuba / forest |"
  echo "|---|---|---|---|---|---|---|"
  printf '%s\n' "${rows[@]}"
} >results/mitsuba.md
echo "wrote results/mitsuba.md"
