#!/usr/bin/env python3
"""Writes assets/gltf-corpus: small glTF 2.0 trees shaped as real exporters write them.

Each file is a tree of leaf cards around a trunk, made from the same deterministic geometry,
and differs in how it is stored, as the tools the project meets store it:

- blender.glb: Blender's glTF exporter: one GLB, images in the binary chunk, separate
  (non-interleaved) attribute views, u16 indices, TRS nodes with a trunk parent and a crown
  child, a MASK leaf material with doubleSided, an animation (wind sway) that the bake does
  not need, asset.generator and extras, KHR_materials_specular used but not required.
- interleaved.gltf (+ .bin, .png): a .gltf with an external buffer and images: positions,
  normals and texture coordinates interleaved in one view (byteStride 32), u32 indices, a
  node `matrix`, a BLEND leaf material with a baseColorFactor tint, a sampler with REPEAT and
  mipmap filters, no `scene` (the first scene is taken), vertex colours (COLOR_0).
- instanced.gltf (+ .bin, .png): features from the Khronos sample models that trees use: one
  mesh of two primitives shared by three nodes (instancing by nodes), texture coordinates as
  normalised u16, a primitive without a material (glTF's default material), a camera, URIs
  with percent escapes, a non-default alphaCutoff (0.3).

Standard library only. Every byte is generated here (no third-party data): the files are
the project's own, under its licence (see assets/gltf-corpus/LICENSE).

    python3 scripts/make_gltf_corpus.py [OUT_DIR]
"""

import json
import math
import os
import struct
import sys
import zlib

OUT = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
    os.path.dirname(os.path.abspath(__file__)), "..", "assets", "gltf-corpus")


def png(width, height, pixel):
    """An 8-bit RGBA PNG of pixel(x, y) -> (r, g, b, a)."""
    raw = b"".join(
        b"\0" + b"".join(bytes(pixel(x, y)) for x in range(width)) for y in range(height))

    def chunk(kind, data):
        c = struct.pack(">I", len(data)) + kind + data
        return c + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def leaf_pixel(x, y):
    """A leaf: an ellipse with a midrib, transparent around it (32×32)."""
    u, v = (x + 0.5) / 32 * 2 - 1, (y + 0.5) / 32 * 2 - 1
    inside = (u / 0.55) ** 2 + v ** 2 <= 1.0
    green = 110 + int(40 * (1 - abs(v)))
    if abs(u) < 0.06:
        return (70, 95, 40, 255 if inside else 0)
    return (50, green, 35, 255 if inside else 0)


def bark_pixel(x, y):
    """Bark: brown with vertical streaks (16×16), opaque."""
    s = ((x * 7919 + (y // 4) * 104729) % 23) * 3
    return (90 + s // 2, 62 + s // 3, 40 + s // 4, 255)


def tree():
    """Trunk and leaf cards: (trunk, leaves), each (positions, normals, uvs, indices)."""
    trunk = ([], [], [], [])
    sides = 6
    for k in range(sides + 1):
        a = 2 * math.pi * k / sides
        c, s = math.cos(a), math.sin(a)
        for y, r in ((0.0, 0.18), (2.2, 0.1)):
            trunk[0].append((r * c, y, r * s))
            trunk[1].append((c, 0.0, s))
            trunk[2].append((k / sides, y / 2.2))
    for k in range(sides):
        i = 2 * k
        trunk[3].extend((i, i + 2, i + 1, i + 1, i + 2, i + 3))
    leaves = ([], [], [], [])
    # Cards on a golden-angle spiral over a crown of radius 1.2 centred 1.1 m above the
    # crown node (which sits on the trunk's top): 40 cards, each 0.35 m, facing outwards.
    for k in range(40):
        t = (k + 0.5) / 40
        el = math.asin(1 - 2 * t)
        az = k * 2.399963
        r = 1.2 * (0.55 + 0.45 * ((k * 37) % 11) / 10)
        cx, cy, cz = r * math.cos(el) * math.cos(az), 1.1 + r * math.sin(el), r * math.cos(el) * math.sin(az)
        n = (math.cos(el) * math.cos(az), math.sin(el), math.cos(el) * math.sin(az))
        right = (-math.sin(az), 0.0, math.cos(az))
        up = (n[1] * right[2] - n[2] * right[1], n[2] * right[0] - n[0] * right[2], n[0] * right[1] - n[1] * right[0])
        h = 0.175
        base = len(leaves[0])
        for (a, b, uv) in ((-1, -1, (0, 1)), (1, -1, (1, 1)), (1, 1, (1, 0)), (-1, 1, (0, 0))):
            leaves[0].append(tuple(c + h * (a * rr + b * uu) for c, rr, uu in zip((cx, cy, cz), right, up)))
            leaves[1].append(n)
            leaves[2].append(uv)
        leaves[3].extend((base, base + 1, base + 2, base, base + 2, base + 3))
    return trunk, leaves


class Buffer:
    """A glTF buffer being filled: views and accessors appended to `doc`."""

    def __init__(self, doc):
        self.doc, self.data = doc, bytearray()
        doc.setdefault("bufferViews", [])
        doc.setdefault("accessors", [])

    def view(self, data, stride=None, target=None):
        while len(self.data) % 4:
            self.data += b"\0"
        v = {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(data)}
        if stride:
            v["byteStride"] = stride
        if target:
            v["target"] = target
        self.data += data
        self.doc["bufferViews"].append(v)
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, view, ctype, count, kind, offset=0, normalized=False, bounds=None):
        a = {"bufferView": view, "componentType": ctype, "count": count, "type": kind}
        if offset:
            a["byteOffset"] = offset
        if normalized:
            a["normalized"] = True
        if bounds:
            a["min"], a["max"] = bounds
        self.doc["accessors"].append(a)
        return len(self.doc["accessors"]) - 1


def bounds(points):
    return ([min(p[i] for p in points) for i in range(3)], [max(p[i] for p in points) for i in range(3)])


def separate(buf, part, uv16=False):
    """Separate views per attribute (Blender's layout): the primitive's attributes, indices."""
    pos, nrm, uv, idx = part
    f = lambda vs: b"".join(struct.pack("<%df" % len(v), *v) for v in vs)
    a = {"POSITION": buf.accessor(buf.view(f(pos), target=34962), 5126, len(pos), "VEC3", bounds=bounds(pos)),
         "NORMAL": buf.accessor(buf.view(f(nrm), target=34962), 5126, len(nrm), "VEC3")}
    if uv16:
        data = b"".join(struct.pack("<2H", round(u * 65535), round(v * 65535)) for u, v in uv)
        a["TEXCOORD_0"] = buf.accessor(buf.view(data, target=34962), 5123, len(uv), "VEC2", normalized=True)
    else:
        a["TEXCOORD_0"] = buf.accessor(buf.view(f(uv), target=34962), 5126, len(uv), "VEC2")
    i = buf.accessor(buf.view(struct.pack("<%dH" % len(idx), *idx), target=34963), 5123, len(idx), "SCALAR")
    return {"attributes": a, "indices": i}


def write_glb(path, doc, data):
    while len(data) % 4:
        data += b"\0"
    doc["buffers"] = [{"byteLength": len(data)}]
    text = json.dumps(doc, separators=(",", ":")).encode()
    while len(text) % 4:
        text += b" "
    body = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(data), 0x004E4942) + data
    with open(path, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)


def write_gltf(path, doc, data, bin_name):
    doc["buffers"] = [{"uri": bin_name, "byteLength": len(data)}]
    with open(os.path.join(os.path.dirname(path), bin_name.replace("%20", " ")), "wb") as f:
        f.write(bytes(data))
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)


def blender(trunk, leaves):
    doc = {"asset": {"version": "2.0", "generator": "Khronos glTF Blender I/O v4.2.57"},
           "extensionsUsed": ["KHR_materials_specular"], "scene": 0,
           "scenes": [{"name": "Scene", "nodes": [0]}],
           "nodes": [{"name": "Trunk", "mesh": 0, "children": [1], "rotation": [0, 0.0871557, 0, 0.9961947]},
                     {"name": "Crown", "mesh": 1, "translation": [0, 1.4, 0], "scale": [1.1, 1.0, 1.1]}],
           "materials": [
               {"name": "Bark", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0,
                                                          "roughnessFactor": 0.9},
                "extensions": {"KHR_materials_specular": {"specularFactor": 0.3}}},
               {"name": "Leaf", "doubleSided": True, "alphaMode": "MASK",
                "pbrMetallicRoughness": {"baseColorTexture": {"index": 1}, "metallicFactor": 0}}],
           "textures": [{"sampler": 0, "source": 0}, {"sampler": 0, "source": 1}],
           "samplers": [{"magFilter": 9729, "minFilter": 9987}],
           "extras": {"blender": {"version": "4.2"}}}
    buf = Buffer(doc)
    doc["meshes"] = [{"name": "Trunk", "primitives": [dict(separate(buf, trunk), material=0)]},
                     {"name": "Leaves", "primitives": [dict(separate(buf, leaves), material=1)]}]
    images = []
    for name, w, h, px in (("bark", 16, 16, bark_pixel), ("leaf", 32, 32, leaf_pixel)):
        images.append({"name": name, "mimeType": "image/png", "bufferView": buf.view(png(w, h, px))})
    doc["images"] = images
    # Wind sway: the crown's rotation over 2 s (times, then quaternions).
    times = buf.accessor(buf.view(struct.pack("<3f", 0, 1, 2)), 5126, 3, "SCALAR", bounds=([0], [2]))
    s = math.sin(0.02)
    quats = buf.accessor(buf.view(struct.pack("<12f", 0, 0, 0, 1, s, 0, 0, math.cos(0.02), 0, 0, 0, 1)),
                         5126, 3, "VEC4")
    doc["animations"] = [{"name": "Wind", "samplers": [{"input": times, "output": quats}],
                          "channels": [{"sampler": 0, "target": {"node": 1, "path": "rotation"}}]}]
    write_glb(os.path.join(OUT, "blender.glb"), doc, buf.data)


def interleaved(trunk, leaves):
    doc = {"asset": {"version": "2.0", "generator": "interleaving exporter"},
           "scenes": [{"nodes": [0]}],
           "nodes": [{"name": "tree", "mesh": 0,
                      "matrix": [0.9, 0, 0, 0, 0, 0.9, 0, 0, 0, 0, 0.9, 0, 0.5, 0, -0.25, 1]}],
           "materials": [
               {"name": "bark", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}},
               {"name": "leaves", "alphaMode": "BLEND", "doubleSided": True,
                "pbrMetallicRoughness": {"baseColorTexture": {"index": 1},
                                         "baseColorFactor": [0.9, 1.0, 0.8, 1.0]}}],
           "textures": [{"sampler": 0, "source": 0}, {"sampler": 0, "source": 1}],
           "samplers": [{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}],
           "images": [{"uri": "interleaved-bark.png"}, {"uri": "interleaved-leaf.png"}]}
    buf = Buffer(doc)
    prims = []
    for part, material in ((trunk, 0), (leaves, 1)):
        pos, nrm, uv, idx = part
        data = b"".join(struct.pack("<8f", *p, *n, *t) for p, n, t in zip(pos, nrm, uv))
        v = buf.view(data, stride=32, target=34962)
        colours = buf.view(b"".join(struct.pack("<4B", 200, 200, 200, 255) for _ in pos), target=34962)
        prims.append({"attributes": {
            "POSITION": buf.accessor(v, 5126, len(pos), "VEC3", bounds=bounds(pos)),
            "NORMAL": buf.accessor(v, 5126, len(pos), "VEC3", offset=12),
            "TEXCOORD_0": buf.accessor(v, 5126, len(pos), "VEC2", offset=24),
            "COLOR_0": buf.accessor(colours, 5121, len(pos), "VEC4", normalized=True)},
            "indices": buf.accessor(buf.view(struct.pack("<%dI" % len(idx), *idx), target=34963),
                                    5125, len(idx), "SCALAR"),
            "material": material})
    doc["meshes"] = [{"primitives": prims}]
    for name, w, h, px in (("interleaved-bark.png", 16, 16, bark_pixel), ("interleaved-leaf.png", 32, 32, leaf_pixel)):
        with open(os.path.join(OUT, name), "wb") as f:
            f.write(png(w, h, px))
    write_gltf(os.path.join(OUT, "interleaved.gltf"), doc, buf.data, "interleaved.bin")


def instanced(trunk, leaves):
    doc = {"asset": {"version": "2.0", "generator": "sample-model features"}, "scene": 0,
           "scenes": [{"nodes": [0, 1, 2, 3]}],
           "nodes": [{"mesh": 0},
                     {"mesh": 0, "translation": [0.4, 0.3, 0.1], "rotation": [0, 0.7071068, 0, 0.7071068],
                      "scale": [0.6, 0.6, 0.6]},
                     {"mesh": 0, "translation": [-0.3, 0.5, 0.2], "rotation": [0, -0.3826834, 0, 0.9238795],
                      "scale": [0.5, 0.5, 0.5]},
                     {"camera": 0, "translation": [0, 1.5, 6]}],
           "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.05, "aspectRatio": 1.5}}],
           "materials": [{"name": "leaf", "alphaMode": "MASK", "alphaCutoff": 0.3, "doubleSided": True,
                          "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
           "textures": [{"source": 0}],
           "images": [{"uri": "instanced%20leaf.png"}]}
    buf = Buffer(doc)
    doc["meshes"] = [{"primitives": [separate(buf, trunk), dict(separate(buf, leaves, uv16=True), material=0)]}]
    with open(os.path.join(OUT, "instanced leaf.png"), "wb") as f:
        f.write(png(32, 32, leaf_pixel))
    write_gltf(os.path.join(OUT, "instanced.gltf"), doc, buf.data, "instanced%20tree.bin")


if __name__ == "__main__":
    os.makedirs(OUT, exist_ok=True)
    t, l = tree()
    blender(t, l)
    interleaved(t, l)
    instanced(t, l)
    print("wrote", sorted(os.listdir(OUT)))
