#!/usr/bin/env python3
"""Self-test of tools/wavepath_tools/peers_scene.py, the glTF converter of tools/peers.py (stdlib unittest only;
no PyPI, no renderer).

    python3 tests/test_peers_scene.py

Known answers on scenes/cornell_box.gltf and cornell_box_point.gltf (the numbers of
scenes/README.md): triangle count, bounding box equal to the published box, the one emitter's area
(0.13 x 0.105 m), radiance (17, 12, 4) and downward normal, the point light, the camera's position,
direction and field of view; every wall triangle faces into the box; the materials' specular layer
and the Lambertian copy (specularFactor 0, all else equal). Node transforms (a parent
with translation, rotation and scale, a child with a mirroring matrix, whose winding must be
reversed) on a scene written with scenes/gltf_builder.py as .glb; refusals of what the peers
cannot represent; the PLY writer read back; for --pbr, world-space bounds, wavepath's framing
camera, and the copy with that camera written in (.glb and .gltf, read back). Coincident emitters
(an emitter coplanar with another surface and overlapping it) are found and refused: the
many-light room of scenes/make_many_lights.py converts with its lamps on a grid, and is refused with
them at random (overlapping) positions or flush with the ceiling.
"""

import math
import os
import struct
import sys
import tempfile
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(REPO, "tools"))  # the root of the wavepath_tools package
sys.path.insert(0, os.path.join(REPO, "scenes"))

import gltf_builder as gb  # noqa: E402
import make_many_lights as mml  # noqa: E402
from wavepath_tools import peers_scene as ps  # noqa: E402

BOX = os.path.join(REPO, "scenes", "cornell_box.gltf")
BOX_POINT = os.path.join(REPO, "scenes", "cornell_box_point.gltf")


class CornellBox(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.scene = ps.load(BOX)
        cls.summary = ps.summary(cls.scene)

    def assertClose(self, a, b, tol=1e-6):
        self.assertEqual(len(a), len(b))
        for x, y in zip(a, b):
            self.assertAlmostEqual(x, y, delta=tol, msg="%s != %s" % (a, b))

    def test_triangles(self):
        # 5 walls x 2, two blocks x 5 sides x 2, the light quad x 2
        self.assertEqual(self.summary["triangles"], 32)
        self.assertEqual(len(self.scene["meshes"]), 8)

    def test_bounding_box_is_the_published_box(self):
        self.assertClose(self.summary["bbox_min"], (0.0, 0.0, 0.0))
        self.assertClose(self.summary["bbox_max"], (0.556, 0.5488, 0.5592))

    def test_emitter(self):
        em = self.summary["emitters"]
        self.assertEqual(len(em), 1)
        self.assertAlmostEqual(em[0]["area"], 0.13 * 0.105, delta=1e-7)
        self.assertClose(em[0]["radiance"], (17.0, 12.0, 4.0), 1e-5)
        self.assertClose(em[0]["normal"], (0.0, -1.0, 0.0))
        self.assertEqual(self.scene["point_lights"], [])

    def test_materials(self):
        by_name = {m["name"]: m for m in self.scene["materials"]}
        self.assertClose(by_name["white"]["reflectance"], (0.725, 0.71, 0.68))
        self.assertClose(by_name["red"]["reflectance"], (0.63, 0.065, 0.05))
        self.assertClose(by_name["green"]["reflectance"], (0.14, 0.45, 0.091))
        self.assertClose(by_name["light"]["reflectance"], (0.78, 0.78, 0.78))
        self.assertFalse(any(m["double_sided"] for m in self.scene["materials"]))
        self.assertFalse(any(max(m["emission"]) > 0 for n, m in by_name.items() if n != "light"))

    def test_camera(self):
        cam = self.scene["camera"]
        self.assertClose(cam["position"], (0.278, 0.273, -0.8))
        self.assertClose(cam["forward"], (0.0, 0.0, 1.0))
        self.assertClose(cam["up"], (0.0, 1.0, 0.0))
        self.assertAlmostEqual(cam["yfov"], 2 * math.atan(12.5 / 35), delta=1e-8)
        self.assertEqual(cam["aspect"], 1.0)

    def test_walls_face_into_the_box(self):
        centre = (0.278, 0.2744, 0.2796)
        for mesh in self.scene["meshes"]:
            if mesh["name"] not in ("floor", "ceiling", "back_wall", "left_wall_red",
                                    "right_wall_green"):
                continue
            for t in mesh["triangles"]:
                a, b, c = (mesh["positions"][k] for k in t)
                _, n = ps.triangle_area(a, b, c)
                to_centre = [centre[i] - a[i] for i in range(3)]
                self.assertGreater(sum(n[i] * to_centre[i] for i in range(3)), 0.0, mesh["name"])

    def test_specular_layer_and_lambertian_copy(self):
        # glTF's dielectric has a specular layer (factor 1) unless KHR_materials_specular says 0.
        self.assertTrue(all(m["specular"] == 1.0 for m in self.scene["materials"]))
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "lambertian.gltf")
            ps.lambertian_copy(BOX, out)
            copy = ps.load(out)
        self.assertTrue(all(m["specular"] == 0.0 for m in copy["materials"]))
        for a, b in zip(copy["materials"], self.scene["materials"]):
            self.assertEqual({**a, "specular": 1.0}, b)
        self.assertEqual(copy["meshes"], self.scene["meshes"])
        self.assertEqual(copy["camera"], self.scene["camera"])

    def test_point_light(self):
        scene = ps.load(BOX_POINT)
        self.assertEqual(ps.summary(scene)["emitters"], [])
        (light,) = scene["point_lights"]
        self.assertClose(light["position"], (0.278, 0.5388, 0.2795))
        self.assertClose(light["intensity"], (0.221063, 0.221063 * 12 / 17, 0.221063 * 4 / 17))


class Transforms(unittest.TestCase):
    def test_nested_nodes_and_mirroring(self):
        b = gb.GltfBuilder()
        white = b.material("white", base_color=(0.5, 0.5, 0.5))
        # One triangle in the z = 0 plane, facing +Z.
        tri = b.mesh("tri", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [0, 1, 2], white)
        # Child: mirror x (matrix, column-major); parent: scale 2, rotate 90 deg about Y, move.
        child = b.node("child", mesh=tri, matrix=(-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0,
                                                  0, 0, 0, 1))
        s = math.sqrt(0.5)
        b.node("parent", translation=(10, 0, 0), rotation=(0, s, 0, s), scale=(2, 2, 2),
               children=[child])
        b.node("camera", camera=b.perspective_camera(0.5, 0.01), translation=(0, 0, 5))
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "t.glb")
            b.write(path)
            scene = ps.load(path)
        (mesh,) = scene["meshes"]
        # x -> -x, then scale 2, then Ry(90): (x, y, z) -> (z, y, -x), then +10 in x.
        want = [(10, 0, 0), (10, 0, 2), (10, 2, 0)]
        for p, w in zip(mesh["positions"], want):
            for i in range(3):
                self.assertAlmostEqual(p[i], w[i], delta=1e-6)
        a, bb, c = (mesh["positions"][k] for k in mesh["triangles"][0])
        _, n = ps.triangle_area(a, bb, c)
        # The front was +Z and stays +Z under the x mirror (whose reversed winding the converter
        # undoes); Ry(90) maps +Z to +X.
        self.assertGreater(n[0], 0.0)
        self.assertAlmostEqual(abs(n[0]), 2.0 * 2.0, delta=1e-5)  # |cross| = 2 x area 2
        self.assertEqual(scene["camera"]["position"], (0.0, 0.0, 5.0))


class Refusals(unittest.TestCase):
    def convert(self, **material):
        b = gb.GltfBuilder()
        m = b.material("m", **material)
        b.node("tri", mesh=b.mesh("tri", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [0, 1, 2], m))
        b.node("camera", camera=b.perspective_camera(0.5, 0.01), translation=(0, 0, 5))
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "t.gltf")
            b.write(path)
            return ps.load(path)

    def test_lambertian_converts(self):
        self.assertEqual(self.convert(base_color=(0.2, 0.3, 0.4))["materials"][0]["reflectance"],
                         (0.2, 0.3, 0.4))

    def test_metal_refused(self):
        with self.assertRaisesRegex(ps.ConversionError, "not Lambertian"):
            self.convert(metallic=1.0)

    def test_transmission_refused(self):
        with self.assertRaisesRegex(ps.ConversionError, "KHR_materials_transmission"):
            self.convert(transmission=1.0)

    def test_spot_light_refused(self):
        b = gb.GltfBuilder()
        b.node("spot", light=b.spot_light((1, 1, 1), 1.0, 0.1, 0.2))
        b.node("camera", camera=b.perspective_camera(0.5, 0.01))
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "t.gltf")
            b.write(path)
            with self.assertRaisesRegex(ps.ConversionError, "only point lights"):
                ps.load(path)


class Cameras(unittest.TestCase):
    """bounds, framing_camera, camera and with_camera (the --pbr mode's camera for files without
    one)."""

    def scene(self, path, camera=False):
        b = gb.GltfBuilder()
        m = b.material("m", base_color=(0.5, 0.5, 0.5), metallic=1.0, roughness=0.3)
        pos, _, idx = gb.box((0.0, 0.0, 0.0), (1.0, 2.0, 3.0))
        b.node("box", mesh=b.mesh("box", pos, idx, m), translation=(1.0, 0.0, -1.0))
        if camera:
            b.node("camera", camera=b.perspective_camera(0.5, 0.01), translation=(0, 0, 5))
        b.write(path)

    def assertClose(self, a, b, tol=1e-9):
        self.assertEqual(len(a), len(b))
        for x, y in zip(a, b):
            self.assertAlmostEqual(x, y, delta=tol, msg="%s != %s" % (a, b))

    def test_bounds_in_world_space(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "t.glb")
            self.scene(path)
            lo, hi = ps.bounds(path)
        self.assertClose(lo, (1.0, 0.0, -1.0))
        self.assertClose(hi, (2.0, 2.0, 2.0))

    def test_framing_camera_is_wavepaths(self):
        # host/scene/gltf_loader.cpp: 45 degrees, from +Z and 15 degrees above, the bounding sphere
        # (radius half the diagonal) fitting the tighter half-angle.
        lo, hi = (0.0, 0.0, 0.0), (2.0, 2.0, 2.0)
        e = math.radians(15.0)
        for aspect, half in ((1.0, math.radians(22.5)),
                             (0.5, math.atan(math.tan(math.radians(22.5)) * 0.5))):
            cam = ps.framing_camera(lo, hi, aspect)
            d = math.sqrt(3.0) / math.sin(half)
            self.assertClose(cam["position"], (1.0, 1.0 + d * math.sin(e), 1.0 + d * math.cos(e)))
            self.assertClose(cam["forward"], (0.0, -math.sin(e), -math.cos(e)))
            self.assertClose(cam["up"], (0.0, math.cos(e), -math.sin(e)))
            self.assertAlmostEqual(cam["yfov"], math.pi / 4)
            self.assertEqual(cam["aspect"], aspect)

    def test_orbit_camera_is_wavepaths(self):
        # host/scene/view.cpp, placed_camera: polar angle phi from +Y, azimuth theta from +Z
        # towards +X, looking at the centre of the bounds; image up towards +Y on the sphere.
        lo, hi = (0.0, 0.0, 0.0), (2.0, 2.0, 2.0)
        cam = ps.orbit_camera(lo, hi, 0.0, 90.0, 2.2, 1.0)  # level, from +Z
        self.assertClose(cam["position"], (1.0, 1.0, 3.2))
        self.assertClose(cam["forward"], (0.0, 0.0, -1.0))
        self.assertClose(cam["up"], (0.0, 1.0, 0.0))
        cam = ps.orbit_camera(lo, hi, 90.0, 60.0, 2.0, 1.0)  # from +X, 30 degrees above
        s3 = math.sqrt(3.0)
        self.assertClose(cam["position"], (1.0 + s3, 2.0, 1.0))
        self.assertClose(cam["forward"], (-s3 / 2, -0.5, 0.0))
        self.assertClose(cam["up"], (-0.5, s3 / 2, 0.0))
        self.assertAlmostEqual(sum(f * u for f, u in zip(cam["forward"], cam["up"])), 0.0)
        # Distance 0 fits the bounding sphere, as the framing camera does.
        fit = ps.orbit_camera(lo, hi, 0.0, 75.0, 0.0, 0.5)
        frame = ps.framing_camera(lo, hi, 0.5)
        for k in ("position", "forward", "up"):
            self.assertClose(fit[k], frame[k], 1e-12)

    def test_replace_camera(self):
        with tempfile.TemporaryDirectory() as tmp:
            path, out = os.path.join(tmp, "t.glb"), os.path.join(tmp, "c.glb")
            self.scene(path, camera=True)
            cam = ps.orbit_camera(*ps.bounds(path), 30.0, 80.0, 4.0, 1.0)
            ps.copy_gltf(path, out, [ps.add_camera(cam, replace=True)])
            got = ps.camera(out)
            for k in ("position", "forward", "up"):
                self.assertClose(got[k], cam[k], 1e-12)

    def test_with_camera_round_trip(self):
        for ext in (".glb", ".gltf"):
            with tempfile.TemporaryDirectory() as tmp:
                path, out = os.path.join(tmp, "t" + ext), os.path.join(tmp, "c" + ext)
                self.scene(path)
                self.assertIsNone(ps.camera(path))
                cam = ps.framing_camera(*ps.bounds(path), 1.5)
                ps.with_camera(path, out, cam)
                os.remove(path)  # the copy stands alone
                if ext == ".gltf":
                    for f in os.listdir(tmp):
                        if f != "c.gltf":
                            os.remove(os.path.join(tmp, f))
                got = ps.camera(out)
                for k in ("position", "forward", "up"):
                    self.assertClose(got[k], cam[k], 1e-12)
                self.assertEqual(got["yfov"], cam["yfov"])
                self.assertEqual(got["aspect"], 1.5)
                self.assertClose(ps.bounds(out)[0], (1.0, 0.0, -1.0))

    def test_with_camera_refuses_a_file_with_cameras(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "t.glb")
            self.scene(path, camera=True)
            self.assertEqual(ps.camera(path)["position"], (0.0, 0.0, 5.0))
            with self.assertRaisesRegex(ValueError, "has cameras already"):
                ps.with_camera(path, os.path.join(tmp, "c.glb"), ps.camera(path))


class NearestTextures(unittest.TestCase):
    def test_every_texture_samples_nearest(self):
        doc = {"samplers": [{"wrapS": 33071}],
               "textures": [{"sampler": 0, "source": 0}, {"source": 1}]}
        ps.nearest_textures(doc)
        self.assertEqual(doc["samplers"], [{"wrapS": 33071, "magFilter": 9728, "minFilter": 9728},
                                           {"magFilter": 9728, "minFilter": 9728}])
        self.assertEqual([t["sampler"] for t in doc["textures"]], [0, 1])

    def test_no_normal_maps(self):
        doc = {"materials": [{"normalTexture": {"index": 0}, "name": "a"}, {"name": "b"}]}
        ps.no_normal_maps(doc)
        self.assertEqual(doc["materials"], [{"name": "a"}, {"name": "b"}])


def _mesh(name, material, *triangles):
    positions = [p for t in triangles for p in t]
    return {"name": name, "material": material, "positions": positions,
            "triangles": [(3 * k, 3 * k + 1, 3 * k + 2) for k in range(len(triangles))]}


class CoincidentEmitters(unittest.TestCase):
    """peers_scene.coincident_emitters and load()'s refusal (docs/peers.md, Coincident emitters: such lamps made
    Cycles 3% darker than wavepath and Mitsuba, and wavepath's light and BSDF sampling disagree)."""

    MATERIALS = [{"emission": (1.0, 1.0, 1.0)}, {"emission": (0.0, 0.0, 0.0)}]

    def found(self, *meshes):
        return ps.coincident_emitters({"meshes": list(meshes), "materials": self.MATERIALS})

    def test_pairs(self):
        lamp = _mesh("lamp", 0, ((0, 1, 0), (0, 1, 1), (1, 1, 0)))  # facing -Y
        self.assertEqual(self.found(lamp), [])
        # Coplanar and overlapping, either facing, emitter or not: found, the area of the overlap.
        for other in (((0.5, 1, 0), (0.5, 1, 1), (1.5, 1, 0)),    # the same facing
                      ((0.5, 1, 0), (1.5, 1, 0), (0.5, 1, 1))):   # facing +Y
            for material in (0, 1):
                (hit,) = self.found(lamp, _mesh("other", material, other))
                self.assertEqual(hit[:2], ("lamp", "other"))
                self.assertAlmostEqual(hit[2], 0.125, delta=1e-9)
        # A shared edge, a parallel plane 1 mm off, a perpendicular triangle: none.
        self.assertEqual(self.found(lamp, _mesh("edge", 0, ((0, 1, 1), (1, 1, 1), (1, 1, 0)))), [])
        self.assertEqual(self.found(lamp, _mesh("off", 1, ((0, 1.001, 0), (0, 1.001, 1),
                                                          (1, 1.001, 0)))), [])
        self.assertEqual(self.found(lamp, _mesh("wall", 1, ((0, 0, 0), (0, 2, 0), (0, 0, 2)))), [])
        # Two non-emitters may coincide (not this check's business).
        self.assertEqual(self.found(_mesh("a", 1, ((0, 1, 0), (0, 1, 1), (1, 1, 0))),
                                    _mesh("b", 1, ((0, 1, 0), (0, 1, 1), (1, 1, 0)))), [])

    def load_room(self, **kw):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "room.gltf")
            mml.build(**kw).write(path)
            return ps.load(path)

    def test_many_light_room_converts(self):
        scene = self.load_room()
        s = ps.summary(scene)
        self.assertEqual(len(s["emitters"]), 300)
        for e in s["emitters"]:
            self.assertEqual(e["normal"], (0.0, -1.0, 0.0))
            self.assertAlmostEqual(e["area"], mml.LAMP ** 2, delta=1e-7)
        self.assertEqual(len({e["radiance"] for e in s["emitters"]}), 300)  # coloured
        by_name = {m["name"]: m for m in scene["materials"]}
        self.assertEqual(by_name["black"]["reflectance"], (0.0, 0.0, 0.0))
        self.assertEqual(by_name["grey"]["reflectance"], (0.5, 0.5, 0.5))
        self.assertTrue(all(m["specular"] == 0.0 and not m["double_sided"]
                            for m in scene["materials"]))
        self.assertEqual(ps.coincident_emitters(scene), [])

    def test_overlapping_lamps_refused(self):
        with self.assertRaisesRegex(ps.ConversionError, "coincide with other surfaces"):
            self.load_room(layout="random", lamp=0.1)

    def test_lamps_flush_with_the_ceiling_refused(self):
        with self.assertRaisesRegex(ps.ConversionError, "'lamp0' and 'ceiling'"):
            self.load_room(lamps=4, drop=0.0)


class Ply(unittest.TestCase):
    def test_round_trip(self):
        mesh = {"positions": [(0.0, 0.5, 1.0), (2.0, 3.0, 4.0), (5.0, 6.0, 7.25)],
                "triangles": [(0, 1, 2), (2, 1, 0)]}
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "m.ply")
            ps.write_ply(path, mesh)
            with open(path, "rb") as f:
                data = f.read()
        head, body = data.split(b"end_header\n", 1)
        self.assertIn(b"element vertex 3", head)
        self.assertIn(b"element face 2", head)
        self.assertEqual(len(body), 3 * 12 + 2 * 13)
        verts = [struct.unpack_from("<3f", body, 12 * i) for i in range(3)]
        self.assertEqual(verts, mesh["positions"])
        faces = [struct.unpack_from("<B3I", body, 36 + 13 * i) for i in range(2)]
        self.assertEqual(faces, [(3, 0, 1, 2), (3, 2, 1, 0)])


if __name__ == "__main__":
    unittest.main(verbosity=2)
