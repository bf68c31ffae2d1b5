#!/usr/bin/env python3
"""Self-test of scenes/gltf_builder.py and scenes/make_cornell_box.py (stdlib unittest only).

    python3 tests/test_scenes_py.py

Checks that the committed Cornell box and failure-mode scene files (scenes/failure/: glTF, the
environment map env_sun.hdr and manifest.json) are exactly what their scripts write, that
everything the builder writes (.gltf and .glb) reads back as structurally valid glTF 2.0, the
failure scenes' stated properties (equal-power Veach lights, the sun where the map convention puts
it, degenerate triangles present, closed-form models matching the files, scaled copies), and the
Cornell box's geometry: every wall/floor/ceiling/light triangle faces into the box, every block triangle
faces out of its block, the light faces down, the camera looks into the open side. If pygltflib
happens to be installed the files are also loaded with it; otherwise that test is skipped.
"""

import base64
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = os.path.join(REPO, "scenes")
sys.path.insert(0, SCENES)

import gltf_builder as gb  # noqa: E402
import make_cornell_box as mcb  # noqa: E402
import make_failure_scenes as mfs  # noqa: E402
import rgbe  # noqa: E402

COMPONENT_SIZE = {5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4}
COMPONENT_FMT = {5120: "b", 5121: "B", 5122: "h", 5123: "H", 5125: "I", 5126: "f"}
TYPE_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
CORNELL_FILES = ("cornell_box.gltf", "cornell_box_point.gltf")


# ---- Reading glTF back ------------------------------------------------------------------------

def load(path):
    """(JSON dict, buffer bytes or b"") from a .gltf with a data: URI buffer, or a .glb."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] == b"glTF":
        magic, version, length = struct.unpack_from("<III", data, 0)
        assert version == 2, "GLB version %d" % version
        assert length == len(data), "GLB header length %d, file %d" % (length, len(data))
        chunks, offset = [], 12
        while offset < length:
            size, kind = struct.unpack_from("<II", data, offset)
            assert size % 4 == 0 and offset % 4 == 0, "GLB chunk not 4-byte aligned"
            chunks.append((kind, data[offset + 8:offset + 8 + size]))
            offset += 8 + size
        assert offset == length, "GLB chunks overrun the file"
        assert chunks[0][0] == 0x4E4F534A, "first GLB chunk is not JSON"
        doc = json.loads(chunks[0][1].decode("utf-8"))
        binary = chunks[1][1] if len(chunks) > 1 else b""
        if len(chunks) > 1:
            assert chunks[1][0] == 0x004E4942, "second GLB chunk is not BIN"
            assert "uri" not in doc["buffers"][0], "GLB buffer 0 must not have a uri"
            # The BIN chunk may be up to 3 bytes longer than the buffer (padding).
            assert 0 <= len(binary) - doc["buffers"][0]["byteLength"] <= 3
        return doc, binary
    doc = json.loads(data.decode("utf-8"))
    binary = b""
    if doc.get("buffers"):
        prefix = "data:application/octet-stream;base64,"
        uri = doc["buffers"][0]["uri"]
        assert uri.startswith(prefix), "buffer is not an embedded base64 data URI"
        binary = base64.b64decode(uri[len(prefix):], validate=True)
        assert len(binary) == doc["buffers"][0]["byteLength"]
    return doc, binary


def read_accessor(doc, binary, index):
    """The accessor's elements as tuples (tightly packed views only, which is all we write)."""
    acc = doc["accessors"][index]
    view = doc["bufferViews"][acc["bufferView"]]
    width = TYPE_WIDTH[acc["type"]]
    start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    flat = struct.unpack_from("<%d%s" % (acc["count"] * width, COMPONENT_FMT[acc["componentType"]]),
                              binary, start)
    return [tuple(flat[i * width:(i + 1) * width]) for i in range(acc["count"])]


def f32(v):
    return struct.unpack("<f", struct.pack("<f", v))[0]


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def unit(a):
    n = math.sqrt(dot(a, a))
    return tuple(x / n for x in a)


def rotate(q, v):
    """v rotated by the unit quaternion q = (x, y, z, w)."""
    u, w = q[:3], q[3]
    t = tuple(2.0 * c for c in cross(u, v))
    return tuple(v[i] + w * t[i] + cross(u, t)[i] for i in range(3))


def triangles(doc, binary, mesh_index):
    """[(v0, v1, v2, n0, n1, n2)] of the mesh's first primitive (positions and stored normals)."""
    prim = doc["meshes"][mesh_index]["primitives"][0]
    pos = read_accessor(doc, binary, prim["attributes"]["POSITION"])
    nrm = read_accessor(doc, binary, prim["attributes"]["NORMAL"])
    idx = [i[0] for i in read_accessor(doc, binary, prim["indices"])]
    return [tuple(pos[i] for i in idx[k:k + 3]) + tuple(nrm[i] for i in idx[k:k + 3])
            for k in range(0, len(idx), 3)]


def mesh_by_name(doc, name):
    return [m["name"] for m in doc["meshes"]].index(name)


def node_by_name(doc, name):
    return next(n for n in doc["nodes"] if n["name"] == name)


def extensions_in(obj, found):
    """Collects every key of every "extensions" object anywhere in the document."""
    if isinstance(obj, dict):
        for key, value in obj.items():
            if key == "extensions":
                found.update(value)
            extensions_in(value, found)
    elif isinstance(obj, list):
        for value in obj:
            extensions_in(value, found)
    return found


class StructureMixin:
    """check_structure(): glTF 2.0 structural rules for what the builder writes."""

    def check_structure(self, doc, binary):
        self.assertEqual(doc["asset"]["version"], "2.0")
        for key, value in doc.items():
            if isinstance(value, list):
                self.assertTrue(value, "empty top-level array %r" % key)
        buffers = doc.get("buffers", [])
        self.assertLessEqual(len(buffers), 1)
        if buffers:
            self.assertGreaterEqual(len(binary), buffers[0]["byteLength"])

        for v in doc.get("bufferViews", []):
            self.assertEqual(v["buffer"], 0)
            self.assertEqual(v.get("byteOffset", 0) % 4, 0, "bufferView not 4-byte aligned")
            self.assertGreater(v["byteLength"], 0)
            self.assertLessEqual(v.get("byteOffset", 0) + v["byteLength"], buffers[0]["byteLength"])
            self.assertIn(v.get("target"), (34962, 34963))
            self.assertNotIn("byteStride", v)  # all views are tightly packed

        for a in doc.get("accessors", []):
            view = doc["bufferViews"][a["bufferView"]]
            size = COMPONENT_SIZE[a["componentType"]]
            offset = a.get("byteOffset", 0)
            self.assertGreaterEqual(a["count"], 1)
            self.assertEqual((view.get("byteOffset", 0) + offset) % size, 0, "misaligned accessor")
            self.assertLessEqual(offset + a["count"] * size * TYPE_WIDTH[a["type"]],
                                 view["byteLength"], "accessor runs past its bufferView")

        used_accessors = set()
        for mesh in doc.get("meshes", []):
            for prim in mesh["primitives"]:
                self.assertEqual(prim.get("mode", 4), 4)
                self.assertLess(prim["material"], len(doc["materials"]))
                attrs = prim["attributes"]
                pos_acc = doc["accessors"][attrs["POSITION"]]
                count = pos_acc["count"]
                for semantic, ai in attrs.items():
                    acc = doc["accessors"][ai]
                    used_accessors.add(ai)
                    self.assertEqual(acc["count"], count, semantic)
                    self.assertEqual(acc["componentType"], 5126, semantic)
                    self.assertEqual(doc["bufferViews"][acc["bufferView"]]["target"], 34962)
                    self.assertEqual(acc["type"], {"TEXCOORD_0": "VEC2"}.get(semantic, "VEC3"))
                # POSITION min/max are required and must be the float32 data's exact bounds.
                pos = read_accessor(doc, binary, attrs["POSITION"])
                for k in range(3):
                    self.assertEqual(f32(pos_acc["min"][k]), min(p[k] for p in pos), "POSITION min")
                    self.assertEqual(f32(pos_acc["max"][k]), max(p[k] for p in pos), "POSITION max")
                if "NORMAL" in attrs:
                    for n in read_accessor(doc, binary, attrs["NORMAL"]):
                        self.assertAlmostEqual(math.sqrt(dot(n, n)), 1.0, places=5)
                ia = doc["accessors"][prim["indices"]]
                used_accessors.add(prim["indices"])
                self.assertEqual(ia["type"], "SCALAR")
                self.assertIn(ia["componentType"], (5121, 5123, 5125))
                self.assertEqual(doc["bufferViews"][ia["bufferView"]]["target"], 34963)
                self.assertEqual(ia["count"] % 3, 0)
                idx = [i[0] for i in read_accessor(doc, binary, prim["indices"])]
                restart = (1 << (8 * COMPONENT_SIZE[ia["componentType"]])) - 1
                self.assertLess(max(idx), count, "index out of range")
                self.assertNotIn(restart, idx, "primitive-restart value used as an index")
        self.assertEqual(used_accessors, set(range(len(doc.get("accessors", [])))))

        for m in doc.get("materials", []):
            pbr = m["pbrMetallicRoughness"]
            for c in pbr["baseColorFactor"] + [pbr["metallicFactor"], pbr["roughnessFactor"]] \
                    + m.get("emissiveFactor", []):
                self.assertTrue(0.0 <= c <= 1.0, "factor %r outside [0, 1] in %s" % (c, m["name"]))

        lights = doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
        parents = {}
        for i, n in enumerate(doc["nodes"]):
            if "mesh" in n:
                self.assertLess(n["mesh"], len(doc["meshes"]))
            if "camera" in n:
                self.assertLess(n["camera"], len(doc["cameras"]))
            if "extensions" in n:
                self.assertLess(n["extensions"]["KHR_lights_punctual"]["light"], len(lights))
            if "rotation" in n:
                self.assertAlmostEqual(math.sqrt(dot(n["rotation"], n["rotation"])), 1.0, places=9)
            self.assertFalse("matrix" in n and any(k in n for k in ("translation", "rotation", "scale")))
            for c in n.get("children", []):
                self.assertNotIn(c, parents, "node %d has two parents" % c)
                self.assertNotEqual(c, i)
                parents[c] = i
        for c in parents:  # no cycles: every chain of parents ends
            seen = set()
            while c in parents:
                self.assertNotIn(c, seen, "node hierarchy has a cycle")
                seen.add(c)
                c = parents[c]
        self.assertEqual(doc["scene"], 0)
        self.assertEqual(sorted(doc["scenes"][0]["nodes"]),
                         [i for i in range(len(doc["nodes"])) if i not in parents])

        for cam in doc.get("cameras", []):
            if cam["type"] == "perspective":
                self.assertTrue(0.0 < cam["perspective"]["yfov"] < math.pi)
                self.assertGreater(cam["perspective"]["znear"], 0.0)
            else:
                o = cam["orthographic"]
                self.assertGreater(o["zfar"], o["znear"])
        self.assertEqual(set(doc.get("extensionsUsed", [])), extensions_in(doc, set()))


# ---- The Cornell box files --------------------------------------------------------------------

class CornellBoxTest(StructureMixin, unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.box = load(os.path.join(SCENES, "cornell_box.gltf"))
        cls.point = load(os.path.join(SCENES, "cornell_box_point.gltf"))

    def test_regenerates_byte_identically(self):
        with tempfile.TemporaryDirectory() as tmp:
            subprocess.run([sys.executable, os.path.join(SCENES, "make_cornell_box.py"), tmp],
                           check=True, stdout=subprocess.DEVNULL)
            for name in CORNELL_FILES:
                with open(os.path.join(tmp, name), "rb") as f:
                    fresh = f.read()
                with open(os.path.join(SCENES, name), "rb") as f:
                    committed = f.read()
                self.assertEqual(fresh, committed, "%s differs from what the script writes: "
                                 "run python3 scenes/make_cornell_box.py" % name)

    def test_structure(self):
        self.check_structure(*self.box)
        self.check_structure(*self.point)

    def test_interior_faces_inward_and_blocks_outward(self):
        doc, binary = self.box
        lo, hi = (0.0, 0.0, 0.0), (0.556, 0.5488, 0.5592)
        centre = tuple((a + b) / 2 for a, b in zip(lo, hi))
        inward = ("floor", "ceiling", "back_wall", "left_wall_red", "right_wall_green", "light")
        for name in inward:
            for v0, v1, v2, *normals in triangles(doc, binary, mesh_by_name(doc, name)):
                g = unit(cross(sub(v1, v0), sub(v2, v0)))
                centroid = tuple(sum(c) / 3 for c in zip(v0, v1, v2))
                self.assertGreater(dot(g, unit(sub(centre, centroid))), 0.3, "%s faces out" % name)
                for n in normals:  # stored normals agree with the winding
                    self.assertGreater(dot(g, n), 0.999, name)
        for name in ("short_block", "tall_block"):
            tris = triangles(doc, binary, mesh_by_name(doc, name))
            self.assertEqual(len(tris), 10)  # 5 quads: 4 sides and the top
            corners = {v for t in tris for v in t[:3]}
            self.assertEqual(len(corners), 8)
            block_centre = tuple(sum(c) / len(corners) for c in zip(*corners))
            for v0, v1, v2, *normals in tris:
                g = unit(cross(sub(v1, v0), sub(v2, v0)))
                centroid = tuple(sum(c) / 3 for c in zip(v0, v1, v2))
                self.assertGreater(dot(g, sub(centroid, block_centre)), 0.0, "%s faces in" % name)
                for n in normals:
                    self.assertGreater(dot(g, n), 0.999, name)

    def test_light(self):
        doc, binary = self.box
        tris = triangles(doc, binary, mesh_by_name(doc, "light"))
        for v0, v1, v2, *_ in tris:
            self.assertLess(unit(cross(sub(v1, v0), sub(v2, v0)))[1], -0.9999, "light faces up")
        pts = {v for t in tris for v in t[:3]}
        xs, ys, zs = zip(*pts)
        self.assertAlmostEqual(max(xs) - min(xs), 0.13, places=6)
        self.assertAlmostEqual(max(zs) - min(zs), 0.105, places=6)
        self.assertEqual(len(set(ys)), 1)
        self.assertTrue(0.54 < ys[0] < 0.5488, "light not just below the ceiling")
        prim = doc["meshes"][mesh_by_name(doc, "light")]["primitives"][0]
        mat = doc["materials"][prim["material"]]
        strength = mat["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"]
        radiance = [c * strength for c in mat["emissiveFactor"]]
        for got, want in zip(radiance, (17.0, 12.0, 4.0)):
            self.assertAlmostEqual(got, want, places=9)
        self.assertIn("KHR_materials_emissive_strength", doc["extensionsUsed"])

    def test_materials(self):
        doc, _ = self.box
        expected = {"floor": (0.725, 0.71, 0.68), "left_wall_red": (0.63, 0.065, 0.05),
                    "right_wall_green": (0.14, 0.45, 0.091), "tall_block": (0.725, 0.71, 0.68)}
        for name, color in expected.items():
            prim = doc["meshes"][mesh_by_name(doc, name)]["primitives"][0]
            pbr = doc["materials"][prim["material"]]["pbrMetallicRoughness"]
            self.assertEqual(tuple(pbr["baseColorFactor"]), color + (1.0,))
            self.assertEqual((pbr["metallicFactor"], pbr["roughnessFactor"]), (0.0, 1.0))

    def test_camera_looks_into_the_open_side(self):
        doc, binary = self.box
        node = node_by_name(doc, "camera")
        cam = doc["cameras"][node["camera"]]["perspective"]
        self.assertAlmostEqual(math.degrees(cam["yfov"]), 39.3, places=1)
        self.assertEqual(cam["znear"], 0.01)
        eye = tuple(node["translation"])
        self.assertEqual(eye, (0.278, 0.273, -0.8))
        forward = rotate(node["rotation"], (0.0, 0.0, -1.0))
        up = rotate(node["rotation"], (0.0, 1.0, 0.0))
        right = rotate(node["rotation"], (1.0, 0.0, 0.0))
        for got, want in zip(forward + up, (0.0, 0.0, 1.0, 0.0, 1.0, 0.0)):
            self.assertAlmostEqual(got, want, places=12)
        # The red wall appears on the left, the green one on the right (the classic view).
        def side(name):
            tris = triangles(doc, binary, mesh_by_name(doc, name))
            c = tuple(sum(c) / (3 * len(tris)) for c in zip(*[v for t in tris for v in t[:3]]))
            return dot(sub(c, eye), right)
        self.assertLess(side("left_wall_red"), 0.0)
        self.assertGreater(side("right_wall_green"), 0.0)
        # The opening (z = 0) is between the camera and the box; nothing has z < 0.
        for a in doc["accessors"]:
            if "min" in a:
                self.assertGreaterEqual(a["min"][2], 0.0)

    def test_point_light_matches_area_light_floor_irradiance(self):
        doc, binary = self.box
        pdoc, pbinary = self.point
        self.assertNotIn("light", [m["name"] for m in pdoc["meshes"]])
        self.assertNotIn("KHR_materials_emissive_strength", pdoc.get("extensionsUsed", []))
        self.assertTrue(all("emissiveFactor" not in m for m in pdoc["materials"]))
        for name in [m["name"] for m in pdoc["meshes"]]:  # the same box otherwise
            self.assertEqual(triangles(pdoc, pbinary, mesh_by_name(pdoc, name)),
                             triangles(doc, binary, mesh_by_name(doc, name)))
        lights = pdoc["extensions"]["KHR_lights_punctual"]["lights"]
        self.assertEqual(len(lights), 1)
        self.assertEqual(lights[0]["type"], "point")
        pos = tuple(node_by_name(pdoc, "light")["translation"])
        self.assertTrue(0.52 < pos[1] < 0.5488, "point light not just below the ceiling")
        intensity = [c * lights[0]["intensity"] for c in lights[0]["color"]]

        # Area light irradiance at the floor point below the point light, by midpoint quadrature
        # of E = L * integral cos(theta_floor) cos(theta_light) / r^2 dA over the light quad.
        tris = triangles(doc, binary, mesh_by_name(doc, "light"))
        xs, ys, zs = zip(*{v for t in tris for v in t[:3]})
        x0, x1, z0, z1, h = min(xs), max(xs), min(zs), max(zs), ys[0]
        p = (pos[0], 0.0, pos[2])
        steps, geometric = 200, 0.0
        dx, dz = (x1 - x0) / steps, (z1 - z0) / steps
        for i in range(steps):
            for k in range(steps):
                q = (x0 + (i + 0.5) * dx, h, z0 + (k + 0.5) * dz)
                r2 = dot(sub(q, p), sub(q, p))
                cos = h / math.sqrt(r2)  # both cosines are the same: parallel planes
                geometric += cos * cos / r2 * dx * dz
        area_e = [c * geometric for c in (17.0, 12.0, 4.0)]
        point_e = [c / (pos[1] ** 2) for c in intensity]  # I cos(theta) / d^2, cos = 1
        for a, b in zip(area_e, point_e):
            self.assertAlmostEqual(a / b, 1.0, delta=1e-3)

    def test_with_pygltflib_if_installed(self):
        try:
            import pygltflib
        except ImportError:
            self.skipTest("pygltflib is not installed")
        for name in CORNELL_FILES:
            g = pygltflib.GLTF2().load(os.path.join(SCENES, name))
            doc, _ = load(os.path.join(SCENES, name))
            self.assertEqual(len(g.meshes), len(doc["meshes"]))
            self.assertEqual(len(g.accessors), len(doc["accessors"]))
            self.assertEqual(len(g.binary_blob() or g.decode_data_uri(g.buffers[0].uri)),
                             doc["buffers"][0]["byteLength"])


# ---- The builder itself -----------------------------------------------------------------------

def sample_builder():
    """A scene using every builder feature: shapes, materials with extensions, all light and
    camera kinds, a node hierarchy."""
    b = gb.GltfBuilder()
    glass = b.material("glass", base_color=(1, 1, 1), roughness=0.0, ior=1.5, transmission=1.0)
    lamp = b.material("lamp", emission=(0.5, 0.5, 0.5), emissive_strength=4.0, double_sided=True)
    pos, nrm, idx = gb.box((-1, -1, -1), (1, 2, 3))
    cube = b.mesh("cube", pos, idx, glass, normals=nrm)
    pos, nrm, idx = gb.uv_sphere((0, 1, 0), 0.5, 8, 12)
    sphere = b.mesh("sphere", pos, idx, lamp, normals=nrm, uvs=[(0.0, 0.0)] * len(pos))
    child = b.node("sphere", mesh=sphere, translation=(0, 1, 0), scale=(2, 2, 2))
    b.node("group", mesh=cube, rotation=(0, 0, 0, 1), children=[child])
    b.node("sun", light=b.directional_light((1, 1, 1), 3.0),
           rotation=b.look_at((0, 0, 0), (0.2, -1, 0.1)))
    b.node("spot", light=b.spot_light((1, 0.5, 0.2), 10.0, 0.2, 0.4), translation=(0, 3, 0),
           rotation=b.look_at((0, 3, 0), (0, 0, 0), (0, 0, 1)))
    b.node("bulb", light=b.point_light((1, 1, 1), 2.0),
           matrix=(1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 2, 0, 1))
    b.node("top", camera=b.orthographic_camera(2.0, 1.5, 0.01, 10.0), translation=(0, 5, 0),
           rotation=b.look_at((0, 5, 0), (0, 0, 0), (0, 0, -1)))
    return b


class BuilderTest(StructureMixin, unittest.TestCase):

    def check_outward(self, shape, centre):
        pos, nrm, idx = shape
        self.assertEqual(len(pos), len(nrm))
        for k in range(0, len(idx), 3):
            v0, v1, v2 = (pos[i] for i in idx[k:k + 3])
            g = cross(sub(v1, v0), sub(v2, v0))
            self.assertGreater(math.sqrt(dot(g, g)), 0.0, "degenerate triangle")
            centroid = tuple(sum(c) / 3 for c in zip(v0, v1, v2))
            self.assertGreater(dot(g, sub(centroid, centre)), 0.0, "triangle faces inward")
            for i in idx[k:k + 3]:
                self.assertGreater(dot(unit(g), nrm[i]), 0.5, "normal disagrees with winding")

    def test_box_faces_outward(self):
        shape = gb.box((-1, -1, -1), (1, 2, 3))
        self.assertEqual((len(shape[0]), len(shape[2])), (24, 36))
        self.check_outward(shape, (0.0, 0.5, 1.0))

    def test_sphere_faces_outward(self):
        shape = gb.uv_sphere((1, 2, 3), 0.5, 6, 9)
        self.assertEqual(len(shape[0]), 7 * 10)
        self.assertEqual(len(shape[2]), 3 * 2 * 9 * (6 - 1))  # two triangles per quad, one at poles
        self.check_outward(shape, (1, 2, 3))
        for p in shape[0]:
            self.assertAlmostEqual(math.dist(p, (1, 2, 3)), 0.5, places=12)

    def test_quad_front(self):
        pos, nrm, idx = gb.quad([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)])
        self.assertEqual(nrm[0], (0.0, 0.0, 1.0))
        self.assertEqual(idx, [0, 1, 2, 0, 2, 3])

    def test_look_at(self):
        cases = [((0, 0, 0), (0, 0, 1), (0, 1, 0)), ((0, 0, 0), (0, 0, -1), (0, 1, 0)),
                 ((1, 2, 3), (-2, 0.5, 7), (0, 1, 0)), ((0, 5, 0), (0, 0, 0), (0, 0, -1)),
                 ((0, 0, 0), (1, 0, 0), (0, 1, 0)), ((0, 0, 0), (-1, -1, 0), (0, 1, 0))]
        for eye, target, up in cases:
            q = gb.look_at(eye, target, up)
            self.assertAlmostEqual(math.sqrt(dot(q, q)), 1.0, places=10)  # rounded to 12 digits
            forward = rotate(q, (0.0, 0.0, -1.0))
            want = unit(sub(target, eye))
            for a, b in zip(forward, want):
                self.assertAlmostEqual(a, b, places=9)
            cam_up = rotate(q, (0.0, 1.0, 0.0))
            self.assertAlmostEqual(dot(cam_up, forward), 0.0, places=9)
            self.assertGreater(dot(cam_up, up), 0.0)  # as close to up as the view allows
        self.assertEqual(gb.look_at((0, 0, 0), (0, 0, 1)), (0.0, 1.0, 0.0, 0.0))

    def test_material_extensions(self):
        b = gb.GltfBuilder()
        b.material("plain")
        b.material("hot", emission=(17, 12, 4))
        b.material("dim", emission=(0.5, 0.25, 0.0))
        b.material("scaled", emission=(0.5, 0.25, 0.0), emissive_strength=2.0)
        b.material("glass", ior=1.33, transmission=0.9)
        doc = b.document()
        plain, hot, dim, scaled, glass = doc["materials"]
        self.assertNotIn("extensions", plain)
        self.assertNotIn("emissiveFactor", plain)
        self.assertEqual(hot["emissiveFactor"], [1.0, 12 / 17, 4 / 17])
        self.assertEqual(hot["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"], 17.0)
        self.assertEqual(dim["emissiveFactor"], [0.5, 0.25, 0.0])
        self.assertNotIn("extensions", dim)
        self.assertEqual(scaled["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"], 2.0)
        self.assertEqual(glass["extensions"]["KHR_materials_ior"]["ior"], 1.33)
        self.assertEqual(glass["extensions"]["KHR_materials_transmission"]["transmissionFactor"], 0.9)
        self.assertEqual(doc["extensionsUsed"], ["KHR_materials_emissive_strength",
                                                 "KHR_materials_ior", "KHR_materials_transmission"])

    def test_index_type(self):
        b = gb.GltfBuilder()
        m = b.material("m")
        pos, nrm, idx = gb.uv_sphere((0, 0, 0), 1.0, 300, 300)  # 90601 vertices
        b.mesh("big", pos, idx, m, normals=nrm)
        pos, nrm, idx = gb.box((0, 0, 0), (1, 1, 1))
        b.mesh("small", pos, idx, m)
        b.node("big", mesh=0)
        b.node("small", mesh=1)
        with tempfile.TemporaryDirectory() as tmp:
            doc, binary = load(b.write(os.path.join(tmp, "big.glb")))
        self.check_structure(doc, binary)
        types = [doc["accessors"][mesh["primitives"][0]["indices"]]["componentType"]
                 for mesh in doc["meshes"]]
        self.assertEqual(types, [5125, 5123])

    def test_gltf_and_glb_agree_and_are_valid(self):
        with tempfile.TemporaryDirectory() as tmp:
            text_doc, text_bin = load(sample_builder().write(os.path.join(tmp, "s.gltf")))
            glb_doc, glb_bin = load(sample_builder().write(os.path.join(tmp, "s.GLB")))
            with open(os.path.join(tmp, "s.GLB"), "rb") as f:
                raw = f.read()
        self.check_structure(text_doc, text_bin)
        self.check_structure(glb_doc, glb_bin)
        del text_doc["buffers"][0]["uri"]
        self.assertEqual(text_doc, glb_doc)
        self.assertEqual(text_bin, glb_bin[:len(text_bin)])
        json_len = struct.unpack_from("<I", raw, 12)[0]
        self.assertTrue(raw[20:20 + json_len].rstrip(b" ").endswith(b"}"), "JSON chunk padding")
        self.assertEqual(set(text_doc["extensionsUsed"]),
                         {"KHR_lights_punctual", "KHR_materials_emissive_strength",
                          "KHR_materials_ior", "KHR_materials_transmission"})
        self.assertEqual(text_doc["scenes"][0]["nodes"], [1, 2, 3, 4, 5])  # node 0 is a child

    def test_deterministic(self):
        for binary in (False, True):
            self.assertEqual(sample_builder().to_bytes(binary), sample_builder().to_bytes(binary))

    def test_rejects_bad_input(self):
        b = gb.GltfBuilder()
        m = b.material("m")
        with self.assertRaises(ValueError):
            b.mesh("bad", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [0, 1, 3], m)
        with self.assertRaises(ValueError):
            b.mesh("bad", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [0, 1], m)
        with self.assertRaises(ValueError):
            b.node("bad", translation=(1, 0, 0), matrix=[1] * 16)


# ---- The failure-mode scenes (scenes/make_failure_scenes.py) ---------------------------------

FAILURE = os.path.join(SCENES, "failure")


def failure_files():
    with open(os.path.join(FAILURE, "manifest.json")) as f:
        manifest = json.load(f)
    return manifest, [e["file"] for e in manifest["scenes"]] + ["env_sun.hdr", "manifest.json"]


def mesh_positions(doc, binary, name):
    prim = doc["meshes"][mesh_by_name(doc, name)]["primitives"][0]
    pos = read_accessor(doc, binary, prim["attributes"]["POSITION"])
    idx = [i[0] for i in read_accessor(doc, binary, prim["indices"])]
    return [tuple(pos[i] for i in idx[k:k + 3]) for k in range(0, len(idx), 3)]


def tri_area(t):
    c = cross(sub(t[1], t[0]), sub(t[2], t[0]))
    return 0.5 * math.sqrt(dot(c, c))


def emission_of(doc, name):
    prim = doc["meshes"][mesh_by_name(doc, name)]["primitives"][0]
    mat = doc["materials"][prim["material"]]
    strength = mat.get("extensions", {}).get("KHR_materials_emissive_strength", {}).get(
        "emissiveStrength", 1.0)
    return [c * strength for c in mat.get("emissiveFactor", [0.0, 0.0, 0.0])]


class FailureScenesTest(StructureMixin, unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.manifest, cls.files = failure_files()
        cls.docs = {e["name"]: load(os.path.join(FAILURE, e["file"])) for e in cls.manifest["scenes"]}

    def test_regenerates_byte_identically(self):
        with tempfile.TemporaryDirectory() as tmp:
            subprocess.run([sys.executable, os.path.join(SCENES, "make_failure_scenes.py"), tmp],
                           check=True, stdout=subprocess.DEVNULL)
            self.assertEqual(sorted(os.listdir(tmp)), sorted(self.files))
            self.assertEqual(sorted(os.listdir(FAILURE)), sorted(self.files), "stray files")
            for name in self.files:
                with open(os.path.join(tmp, name), "rb") as f:
                    fresh = f.read()
                with open(os.path.join(FAILURE, name), "rb") as f:
                    committed = f.read()
                self.assertEqual(fresh, committed, "%s differs from what the script writes: run "
                                 "python3 scenes/make_failure_scenes.py" % name)

    def test_structure(self):
        for name, (doc, binary) in self.docs.items():
            with self.subTest(scene=name):
                self.check_structure(doc, binary)
                self.assertTrue(doc.get("cameras"), "no camera")

    def test_manifest(self):
        names = [e["name"] for e in self.manifest["scenes"]]
        self.assertEqual(len(names), len(set(names)))
        for e in self.manifest["scenes"]:
            self.assertIn(e["reference"]["kind"], ("render", "closed_form", "black", "scene"))
            if e["reference"]["kind"] == "scene":
                self.assertIn(e["reference"]["scene"], names)
            x, y, w, h = e["crop"]
            self.assertTrue(0 <= x and 0 <= y and w > 0 and h > 0 and x + w <= 128 and y + h <= 96)
            self.assertTrue(e["breaks"])
            for i, a in enumerate(e["args"]):
                if i > 0 and e["args"][i - 1] == "--env":
                    self.assertTrue(os.path.isfile(os.path.join(FAILURE, a)))

    def test_veach_lights_have_equal_power(self):
        doc, binary = self.docs["veach_mis"]
        powers = []
        for i in range(4):
            name = "light%d" % i
            area = sum(tri_area(t) for t in mesh_positions(doc, binary, name))
            powers.append(math.pi * area * sum(emission_of(doc, name)) / 3.0)
        for p in powers:  # equal up to the tessellation's area (the same 10 x 20 grid for all)
            self.assertAlmostEqual(p / powers[0], 1.0, delta=1e-4)
        radii = [max(abs(v[0] - sum(t[0] for t in tri) / 3) for tri in mesh_positions(doc, binary, "light%d" % i)
                     for v in tri) for i in range(4)]
        self.assertEqual(radii, sorted(radii), "emitters not in increasing size")

    def test_closed_form_models_match_the_files(self):
        doc, binary = self.docs["lambert_quad"]
        model = self.manifest["scenes"][[e["name"] for e in self.manifest["scenes"]].index(
            "lambert_quad")]["reference"]["model"]
        for q, name in zip(model["quads"], ("big", "small")):
            corners = {tuple(f32(c) for c in v) for v in q["corners"]}
            got = {v for t in mesh_positions(doc, binary, name) for v in t}
            self.assertEqual(corners, got)
            for a, b in zip(emission_of(doc, name), q["radiance"]):
                self.assertAlmostEqual(a, b, places=5)
            for t in mesh_positions(doc, binary, name):  # the emitter's front faces the plane
                self.assertLess(cross(sub(t[1], t[0]), sub(t[2], t[0]))[1], 0.0)
        doc, _ = self.docs["punctual"]
        model = [e for e in self.manifest["scenes"] if e["name"] == "punctual"][0]["reference"]["model"]
        lights = doc["extensions"]["KHR_lights_punctual"]["lights"]
        for kind, entries in (("point", model["points"]), ("spot", model["spots"])):
            light = [l for l in lights if l["type"] == kind][0]
            node = node_by_name(doc, kind)
            self.assertEqual(tuple(node["translation"]), tuple(entries[0]["position"]))
            for a, b in zip([c * light["intensity"] for c in light["color"]], entries[0]["intensity"]):
                self.assertAlmostEqual(a, b, places=9)
            if kind == "spot":
                d = rotate(node["rotation"], (0.0, 0.0, -1.0))
                for a, b in zip(d, entries[0]["direction"]):
                    self.assertAlmostEqual(a, b, places=9)
        for name in ("punctual", "lambert_quad"):  # Lambertian: no specular layer
            doc, _ = self.docs[name]
            plane = doc["materials"][doc["meshes"][mesh_by_name(doc, "plane")]["primitives"][0]["material"]]
            self.assertEqual(plane["extensions"]["KHR_materials_specular"]["specularFactor"], 0.0)

    def test_degenerate_scene_is_degenerate(self):
        doc, binary = self.docs["degenerate"]
        tris = mesh_positions(doc, binary, "degenerate")
        areas = [tri_area(t) for t in tris]
        self.assertGreaterEqual(sum(1 for a in areas if a == 0.0), 20)  # coincident or collinear
        self.assertGreaterEqual(sum(1 for a in areas if 0.0 < a < 1e-6), 20)  # slivers
        lights = [tri_area(t) for t in mesh_positions(doc, binary, "degenerate_lights")]
        self.assertEqual(lights[0], 0.0)
        self.assertTrue(0.0 < lights[1] < 1e-5)
        prim = doc["meshes"][mesh_by_name(doc, "degenerate")]["primitives"][0]
        self.assertNotIn("NORMAL", prim["attributes"])  # the loader must make its own

    def test_scaled_scenes_are_scaled_copies(self):
        base_doc, base_bin = self.docs["scale_1"]
        for name, s in (("scale_1e-3", 1e-3), ("scale_1e4", 1e4)):
            doc, binary = self.docs[name]
            for mesh in base_doc["meshes"]:
                a = mesh_positions(base_doc, base_bin, mesh["name"])
                b = mesh_positions(doc, binary, mesh["name"])
                self.assertEqual(len(a), len(b))
                for ta, tb in zip(a, b):
                    for va, vb in zip(ta, tb):
                        for ca, cb in zip(va, vb):
                            self.assertAlmostEqual(ca * s, cb, delta=1e-6 * s)
            for mesh in doc["meshes"]:  # radiance does not scale
                self.assertEqual(emission_of(doc, mesh["name"]), emission_of(base_doc, mesh["name"]))

    def test_environment_map(self):
        width, height, rows = rgbe.read_rgbe(os.path.join(FAILURE, "env_sun.hdr"))
        self.assertEqual((width, height), (mfs.ENV_W, mfs.ENV_H))
        # host/lights/environment.h's convention: the centre column looks down -Z, row 0 is +Y.
        for got, want in zip(rgbe.direction(0.5, 0.5), (0.0, 0.0, -1.0)):
            self.assertAlmostEqual(got, want, places=12)
        self.assertAlmostEqual(rgbe.direction(0.5, 0.0)[1], 1.0, places=12)
        self.assertGreater(rgbe.direction(0.75, 0.5)[0], 0.999)  # u = 3/4: phi = pi/2, +X
        for u, v in ((0.1, 0.3), (0.8, 0.7), (0.5, 0.5)):
            back = rgbe.map_coordinates(rgbe.direction(u, v))
            self.assertAlmostEqual(back[0], u, places=9)
            self.assertAlmostEqual(back[1], v, places=9)
        # The brightest pixel lies on the sun, and the sun's power is its radiance x solid angle.
        best = max(((sum(rows[y][x]), x, y) for y in range(height) for x in range(width)))
        d = rgbe.direction((best[1] + 0.5) / width, (best[2] + 0.5) / height)
        sun = mfs._sun_direction()
        self.assertLess(math.acos(min(1.0, dot(d, sun))), mfs.SUN_RADIUS + 2 * math.pi / height)
        flux = 0.0
        for y in range(height):
            theta0, theta1 = math.pi * y / height, math.pi * (y + 1) / height
            omega = 2 * math.pi / width * (math.cos(theta0) - math.cos(theta1))
            for x in range(width):
                dd = rgbe.direction((x + 0.5) / width, (y + 0.5) / height)
                if math.acos(min(1.0, dot(dd, sun))) < mfs.SUN_RADIUS + 4 * math.pi / height:
                    flux += (rows[y][x][0] - mfs.sky(dd)[0]) * omega
        want = (mfs.SUN_RADIANCE[0] - mfs.sky(sun)[0]) * 2 * math.pi * (1 - math.cos(mfs.SUN_RADIUS))
        self.assertAlmostEqual(flux / want, 1.0, delta=0.03)  # RGBE rounding and pixelation

    def test_rgbe_round_trip(self):
        for value in ((1.0, 0.5, 0.25), (2600.0, 2400.0, 2000.0), (1e-3, 0.0, 5e-4), (0.0, 0.0, 0.0)):
            back = rgbe.decode(rgbe.encode(value))
            for a, b in zip(value, back):
                self.assertLessEqual(abs(a - b), max(value) * 2.0 ** -7)
        self.assertEqual(rgbe.encode((0.0, 0.0, 0.0)), b"\0\0\0\0")

    def test_builder_extensions_used_by_the_scenes(self):
        b = gb.GltfBuilder()
        b.material("lambert", specular=0.0)
        b.material("glass", transmission=1.0, ior=1.5, thickness=1.0)
        b.material("tinted", thickness=0.5, attenuation=((0.5, 0.6, 0.7), 2.0))
        b.material("flat", unlit=True)
        lambert, glass, tinted, flat = b.document()["materials"]
        self.assertEqual(lambert["extensions"], {"KHR_materials_specular": {"specularFactor": 0.0}})
        self.assertEqual(glass["extensions"]["KHR_materials_volume"], {"thicknessFactor": 1.0})
        self.assertEqual(tinted["extensions"]["KHR_materials_volume"],
                         {"thicknessFactor": 0.5, "attenuationColor": [0.5, 0.6, 0.7],
                          "attenuationDistance": 2.0})
        self.assertEqual(flat["extensions"], {"KHR_materials_unlit": {}})
        self.assertEqual(b.document()["extensionsUsed"],
                         ["KHR_materials_ior", "KHR_materials_specular", "KHR_materials_transmission",
                          "KHR_materials_unlit", "KHR_materials_volume"])

    def test_closed_box_is_closed(self):
        """The shell's slabs overlap: a point just outside the inner space, across each of the
        six walls and at every edge and corner, lies inside some slab (so no straight path
        leaves the room without entering one through a face toward the room)."""
        lo, hi, t = (-1, 0, -1), (1, 2, 1), 0.1
        pos, _, _ = mfs.shell(lo, hi, t)
        boxes = [pos[k:k + 24] for k in range(0, len(pos), 24)]  # box() gives 24 vertices
        self.assertEqual(len(boxes), 6)
        for cx in (0, 1, 2):
            for cy in (0, 1, 2):
                for cz in (0, 1, 2):
                    if (cx, cy, cz) == (1, 1, 1):
                        continue  # the room itself
                    probe = [(lo[k] - t / 2, (lo[k] + hi[k]) / 2, hi[k] + t / 2)[c]
                             for k, c in enumerate((cx, cy, cz))]
                    inside = any(all(min(p[c] for p in bx) <= probe[c] <= max(p[c] for p in bx)
                                     for c in range(3)) for bx in boxes)
                    self.assertTrue(inside, "probe %s is in no slab" % probe)


if __name__ == "__main__":
    unittest.main(verbosity=2)
