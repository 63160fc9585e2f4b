#!/usr/bin/env python3
"""Where does the quad stream become more accurate than full geometry at 1x?

For each species, one tree (scale 1, rotation 0) at the origin is seen from seeded random
cameras at fixed distances (in bounding-sphere radii from the crown centre; azimuth uniform,
elevation -20..40 degrees, eyes kept 0.3 m above the ground), 400x300, 60 degrees. Each view is
rendered as full geometry at 1x and as the quad stream at epsilon 2, and both are compared
(mean FLIP) with the 4x4 supersampled full-geometry reference. Prints the mean per distance
and the crossover: the first distance from which the stream's mean is the lower.

Needs `forest` built (target/release) and the atlases of `bash scripts/demo.sh`.

    python3 scripts/crossover.py [SPECIES,...] [DISTANCES,...] [CAMERAS]
"""
import json, math, os, random, subprocess, sys, tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FOREST = os.path.join(ROOT, "target/release/forest")
ATLASES = os.path.join(ROOT, "out/atlases")
MODELS = os.path.join(ROOT, "assets/trees")

species = (sys.argv[1] if len(sys.argv) > 1 else "oak,pine,aspen,ash,bush").split(",")
dists = [float(x) for x in (sys.argv[2] if len(sys.argv) > 2 else "1.5,2,2.5,3,3.5,4,5").split(",")]
ncam = int(sys.argv[3]) if len(sys.argv) > 3 else 6


def run(*args):
    return subprocess.run([FOREST, *args], check=True, capture_output=True, text=True).stdout


with tempfile.TemporaryDirectory() as tmp:
    print("species,distance_radii,camera,azimuth_deg,elevation_deg,flip_geometry_1x,flip_quads_eps2")
    summary = []
    for s in species:
        man = json.load(open(f"{ATLASES}/{s}.atlas/manifest.json"))
        c, r = man["bounding_sphere"]["center"], man["bounding_sphere"]["radius"]
        forest = os.path.join(tmp, f"{s}.json")
        json.dump({"species": [f"{ATLASES}/{s}.atlas"],
                   "instances": [{"species": 0, "position": [0, 0, 0], "rotation_deg": 0, "scale": 1}],
                   "presort_directions": 15}, open(forest, "w"))
        rng = random.Random(7)
        cams = [(rng.uniform(0, 360), rng.uniform(-20, 40)) for _ in range(ncam)]
        means = []
        for d in dists:
            g_sum = q_sum = 0.0
            for i, (az, el) in enumerate(cams):
                a, e = math.radians(az), math.radians(el)
                eye = [c[0] + d * r * math.cos(e) * math.cos(a), c[1] + d * r * math.sin(e),
                       c[2] + d * r * math.cos(e) * math.sin(a)]
                eye[1] = max(eye[1], 0.3)
                common = [forest, "--eye", ",".join(map(str, eye)), "--target", ",".join(map(str, c)),
                          "--size", "400x300", "--transparent"]
                png = lambda n: os.path.join(tmp, f"{n}.png")
                model = f"{MODELS}/{s}/{s}.obj"
                run("render", *common, "--method", "geometry", "--models", model, "--supersample", "4", "-o", png("ref"))
                run("render", *common, "--method", "geometry", "--models", model, "-o", png("geo"))
                run("render", *common, "--method", "quads", "--epsilon", "2", "-o", png("quads"))
                g, q = (json.loads(run("compare", png("ref"), png(n), "--json").strip().splitlines()[-1])["flip_mean"]
                        for n in ("geo", "quads"))
                g_sum, q_sum = g_sum + g, q_sum + q
                print(f"{s},{d},{i},{az:.1f},{el:.1f},{g:.5f},{q:.5f}", flush=True)
            means.append((d, g_sum / ncam, q_sum / ncam))
        cross = next((d for d, g, q in means if q <= g), None)
        summary.append(f"{s}: " + ", ".join(f"{d}: {g:.4f}/{q:.4f}" for d, g, q in means)
                       + f"; the stream is the more accurate from {cross} radii")
    print("\n# mean FLIP per distance (geometry 1x / quads eps 2)", file=sys.stderr)
    for line in summary:
        print(line, file=sys.stderr)
