#!/usr/bin/env python3
"""Self-test of tools/wavepath_tools/peers_pbr.py, the glTF to Mitsuba 3 converter of
`tools/peers.py --pbr` (stdlib unittest; runs with plain python3).

    python3 tests/test_peers_pbr.py

Without PyPI: the mapping of each material parameter onto Mitsuba's principled BSDF (and its
twosided, normalmap and mask wrappers), the textures' channels and colour spaces, the samplers,
node transforms of the PLY meshes written (positions, normals, winding, the texture coordinates), punctual
lights, the environment's orientation (wavepath's env_dir_uv against Mitsuba's envmap lookup,
in Python), KHR_texture_transform's matrix and its to_uv on every texture slot, and the
refusals. With NumPy and Pillow (Debian's python3-numpy, python3-pil): the
texture data baked from a PNG (sRGB decoding, factors, the MASK cut-off, the normal scale).
With Mitsuba: the realised dict loads and evaluates, and a transformed bitmap looks up the texel
glTF's transform names. With ../shared/assets: the sample models
convert. Each of those skips, not fails, where its packages or files are absent.
"""

import json
import math
import os
import struct
import sys
import tempfile
import unittest
import zlib

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(REPO, "tools"))
sys.path.insert(0, os.path.join(REPO, "scenes"))

import gltf_builder as gb  # noqa: E402
from wavepath_tools import peers_pbr as pp  # noqa: E402

ASSETS = os.path.join(os.path.dirname(REPO), "shared", "assets")


def have(module):
    try:
        __import__(module)
        return True
    except ImportError:
        return False


def png(pixels):
    """A minimal 8-bit RGBA PNG of rows of (r, g, b, a) tuples."""
    raw = b"".join(b"\0" + bytes(c for p in row for c in p) for row in pixels)

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    head = struct.pack(">IIBBBBB", len(pixels[0]), len(pixels), 8, 6, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", head) + chunk(b"IDAT", zlib.compress(raw))
            + chunk(b"IEND", b""))


TEXELS = [[(255, 0, 0, 255), (0, 255, 0, 0)], [(0, 0, 255, 128), (188, 188, 188, 255)]]


def document(material=None, extensions_used=(), uvs=True, **node):
    """A one-triangle glTF document (dict) with one 2 x 2 PNG image and texture 0 on it;
    `material` updates the material's JSON; `node` are node() arguments of the triangle."""
    b = gb.GltfBuilder()
    m = b.material("m", base_color=(0.5, 0.5, 0.5))
    tri = b.mesh("tri", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [0, 1, 2], m,
                 normals=[(0, 0, 1)] * 3, uvs=[(0, 0), (1, 0), (0, 1)] if uvs else None)
    b.node("tri", mesh=tri, **node)
    doc = json.loads(b.to_bytes(False))
    doc["images"] = [{"uri": "tex.png"}]
    doc["samplers"] = [{"magFilter": 9728, "wrapS": 33071, "wrapT": 33071}]
    doc["textures"] = [{"source": 0, "sampler": 0}, {"source": 0}]
    doc["materials"][0].update(material or {})
    if extensions_used:
        doc["extensionsUsed"] = sorted(set(doc.get("extensionsUsed", [])) | set(extensions_used))
    return doc


def convert(doc, tmp, texels=TEXELS):
    path = os.path.join(tmp, "t.gltf")
    with open(path, "w") as f:
        json.dump(doc, f)
    with open(os.path.join(tmp, "tex.png"), "wb") as f:
        f.write(png(texels))
    return pp.convert(path, os.path.join(tmp, "work"))


def one_material(material=None, extensions_used=()):
    with tempfile.TemporaryDirectory() as tmp:
        return convert(document(material, extensions_used), tmp)


def read_ply(path):
    """(property names, vertex rows, triangles) of write_ply's output."""
    with open(path, "rb") as f:
        data = f.read()
    head, body = data.split(b"end_header\n", 1)
    lines = head.decode().splitlines()
    props = [l.split()[-1] for l in lines if l.startswith("property float")]
    nv = int([l for l in lines if l.startswith("element vertex")][0].split()[-1])
    nf = int([l for l in lines if l.startswith("element face")][0].split()[-1])
    size = 4 * len(props)
    verts = [struct.unpack_from("<%df" % len(props), body, k * size) for k in range(nv)]
    tris = [struct.unpack_from("<B3I", body, nv * size + 13 * k)[1:] for k in range(nf)]
    return props, verts, tris


class Materials(unittest.TestCase):
    def bsdf(self, material=None, extensions_used=()):
        return one_material(material, extensions_used)["materials"][0]["bsdf"]

    def test_constant_metallic_roughness(self):
        b = self.bsdf({"pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.3, 0.4, 1.0],
                                                "metallicFactor": 0.7, "roughnessFactor": 0.4}})
        self.assertEqual(b["type"], "principled")
        self.assertEqual(b["base_color"], {"type": "rgb", "value": [0.2, 0.3, 0.4]})
        self.assertEqual((b["metallic"], b["roughness"]), (0.7, 0.4))
        self.assertAlmostEqual(b["eta"], 1.5)  # F0 0.04, principled's specular 0.5

    def test_textures_and_colour_spaces(self):
        b = self.bsdf({"pbrMetallicRoughness": {
            "baseColorFactor": [0.5, 1.0, 1.0, 1.0], "baseColorTexture": {"index": 0},
            "metallicFactor": 0.8, "roughnessFactor": 0.6,
            "metallicRoughnessTexture": {"index": 1}}})
        base, metal, rough = (b[k]["peers"] for k in ("base_color", "metallic", "roughness"))
        self.assertEqual((base["channels"], base["srgb"], base["factor"]),
                         ([0, 1, 2], True, [0.5, 1.0, 1.0]))
        self.assertEqual((metal["channels"], metal["srgb"], metal["factor"]), ([2], False, [0.8]))
        self.assertEqual((rough["channels"], rough["srgb"], rough["factor"]), ([1], False, [0.6]))
        # texture 0's sampler: NEAREST, CLAMP_TO_EDGE; texture 1 has none: glTF's defaults
        self.assertEqual((b["base_color"]["filter_type"], b["base_color"]["wrap_mode"]),
                         ("nearest", "clamp"))
        self.assertEqual((b["metallic"]["filter_type"], b["metallic"]["wrap_mode"]),
                         ("bilinear", "repeat"))

    def test_ior_and_specular(self):
        self.assertAlmostEqual(self.bsdf({"extensions": {"KHR_materials_ior": {"ior": 1.7}}})
                               ["eta"], 1.7)
        b = self.bsdf({"extensions": {"KHR_materials_specular": {"specularFactor": 0.5}}})
        f0 = ((b["eta"] - 1) / (b["eta"] + 1)) ** 2
        self.assertAlmostEqual(f0, 0.02)  # 0.04 x 0.5
        self.assertEqual(self.bsdf({"extensions": {"KHR_materials_specular": {
            "specularFactor": 0.0}}})["eta"], 1.0)

    def test_transmission_thin_and_solid(self):
        thin = self.bsdf({"extensions": {"KHR_materials_transmission": {
            "transmissionFactor": 0.9}}})
        self.assertEqual((thin["type"], thin["spec_trans"]), ("principledthin", 0.9))
        self.assertNotIn("metallic", thin)
        solid = self.bsdf({"doubleSided": True, "extensions": {
            "KHR_materials_transmission": {"transmissionFactor": 1.0},
            "KHR_materials_volume": {"thicknessFactor": 0.1}}})
        self.assertEqual((solid["type"], solid["spec_trans"]), ("principled", 1.0))  # no twosided

    def test_clearcoat(self):
        b = self.bsdf({"extensions": {"KHR_materials_clearcoat": {
            "clearcoatFactor": 0.7, "clearcoatRoughnessFactor": 0.2}}})
        self.assertEqual(b["clearcoat"], 0.7)
        self.assertAlmostEqual(0.1 + (0.001 - 0.1) * b["clearcoat_gloss"], 0.2 ** 2)

    def test_anisotropy_keeps_both_alphas(self):
        b = self.bsdf({"pbrMetallicRoughness": {"roughnessFactor": 0.5}, "extensions": {
            "KHR_materials_anisotropy": {"anisotropyStrength": 0.6}}})
        a = 0.25
        at = a + (1 - a) * 0.36  # glTF: alpha_t = mix(alpha, 1, strength^2), alpha_b = alpha
        aspect = math.sqrt(1 - 0.9 * b["anisotropic"])
        self.assertAlmostEqual(b["roughness"] ** 2 / aspect, at)
        self.assertAlmostEqual(b["roughness"] ** 2 * aspect, a)

    def test_wrappers(self):
        b = self.bsdf({"doubleSided": True, "alphaMode": "MASK", "alphaCutoff": 0.3,
                       "normalTexture": {"index": 1, "scale": 0.5},
                       "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.8],
                                                "baseColorTexture": {"index": 1}}})
        self.assertEqual(b["type"], "mask")
        op = b["opacity"]["peers"]
        self.assertEqual((op["channels"], op["srgb"], op["factor"], op["op"], op["arg"]),
                         ([3], False, [0.8], "cutoff", 0.3))
        self.assertEqual(b["opacity"]["filter_type"], "nearest")
        self.assertEqual(b["bsdf"]["type"], "normalmap")
        nm = b["bsdf"]["normalmap"]["peers"]
        self.assertEqual((nm["srgb"], nm["op"], nm["arg"]), (False, "normal", 0.5))
        self.assertEqual(b["bsdf"]["bsdf"]["type"], "twosided")
        self.assertEqual(b["bsdf"]["bsdf"]["bsdf"]["type"], "principled")

    def test_constant_alpha(self):
        self.assertEqual(self.bsdf({"alphaMode": "MASK", "pbrMetallicRoughness": {
            "baseColorFactor": [1, 1, 1, 0.6]}})["type"], "principled")  # 0.6 >= 0.5: opaque
        b = self.bsdf({"alphaMode": "BLEND", "pbrMetallicRoughness": {
            "baseColorFactor": [1, 1, 1, 0.25]}})
        self.assertEqual((b["type"], b["opacity"]), ("mask", 0.25))

    def test_emission(self):
        mat = one_material({"emissiveFactor": [1.0, 0.5, 0.25],
                            "emissiveTexture": {"index": 0},
                            "extensions": {"KHR_materials_emissive_strength": {
                                "emissiveStrength": 4.0}}})["materials"][0]
        rad = mat["emitter"]["radiance"]["peers"]
        self.assertEqual(mat["emitter"]["type"], "area")
        self.assertEqual((rad["srgb"], rad["factor"]), (True, [4.0, 2.0, 1.0]))
        self.assertIsNone(one_material()["materials"][0]["emitter"])

    def test_gaps_are_noted(self):
        notes = one_material({"extensions": {"KHR_materials_sheen": {
            "sheenColorFactor": [0.5, 0.4, 0.3]}, "KHR_materials_iridescence": {}}})["notes"]
        self.assertTrue(any("sheen" in n for n in notes))
        self.assertTrue(any("iridescence" in n for n in notes))


class Refusals(unittest.TestCase):
    def refused(self, pattern, material=None, extensions_used=()):
        doc = document(material, extensions_used)
        with tempfile.TemporaryDirectory() as tmp:
            with self.assertRaisesRegex(pp.ConversionError, pattern):
                convert(doc, tmp)

    def test_texture_transform_texcoord_override(self):
        # KHR_texture_transform converts (TextureTransform), but its texCoord override names
        # the UV set looked up, and only TEXCOORD_0 converts.
        self.refused("KHR_texture_transform texCoord 1", {"pbrMetallicRoughness": {
            "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {
                "scale": [2, 2], "texCoord": 1}}}}}, ["KHR_texture_transform"])
        self.refused("KHR_texture_transform texCoord 1", {"normalTexture": {
            "index": 0, "texCoord": 0, "extensions": {"KHR_texture_transform": {"texCoord": 1}}}})

    def test_second_uv_set(self):
        self.refused("texCoord 1", {"normalTexture": {"index": 0, "texCoord": 1}})

    def test_compression_and_others(self):
        for ext in ("KHR_draco_mesh_compression", "EXT_meshopt_compression",
                    "KHR_materials_unlit", "KHR_materials_pbrSpecularGlossiness"):
            self.refused(ext, extensions_used=[ext])

    def test_unknown_required(self):
        doc = document()
        doc["extensionsRequired"] = ["EXT_made_up"]
        with tempfile.TemporaryDirectory() as tmp:
            with self.assertRaisesRegex(pp.ConversionError, "EXT_made_up"):
                convert(doc, tmp)


class TextureTransform(unittest.TestCase):
    def assert_maps(self, m, uv, want):
        got = [m[i][0] * uv[0] + m[i][1] * uv[1] + m[i][2] for i in range(2)]
        self.assertEqual([row[:] for row in m[2:]], [[0.0, 0.0, 1.0]])
        for g, w in zip(got, want):
            self.assertAlmostEqual(g, w, places=12, msg=(uv, got, want))

    def test_matrix(self):
        # offset (0.25, 0.5), rotation pi/2, scale (2, 3): S (u, v) = (2u, 3v); R turns the
        # UVs counter-clockwise (rows (c, s), (-s, c)): (x, y) -> (y, -x); then T: + offset.
        # So (u, v) -> (3v + 0.25, -2u + 0.5).
        m = pp.uv_transform({"offset": [0.25, 0.5], "rotation": math.pi / 2, "scale": [2, 3]})
        for uv, want in (((0, 0), (0.25, 0.5)), ((1, 0), (0.25, -1.5)), ((0, 1), (3.25, 0.5)),
                         ((0.5, 0.5), (1.75, -0.5)), ((0.1, 0.05), (0.4, 0.3))):
            self.assert_maps(m, uv, want)

    def test_extension_example(self):
        # The extension's own example: offset (0, 1), rotation pi/2, scale 0.5 uses "only the
        # lower left quadrant of the source image, rotated clockwise 90 degrees" (v = 0 at the
        # top): (u, v) -> (v / 2, 1 - u / 2).
        m = pp.uv_transform({"offset": [0, 1], "rotation": math.pi / 2, "scale": [0.5, 0.5]})
        for uv, want in (((0, 0), (0, 1)), ((1, 0), (0, 0.5)), ((0, 1), (0.5, 1)),
                         ((1, 1), (0.5, 0.5))):
            self.assert_maps(m, uv, want)
        # flipping T: offset (0, 1), scale (1, -1): (u, v) -> (u, 1 - v)
        self.assert_maps(pp.uv_transform({"offset": [0, 1], "scale": [1, -1]}), (0.2, 0.3),
                         (0.2, 0.7))
        self.assertEqual(pp.uv_transform({}), pp.IDENTITY3)

    def test_every_slot_carries_to_uv(self):
        def xf(k, **extra):
            return dict({"index": k % 2, "extensions": {"KHR_texture_transform": {
                "offset": [0.1 * k, 0.0], "scale": [2, 2]}}}, **extra)
        desc = one_material({
            "alphaMode": "MASK", "doubleSided": True,
            "pbrMetallicRoughness": {"baseColorTexture": xf(1), "metallicRoughnessTexture": xf(2)},
            "normalTexture": xf(3, scale=0.5), "emissiveFactor": [1, 1, 1],
            "emissiveTexture": xf(4),
            "extensions": {"KHR_materials_clearcoat": {
                "clearcoatFactor": 1.0, "clearcoatTexture": xf(5),
                "clearcoatRoughnessTexture": xf(6)}}}, ["KHR_texture_transform"])
        mat = desc["materials"][0]
        mask = mat["bsdf"]
        normal = mask["bsdf"]["normalmap"]
        p = mask["bsdf"]["bsdf"]["bsdf"]
        slots = {"alpha": (mask["opacity"], 1), "base_color": (p["base_color"], 1),
                 "metallic": (p["metallic"], 2), "roughness": (p["roughness"], 2),
                 "normal": (normal, 3), "emission": (mat["emitter"]["radiance"], 4),
                 "clearcoat": (p["clearcoat"], 5), "clearcoat_gloss": (p["clearcoat_gloss"], 6)}
        for name, (tex, k) in slots.items():
            self.assertEqual(tex["to_uv"], {"peers_to_uv": [[2.0, 0.0, 0.1 * k],
                                                            [0.0, 2.0, 0.0],
                                                            [0.0, 0.0, 1.0]]}, name)
        # one image, three transforms: each bitmap its own to_uv (not shared dicts)
        self.assertIsNot(p["base_color"]["to_uv"], normal["to_uv"])
        self.assertEqual(p["base_color"]["peers"]["image"], normal["peers"]["image"])
        self.assertNotIn("KHR_texture_transform", " ".join(desc["notes"]))

    def test_identity_and_plain_textures_have_no_to_uv(self):
        b = one_material({"pbrMetallicRoughness": {
            "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {
                "texCoord": 0}}},
            "metallicRoughnessTexture": {"index": 1}}})["materials"][0]["bsdf"]
        self.assertNotIn("to_uv", b["base_color"])
        self.assertNotIn("to_uv", b["metallic"])

    def test_override_zero_replaces_texcoord(self):
        b = one_material({"pbrMetallicRoughness": {"baseColorTexture": {
            "index": 0, "texCoord": 1, "extensions": {"KHR_texture_transform": {
                "rotation": 0.5, "texCoord": 0}}}}})["materials"][0]["bsdf"]
        self.assertIn("to_uv", b["base_color"])

    def test_required_extension_converts(self):
        doc = document({"pbrMetallicRoughness": {"baseColorTexture": {
            "index": 0, "extensions": {"KHR_texture_transform": {"scale": [2, 2]}}}}},
            ["KHR_texture_transform"])
        doc["extensionsRequired"] = ["KHR_texture_transform"]
        with tempfile.TemporaryDirectory() as tmp:
            desc = convert(doc, tmp)
        self.assertEqual(desc["materials"][0]["bsdf"]["base_color"]["to_uv"]["peers_to_uv"][0],
                         [2.0, 0.0, 0.0])


class Geometry(unittest.TestCase):
    def test_transform_normals_winding_and_uvs(self):
        # Mirror x and scale y by 2 (matrix, column-major): positions, normals (inverse
        # transpose, unit), the winding reversed, the texture coordinates as they are (Mitsuba's
        # PLY reader keeps them and its bitmaps put v = 0 at the top row, as glTF does:
        # WithMitsuba.test_texture_coordinates_are_gltfs).
        doc = document(matrix=(-1, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1, 0, 3, 0, 0, 1))
        with tempfile.TemporaryDirectory() as tmp:
            desc = convert(doc, tmp)
            props, verts, tris = read_ply(desc["shapes"][0]["ply"])
        self.assertEqual(props, ["x", "y", "z", "nx", "ny", "nz", "u", "v"])
        for got, want in zip(verts, [(3, 0, 0, 0, 0, 1, 0, 0), (2, 0, 0, 0, 0, 1, 1, 0),
                                     (3, 2, 0, 0, 0, 1, 0, 1)]):
            for g, w in zip(got, want):
                self.assertAlmostEqual(g, w, places=6)
        self.assertEqual(tris, [(0, 2, 1)])
        a, b, c = (verts[k][:3] for k in tris[0])
        cross_z = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        self.assertGreater(cross_z, 0.0)  # the front still faces +Z, as the normals

    def test_normal_under_rotation(self):
        s = math.sqrt(0.5)
        doc = document(rotation=(0, s, 0, s), scale=(1, 1, 3))  # Ry(90): +Z -> +X
        with tempfile.TemporaryDirectory() as tmp:
            _, verts, _ = read_ply(convert(doc, tmp)["shapes"][0]["ply"])
        for g, w in zip(verts[0][3:6], (1, 0, 0)):
            self.assertAlmostEqual(g, w, places=6)

    def test_flat_shading_without_normals(self):
        b = gb.GltfBuilder()
        m = b.material("m")
        b.node("t", mesh=b.mesh("t", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [0, 1, 2], m))
        with tempfile.TemporaryDirectory() as tmp:
            path = b.write(os.path.join(tmp, "t.glb"))
            desc = pp.convert(path, tmp)
            d = pp.mitsuba_scene(desc, CAM, JOB)
        self.assertTrue(d["shape0"]["face_normals"])


CAM = {"position": (0, 0, 5), "forward": (0, 0, -1), "up": (0, 1, 0), "yfov": 0.5}
JOB = {"spp": 4, "width": 8, "height": 6, "max_depth": 3, "rr_depth": 5}


class SceneAndLights(unittest.TestCase):
    def test_lights(self):
        b = gb.GltfBuilder()
        b.node("p", light=b.point_light((1, 0.5, 0.25), 8.0), translation=(1, 2, 3))
        b.node("s", light=b.spot_light((1, 1, 1), 2.0, 0.1, 0.3), translation=(0, 1, 0),
               rotation=(-math.sqrt(0.5), 0, 0, math.sqrt(0.5)))  # -Z turned to -Y
        b.node("d", light=b.directional_light((1, 1, 1), 3.0))
        with tempfile.TemporaryDirectory() as tmp:
            desc = pp.convert(b.write(os.path.join(tmp, "l.gltf")), tmp)
        point, spot, sun = desc["emitters"]
        self.assertEqual(point, {"type": "point", "position": [1.0, 2.0, 3.0],
                                 "intensity": {"type": "rgb", "value": [8.0, 4.0, 2.0]}})
        self.assertEqual(spot["type"], "spot")
        self.assertAlmostEqual(spot["cutoff_angle"], math.degrees(0.3))
        self.assertAlmostEqual(spot["beam_width"], math.degrees(0.1))
        o, t, _ = spot["to_world"]["peers_look_at"]
        for g, w in zip([t[i] - o[i] for i in range(3)], (0, -1, 0)):
            self.assertAlmostEqual(g, w, places=6)
        self.assertEqual(sun["type"], "directional")
        for g, w in zip(sun["direction"], (0, 0, -1)):
            self.assertAlmostEqual(g, w)

    def test_scene_dict(self):
        desc = one_material()
        d = pp.mitsuba_scene(desc, CAM, dict(JOB, sampler="ldsampler"),
                             {"path": "env.hdr", "intensity": 2.0, "rotation": 30.0})
        self.assertEqual(d["integrator"], {"type": "path", "max_depth": 4, "rr_depth": 5})
        self.assertEqual(d["sensor"]["sampler"], {"type": "ldsampler", "sample_count": 4})
        self.assertEqual(d["sensor"]["fov_axis"], "y")
        self.assertEqual(d["environment"]["scale"], 2.0)
        self.assertEqual(d["environment"]["to_world"], {"peers_rotate_y": 210.0})
        self.assertNotIn("environment", pp.mitsuba_scene(desc, CAM, JOB))


class Environment(unittest.TestCase):
    def test_mitsuba_looks_up_wavepaths_texel(self):
        # wavepath's env_dir_uv (kernels/lights/environment.h) and Mitsuba's envmap
        # direction_to_uv under to_world = Ry(env_to_world_degrees(R)) agree on every direction.
        dirs = [(math.sin(t) * math.cos(p), math.cos(t), math.sin(t) * math.sin(p))
                for t in (0.3, 1.0, 1.5707, 2.4) for p in (0.0, 0.7, 2.0, 3.5, 5.0)]
        dirs += [(1, 0, 0), (-1, 0, 0), (0, 0, 1), (0, 0, -1)]
        for rot in (0.0, 30.0, -75.0, 180.0):
            for w in dirs:
                uw, vw = pp.wavepath_env_uv(w, rot)
                um, vm = pp.mitsuba_env_uv(w, pp.env_to_world_degrees(rot))
                du = (uw - um) % 1.0
                self.assertLess(min(du, 1.0 - du), 1e-9, (w, rot))
                self.assertAlmostEqual(vw, vm, places=9)

    def test_map_centre(self):
        self.assertAlmostEqual(pp.wavepath_env_uv((0, 0, -1), 0.0)[0], 0.5)  # -Z at the centre
        self.assertAlmostEqual(pp.mitsuba_env_uv((0, 0, 1), 0.0)[0], 0.5)   # Mitsuba's: +Z


@unittest.skipUnless(have("numpy") and have("PIL"), "needs NumPy and Pillow")
class TextureData(unittest.TestCase):
    def data(self, **spec):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "t.png")
            with open(path, "wb") as f:
                f.write(png(TEXELS))
            base = {"image": path, "channels": [0, 1, 2], "srgb": False, "factor": [1, 1, 1],
                    "op": None, "arg": None}
            base.update(spec)
            return pp.texture_data(base, {})

    def test_srgb_decoded(self):
        x = self.data(srgb=True)
        self.assertEqual(x.shape, (2, 2, 3))
        self.assertAlmostEqual(float(x[1, 1, 0]), ((188 / 255 + 0.055) / 1.055) ** 2.4, places=6)
        self.assertAlmostEqual(float(self.data()[1, 1, 0]), 188 / 255, places=6)  # linear data
        self.assertEqual(float(x[0, 0, 0]), 1.0)  # row 0 is the image's top

    def test_factor_and_cutoff(self):
        a = self.data(channels=[3], factor=[0.8], op="cutoff", arg=0.4)
        self.assertEqual([float(v) for v in a.ravel()], [1.0, 0.0, 1.0, 1.0])  # 128/255 x .8
        g = self.data(channels=[1], factor=[0.5])
        self.assertAlmostEqual(float(g[0, 1, 0]), 0.5)

    def test_normal_scale(self):
        n = self.data(op="normal", arg=0.5)
        self.assertAlmostEqual(float(n[0, 0, 0]), 0.75)  # x: (2 - 1) x 0.5 -> 0.75
        self.assertAlmostEqual(float(n[0, 0, 2]), 0.0)   # z unscaled


@unittest.skipUnless(have("mitsuba") and have("numpy") and have("PIL"), "needs Mitsuba")
class WithMitsuba(unittest.TestCase):
    def test_loads_and_renders(self):
        import mitsuba as mi
        import numpy as np
        mi.set_variant("scalar_rgb")
        with tempfile.TemporaryDirectory() as tmp:
            desc = convert(document({"doubleSided": True, "normalTexture": {"index": 0},
                                     "pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                                                              "metallicRoughnessTexture": {
                                                                  "index": 1}}}), tmp)
            d = pp.realize(pp.mitsuba_scene(desc, CAM, JOB), mi)
            img = np.array(mi.render(mi.load_dict(d), spp=4))
        self.assertEqual(img.shape[:2], (6, 8))

    def test_texture_coordinates_are_gltfs(self):
        # A ray hitting the converted triangle at (0.1, 0.6) finds glTF's uv there, (0.1, 0.6)
        # (the triangle's uv is its (x, y)), and a Mitsuba bitmap looks v < 0.5 up in its top
        # row, as glTF does: so the converted texture shows the texel glTF names. (Written as
        # 1 - v, DamagedHelmet's textures came out mirrored: a metal visor without its lights.)
        import mitsuba as mi
        import numpy as np
        mi.set_variant("scalar_rgb")
        with tempfile.TemporaryDirectory() as tmp:
            desc = convert(document(), tmp)
            scene = mi.load_dict({"type": "scene", "s": {"type": "ply",
                                                         "filename": desc["shapes"][0]["ply"]}})
            si = scene.ray_intersect(mi.Ray3f(mi.Point3f(0.1, 0.6, 1.0),
                                              mi.Vector3f(0.0, 0.0, -1.0)))
            self.assertAlmostEqual(si.uv[0], 0.1, places=5)
            self.assertAlmostEqual(si.uv[1], 0.6, places=5)
        img = np.zeros((2, 2, 3), np.float32)
        img[0, :, 0] = 1.0  # top row red, bottom row blue
        img[1, :, 2] = 1.0
        tex = mi.load_dict({"type": "bitmap", "bitmap": mi.Bitmap(img), "raw": True,
                            "filter_type": "nearest"})
        probe = mi.SurfaceInteraction3f()
        for v, want in ((0.1, (1.0, 0.0, 0.0)), (0.9, (0.0, 0.0, 1.0))):
            probe.uv = mi.Point2f(0.25, v)
            self.assertEqual(tuple(float(c) for c in tex.eval(probe)), want)

    def test_texture_transform_picks_gltfs_texel(self):
        # A 4 x 4 image, texel (column c, row r; row 0 the top) of colour (30 + 60 c, 30 + 60 r,
        # 128), as baseColorTexture (sRGB) with nearest filtering. glTF looks uv up at
        # (u', v') = M (u, v, 1), texel (floor(4 u'), floor(4 v')) (wrapped). Worked by hand:
        #   offset (0.25, 0.5), rotation pi/2, scale (2, 3), REPEAT: (u', v') = (3v + 0.25,
        #   -2u + 0.5); uv (0.1, 0.05) -> (0.4, 0.3): texel (1, 1); (0.3, 0.2) -> (0.85, -0.1),
        #   v' wraps to 0.9: texel (3, 3); (0.05, 0.3) -> (1.15, 0.4), u' wraps to 0.15:
        #   texel (0, 1); (0.35, 0.1) -> (0.55, -0.2) -> (0.55, 0.8): texel (2, 3).
        #   The extension's example, offset (0, 1), rotation pi/2, scale 0.5, CLAMP:
        #   (u', v') = (v / 2, 1 - u / 2); uv (0.1, 0.9) -> (0.45, 0.95): texel (1, 3);
        #   (0.9, 0.2) -> (0.1, 0.55): texel (0, 2); (0.6, 0.7) -> (0.35, 0.7): texel (1, 2).
        import mitsuba as mi
        mi.set_variant("scalar_rgb")
        texels = [[(30 + 60 * c, 30 + 60 * r, 128, 255) for c in range(4)] for r in range(4)]

        def linear(byte):
            x = byte / 255.0
            return x / 12.92 if x <= 0.04045 else ((x + 0.055) / 1.055) ** 2.4

        cases = (({"offset": [0.25, 0.5], "rotation": math.pi / 2, "scale": [2, 3]}, 10497,
                  [((0.1, 0.05), (1, 1)), ((0.3, 0.2), (3, 3)), ((0.05, 0.3), (0, 1)),
                   ((0.35, 0.1), (2, 3))]),
                 ({"offset": [0, 1], "rotation": math.pi / 2, "scale": [0.5, 0.5]}, 33071,
                  [((0.1, 0.9), (1, 3)), ((0.9, 0.2), (0, 2)), ((0.6, 0.7), (1, 2))]))
        for xf, wrap, points in cases:
            doc = document({"pbrMetallicRoughness": {"baseColorTexture": {
                "index": 0, "extensions": {"KHR_texture_transform": xf}}}},
                ["KHR_texture_transform"])
            doc["samplers"] = [{"magFilter": 9728, "wrapS": wrap, "wrapT": wrap}]
            with tempfile.TemporaryDirectory() as tmp:
                desc = convert(doc, tmp, texels)
                tex = mi.load_dict(pp.realize(desc["materials"][0]["bsdf"]["base_color"], mi))
            probe = mi.SurfaceInteraction3f()
            for uv, (c, r) in points:
                probe.uv = mi.Point2f(*uv)
                want = [linear(v) for v in texels[r][c][:3]]
                got = [float(x) for x in tex.eval(probe)]
                for g, w in zip(got, want):
                    self.assertAlmostEqual(g, w, places=5, msg=(xf, uv, (c, r), got, want))


@unittest.skipUnless(os.path.isdir(os.path.join(ASSETS, "models")), "needs ../shared/assets")
class SampleModels(unittest.TestCase):
    def test_convert(self):
        for name in ("BoxTextured/BoxTextured.glb", "DamagedHelmet/DamagedHelmet.glb",
                     "SheenChair/SheenChair.gltf", "ClearCoatCarPaint/ClearCoatCarPaint.glb"):
            path = os.path.join(ASSETS, "models", name)
            if not os.path.exists(path):
                continue
            with tempfile.TemporaryDirectory() as tmp:
                desc = pp.convert(path, tmp)
            self.assertTrue(desc["shapes"], name)


if __name__ == "__main__":
    unittest.main()
