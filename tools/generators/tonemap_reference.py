#!/usr/bin/env python3
"""The PNG tonemappers' reference values (tests/data/tonemap_reference.csv, read by
tests/test_tonemap.cpp): each mapper transcribed in float64 from its published definition,
independently of host/film/tonemap.cpp, and applied to a fixed set of linear Rec.709 colours.

  agx          three.js's AgXToneMapping (src/renderers/shaders/ShaderChunk/
               tonemapping_pars_fragment.glsl.js; Filament's AgX uses the same matrices and curve):
               Blender 4's AgX base matrices in Rec.2020, the sigmoid as Wrensch's 6th-order
               polynomial fit; its output is linear Rec.709 (the 2.2 power undone), so the sRGB
               encoding below is applied once.
  pbr-neutral  Khronos PBR Neutral, the normative text of KhronosGroup/ToneMapping
               PBR_Neutral/README.md (desaturation towards [p_n, p_n, p_n]); linear output.
  aces         Narkowicz 2015's rational fit, per channel; linear output.
  clamp        min(max(x, 0), 1) per channel.

Every row: mapper, the input R,G,B (float32 values, printed so that they read back exactly), the
sRGB-encoded output in [0, 1] (IEC 61966-2-1, after clamping to [0, 1]) and its 8-bit PNG code
(round half up of 255 * value).

  python3 -m tools.generators.tonemap_reference > tests/data/tonemap_reference.csv
  python3 -m tools.generators.tonemap_reference --check tests/data/tonemap_reference.csv
"""

import argparse
import colorsys
import io
import sys

from tools.wavepath_tools import system_python  # noqa: E402

system_python.need_numpy("tonemap_reference.py")
import numpy as np  # noqa: E402

# three.js: LINEAR_REC2020_TO_LINEAR_SRGB as written there (4 digits, rows), the other way its
# exact inverse (three.js computes it with inverse() in the shader).
REC2020_TO_REC709 = np.array([[1.6605, -0.5876, -0.0728],
                              [-0.1246, 1.1329, -0.0083],
                              [-0.0182, -0.1006, 1.1187]])
REC709_TO_REC2020 = np.linalg.inv(REC2020_TO_REC709)
# three.js writes GLSL mat3(col0, col1, col2); these are the columns, so the matrices are their
# transposes. Each matrix's rows sum to 1 (white stays white).
AGX_INSET = np.array([[0.856627153315983, 0.137318972929847, 0.11189821299995],
                      [0.0951212405381588, 0.761241990602591, 0.0767994186031903],
                      [0.0482516061458583, 0.101439036467562, 0.811302368396859]]).T
AGX_OUTSET = np.linalg.inv(np.array([[0.899796955911611, 0.11142098895748, 0.11142098895748],
                                     [0.0871996192028351, 0.875575586156966, 0.0871996192028349],
                                     [0.013003424885555, 0.0130034248855548, 0.801379391839686]]).T)
AGX_MIN_EV, AGX_MAX_EV = -12.47393, 4.026069


def agx(c):
    v = np.maximum(REC709_TO_REC2020 @ c, 0.0)
    v = AGX_INSET @ v
    v = (np.log2(np.maximum(v, 1e-10)) - AGX_MIN_EV) / (AGX_MAX_EV - AGX_MIN_EV)
    x = np.clip(v, 0.0, 1.0)
    x2 = x * x
    x4 = x2 * x2
    v = (15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2
         + 0.1191 * x - 0.00232)
    v = AGX_OUTSET @ v
    v = np.maximum(v, 0.0) ** 2.2
    return REC2020_TO_REC709 @ v


def pbr_neutral(c):
    f90 = 0.04
    ks = 0.8 - f90
    kd = 0.15
    x = c.min()
    f = x - x * x / (4 * f90) if x <= 2 * f90 else f90
    p = (c - f).max()
    if p <= ks:
        return c - f
    pn = 1 - (1 - ks) ** 2 / (p + 1 - 2 * ks)
    g = 1 / (kd * (p - pn) + 1)
    return (c - f) * (pn / p) * g + pn * (1 - g)


def aces(c):
    x = np.maximum(c, 0.0)
    return (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)


MAPPERS = {"aces": aces, "agx": agx, "pbr-neutral": pbr_neutral, "clamp": lambda c: c}


def srgb_encode(x):
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def inputs():
    """The colours: a grey ramp (0, then 2^-12 .. 16 in quarter stops), primaries and
    secondaries at a few intensities, a hue sweep at two saturations and intensities, and
    colours whose minimum falls in PBR Neutral's x < 0.08 offset. Rounded to float32."""
    colours = [(0.0, 0.0, 0.0)]
    colours += [(2.0 ** (k / 4),) * 3 for k in range(-48, 17)]
    for level in (0.05, 0.5, 1.0, 4.0, 16.0):
        for r, g, b in ((1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 0), (0, 1, 1), (1, 0, 1)):
            colours.append((r * level, g * level, b * level))
    for value in (0.7, 6.0):
        for saturation in (0.5, 0.95):
            for hue in range(0, 360, 15):
                colours.append(tuple(value * x for x in colorsys.hsv_to_rgb(hue / 360,
                                                                            saturation, 1.0)))
    colours += [(0.02, 0.3, 0.5), (0.05, 0.05, 0.6), (0.079, 0.2, 0.9), (0.001, 0.5, 2.0),
                (0.07, 0.07, 0.07), (0.3, 0.76, 0.5), (0.5, 0.9, 0.2), (0.1, 3.0, 0.4)]
    return [tuple(float(np.float32(v)) for v in c) for c in colours]


def table():
    out = io.StringIO()
    out.write("mapper,r,g,b,srgb_r,srgb_g,srgb_b,code_r,code_g,code_b\n")
    for name, mapper in MAPPERS.items():
        for c in inputs():
            s = srgb_encode(mapper(np.array(c)))
            codes = np.floor(s * 255.0 + 0.5).astype(int)
            out.write(",".join([name] + ["%.9g" % v for v in c] + ["%.9f" % v for v in s]
                               + ["%d" % v for v in codes]) + "\n")
    return out.getvalue()


def same_table(a, b):
    """The same rows, the floats within 1e-9 (another libm may round the last digit printed)."""
    rows_a, rows_b = a.splitlines(), b.splitlines()
    if len(rows_a) != len(rows_b) or rows_a[:1] != rows_b[:1]:
        return False
    for ra, rb in zip(rows_a[1:], rows_b[1:]):
        fa, fb = ra.split(","), rb.split(",")
        if len(fa) != len(fb) or fa[0] != fb[0] or fa[7:] != fb[7:]:
            return False
        if any(abs(float(x) - float(y)) > 1e-9 for x, y in zip(fa[1:7], fb[1:7])):
            return False
    return True


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", metavar="CSV",
                        help="exit 1 unless CSV is exactly what this script writes")
    args = parser.parse_args()
    text = table()
    if not args.check:
        sys.stdout.write(text)
        return
    with open(args.check) as f:
        if not same_table(f.read(), text):
            sys.exit("tonemap_reference.py: %s differs from this script's output; regenerate it"
                     % args.check)
    print("tonemap_reference.py: %s matches" % args.check)


if __name__ == "__main__":
    main()
