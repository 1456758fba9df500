#!/usr/bin/env python3
"""Writes scenes/gltf/room.glb and scenes/gltf/room.gltf: a small glTF 2.0 scene of pathlab's own
making, shaped like what Blender's glTF exporter writes (Y up, metres, a camera node, punctual
lights in candela, metallic-roughness materials with textures, emissive strength).

The two files hold the same scene: room.glb with its buffer and images in the binary chunk,
room.gltf with them as data: URIs. `pathlab scenes/gltf/room.glb` renders it;
`pathlab convert scenes/gltf/room.glb room.xml` writes the Mitsuba XML it amounts to.

Usage: scripts/make-gltf-scene.py [OUT_DIR]   (default: scenes/gltf next to this script's repo)
Only the Python standard library is used.
"""
import base64
import json
import math
import os
import struct
import sys
import zlib


def png_bytes(width, height, pixel):
    """An 8-bit RGB PNG; pixel(x, y) -> (r, g, b) in 0..255, row 0 at the top."""
    raw = b"".join(b"\x00" + bytes(c for x in range(width) for c in pixel(x, y)) for y in range(height))

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")


class Builder:
    def __init__(self):
        self.blob = bytearray()
        self.views, self.accessors, self.meshes, self.images = [], [], [], []

    def view(self, data, target=None):
        while len(self.blob) % 4:
            self.blob.append(0)
        v = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)}
        if target:
            v["target"] = target
        self.blob += data
        self.views.append(v)
        return len(self.views) - 1

    def accessor(self, values, kind):
        flat = [c for v in values for c in (v if isinstance(v, (tuple, list)) else (v,))]
        if kind == "SCALAR":
            view = self.view(struct.pack("<%dI" % len(flat), *flat), 34963)
            a = {"bufferView": view, "componentType": 5125, "count": len(values), "type": "SCALAR"}
        else:
            view = self.view(struct.pack("<%df" % len(flat), *flat), 34962)
            a = {"bufferView": view, "componentType": 5126, "count": len(values), "type": kind}
            if kind == "VEC3":
                a["min"] = [min(v[i] for v in values) for i in range(3)]
                a["max"] = [max(v[i] for v in values) for i in range(3)]
        self.accessors.append(a)
        return len(self.accessors) - 1

    def mesh(self, name, positions, normals, uvs, indices, material):
        attributes = {"POSITION": self.accessor(positions, "VEC3"), "NORMAL": self.accessor(normals, "VEC3")}
        if uvs:
            attributes["TEXCOORD_0"] = self.accessor(uvs, "VEC2")
        prim = {"attributes": attributes, "indices": self.accessor(indices, "SCALAR"), "material": material}
        self.meshes.append({"name": name, "primitives": [prim]})
        return len(self.meshes) - 1

    def image(self, name, data):
        self.images.append({"name": name, "mimeType": "image/png", "bufferView": self.view(data)})
        return len(self.images) - 1


def quad(corner, edge_u, edge_v):
    """Two triangles over corner + s edge_u + t edge_v, normal edge_u x edge_v, uv (s, 1 - t)
    (glTF's v runs down the image: the edge t = 1 shows the image's top row)."""
    n = [edge_u[1] * edge_v[2] - edge_u[2] * edge_v[1], edge_u[2] * edge_v[0] - edge_u[0] * edge_v[2],
         edge_u[0] * edge_v[1] - edge_u[1] * edge_v[0]]
    length = math.sqrt(sum(c * c for c in n))
    n = [c / length for c in n]
    pos = [[corner[i] + s * edge_u[i] + t * edge_v[i] for i in range(3)] for s, t in ((0, 0), (1, 0), (1, 1), (0, 1))]
    uv = [[s, 1 - t] for s, t in ((0, 0), (1, 0), (1, 1), (0, 1))]
    return pos, [n] * 4, uv, [0, 1, 2, 0, 2, 3]


def box():
    """A unit cube centred on the origin, 24 vertices (flat faces), outward normals."""
    positions, normals, uvs, indices = [], [], [], []
    faces = [((-.5, -.5, .5), (1, 0, 0), (0, 1, 0)), ((.5, -.5, -.5), (-1, 0, 0), (0, 1, 0)),
             ((.5, -.5, .5), (0, 0, -1), (0, 1, 0)), ((-.5, -.5, -.5), (0, 0, 1), (0, 1, 0)),
             ((-.5, .5, .5), (1, 0, 0), (0, 0, -1)), ((-.5, -.5, -.5), (1, 0, 0), (0, 0, 1))]
    for corner, eu, ev in faces:
        p, n, t, i = quad(corner, eu, ev)
        indices += [len(positions) + k for k in i]
        positions += p
        normals += n
        uvs += t
    return positions, normals, uvs, indices


def sphere(rings=12, segments=24):
    positions, normals, uvs, indices = [], [], [], []
    for r in range(rings + 1):
        theta = math.pi * r / rings
        for s in range(segments + 1):
            phi = 2 * math.pi * s / segments
            n = [math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi)]
            positions.append(n)
            normals.append(n)
            uvs.append([s / segments, r / rings])
    for r in range(rings):
        for s in range(segments):
            a = r * (segments + 1) + s
            b = a + segments + 1
            if r != 0:
                indices += [a, b, a + 1]
            if r != rings - 1:
                indices += [a + 1, b, b + 1]
    return positions, normals, uvs, indices


def build():
    g = Builder()
    checker = png_bytes(8, 8, lambda x, y: (230, 200, 60) if (x + y) % 2 else (40, 70, 160))
    # metallic-roughness texture: roughness in G (0.2 or 0.8 by checker), metallic in B (0)
    rough = png_bytes(8, 8, lambda x, y: (0, 204, 0) if (x // 2 + y // 2) % 2 else (0, 51, 0))
    # tangent-space normal map: ridges along v (normals tilted in +-u), encoded (n + 1) / 2
    def ridge(x, y):
        tilt = 0.9 * math.sin(2 * math.pi * (x + 0.5) / 8)
        n = [tilt, 0.0, 1.0]
        length = math.sqrt(sum(c * c for c in n))
        return tuple(int(round((c / length + 1) / 2 * 255)) for c in n)
    ridges = png_bytes(8, 8, ridge)
    g.image("checker", checker)
    g.image("roughness", rough)
    g.image("ridges", ridges)
    materials = [
        {"name": "white", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0, "roughnessFactor": 1}},
        {"name": "floor", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0, "roughnessFactor": 0.2},
         "normalTexture": {"index": 2}},
        {"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.08, 0.06, 1], "metallicFactor": 0, "roughnessFactor": 1}},
        {"name": "green", "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.6, 0.12, 1], "metallicFactor": 0, "roughnessFactor": 1}},
        {"name": "gold", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.77, 0.34, 1], "metallicFactor": 1, "roughnessFactor": 0.3}},
        {"name": "checker", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 1},
                                                     "metallicFactor": 1, "roughnessFactor": 1}},
        {"name": "lamp", "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0, "roughnessFactor": 1},
         "emissiveFactor": [1.0, 0.85, 0.6], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 12}}},
    ]
    nodes, roots = [], []

    def node(**kw):
        nodes.append(kw)
        return len(nodes) - 1

    walls = [("floor", (-1, 0, 1), (2, 0, 0), (0, 0, -2), 1), ("ceiling", (-1, 2, -1), (2, 0, 0), (0, 0, 2), 0),
             ("back", (-1, 0, -1), (2, 0, 0), (0, 2, 0), 0), ("left", (-1, 0, 1), (0, 0, -2), (0, 2, 0), 2),
             ("right", (1, 0, -1), (0, 0, 2), (0, 2, 0), 3), ("lamp", (-0.25, 1.98, -0.25), (0.5, 0, 0), (0, 0, 0.5), 6)]
    for name, c, eu, ev, m in walls:
        pos, nrm, uv, idx = quad(c, eu, ev)
        if name == "floor":
            uv = [[8 * u, 8 * v] for u, v in uv]  # the ridges repeat eight times across the floor
        roots.append(node(name=name, mesh=g.mesh(name, pos, nrm, uv, idx, m)))
    # The box: a child of a node that turns it 30 degrees about y (a quaternion), scaled in its own node.
    half = math.radians(30) / 2
    box_mesh = g.mesh("box", *box(), 5)
    box_node = node(name="box", mesh=box_mesh, scale=[0.5, 0.9, 0.5], translation=[0, 0.45, 0])
    roots.append(node(name="box-turn", rotation=[0, math.sin(half), 0, math.cos(half)], translation=[-0.35, 0, -0.3], children=[box_node]))
    roots.append(node(name="ball", mesh=g.mesh("ball", *sphere(), 4), scale=[0.3] * 3, translation=[0.45, 0.3, 0.3]))
    roots.append(node(name="fill-light", extensions={"KHR_lights_punctual": {"light": 0}}, translation=[0.6, 1.6, 0.8]))
    # The camera: 3.4 m in front of the room, tilted 4 degrees down (a rotation about x).
    tilt = math.radians(-4) / 2
    roots.append(node(name="camera", camera=0, translation=[0, 1.05, 3.4], rotation=[math.sin(tilt), 0, 0, math.cos(tilt)]))

    gltf = {
        "asset": {"version": "2.0", "generator": "pathlab scripts/make-gltf-scene.py"},
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"name": "fill", "type": "point", "color": [1, 0.95, 0.9], "intensity": 120}]}},
        "scene": 0,
        "scenes": [{"name": "room", "nodes": roots}],
        "nodes": nodes,
        "cameras": [{"name": "camera", "type": "perspective", "perspective": {"yfov": math.radians(39.6), "aspectRatio": 4 / 3, "znear": 0.1}}],
        "meshes": g.meshes,
        "materials": materials,
        "textures": [{"sampler": 0, "source": 0}, {"sampler": 1, "source": 1}, {"sampler": 1, "source": 2}],
        "samplers": [{"magFilter": 9728, "wrapS": 10497, "wrapT": 10497}, {"magFilter": 9729}],
        "images": g.images,
        "accessors": g.accessors,
        "bufferViews": g.views,
    }
    while len(g.blob) % 4:
        g.blob.append(0)
    return gltf, bytes(g.blob)


def write(out_dir):
    gltf, blob = build()
    os.makedirs(out_dir, exist_ok=True)
    # room.glb: the JSON chunk (padded with spaces) and the BIN chunk (padded with zeros)
    glb_json = dict(gltf, buffers=[{"byteLength": len(blob)}])
    text = json.dumps(glb_json, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    body = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(blob), 0x004E4942) + blob
    with open(os.path.join(out_dir, "room.glb"), "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)
    # room.gltf: the same, its buffer a data: URI
    uri = "data:application/octet-stream;base64," + base64.b64encode(blob).decode()
    with open(os.path.join(out_dir, "room.gltf"), "w") as f:
        json.dump(dict(gltf, buffers=[{"byteLength": len(blob), "uri": uri}]), f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    here = os.path.dirname(os.path.abspath(__file__))
    write(sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "scenes", "gltf"))
