#!/usr/bin/env python3
"""What PoCL vectorises: for each stage kernel, whether LLVM's loop vectoriser vectorised PoCL's
work-item loop (the loop over a work-group's work-items that PoCL wraps around a kernel on a CPU),
at what width (vectorization factor and interleave count), and if not, the reason LLVM gives.

How: a tiny render (16 x 16, 1 spp) per pipeline (fused and split: together they launch every
stage kernel), side by side, each with an empty PoCL cache, POCL_VECTORIZER_REMARKS=1 (PoCL
prints LLVM's optimisation remarks as it compiles a kernel for its launch) and
POCL_EXTRA_BUILD_FLAGS=-g (the remarks then carry source locations; the loop vectoriser's remarks
are the same, in the same order, without it: checked for the three default configurations at
6f78751). For each kernel PoCL prints the remarks of -O3 over the kernel alone (its own loops),
then, after wrapping the work-item loops around it and inlining it into its launchers, those of
-O3 again: a loop vectoriser verdict there at a loop the first part does not have is a work-item
loop's. A kernel with barriers (the queue pushes) has a work-item loop per region between them.
LLVM vectorises innermost loops only, so a work-item loop around a loop of the kernel gets no
remark: that kernel runs one work-item at a time ("not innermost", with the kernel's loops). The
kernels launched and their work-group size come from PoCL's cache (a folder per kernel and size),
the target from its CL_DEVICE_VERSION.

  tools/vectorization.py                    the table of docs/performance.md: the Cornell box with
                                            its features and with all, and DamagedHelmet (when
                                            ../shared/assets has it) with its own
  tools/vectorization.py --json SCENE:all   every work-item loop's verdict and location, as JSON
  tools/vectorization.py --check SCENE      the ctest: exit 1 when a kernel launched has no verdict

Exit status: 0; 1 with --check when a launched kernel got no verdict (the remarks did not parse);
2 when wavepath fails or the remarks are not as expected; 77 (CTest's skip) when wavepath's default
device is not PoCL's. Standard library only.
"""

import argparse
import concurrent.futures
import ctypes
import glob
import json
import os
import re
import shlex
import subprocess
import sys
import tempfile

from wavepath_tools.pocl_remarks import analyse, default_device, verdict
from wavepath_tools.stage_names import stage_names

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
KERNELS = os.path.join(ROOT, "kernels")
HELMET = os.path.join(ROOT, "..", "shared", "assets", "models", "DamagedHelmet",
                      "DamagedHelmet.glb")
PIPELINES = ("fused", "split")
SKIP = 77

def fail(message, status=2):
    print("vectorization.py: " + message, file=sys.stderr)
    sys.exit(status)


def launched(cache):
    """{kernel: work-group size} of the kernels PoCL compiled for a launch (its cache holds a
    folder NAME/X-Y-Z-... per kernel and size; 0-0-0 is the generic one for program binaries)."""
    out = {}
    for path in glob.glob(os.path.join(cache, "*", "*", "*", "*")):
        m = re.match(r"(\d+)-(\d+)-(\d+)", os.path.basename(path))
        if m and m.groups() != ("0", "0", "0"):
            out[os.path.basename(os.path.dirname(path))] = "x".join(m.groups())
    return out


def render(wavepath, scene, features, pipeline):
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, POCL_VECTORIZER_REMARKS="1", POCL_CACHE_DIR=os.path.join(tmp, "c"),
                   POCL_EXTRA_BUILD_FLAGS=(os.environ.get("POCL_EXTRA_BUILD_FLAGS", "") + " -g"))
        cmd = [wavepath, "render", scene, "-o", os.path.join(tmp, "x.pfm"), "-q", "--json",
               "--width", "16", "--height", "16", "--spp", "1", "--no-kernel-cache",
               "--features", features, "--pipeline", pipeline]
        run = subprocess.run(cmd, env=env, capture_output=True, text=True, errors="replace")
        if run.returncode != 0:
            fail(f"{shlex.join(cmd)} failed:\n{run.stderr.strip()}")
        # The JSON report is the last line, after remarks with no newline between them.
        last = run.stdout.rstrip().splitlines()[-1]
        report = json.loads(last[last.index('{"'):])
        return report, analyse(run.stdout + run.stderr), launched(env["POCL_CACHE_DIR"])


def pocl_target(device_name):
    """PoCL's LLVM target (triple and CPU) for the device: the end of its CL_DEVICE_VERSION,
    "OpenCL 3.0 PoCL HSTR: pthread-x86_64-pc-linux-gnu-skylake-avx512", through libOpenCL."""
    try:
        cl = ctypes.CDLL("libOpenCL.so.1")
    except OSError:
        return None
    ptr, uint, size = ctypes.c_void_p, ctypes.c_uint, ctypes.c_size_t
    cl.clGetPlatformIDs.argtypes = [uint, ctypes.POINTER(ptr), ctypes.POINTER(uint)]
    cl.clGetDeviceIDs.argtypes = [ptr, ctypes.c_uint64, uint, ctypes.POINTER(ptr),
                                  ctypes.POINTER(uint)]
    cl.clGetDeviceInfo.argtypes = [ptr, uint, size, ctypes.c_char_p, ctypes.POINTER(size)]

    def info(device, what):
        buf = ctypes.create_string_buffer(4096)
        cl.clGetDeviceInfo(device, what, len(buf), buf, None)
        return buf.value.decode(errors="replace").strip()

    platforms, n = (ptr * 16)(), uint()
    if cl.clGetPlatformIDs(16, platforms, ctypes.byref(n)) != 0:
        return None
    for platform in platforms[:n.value]:
        devices, m = (ptr * 64)(), uint()
        if cl.clGetDeviceIDs(platform, 0xFFFFFFFF, 64, devices, ctypes.byref(m)) != 0:
            continue
        for device in devices[:m.value]:
            if info(device, 0x102B) == device_name:  # CL_DEVICE_NAME
                hstr = re.search(r"HSTR: (\S+)", info(device, 0x102F))  # CL_DEVICE_VERSION
                return hstr.group(1) if hstr else None
    return None


def parse_configs(args):
    if not args.configs:
        configs = [(os.path.join(ROOT, "scenes", "cornell_box.gltf"), "scene"),
                   (os.path.join(ROOT, "scenes", "cornell_box.gltf"), "all")]
        if os.path.isfile(HELMET):
            configs.append((os.path.normpath(HELMET), "scene"))
        return configs
    out = []
    for c in args.configs:
        scene, _, features = c.rpartition(":")
        if features not in ("scene", "all"):
            scene, features = c, "scene"
        out.append((scene, features))
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                epilog=__doc__.split("\n\n", 1)[1],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("configs", nargs="*", metavar="SCENE[:FEATURES]",
                   help="a scene and --features scene (default) or all; default: see below")
    p.add_argument("--wavepath", default=os.path.join(ROOT, "build", "wavepath"),
                   help="the wavepath binary (default: build/wavepath)")
    p.add_argument("--pipeline", action="append", choices=PIPELINES,
                   help="only this pipeline (repeatable; default both)")
    p.add_argument("--json", action="store_true", help="JSON instead of Markdown")
    p.add_argument("--check", action="store_true",
                   help="exit 1 when a launched kernel has no verdict")
    args = p.parse_args()
    device, row = default_device(args.wavepath)
    if device is None:
        fail(f"`{args.wavepath} devices` found no device", SKIP)
    if "Portable Computing Language" not in row:
        fail(f"the default device ({device}) is not PoCL's: nothing to read", SKIP)

    results, missing = [], []
    for scene, features in parse_configs(args):
        entry = {"scene": os.path.relpath(scene, ROOT), "features_option": features,
                 "pipelines": {}}
        pipelines = args.pipeline or PIPELINES
        with concurrent.futures.ThreadPoolExecutor(len(pipelines)) as pool:
            runs = list(pool.map(lambda pl: render(args.wavepath, scene, features, pl), pipelines))
        for pipeline, (report, kernels, sizes) in zip(pipelines, runs):
            order = list(kernels)[:len(sizes)]
            if sorted(order) != sorted(sizes):
                fail(f"{pipeline} on {scene}: PoCL compiled {sorted(sizes)} for the launches, "
                     f"but its remarks name {order} first")
            entry.update(features=report["features"], build_options=report["build_options"])
            entry["pipelines"][pipeline] = {
                name: dict(kernels[name], work_group_size=sizes[name],
                           verdict=verdict(kernels[name])) for name in order}
            missing += [f"{entry['scene']} --features {features} --pipeline {pipeline}: {name}"
                        for name in order if verdict(kernels[name]) is None]
        results.append(entry)

    if args.json:
        json.dump({"device": device, "target": pocl_target(device), "configurations": results},
                  sys.stdout, indent=1)
        print()
    else:
        print_markdown(results, device, pocl_target(device))
    for m in missing:
        print(f"vectorization.py: no verdict for {m}", file=sys.stderr)
    if args.check and missing:
        sys.exit(1)


def print_markdown(results, device, target):
    sizes = {k["work_group_size"] for r in results for pl in r["pipelines"].values()
             for k in pl.values()}
    print(f"Device: {device}; PoCL's LLVM target: {target or 'unknown'}; "
          f"work-group size {', '.join(sorted(sizes))}.")
    print(f"Command: `python3 tools/vectorization.py {shlex.join(sys.argv[1:])}`")
    print()
    head = [os.path.basename(r["scene"]) + (", `--features all`" if r["features_option"] == "all"
                                             else f" ({r['features'] or 'no features'})")
            for r in results]
    print("| kernel | " + " | ".join(head) + " |")
    print("|---" * (len(head) + 1) + "|")
    for name in stage_names():
        cells = []
        for r in results:
            seen = {pl: k[name]["verdict"] for pl, k in r["pipelines"].items() if name in k}
            texts = list(dict.fromkeys(seen.values()))
            if len(texts) > 1:  # the pipelines disagree (they build the same program)
                cells.append("<br>".join(f"{pl}: {t}" for pl, t in seen.items()))
            else:
                cells.append((texts[0] or "no verdict") if texts else "–")
        print(f"| {name} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
