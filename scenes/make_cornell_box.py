#!/usr/bin/env python3
"""Writes the Cornell box scenes: cornell_box.gltf (area light) and cornell_box_point.gltf.

    python3 scenes/make_cornell_box.py [OUT_DIR]    (default: next to this script)

Geometry is the Cornell Program of Computer Graphics' published measurements of the real box
("Cornell Box Data", millimetres), converted to metres. Coordinates are the published ones, which
are right-handed with +Y up like glTF, so nothing is flipped:

    x: 0 (green wall, on the camera's right) .. ~0.556 (red wall, on the camera's left)
    y: 0 (floor) .. 0.5488 (ceiling)
    z: 0 (the open front, no wall) .. 0.5592 (back wall)

The camera stands in front of the opening at (0.278, 0.273, -0.800) looking down +Z; a glTF
camera looks down its node's -Z, so its node is turned 180 degrees about +Y.

The published vertex lists already run counter-clockwise seen from inside the box (walls, floor,
ceiling, light: fronts toward the box's interior, the light's front down) and seen from outside
the blocks (fronts outward), so they are used in their published order. The blocks have no
bottom face, as published (they stand on the floor). tests/test_scenes_py.py checks all of this.
"""

import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gltf_builder import GltfBuilder, merge, quad  # noqa: E402


def mm(*points):
    """Published millimetres -> metres, rounded so the JSON shows 0.5528, not 0.5528000000000001."""
    return [tuple(round(c / 1000.0, 7) for c in p) for p in points]


# ---- The published data (mm); each face's 4 corners in the published order. ----------------

FLOOR = mm((552.8, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 559.2), (549.6, 0.0, 559.2))
CEILING = mm((556.0, 548.8, 0.0), (556.0, 548.8, 559.2), (0.0, 548.8, 559.2), (0.0, 548.8, 0.0))
BACK_WALL = mm((549.6, 0.0, 559.2), (0.0, 0.0, 559.2), (0.0, 548.8, 559.2), (556.0, 548.8, 559.2))
RIGHT_WALL = mm((0.0, 0.0, 559.2), (0.0, 0.0, 0.0), (0.0, 548.8, 0.0), (0.0, 548.8, 559.2))  # green
LEFT_WALL = mm((552.8, 0.0, 0.0), (549.6, 0.0, 559.2), (556.0, 548.8, 559.2), (556.0, 548.8, 0.0))  # red

SHORT_BLOCK = [
    mm((130.0, 165.0, 65.0), (82.0, 165.0, 225.0), (240.0, 165.0, 272.0), (290.0, 165.0, 114.0)),
    mm((290.0, 0.0, 114.0), (290.0, 165.0, 114.0), (240.0, 165.0, 272.0), (240.0, 0.0, 272.0)),
    mm((130.0, 0.0, 65.0), (130.0, 165.0, 65.0), (290.0, 165.0, 114.0), (290.0, 0.0, 114.0)),
    mm((82.0, 0.0, 225.0), (82.0, 165.0, 225.0), (130.0, 165.0, 65.0), (130.0, 0.0, 65.0)),
    mm((240.0, 0.0, 272.0), (240.0, 165.0, 272.0), (82.0, 165.0, 225.0), (82.0, 0.0, 225.0)),
]
TALL_BLOCK = [
    mm((423.0, 330.0, 247.0), (265.0, 330.0, 296.0), (314.0, 330.0, 456.0), (472.0, 330.0, 406.0)),
    mm((423.0, 0.0, 247.0), (423.0, 330.0, 247.0), (472.0, 330.0, 406.0), (472.0, 0.0, 406.0)),
    mm((472.0, 0.0, 406.0), (472.0, 330.0, 406.0), (314.0, 330.0, 456.0), (314.0, 0.0, 456.0)),
    mm((314.0, 0.0, 456.0), (314.0, 330.0, 456.0), (265.0, 330.0, 296.0), (265.0, 0.0, 296.0)),
    mm((265.0, 0.0, 296.0), (265.0, 330.0, 296.0), (423.0, 330.0, 247.0), (423.0, 0.0, 247.0)),
]

# The light: 130 x 105 mm, published at the ceiling's height (548.8 mm; in the real box it fills a
# hole in the ceiling). Here it hangs 1 mm lower so it does not coincide with the ceiling quad.
LIGHT_Y_MM = 547.8
LIGHT = mm((343.0, LIGHT_Y_MM, 227.0), (343.0, LIGHT_Y_MM, 332.0),
           (213.0, LIGHT_Y_MM, 332.0), (213.0, LIGHT_Y_MM, 227.0))

# Emitted radiance (linear RGB, W/(m^2 sr)): the RGB value renderers commonly use for the Cornell
# box light (e.g. PBRT's and Mitsuba's Cornell box scenes). Written as emissiveFactor (17,12,4)/17
# with KHR_materials_emissive_strength 17.
LIGHT_RADIANCE = (17.0, 12.0, 4.0)

# Diffuse reflectances (linear RGB), the values usually derived from the published spectra.
WHITE = (0.725, 0.71, 0.68)
RED = (0.63, 0.065, 0.05)
GREEN = (0.14, 0.45, 0.091)
LIGHT_REFLECTANCE = (0.78, 0.78, 0.78)

# Camera: published position (278, 273, -800) mm, looking down +Z, up +Y; focal length 35 mm on a
# 25 x 25 mm film, so vertical fov = 2 atan(12.5 / 35) = 0.686048 rad = 39.31 degrees, aspect 1.
CAMERA_EYE = (0.278, 0.273, -0.8)
CAMERA_YFOV = round(2.0 * math.atan(12.5 / 35.0), 9)
CAMERA_ZNEAR = 0.01

# ---- The point-light variant ------------------------------------------------------------------
# A point light 1 cm below the ceiling, above the area light's centre, coloured like it. Its
# intensity is chosen so the floor point straight below (0.278, 0, 0.2795) receives the same
# irradiance as from the area light:
#
#   area light: E = L * G, G = 2 [X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))]
#     (pi x the form factor of a parallel rectangle, summed over the four quarters of the light
#     that meet above the point; X = 0.065/h and Y = 0.0525/h are the light's half sizes over its
#     height h = 0.5478 m), G = 0.044793 (the small-source estimate A/h^2 gives 0.045487);
#     so E = (17, 12, 4) * 0.044793 = (0.7615, 0.5375, 0.1792) W/m^2.
#   point light: E = I cos(theta) / d^2 with cos(theta) = 1, d = 0.5388 m, I in W/sr (wavepath
#     reads glTF's candela as W/sr, no 683 lm/W factor), so I = E d^2 = 17 * G * d^2 = 0.221063
#     times the colour (1, 12/17, 4/17), i.e. (0.2211, 0.1560, 0.0520) W/sr.
POINT_LIGHT_POS = (0.278, 0.5388, 0.2795)


def light_irradiance_factor():
    """G above: irradiance at the floor point below the light's centre per unit radiance."""
    (x0, h, z0), (x1, _, z1) = LIGHT[0], LIGHT[2]
    a, b = abs(x1 - x0) / 2.0 / h, abs(z1 - z0) / 2.0 / h
    ra, rb = math.sqrt(1.0 + a * a), math.sqrt(1.0 + b * b)
    return 2.0 * (a / ra * math.atan(b / ra) + b / rb * math.atan(a / rb))


def point_light_intensity():
    """(colour, intensity): the point light that matches the area light's floor irradiance.
    Rounded to 6 digits so the file does not depend on the last bit of the platform's atan."""
    peak = max(LIGHT_RADIANCE)
    color = tuple(c / peak for c in LIGHT_RADIANCE)
    d = POINT_LIGHT_POS[1]
    return color, round(peak * light_irradiance_factor() * d * d, 6)


def build(with_area_light):
    b = GltfBuilder()
    white = b.material("white", base_color=WHITE)
    red = b.material("red", base_color=RED)
    green = b.material("green", base_color=GREEN)

    def add(name, shape, material):
        positions, normals, indices = shape
        b.node(name, mesh=b.mesh(name, positions, indices, material, normals=normals))

    add("floor", quad(FLOOR), white)
    add("ceiling", quad(CEILING), white)
    add("back_wall", quad(BACK_WALL), white)
    add("left_wall_red", quad(LEFT_WALL), red)
    add("right_wall_green", quad(RIGHT_WALL), green)
    add("short_block", merge(*[quad(f) for f in SHORT_BLOCK]), white)
    add("tall_block", merge(*[quad(f) for f in TALL_BLOCK]), white)

    if with_area_light:
        light = b.material("light", base_color=LIGHT_REFLECTANCE, emission=LIGHT_RADIANCE)
        add("light", quad(LIGHT), light)
    else:
        color, intensity = point_light_intensity()
        b.node("light", light=b.point_light(color, intensity, name="light"),
               translation=POINT_LIGHT_POS)

    cam = b.perspective_camera(CAMERA_YFOV, CAMERA_ZNEAR, aspect=1.0, name="camera")
    target = (CAMERA_EYE[0], CAMERA_EYE[1], CAMERA_EYE[2] + 1.0)  # straight down +Z
    b.node("camera", camera=cam, translation=CAMERA_EYE,
           rotation=b.look_at(CAMERA_EYE, target, (0.0, 1.0, 0.0)))
    return b


def main(argv):
    out_dir = argv[1] if len(argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    for name, area in (("cornell_box.gltf", True), ("cornell_box_point.gltf", False)):
        path = build(area).write(os.path.join(out_dir, name))
        print("wrote", path)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
