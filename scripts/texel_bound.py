#!/usr/bin/env python3
"""What any image-based tree costs close up: a perfect image seen through coarser texels.

Takes a reference render (RGBA PNG, e.g. `forest render --method geometry --supersample 4
--transparent`) and writes the same picture as a texture would show it whose texels each
cover K×K pixels: box-filtered into K-pixel texels (premultiplied, linear light), then
magnified back with the bilinear filter a GPU sampler uses. Compare the output with the
reference (`forest compare REF OUT`): the FLIP that remains is what magnification alone
costs, however exact the texels' colours, depths and coverage.

A slab image's texel is 2r/resolution metres (r the crown radius), and a pixel at distance
z is z·2·tan(fov/2)/height metres, so K = 2r·height / (resolution·z·2·tan(fov/2)): for the
bundled oak (r 3.79 m) at 512², 400×300 and 60°, K = 3.85 m / z — 1.5 at 2.6 m, 3 at 1.3 m.

Usage: texel_bound.py REFERENCE.png OUT.png K

Standard library only (zlib, struct), so it runs wherever the project builds.
"""

import math
import struct
import sys
import zlib


def read_png(path):
    """8-bit RGBA or RGB, non-interlaced PNG -> (width, height, rows of RGBA bytes)."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG")
    i, idat = 8, b""
    width = height = ctype = None
    while i < len(data):
        (n,) = struct.unpack(">I", data[i : i + 4])
        kind, chunk = data[i + 4 : i + 8], data[i + 8 : i + 8 + n]
        i += 12 + n
        if kind == b"IHDR":
            width, height, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", chunk)
            if depth != 8 or ctype not in (2, 6) or interlace:
                sys.exit(f"{path}: only 8-bit RGB/RGBA, non-interlaced PNGs are read")
        elif kind == b"IDAT":
            idat += chunk
    bpp = 4 if ctype == 6 else 3
    raw = zlib.decompress(idat)
    stride = width * bpp
    rows, prev, k = [], bytearray(stride), 0
    for _ in range(height):
        f, line = raw[k], bytearray(raw[k + 1 : k + 1 + stride])
        k += 1 + stride
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            b = prev[x]
            c = prev[x - bpp] if x >= bpp else 0
            if f == 1:
                line[x] = (line[x] + a) & 255
            elif f == 2:
                line[x] = (line[x] + b) & 255
            elif f == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line if bpp == 4 else bytearray(
            b for x in range(width) for b in (*line[3 * x : 3 * x + 3], 255)))
        prev = line
    return width, height, rows


def write_png(path, width, height, rows):
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(
            ">I", zlib.crc32(kind + body) & 0xFFFFFFFF)

    raw = b"".join(b"\x00" + bytes(r) for r in rows)
    header = struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw))
                + chunk(b"IEND", b""))


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__.split("Usage: ")[1].split("\n")[0])
    src, dst, k = sys.argv[1], sys.argv[2], float(sys.argv[3])
    if not k >= 1.0:
        sys.exit(f"K {sys.argv[3]} must be at least 1 (pixels per texel)")
    w, h, rows = read_png(src)
    lin = [(c / 255.0) ** 2.2 for c in range(256)]
    tw, th = math.ceil(w / k), math.ceil(h / k)
    # Texels: premultiplied linear colour and coverage, averaged over their pixels.
    tex = []
    for ty in range(th):
        line = []
        for tx in range(tw):
            acc, n = [0.0] * 4, 0
            for y in range(int(ty * k), min(int((ty + 1) * k), h)):
                r = rows[y]
                for x in range(int(tx * k), min(int((tx + 1) * k), w)):
                    a = r[4 * x + 3] / 255.0
                    for m in range(3):
                        acc[m] += lin[r[4 * x + m]] * a
                    acc[3] += a
                    n += 1
            line.append([v / max(n, 1) for v in acc])
        tex.append(line)

    def texel(i, j):
        return tex[min(max(j, 0), th - 1)][min(max(i, 0), tw - 1)]

    out = []
    for y in range(h):
        fy = (y + 0.5) / k - 0.5
        y0 = math.floor(fy)
        ay = fy - y0
        line = bytearray()
        for x in range(w):
            fx = (x + 0.5) / k - 0.5
            x0 = math.floor(fx)
            ax = fx - x0
            t00, t10, t01, t11 = texel(x0, y0), texel(x0 + 1, y0), texel(x0, y0 + 1), texel(x0 + 1, y0 + 1)
            c = [(1 - ax) * (1 - ay) * t00[m] + ax * (1 - ay) * t10[m] + (1 - ax) * ay * t01[m]
                 + ax * ay * t11[m] for m in range(4)]
            a = c[3]
            rgb = [round(255 * (c[m] / a) ** (1 / 2.2)) if a > 0 else 0 for m in range(3)]
            line += bytes([min(v, 255) for v in rgb] + [round(a * 255)])
        out.append(line)
    write_png(dst, w, h, out)


if __name__ == "__main__":
    main()
