#!/usr/bin/env python3
"""Render one tree in Mitsuba 3 lit as forest's shading model lights it, to check the
project's full-geometry reference against an independent renderer (scripts/validate_reference.sh
drives it and compares).

The light is forest_format::shading::Lighting::with_sun(AZ, EL): a directional sun of
irradiance pi*sun (the shading model writes radiance = albedo * irradiance, Mitsuba's diffuse
albedo / pi * irradiance), and an environment of radiance `sky` over the upper hemisphere and
`ground` under it, whose cosine-weighted integral is exactly the model's hemispherical ambient
(sky * (1 + n.y)/2 + ground * (1 - n.y)/2). Direct light only (max_depth 2), as the model has
no inter-reflection. Leaves are alpha-tested at 0.5 like the bake's, two-sided diffuse; the
model's translucency (0.35 for leaves) is not modelled here, so leaves whose back faces the
sun are darker than forest's. Materials: OBJ + MTL (map_Kd, map_d, Kd as an sRGB tint).
Mitsuba's shadow rays treat masked (`mask` BSDF) surfaces as opaque and its path tracer counts
each pass through a mask as a bounce, so the alpha test is made geometry: every alpha-tested
triangle is cut into --cuts^2 pieces and the pieces on transparent texels are dropped.

Writes OUT.png (premultiplied colour, sRGB-encoded; alpha = coverage) and OUT-sun.png (sun only, no sky: the lit mask).
Needs: pip install mitsuba numpy pillow.
"""

import argparse
import math
import os
import tempfile

import mitsuba as mi
import numpy as np
from PIL import Image

SUN = (1.0, 0.95, 0.85)
SKY = (0.32, 0.38, 0.48)
GROUND = (0.10, 0.09, 0.07)


def srgb_decode(c):
    c = np.asarray(c, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def srgb_encode(c):
    c = np.clip(c, 0.0, 1.0)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055)


def parse_mtl(path):
    mats, cur = {}, None
    for line in open(path):
        p = line.split()
        if not p or p[0].startswith("#"):
            continue
        if p[0] == "newmtl":
            cur = mats.setdefault(p[1], {"Kd": (1, 1, 1)})
        elif cur is not None and p[0] == "Kd":
            cur["Kd"] = tuple(float(x) for x in p[1:4])
        elif cur is not None and p[0] in ("map_Kd", "map_d"):
            cur[p[0]] = p[-1]
    return mats


def material_bsdf(m, model_dir, tmp):
    """Two-sided diffuse, albedo = Kd (sRGB tint, decoded) x texture."""
    kd = srgb_decode(m["Kd"])
    if "map_Kd" in m:
        img = Image.open(os.path.join(model_dir, m["map_Kd"])).convert("RGBA")
        a = np.asarray(img, dtype=np.float64) / 255.0
        lin = srgb_decode(a[..., :3]) * kd
        rgb = Image.fromarray((srgb_encode(lin) * 255 + 0.5).astype(np.uint8), "RGB")
        tex = os.path.join(tmp, os.path.basename(m["map_Kd"]) + ".tinted.png")
        rgb.save(tex)
        reflectance = {"type": "bitmap", "filename": tex}
    else:
        reflectance = {"type": "rgb", "value": kd.tolist()}
    return {"type": "twosided", "material": {"type": "diffuse", "reflectance": reflectance}}


def alpha_of(m, model_dir):
    """The material's alpha texture (8-bit, row 0 at the top), or None."""
    if "map_d" not in m:
        return None
    return np.asarray(Image.open(os.path.join(model_dir, m["map_d"])).convert("RGBA"))[..., 3]


def read_obj(path):
    """Triangles per material: {material: (positions, uvs, normals)}, each (n, 3, k)."""
    v, vt, vn, faces, mtllib, cur = [], [], [], {}, None, None
    for line in open(path):
        p = line.split()
        if not p:
            continue
        if p[0] == "v":
            v.append([float(x) for x in p[1:4]])
        elif p[0] == "vt":
            vt.append([float(x) for x in p[1:3]])
        elif p[0] == "vn":
            vn.append([float(x) for x in p[1:4]])
        elif p[0] == "mtllib":
            mtllib = line.split(maxsplit=1)[1].strip()
        elif p[0] == "usemtl":
            cur = p[1]
        elif p[0] == "f":
            # 1-based indices; negative ones count back from the latest element (0: none).
            counts = (len(v), len(vt), len(vn))
            idx = [
                [(int(x) if int(x) > 0 else counts[j] + 1 + int(x)) if x else 0
                 for j, x in enumerate((c.split("/") + ["", ""])[:3])]
                for c in p[1:]
            ]
            for k in range(1, len(idx) - 1):
                faces.setdefault(cur or "default", []).append([idx[0], idx[k], idx[k + 1]])
    v, vt, vn = np.array(v), np.array(vt or [[0.0, 0.0]]), np.array(vn or [[0.0, 1.0, 0.0]])
    out = {}
    for m, fs in faces.items():
        f = np.array(fs)  # (n, 3, 3): v, vt, vn indices (1-based; 0 = none)
        pos = v[f[..., 0] - 1]
        uv = np.where(f[..., 1:2] > 0, vt[np.maximum(f[..., 1], 1) - 1], 0.0)
        geo = np.cross(pos[:, 1] - pos[:, 0], pos[:, 2] - pos[:, 0])
        geo /= np.maximum(np.linalg.norm(geo, axis=1, keepdims=True), 1e-12)
        nrm = np.where(f[..., 2:3] > 0, vn[np.maximum(f[..., 2], 1) - 1], geo[:, None, :])
        out[m] = (pos, uv, nrm)
    return out, mtllib


def solid_parts(tris, alpha, n):
    """The alpha-tested surface as geometry: each triangle cut into n^2 sub-triangles, those
    whose centre lies on a texel of alpha >= 0.5 kept."""
    pos, uv, nrm = tris
    bary = []
    for i in range(n):
        for j in range(n - i):
            a, b, c = (i, j), (i + 1, j), (i, j + 1)
            bary.append([a, b, c])
            if j < n - i - 1:
                bary.append([b, (i + 1, j + 1), c])
    bary = np.array(bary, dtype=np.float64) / n  # (m, 3 corners, 2): weights of corners 1, 2
    w = np.concatenate([1 - bary.sum(-1, keepdims=True), bary], axis=-1)  # (m, 3, 3)
    h, wd = alpha.shape
    parts = ([], [], [])
    for start in range(0, len(pos), 1024):
        P, U, N = (x[start:start + 1024] for x in (pos, uv, nrm))
        sp, su, sn = (np.einsum("mcw,twk->tmck", w, x) for x in (P, U, N))
        centre = su.mean(axis=2)  # (t, m, 2); OBJ v = 0 is the bottom row
        x = (np.mod(centre[..., 0], 1.0) * wd).astype(int).clip(0, wd - 1)
        y = ((1.0 - np.mod(centre[..., 1], 1.0)) * h).astype(int).clip(0, h - 1)
        solid = alpha[y, x] >= 128
        for out, s in zip(parts, (sp, su, sn)):
            out.append(s[solid])
    return tuple(np.concatenate(p) for p in parts)


def write_ply(path, pos, uv, nrm):
    """Binary PLY of unshared triangles. Mitsuba's OBJ reader flips v and its PLY reader does
    not, so v is flipped here to keep the OBJ convention."""
    t = len(pos)
    vert = np.zeros((t * 3, 8), dtype="<f4")
    vert[:, 0:3] = pos.reshape(-1, 3)
    n = nrm.reshape(-1, 3)
    vert[:, 3:6] = n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    vert[:, 6] = uv.reshape(-1, 2)[:, 0]
    vert[:, 7] = 1.0 - uv.reshape(-1, 2)[:, 1]
    faces = np.zeros(t, dtype=[("n", "u1"), ("i", "<i4", (3,))])
    faces["n"] = 3
    faces["i"] = np.arange(t * 3, dtype="<i4").reshape(-1, 3)
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {t * 3}\n"
        "property float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        "property float u\nproperty float v\n"
        f"element face {t}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(vert.tobytes())
        f.write(faces.tobytes())


def view_arguments(ap, size, spp, cuts):
    """The arguments both Mitsuba scripts take: the sun, the camera, samples and alpha cuts."""
    ap.add_argument("--sun", required=True, help="AZ,EL degrees")
    ap.add_argument("--eye", required=True)
    ap.add_argument("--target", required=True)
    ap.add_argument("--fov", type=float, default=60.0)
    ap.add_argument("--size", default=size)
    ap.add_argument("--spp", type=int, default=spp)
    ap.add_argument("--cuts", type=int, default=cuts,
                    help="sub-triangles per edge of an alpha-tested triangle")
    ap.add_argument("-o", "--output", required=True, help="output stem (no extension)")


def parse_view(a):
    """The unit direction towards the sun (as forest_format::shading::sun_direction), its
    elevation (radians), and the Mitsuba sensor of the parsed arguments `a`."""
    az, el = (math.radians(float(x)) for x in a.sun.split(","))
    sun_dir = [math.cos(el) * math.sin(az), math.sin(el), math.cos(el) * math.cos(az)]
    w, h = (int(x) for x in a.size.split("x"))
    eye = [float(x) for x in a.eye.split(",")]
    target = [float(x) for x in a.target.split(",")]
    sensor = {
        "type": "perspective",
        "fov": a.fov,
        "fov_axis": "y",
        "near_clip": 0.05,
        "to_world": mi.ScalarTransform4f().look_at(origin=eye, target=target, up=[0, 1, 0]),
        "film": {"type": "hdrfilm", "width": w, "height": h, "pixel_format": "rgba",
                 "rfilter": {"type": "box"}},
        "sampler": {"type": "independent", "sample_count": a.spp},
    }
    return sun_dir, el, sensor


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("model")
    view_arguments(ap, "320x240", 64, 48)
    a = ap.parse_args()
    mi.set_variant("scalar_rgb")
    sun_dir, _, sensor = parse_view(a)
    model_dir = os.path.dirname(os.path.abspath(a.model))
    with tempfile.TemporaryDirectory() as tmp:
        tris, mtllib = read_obj(a.model)
        mats = parse_mtl(os.path.join(model_dir, mtllib)) if mtllib else {}
        # Environment: `sky` above the horizon, `ground` below (latitude-longitude, +Y up).
        env = np.zeros((32, 64, 3), dtype=np.float32)
        env[:16] = SKY
        env[16:] = GROUND
        scene = {
            "type": "scene",
            "integrator": {"type": "path", "max_depth": 2, "hide_emitters": True},
            "sensor": sensor,
        }
        for name, t in tris.items():
            m = mats.get(name, {"Kd": (0.5, 0.5, 0.5)})
            alpha = alpha_of(m, model_dir)
            if alpha is not None:
                t = solid_parts(t, alpha, a.cuts)
            path = os.path.join(tmp, f"{name}.ply")
            write_ply(path, *t)
            print(f"{name}: {len(t[0])} triangles")
            scene["shape_" + name] = {
                "type": "ply",
                "filename": path,
                "bsdf": material_bsdf(m, model_dir, tmp),
            }
        for suffix, with_sky in (("", True), ("-sun", False)):
            s = dict(scene)
            s["sun"] = {
                "type": "directional",
                "direction": [-x for x in sun_dir],
                "irradiance": {"type": "rgb", "value": [math.pi * c for c in SUN]},
            }
            if with_sky:
                s["sky"] = {"type": "envmap", "bitmap": mi.Bitmap(env)}
            img = np.array(mi.render(mi.load_dict(s)))
            rgb = img[..., :3]
            alpha = np.clip(img[..., 3], 0, 1)
            # Misses count as black: the colour is premultiplied, sRGB-encoded, as forest's
            # transparent targets and its downsampled reference hold it.
            out = np.concatenate([srgb_encode(rgb), alpha[..., None]], axis=-1)
            Image.fromarray((out * 255 + 0.5).astype(np.uint8), "RGBA").save(a.output + suffix + ".png")
            print("wrote", a.output + suffix + ".png")


if __name__ == "__main__":
    main()
