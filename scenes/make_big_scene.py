#!/usr/bin/env python3
"""Writes a .glb scene with a requested number of triangles, to test very large scenes.

    python3 scenes/make_big_scene.py OUT.glb --triangles N [--shared]

The scene is a gently bumpy terrain (a height field of amplitude 0.3 m) over the 10 x 10 m square
around the origin in the XZ plane (+Y up), made of exactly N small triangles, seen from above at
an angle by a perspective camera at (0, 6, 9) looking at the origin and lit by a directional light
(KHR_lights_punctual). One grey material (base colour 0.8, metallic 0, roughness 0.8).

The terrain is a grid of cols x rows quads, two triangles each, cols and rows near sqrt(N / 2);
the triangle list is cut after exactly N triangles (the last, far row of quads may be partial).
Triangle fronts face up (+Y). Normals are the height field's exact smooth normals.

- Default (unshared): every triangle has its own 3 vertices (3N vertices; POSITION, NORMAL and
  uint32 indices 0, 1, 2, ...), the worst case for a loader's memory.
- --shared: the grid's vertices are shared between neighbouring triangles (about N / 2 vertices).

Made for tens of millions of triangles: the geometry is computed with numpy in chunks and streamed
into the file, so memory stays far below the file's size (the grid's vertices, about 12 N bytes,
plus fixed-size chunks). The file is written to OUT.tmp and renamed to OUT when complete. A GLB's
length is a uint32, so N is refused (before anything is written) when the file would reach 4 GiB:
about 51 million triangles unshared, 178 million shared.

Needs numpy (unlike the other scripts here, which use the standard library only). Output is
deterministic: the same arguments give the same bytes.
"""

import argparse
import json
import math
import os
import signal
import struct
import sys

try:
    import numpy as np
except ImportError:  # pragma: no cover - depends on the environment
    sys.exit("make_big_scene: error: numpy is required (python3 -m pip install numpy)")

GENERATOR = "wavepath scenes/make_big_scene.py"

# glTF enums.
_FLOAT, _UINT32 = 5126, 5125
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963
_TRIANGLES = 4

# GLB framing.
_GLB_MAGIC, _GLB_VERSION = 0x46546C67, 2  # "glTF"
_CHUNK_JSON, _CHUNK_BIN = 0x4E4F534A, 0x004E4942  # "JSON", "BIN\0"
_GLB_MAX_LENGTH = 2 ** 32 - 1  # the header's total length is a uint32

# The terrain: a HALF x HALF square on each side of the origin, height h(x, z) below.
HALF = 5.0
AMPLITUDE = 0.3

CAMERA_EYE = (0.0, 6.0, 9.0)
CAMERA_TARGET = (0.0, 0.0, 0.0)
CAMERA_YFOV = 0.8
CAMERA_ZNEAR = 0.01

LIGHT_DIRECTION = (1.0, -0.7, -0.4)  # the way the light travels (down, at an angle)
LIGHT_INTENSITY = 3.0  # W/m^2 for wavepath (lux in glTF)

CHUNK_TRIANGLES = 1 << 20  # triangles generated and written per step (even)
CHUNK_VERTICES = 1 << 21  # grid vertices computed per step


# --------------------------------------------------------------------------------------------
# The grid: vertex (j, i) is number j * (cols + 1) + i, at x = -HALF + 2 HALF i / cols and
# z = HALF - 2 HALF j / rows (row 0 is the near edge, toward the camera; the last, possibly
# partial, row of quads is the far edge).

def grid_size(triangles):
    """(cols, rows) of quads: cols x rows >= triangles / 2 quads, both near sqrt(triangles / 2)."""
    quads = (triangles + 1) // 2
    cols = math.isqrt(quads - 1) + 1  # ceil(sqrt(quads))
    rows = -(-quads // cols)
    return cols, rows


def height(x, z):
    """Terrain height and its partial derivatives dh/dx, dh/dz (numpy arrays, |h| <= 0.3)."""
    a, b = 0.2, 0.1  # a + b = AMPLITUDE
    s = 2.3 * x + 1.7 * z
    h = a * np.sin(0.9 * x) * np.cos(0.7 * z) + b * np.sin(s)
    hx = 0.9 * a * np.cos(0.9 * x) * np.cos(0.7 * z) + 2.3 * b * np.cos(s)
    hz = -0.7 * a * np.sin(0.9 * x) * np.sin(0.7 * z) + 1.7 * b * np.cos(s)
    return h, hx, hz


def grid_vertices(cols, rows, count):
    """Positions and unit normals (float32, count x 3) of the grid's first count vertices."""
    positions = np.empty((count, 3), dtype=np.float32)
    normals = np.empty((count, 3), dtype=np.float32)
    for start in range(0, count, CHUNK_VERTICES):
        n = np.arange(start, min(start + CHUNK_VERTICES, count), dtype=np.int64)
        j, i = np.divmod(n, cols + 1)
        x = -HALF + (2.0 * HALF / cols) * i
        z = HALF - (2.0 * HALF / rows) * j
        h, hx, hz = height(x, z)
        # Surface (x, h, z): tangents (1, hx, 0) and (0, hz, 1); their cross product, up.
        nrm = np.stack((-hx, np.ones_like(hx), -hz), axis=1)
        nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
        positions[start:start + len(n)] = np.stack((x, h, z), axis=1)
        normals[start:start + len(n)] = nrm
    return positions, normals


def grid_triangles(start, stop, cols):
    """Grid vertex indices (uint32, (stop - start) x 3) of triangles start..stop-1 (start even).

    Quad q is at column q % cols, row q // cols; its corners v00 (row j, column i), v10 (i + 1),
    v01 (row j + 1, farther away) and v11 give triangles (v00, v11, v01) and (v00, v10, v11),
    both counter-clockwise seen from above."""
    q = np.arange(start // 2, (stop + 1) // 2, dtype=np.int64)
    j, i = np.divmod(q, cols)
    v00 = j * (cols + 1) + i
    v10 = v00 + 1
    v01 = v00 + (cols + 1)
    v11 = v01 + 1
    tris = np.stack((v00, v11, v01, v00, v10, v11), axis=1).reshape(-1, 3)
    return tris[:stop - start].astype(np.uint32)


def grid_vertex_count(triangles, cols):
    """Vertices up to the highest one used: the last quad's v11 is the highest so far."""
    return int(grid_triangles(triangles - 1 - (triangles - 1) % 2, triangles, cols).max()) + 1


def chunks(total):
    """(start, stop) triangle ranges of CHUNK_TRIANGLES."""
    for start in range(0, total, CHUNK_TRIANGLES):
        yield start, min(start + CHUNK_TRIANGLES, total)


def used_vertices(triangles, cols, count):
    """Boolean mask of the grid vertices some triangle uses."""
    used = np.zeros(count, dtype=bool)
    for start, stop in chunks(triangles):
        used[grid_triangles(start, stop, cols).ravel()] = True
    return used


# --------------------------------------------------------------------------------------------
# Camera and light orientation.

def look_at(eye, target, up=(0.0, 1.0, 0.0)):
    """Quaternion (x, y, z, w) turning a node at eye so its -Z points at target, +Y near up
    (glTF cameras and directional lights look and shine down their node's -Z)."""
    z = np.subtract(eye, target).astype(np.float64)
    z /= np.linalg.norm(z)
    x = np.cross(up, z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    m = np.column_stack((x, y, z))  # the rotation matrix, m[row][column]
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0.0:
        s = 2.0 * math.sqrt(trace + 1.0)
        q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, s / 4]
    elif m[0, 0] >= m[1, 1] and m[0, 0] >= m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = [s / 4, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s]
    elif m[1, 1] >= m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = [(m[0, 1] + m[1, 0]) / s, s / 4, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = [(m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, s / 4, (m[1, 0] - m[0, 1]) / s]
    q = np.array(q) / np.linalg.norm(q)
    if q[3] < 0.0:  # q and -q are the same rotation; keep w >= 0
        q = -q
    return [_clean(round(float(c), 12)) for c in q]


def _clean(v):
    """Floats as they go into the JSON: no -0.0."""
    return 0.0 if v == 0.0 else float(v)


def _f32_json(v):
    """A float32 as the shortest decimal that reads back as the same float32."""
    return _clean(float(str(np.float32(v))))


# --------------------------------------------------------------------------------------------
# The document.

class Layout:
    """Sizes of the three buffer views (POSITION, NORMAL, indices), packed 4-byte aligned."""

    def __init__(self, vertices, triangles):
        self.vertices, self.triangles = vertices, triangles
        self.lengths = [12 * vertices, 12 * vertices, 12 * triangles]
        self.offsets = [0, self.lengths[0], self.lengths[0] + self.lengths[1]]
        self.bin_length = sum(self.lengths)  # all multiples of 4: no padding between views

    def glb_length(self, json_length):
        return 12 + 8 + _pad4(json_length) + 8 + _pad4(self.bin_length)


def _pad4(n):
    return n + (-n % 4)


def document(layout, lo, hi):
    """The glTF JSON for the terrain, camera and light; lo, hi: POSITION's min and max."""
    views = [{"buffer": 0, "byteOffset": off, "byteLength": length, "target": target}
             for off, length, target in zip(layout.offsets, layout.lengths,
                                            (_ARRAY_BUFFER, _ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER))]
    accessors = [
        {"bufferView": 0, "componentType": _FLOAT, "count": layout.vertices, "type": "VEC3",
         "min": [_f32_json(c) for c in lo], "max": [_f32_json(c) for c in hi]},
        {"bufferView": 1, "componentType": _FLOAT, "count": layout.vertices, "type": "VEC3"},
        {"bufferView": 2, "componentType": _UINT32, "count": 3 * layout.triangles,
         "type": "SCALAR"},
    ]
    primitive = {"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": 0,
                 "mode": _TRIANGLES}
    material = {"name": "terrain", "pbrMetallicRoughness": {
        "baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.8}}
    camera = {"name": "camera", "type": "perspective",
              "perspective": {"yfov": CAMERA_YFOV, "znear": CAMERA_ZNEAR}}
    light = {"name": "sun", "type": "directional", "color": [1.0, 1.0, 1.0],
             "intensity": LIGHT_INTENSITY}
    nodes = [
        {"name": "terrain", "mesh": 0},
        {"name": "camera", "camera": 0, "translation": [_clean(c) for c in CAMERA_EYE],
         "rotation": look_at(CAMERA_EYE, CAMERA_TARGET)},
        {"name": "sun", "extensions": {"KHR_lights_punctual": {"light": 0}},
         "rotation": look_at((0.0, 0.0, 0.0), LIGHT_DIRECTION)},
    ]
    return {
        "asset": {"version": "2.0", "generator": GENERATOR},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [light]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": nodes,
        "cameras": [camera],
        "materials": [material],
        "meshes": [{"name": "terrain", "primitives": [primitive]}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": layout.bin_length}],
    }


def json_chunk(doc):
    js = json.dumps(doc, sort_keys=True, separators=(",", ":")).encode("utf-8")
    return js + b" " * (-len(js) % 4)  # JSON chunk padding is spaces


# --------------------------------------------------------------------------------------------
# Writing.

def write_glb(f, js, layout, sections):
    """Header, JSON chunk, then the BIN chunk streamed from sections (iterables of arrays)."""
    f.write(struct.pack("<III", _GLB_MAGIC, _GLB_VERSION, layout.glb_length(len(js))))
    f.write(struct.pack("<II", len(js), _CHUNK_JSON))
    f.write(js)
    f.write(struct.pack("<II", _pad4(layout.bin_length), _CHUNK_BIN))
    for expected, arrays in zip(layout.lengths, sections):
        written = 0
        for arr in arrays:
            data = memoryview(np.ascontiguousarray(arr)).cast("B")
            f.write(data)
            written += len(data)
        if written != expected:
            raise RuntimeError("internal error: wrote %d bytes for a %d-byte view"
                               % (written, expected))
    f.write(b"\0" * (-layout.bin_length % 4))  # BIN chunk padding is zeros


def shared_sections(triangles, cols, positions, normals):
    yield (positions,)
    yield (normals,)
    yield (grid_triangles(start, stop, cols) for start, stop in chunks(triangles))


def unshared_sections(triangles, cols, positions, normals):
    yield (positions[grid_triangles(start, stop, cols)] for start, stop in chunks(triangles))
    yield (normals[grid_triangles(start, stop, cols)] for start, stop in chunks(triangles))
    yield (np.arange(3 * start, 3 * stop, dtype=np.uint32) for start, stop in chunks(triangles))


def fail(message):
    print("make_big_scene: error: " + message, file=sys.stderr)
    sys.exit(1)


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog="make_big_scene",
        description="Write a glTF 2.0 binary (.glb) terrain scene of exactly N triangles, with a "
                    "camera and a directional light, for testing very large scenes.",
        epilog="Example: python3 scenes/make_big_scene.py /tmp/big.glb --triangles 20000000")
    parser.add_argument("output", metavar="OUT.glb", help="the file to write (via OUT.glb.tmp)")
    parser.add_argument("--triangles", "-n", type=int, required=True, metavar="N",
                        help="number of triangles, at least 1")
    parser.add_argument("--shared", action="store_true",
                        help="share vertices between neighbouring triangles (about N/2 "
                             "vertices); default: 3 vertices of its own per triangle (3N)")
    return parser.parse_args(argv)


def main(argv=None):
    args = parse_args(argv)
    n = args.triangles
    if n < 1:
        fail("--triangles must be at least 1, got %d" % n)
    cols, rows = grid_size(n)
    grid_count = grid_vertex_count(n, cols)
    layout = Layout(grid_count if args.shared else 3 * n, n)
    # The JSON is a few kB; refuse now, before computing or writing anything, if even a short
    # JSON chunk would not fit, and again below with the exact one.
    if layout.glb_length(4096) > _GLB_MAX_LENGTH:
        fail("%d %s triangles need a %.2f GB file; a .glb must stay under 4 GiB (%d bytes)"
             % (n, "shared" if args.shared else "unshared", layout.glb_length(4096) / 1e9,
                _GLB_MAX_LENGTH))

    positions, normals = grid_vertices(cols, rows, grid_count)
    if args.shared:
        stored = positions
    else:
        stored = positions[used_vertices(n, cols, grid_count)]
    js = json_chunk(document(layout, stored.min(axis=0), stored.max(axis=0)))
    del stored
    total = layout.glb_length(len(js))
    if total > _GLB_MAX_LENGTH:
        fail("the file would be %d bytes; a .glb must stay under 4 GiB" % total)

    make_sections = shared_sections if args.shared else unshared_sections
    tmp = args.output + ".tmp"
    # A kill (SIGTERM) unwinds like Ctrl-C, so the partial OUT.tmp is removed below.
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    try:
        with open(tmp, "wb") as f:
            write_glb(f, js, layout, make_sections(n, cols, positions, normals))
        os.replace(tmp, args.output)
    except BaseException as e:
        if os.path.exists(tmp):
            os.remove(tmp)
        if isinstance(e, OSError):
            fail("%s: %s" % (e.filename or args.output, e.strerror or e))
        raise
    print("%s: %d triangles, %d vertices, %.2f MB (%s, %d x %d quads)"
          % (args.output, n, layout.vertices, total / 1e6,
             "shared" if args.shared else "unshared", cols, rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
