"""The scene converter of tools/peers.py: reads a glTF 2.0 scene (.gltf with embedded or external
buffers, or .glb) into a renderer-neutral description that Mitsuba 3 and Cycles are built from.
Standard library only, so that tests/test_peers_scene.py runs without PyPI.

    from wavepath_tools import peers_scene
    scene = peers_scene.load("scenes/cornell_box.gltf")
    scene["meshes"]        # [{"name", "material", "positions": [(x, y, z)...] in world space,
                           #   "triangles": [(i, j, k)...]}], one per triangle primitive
    scene["materials"]     # [{"name", "reflectance": (r, g, b), "emission": (r, g, b) W/(m^2 sr),
                           #   "double_sided": bool, "specular": KHR_materials_specular factor}]
    scene["point_lights"]  # [{"name", "position": (x, y, z), "intensity": (r, g, b) W/sr}]
    scene["camera"]        # {"position", "forward", "up" (unit vectors), "yfov" (radians),
                           #  "aspect" (width / height, None when the glTF leaves it open)}
    peers_scene.coincident_emitters(scene)  # [(emitter, other mesh, area)]: coplanar overlaps
    peers_scene.write_ply(path, mesh)   # binary little-endian PLY of one mesh
    peers_scene.lambertian_copy(path, out)  # the .gltf with specularFactor 0 on every material
    peers_scene.bounds(path)            # (lo, hi): world-space bounds of the triangle vertices
    peers_scene.framing_camera(lo, hi, aspect)  # wavepath's camera for a file without one
    peers_scene.camera(path)            # the first camera, as scene["camera"]; None without one
    peers_scene.with_camera(path, out, cam)  # a copy (.gltf or .glb) with cam as its camera
    peers_scene.copy_gltf(path, out, [peers_scene.add_camera(cam), peers_scene.nearest_textures])
                                        # (edits: add_camera, nearest_textures, no_normal_maps)

Only what the peers can represent exactly is accepted: triangle primitives, Lambertian materials
(metallic 0, roughness 1, base colour factor and emission without textures, opaque), point lights,
one perspective camera. A glTF dielectric (metallic 0) is Lambertian only with
KHR_materials_specular specularFactor 0: without it, glTF (and wavepath) put a rough specular layer
with Fresnel reflectance 0.04 (rising to 1 at grazing angles) over the diffuse one. Each material's
"specular" is that factor (1 when absent); lambertian_copy() writes a copy of a .gltf with 0 on
every material, the scene the peers can match. Anything else (textures, metals, transmission, spot
lights, ...) is a ConversionError naming it, never a silent approximation; so is an emitter that
coincides with another surface (coplanar and overlapping: coincident_emitters()), a scene that
does not define its image. Units and conventions are wavepath's (scenes/README.md): metres, +Y up,
linear RGB, emission = emissiveFactor x emissiveStrength as radiance, point light intensity x
colour read as W/sr; a triangle's front is the side from which its vertices run counter-clockwise,
and a material that is not double-sided is invisible from the back (wavepath culls back faces: rays
pass through them).

bounds(), framing_camera(), camera(), with_camera() and copy_gltf() work on any glTF (textures
and all): they serve the --pbr mode of tools/peers.py, where Cycles imports the file itself and
both renderers must see it through the same camera (and, for the diagnostics --nearest-textures
and --no-normal-maps, a copy with its textures sampled alike or without its normal maps).
"""

import base64
import json
import mimetypes
import math
import os
import struct


class ConversionError(ValueError):
    pass


# ---- Reading glTF --------------------------------------------------------------------------------

_COMPONENT = {5120: "b", 5121: "B", 5122: "h", 5123: "H", 5125: "I", 5126: "f"}
_COUNT = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


def _read_document(path):
    """(glTF JSON dict, list of buffer bytes)."""
    with open(path, "rb") as f:
        data = f.read()
    base = os.path.dirname(os.path.abspath(path))
    bin_chunk = None
    if data[:4] == b"glTF":
        _, _, length = struct.unpack_from("<4sII", data, 0)
        offset, doc = 12, None
        while offset + 8 <= length:
            chunk_len, chunk_type = struct.unpack_from("<II", data, offset)
            chunk = data[offset + 8:offset + 8 + chunk_len]
            if chunk_type == 0x4E4F534A:
                doc = json.loads(chunk.decode("utf-8"))
            elif chunk_type == 0x004E4942:
                bin_chunk = chunk
            offset += 8 + chunk_len
        if doc is None:
            raise ConversionError("%s: GLB without a JSON chunk" % path)
    else:
        doc = json.loads(data.decode("utf-8"))
    buffers = []
    for i, b in enumerate(doc.get("buffers", [])):
        uri = b.get("uri")
        if uri is None:
            if bin_chunk is None:
                raise ConversionError("%s: buffer %d has no uri and no GLB chunk" % (path, i))
            buffers.append(bin_chunk)
        elif uri.startswith("data:"):
            buffers.append(base64.b64decode(uri.split(",", 1)[1]))
        else:
            from urllib.parse import unquote
            with open(os.path.join(base, unquote(uri)), "rb") as f:
                buffers.append(f.read())
    return doc, buffers


def _accessor(doc, buffers, index):
    """The elements of accessor `index` as a list of tuples (or of numbers for SCALAR)."""
    acc = doc["accessors"][index]
    if "sparse" in acc:
        raise ConversionError("accessor %d: sparse accessors are not supported" % index)
    fmt = _COMPONENT[acc["componentType"]]
    n = _COUNT[acc["type"]]
    count = acc["count"]
    if "bufferView" not in acc:
        return [0 if n == 1 else (0,) * n] * count
    view = doc["bufferViews"][acc["bufferView"]]
    data = buffers[view["buffer"]]
    start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    size = struct.calcsize("<" + fmt * n)
    stride = view.get("byteStride", size)
    out = []
    for k in range(count):
        v = struct.unpack_from("<" + fmt * n, data, start + k * stride)
        out.append(v[0] if n == 1 else v)
    return out


# ---- Transforms (4 x 4 row-major lists) ----------------------------------------------------------

def _matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def node_matrix(node):
    """A node's local transform: its `matrix` (column-major in glTF) or T * R * S."""
    if "matrix" in node:
        m = node["matrix"]
        return [[m[c * 4 + r] for c in range(4)] for r in range(4)]
    tx, ty, tz = node.get("translation", (0.0, 0.0, 0.0))
    x, y, z, w = node.get("rotation", (0.0, 0.0, 0.0, 1.0))
    sx, sy, sz = node.get("scale", (1.0, 1.0, 1.0))
    r = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
         [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
         [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    return [[r[0][0] * sx, r[0][1] * sy, r[0][2] * sz, tx],
            [r[1][0] * sx, r[1][1] * sy, r[1][2] * sz, ty],
            [r[2][0] * sx, r[2][1] * sy, r[2][2] * sz, tz],
            [0.0, 0.0, 0.0, 1.0]]


def _point(m, p):
    return tuple(m[i][0] * p[0] + m[i][1] * p[1] + m[i][2] * p[2] + m[i][3] for i in range(3))


def _vector(m, v):
    return tuple(m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2] for i in range(3))


def _det3(m):
    return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))


def _normalize(v):
    n = math.sqrt(sum(c * c for c in v))
    if n == 0.0:
        raise ConversionError("degenerate camera transform")
    return tuple(c / n for c in v)


# ---- Materials -----------------------------------------------------------------------------------

def _material(doc, index):
    if index is None:  # glTF's default material: white 1.0, metallic 1, roughness 1
        raise ConversionError("a primitive without a material (glTF's default is metallic)")
    m = doc["materials"][index]
    name = m.get("name", "material%d" % index)
    pbr = m.get("pbrMetallicRoughness", {})
    bad = [k for k in ("baseColorTexture", "metallicRoughnessTexture") if k in pbr]
    bad += [k for k in ("normalTexture", "occlusionTexture", "emissiveTexture") if k in m]
    ext = m.get("extensions", {})
    bad += [k for k in ext if k not in ("KHR_materials_emissive_strength",
                                         "KHR_materials_specular")]
    spec = ext.get("KHR_materials_specular", {})
    bad += [k for k in ("specularTexture", "specularColorTexture") if k in spec]
    specular = float(spec.get("specularFactor", 1.0))
    if pbr.get("metallicFactor", 1.0) != 0.0 or pbr.get("roughnessFactor", 1.0) != 1.0:
        bad.append("metallic %s / roughness %s (needs 0 / 1)"
                   % (pbr.get("metallicFactor", 1.0), pbr.get("roughnessFactor", 1.0)))
    if m.get("alphaMode", "OPAQUE") != "OPAQUE":
        bad.append("alphaMode " + m["alphaMode"])
    if bad:
        raise ConversionError("material %r is not Lambertian: %s" % (name, ", ".join(bad)))
    color = tuple(float(c) for c in pbr.get("baseColorFactor", (1.0, 1.0, 1.0, 1.0))[:3])
    strength = m.get("extensions", {}).get("KHR_materials_emissive_strength", {}).get(
        "emissiveStrength", 1.0)
    emission = tuple(float(c) * strength for c in m.get("emissiveFactor", (0.0, 0.0, 0.0)))
    return {"name": name, "reflectance": color, "emission": emission,
            "double_sided": bool(m.get("doubleSided", False)), "specular": specular}


def lambertian_copy(path, out):
    """Writes `path` (.gltf) to `out` with KHR_materials_specular specularFactor 0 on every
    material, everything else unchanged (buffers stay embedded or next to `path`: `out` should be
    in the same folder, or the buffers embedded)."""
    with open(path) as f:
        doc = json.load(f)
    base = os.path.dirname(os.path.abspath(path))
    for b in doc.get("buffers", []):
        uri = b.get("uri", "")
        if uri and not uri.startswith("data:"):
            with open(os.path.join(base, uri), "rb") as f:
                b["uri"] = ("data:application/octet-stream;base64,"
                            + base64.b64encode(f.read()).decode("ascii"))
    for m in doc.get("materials", []):
        m.setdefault("extensions", {})["KHR_materials_specular"] = {"specularFactor": 0.0}
    used = doc.setdefault("extensionsUsed", [])
    if "KHR_materials_specular" not in used:
        used.append("KHR_materials_specular")
    with open(out, "w") as f:
        json.dump(doc, f)


# ---- The scene -----------------------------------------------------------------------------------

def load(path):
    """The description of the module docstring; ConversionError for what it cannot convert."""
    doc, buffers = _read_document(path)
    materials = [_material(doc, i) for i in range(len(doc.get("materials", [])))]
    lights = doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    scene = {"meshes": [], "materials": materials, "point_lights": [], "camera": None}
    cameras = []

    def visit(index, parent):
        node = doc["nodes"][index]
        world = _matmul(parent, node_matrix(node))
        if "mesh" in node:
            mesh = doc["meshes"][node["mesh"]]
            flip = _det3(world) < 0.0  # a mirroring transform reverses the winding
            for p, prim in enumerate(mesh["primitives"]):
                if prim.get("mode", 4) != 4:
                    raise ConversionError("mesh %r: primitive mode %d is not triangles"
                                          % (mesh.get("name"), prim.get("mode")))
                if "material" not in prim:
                    _material(doc, None)
                positions = [_point(world, v) for v in _accessor(doc, buffers,
                                                                 prim["attributes"]["POSITION"])]
                if "indices" in prim:
                    idx = _accessor(doc, buffers, prim["indices"])
                else:
                    idx = list(range(len(positions)))
                tris = [tuple(idx[k:k + 3]) for k in range(0, len(idx) - 2, 3)]
                if flip:
                    tris = [(a, c, b) for a, b, c in tris]
                name = mesh.get("name", "mesh%d" % node["mesh"])
                scene["meshes"].append({"name": name if len(mesh["primitives"]) == 1
                                        else "%s_%d" % (name, p),
                                        "material": prim["material"], "positions": positions,
                                        "triangles": tris})
        light = node.get("extensions", {}).get("KHR_lights_punctual")
        if light is not None:
            l = lights[light["light"]]
            if l.get("type") != "point":
                raise ConversionError("light %r: type %r (only point lights convert)"
                                      % (l.get("name"), l.get("type")))
            if "range" in l:
                raise ConversionError("light %r: a range is not supported" % l.get("name"))
            i = float(l.get("intensity", 1.0))
            scene["point_lights"].append({
                "name": l.get("name", "light%d" % light["light"]),
                "position": _point(world, (0, 0, 0)),
                "intensity": tuple(float(c) * i for c in l.get("color", (1.0, 1.0, 1.0)))})
        if "camera" in node:
            cameras.append((doc["cameras"][node["camera"]], world))
        for child in node.get("children", []):
            visit(child, world)

    identity = [[float(i == j) for j in range(4)] for i in range(4)]
    for root in doc["scenes"][doc.get("scene", 0)]["nodes"]:
        visit(root, identity)
    if not cameras:
        raise ConversionError("%s: no camera" % path)
    cam, world = cameras[0]  # wavepath renders with the first camera too
    if cam.get("type") != "perspective":
        raise ConversionError("camera type %r: only perspective converts" % cam.get("type"))
    scene["camera"] = {
        "position": _point(world, (0, 0, 0)),
        "forward": _normalize(_vector(world, (0, 0, -1))),  # glTF cameras look down -Z
        "up": _normalize(_vector(world, (0, 1, 0))),
        "yfov": float(cam["perspective"]["yfov"]),
        "aspect": cam["perspective"].get("aspectRatio"),
    }
    found = coincident_emitters(scene)
    if found:
        raise ConversionError(
            "%s: emitters coincide with other surfaces (coplanar and overlapping) in %d pair(s) "
            "of meshes, e.g. %s: the renderers resolve coincident surfaces differently (and "
            "wavepath's own light and BSDF sampling disagree there), so the scene does not define "
            "its image; move them apart" % (path, len(found), "; ".join(
                "%r and %r (overlap %.3g m^2)" % f for f in found[:3])))
    return scene


# ---- Coincident emitters -------------------------------------------------------------------------

COINCIDENT_TOLERANCE = 1e-5  # of the scene's bounding-box diagonal


def _clip_convex(poly, a, b):
    """The part of 2D polygon `poly` on the left of the directed line a -> b."""
    def side(p):
        return (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
    out = []
    for k, p in enumerate(poly):
        q = poly[(k + 1) % len(poly)]
        sp, sq = side(p), side(q)
        if sp >= 0.0:
            out.append(p)
        if (sp >= 0.0) != (sq >= 0.0):
            t = sp / (sp - sq)
            out.append((p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])))
    return out


def _area2(poly):
    """Signed area of a 2D polygon (counter-clockwise positive)."""
    return 0.5 * sum(poly[k][0] * poly[(k + 1) % len(poly)][1]
                     - poly[(k + 1) % len(poly)][0] * poly[k][1] for k in range(len(poly)))


def coincident_emitters(scene, tolerance=COINCIDENT_TOLERANCE):
    """[(emitter mesh name, other mesh name, overlap area m^2 of the first overlapping pair of
    triangles found)], one per pair of meshes (load() refuses a scene with any), where a
    triangle of an emissive material and another triangle (of any material, either facing) lie in
    one plane (every vertex of the other within `tolerance` x the bounding-box diagonal of the
    emitter's plane) and overlap with positive area (more than 1e-6 of the smaller triangle's; a
    shared edge is no overlap). Such a scene does not define its image: which of two coincident
    surfaces a ray hits is up to each renderer's intersection code, and the light sampled on the
    hidden part of an emitter is found by light sampling but not by BSDF sampling."""
    tris = []  # (mesh index, (a, b, c), emissive)
    lo, hi = [math.inf] * 3, [-math.inf] * 3
    for mi, mesh in enumerate(scene["meshes"]):
        emissive = max(scene["materials"][mesh["material"]]["emission"]) > 0.0
        for t in mesh["triangles"]:
            v = tuple(tuple(mesh["positions"][k]) for k in t)
            tris.append((mi, v, emissive))
            for p in v:
                lo = [min(lo[i], p[i]) for i in range(3)]
                hi = [max(hi[i], p[i]) for i in range(3)]
    if not any(e for _, _, e in tris):
        return []
    tol = tolerance * math.sqrt(sum((hi[i] - lo[i]) ** 2 for i in range(3)))
    # A uniform grid of the emitter triangles' bounding boxes (cells of the largest emitter's
    # extent, at least 1/64 of the scene's), queried with every triangle's.
    emitters = [k for k, (_, _, e) in enumerate(tris) if e]
    size = max(max(max(p[i] for p in tris[k][1]) - min(p[i] for p in tris[k][1])
                   for i in range(3)) for k in emitters)
    cell = max(size, max(hi[i] - lo[i] for i in range(3)) / 64.0, tol, 1e-30)

    def cells(v):
        a = [int(math.floor((min(p[i] for p in v) - tol - lo[i]) / cell)) for i in range(3)]
        b = [int(math.floor((max(p[i] for p in v) + tol - lo[i]) / cell)) for i in range(3)]
        return [(x, y, z) for x in range(a[0], b[0] + 1) for y in range(a[1], b[1] + 1)
                for z in range(a[2], b[2] + 1)]

    grid = {}
    for k in emitters:
        for c in cells(tris[k][1]):
            grid.setdefault(c, []).append(k)
    found, tested = {}, set()
    for j, (mj, vj, ej) in enumerate(tris):
        candidates = set()
        for c in cells(vj):
            candidates.update(grid.get(c, ()))
        for k in candidates:
            if k == j:
                continue
            if ej:  # both emissive: test the pair once
                if (min(j, k), max(j, k)) in tested:
                    continue
                tested.add((min(j, k), max(j, k)))
            mk, vk, _ = tris[k]
            key = (min(mk, mj), max(mk, mj)) if ej else (mk, mj)
            if key in found:
                continue
            area = _coplanar_overlap(vk, vj, tol)
            if area > 0.0:
                found[key] = area
    names = [m["name"] for m in scene["meshes"]]
    return [(names[a], names[b], area) for (a, b), area in found.items()]


def _coplanar_overlap(e, t, tol):
    """Overlap area of triangle t with triangle e when t lies in e's plane (within tol), else 0."""
    area_e, n = triangle_area(*e)
    area_t, _ = triangle_area(*t)
    if area_e == 0.0 or area_t == 0.0:
        return 0.0
    n = [c / (2.0 * area_e) for c in n]
    if any(abs(sum(n[i] * (p[i] - e[0][i]) for i in range(3))) > tol for p in t):
        return 0.0
    drop = max(range(3), key=lambda i: abs(n[i]))  # project onto the other two axes
    u, v = [i for i in range(3) if i != drop]
    pe = [(p[u], p[v]) for p in e]
    pt = [(p[u], p[v]) for p in t]
    if _area2(pe) < 0.0:
        pe.reverse()
    poly = pt
    for k in range(3):
        poly = _clip_convex(poly, pe[k], pe[(k + 1) % 3])
        if len(poly) < 3:
            return 0.0
    scale = 1.0 / abs(n[drop])  # projected area back to the plane's
    overlap = abs(_area2(poly)) * scale
    return overlap if overlap > 1e-6 * min(area_e, area_t) else 0.0


# ---- Geometry and cameras of any glTF (the --pbr mode) -------------------------------------------

def _walk(doc, visit_node):
    """Calls visit_node(node, world matrix) for every node of the default scene, depth first,
    children after their parent, roots in the scene's order."""
    identity = [[float(i == j) for j in range(4)] for i in range(4)]

    def visit(index, parent):
        node = doc["nodes"][index]
        world = _matmul(parent, node_matrix(node))
        visit_node(node, world)
        for child in node.get("children", []):
            visit(child, world)

    for root in doc["scenes"][doc.get("scene", 0)]["nodes"]:
        visit(root, identity)


def bounds(path):
    """(lo, hi): the world-space bounds of the vertices that triangle primitives use, as
    wavepath's loader computes them (its framing camera is made from them)."""
    doc, buffers = _read_document(path)
    lo, hi = [math.inf] * 3, [-math.inf] * 3

    def visit_node(node, world):
        if "mesh" not in node:
            return
        for prim in doc["meshes"][node["mesh"]]["primitives"]:
            if prim.get("mode", 4) != 4:
                continue  # wavepath skips non-triangle primitives
            positions = _accessor(doc, buffers, prim["attributes"]["POSITION"])
            used = (sorted(set(_accessor(doc, buffers, prim["indices"])))
                    if "indices" in prim else range(len(positions)))
            for k in used:
                p = _point(world, positions[k])
                for i in range(3):
                    lo[i] = min(lo[i], p[i])
                    hi[i] = max(hi[i], p[i])

    _walk(doc, visit_node)
    if lo[0] == math.inf:
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    return tuple(lo), tuple(hi)


def framing_camera(lo, hi, aspect):
    """wavepath's camera for a file without one (host/scene/gltf_loader.cpp, framing_camera): 45 degree
    vertical field of view, looking at the centre of the bounds along -Z from the +Z side, 15
    degrees from above, at the distance where the bounding sphere fits the view at `aspect`
    (width / height). As scene["camera"] of load(), with "aspect": aspect."""
    center = [0.5 * (lo[i] + hi[i]) for i in range(3)]
    radius = 0.5 * math.sqrt(sum((hi[i] - lo[i]) ** 2 for i in range(3)))
    if not radius > 0.0 or not math.isfinite(radius):
        radius = 1.0
    yfov = math.radians(45.0)
    half = min(0.5 * yfov, math.atan(math.tan(0.5 * yfov) * aspect))
    distance = radius / math.sin(half)
    e = math.radians(15.0)
    back = (0.0, math.sin(e), math.cos(e))
    return {"position": tuple(center[i] + distance * back[i] for i in range(3)),
            "forward": tuple(-c for c in back), "up": (0.0, math.cos(e), -math.sin(e)),
            "yfov": yfov, "aspect": aspect}


def orbit_camera(lo, hi, theta, phi, distance, aspect, yfov=math.radians(45.0)):
    """wavepath's --orbit THETA,PHI,DISTANCE camera (host/scene/view.cpp, placed_camera): on the
    sphere about the centre of the bounds, at polar angle phi from +Y and azimuth theta from +Z
    towards +X (degrees), looking at the centre, image up towards +Y on that sphere; distance 0
    fits the bounding sphere (radius half the diagonal) as framing_camera does. As
    scene["camera"] of load(), with "aspect": aspect."""
    center = [0.5 * (lo[i] + hi[i]) for i in range(3)]
    if distance <= 0.0:
        radius = 0.5 * math.sqrt(sum((hi[i] - lo[i]) ** 2 for i in range(3)))
        if not radius > 0.0 or not math.isfinite(radius):
            radius = 1.0
        half = min(0.5 * yfov, math.atan(math.tan(0.5 * yfov) * aspect))
        distance = radius / math.sin(half)
    t, p = math.radians(theta), math.radians(phi)
    out = (math.sin(p) * math.sin(t), math.cos(p), math.sin(p) * math.cos(t))
    up = _normalize((-math.cos(p) * math.sin(t), math.sin(p), -math.cos(p) * math.cos(t)))
    return {"position": tuple(center[i] + distance * out[i] for i in range(3)),
            "forward": tuple(-c for c in out), "up": up, "yfov": yfov, "aspect": aspect}


def camera(path):
    """The camera wavepath renders a file with by default (its first), as scene["camera"] of
    load(); None when the file has none. ConversionError for a camera that is not perspective."""
    doc, _ = _read_document(path)
    cameras = []
    _walk(doc, lambda node, world: cameras.append((doc["cameras"][node["camera"]], world))
          if "camera" in node else None)
    if not cameras:
        return None
    cam, world = cameras[0]
    if cam.get("type") != "perspective":
        raise ConversionError("camera type %r: only perspective converts" % cam.get("type"))
    return {"position": _point(world, (0, 0, 0)),
            "forward": _normalize(_vector(world, (0, 0, -1))),
            "up": _normalize(_vector(world, (0, 1, 0))),
            "yfov": float(cam["perspective"]["yfov"]),
            "aspect": cam["perspective"].get("aspectRatio")}


def _rotation_quaternion(right, up, back):
    """(x, y, z, w) of the rotation whose matrix has columns right, up, back (orthonormal)."""
    m = [[right[i], up[i], back[i]] for i in range(3)]
    t = m[0][0] + m[1][1] + m[2][2]
    if t > 0.0:
        s = 2.0 * math.sqrt(1.0 + t)
        return ((m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, s / 4)
    i = max(range(3), key=lambda k: m[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2.0 * math.sqrt(1.0 + m[i][i] - m[j][j] - m[k][k])
    q = [0.0] * 4
    q[i] = s / 4
    q[j] = (m[j][i] + m[i][j]) / s
    q[k] = (m[k][i] + m[i][k]) / s
    q[3] = (m[k][j] - m[j][k]) / s
    return tuple(q)


def copy_gltf(path, out, edits):
    """Writes a copy of `path` (.gltf or .glb; `out` the same kind) with each function of `edits`
    applied to its JSON document in turn. Buffers and images the file keeps outside are embedded
    as data URIs, so `out` can be anywhere; a .glb keeps its binary chunk."""
    doc, buffers = _read_document(path)
    base = os.path.dirname(os.path.abspath(path))
    glb = path.lower().endswith(".glb")
    if glb != out.lower().endswith(".glb"):
        raise ValueError("copy_gltf: %s and %s must both be .glb or both .gltf" % (path, out))
    for i, b in enumerate(doc.get("buffers", [])):
        if b.get("uri") is not None and not b["uri"].startswith("data:"):
            b["uri"] = ("data:application/octet-stream;base64,"
                        + base64.b64encode(buffers[i]).decode("ascii"))
    for im in doc.get("images", []):
        uri = im.get("uri")
        if uri is not None and not uri.startswith("data:"):
            from urllib.parse import unquote
            with open(os.path.join(base, unquote(uri)), "rb") as f:
                data = f.read()
            mime = im.get("mimeType") or mimetypes.guess_type(uri)[0] or "image/png"
            im["uri"] = "data:%s;base64,%s" % (mime, base64.b64encode(data).decode("ascii"))
    for edit in edits:
        edit(doc)
    if not glb:
        with open(out, "w") as fh:
            json.dump(doc, fh)
        return
    bin_chunk = None
    for i, b in enumerate(doc.get("buffers", [])):
        if b.get("uri") is None:
            bin_chunk = buffers[i]
    js = json.dumps(doc, separators=(",", ":")).encode("utf-8")
    js += b" " * (-len(js) % 4)
    chunks = struct.pack("<II", len(js), 0x4E4F534A) + js
    if bin_chunk is not None:
        bin_chunk = bin_chunk + b"\0" * (-len(bin_chunk) % 4)
        chunks += struct.pack("<II", len(bin_chunk), 0x004E4942) + bin_chunk
    with open(out, "wb") as fh:
        fh.write(struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks)


def add_camera(cam, replace=False):
    """An edit for copy_gltf: `cam` (a dict like scene["camera"]; znear 0.001) as the document's
    one camera, on a new root node; ValueError for a document with cameras, unless `replace`,
    which takes the file's own cameras off their nodes first."""
    def edit(doc):
        if doc.get("cameras") and replace:
            for node in doc.get("nodes", []):
                node.pop("camera", None)
            doc.pop("cameras")
        if doc.get("cameras"):
            raise ValueError("add_camera: the file has cameras already")
        f, u = _normalize(cam["forward"]), _normalize(cam["up"])
        right = _normalize((f[1] * u[2] - f[2] * u[1], f[2] * u[0] - f[0] * u[2],
                            f[0] * u[1] - f[1] * u[0]))
        up = (right[1] * f[2] - right[2] * f[1], right[2] * f[0] - right[0] * f[2],
              right[0] * f[1] - right[1] * f[0])
        persp = {"yfov": cam["yfov"], "znear": 0.001}
        if cam.get("aspect"):
            persp["aspectRatio"] = cam["aspect"]
        doc["cameras"] = [{"type": "perspective", "perspective": persp}]
        doc["nodes"].append({"name": "peers_camera", "camera": 0,
                             "translation": list(cam["position"]),
                             "rotation": list(_rotation_quaternion(right, up,
                                                                   tuple(-c for c in f)))})
        doc["scenes"][doc.get("scene", 0)]["nodes"].append(len(doc["nodes"]) - 1)
    return edit


NEAREST = 9728  # glTF's (OpenGL's) NEAREST filter


def nearest_textures(doc):
    """An edit for copy_gltf: every texture samples its nearest texel (magFilter and minFilter
    NEAREST; a texture without a sampler gets one with glTF's default wrapping, REPEAT)."""
    samplers = doc.setdefault("samplers", [])
    for s in samplers:
        s["magFilter"] = s["minFilter"] = NEAREST
    for t in doc.get("textures", []):
        if "sampler" not in t:
            samplers.append({"magFilter": NEAREST, "minFilter": NEAREST})
            t["sampler"] = len(samplers) - 1


def no_normal_maps(doc):
    """An edit for copy_gltf: no material has a normal texture."""
    for m in doc.get("materials", []):
        m.pop("normalTexture", None)


def with_camera(path, out, cam):
    """copy_gltf(path, out, [add_camera(cam)])."""
    copy_gltf(path, out, [add_camera(cam)])


# ---- Summaries (for the test and the report) -----------------------------------------------------

def triangle_area(a, b, c):
    u = [b[i] - a[i] for i in range(3)]
    v = [c[i] - a[i] for i in range(3)]
    n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    return 0.5 * math.sqrt(sum(x * x for x in n)), n


def summary(scene):
    """{"triangles", "bbox_min", "bbox_max", "emitters": [{"name", "area", "radiance",
    "normal"}]} (normal: the unit normal of an emitter's first triangle, its emitting side)."""
    lo, hi = [math.inf] * 3, [-math.inf] * 3
    tris, emitters = 0, []
    for mesh in scene["meshes"]:
        for p in mesh["positions"]:
            lo = [min(lo[i], p[i]) for i in range(3)]
            hi = [max(hi[i], p[i]) for i in range(3)]
        tris += len(mesh["triangles"])
        mat = scene["materials"][mesh["material"]]
        if max(mat["emission"]) > 0.0:
            area, normal = 0.0, None
            for t in mesh["triangles"]:
                a, n = triangle_area(*(mesh["positions"][k] for k in t))
                area += a
                normal = normal or _normalize(n)
            emitters.append({"name": mesh["name"], "area": area, "radiance": mat["emission"],
                             "normal": normal})
    return {"triangles": tris, "bbox_min": tuple(lo), "bbox_max": tuple(hi), "emitters": emitters}


def write_ply(path, mesh):
    """One mesh as a binary little-endian PLY (float vertices, uint32 triangle lists)."""
    head = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\n"
            "property float y\nproperty float z\nelement face %d\n"
            "property list uchar uint vertex_indices\nend_header\n"
            % (len(mesh["positions"]), len(mesh["triangles"])))
    with open(path, "wb") as f:
        f.write(head.encode("ascii"))
        for p in mesh["positions"]:
            f.write(struct.pack("<3f", *p))
        for t in mesh["triangles"]:
            f.write(struct.pack("<B3I", 3, *t))
