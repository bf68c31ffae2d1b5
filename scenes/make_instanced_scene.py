#!/usr/bin/env python3
"""Writes a .glb scene of one mesh placed many times, to test instancing at scale.

    python3 scenes/make_instanced_scene.py OUT.glb --triangles N --instances K [--gpu-instancing]

The mesh is a bumpy square tile (a height field of amplitude 0.2 over 1 x 1 m in the XZ plane,
+Y up, fronts up) of exactly N triangles (a grid of quads, two triangles each, cut after N),
with shared vertices and smooth normals. It is placed K times on a square grid 1.25 m apart,
centred on the origin, each placement turned about +Y by a multiple of 37 degrees and scaled by
0.8 to 1.2 (deterministic): the world holds N x K triangles. K nodes place it (default), or, with
--gpu-instancing, one node with K EXT_mesh_gpu_instancing instances. A perspective camera looks
down at the field's centre from above one side; a directional light (KHR_lights_punctual) shines
from above at an angle; one grey material.

Standard library only; deterministic (the same arguments give the same bytes). The file is
written to OUT.tmp and renamed to OUT when complete.
"""

import argparse
import json
import math
import os
import struct
import sys

GENERATOR = "wavepath scenes/make_instanced_scene.py"
_FLOAT, _UINT32 = 5126, 5125
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963
SPACING = 1.25
AMPLITUDE = 0.2


def grid_size(triangles):
    """(cols, rows) of quads covering at least `triangles` triangles, near square."""
    quads = (triangles + 1) // 2
    cols = max(1, int(math.ceil(math.sqrt(quads))))
    rows = max(1, (quads + cols - 1) // cols)
    return cols, rows


def height(x, z):
    return AMPLITUDE * math.sin(6.0 * x) * math.cos(5.0 * z)


def normal(x, z):
    dx = AMPLITUDE * 6.0 * math.cos(6.0 * x) * math.cos(5.0 * z)
    dz = -AMPLITUDE * 5.0 * math.sin(6.0 * x) * math.sin(5.0 * z)
    n = (-dx, 1.0, -dz)
    length = math.sqrt(sum(c * c for c in n))
    return tuple(c / length for c in n)


def tile(triangles):
    """(positions, normals, indices) of the tile: packed float32 / uint32 bytes, vertex count."""
    cols, rows = grid_size(triangles)
    pos, nrm = bytearray(), bytearray()
    for r in range(rows + 1):
        for c in range(cols + 1):
            x, z = c / cols - 0.5, r / rows - 0.5
            pos += struct.pack("<3f", x, height(x, z), z)
            nrm += struct.pack("<3f", *normal(x, z))
    idx = bytearray()
    written = 0
    for r in range(rows):
        for c in range(cols):
            a = r * (cols + 1) + c
            b, d, e = a + 1, a + cols + 1, a + cols + 2
            for t in ((a, d, b), (b, d, e)):  # counter-clockwise seen from +Y
                if written == triangles:
                    break
                idx += struct.pack("<3I", *t)
                written += 1
    return bytes(pos), bytes(nrm), bytes(idx), (rows + 1) * (cols + 1)


def placements(count):
    """[(translation, rotation quaternion xyzw, scale)] on a square grid around the origin."""
    side = max(1, int(math.ceil(math.sqrt(count))))
    out = []
    for i in range(count):
        gx, gz = i % side, i // side
        t = ((gx - (side - 1) / 2) * SPACING, 0.0, (gz - (side - 1) / 2) * SPACING)
        angle = math.radians(37.0 * (i % 10))
        q = (0.0, math.sin(angle / 2), 0.0, math.cos(angle / 2))
        s = 0.8 + 0.4 * ((i * 7919) % 101) / 100.0
        out.append((t, q, (s, s, s)))
    return out, side


def look_at_quaternion(eye, target):
    """The rotation (x, y, z, w) turning a glTF camera (looking down -Z, +Y up) toward target."""
    f = [t - e for t, e in zip(target, eye)]
    fl = math.sqrt(sum(c * c for c in f))
    f = [c / fl for c in f]
    up = (0.0, 1.0, 0.0)
    r = [f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2], f[0] * up[1] - f[1] * up[0]]
    rl = math.sqrt(sum(c * c for c in r))
    r = [c / rl for c in r]
    u = [r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]]
    m = [[r[0], u[0], -f[0]], [r[1], u[1], -f[1]], [r[2], u[2], -f[2]]]  # columns: x, y, z axes
    tr = m[0][0] + m[1][1] + m[2][2]
    if tr > 0:
        s = 2.0 * math.sqrt(tr + 1.0)
        return ((m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, s / 4)
    i = max(range(3), key=lambda k: m[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2.0 * math.sqrt(1.0 + m[i][i] - m[j][j] - m[k][k])
    q = [0.0, 0.0, 0.0, (m[k][j] - m[j][k]) / s]
    q[i] = s / 4
    q[j] = (m[j][i] + m[i][j]) / s
    q[k] = (m[k][i] + m[i][k]) / s
    return tuple(q)


def build(triangles, instances, gpu_instancing):
    pos, nrm, idx, vertices = tile(triangles)
    places, side = placements(instances)
    chunks = [pos, nrm, idx]
    views = []
    offset = 0
    for data, target in ((pos, _ARRAY_BUFFER), (nrm, _ARRAY_BUFFER), (idx, _ELEMENT_ARRAY_BUFFER)):
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(data), "target": target})
        offset += len(data)
    lo = [-0.5, -AMPLITUDE, -0.5]
    hi = [0.5, AMPLITUDE, 0.5]
    accessors = [
        {"bufferView": 0, "componentType": _FLOAT, "count": vertices, "type": "VEC3",
         "min": lo, "max": hi},
        {"bufferView": 1, "componentType": _FLOAT, "count": vertices, "type": "VEC3"},
        {"bufferView": 2, "componentType": _UINT32, "count": 3 * triangles, "type": "SCALAR"},
    ]
    extent = side * SPACING / 2
    eye = (0.0, 0.9 * extent + 1.0, 1.3 * extent + 1.0)
    nodes = [{"camera": 0, "translation": list(eye),
              "rotation": list(look_at_quaternion(eye, (0.0, 0.0, 0.0)))},
             {"extensions": {"KHR_lights_punctual": {"light": 0}},
              "rotation": [-0.3826834, 0.2, 0.0, 0.9018]}]
    used = ["KHR_lights_punctual"]
    if gpu_instancing:
        data = bytearray()
        for t, _, _ in places:
            data += struct.pack("<3f", *t)
        rot = bytearray()
        for _, q, _ in places:
            rot += struct.pack("<4f", *q)
        sc = bytearray()
        for _, _, s in places:
            sc += struct.pack("<3f", *s)
        attributes = {}
        for name, blob, kind in (("TRANSLATION", data, "VEC3"), ("ROTATION", rot, "VEC4"),
                                 ("SCALE", sc, "VEC3")):
            views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(blob)})
            offset += len(blob)
            chunks.append(bytes(blob))
            accessors.append({"bufferView": len(views) - 1, "componentType": _FLOAT,
                              "count": instances, "type": kind})
            attributes[name] = len(accessors) - 1
        nodes.append({"mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": {
            "attributes": attributes}}})
        used.append("EXT_mesh_gpu_instancing")
    else:
        for t, q, s in places:
            nodes.append({"mesh": 0, "translation": list(t), "rotation": list(q), "scale": list(s)})
    doc = {
        "asset": {"version": "2.0", "generator": GENERATOR},
        "extensionsUsed": used,
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "directional", "intensity": 3.0, "color": [1.0, 0.97, 0.9]}]}},
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2,
                                    "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0],
                                                "metallicFactor": 0.0, "roughnessFactor": 0.8}}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": offset}],
    }
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    binary = b"".join(chunks)
    binary += b"\0" * (-len(binary) % 4)
    total = 12 + 8 + len(text) + 8 + len(binary)
    return (struct.pack("<III", 0x46546C67, 2, total) + struct.pack("<II", len(text), 0x4E4F534A) +
            text + struct.pack("<II", len(binary), 0x004E4942) + binary)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("out", help="the .glb to write")
    p.add_argument("--triangles", type=int, required=True, help="triangles of the mesh")
    p.add_argument("--instances", type=int, required=True, help="placements of the mesh")
    p.add_argument("--gpu-instancing", action="store_true",
                   help="one node with EXT_mesh_gpu_instancing instead of a node per placement")
    a = p.parse_args(argv)
    if a.triangles < 1 or a.instances < 1:
        p.error("--triangles and --instances must be at least 1")
    data = build(a.triangles, a.instances, a.gpu_instancing)
    tmp = a.out + ".tmp"
    with open(tmp, "wb") as f:
        f.write(data)
    os.replace(tmp, a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
