#!/usr/bin/env python3
"""Scale: a billion triangles by instancing render in under 2 GB (ctest, scene tier).

scenes/make_instanced_scene.py writes one mesh of 10^5 triangles placed by 10^4 nodes (10^9
triangles in the world) into a temporary folder; `wavepath render` draws it at 640 x 480, one
sample per pixel. Checked: the render completes (status 0, no NaN/Inf sample), the program is the
two-level one (WP_BVH_INSTANCES) with the mesh stored once (10^5 triangles, 10^4 instances,
10^9 in the world), rays hit the field (more rays than camera rays: paths continue from it), and
the child's peak resident size (getrusage of the waited-for child, Linux: KiB) stays under 2 GiB.
Flattened, the same scene would need about 40 GB for its vertex references alone (16 bytes a
triangle), so the bound holds only if the mesh is stored once.

Usage: test_scale_instances.py WAVEPATH_BINARY
"""

import json
import os
import resource
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
GENERATOR = os.path.join(HERE, "..", "scenes", "make_instanced_scene.py")
TRIANGLES, INSTANCES = 10 ** 5, 10 ** 4
WIDTH, HEIGHT = 640, 480
LIMIT_KIB = 2 * 1024 * 1024


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    wavepath = sys.argv[1]
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        scene = os.path.join(tmp, "field.glb")
        subprocess.run([sys.executable, GENERATOR, scene, "--triangles", str(TRIANGLES),
                        "--instances", str(INSTANCES)], check=True)
        env = dict(os.environ, WAVEPATH_CACHE_DIR=os.path.join(tmp, "cache"))
        run = subprocess.run([wavepath, "render", scene, "--width", str(WIDTH), "--height",
                              str(HEIGHT), "--spp", "1", "--json", "-o",
                              os.path.join(tmp, "field.png")],
                             capture_output=True, text=True, env=env)
        peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss  # KiB, the largest child
        if run.returncode != 0:
            sys.exit(f"FAIL: wavepath exited {run.returncode}: {run.stderr.strip()}")
        report = json.loads(run.stdout.strip().splitlines()[-1])
        checks = [
            ("nonfinite_samples", report["nonfinite_samples"] == 0),
            ("two-level program", "WP_BVH_INSTANCES=1" in report["build_options"]),
            ("mesh stored once", report["triangles"] == TRIANGLES),
            ("instances", report["instances"] == INSTANCES),
            ("world triangles", report["world_triangles"] == TRIANGLES * INSTANCES),
            ("rays beyond the camera's", report["rays"] > WIDTH * HEIGHT),
            (f"peak {peak} KiB under {LIMIT_KIB} KiB", peak < LIMIT_KIB),
        ]
        failures = [name for name, ok in checks if not ok]
        print(f"{TRIANGLES * INSTANCES} triangles ({INSTANCES} instances of {TRIANGLES}): "
              f"{report['seconds']:.2f} s for {WIDTH}x{HEIGHT}x1, scene {report['scene_bytes']} "
              f"bytes, peak resident {peak / 1024:.0f} MiB")
    if failures:
        sys.exit("FAIL: " + "; ".join(failures))
    return 0


if __name__ == "__main__":
    sys.exit(main())
