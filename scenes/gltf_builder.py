"""A small glTF 2.0 writer for wavepath's own test scenes (Python 3 standard library only).

Usage:

    b = GltfBuilder()
    red = b.material("red", base_color=(0.63, 0.065, 0.05))
    pos, nrm, idx = box((0, 0, 0), (1, 1, 1))
    b.node("cube", mesh=b.mesh("cube", pos, idx, red, normals=nrm))
    b.node("camera", camera=b.perspective_camera(0.7, 0.01),
           translation=(0, 0.5, 3), rotation=b.look_at((0, 0.5, 3), (0.5, 0.5, 0.5)))
    b.write("cube.gltf")   # or "cube.glb"

Conventions (those of glTF 2.0, and of wavepath's loader):
- Right-handed, +Y up, metres. A camera looks down its node's -Z with +Y up; spot and
  directional lights shine down their node's -Z.
- A triangle's front is the side from which its vertices run counter-clockwise; the shape helpers
  below return triangles whose fronts face outward (quad: toward the side its corners are
  counter-clockwise from).
- Colours are linear RGB. Emission is radiance = emissiveFactor x emissive strength; punctual
  light intensities are read by wavepath as W/sr (point, spot) and W/m^2 (directional).

Every node whose index is not any other node's child is a root of the one scene. Output is
deterministic: the same calls give the same bytes (JSON with sorted keys, no timestamps).
"""

import base64
import json
import math
import struct

# glTF enums used here.
_FLOAT, _UINT16, _UINT32 = 5126, 5123, 5125
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963
_TRIANGLES = 4

GENERATOR = "wavepath scenes/gltf_builder.py"


# --------------------------------------------------------------------------------------------
# Small vector helpers (tuples of floats).

def _sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def _add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def _scale(a, s):
    return tuple(x * s for x in a)


def _dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _normalize(a):
    n = math.sqrt(_dot(a, a))
    if n == 0.0:
        raise ValueError("cannot normalise a zero vector")
    return tuple(x / n for x in a)


def _f32(v):
    """The float32 nearest to v, as a Python float."""
    return struct.unpack("<f", struct.pack("<f", v))[0]


def _f32_json(v):
    """The shortest decimal that reads back as the same float32 as v.

    Used for accessor min/max: the spec says they describe the float32 data, and readers round
    them to float32; writing 0.5528 instead of 0.5527999997138977 keeps the JSON readable.
    """
    target = _f32(v)
    for digits in range(6, 10):  # 9 significant digits always round-trip a float32
        candidate = float("%.*g" % (digits, target))
        if _f32(candidate) == target:
            return _clean(candidate)
    return _clean(target)


def _clean(v):
    """Floats as they go into the JSON: no -0.0, integers that are floats stay floats."""
    return 0.0 if v == 0.0 else float(v)


# --------------------------------------------------------------------------------------------
# Shapes. Each returns (positions, normals, indices): lists of 3-tuples, 3-tuples and ints.

def quad(corners):
    """A planar (or nearly planar) quadrilateral from 4 corners, counter-clockwise seen from the
    front; two triangles (0,1,2) and (0,2,3), one flat normal for all 4 vertices (from the
    diagonals, so a slightly twisted quad still gets its average normal)."""
    if len(corners) != 4:
        raise ValueError("quad needs 4 corners")
    c = [tuple(float(x) for x in p) for p in corners]
    n = tuple(_clean(x) for x in _normalize(_cross(_sub(c[2], c[0]), _sub(c[3], c[1]))))
    return c, [n] * 4, [0, 1, 2, 0, 2, 3]


def merge(*parts):
    """Concatenates several (positions, normals, indices) shapes into one."""
    positions, normals, indices = [], [], []
    for p, n, i in parts:
        base = len(positions)
        positions.extend(p)
        normals.extend(n)
        indices.extend(base + k for k in i)
    return positions, normals, indices


def box(lo, hi):
    """An axis-aligned box, 6 faces of 4 vertices each, fronts facing out."""
    faces = []
    for axis in range(3):
        # (u, v, axis) is right-handed, so corners (0,0) (1,0) (1,1) (0,1) in (u, v) run
        # counter-clockwise seen from +axis.
        u, v = (axis + 1) % 3, (axis + 2) % 3
        for side, uv in ((hi, ((0, 0), (1, 0), (1, 1), (0, 1))),
                         (lo, ((0, 0), (0, 1), (1, 1), (1, 0)))):  # reversed: seen from -axis
            corners = []
            for a, b in uv:
                p = [0.0, 0.0, 0.0]
                p[axis] = side[axis]
                p[u] = (lo, hi)[a][u]
                p[v] = (lo, hi)[b][v]
                corners.append(tuple(p))
            faces.append(quad(corners))
    return merge(*faces)


def uv_sphere(center, radius, rings, segments):
    """A latitude/longitude sphere: rings+1 rows of segments+1 vertices (the seam column is
    duplicated so texture coordinates could be added), smooth outward normals, fronts out.
    The single-point rows at the poles give one triangle per quad there, not two."""
    if rings < 2 or segments < 3:
        raise ValueError("uv_sphere needs rings >= 2 and segments >= 3")
    positions, normals, indices = [], [], []
    for i in range(rings + 1):
        theta = math.pi * i / rings  # 0 at +Y (north pole)
        for j in range(segments + 1):
            phi = 2.0 * math.pi * j / segments
            # phi grows from +X toward -Z, i.e. counter-clockwise seen from +Y.
            n = (math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))
            n = tuple(_clean(x) for x in n)
            normals.append(n)
            positions.append(_add(tuple(center), _scale(n, radius)))
    row = segments + 1
    for i in range(rings):
        for j in range(segments):
            a, b = i * row + j, i * row + j + 1  # upper row (nearer +Y)
            c, d = a + row, b + row              # lower row
            # Seen from outside (+Y up), phi grows to the right, so a b / c d are laid out as
            # top-left, top-right / bottom-left, bottom-right and (a, c, b), (b, c, d) run
            # counter-clockwise. At a pole a row is one point: skip the triangle that collapses.
            if i != 0:
                indices += [a, c, b]
            if i != rings - 1:
                indices += [b, c, d]
    return positions, normals, indices


def look_at(eye, target, up=(0.0, 1.0, 0.0)):
    """The rotation quaternion (x, y, z, w) that turns a glTF camera (or spot light) at eye to
    look at target: the node's -Z goes to (target - eye), its +Y as close to up as possible."""
    z = _normalize(_sub(eye, target))  # the node's +Z points away from what it looks at
    x = _normalize(_cross(up, z))
    y = _cross(z, x)
    # Rotation matrix with columns x, y, z; m[r][c].
    m = ((x[0], y[0], z[0]), (x[1], y[1], z[1]), (x[2], y[2], z[2]))
    trace = m[0][0] + m[1][1] + m[2][2]
    # Standard matrix-to-quaternion conversion, branching on the largest diagonal term for
    # numerical robustness (e.g. the 180 degree turn of a camera looking down +Z).
    if trace > 0.0:
        s = 2.0 * math.sqrt(trace + 1.0)
        q = ((m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s)
    elif m[0][0] >= m[1][1] and m[0][0] >= m[2][2]:
        s = 2.0 * math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2])
        q = (0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s)
    elif m[1][1] >= m[2][2]:
        s = 2.0 * math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2])
        q = ((m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1])
        q = ((m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s, (m[1][0] - m[0][1]) / s)
    q = _normalize(q)
    if q[3] < 0.0:  # q and -q are the same rotation; pick w >= 0 so output is canonical
        q = _scale(q, -1.0)
    return tuple(_clean(round(c, 12)) for c in q)


# --------------------------------------------------------------------------------------------

class GltfBuilder:
    """Collects materials, meshes, cameras, lights and nodes; write() emits .gltf or .glb.

    Each add method returns the new object's index, which is what the others take."""

    look_at = staticmethod(look_at)  # also reachable as b.look_at(eye, target, up)

    def __init__(self):
        self._doc = {
            "asset": {"version": "2.0", "generator": GENERATOR},
            "materials": [], "meshes": [], "accessors": [], "bufferViews": [],
            "nodes": [], "cameras": [],
        }
        self._lights = []
        self._extensions = set()
        self._bin = bytearray()

    # ---- materials ---------------------------------------------------------------------------

    def material(self, name, base_color=(1.0, 1.0, 1.0), metallic=0.0, roughness=1.0,
                 emission=(0.0, 0.0, 0.0), emissive_strength=None, double_sided=False,
                 ior=None, transmission=None, specular=None, thickness=None,
                 attenuation=None, unlit=False):
        """A metallic-roughness material. emission is the emitted radiance's colour; when a
        component exceeds 1 it is normalised into emissiveFactor and its maximum moves into
        KHR_materials_emissive_strength. emissive_strength, if given, multiplies on top, so the
        radiance is always emission x (emissive_strength or 1).

        Extensions, each written only when its argument is given: ior (KHR_materials_ior),
        transmission (KHR_materials_transmission factor), specular (KHR_materials_specular
        specularFactor; 0 leaves a pure Lambertian dielectric), thickness and attenuation
        (KHR_materials_volume: thicknessFactor > 0 makes transmission refract; attenuation is
        (colour, distance)), unlit (KHR_materials_unlit)."""
        color = [float(c) for c in base_color]
        if len(color) == 3:
            color.append(1.0)
        m = {
            "name": name,
            "pbrMetallicRoughness": {
                "baseColorFactor": [_clean(c) for c in color],
                "metallicFactor": _clean(metallic),
                "roughnessFactor": _clean(roughness),
            },
        }
        ext = {}
        emission = [float(c) for c in emission]
        strength = 1.0 if emissive_strength is None else float(emissive_strength)
        peak = max(emission)
        if peak > 1.0:
            emission = [c / peak for c in emission]
            strength *= peak
        if peak > 0.0:
            m["emissiveFactor"] = [_clean(c) for c in emission]
        if emissive_strength is not None or peak > 1.0:
            ext["KHR_materials_emissive_strength"] = {"emissiveStrength": _clean(strength)}
        if ior is not None:
            ext["KHR_materials_ior"] = {"ior": _clean(ior)}
        if transmission is not None:
            ext["KHR_materials_transmission"] = {"transmissionFactor": _clean(transmission)}
        if specular is not None:
            ext["KHR_materials_specular"] = {"specularFactor": _clean(specular)}
        if thickness is not None or attenuation is not None:
            volume = {"thicknessFactor": _clean(1.0 if thickness is None else thickness)}
            if attenuation is not None:
                colour, distance = attenuation
                volume["attenuationColor"] = [_clean(c) for c in colour]
                volume["attenuationDistance"] = _clean(distance)
            ext["KHR_materials_volume"] = volume
        if unlit:
            ext["KHR_materials_unlit"] = {}
        if double_sided:
            m["doubleSided"] = True
        if ext:
            m["extensions"] = ext
            self._extensions.update(ext)
        return self._append("materials", m)

    # ---- geometry ----------------------------------------------------------------------------

    def mesh(self, name, positions, indices, material, normals=None, uvs=None):
        """A mesh with one indexed triangle primitive. Positions, normals (3 floats) and uvs
        (2 floats) go into the buffer as float32, indices as uint16 when every index fits
        (65535 itself is reserved), else uint32."""
        count = len(positions)
        if len(indices) % 3 != 0 or not indices:
            raise ValueError("%s: index count must be a positive multiple of 3" % name)
        if min(indices) < 0 or max(indices) >= count:
            raise ValueError("%s: index out of range" % name)
        attributes = {"POSITION": self._float_accessor(positions, 3, with_bounds=True)}
        for semantic, data, width in (("NORMAL", normals, 3), ("TEXCOORD_0", uvs, 2)):
            if data is not None:
                if len(data) != count:
                    raise ValueError("%s: %s count differs from POSITION's" % (name, semantic))
                attributes[semantic] = self._float_accessor(data, width)
        if count <= 65535:
            ctype, fmt = _UINT16, "H"
        else:
            ctype, fmt = _UINT32, "I"
        view = self._view(struct.pack("<%d%s" % (len(indices), fmt), *indices), _ELEMENT_ARRAY_BUFFER)
        idx = self._append("accessors", {"bufferView": view, "componentType": ctype,
                                         "count": len(indices), "type": "SCALAR"})
        prim = {"attributes": attributes, "indices": idx, "material": material, "mode": _TRIANGLES}
        return self._append("meshes", {"name": name, "primitives": [prim]})

    def _float_accessor(self, rows, width, with_bounds=False):
        flat = [float(c) for row in rows for c in row]
        if len(flat) != width * len(rows):
            raise ValueError("expected %d components per element" % width)
        view = self._view(struct.pack("<%df" % len(flat), *flat), _ARRAY_BUFFER)
        acc = {"bufferView": view, "componentType": _FLOAT, "count": len(rows),
               "type": "VEC%d" % width}
        if with_bounds:  # required for POSITION; computed on the float32 values actually stored
            cols = [[_f32(row[k]) for row in rows] for k in range(width)]
            acc["min"] = [_f32_json(min(c)) for c in cols]
            acc["max"] = [_f32_json(max(c)) for c in cols]
        return self._append("accessors", acc)

    def _view(self, data, target):
        # Every view starts on a 4-byte boundary: enough for float32 and uint32 (and uint16).
        self._bin.extend(b"\0" * (-len(self._bin) % 4))
        view = {"buffer": 0, "byteOffset": len(self._bin), "byteLength": len(data),
                "target": target}
        self._bin.extend(data)
        return self._append("bufferViews", view)

    # ---- cameras and lights ------------------------------------------------------------------

    def perspective_camera(self, yfov, znear, aspect=None, zfar=None, name=None):
        """yfov: vertical field of view in radians. No zfar: infinite projection."""
        p = {"yfov": _clean(yfov), "znear": _clean(znear)}
        if aspect is not None:
            p["aspectRatio"] = _clean(aspect)
        if zfar is not None:
            p["zfar"] = _clean(zfar)
        return self._camera({"type": "perspective", "perspective": p}, name)

    def orthographic_camera(self, xmag, ymag, znear, zfar=100.0, name=None):
        """xmag, ymag: half width and height of the view. zfar is required by glTF here."""
        o = {"xmag": _clean(xmag), "ymag": _clean(ymag), "znear": _clean(znear),
             "zfar": _clean(zfar)}
        return self._camera({"type": "orthographic", "orthographic": o}, name)

    def _camera(self, cam, name):
        if name is not None:
            cam["name"] = name
        return self._append("cameras", cam)

    def point_light(self, color, intensity, name=None):
        """KHR_lights_punctual point light; intensity in candela (wavepath: W/sr)."""
        return self._light({"type": "point"}, color, intensity, name)

    def spot_light(self, color, intensity, inner, outer, name=None):
        """Spot light shining down its node's -Z; cone half-angles in radians,
        0 <= inner < outer <= pi/2 as glTF requires."""
        if not 0.0 <= inner < outer <= math.pi / 2:
            raise ValueError("spot cone angles need 0 <= inner < outer <= pi/2")
        spot = {"innerConeAngle": _clean(inner), "outerConeAngle": _clean(outer)}
        return self._light({"type": "spot", "spot": spot}, color, intensity, name)

    def directional_light(self, color, intensity, name=None):
        """Directional light shining down its node's -Z; intensity in lux (wavepath: W/m^2)."""
        return self._light({"type": "directional"}, color, intensity, name)

    def _light(self, light, color, intensity, name):
        light["color"] = [_clean(c) for c in color]
        light["intensity"] = _clean(intensity)
        if name is not None:
            light["name"] = name
        self._extensions.add("KHR_lights_punctual")
        self._lights.append(light)
        return len(self._lights) - 1

    # ---- nodes -------------------------------------------------------------------------------

    def node(self, name, mesh=None, camera=None, light=None, translation=None, rotation=None,
             scale=None, matrix=None, children=()):
        """A node; rotation is a unit quaternion (x, y, z, w), matrix 16 floats column-major
        (not together with translation/rotation/scale)."""
        if matrix is not None and (translation or rotation or scale):
            raise ValueError("a node has either matrix or translation/rotation/scale")
        n = {"name": name}
        for key, value in (("mesh", mesh), ("camera", camera)):
            if value is not None:
                n[key] = value
        if light is not None:
            n["extensions"] = {"KHR_lights_punctual": {"light": light}}
        for key, value in (("translation", translation), ("rotation", rotation),
                           ("scale", scale), ("matrix", matrix)):
            if value is not None:
                n[key] = [_clean(c) for c in value]
        if children:
            n["children"] = list(children)
        return self._append("nodes", n)

    # ---- output ------------------------------------------------------------------------------

    def _append(self, key, obj):
        self._doc[key].append(obj)
        return len(self._doc[key]) - 1

    def document(self, uri=None):
        """The glTF JSON as a dict. uri: the buffer's URI (None for GLB's binary chunk)."""
        doc = {k: v for k, v in self._doc.items() if v}  # glTF forbids empty top-level arrays
        doc["asset"] = self._doc["asset"]
        children = {c for n in self._doc["nodes"] for c in n.get("children", ())}
        roots = [i for i in range(len(self._doc["nodes"])) if i not in children]
        doc["scenes"] = [{"nodes": roots} if roots else {}]  # glTF forbids an empty nodes array
        doc["scene"] = 0
        if self._bin:
            buf = {"byteLength": len(self._padded_bin())}
            if uri is not None:
                buf["uri"] = uri
            doc["buffers"] = [buf]
        if self._lights:
            doc["extensions"] = {"KHR_lights_punctual": {"lights": self._lights}}
        if self._extensions:
            doc["extensionsUsed"] = sorted(self._extensions)
        return doc

    def _padded_bin(self):
        return bytes(self._bin) + b"\0" * (-len(self._bin) % 4)

    def to_bytes(self, binary):
        """The file's bytes: GLB when binary, else .gltf JSON with an embedded base64 buffer."""
        if not binary:
            uri = "data:application/octet-stream;base64," + base64.b64encode(self._padded_bin()).decode("ascii")
            text = json.dumps(self.document(uri if self._bin else None), indent=2, sort_keys=True)
            return (text + "\n").encode("utf-8")
        # GLB: 12-byte header, a JSON chunk padded with spaces, a BIN chunk padded with zeros.
        js = json.dumps(self.document(), sort_keys=True, separators=(",", ":")).encode("utf-8")
        js += b" " * (-len(js) % 4)
        chunks = struct.pack("<II", len(js), 0x4E4F534A) + js  # "JSON"
        if self._bin:
            data = self._padded_bin()
            chunks += struct.pack("<II", len(data), 0x004E4942) + data  # "BIN\0"
        return struct.pack("<III", 0x46546C67, 2, 12 + len(chunks)) + chunks  # "glTF", version 2

    def write(self, path):
        """Writes path as .glb if it ends in .glb (any case), else as embedded .gltf."""
        data = self.to_bytes(str(path).lower().endswith(".glb"))
        with open(path, "wb") as f:
            f.write(data)
        return path
