#!/usr/bin/env python3
"""Writes the images of scenes/textures.xml (deterministic; Python's standard library only):
  scenes/textures/bricks.png         a brick wall, sRGB colours (256 x 256)
  scenes/textures/bricks-height.png  its height field for bumpmap: 1 on the bricks, 0 in the
                                     mortar, with bevelled edges (grey, linear: raw = true)
  scenes/textures/dimples.png        a tangent-space normal map of a grid of round dimples
                                     (RGB = (n + 1) / 2, linear: raw = true)
  scenes/textures/uvgrid.png         a uv test grid: u in red, v in green, lines every 1/8
  scenes/textures/letters.png        32 x 32: "PL" in dark letters on four coloured quadrants, the
                                     texture that docs/differentiable.md recovers (scenes/diff-texture.xml)
Run from the repository's root: python3 scripts/make_texture_images.py"""
import math
import os
import struct
import zlib

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes", "textures")


def write_png(path, width, height, pixel):
    """pixel(x, y) -> (r, g, b) in 0..255; row 0 is the top of the image."""
    raw = bytearray()
    for y in range(height):
        raw.append(0)  # filter: none
        for x in range(width):
            raw.extend(max(0, min(255, int(round(c)))) for c in pixel(x, y))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


def brick(x, y, size=256):
    """(brick column, row, distance to the nearest mortar line in texels) at texel (x, y)."""
    bh, bw, mortar = size // 8, size // 4, 3
    row = y // bh
    xs = x + (bw // 2 if row % 2 else 0)
    col = (xs // bw) % 4
    dx = min(xs % bw, bw - 1 - xs % bw)
    dy = min(y % bh, bh - 1 - y % bh)
    return col, row, min(dx, dy) - mortar / 2


def hash01(*v):
    h = 2166136261
    for i in v:
        h = ((h ^ (i & 0xFFFFFFFF)) * 16777619) & 0xFFFFFFFF
    return h / 0xFFFFFFFF


def bricks(x, y):
    col, row, d = brick(x, y)
    if d < 0:
        return (200, 195, 185)  # mortar
    t = hash01(col, row)
    grain = 12 * (hash01(x, y, 7) - 0.5)
    return (150 + 60 * t + grain, 60 + 30 * t + grain, 40 + 15 * t + grain)


def bricks_height(x, y):
    _, _, d = brick(x, y)
    h = max(0.0, min(1.0, d / 3.0))  # a 3-texel bevel
    return (255 * h,) * 3


def dimples(x, y, size=256, cells=8):
    # Height: a spherical cap of radius 0.4 cell dug into each cell; normal = (-dh/dx, -dh/dy, 1)
    # in texel units of the cell, scaled so the steepest dimple wall tilts by about 45 degrees.
    c = size / cells
    u = (x + 0.5) / c % 1 - 0.5
    v = (y + 0.5) / c % 1 - 0.5
    r2 = u * u + v * v
    R = 0.4
    if r2 >= R * R * 0.98:
        n = (0.0, 0.0, 1.0)
    else:
        z = math.sqrt(R * R - r2)
        # h = -(z - ...): dh/du = u / z, dh/dv = v / z (the cap is dug in); image v grows downwards.
        gx, gy = u / z, v / z
        k = 0.8
        n = (-k * gx, -k * gy, 1.0)  # y along t = n x s, which follows v (down the image)
    L = math.sqrt(sum(a * a for a in n))
    return tuple(255 * (a / L + 1) / 2 for a in n)


# A 5 x 7 pixel font, just the letters used.
GLYPHS = {
    "P": ["11110", "10001", "10001", "11110", "10000", "10000", "10000"],
    "L": ["10000", "10000", "10000", "10000", "10000", "10000", "11111"],
}


def letters(x, y, size=32):
    """Four quadrants of sRGB colours, "PL" in 2 x 2 texel strokes across the middle."""
    quadrant = [[(214, 96, 77), (92, 168, 96)], [(84, 120, 200), (230, 200, 90)]][y * 2 // size][x * 2 // size]
    text, scale, gap = "PL", 2, 2
    width = len(text) * 5 * scale + (len(text) - 1) * gap
    x0, y0 = (size - width) // 2, (size - 7 * scale) // 2
    for i, ch in enumerate(text):
        gx, gy = (x - x0 - i * (5 * scale + gap)) // scale, (y - y0) // scale
        if 0 <= gx < 5 and 0 <= gy < 7 and x - x0 - i * (5 * scale + gap) >= 0 and y >= y0 and GLYPHS[ch][gy][gx] == "1":
            return (30, 30, 36)
    return quadrant


def uvgrid(x, y, size=256):
    u, v = (x + 0.5) / size, (y + 0.5) / size
    line = (x % (size // 8) in (0, size // 8 - 1)) or (y % (size // 8) in (0, size // 8 - 1))
    if line:
        return (20, 20, 20)
    return (40 + 215 * u, 40 + 215 * v, 90)


if __name__ == "__main__":
    os.makedirs(OUT, exist_ok=True)
    write_png(os.path.join(OUT, "bricks.png"), 256, 256, bricks)
    write_png(os.path.join(OUT, "bricks-height.png"), 256, 256, bricks_height)
    write_png(os.path.join(OUT, "dimples.png"), 256, 256, dimples)
    write_png(os.path.join(OUT, "uvgrid.png"), 256, 256, uvgrid)
    write_png(os.path.join(OUT, "letters.png"), 32, 32, letters)
