#!/usr/bin/env python3
"""Blender's own view transforms on tools/generators/tonemap_reference.py's colours, for
tests/data/tonemap_blender.csv (read by tests/test_tonemap.cpp): the colours as a one-row float
image in Blender's scene linear space (Linear Rec.709), saved as an 8-bit PNG through the sRGB
display's "AgX" and "Khronos PBR Neutral" views (look None, exposure 0, gamma 1, no dither), and
read back. Needs Blender as a Python module (PyPI's bpy, Python 3.11) and numpy:

  python3.11 -m venv /tmp/bpy && /tmp/bpy/bin/pip install bpy numpy
  /tmp/bpy/bin/python -m tools.generators.tonemap_blender > tests/data/tonemap_blender.csv

The first line names Blender's version. Prints to stderr, per view, the largest difference from the reference's 8-bit
codes (greys and all colours). Blender's "Khronos PBR Neutral" is a 3D LUT fitted to the same
function; its "AgX" is Eary Chow's LUT-based AgX (E-Gamut, guard rails, Rec.1886 base) of which
three.js's polynomial AgX, wavepath's, is an approximation: the AgX differences are larger.
"""

import os
import sys
import tempfile

import bpy
import numpy as np

from tools.generators import tonemap_reference as ref  # noqa: E402

VIEWS = {"agx": "AgX", "pbr-neutral": "Khronos PBR Neutral"}


def blender_codes(colours, view):
    scene = bpy.context.scene
    scene.display_settings.display_device = "sRGB"
    scene.view_settings.view_transform = view
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.render.dither_intensity = 0.0
    settings = scene.render.image_settings
    settings.file_format, settings.color_depth, settings.color_mode = "PNG", "8", "RGB"
    image = bpy.data.images.new("ramp", len(colours), 1, float_buffer=True, alpha=False)
    pixels = np.ones((len(colours), 4), np.float32)
    pixels[:, :3] = colours
    image.pixels.foreach_set(pixels.ravel())
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "ramp.png")
        image.save_render(path, scene=scene)
        png = bpy.data.images.load(path)
        back = np.empty(len(colours) * 4, np.float32)
        png.pixels.foreach_get(back)
    return np.rint(back.reshape(-1, 4)[:, :3] * 255).astype(int)


def main():
    colours = np.array(ref.inputs(), np.float32)
    reference = {}
    for line in ref.table().splitlines()[1:]:
        f = line.split(",")
        reference.setdefault(f[0], []).append([int(v) for v in f[7:]])
    print("# Blender %s, tools/generators/tonemap_blender.py" % bpy.app.version_string)
    print("mapper,r,g,b,code_r,code_g,code_b")
    for name, view in VIEWS.items():
        codes = blender_codes(colours, view)
        for c, k in zip(colours, codes):
            print(",".join([name] + ["%.9g" % v for v in c] + ["%d" % v for v in k]))
        diff = np.abs(codes - np.array(reference[name]))
        grey = (colours[:, 0] == colours[:, 1]) & (colours[:, 1] == colours[:, 2])
        print("%s (%s): max difference %d levels on greys, %d on all colours"
              % (name, view, diff[grey].max(), diff.max()), file=sys.stderr)


if __name__ == "__main__":
    main()
