#!/usr/bin/env python3
"""Measures what kernel specialisation buys: each scene rendered with kernels built for its own
features (--features scene) and with every feature (--features all).

For each scene and build it records samples/s of the render, the program build time with a cold
kernel cache (a fresh POCL_CACHE_DIR, so PoCL compiles everything) and with a warm one (the same
cache again), and the size of the program binary. Prints a Markdown table (the
specialisation table of docs/performance.md) with the machine, the device and this command line.

With --extensions it measures what the material extensions cost instead: each scene (a model that
uses some) rendered as it is and from a copy without those extensions (tools/wavepath_tools/peers_scene.py's
copy_gltf, into a temporary folder), both with kernels for their own features; the extensions are
the layered ones (specular, clearcoat, sheen, anisotropy, iridescence, diffuse transmission,
dispersion), each a kernel feature of its own.

Usage:
  python3 tools/specialization.py [--wavepath build/wavepath] [--spp 16] [--width 320]
                                  [--height 240] [--repeat 3] [--extensions] SCENE...
Standard library only.
"""
import argparse
import json
import os
import platform
import shlex
import subprocess
import sys
import tempfile

from wavepath_tools import peers_scene  # noqa: E402

# The material extensions that are kernel features of their own (kernels/util/features.h).
LAYERED = ("KHR_materials_specular", "KHR_materials_clearcoat", "KHR_materials_sheen",
           "KHR_materials_anisotropy", "KHR_materials_iridescence",
           "KHR_materials_diffuse_transmission", "KHR_materials_dispersion")


def strip_layered(doc):
    """Removes the layered material extensions from every material and from the lists of used and
    required extensions."""
    for m in doc.get("materials", []):
        for name in LAYERED:
            m.get("extensions", {}).pop(name, None)
    for key in ("extensionsUsed", "extensionsRequired"):
        if key in doc:
            doc[key] = [e for e in doc[key] if e not in LAYERED]


def render(wavepath, scene, features, args, cache_dir):
    """One render; returns the JSON report."""
    with tempfile.TemporaryDirectory() as out:
        cmd = [wavepath, "render", scene, "-o", os.path.join(out, "x.exr"), "--json", "-q",
               "--spp", str(args.spp), "--width", str(args.width), "--height", str(args.height),
               "--features", features] + args.extra
        env = dict(os.environ, POCL_CACHE_DIR=cache_dir)
        done = subprocess.run(cmd, env=env, capture_output=True, text=True)
        if done.returncode != 0:
            sys.exit(f"specialization.py: {' '.join(cmd)} failed: {done.stderr.strip()}")
        return json.loads(done.stdout.strip().splitlines()[-1])


def measure(args, scene, features):
    with tempfile.TemporaryDirectory() as cache:
        cold = render(args.wavepath, scene, features, args, cache)
        warm = [render(args.wavepath, scene, features, args, cache) for _ in range(args.repeat)]
    best = max(warm, key=lambda r: r["samples_per_second"])
    return {
        "features": best["features"],
        "samples_per_second": best["samples_per_second"],
        "cold_build": cold["kernel_build_seconds"],
        "warm_build": min(r["kernel_build_seconds"] for r in warm),
        "binary_bytes": best.get("kernel_binary_bytes", 0),
        "device": best["device"],
    }


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scenes", nargs="+", metavar="SCENE")
    p.add_argument("--wavepath", default="build/wavepath")
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--width", type=int, default=320)
    p.add_argument("--height", type=int, default=240)
    p.add_argument("--repeat", type=int, default=3, help="warm runs per build; the best counts")
    p.add_argument("--extra", nargs=argparse.REMAINDER, default=[],
                   help="further wavepath render options (last)")
    p.add_argument("--extensions", action="store_true",
                   help="each scene as it is against a copy without its material extensions")
    args = p.parse_args()
    if args.extensions:
        return extension_table(args)

    rows, device = [], ""
    for scene in args.scenes:
        own = measure(args, scene, "scene")
        full = measure(args, scene, "all")
        device = own["device"]
        rows.append((os.path.basename(scene), own, full))

    print(f"Machine: {platform.node()}, {os.cpu_count()} CPUs; device: {device}.")
    print(f"Command: `python3 tools/specialization.py {' '.join(map(shlex.quote, sys.argv[1:]))}`")
    print()
    print("| scene | features used | samples/s (scene / all) | speed-up | cold build s (scene / all) "
          "| warm build s (scene / all) | binary KiB (scene / all) |")
    print("|---|---|---|---|---|---|---|")
    for name, own, full in rows:
        print(f"| {name} | {own['features']} "
              f"| {own['samples_per_second']:.3g} / {full['samples_per_second']:.3g} "
              f"| {own['samples_per_second'] / full['samples_per_second']:.2f}x "
              f"| {own['cold_build']:.2f} / {full['cold_build']:.2f} "
              f"| {own['warm_build']:.3f} / {full['warm_build']:.3f} "
              f"| {own['binary_bytes'] / 1024:.0f} / {full['binary_bytes'] / 1024:.0f} |")


def extension_table(args):
    rows, device = [], ""
    with tempfile.TemporaryDirectory() as work:
        for scene in args.scenes:
            plain = os.path.join(work, "plain_" + os.path.basename(scene))
            peers_scene.copy_gltf(scene, plain, [strip_layered])
            used = measure(args, scene, "scene")
            without = measure(args, plain, "scene")
            device = used["device"]
            rows.append((os.path.basename(scene), used, without))
    print(f"Machine: {platform.node()}, {os.cpu_count()} CPUs; device: {device}.")
    print(f"Command: `python3 tools/specialization.py {' '.join(map(shlex.quote, sys.argv[1:]))}`")
    print()
    print("| scene | features with the extensions | samples/s (with / without) | cost "
          "| cold build s (with / without) | warm build s (with / without) |")
    print("|---|---|---|---|---|---|")
    for name, used, without in rows:
        print(f"| {name} | {used['features']} "
              f"| {used['samples_per_second']:.3g} / {without['samples_per_second']:.3g} "
              f"| {without['samples_per_second'] / used['samples_per_second']:.2f}x "
              f"| {used['cold_build']:.2f} / {without['cold_build']:.2f} "
              f"| {used['warm_build']:.3f} / {without['warm_build']:.3f} |")


if __name__ == "__main__":
    main()
