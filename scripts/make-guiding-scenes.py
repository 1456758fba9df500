#!/usr/bin/env python3
"""Writes the path-guiding scenes (issue "Path guiding"; docs/estimators.md "Path guiding"):

  scenes/torus-glass.xml    a torus in a closed box of thin glass, in a room lit only by the
                            ceiling's patch above a light that faces up (Müller et al. 2017's
                            TORUS, in spirit): everything in the box is lit through the glass,
                            where no shadow ray passes, by the light of one bright patch
  scenes/glass-panel.xml    a room whose ceiling light is covered by a panel of thin glass
                            (Müller 2019's bathroom, in spirit): next-event estimation is blocked
                            everywhere and the light is found only by paths through the panel
  scenes/meshes/torus.obj   the torus (48 x 24 quads, as triangles, with normals)

Deterministic: running it again gives the same files.
    python3 scripts/make-guiding-scenes.py
"""
import math
import os

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes")


def torus_obj(major=1.0, minor=0.35, segments=48, sides=24):
    """A torus around the z axis, centred at the origin: positions, normals, faces."""
    lines = ["# A torus (scripts/make-guiding-scenes.py): major radius 1, minor 0.35, around z."]
    for i in range(segments):
        u = 2 * math.pi * i / segments
        for j in range(sides):
            v = 2 * math.pi * j / sides
            cx, cy = math.cos(u), math.sin(u)
            nx, ny, nz = cx * math.cos(v), cy * math.cos(v), math.sin(v)
            lines.append(f"v {(major + minor * math.cos(v)) * cx:.6f} {(major + minor * math.cos(v)) * cy:.6f} {minor * nz:.6f}")
            lines.append(f"vn {nx:.6f} {ny:.6f} {nz:.6f}")
    # Vertex (i, j) is number i * sides + j + 1 (positions and normals alike).
    def index(i, j):
        return (i % segments) * sides + (j % sides) + 1
    for i in range(segments):
        for j in range(sides):
            a, b, c, d = index(i, j), index(i + 1, j), index(i + 1, j + 1), index(i, j + 1)
            lines.append(f"f {a}//{a} {b}//{b} {c}//{c}")
            lines.append(f"f {a}//{a} {c}//{c} {d}//{d}")
    return "\n".join(lines) + "\n"


ROOM = """    <bsdf type="twosided" id="white"><bsdf type="diffuse"><rgb name="reflectance" value="0.75"/></bsdf></bsdf>
    <bsdf type="twosided" id="red"><bsdf type="diffuse"><rgb name="reflectance" value="0.7, 0.15, 0.1"/></bsdf></bsdf>
    <bsdf type="twosided" id="blue"><bsdf type="diffuse"><rgb name="reflectance" value="0.15, 0.25, 0.65"/></bsdf></bsdf>
    <bsdf type="thindielectric" id="glass"><float name="int_ior" value="1.5"/></bsdf>

    <!-- The room: [-2, 2] x [-2, 2] x [0, 3], open towards the camera. -->
    <shape type="rectangle"><transform name="to_world"><scale value="2"/></transform><ref id="white"/></shape>
    <shape type="rectangle"><transform name="to_world"><scale value="2"/><rotate x="1" angle="180"/><translate z="3"/></transform><ref id="white"/></shape>
    <shape type="rectangle"><transform name="to_world"><scale x="2" y="1.5"/><rotate x="1" angle="90"/><translate y="2" z="1.5"/></transform><ref id="white"/></shape>
    <shape type="rectangle"><transform name="to_world"><scale x="1.5" y="2"/><rotate y="1" angle="90"/><translate x="-2" z="1.5"/></transform><ref id="red"/></shape>
    <shape type="rectangle"><transform name="to_world"><scale x="1.5" y="2"/><rotate y="1" angle="-90"/><translate x="2" z="1.5"/></transform><ref id="blue"/></shape>
"""


def header(comment, integrator="ppg"):
    return f"""<!-- {comment} -->
<scene version="3.0.0">
    <default name="spp" value="64"/>
    <integrator type="{integrator}"/>

    <sensor type="perspective">
        <float name="fov" value="70"/>
        <transform name="to_world"><lookat origin="0, -1.95, 1.2" target="0, 0.6, 0.9" up="0, 0, 1"/></transform>
        <film type="hdrfilm"><integer name="width" value="320"/><integer name="height" value="240"/><rfilter type="box"/></film>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    </sensor>

"""


TORUS_COMMENT = """A torus in a closed box of thin glass (thindielectric panes: no shadow ray passes them),
     in a room lit only by the ceiling's patch above a light that faces up: the torus, and all in
     the box, is lit by paths that leave it through the glass and find the bright patch, which
     path guiding can learn (Müller, Gross and Novák 2017's TORUS, in spirit). Written by
     scripts/make-guiding-scenes.py.
     pathlab --scene scenes/torus-glass.xml -a ppg --guiding-rr --time 60 -o torus-glass.png"""

PANEL_COMMENT = """A room whose ceiling light is covered by a panel of thin glass (a thindielectric pane just
     below it): no shadow ray passes the panel, so next-event estimation finds nothing anywhere and
     the light is found only by paths that pass the panel and hit the emitter (Müller 2019's
     bathroom, where guiding lost to path tracing, in spirit). Written by
     scripts/make-guiding-scenes.py.
     pathlab --scene scenes/glass-panel.xml -a ppg --guiding-rr --time 60 -o glass-panel.png"""


def torus_scene():
    return header(TORUS_COMMENT) + ROOM + """
    <!-- The light: a disk under the ceiling facing up; the room sees only the patch it lights. -->
    <shape type="disk">
        <transform name="to_world"><scale value="0.2"/><translate x="-0.6" y="1.0" z="2.6"/></transform>
        <emitter type="area"><rgb name="radiance" value="300, 260, 200"/></emitter>
    </shape>
    <shape type="disk"><transform name="to_world"><scale value="0.22"/><rotate x="1" angle="180"/><translate x="-0.6" y="1.0" z="2.59"/></transform><ref id="white"/></shape>

    <!-- The glass box, 1.2 x 1.0 x 0.9 on the floor, and the torus inside it. -->
    <shape type="cube"><transform name="to_world"><scale x="0.6" y="0.5" z="0.45"/><translate x="0.2" y="0.4" z="0.46"/></transform><ref id="glass"/></shape>
    <shape type="obj">
        <string name="filename" value="meshes/torus.obj"/>
        <transform name="to_world"><scale value="0.32"/><rotate x="1" angle="35"/><translate x="0.2" y="0.4" z="0.45"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.75, 0.55, 0.25"/></bsdf>
    </shape>
</scene>
"""


def panel_scene():
    return header(PANEL_COMMENT) + ROOM + """
    <!-- The light on the ceiling, facing down, and the glass panel 5 cm below it. -->
    <shape type="rectangle">
        <transform name="to_world"><scale x="0.5" y="0.3"/><rotate x="1" angle="180"/><translate x="0" y="0.6" z="2.99"/></transform>
        <emitter type="area"><rgb name="radiance" value="20, 17, 13"/></emitter>
    </shape>
    <shape type="rectangle"><transform name="to_world"><scale x="0.7" y="0.5"/><translate x="0" y="0.6" z="2.94"/></transform><ref id="glass"/></shape>

    <!-- Things in the room. -->
    <shape type="cube"><transform name="to_world"><scale x="0.35" y="0.35" z="0.5"/><rotate z="1" angle="20"/><translate x="-0.9" y="0.7" z="0.5"/></transform><ref id="white"/></shape>
    <shape type="sphere"><point name="center" value="0.6, 0.1, 0.35"/><float name="radius" value="0.35"/><ref id="white"/></shape>
</scene>
"""


def main():
    os.makedirs(os.path.join(ROOT, "meshes"), exist_ok=True)
    with open(os.path.join(ROOT, "meshes", "torus.obj"), "w") as f:
        f.write(torus_obj())
    with open(os.path.join(ROOT, "torus-glass.xml"), "w") as f:
        f.write(torus_scene())
    with open(os.path.join(ROOT, "glass-panel.xml"), "w") as f:
        f.write(panel_scene())


if __name__ == "__main__":
    main()
