#!/usr/bin/env python3
"""Writes the many-light scenes (issue "Many lights"; docs/lights.md):

  scenes/many-lights.xml     a hall of 24 x 24 m split in three by partitions, the camera in the
                             middle part; 2304 small emissive tiles of different powers and tints
                             under the ceiling, two thirds of them behind the partitions
  scenes/emissive-lamp.xml   a room lit by a lamp whose shade is an emissive mesh
  scenes/meshes/lamp-shade.obj   (1024 emitting triangles, each one a light)

Deterministic (a fixed seed): running it again gives the same files.
    python3 scripts/make-many-lights.py
"""
import math
import os
import random

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes")


def preamble(origin, target, width, height, white):
    """The scene element's start: the camera (fov 70) and the walls' white, red and blue."""
    return f"""<scene version="3.0.0">
    <default name="spp" value="64"/>
    <sensor type="perspective">
        <float name="fov" value="70"/>
        <transform name="to_world"><lookat origin="{origin}" target="{target}" up="0, 0, 1"/></transform>
        <film type="hdrfilm"><integer name="width" value="{width}"/><integer name="height" value="{height}"/><rfilter type="box"/></film>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    </sensor>

    <bsdf type="twosided" id="white"><bsdf type="diffuse"><rgb name="reflectance" value="{white}"/></bsdf></bsdf>
    <bsdf type="twosided" id="red"><bsdf type="diffuse"><rgb name="reflectance" value="0.7, 0.15, 0.1"/></bsdf></bsdf>
    <bsdf type="twosided" id="blue"><bsdf type="diffuse"><rgb name="reflectance" value="0.15, 0.25, 0.65"/></bsdf></bsdf>
"""


def rect(transform, body):
    return f'    <shape type="rectangle"><transform name="to_world">{transform}</transform>{body}</shape>\n'


def wall_x(x, y0, y1, z0, z1, ref="white"):
    """A wall in the plane x = const over [y0, y1] x [z0, z1]."""
    sy, sz = (y1 - y0) / 2, (z1 - z0) / 2
    return rect(f'<scale x="{sz:g}" y="{sy:g}"/><rotate y="1" angle="90"/><translate x="{x:g}" y="{(y0 + y1) / 2:g}" z="{(z0 + z1) / 2:g}"/>',
                f'<ref id="{ref}"/>')


def room_shell():
    out = ""
    # Floor, ceiling and the four walls of the hall [-12, 12] x [0, 24] x [0, 3].
    out += rect('<scale x="12" y="12"/><translate y="12"/>', '<ref id="floor"/>')
    out += rect('<scale x="12" y="12"/><rotate x="1" angle="180"/><translate y="12" z="3"/>', '<ref id="white"/>')
    out += rect('<scale x="12" y="1.5"/><rotate x="1" angle="90"/><translate y="24" z="1.5"/>', '<ref id="white"/>')
    out += rect('<scale x="12" y="1.5"/><rotate x="1" angle="-90"/><translate z="1.5"/>', '<ref id="white"/>')
    out += wall_x(-12, 0, 24, 0, 3, "red")
    out += wall_x(12, 0, 24, 0, 3, "blue")
    # Two partitions across the hall at x = -4 and x = 4, each leaving a passage y in [20, 24]:
    # the lights of the side parts are behind them.
    for x in (-4, 4):
        out += wall_x(x, 0, 20, 0, 3)
    return out


def many_lights():
    rng = random.Random(20261205)
    tiles = ""
    count = 0
    size = 0.06  # half the side of a tile
    # 48 x 48 tiles under the ceiling (a grid of 0.5), facing down.
    for i in range(48):
        for j in range(48):
            x, y = -12 + 0.5 * (i + 0.5), 0.5 * (j + 0.5)
            if abs(abs(x) - 4) < 0.2:
                continue  # not inside a partition
            tiles += tile(rng, f'<scale value="{size}"/><rotate x="1" angle="180"/><translate x="{x:.3f}" y="{y:.3f}" z="2.999"/>')
            count += 1
    head = f"""<!-- Many lights: a hall of 24 x 24 x 3 ([-12, 12] x [0, 24] x [0, 3]) split in three by two
     partitions (x = -4 and 4, open at the far end), the camera in the middle part looking down at
     the floor and the partitions (the tiles themselves out of view). {count}
     small emissive tiles under the ceiling (each two triangles, so twice as many lights) of
     radiances spread over two decades and of different tints; two thirds of them are behind the
     partitions, and from any point most of the others are far away. Choosing a light by power
     alone spends most shadow rays on lights far away or hidden; --light-sampler bvh chooses by
     each light's bound at the shading point (docs/lights.md).
     Made by scripts/make-many-lights.py (do not edit by hand).
     pathlab --scene scenes/many-lights.xml -a pt-mis --light-sampler bvh --spp 64 -o many-lights.png -->
""" + preamble("2.5, 0.5, 1.2", "-2.5, 9, -4.8", 256, 256, "0.7") + """    <bsdf type="twosided" id="floor"><bsdf type="roughplastic"><rgb name="diffuse_reflectance" value="0.45, 0.35, 0.25"/><float name="alpha" value="0.2"/></bsdf></bsdf>
    <bsdf type="diffuse" id="tile"><rgb name="reflectance" value="0"/></bsdf>

"""
    return head + room_shell() + "\n" + tiles + "</scene>\n"


def tile(rng, transform):
    level = 10 ** rng.uniform(-0.7, 1.3)  # radiance 0.2 to 20
    tint = rng.choice([(1.0, 0.85, 0.6), (1.0, 1.0, 1.0), (0.6, 0.8, 1.0), (1.0, 0.5, 0.3)])
    r, g, b = (level * c for c in tint)
    return rect(transform, f'<ref id="tile"/><emitter type="area"><rgb name="radiance" value="{r:.3g}, {g:.3g}, {b:.3g}"/></emitter>')


def lamp_shade_obj(segments=64, rings=8):
    """A truncated cone (radius 0.35 at the bottom, 0.2 at the top, 0.4 tall), its normals outward."""
    lines = ["# A lamp shade: a truncated cone of %d x %d quads (scripts/make-many-lights.py)" % (segments, rings)]
    for k in range(rings + 1):
        t = k / rings
        r, z = 0.35 + (0.2 - 0.35) * t, 0.4 * t
        for i in range(segments):
            a = 2 * math.pi * i / segments
            lines.append(f"v {r * math.cos(a):.6f} {r * math.sin(a):.6f} {z:.6f}")
    idx = lambda k, i: k * segments + (i % segments) + 1
    for k in range(rings):
        for i in range(segments):
            a, b, c, d = idx(k, i), idx(k, i + 1), idx(k + 1, i + 1), idx(k + 1, i)
            lines.append(f"f {a} {b} {c}")
            lines.append(f"f {a} {c} {d}")
    return "\n".join(lines) + "\n"


def emissive_lamp():
    return """<!-- A room lit by a lamp whose shade is an emissive mesh: 1024 triangles, each one a light, on a
     truncated cone (scenes/meshes/lamp-shade.obj) standing on a table in a room of [-2, 2] x [-2, 2] x [0, 3].
     From any point of the room about half of the shade's triangles face away; --light-sampler bvh sees
     it from their normal cones, power alone does not (docs/lights.md).
     Made by scripts/make-many-lights.py (do not edit by hand).
     pathlab --scene scenes/emissive-lamp.xml -a pt-mis --light-sampler bvh --spp 64 -o emissive-lamp.png -->
""" + preamble("0, -1.9, 1.4", "0, 0.6, 1.0", 320, 240, "0.75") + """    <bsdf type="twosided" id="wood"><bsdf type="roughplastic"><rgb name="diffuse_reflectance" value="0.4, 0.25, 0.12"/><float name="alpha" value="0.15"/></bsdf></bsdf>
    <bsdf type="diffuse" id="shade"><rgb name="reflectance" value="0"/></bsdf>

    <shape type="rectangle"><transform name="to_world"><scale value="2"/></transform><ref id="white"/></shape>
    <shape type="rectangle"><transform name="to_world"><scale value="2"/><rotate x="1" angle="180"/><translate z="3"/></transform><ref id="white"/></shape>
    <shape type="rectangle"><transform name="to_world"><scale x="2" y="1.5"/><rotate x="1" angle="90"/><translate y="2" z="1.5"/></transform><ref id="white"/></shape>
    <shape type="rectangle"><transform name="to_world"><scale x="1.5" y="2"/><rotate y="1" angle="90"/><translate x="-2" z="1.5"/></transform><ref id="red"/></shape>
    <shape type="rectangle"><transform name="to_world"><scale x="1.5" y="2"/><rotate y="1" angle="-90"/><translate x="2" z="1.5"/></transform><ref id="blue"/></shape>

    <!-- The table: a top at z = 0.75 on a block. -->
    <shape type="cube"><transform name="to_world"><scale x="0.6" y="0.4" z="0.03"/><translate y="0.6" z="0.75"/></transform><ref id="wood"/></shape>
    <shape type="cube"><transform name="to_world"><scale x="0.1" y="0.1" z="0.36"/><translate y="0.6" z="0.36"/></transform><ref id="wood"/></shape>

    <!-- The lamp: the emissive shade on the table, warm. -->
    <shape type="obj"><string name="filename" value="meshes/lamp-shade.obj"/>
        <transform name="to_world"><translate y="0.6" z="0.85"/></transform>
        <ref id="shade"/><emitter type="area"><rgb name="radiance" value="3, 2.2, 1.2"/></emitter></shape>
</scene>
"""


if __name__ == "__main__":
    with open(os.path.join(ROOT, "many-lights.xml"), "w") as f:
        f.write(many_lights())
    with open(os.path.join(ROOT, "meshes", "lamp-shade.obj"), "w") as f:
        f.write(lamp_shade_obj())
    with open(os.path.join(ROOT, "emissive-lamp.xml"), "w") as f:
        f.write(emissive_lamp())
