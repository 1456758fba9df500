#!/usr/bin/env python3
"""Writes the many-light scenes (issue "Many lights"; docs/lights.md):

  scenes/many-lights.xml     three rooms in a row joined by doorways, the camera in the middle one;
                             2560 small emissive tiles of different powers and tints on the
                             ceilings and along the back wall, two thirds of them in the side rooms
                             (behind walls, seen only through the doorways)
  scenes/emissive-lamp.xml   a room lit by a lamp whose shade is an emissive mesh
  scenes/meshes/lamp-shade.obj   (1024 emitting triangles, each one a light)

Deterministic (a fixed seed): running it again gives the same files.
    python3 scripts/make-many-lights.py
"""
import math
import os
import random

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes")


def rect(transform, body):
    return f'    <shape type="rectangle"><transform name="to_world">{transform}</transform>{body}</shape>\n'


def wall_x(x, y0, y1, z0, z1, ref="white"):
    """A wall in the plane x = const over [y0, y1] x [z0, z1]."""
    sy, sz = (y1 - y0) / 2, (z1 - z0) / 2
    return rect(f'<scale x="{sz:g}" y="{sy:g}"/><rotate y="1" angle="90"/><translate x="{x:g}" y="{(y0 + y1) / 2:g}" z="{(z0 + z1) / 2:g}"/>',
                f'<ref id="{ref}"/>')


def room_shell():
    out = ""
    # Floor, ceiling, front and back walls, the end walls: the hall [-6, 6] x [0, 4] x [0, 3].
    out += rect('<scale x="6" y="2"/><translate y="2"/>', '<ref id="floor"/>')
    out += rect('<scale x="6" y="2"/><rotate x="1" angle="180"/><translate y="2" z="3"/>', '<ref id="white"/>')
    out += rect('<scale x="6" y="1.5"/><rotate x="1" angle="90"/><translate y="4" z="1.5"/>', '<ref id="white"/>')
    out += rect('<scale x="6" y="1.5"/><rotate x="1" angle="-90"/><translate z="1.5"/>', '<ref id="white"/>')
    out += wall_x(-6, 0, 4, 0, 3, "red")
    out += wall_x(6, 0, 4, 0, 3, "blue")
    # The two inner walls at x = -2 and x = 2, each with a doorway y in [1.5, 2.5], z in [0, 2.2].
    for x in (-2, 2):
        out += wall_x(x, 0, 1.5, 0, 3)
        out += wall_x(x, 2.5, 4, 0, 3)
        out += wall_x(x, 1.5, 2.5, 2.2, 3)
    return out


def many_lights():
    rng = random.Random(20261205)
    tiles = ""
    count = 0
    size = 0.05  # half the side of a tile
    # 80 x 26 tiles under the ceiling, facing down.
    for i in range(80):
        for j in range(26):
            x, y = -6 + 0.15 * (i + 0.5), 0.15 * (j + 0.5) + 0.05
            if abs(abs(x) - 2) < 0.1:
                continue  # not inside an inner wall
            tiles += tile(rng, f'<scale value="{size}"/><rotate x="1" angle="180"/><translate x="{x:.3f}" y="{y:.3f}" z="2.999"/>')
            count += 1
    # A strip along the back wall, facing the rooms.
    for i in range(80):
        for k in range(6):
            x, z = -6 + 0.15 * (i + 0.5), 1.0 + 0.15 * k
            if abs(abs(x) - 2) < 0.1:
                continue
            tiles += tile(rng, f'<scale value="{size}"/><rotate x="1" angle="90"/><translate x="{x:.3f}" y="3.999" z="{z:.3f}"/>')
            count += 1
    head = f"""<!-- Many lights: three rooms in a row ([-6, 6] x [0, 4] x [0, 3], inner walls at x = -2 and 2
     with doorways), the camera in the middle room looking towards the left doorway. {count} small
     emissive tiles (each two triangles, so twice as many lights) of radiances spread over two
     decades and of different tints, under the ceilings and along the back wall; two thirds of them
     are in the side rooms, behind the walls. Choosing a light by power alone spends most shadow
     rays on lights far away or hidden; --light-sampler bvh chooses by each light's bound at the
     shading point (docs/lights.md).
     Made by scripts/make-many-lights.py (do not edit by hand).
     pathlab --scene scenes/many-lights.xml -a pt-mis --light-sampler bvh --spp 64 -o many-lights.png -->
<scene version="3.0.0">
    <default name="spp" value="64"/>
    <sensor type="perspective">
        <float name="fov" value="80"/>
        <transform name="to_world"><lookat origin="1.4, 0.35, 1.55" target="-3, 3.2, 1.1" up="0, 0, 1"/></transform>
        <film type="hdrfilm"><integer name="width" value="320"/><integer name="height" value="240"/><rfilter type="box"/></film>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    </sensor>

    <bsdf type="twosided" id="white"><bsdf type="diffuse"><rgb name="reflectance" value="0.7"/></bsdf></bsdf>
    <bsdf type="twosided" id="floor"><bsdf type="roughplastic"><rgb name="diffuse_reflectance" value="0.45, 0.35, 0.25"/><float name="alpha" value="0.2"/></bsdf></bsdf>
    <bsdf type="twosided" id="red"><bsdf type="diffuse"><rgb name="reflectance" value="0.7, 0.15, 0.1"/></bsdf></bsdf>
    <bsdf type="twosided" id="blue"><bsdf type="diffuse"><rgb name="reflectance" value="0.15, 0.25, 0.65"/></bsdf></bsdf>
    <bsdf type="diffuse" id="tile"><rgb name="reflectance" value="0"/></bsdf>

"""
    return head + room_shell() + "\n" + tiles + "</scene>\n"


def tile(rng, transform):
    level = 10 ** rng.uniform(-1.5, 0.5)  # radiance 0.03 to 3
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
     From any point of the room most of the shade's triangles face away; --light-sampler bvh sees
     it from their normal cones, power alone does not (docs/lights.md).
     Made by scripts/make-many-lights.py (do not edit by hand).
     pathlab --scene scenes/emissive-lamp.xml -a pt-mis --light-sampler bvh --spp 64 -o emissive-lamp.png -->
<scene version="3.0.0">
    <default name="spp" value="64"/>
    <sensor type="perspective">
        <float name="fov" value="70"/>
        <transform name="to_world"><lookat origin="0, -1.9, 1.4" target="0, 0.6, 1.0" up="0, 0, 1"/></transform>
        <film type="hdrfilm"><integer name="width" value="320"/><integer name="height" value="240"/><rfilter type="box"/></film>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    </sensor>

    <bsdf type="twosided" id="white"><bsdf type="diffuse"><rgb name="reflectance" value="0.75"/></bsdf></bsdf>
    <bsdf type="twosided" id="red"><bsdf type="diffuse"><rgb name="reflectance" value="0.7, 0.15, 0.1"/></bsdf></bsdf>
    <bsdf type="twosided" id="blue"><bsdf type="diffuse"><rgb name="reflectance" value="0.15, 0.25, 0.65"/></bsdf></bsdf>
    <bsdf type="twosided" id="wood"><bsdf type="roughplastic"><rgb name="diffuse_reflectance" value="0.4, 0.25, 0.12"/><float name="alpha" value="0.15"/></bsdf></bsdf>
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
