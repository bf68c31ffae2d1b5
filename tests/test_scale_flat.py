#!/usr/bin/env python3
"""Scale: a large flattened scene peaks at its packed size plus a bounded overhead (ctest).

scenes/make_big_scene.py writes a terrain of 2 million triangles, each with its own three vertices
(the worst case for memory), into a temporary folder; `wavepath render` draws it at 320 x 240, one
sample per pixel: first with an empty BVH cache (the BVH is built), then again (the BVH is read
from the cache). The program's own memory (OpenCL runtime, kernels, path state and film: the same
for any scene at this image size and feature set) is the peak resident size of the same render of
the terrain cut to 2 triangles. Over it, with `packed` the packed scene's bytes (`scene_bytes`):

- BVH from the cache: peak <= packed + 16 MiB + 4 bytes a triangle. Derivation: the CLI frees the
  scene's and the BVH's host arrays while it packs them (host/device/device_scene.h, HostArrays):
  each array is written 16 MiB at a time (kReleaseSlice), after each slice the pages of its host
  sources that it has read are returned, and the sources are freed once it is done; the packed
  buffers' pages become resident only as they are written. At any moment the host holds the
  packed bytes written so far, the unread rest of the sources of the array being written (at most
  what its unwritten part packs: a 3-float vertex packs into 4 floats, indices and material into
  16 bytes a triangle either way, BVH arrays as they are), at most one slice of sources read but
  not returned (plus a page each), and the host arrays of the arrays after it (each at most its
  packed size): at most packed + one slice. The light table's 4 bytes a triangle (its per-triangle
  light index) stay on the host beside their packed copy. Before packing starts, the loader holds
  the file's bytes and the arrays read from them, and reading the cached BVH its arrays beside the
  scene's: for this terrain both are below the bound (docs/reliability.md#scene-size).
- BVH built: peak <= packed + the largest packed array (`wavepath info --json`). The build adds
  Embree's tree beside the scene's arrays and the finished BVH (measured: under a tenth of the
  packed size here, 8% at 40 million triangles); packing stays within the bound above.

Without the freeing, the scene's and the BVH's host arrays are held beside the whole packed scene
(measured with the BVH built: 860 MiB over the program, 213 MiB over its bound; both checks fail).

Usage: test_scale_flat.py WAVEPATH_BINARY   (numpy needed by the generator: Debian's python3-numpy)
"""

import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
GENERATOR = os.path.join(HERE, "..", "scenes", "make_big_scene.py")
TRIANGLES = 2 * 10 ** 6
RENDER = ["--width", "320", "--height", "240", "--spp", "1", "--json"]
RELEASE_SLICE = 16 << 20  # kReleaseSlice, host/device/device_scene.cpp
LIGHT_INDEX_BYTES = 4     # the light table's per-triangle light index (LightTable::tri_light)
MIB = 1 << 20


def peak_render(wavepath, scene, out, env):
    """Renders `scene` in a child; returns its JSON report and its peak resident bytes."""
    # getrusage(RUSAGE_CHILDREN) is the largest of the waited-for children (Linux: KiB): a fresh
    # process each time, so that the value is this render's own.
    probe = ("import resource, subprocess, sys\n"
             "r = subprocess.run(sys.argv[1:], capture_output=True, text=True)\n"
             "sys.stderr.write(r.stderr)\n"
             "print(r.returncode)\n"
             "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)\n"
             "print(r.stdout.strip().splitlines()[-1] if r.stdout.strip() else '{}')\n")
    run = subprocess.run([sys.executable, "-c", probe, wavepath, "render", scene, *RENDER, "-o",
                          out], capture_output=True, text=True, env=env, check=True)
    status, peak_kib, report = run.stdout.splitlines()
    if int(status) != 0:
        sys.exit(f"FAIL: wavepath render {scene} exited {status}: {run.stderr.strip()}")
    return json.loads(report), int(peak_kib) * 1024


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    wavepath = sys.argv[1]
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, WAVEPATH_CACHE_DIR=os.path.join(tmp, "cache"))
        scenes = {}
        for name, triangles in (("small", 2), ("big", TRIANGLES)):
            scenes[name] = os.path.join(tmp, name + ".glb")
            subprocess.run([sys.executable, GENERATOR, scenes[name], "--triangles",
                            str(triangles)], check=True, stdout=subprocess.DEVNULL)
        out = os.path.join(tmp, "out.png")
        peak_render(wavepath, scenes["small"], out, env)  # builds and caches the program
        _, base = peak_render(wavepath, scenes["small"], out, env)
        built, built_peak = peak_render(wavepath, scenes["big"], out, env)
        cached, cached_peak = peak_render(wavepath, scenes["big"], out, env)
        info = subprocess.run([wavepath, "info", scenes["big"], "--json"], capture_output=True,
                              text=True, env=env, check=True)
    width = 8 if "WP_BVH_WIDTH=8" in built["build_options"] else 2
    layout = next(b for b in json.loads(info.stdout)["bvh"] if b["width"] == width)
    packed = built["scene_bytes"]
    largest_name, largest = max(layout["scene_arrays"].items(), key=lambda kv: kv[1])
    cached_bound = packed + RELEASE_SLICE + LIGHT_INDEX_BYTES * TRIANGLES
    built_bound = packed + largest
    print(f"{TRIANGLES} triangles, BVH width {width}, packed {packed / MIB:.0f} MiB, program "
          f"{base / MIB:.0f} MiB; over the program: BVH cached {(cached_peak - base) / MIB:.0f} "
          f"MiB (bound {cached_bound / MIB:.0f}), BVH built {(built_peak - base) / MIB:.0f} MiB "
          f"(bound: + {largest_name} array {built_bound / MIB:.0f})")
    checks = [
        ("packed size agrees with wavepath info", layout["scene_bytes"] == packed),
        ("BVH built, then read from the cache", not built["bvh_cached"] and cached["bvh_cached"]),
        ("triangles", built["triangles"] == TRIANGLES),
        ("no NaN/Inf sample", built["nonfinite_samples"] == 0),
        (f"cached: {cached_peak - base} bytes over the program <= {cached_bound}",
         cached_peak - base <= cached_bound),
        (f"built: {built_peak - base} bytes over the program <= {built_bound}",
         built_peak - base <= built_bound),
    ]
    failures = [name for name, ok in checks if not ok]
    if failures:
        sys.exit("FAIL: " + "; ".join(failures))
    return 0


if __name__ == "__main__":
    sys.exit(main())
