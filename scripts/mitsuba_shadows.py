#!/usr/bin/env python3
"""Render a forest's trees over flat ground in Mitsuba 3 under a directional sun alone, to check
where forest's shadows fall on the ground against exact shadow rays (scripts/validate_shadows.sh
drives it and compares the masks).

Reads a forest JSON (species, instances with position, rotation_deg about +Y and scale, as
forest places them) and the species' OBJ models in the same order; the trees are built as
scripts/mitsuba_reference.py builds one (alpha test cut into geometry). The ground is the plane
y = 0 (flat ground, no terrain), diffuse albedo 0.5.

Writes OUT-ground.png: the sun-only image, trees and ground (linear luminance scaled so that
open ground is 0.5: shadowed ground is darker); and OUT-trees.png: alpha = the trees' coverage
without the ground. Needs: pip install mitsuba numpy pillow.
"""

import argparse
import json
import math
import os
import tempfile

import mitsuba as mi
import numpy as np
from PIL import Image

import mitsuba_reference as ref


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("forest", help="forest JSON (flat ground)")
    ap.add_argument("--models", required=True, help="OBJ models of its species, comma-separated")
    ref.view_arguments(ap, "400x400", 16, 8)
    a = ap.parse_args()
    mi.set_variant("scalar_rgb")
    sun_dir, el, sensor = ref.parse_view(a)
    forest = json.load(open(a.forest))
    models = a.models.split(",")
    if len(models) != len(forest["species"]):
        raise SystemExit(f"{len(forest['species'])} species but {len(models)} models")
    base = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 2, "hide_emitters": True},
        "sensor": sensor,
        "sun": {
            "type": "directional",
            "direction": [-x for x in sun_dir],
            "irradiance": {"type": "rgb", "value": [math.pi] * 3},
        },
    }
    with tempfile.TemporaryDirectory() as tmp:
        # Each species' parts once, as PLY files; every instance of it places them.
        parts = []
        for k, model in enumerate(models):
            tris, mtllib = ref.read_obj(model)
            model_dir = os.path.dirname(os.path.abspath(model))
            mats = ref.parse_mtl(os.path.join(model_dir, mtllib)) if mtllib else {}
            mine = []
            for name, t in tris.items():
                m = mats.get(name, {"Kd": (0.5, 0.5, 0.5)})
                alpha = ref.alpha_of(m, model_dir)
                if alpha is not None:
                    t = ref.solid_parts(t, alpha, a.cuts)
                path = os.path.join(tmp, f"{k}-{name}.ply")
                ref.write_ply(path, *t)
                mine.append((path, ref.material_bsdf(m, model_dir, tmp)))
            parts.append(mine)
        trees = {}
        for i, inst in enumerate(forest["instances"]):
            place = (mi.ScalarTransform4f()
                     .translate(inst["position"])
                     .rotate([0, 1, 0], inst.get("rotation_deg", 0.0))
                     .scale(inst.get("scale", 1.0)))
            for j, (path, bsdf) in enumerate(parts[inst["species"]]):
                trees[f"tree_{i}_{j}"] = {"type": "ply", "filename": path, "bsdf": bsdf,
                                          "to_world": place}
        ground = {
            "type": "rectangle",
            "to_world": mi.ScalarTransform4f().rotate([1, 0, 0], -90).scale(1e4),
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.5] * 3}},
        }
        # With the ground, sun only: open ground's radiance is albedo x sin(el) x 1; scaled
        # so that it reads 0.5.
        img = np.array(mi.render(mi.load_dict({**base, **trees, "ground": ground})))
        lum = img[..., :3] @ np.array([0.2126, 0.7152, 0.0722])
        open_ground = 0.5 * math.sin(el)
        grey = np.clip(0.5 * lum / open_ground, 0, 1)
        Image.fromarray((grey * 255 + 0.5).astype(np.uint8), "L").save(a.output + "-ground.png")
        img = np.array(mi.render(mi.load_dict({**base, **trees})))
        alpha = np.clip(img[..., 3], 0, 1)
        Image.fromarray((alpha * 255 + 0.5).astype(np.uint8), "L").save(a.output + "-trees.png")
        print("wrote", a.output + "-ground.png", a.output + "-trees.png")


if __name__ == "__main__":
    main()
