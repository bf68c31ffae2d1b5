#!/usr/bin/env python3
"""Writes the many-light room of tools/peers.py's checks: a closed box room lit only by N (default
300) small one-sided emissive squares of different colours hanging just under a black ceiling,
facing down; grey Lambertian walls and floor; the camera inside.

    python3 scenes/make_many_lights.py OUT.gltf [--lamps 300] [--layout grid|random] [--seed 1]

Room: x 0 .. 4, y 0 (floor) .. 2.5 (ceiling), z 0 .. 4 metres; the walls, the floor and the
ceiling face into the room (one-sided, like every material here), so the room is closed from the
inside. Walls and floor reflect 0.5 (grey), the ceiling 0 (black). The lamps: squares of
--lamp-size (6 cm) hanging --drop (1 cm) below the ceiling, front (the emitting side) down, base
colour 0.8 grey, each its own material with a random colour (deterministic in --seed) of peak
radiance 10 to 30 W/(m^2 sr) times --radiance. Layout `grid` (the default) puts them on a regular
grid over the ceiling, apart from each other; `random` at uniformly random positions at the same
height, where some overlap: coincident emitters, which tools/wavepath_tools/peers_scene.py refuses (the renderers,
and wavepath's own light and BSDF sampling, resolve them differently; docs/peers.md, Coincident emitters).
Every material has KHR_materials_specular specularFactor 0, so wavepath renders it Lambertian, as
the peers do (no Lambertian copy needed). The camera stands near the wall at z = 4 and looks
across the room and up at the lamps.
"""

import argparse
import colorsys
import math
import random

from gltf_builder import GltfBuilder

W, H, D = 4.0, 2.5, 4.0  # room size (x, y, z), metres
LAMP = 0.06  # lamp side, metres
DROP = 0.01  # lamps hang this far below the ceiling
MARGIN = 0.2  # random layout: lamp centres this far from the walls at least


def _inward_quads():
    """{name: 4 corners counter-clockwise seen from inside the room}."""
    return {
        "floor": [(0, 0, 0), (0, 0, D), (W, 0, D), (W, 0, 0)],
        "ceiling": [(0, H, 0), (W, H, 0), (W, H, D), (0, H, D)],
        "wall_z0": [(0, 0, 0), (W, 0, 0), (W, H, 0), (0, H, 0)],
        "wall_zd": [(0, 0, D), (0, H, D), (W, H, D), (W, 0, D)],
        "wall_x0": [(0, 0, 0), (0, H, 0), (0, H, D), (0, 0, D)],
        "wall_xw": [(W, 0, 0), (W, 0, D), (W, H, D), (W, H, 0)],
    }


def build(lamps=300, seed=1, layout="grid", lamp=LAMP, drop=DROP, radiance=1.0):
    """The room as a GltfBuilder (arguments as the options of main)."""
    if layout not in ("grid", "random"):
        raise ValueError("layout must be grid or random")
    b = GltfBuilder()
    grey = b.material("grey", base_color=(0.5, 0.5, 0.5), specular=0.0)
    black = b.material("black", base_color=(0.0, 0.0, 0.0), specular=0.0)
    for name, corners in _inward_quads().items():
        b.node(name, mesh=b.mesh(name, corners, [0, 1, 2, 0, 2, 3],
                                 black if name == "ceiling" else grey))
    rng = random.Random(seed)
    cols = math.ceil(math.sqrt(lamps))
    rows = math.ceil(lamps / cols)
    y = H - drop
    h = 0.5 * lamp
    for k in range(lamps):
        if layout == "grid":
            cx, cz = W * (k % cols + 0.5) / cols, D * (k // cols + 0.5) / rows
        else:
            cx, cz = rng.uniform(MARGIN, W - MARGIN), rng.uniform(MARGIN, D - MARGIN)
        r, g, bl = colorsys.hsv_to_rgb(rng.random(), 0.3 + 0.7 * rng.random(), 1.0)
        peak = radiance * (10.0 + 20.0 * rng.random())
        m = b.material("lamp%d" % k, base_color=(0.8, 0.8, 0.8), specular=0.0,
                       emission=(r * peak, g * peak, bl * peak))
        # Counter-clockwise seen from below: the front (emitting side) faces -Y.
        corners = [(cx - h, y, cz - h), (cx + h, y, cz - h), (cx + h, y, cz + h),
                   (cx - h, y, cz + h)]
        b.node("lamp%d" % k, mesh=b.mesh("lamp%d" % k, corners, [0, 1, 2, 0, 2, 3], m))
    eye, target = (0.5 * W, 1.2, D - 0.1), (0.5 * W, 1.6, 0.0)
    b.node("camera", camera=b.perspective_camera(math.radians(70.0), 0.01, aspect=1.0),
           translation=eye, rotation=b.look_at(eye, target))
    return b


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("out", help="the .gltf (or .glb) to write")
    p.add_argument("--lamps", type=int, default=300)
    p.add_argument("--layout", choices=("grid", "random"), default="grid",
                   help="grid: apart on a regular grid (default); random: uniformly random "
                        "positions, some overlapping")
    p.add_argument("--seed", type=int, default=1, help="colours (and random positions)")
    p.add_argument("--lamp-size", type=float, default=LAMP,
                   help="side of a lamp in metres (default %(default)s)")
    p.add_argument("--drop", type=float, default=DROP,
                   help="how far below the ceiling the lamps hang, metres (default %(default)s)")
    p.add_argument("--radiance", type=float, default=1.0,
                   help="scale of every lamp's radiance (default 1: peaks 10 to 30)")
    a = p.parse_args(argv)
    if a.lamps < 1 or a.lamp_size <= 0.0:
        p.error("--lamps and --lamp-size must be positive")
    build(a.lamps, a.seed, a.layout, a.lamp_size, a.drop, a.radiance).write(a.out)


if __name__ == "__main__":
    main()
