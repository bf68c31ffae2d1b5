#!/usr/bin/env python3
"""GPU readiness without a GPU: compiles the wavefront program for NVIDIA and AMD GPUs offline.

For each kernel variant (a set of build options), compiles the whole program (the 9 stage files
in the host's order, one translation unit like host/render/wavefront.cpp's program_source()) with
clang's OpenCL C front end, warnings as errors (-Wall -Wextra -Werror):
  nvptx64  to PTX for sm_86 (the newest clang 14 knows), linked with libclc's builtins, then
           ptxas -arch=sm_90 -v: registers, spill stores/loads and stack frame of each kernel;
  amdgcn   to a gfx90a code object (amdhsa), linked with libclc's builtins; VGPRs, SGPRs,
           spills and scratch per kernel from its metadata (llvm-readelf, when there).
The variants: all features (with and without a two-level BVH, -D WP_BVH_INSTANCES=1, the latter
at width 2 only) and the scene features wavepath derives for each scene (taken from
`wavepath render --json`'s build_options, so they are exactly the host's), each at BVH width 2
and 8, each with and without -D WP_AOV=1; identical option sets are compiled once.

Why clang can stand in for a driver: NVIDIA's and AMD's OpenCL compilers are LLVM based too, and
what breaks on them first (C99 inline functions left unlinked, warnings a stricter front end turns
into errors, unresolved builtins, spills in the traversal loop) shows here. No GPU runs anything:
register counts are ptxas's for clang's PTX, not the NVIDIA driver's own front end.

Exit status: 0 all compiled and no spills in the traversal kernels (intersect_closest,
trace_shadow: a spill there is paid at every BVH step; sm_90's, and gfx90a's VGPR spills when
known: its SGPR spills go to VGPR lanes, not memory); 1 a compile error or warning, or such a
spill; 2 a usage error or wavepath failing; 77 (CTest's skip) when clang lacks the nvptx64 or
amdgcn target, or, after the clang part passed, when ptxas or libclc's nvptx64 library is absent
so registers and spills went unchecked.

  tools/gpu_compile.py                       everything, a table of variant x kernel
  tools/gpu_compile.py --scenes scenes/cornell_box.gltf --no-aov --markdown
                                             the table of docs/performance.md
  tools/gpu_compile.py --quick               all features only (no wavepath runs)
  tools/gpu_compile.py --representative      two of those, each for one target: all features at
                                             width 8 without AOVs for amdgcn, instanced at width 2
                                             with AOVs (a GPU's layout) for nvptx64 and ptxas (each
                                             width, BVH level, AOV setting and target once; the
                                             default test suite)
Environment: PTXAS (default: ptxas on PATH, else /usr/local/cuda/bin/ptxas), WP_LIBCLC_DIR
(default: /usr/lib/clc, Debian's libclc-14), CLANG (default: clang).
"""

import argparse
import concurrent.futures
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile

from wavepath_tools.stage_names import stage_names

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
KERNELS = os.path.join(ROOT, "kernels")
# host/render/pipeline.h's kStageNames: the order program_source() concatenates them in.
STAGES = stage_names()
TRAVERSAL = ("intersect_closest", "trace_shadow")
SKIP = 77

# An OpenCL runtime defines __OPENCL_VERSION__ (the device's version) for the programs it builds;
# clang alone defines only __OPENCL_C_VERSION__, and kernels/shared/compat.h needs the former.
COMMON_FLAGS = ["-x", "cl", "-Xclang", "-finclude-default-header", "-D__OPENCL_VERSION__=120",
                "-O3", "-Wall", "-Wextra", "-Werror", "-I", KERNELS]
# The triples match libclc's bitcode (else clang warns about linking two triples).
TARGETS = {
    "nvptx64": {"triple": "nvptx64-unknown-nvidiacl", "cpu": ["-march=sm_86"],
                "libclc": "nvptx64--nvidiacl.bc", "out": ["-S"], "ext": "ptx"},
    "amdgcn": {"triple": "amdgcn-unknown-amdhsa", "cpu": ["-mcpu=gfx90a", "-nogpulib"],
               "libclc": "amdgcn--amdhsa.bc", "out": ["-c"], "ext": "o"},
}


def fail(message, status=2):
    print("gpu_compile: " + message, file=sys.stderr)
    sys.exit(status)


def find_ptxas():
    if os.environ.get("PTXAS"):
        return os.environ["PTXAS"] if os.access(os.environ["PTXAS"], os.X_OK) else None
    return shutil.which("ptxas") or next(
        (p for p in ["/usr/local/cuda/bin/ptxas"] if os.access(p, os.X_OK)), None)


def libclc(name):
    path = os.path.join(os.environ.get("WP_LIBCLC_DIR", "/usr/lib/clc"), name)
    return path if os.path.isfile(path) else None


def clang_targets(clang):
    try:
        out = subprocess.run([clang, "-print-targets"], capture_output=True, text=True).stdout
    except OSError:
        return set()
    return {line.split()[0] for line in out.splitlines()[1:] if line.strip()}


def wavepath_options(wavepath, scene, features):
    """The build options wavepath uses for `scene` (a 4 x 4, 1 spp render on the default device,
    PoCL here), with the scene's manifest arguments when it has some."""
    args = [wavepath, "render", scene["path"], "--width", "4", "--height", "4", "--spp", "1",
            "--json", "--features", features, "--no-bvh-cache", "-o",
            os.path.join(scene["tmp"], scene["name"] + "." + features + ".pfm")] + scene["args"]
    run = subprocess.run(args, capture_output=True, text=True, cwd=os.path.dirname(scene["path"]))
    if run.returncode != 0:
        fail(f"wavepath failed on {scene['path']}:\n{run.stderr}")
    report = json.loads(run.stdout.strip().splitlines()[-1])
    # The host adds the cache hints (WP_PREFETCH) and packets of rays and paths (WP_SHADOW_PACKET,
    # WP_CLOSEST_PACKET and its WP_PACKET_MASKED_CLOSEST, WP_SHADE_PACKET) for PoCL's CPU devices
    # only: a GPU's build has none, so neither do these.
    options = re.sub(
        r" -D WP_(PREFETCH|SHADOW_PACKET|CLOSEST_PACKET|SHADE_PACKET|PACKET_MASKED_CLOSEST)=\d+", "",
        report["build_options"]
    )
    return options, report["features"]


def manifest_scenes(path):
    with open(path) as f:
        manifest = json.load(f)
    folder = os.path.dirname(path)
    return [(os.path.join(folder, s["file"]), s["args"]) for s in manifest["scenes"]]


def with_width(options, width):
    return re.sub(r"-D WP_BVH_WIDTH=\d+", f"-D WP_BVH_WIDTH={width}", options)


def variants(args, tmp):
    """[{label, options, scenes}]: identical option sets merged, with the scenes sharing each."""
    all_options = "-cl-std=CL1.2 -D WP_BVH_WIDTH=8"  # kernels/util/features.h: undefined = all on
    # A two-level BVH (instanced scenes) is the scene's structure, not a feature: its own variant.
    found = [("all", all_options, "all features"),
             ("all instanced", all_options + " -D WP_BVH_INSTANCES=1", "all features instances")]
    scenes = []
    if not args.quick:
        for spec in args.scenes:
            if spec.endswith(".json"):
                scenes += manifest_scenes(spec)
            else:
                scenes.append((spec, []))
    jobs = []
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        for path, extra in scenes:
            name = os.path.splitext(os.path.basename(path))[0]
            scene = {"path": os.path.abspath(path), "args": extra, "name": name, "tmp": tmp}
            jobs.append((name, pool.submit(wavepath_options, args.wavepath, scene, "scene")))
    for name, job in jobs:
        options, features = job.result()
        found.append((name, options, features))
    out = {}
    for name, options, features in found:
        # A two-level BVH at the GPUs' layout only: at width 8 (the CPUs' layout, which a GPU takes
        # only when asked) trace_shadow spills 4 VGPRs on gfx90a (docs/performance.md, "GPU
        # registers").
        for width in (2,) if "WP_BVH_INSTANCES=1" in options else (2, 8):
            for aov in ([False] if args.no_aov else [False, True]):
                o = with_width(options, width) + (" -D WP_AOV=1" if aov else "")
                label = f"{features} w{width}" + (" aov" if aov else "")
                if o in out:
                    out[o]["scenes"].append(name)
                else:
                    out[o] = {"label": label, "options": o, "scenes": [name]}
    for v in out.values():
        v["targets"] = list(TARGETS)
    if args.representative:
        keep = {"all features w8": ["amdgcn"], "all features instances w2 aov": ["nvptx64"]}
        for v in out.values():
            v["targets"] = keep.get(v["label"], [])
        return [v for v in out.values() if v["targets"]]
    return list(out.values())


def compile_variant(clang, target, variant, program, tmp, index):
    t = TARGETS[target]
    out = os.path.join(tmp, f"v{index}.{t['ext']}")
    cmd = [clang] + COMMON_FLAGS + ["-target", t["triple"]] + t["cpu"] + t["out"]
    lib = libclc(t["libclc"])
    if lib:
        cmd += ["-Xclang", "-mlink-builtin-bitcode", "-Xclang", lib]
    cmd += shlex.split(variant["options"]) + [program, "-o", out]
    run = subprocess.run(cmd, capture_output=True, text=True)
    return out, run.returncode, run.stderr


def ptxas_report(ptxas, ptx):
    """{kernel: {regs, spill_stores, spill_loads, stack}} from ptxas -v; spills of the functions a
    kernel calls (listed after it) count as its own."""
    run = subprocess.run([ptxas, "-arch=sm_90", "-v", ptx, "-o", ptx + ".cubin"],
                         capture_output=True, text=True)
    if run.returncode != 0:
        return None, run.stderr
    kernels, current = {}, None
    for line in run.stderr.splitlines():
        m = re.search(r"Compiling entry function '(\w+)'", line)
        if m:
            current = kernels.setdefault(m.group(1), {"regs": 0, "spill_stores": 0,
                                                      "spill_loads": 0, "stack": None})
            continue
        m = re.search(r"(\d+) bytes stack frame, (\d+) bytes spill stores, (\d+) bytes spill loads",
                      line)
        if m and current is not None:
            if current["stack"] is None:  # the kernel's own line comes first
                current["stack"] = int(m.group(1))
            current["spill_stores"] += int(m.group(2))
            current["spill_loads"] += int(m.group(3))
        m = re.search(r"Used (\d+) registers", line)
        if m and current is not None:
            current["regs"] = int(m.group(1))
    return kernels, run.stderr


def find_readelf():
    return shutil.which("llvm-readelf") or shutil.which("llvm-readelf-14")


def amd_report(readelf, obj):
    """{kernel: {vgprs, sgprs, vgpr_spills, sgpr_spills, scratch}} from the code object's AMDGPU
    metadata, or None without llvm-readelf. Kernel keys are indented 4 spaces (arguments' deeper).
    SGPR spills go to VGPR lanes, not memory; VGPR spills go to scratch memory."""
    if not readelf:
        return None
    notes = subprocess.run([readelf, "--notes", obj], capture_output=True, text=True).stdout
    kernels = []
    for line in notes.splitlines():
        if line.startswith("  - "):
            kernels.append({})
        m = re.match(r"^(?:  - |    )\.(\w+):\s+(\S+)", line)
        if m and kernels:
            kernels[-1][m.group(1)] = m.group(2)
    return {k["name"]: {"vgprs": int(k["vgpr_count"]), "sgprs": int(k["sgpr_count"]),
                        "vgpr_spills": int(k["vgpr_spill_count"]),
                        "sgpr_spills": int(k["sgpr_spill_count"]),
                        "scratch": int(k["private_segment_fixed_size"])}
            for k in kernels if "name" in k}


def markdown(results):
    """Kernels x variants: sm_90 registers / stack, then gfx90a VGPRs / scratch when known."""
    names = [r["variant"]["label"] for r in results]
    tables = [("sm_90", "ptxas", lambda p: (p["regs"], p["stack"], "spills", p["spill_stores"]
                                           + p["spill_loads"]))]
    if all(r["amd"] for r in results):
        tables.append(("gfx90a", "amd", lambda a: (a["vgprs"], a["scratch"], "SGPR spills",
                                                   a["sgpr_spills"], "VGPR spills",
                                                   a["vgpr_spills"])))
    for title, key, cell in tables:
        print(f"\n| {title} | " + " | ".join(names) + " |")
        print("|---|" + "---:|" * len(names))
        for k in STAGES:
            cells = []
            for r in results:
                regs, stack, *spills = cell(r[key][k])
                text = f"{regs} / {stack} B"
                for what, count in zip(spills[::2], spills[1::2]):
                    text += f", {what} {count}" if count else ""
                cells.append(text)
            print(f"| {k} | " + " | ".join(cells) + " |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scenes", nargs="*",
                        default=[os.path.join(ROOT, "scenes", "cornell_box.gltf"),
                                 os.path.join(ROOT, "scenes", "failure", "manifest.json")],
                        help="scenes (.gltf/.glb) or failure manifests (.json, with their args)")
    parser.add_argument("--quick", action="store_true", help="all features only")
    parser.add_argument("--representative", action="store_true",
                        help="all features at width 8 without AOVs, and instanced at width 2 "
                             "with them")
    parser.add_argument("--no-aov", action="store_true", help="no WP_AOV=1 variants")
    parser.add_argument("--markdown", action="store_true",
                        help="print the tables as markdown (kernels x variants)")
    parser.add_argument("--wavepath", default=os.path.join(ROOT, "build", "wavepath"))
    parser.add_argument("-j", "--jobs", type=int, default=os.cpu_count() or 2)
    args = parser.parse_args()

    clang = os.environ.get("CLANG", "clang")
    if not shutil.which(clang):
        print(f"gpu_compile: SKIP: {clang} not found")
        return SKIP
    missing = [t for t in TARGETS if t not in clang_targets(clang)]
    if missing:
        print(f"gpu_compile: SKIP: {clang} lacks the target(s) {', '.join(missing)}")
        return SKIP
    if args.representative:
        args.quick = True
    if not args.quick and not os.access(args.wavepath, os.X_OK):
        fail(f"{args.wavepath} not found (build it, or --quick, or --wavepath PATH)")
    ptxas = find_ptxas()
    nv_lib = libclc(TARGETS["nvptx64"]["libclc"])

    with tempfile.TemporaryDirectory(prefix="wp-gpu-") as tmp:
        program = os.path.join(tmp, "program.cl")
        with open(program, "w") as f:
            f.writelines(f'#include "{s}.cl"\n' for s in STAGES)
        found = variants(args, tmp)
        jobs = []
        with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
            for i, v in enumerate(found):
                for target in v["targets"]:
                    jobs.append((v, target, pool.submit(compile_variant, clang, target, v,
                                                        program, tmp, i)))
        errors = 0
        ptx, amd = {}, {}
        readelf = find_readelf()
        for v, target, job in jobs:
            out, status, stderr = job.result()
            if status != 0 or stderr.strip():
                errors += 1
                print(f"FAIL {target} [{v['label']}] {v['options']}\n{stderr}", file=sys.stderr)
            elif target == "nvptx64":
                ptx[v["options"]] = out
            else:
                amd[v["options"]] = amd_report(readelf, out)
        print(f"gpu_compile: {len(jobs)} compiles of {len(found)} variants, {errors} failed "
              f"(clang -Wall -Wextra -Werror; nvptx64 sm_86, amdgcn gfx90a; libclc "
              f"{'linked' if nv_lib else 'absent'})")
        for v in found:
            print(f"  {v['label']:<40} {', '.join(v['scenes'])}")
        if errors:
            return 1
        if ptx and (not ptxas or not nv_lib):
            why = "ptxas not found (PTXAS=...)" if not ptxas else \
                "libclc's nvptx64--nvidiacl.bc not found (apt-get install libclc-14)"
            print(f"gpu_compile: SKIP: the clang part passed; {why}, so no registers or spills")
            return SKIP

        results, spills = [], []
        with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
            reports = [(v, pool.submit(ptxas_report, ptxas, ptx[v["options"]])
                        if v["options"] in ptx else None) for v in found]
        for v, job in reports:
            kernels, stderr = job.result() if job else ({}, "")
            if job and (kernels is None or set(kernels) != set(STAGES)):
                print(f"FAIL ptxas [{v['label']}]\n{stderr}", file=sys.stderr)
                return 1
            a = amd.get(v["options"])
            results.append({"variant": v, "ptxas": kernels, "amd": a})
            spills += [(v["label"], "sm_90", k) for k in TRAVERSAL
                       if kernels and (kernels[k]["spill_stores"] or kernels[k]["spill_loads"])]
            spills += [(v["label"], "gfx90a", k) for k in TRAVERSAL if a and a[k]["vgpr_spills"]]
        if args.markdown:
            markdown(results)
        else:
            print(f"\n{'':<62}{'sm_90 (ptxas), bytes':<32}gfx90a (clang), spills in registers")
            print(f"{'variant':<40} {'kernel':<21} {'regs':>5} {'spill st':>9} {'spill ld':>9} "
                  f"{'stack':>6} {'vgprs':>6} {'sgprs':>6} {'v spill':>7} {'s spill':>7} "
                  f"{'scratch':>8}")
            for r in results:
                for k in STAGES:
                    p = r["ptxas"][k] if r["ptxas"] else dict.fromkeys(
                        ["regs", "spill_stores", "spill_loads", "stack"], "-")
                    a = r["amd"][k] if r["amd"] else dict.fromkeys(
                        ["vgprs", "sgprs", "vgpr_spills", "sgpr_spills", "scratch"], "-")
                    print(f"{r['variant']['label']:<40} {k:<21} {p['regs']:>5} "
                          f"{p['spill_stores']:>9} {p['spill_loads']:>9} {p['stack']:>6} "
                          f"{a['vgprs']:>6} {a['sgprs']:>6} {a['vgpr_spills']:>7} "
                          f"{a['sgpr_spills']:>7} {a['scratch']:>8}")
        for label, target, k in spills:
            print(f"FAIL spills in traversal kernel {k} for {target} [{label}]", file=sys.stderr)
        return 1 if spills else 0


if __name__ == "__main__":
    sys.exit(main())
