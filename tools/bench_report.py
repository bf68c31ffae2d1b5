#!/usr/bin/env python3
"""Turns wavepath-bench's JSON into the README's Performance section (Markdown on stdout).

Usage:
  build/wavepath-bench --benchmark_format=json --benchmark_out=bench.json
  python3 tools/bench_report.py bench.json          # or: ... | python3 tools/bench_report.py -

Per scene, a table of the stage kernels (stage, bounce, rays, time per launch, items/s, and for
the two ray-tracing stages Embree's rays/s on the same rays, embree_ratio = ours / Embree's and
the fraction of rays that hit, ours and Embree's)
and a table of end-to-end figures (samples/s of whole passes, each kernel's and the host's share
of wall time, cold and warm program build and first pass, BVH build and SAH cost, path state per
path, device memory). Above them: the machine and the OpenCL device from the JSON's context, and
the exact command that produced the figures. With --benchmark_repetitions the median aggregate of
each benchmark is used. Python 3 standard library only.
"""

import argparse
import json
import re
import sys

STAGES = [
    "generate_camera_rays", "intersect_closest", "shade_surface", "sample_lights",
    "trace_shadow", "sample_bsdf", "roulette_compact", "shade", "accumulate",
]
END_TO_END = ["render", "bvh_build", "program_build"]
# Google Benchmark appends these to a name (UseManualTime, MinTime, Iterations, ...).
SUFFIX = re.compile(r"^(manual_time|real_time|process_time|[a-z_]+:[^/]*)$")
TO_SECONDS = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}


def base_name(name):
    """'intersect_closest/bounce0/X/manual_time' -> ['intersect_closest', 'bounce0', 'X']."""
    return [p for p in name.split("/") if not SUFFIX.match(p)]


def pick_runs(benchmarks):
    """One entry per benchmark, in first-seen order: the median aggregate when there are
    repetitions, else the (last) iteration run."""
    chosen, order, repetitions = {}, [], 1
    for b in benchmarks:
        key = "/".join(base_name(b.get("run_name", b["name"])))
        if key not in order:  # (not `chosen`: with aggregates only, the mean comes first)
            order.append(key)
        repetitions = max(repetitions, int(b.get("repetitions", 1) or 1))
        if b.get("run_type") == "aggregate":
            if b.get("aggregate_name") == "median":
                chosen[key] = b
        elif key not in chosen or chosen[key].get("run_type") != "aggregate":
            chosen[key] = b
    return [(key, chosen[key]) for key in order if key in chosen], repetitions


def si(value, unit=""):
    """3 significant digits with k/M/G."""
    for factor, prefix in ((1e9, "G"), (1e6, "M"), (1e3, "k")):
        if abs(value) >= factor:
            return f"{value / factor:.3g} {prefix}{unit}".rstrip()
    return f"{value:.3g} {unit}".rstrip()


def seconds(value):
    if value >= 1.0:
        return f"{value:.3g} s"
    if value >= 1e-3:
        return f"{value * 1e3:.3g} ms"
    return f"{value * 1e6:.3g} µs"


def mib(value):
    return f"{value / 2**20:.1f} MiB"


def percent(value):
    return f"{100 * value:.1f}%"


def run_time(b):
    return b["real_time"] * TO_SECONDS.get(b.get("time_unit", "ns"), 1e-9)


def failed(b):
    return b.get("error_occurred") or b.get("skipped")


def stage_rows(runs):
    rows = [
        "| stage | bounce | rays | time per launch | items/s | Embree rays/s | embree_ratio "
        "| hit or occluded, ours / Embree's |",
        "|---|---|--:|--:|--:|--:|--:|--:|",
    ]
    for parts, b in runs:
        stage, bounce = parts[0], parts[1].replace("bounce", "")
        if failed(b):
            rows.append(f"| {stage} | {bounce} | — | skipped: {b.get('error_message', '')} | | | | |")
            continue
        ratio = b.get("embree_ratio")
        embree = b.get("embree_rays_per_second")
        hits = ""
        if "hit_fraction" in b and "embree_hit_fraction" in b:
            hits = f"{percent(b['hit_fraction'])} / {percent(b['embree_hit_fraction'])}"
        rows.append("| {} | {} | {:,} | {} | {} | {} | {} | {} |".format(
            stage, bounce, int(round(b.get("rays", 0))), seconds(run_time(b)),
            si(b.get("items_per_second", 0)), si(embree) if embree is not None else "",
            f"**{ratio:.2f}**" if ratio is not None else "", hits))
    return rows


def end_to_end_rows(runs):
    rows = ["| end to end | |", "|---|--:|"]
    by_family = {parts[0]: b for parts, b in runs}
    for family in END_TO_END:
        b = by_family.get(family)
        if b is not None and failed(b):
            rows.append(f"| {family} | skipped: {b.get('error_message', '')} |")
    r = by_family.get("render")
    if r is not None and not failed(r):
        rows.append(f"| samples/s (whole passes, {int(r.get('passes', 0))} passes) | "
                    f"{si(r.get('items_per_second', 0))} |")
        for stage in STAGES:
            if f"share_{stage}" in r:
                rows.append(f"| share of wall: `{stage}` | {percent(r[f'share_{stage}'])} |")
        rows.append(f"| share of wall: host (launch, sync, read-back) | "
                    f"{percent(r.get('share_host', 0))} |")
        rows.append(f"| path state | {int(r.get('bytes_per_path', 0))} B per path, "
                    f"{int(r.get('wave_size', 0)):,} paths per wave |")
        rows.append(f"| device memory (scene, paths, queues, film) | "
                    f"{mib(r.get('device_memory_bytes', 0))} |")
    p = by_family.get("program_build")
    if p is not None and not failed(p):
        rows.append(f"| program build, cold / warm kernel cache | {seconds(p['cold_build_s'])} / "
                    f"{seconds(p['warm_build_s'])} |")
        rows.append(f"| first finished pass from process start, cold / warm | "
                    f"{seconds(p['cold_first_pass_s'])} / {seconds(p['warm_first_pass_s'])} |")
    v = by_family.get("bvh_build")
    if v is not None and not failed(v):
        rows.append(f"| BVH build ({int(v.get('triangles', 0)):,} triangles) | "
                    f"{seconds(run_time(v))} |")
        rows.append(f"| BVH SAH cost | {v.get('sah_cost', 0):.2f} |")
    return rows


def report(data, source):
    ctx = data.get("context", {})
    runs, repetitions = pick_runs(data.get("benchmarks", []))
    scenes = {}
    for key, b in runs:
        parts = key.split("/")
        scenes.setdefault(parts[-1], []).append((parts[:-1], b))

    out = ["## Performance", ""]
    command = ctx.get("wavepath_command", "build/wavepath-bench --benchmark_format=json")
    out.append(f"Measured with `{command}`; this section is its JSON output turned into Markdown "
               f"by `python3 tools/bench_report.py {source}`.")
    out.append("")
    mhz = ctx.get("mhz_per_cpu")
    out.append(f"- Machine: {ctx.get('host_name', '?')}, {ctx.get('num_cpus', '?')} CPUs"
               + (f" at {mhz} MHz" if mhz else "") + f", {ctx.get('date', '')}")
    out.append(f"- OpenCL device: {ctx.get('opencl_device', '?')} ({ctx.get('opencl_platform', '?')},"
               f" {ctx.get('opencl_compute_units', '?')} compute units; "
               f"{ctx.get('opencl_version', '?')})")
    out.append(f"- Image {ctx.get('image', '?')}, sample 0, background radiance 1; Embree at as many "
               f"threads as the device has compute units"
               + (f"; median of {repetitions} repetitions" if repetitions > 1 else ""))
    out.append("")
    out.append("Stage rows: one launch of the kernel on the state captured from a real render "
               "(bounce 0: camera rays; bounce 1: the first bounce's rays; accumulate: after the "
               "last bounce), device time from its OpenCL profiling event. embree_ratio: our rays/s "
               "over Embree's `rtcIntersect1` / `rtcOccluded1` on the very same rays; the last "
               "column shows they are the same rays (they differ only where our kernels cull back "
               "faces or test alpha, which Embree here does not).")
    for scene, scene_runs in scenes.items():
        out += ["", f"### {scene}", ""]
        stages = [(p, b) for p, b in scene_runs if p[0] in STAGES]
        others = [(p, b) for p, b in scene_runs if p[0] not in STAGES]
        if stages:
            out += stage_rows(stages) + [""]
        if others:
            out += end_to_end_rows(others)
    return "\n".join(out).rstrip() + "\n"


def main():
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("json", nargs="?", default="-",
                        help="wavepath-bench's --benchmark_format=json output (a file, or - for "
                             "stdin; default: stdin)")
    args = parser.parse_args()
    try:
        if args.json == "-":
            data = json.load(sys.stdin)
        else:
            with open(args.json, encoding="utf-8") as f:
                data = json.load(f)
    except (OSError, json.JSONDecodeError) as e:
        sys.exit(f"bench_report.py: error: {args.json}: {e}")
    if not isinstance(data, dict) or "benchmarks" not in data:
        sys.exit(f"bench_report.py: error: {args.json}: not Google Benchmark JSON output")
    sys.stdout.write(report(data, args.json))


if __name__ == "__main__":
    main()
