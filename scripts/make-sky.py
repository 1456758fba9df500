#!/usr/bin/env python3
"""Writes scenes/envmaps/sky.exr: a small procedural sky with a sun, as a latitude-longitude map.

The map is in Mitsuba 3's convention (src/lights/envmap.hpp): the top row looks up (+y), u = 0
towards -z, u = 1/4 towards +x. The sky darkens from a pale horizon to a blue zenith, with a
glow around the sun; the ground below the horizon is a dim brown; the sun is a disk of 2 degrees
radius (four times the real one, so that a 256 x 128 map resolves it) whose irradiance on a
surface facing it is about three times the sky's on the ground. Each texel averages 4 x 4
points. Written as an uncompressed scanline OpenEXR file with half-float R, G, B channels by
hand (no OpenEXR module needed).

Run: /usr/bin/python3 scripts/make-sky.py [OUT] [WIDTH]   (defaults scenes/envmaps/sky.exr, 256)
"""
import math
import os
import struct
import sys

OUT = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "scenes", "envmaps", "sky.exr")
W = int(sys.argv[2]) if len(sys.argv) > 2 else 256
H = W // 2

SUN_ELEVATION, SUN_AZIMUTH, SUN_RADIUS = math.radians(35), math.radians(110), math.radians(2.0)
SUN_RADIANCE = (1200.0, 1080.0, 930.0)
ZENITH, HORIZON, GROUND = (0.10, 0.22, 0.55), (0.75, 0.80, 0.88), (0.09, 0.075, 0.06)


def direction(u, v):
    theta, phi = v * math.pi, u * 2 * math.pi
    return (math.sin(phi) * math.sin(theta), math.cos(theta), -math.cos(phi) * math.sin(theta))


SUN = direction(SUN_AZIMUTH / (2 * math.pi), 0.5 - SUN_ELEVATION / math.pi)


def radiance(d):
    cos_sun = sum(a * b for a, b in zip(d, SUN))
    if cos_sun >= math.cos(SUN_RADIUS):
        return SUN_RADIANCE
    if d[1] < 0:  # the ground, a little lighter towards the horizon
        t = math.exp(8 * d[1])
        return tuple(g * (0.7 + 0.3 * t) for g in GROUND)
    t = (1 - d[1]) ** 3  # 0 at the zenith, 1 at the horizon
    glow = 1.5 * math.exp(-math.acos(max(-1.0, min(1.0, cos_sun))) / 0.25) + 0.15 * (1 + cos_sun * cos_sun)
    return tuple(z + (h - z) * t + glow * h for z, h in zip(ZENITH, HORIZON))


def texel(x, y, n=4):
    acc = [0.0, 0.0, 0.0]
    for j in range(n):
        for i in range(n):
            r = radiance(direction((x + (i + 0.5) / n) / W, (y + (j + 0.5) / n) / H))
            for c in range(3):
                acc[c] += r[c]
    return [a / (n * n) for a in acc]


def attribute(name, type_, value):
    return name.encode() + b"\0" + type_.encode() + b"\0" + struct.pack("<i", len(value)) + value


def write_exr(path, pixels):
    chlist = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", 1, 0, 1, 1) for c in "BGR") + b"\0"
    box = struct.pack("<iiii", 0, 0, W - 1, H - 1)
    header = b"".join([
        attribute("channels", "chlist", chlist),
        attribute("compression", "compression", b"\0"),
        attribute("dataWindow", "box2i", box),
        attribute("displayWindow", "box2i", box),
        attribute("lineOrder", "lineOrder", b"\0"),
        attribute("pixelAspectRatio", "float", struct.pack("<f", 1.0)),
        attribute("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0)),
        attribute("screenWindowWidth", "float", struct.pack("<f", 1.0)),
    ]) + b"\0"
    start = 8 + len(header) + 8 * H
    block_size = 8 + 3 * 2 * W
    out = bytearray(b"\x76\x2f\x31\x01" + struct.pack("<i", 2) + header)
    out += b"".join(struct.pack("<Q", start + y * block_size) for y in range(H))
    for y in range(H):
        out += struct.pack("<ii", y, 3 * 2 * W)
        for c in (2, 1, 0):  # B, G, R
            out += struct.pack("<%de" % W, *(pixels[y][x][c] for x in range(W)))
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "wb") as f:
        f.write(out)


write_exr(OUT, [[texel(x, y) for x in range(W)] for y in range(H)])
