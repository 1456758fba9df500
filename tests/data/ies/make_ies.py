#!/usr/bin/env python3
"""Writes the IES LM-63 test files of this folder (pathlab's own, made for the tests).

Each file tabulates a smooth analytic distribution, with its total flux stated as the lamps'
lumens, so that the tests can check the parsed values against the formula and the integrated
flux against the lumens. One file per horizontal symmetry of type C photometry:
  downlight-rotational.ies   LM-63-2002  last horizontal angle 0    I = I0 cos(g)
  corridor-quadrant.ies      LM-63-1995  0 .. 90 (quadrants)        I = I0 cos(g) (1 + 0.5 cos 2C)
  wallwasher-bilateral.ies   LM-63-2002  0 .. 180, TILT=INCLUDE     I = I0 (0.1 + max(cos g, 0) (1 + 0.6 cos C))
  asymmetric-full.ies        LM-63-2002  0 .. 360                   I = I0 cos(g) (1 + 0.4 cos(C - 60))
  bilateral-90-270.ies       LM-63-1995  90 .. 270                  I = I0 cos(g) (1 + 0.5 sin C)
(g: vertical angle from the nadir, C: horizontal angle, degrees). Values are written with two
decimals. It also writes scenes/ies/narrow-downlight.ies for scenes/ies.xml (I = I0 cos(g)^6,
a narrow beam that draws scallops on a wall). Run: /usr/bin/python3 tests/data/ies/make_ies.py
"""
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def cosd(a):
    return math.cos(math.radians(a))


def sind(a):
    return math.sin(math.radians(a))


def rows(values, per_line=10):
    out = []
    for i in range(0, len(values), per_line):
        out.append(" ".join(values[i:i + per_line]))
    return "\n".join(out)


def fmt_angle(a):
    return ("%.1f" % a).rstrip("0").rstrip(".") if a != int(a) else "%d" % a


def write(name, header, tilt, lamps, lumens, multiplier, vertical, horizontal, candela, ballast=1.0, blp=1.0, watts=20.0,
          width=0.1, length=0.1, height=0.02):
    # candela(g, C): the luminaire's true candela; the file stores them / (multiplier * ballast * blp).
    div = multiplier * ballast * (blp if "1995" in header[0] else 1.0)
    lines = list(header)
    lines.append(tilt)
    lines.append("%d %g %g %d %d 1 2 %g %g %g" % (lamps, lumens, multiplier, len(vertical), len(horizontal), width, length, height))
    lines.append("%g %g %g" % (ballast, blp, watts))
    lines.append(rows([fmt_angle(a) for a in vertical]))
    lines.append(rows([fmt_angle(a) for a in horizontal]))
    for c in horizontal:
        lines.append(rows(["%.2f" % (candela(g, c) / div) for g in vertical]))
    with open(os.path.join(HERE, name) if "/" not in name else name, "w", newline="\r\n") as f:
        f.write("\n".join(lines) + "\n")


def keywords(version, test, luminaire, lamp):
    return [version, "[TEST] " + test, "[TESTLAB] pathlab (synthetic test data)", "[ISSUEDATE] 2024-05-01",
            "[MANUFAC] pathlab", "[LUMCAT] " + test, "[LUMINAIRE] " + luminaire, "[LAMP] " + lamp,
            "[OTHER] made by tests/data/ies/make_ies.py from an analytic distribution"]


v5 = [5 * i for i in range(19)]      # 0 .. 90
v10 = [10 * i for i in range(10)]    # 0 .. 90
v10_180 = [10 * i for i in range(19)]  # 0 .. 180

# 1000 lm Lambertian downlight: flux = pi I0.
I0 = 1000 / math.pi
write("downlight-rotational.ies", keywords("IESNA:LM-63-2002", "PL-DL-1000", "LED downlight, rotationally symmetric",
                                           "LED module 1000 lm 3000 K"),
      "TILT=NONE", 1, 1000, 1, v5, [0], lambda g, c: I0 * cosd(g), watts=11)

# 2 x 1500 lm, ballast factor 0.95, candela multiplier 0.5: flux 2850 lm = pi I0.
I0q = 2 * 1500 * 0.95 / math.pi
write("corridor-quadrant.ies", keywords("IESNA:LM-63-1995", "PL-CR-3000", "corridor luminaire, symmetric in each quadrant",
                                        "2 x T5 tube 1500 lm"),
      "TILT=NONE", 2, 1500, 0.5, v10, [0, 22.5, 45, 67.5, 90],
      lambda g, c: I0q * cosd(g) * (1 + 0.5 * cosd(2 * c)), ballast=0.95, watts=52)

# 2400 lm wall washer with an uplight part: flux = I0 (0.1 * 4 pi + pi).
I0b = 2400 / (1.4 * math.pi)
tilt = "TILT=INCLUDE\n1\n7\n0 15 30 45 60 75 90\n1 0.98 0.95 0.9 0.85 0.8 0.7"
write("wallwasher-bilateral.ies", keywords("IESNA:LM-63-2002", "PL-WW-2400", "wall washer, symmetric about the 0-180 plane",
                                           "LED module 2400 lm 4000 K"),
      tilt, 1, 2400, 1, v10_180, [30 * i for i in range(7)],
      lambda g, c: I0b * (0.1 + max(cosd(g), 0.0) * (1 + 0.6 * cosd(c))), watts=24)

# 1800 lm asymmetric floodlight: flux = pi I0.
I0a = 1800 / math.pi
write("asymmetric-full.ies", keywords("IESNA:LM-63-2002", "PL-FL-1800", "asymmetric floodlight, no symmetry",
                                      "LED module 1800 lm 4000 K"),
      "TILT=NONE", 1, 1800, 1, v10, [30 * i for i in range(13)],
      lambda g, c: I0a * cosd(g) * (1 + 0.4 * cosd(c - 60)), watts=18)

# 1200 lm, symmetric about the 90-270 plane (horizontal angles 90 .. 270): flux = pi I0.
I0s = 1200 / math.pi
write("bilateral-90-270.ies", keywords("IESNA:LM-63-1995", "PL-BL-1200", "bollard, symmetric about the 90-270 plane",
                                       "LED module 1200 lm 3000 K"),
      "TILT=NONE", 1, 1200, 1, v10, [90 + 30 * i for i in range(7)],
      lambda g, c: I0s * cosd(g) * (1 + 0.5 * sind(c)), watts=14)

# 1500 lm narrow downlight for scenes/ies.xml: flux = 2 pi I0 / 7.
I0n = 1500 * 7 / (2 * math.pi)
write(os.path.join(HERE, "..", "..", "..", "scenes", "ies", "narrow-downlight.ies"),
      keywords("IESNA:LM-63-2002", "PL-ND-1500", "narrow downlight, rotationally symmetric", "LED module 1500 lm 3000 K"),
      "TILT=NONE", 1, 1500, 1, [2.5 * i for i in range(37)], [0], lambda g, c: I0n * cosd(g) ** 6, watts=15)
