"""Radiance RGBE (.hdr) writing and equirectangular directions (Python 3 standard library only).

    write_rgbe(path, width, height, pixels)   # pixels: rows from the top, (r, g, b) linear floats
    direction(u, v)                           # unit direction of map coordinates u, v in [0, 1]

RGBE stores a shared 8-bit exponent e and three 8-bit mantissas: a value x is written as
floor(x * 256 / 2^(e - 128)) with e chosen so the largest component's mantissa is in [128, 256);
reading gives (m + 0.5) * 2^(e - 136) (stb_image, which wavepath uses, omits the + 0.5). The
relative rounding of the largest component is under 2^-7. Scanlines are written flat (not
run-length encoded), which every reader accepts, so the bytes depend only on the pixels.

The direction convention is host/lights/environment.h's (glTF frame, +Y up): u runs with the azimuth
phi = atan2(d.x, -d.z) as u = (phi + pi) / (2 pi), so the map's centre column is seen looking down
-Z; v = acos(d.y) / pi, row 0 at the top (+Y).
"""

import math
import struct


def direction(u, v):
    """The unit direction at map coordinates (u, v), the inverse of host/lights/environment.h's map."""
    phi = 2.0 * math.pi * u - math.pi
    theta = math.pi * v
    s = math.sin(theta)
    return (s * math.sin(phi), math.cos(theta), -s * math.cos(phi))


def map_coordinates(d):
    """(u, v) of unit direction d."""
    u = (math.atan2(d[0], -d[2]) + math.pi) / (2.0 * math.pi)
    v = math.acos(max(-1.0, min(1.0, d[1]))) / math.pi
    return u, v


def encode(rgb):
    """The 4 RGBE bytes of one linear RGB value (negative components are written as 0)."""
    r, g, b = (max(0.0, float(c)) for c in rgb)
    peak = max(r, g, b)
    if peak < 1e-32:
        return b"\0\0\0\0"
    mantissa, exponent = math.frexp(peak)  # peak = mantissa * 2^exponent, mantissa in [0.5, 1)
    if exponent > 127:
        raise ValueError("value %g too large for RGBE" % peak)
    scale = mantissa * 256.0 / peak  # = 2^(8 - exponent)
    return struct.pack("4B", int(r * scale), int(g * scale), int(b * scale), exponent + 128)


def decode(rgbe):
    """Linear RGB of 4 RGBE bytes, as stb_image reads them (no half-step offset)."""
    r, g, b, e = rgbe
    if e == 0:
        return (0.0, 0.0, 0.0)
    f = math.ldexp(1.0, e - 136)
    return (r * f, g * f, b * f)


def write_rgbe(path, width, height, pixels):
    """Writes a Radiance .hdr: pixels is a list of height rows of width (r, g, b), top row first."""
    if len(pixels) != height or any(len(row) != width for row in pixels):
        raise ValueError("pixels must be %d rows of %d values" % (height, width))
    out = bytearray(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n")
    out += ("-Y %d +X %d\n" % (height, width)).encode("ascii")
    for row in pixels:
        for rgb in row:
            out += encode(rgb)
    with open(path, "wb") as f:
        f.write(bytes(out))
    return path


def read_rgbe(path):
    """(width, height, rows of (r, g, b)) of a flat (not run-length encoded) .hdr as written above."""
    with open(path, "rb") as f:
        data = f.read()
    header_end = data.index(b"\n\n") + 2
    line_end = data.index(b"\n", header_end)
    parts = data[header_end:line_end].split()
    if parts[0] != b"-Y" or parts[2] != b"+X":
        raise ValueError("%s: only -Y H +X W orientation is read" % path)
    height, width = int(parts[1]), int(parts[3])
    body = data[line_end + 1:]
    if len(body) != 4 * width * height:
        raise ValueError("%s: expected %d flat RGBE pixels" % (path, width * height))
    rows = []
    for y in range(height):
        base = 4 * width * y
        rows.append([decode(body[base + 4 * x:base + 4 * x + 4]) for x in range(width)])
    return width, height, rows
