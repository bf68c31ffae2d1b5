#!/usr/bin/env python3
"""Writes the failure-mode scenes of scenes/failure/: one small glTF scene per way in which a
light-transport strategy breaks, the synthetic environment map one of them needs, and
manifest.json, which tools/convergence.py and tests/test_accuracy.py read.

    python3 scenes/make_failure_scenes.py [OUT_DIR]    (default: scenes/failure/)

Each scene is meant to be rendered at 128 x 96 (4:3) in seconds. scenes/README.md says, per scene,
which method it breaks and why; the manifest carries the same note ("breaks"), the extra command
line arguments a render needs ("args", paths relative to the manifest), how its reference is
obtained ("reference": a closed form, a high-sample MIS render, or another scene's reference) and
a crop for the equal-time comparison ("crop": x, y, w, h in the 128 x 96 frame) and, where the
default does not suit, the target error of the time tables ("target", a fraction of the
reference's RMS value, chosen so that MIS reaches it at roughly 64 samples per pixel).

Units are metres; emission is radiance (W/(m^2 sr)); point/spot intensity W/sr. Every
coordinate goes through _r() (9 significant digits) so the bytes do not depend on the last bit of
the platform's sin/cos.
"""

import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from gltf_builder import GltfBuilder, box, look_at, merge, quad, uv_sphere  # noqa: E402
import rgbe  # noqa: E402

WIDTH, HEIGHT = 128, 96  # the frame crops refer to; scenes render at any 4:3 size


def _r(x):
    v = float("%.9g" % x)
    return 0.0 if v == 0.0 else v


def _rv(p):
    return tuple(_r(c) for c in p)


def _shape(shape, scale=1.0, offset=(0.0, 0.0, 0.0)):
    """A (positions, normals, indices) shape with positions scaled and moved, all rounded."""
    positions, normals, indices = shape
    pos = [_rv(tuple(o + scale * c for o, c in zip(offset, p))) for p in positions]
    nrm = None if normals is None else [_rv(n) for n in normals]
    return pos, nrm, list(indices)


def _add(b, name, shape, material):
    positions, normals, indices = shape
    return b.node(name, mesh=b.mesh(name, positions, indices, material, normals=normals))


def _camera(b, eye, target, yfov=0.8, znear=0.01, up=(0.0, 1.0, 0.0)):
    cam = b.perspective_camera(_r(yfov), _r(znear), name="camera")
    b.node("camera", camera=cam, translation=_rv(eye), rotation=look_at(eye, target, up))


def _sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def _norm(a):
    n = math.sqrt(sum(x * x for x in a))
    return tuple(x / n for x in a)


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def shell(lo, hi, t, hole=None):
    """A closed room with inner space lo..hi made of six slab boxes of thickness t (their faces
    toward the room face into it). Slabs overlap at every edge and corner, so a ray can leave the
    room only through `hole`: (axis, side, (a0, a1), (b0, b1)) cuts a rectangle out of the wall
    on `side` (0: lo, 1: hi) of `axis`, spanning a0..a1 and b0..b1 along the other two axes in
    cyclic order (axis + 1, axis + 2)."""
    slabs = []
    for axis in range(3):
        for side in (0, 1):
            s_lo = [lo[k] - t for k in range(3)]
            s_hi = [hi[k] + t for k in range(3)]
            if side == 0:
                s_hi[axis] = lo[axis]
            else:
                s_lo[axis] = hi[axis]
            if hole is not None and hole[0] == axis and hole[1] == side:
                u, v = (axis + 1) % 3, (axis + 2) % 3
                (a0, a1), (b0, b1) = hole[2], hole[3]
                parts = []
                for (ul, uh, vl, vh) in ((s_lo[u], a0, s_lo[v], s_hi[v]), (a1, s_hi[u], s_lo[v], s_hi[v]),
                                         (a0, a1, s_lo[v], b0), (a0, a1, b1, s_hi[v])):
                    p_lo, p_hi = list(s_lo), list(s_hi)
                    p_lo[u], p_hi[u], p_lo[v], p_hi[v] = ul, uh, vl, vh
                    parts.append(box(tuple(p_lo), tuple(p_hi)))
                slabs.append(merge(*parts))
            else:
                slabs.append(box(tuple(s_lo), tuple(s_hi)))
    return merge(*slabs)


def rect(center, u, v, hu, hv):
    """A rectangle centred at `center` with half extents hu, hv along unit vectors u, v; its front
    faces u x v."""
    c = [tuple(center[k] + su * hu * u[k] + sv * hv * v[k] for k in range(3))
         for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    return quad(c)


def rect_facing(center, normal, hu, hv, ref=(0.0, 1.0, 0.0)):
    """A rectangle centred at `center` whose front faces `normal`; v is the direction of `ref`
    projected onto the plane (hv its half extent), u = v x normal (hu)."""
    n = _norm(normal)
    d = sum(a * b for a, b in zip(ref, n))
    v = _norm(tuple(r - d * c for r, c in zip(ref, n)))
    u = _cross(v, n)
    return rect(center, u, v, hu, hv)


def corners_of(shape):
    return [list(p) for p in shape[0]]


def rotated_box(center_bottom, size, angle):
    """A box of size (sx, sy, sz) standing on center_bottom, turned by angle about +Y."""
    pos, nrm, idx = box((-size[0] / 2, 0.0, -size[2] / 2), (size[0] / 2, size[1], size[2] / 2))
    c, s = math.cos(angle), math.sin(angle)

    def rot(p):
        return (c * p[0] + s * p[2], p[1], -s * p[0] + c * p[2])

    pos = [tuple(a + b for a, b in zip(rot(p), center_bottom)) for p in pos]
    nrm = [rot(n) for n in nrm]
    return pos, nrm, idx


# ---- Scenes ------------------------------------------------------------------------------------
# Each function returns (builder, manifest entry).

def veach_mis():
    """Veach's MIS scene (his thesis, fig. 9.2), with our own numbers: four metal plates, smoothest
    farthest, each turned so that it reflects the row of lights toward the camera, and four
    spherical emitters of radius 0.03 .. 0.9 with equal power (radiance ~ 1/r^2)."""
    b = GltfBuilder()
    eye, target = (0.0, 2.4, 9.0), (0.0, 1.3, 0.0)
    light_row = (0.0, 6.0, -3.5)
    radii = (0.05, 0.12, 0.3, 0.8)
    xs = (-3.0, -1.2, 0.6, 2.7)
    colours = ((1.0, 0.85, 0.7), (0.75, 1.0, 0.75), (0.7, 0.8, 1.0), (1.0, 0.8, 1.0))
    power = 8.0  # pi * (4 pi r^2) * mean(L over R, G, B), the same for every sphere
    for i, (r, x, col) in enumerate(zip(radii, xs, colours)):
        col = tuple(3.0 * c / sum(col) for c in col)  # mean 1
        radiance = power / (4.0 * math.pi ** 2 * r * r)
        m = b.material("light%d" % i, base_color=(0.0, 0.0, 0.0), specular=0.0,
                       emission=tuple(_r(c * radiance) for c in col))
        _add(b, "light%d" % i, _shape(uv_sphere((x, light_row[1], light_row[2]), r, 10, 20)), m)
    plate_roughness = (0.5, 0.34, 0.22, 0.13)  # nearest (bottom of the image) to farthest
    centres = ((0.0, 0.1, 2.6), (0.0, 0.55, 1.5), (0.0, 1.05, 0.4), (0.0, 1.6, -0.7))
    for i, (rough, c) in enumerate(zip(plate_roughness, centres)):
        to_eye, to_light = _norm(_sub(eye, c)), _norm(_sub(light_row, c))
        n = _norm(tuple(a + b_ for a, b_ in zip(to_eye, to_light)))
        m = b.material("plate%d" % i, base_color=(0.8, 0.8, 0.8), metallic=1.0, roughness=rough)
        t = _cross(n, (1.0, 0.0, 0.0))
        _add(b, "plate%d" % i, _shape(rect(c, (1.0, 0.0, 0.0), t, 4.0, 0.45)), m)
    dark = b.material("backdrop", base_color=(0.12, 0.12, 0.12))
    _add(b, "floor", _shape(quad([(-12, -0.6, 12), (12, -0.6, 12), (12, -0.6, -8), (-12, -0.6, -8)])), dark)
    _add(b, "back", _shape(quad([(-12, -0.6, -8), (12, -0.6, -8), (12, 8, -8), (-12, 8, -8)])), dark)
    _camera(b, eye, target, yfov=0.62)
    return b, {
        "breaks": "bsdf on small lights seen in rough plates; nee on large lights seen in smooth "
                  "plates; MIS is good on both",
        "crop": [8, 32, 112, 44],
        "target": 0.25,
    }


def small_light_room():
    """A tiny (3 x 3 cm), very bright emitter in an 8 x 3 x 8 m diffuse room, out of view."""
    b = GltfBuilder()
    wall = b.material("wall", base_color=(0.7, 0.68, 0.62))
    _add(b, "room", _shape(shell((-4, 0, -4), (4, 3, 4), 0.2)), wall)
    blue = b.material("cabinet", base_color=(0.2, 0.3, 0.6))
    red = b.material("table", base_color=(0.6, 0.2, 0.15))
    _add(b, "cabinet", _shape(rotated_box((2.5, 0, -2.5), (1.2, 2.0, 0.6), 0.4)), blue)
    _add(b, "table", _shape(rotated_box((0.2, 0, -1.0), (1.6, 0.75, 0.9), -0.3)), red)
    lamp = b.material("lamp", base_color=(0.0, 0.0, 0.0), specular=0.0, emission=(30000.0, 28000.0, 24000.0))
    _add(b, "lamp", _shape(rect_facing((-1.5, 2.98, 3.0), (0, -1, 0), 0.015, 0.015, ref=(0, 0, 1))), lamp)
    _camera(b, (-3.2, 1.6, 3.6), (1.5, 0.9, -2.0), yfov=0.9)
    return b, {
        "breaks": "bsdf: a BSDF-sampled ray hits a 9 cm^2 light with probability ~1e-5",
        "crop": [40, 30, 64, 48],
    }


def glossy_floor():
    """A large emitter panel reflected in a near-mirror metal floor (roughness 0.05)."""
    b = GltfBuilder()
    floor = b.material("floor", base_color=(0.85, 0.85, 0.85), metallic=1.0, roughness=0.05)
    _add(b, "floor", _shape(quad([(-6, 0, 6), (6, 0, 6), (6, 0, -6), (-6, 0, -6)])), floor)
    back = b.material("back", base_color=(0.3, 0.3, 0.3))
    _add(b, "back", _shape(quad([(-6, 0, -4.2), (6, 0, -4.2), (6, 4, -4.2), (-6, 4, -4.2)])), back)
    panel = b.material("panel", base_color=(0.0, 0.0, 0.0), specular=0.0, emission=(4.0, 3.8, 3.4))
    _add(b, "panel", _shape(rect_facing((0.0, 1.3, -4.0), (0, 0, 1), 2.2, 0.7)), panel)
    white = b.material("white", base_color=(0.75, 0.75, 0.75))
    red = b.material("red", base_color=(0.7, 0.12, 0.08), roughness=0.5)
    _add(b, "box", _shape(rotated_box((-1.3, 0, -1.6), (0.6, 0.6, 0.6), 0.5)), white)
    _add(b, "ball", _shape(uv_sphere((1.3, 0.45, -1.0), 0.45, 16, 32)), red)
    _camera(b, (0.0, 1.2, 4.5), (0.0, 0.4, -2.0), yfov=0.7)
    return b, {
        "breaks": "nee: a light sample on the big panel almost never falls in the floor's narrow "
                  "GGX lobe; bsdf sampling finds the reflection directly",
        "crop": [32, 40, 64, 48],
        "target": 0.02,
    }


def _lambert_plane(b, half_x, half_z, albedo):
    m = b.material("plane", base_color=albedo, specular=0.0)
    _add(b, "plane", _shape(quad([(-half_x, 0, half_z), (half_x, 0, half_z), (half_x, 0, -half_z),
                                  (-half_x, 0, -half_z)])), m)


def _top_camera(b, half_z):
    """An orthographic camera straight above the origin looking down -Y: image right = +X, image
    up = -Z, half height half_z (the image's 4:3 aspect gives the half width)."""
    cam = b.orthographic_camera(_r(half_z * 4.0 / 3.0), _r(half_z), 0.01, 20.0, name="camera")
    eye = (0.0, 5.0, 0.0)
    b.node("camera", camera=cam, translation=eye, rotation=look_at(eye, (0.0, 0.0, 0.0), (0, 0, -1)))


PLANE_ALBEDO = (0.8, 0.8, 0.8)


def punctual():
    """A point and a spot light over a Lambertian plane, seen from straight above: the image is
    known in closed form (tools/wavepath_tools/closed_form.py)."""
    b = GltfBuilder()
    _lambert_plane(b, 2.0, 1.5, PLANE_ALBEDO)
    point_pos, point_col, point_i = (-1.0, 0.8, -0.3), (1.0, 0.85, 0.7), 1.5
    b.node("point", light=b.point_light(point_col, point_i, name="point"), translation=point_pos)
    spot_pos, spot_target = (1.0, 1.2, 0.4), (0.8, 0.0, 0.1)
    inner, outer, spot_col, spot_i = 0.25, 0.45, (0.7, 0.85, 1.0), 5.0
    b.node("spot", light=b.spot_light(spot_col, spot_i, inner, outer, name="spot"),
           translation=spot_pos, rotation=look_at(spot_pos, spot_target, (0, 0, -1)))
    _top_camera(b, 1.5)
    spot_dir = _norm(_sub(spot_target, spot_pos))
    return b, {
        "breaks": "bsdf: no sampled direction ever hits a point or spot light, so bsdf renders "
                  "black (the expected answer); nee and mis are exact here",
        "crop": [0, 0, 128, 96],
        "target": 0.25,
        "reference": {"kind": "closed_form", "model": {
            "albedo": list(PLANE_ALBEDO), "view": {"x": [-2.0, 2.0], "z": [-1.5, 1.5]},
            "points": [{"position": list(point_pos), "intensity": [c * point_i for c in point_col]}],
            "spots": [{"position": list(spot_pos), "direction": list(spot_dir),
                       "intensity": [c * spot_i for c in spot_col], "inner": inner, "outer": outer}],
            "quads": []}},
    }


def lambert_quad():
    """Two emissive rectangles (one large and dim, one small and bright) facing down over a
    Lambertian plane, seen from straight above through their backs (single-sided, so invisible):
    the irradiance is Lambert's polygon formula, the image known in closed form."""
    b = GltfBuilder()
    _lambert_plane(b, 2.0, 1.5, PLANE_ALBEDO)
    quads = []
    for name, centre, hu, hv, radiance in (("big", (-0.4, 0.6, 0.1), 0.6, 0.3, (3.0, 2.8, 2.5)),
                                           ("small", (1.2, 0.4, -0.6), 0.05, 0.05, (40.0, 30.0, 20.0))):
        shape = _shape(rect_facing(centre, (0, -1, 0), hu, hv, ref=(0, 0, -1)))
        m = b.material(name, base_color=(0.0, 0.0, 0.0), specular=0.0, emission=radiance)
        _add(b, name, shape, m)
        quads.append({"corners": corners_of(shape), "radiance": list(radiance)})
    _top_camera(b, 1.5)
    return b, {
        "breaks": "nothing badly: a large and a small area light over a diffuse plane; the scene "
                  "with a closed-form answer for area lights (bsdf is noisy under the small one)",
        "crop": [0, 0, 128, 96],
        "reference": {"kind": "closed_form", "model": {
            "albedo": list(PLANE_ALBEDO), "view": {"x": [-2.0, 2.0], "z": [-1.5, 1.5]},
            "points": [], "spots": [], "quads": quads}},
    }


def caustics():
    """A perfect mirror and a smooth glass ball in a small room under a small ceiling light."""
    b = GltfBuilder()
    wall = b.material("wall", base_color=(0.75, 0.73, 0.7))
    _add(b, "room", _shape(shell((-1.5, 0, -1.5), (1.5, 2.4, 1.5), 0.1)), wall)
    lamp = b.material("lamp", base_color=(0.0, 0.0, 0.0), specular=0.0, emission=(40.0, 38.0, 34.0))
    _add(b, "lamp", _shape(rect_facing((-0.45, 2.39, -0.5), (0, -1, 0), 0.12, 0.12, ref=(0, 0, 1))), lamp)
    glass = b.material("glass", base_color=(1.0, 1.0, 1.0), roughness=0.0, transmission=1.0,
                       ior=1.5, thickness=1.0)
    _add(b, "glass_ball", _shape(uv_sphere((-0.45, 0.35, -0.5), 0.35, 32, 64)), glass)
    mirror = b.material("mirror", base_color=(0.95, 0.95, 0.95), metallic=1.0, roughness=0.0)
    _add(b, "mirror", _shape(rect_facing((1.45, 0.9, -0.5), (-1, 0, 0.35), 0.6, 0.7)), mirror)
    _camera(b, (0.0, 1.3, 1.45), (0.0, 0.45, -0.6), yfov=1.0)
    return b, {
        "breaks": "every strategy: caustics (light -> glass or mirror -> diffuse floor) are found "
                  "only by BSDF-sampled rays that happen to pass through the glass or mirror and "
                  "hit the small light; NEE cannot connect through a delta lobe",
        "crop": [16, 40, 72, 56],
        "target": 0.5,
    }


def opening_room():
    """A closed room lit only through a 40 x 40 cm opening by a bright panel outside."""
    b = GltfBuilder()
    wall = b.material("wall", base_color=(0.75, 0.72, 0.68))
    # The opening is in the +X wall: axis 0, side 1, spanning y (1.4, 1.8) and z (-0.2, 0.2).
    _add(b, "room", _shape(shell((-2, 0, -2), (2, 2.5, 2), 0.15,
                                 hole=(0, 1, (1.4, 1.8), (-0.2, 0.2)))), wall)
    sun = b.material("panel", base_color=(0.0, 0.0, 0.0), specular=0.0, emission=(60.0, 55.0, 45.0))
    _add(b, "panel", _shape(rect_facing((4.5, 3.6, 0.0), (-1.0, -0.8, 0.0), 0.8, 0.8, ref=(0, 0, 1))), sun)
    blocks = b.material("blocks", base_color=(0.3, 0.5, 0.3))
    _add(b, "block", _shape(rotated_box((-0.6, 0, -0.9), (0.7, 0.9, 0.7), 0.3)), blocks)
    _camera(b, (-1.8, 1.6, 1.8), (1.2, 0.6, -0.8), yfov=1.0)
    return b, {
        "breaks": "all strategies, mostly bsdf: indirect light through a gap; most NEE shadow rays "
                  "are blocked, and only paths that leave through the opening find the light",
        "crop": [32, 24, 64, 48],
        "target": 0.4,
    }


def contact(scale):
    """A closed room with a turned block, a ball resting on the floor and a thin plate 1 mm above
    it, lit by a ceiling panel; every length multiplied by `scale` (radiance does not change, so
    the image must not either)."""
    b = GltfBuilder()
    s = scale
    wall = b.material("wall", base_color=(0.75, 0.73, 0.7))
    red = b.material("red", base_color=(0.7, 0.1, 0.08))
    metal = b.material("metal", base_color=(0.9, 0.8, 0.6), metallic=1.0, roughness=0.25)
    plate = b.material("plate", base_color=(0.2, 0.4, 0.7))
    _add(b, "room", _shape(shell((-1.5, 0, -1.5), (1.5, 2.0, 1.5), 0.1), s), wall)
    _add(b, "block", _shape(rotated_box((-0.6, 0, -0.6), (0.5, 0.5, 0.5), 0.5), s), metal)
    _add(b, "ball", _shape(uv_sphere((0.55, 0.3, -0.4), 0.3, 24, 48), s), red)
    _add(b, "plate", _shape(box((-0.3, 0.001, 0.05), (0.4, 0.003, 0.65)), s), plate)
    lamp = b.material("lamp", base_color=(0.0, 0.0, 0.0), specular=0.0, emission=(20.0, 19.0, 17.0))
    _add(b, "lamp", _shape(rect_facing((0.0, 1.99, 0.0), (0, -1, 0), 0.3, 0.3, ref=(0, 0, 1)), s), lamp)
    eye, target = (-1.2, 1.3, 1.35), (0.2, 0.2, -0.4)
    _camera(b, tuple(s * c for c in eye), tuple(s * c for c in target), yfov=1.0, znear=0.01 * s)
    return b


def degenerate():
    """The contact room at scale 1 with numerically hostile geometry in view: zero-area triangles
    (coincident and collinear vertices, no normals given), 1e-6-wide slivers, a zero-area and a
    sliver emitter, two coplanar overlapping quads, a perfect mirror and a floor seen at grazing
    angles from a camera 4 cm above it."""
    b = contact(1.0)
    grey = b.material("grey", base_color=(0.6, 0.6, 0.6))
    pos, idx = [], []
    for k in range(40):  # zero-area: repeated points, then collinear ones
        x, z = -1.2 + 0.06 * k, 0.9 - 0.02 * k
        p = (x, 0.15 + 0.01 * (k % 7), z)
        q = (x + 0.05, 0.2, z)
        base = len(pos)
        pos += [p, p, p] if k % 2 == 0 else [p, q, tuple(0.5 * (a + c) for a, c in zip(p, q))]
        idx += [base, base + 1, base + 2]
    for k in range(30):  # slivers: 0.8 m long, 1e-6 m wide, standing across the view
        x = -1.0 + 0.07 * k
        base = len(pos)
        pos += [(x, 0.0, 0.2), (x + 1e-6, 0.0, 0.2), (x, 0.8, 0.2 - 0.3 * (k % 3))]
        idx += [base, base + 1, base + 2]
    _add(b, "degenerate", (_shape((pos, None, idx))), grey)
    glow = b.material("glow", base_color=(0.0, 0.0, 0.0), specular=0.0, emission=(50.0, 20.0, 5.0),
                      double_sided=True)
    pos = [(-1.0, 1.2, -1.4), (-1.0, 1.2, -1.4), (-1.0, 1.2, -1.4),  # zero-area emitter
           (-0.9, 1.0, -1.45), (-0.9 + 1e-6, 1.0, -1.45), (0.9, 1.6, -1.45)]  # sliver emitter
    _add(b, "degenerate_lights", _shape((pos, None, [0, 1, 2, 3, 4, 5])), glow)
    a = b.material("coplanar_a", base_color=(0.8, 0.6, 0.2))
    c = b.material("coplanar_b", base_color=(0.2, 0.6, 0.8))
    _add(b, "coplanar_a", _shape(rect_facing((0.0, 0.8, -1.49), (0, 0, 1), 0.4, 0.3)), a)
    _add(b, "coplanar_b", _shape(rect_facing((0.05, 0.8, -1.49), (0, 0, 1), 0.4, 0.3)), c)
    mirror = b.material("mirror", base_color=(0.9, 0.9, 0.9), metallic=1.0, roughness=0.0)
    _add(b, "mirror_ball", _shape(uv_sphere((-0.1, 0.2, 0.9), 0.2, 16, 32)), mirror)
    # The contact() camera is node 0's sibling; add a second, grazing one and point --camera at it.
    eye = (1.3, 0.04, 1.3)
    cam = b.perspective_camera(0.9, 0.01, name="grazing")
    b.node("grazing", camera=cam, translation=eye, rotation=look_at(eye, (-0.6, 0.3, -1.2)))
    return b, {
        "breaks": "numerical robustness: degenerate and sliver triangles, a zero-area emitter, "
                  "coplanar faces and grazing angles must not produce NaN/Inf or fireflies that "
                  "are not the estimator's",
        "args": ["--camera", "1"],
        "crop": [0, 48, 128, 48],
    }


def closed_box():
    """A closed box with the camera inside and every kind of light outside: an area light, a
    point light and (on the command line) a white sky. Nothing can reach the inside."""
    b = GltfBuilder()
    wall = b.material("wall", base_color=(0.8, 0.8, 0.8))
    _add(b, "box", _shape(shell((-1, 0, -1), (1, 2, 1), 0.1)), wall)
    lamp = b.material("lamp", base_color=(0.0, 0.0, 0.0), specular=0.0, emission=(10.0, 10.0, 10.0),
                      double_sided=True)
    _add(b, "lamp", _shape(rect_facing((0.0, 2.6, 0.0), (0, -1, 0), 1.0, 1.0, ref=(0, 0, 1))), lamp)
    b.node("point", light=b.point_light((1.0, 1.0, 1.0), 10.0, name="point"), translation=(1.5, 1.0, 0.0))
    _camera(b, (0.0, 1.0, 0.85), (0.0, 0.8, -1.0), yfov=1.4)
    return b, {
        "breaks": "light leaks: a closed box with an area light, a point light and a white sky "
                  "outside must render exactly 0 inside",
        "args": ["--env-color", "1,1,1"],
        "crop": [0, 0, 128, 96],
        "reference": {"kind": "black"},
        "chart": False,
    }


# ---- The environment map with a small sun -------------------------------------------------------

ENV_W, ENV_H = 512, 256
SUN_RADIUS = math.radians(1.5)
SUN_RADIANCE = (2600.0, 2400.0, 2000.0)


def _sun_direction():
    elevation, azimuth = math.radians(35.0), math.radians(-55.0)  # azimuth from -Z toward +X
    theta = math.pi / 2 - elevation
    return (math.sin(theta) * math.sin(azimuth), math.cos(theta), -math.sin(theta) * math.cos(azimuth))


def sky(d):
    """Sky radiance toward unit d (no sun): a blue gradient above the horizon, brown ground below."""
    y = d[1]
    if y < 0.0:
        return (0.12, 0.1, 0.08)
    t = math.sqrt(y)
    horizon, zenith = (0.9, 0.95, 1.0), (0.25, 0.45, 0.9)
    return tuple(h + (z - h) * t for h, z in zip(horizon, zenith))


def environment_pixels():
    """The map's pixels, top row first: the sky at each pixel's centre direction, and near the sun
    the average over an 8 x 8 grid of directions inside the pixel, so the sun disk's edge is
    anti-aliased and its flux kept (the sky varies too slowly to need it)."""
    sun = _sun_direction()
    cos_r = math.cos(SUN_RADIUS)
    cos_near = math.cos(SUN_RADIUS + 4.0 * math.pi / ENV_H)  # within ~4 pixels of the disk
    n = 8
    rows = []
    for y in range(ENV_H):
        row = []
        for x in range(ENV_W):
            d = rgbe.direction((x + 0.5) / ENV_W, (y + 0.5) / ENV_H)
            if sum(a * b_ for a, b_ in zip(d, sun)) < cos_near:
                row.append(tuple(_r(c) for c in sky(d)))
                continue
            acc = [0.0, 0.0, 0.0]
            for j in range(n):
                for i in range(n):
                    d = rgbe.direction((x + (i + 0.5) / n) / ENV_W, (y + (j + 0.5) / n) / ENV_H)
                    c = SUN_RADIANCE if sum(a * b_ for a, b_ in zip(d, sun)) >= cos_r else sky(d)
                    for k in range(3):
                        acc[k] += c[k]
            row.append(tuple(_r(a / (n * n)) for a in acc))
        rows.append(row)
    return rows


def env_sun():
    """Objects on a grey ground under the synthetic sky with a 1.5-degree sun (env_sun.hdr)."""
    b = GltfBuilder()
    ground = b.material("ground", base_color=(0.5, 0.5, 0.5))
    _add(b, "ground", _shape(quad([(-15, 0, 15), (15, 0, 15), (15, 0, -15), (-15, 0, -15)])), ground)
    metal = b.material("metal", base_color=(0.95, 0.9, 0.8), metallic=1.0, roughness=0.4)
    red = b.material("red", base_color=(0.7, 0.1, 0.08), roughness=0.5)
    white = b.material("white", base_color=(0.8, 0.8, 0.8))
    _add(b, "metal_ball", _shape(uv_sphere((-0.9, 0.5, -0.5), 0.5, 24, 48)), metal)
    _add(b, "red_ball", _shape(uv_sphere((0.8, 0.4, 0.2), 0.4, 24, 48)), red)
    _add(b, "block", _shape(rotated_box((0.3, 0, -1.6), (0.8, 1.0, 0.8), 0.6)), white)
    _camera(b, (0.0, 1.6, 4.0), (0.0, 0.4, -0.5), yfov=0.8)
    return b, {
        "breaks": "bsdf: the sun covers 0.002 sr but carries most of the light; environment "
                  "importance sampling (nee) finds it, BSDF sampling rarely does",
        "args": ["--env", "env_sun.hdr"],
        "crop": [24, 32, 80, 56],
    }


SCENES = (
    ("veach_mis", veach_mis),
    ("small_light_room", small_light_room),
    ("glossy_floor", glossy_floor),
    ("punctual", punctual),
    ("lambert_quad", lambert_quad),
    ("caustics", caustics),
    ("opening_room", opening_room),
    ("env_sun", env_sun),
    ("degenerate", degenerate),
    ("closed_box", closed_box),
)
SCALES = (("scale_1", 1.0), ("scale_1e-3", 1e-3), ("scale_1e4", 1e4))


def build_all():
    """[(file name, builder), ...] and the manifest dict."""
    files, entries = [], []
    for name, fn in SCENES:
        builder, entry = fn()
        files.append((name + ".gltf", builder))
        entry = dict(entry)
        entry["name"] = name
        entry["file"] = name + ".gltf"
        entry.setdefault("args", [])
        entry.setdefault("reference", {"kind": "render"})
        entries.append(entry)
    for name, s in SCALES:
        files.append((name + ".gltf", contact(s)))
        entry = {
            "name": name, "file": name + ".gltf", "args": [], "crop": [32, 40, 64, 48],
            "breaks": "self-intersection and precision at scale %g: the ray offset must hold; "
                      "radiance does not depend on scale, so the image must equal scale_1's" % s,
            "reference": {"kind": "render"} if s == 1.0 else {"kind": "scene", "scene": "scale_1"},
        }
        if s == 1.0:
            entry["chart"] = False  # the scaled scenes' reference
        entries.append(entry)
    manifest = {
        "comment": "written by scenes/make_failure_scenes.py; read by tools/convergence.py and "
                   "tests/test_accuracy.py",
        "frame": [WIDTH, HEIGHT],
        "scenes": entries,
    }
    return files, manifest


def main(argv):
    out_dir = argv[1] if len(argv) > 1 else os.path.join(HERE, "failure")
    os.makedirs(out_dir, exist_ok=True)
    files, manifest = build_all()
    for name, builder in files:
        print("wrote", builder.write(os.path.join(out_dir, name)))
    print("wrote", rgbe.write_rgbe(os.path.join(out_dir, "env_sun.hdr"), ENV_W, ENV_H,
                                   environment_pixels()))
    path = os.path.join(out_dir, "manifest.json")
    with open(path, "w") as f:
        f.write(json.dumps(manifest, indent=2, sort_keys=True) + "\n")
    print("wrote", path)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
