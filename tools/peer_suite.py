#!/usr/bin/env python3
"""Peer suite: wavepath against Mitsuba 3 (both samplers) and Cycles on the models users render,
at 512 x 512 and 1280 x 720, one page: time to relMSE 1e-2 and 1e-3 and the cost of a sample.

    tools/peer_suite.py                              every scene and size (hours on 2 cores)
    tools/peer_suite.py --scenes cornell_box,DamagedHelmet --sizes 512x512
    tools/peer_suite.py --page-only                  the page from the entries measured so far

Each entry (a scene at a size) is one run of tools/peers.py --pbr (its page, chart and
references go to docs/peers_suite/SCENE_WxH.md and .png; its work folder, with the cached
converged references, to build/peer-suite/SCENE_WxH/), with --repeat 3 --statistic median: the
renderers take turns at each sample count, three times, and a run's time is the median of its
three. Every renderer is measured against its own converged reference (see tools/peers.py
--help, PBR MODE), so the times compare the renderers' speed of convergence to their own images;
the references' image means are compared on each entry's page.

An entry that finished is kept (build/peer-suite/SCENE_WxH/entry.json) and not run again unless
--rerun names it: the suite can be run a few scenes at a time, and the page always shows every
entry measured so far, with the commit and the date each was measured at, and lists the ones
not yet measured with the command that measures them.

Time to a target is tools/peers.py's (log-log interpolation between the runs around it; past the
largest run, relMSE ~ 1/time, marked ~). The cost of a sample is the marginal one, without
start-up: (time of the largest run - time of the one before) / (their difference in pixel
samples), in nanoseconds per pixel sample.
"""

import argparse
import datetime
import json
import os
import subprocess
import sys

TOOLS = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(TOOLS)
sys.path.insert(0, TOOLS)
import peers  # noqa: E402

ASSETS = os.path.join(REPO, "..", "shared", "assets")
STUDIO = os.path.join(ASSETS, "env", "studio_small_03_1k.hdr")


def model(name, file):
    return os.path.join(ASSETS, "models", name, file)


# (key, glTF file, tools/peers.py options beyond the common ones, what it exercises). The models
# are lit by the studio map; the Cornell box by its own lamp, seen through its own camera.
SCENES = [
    ("cornell_box", os.path.join(REPO, "scenes", "cornell_box.gltf"), [],
     "the box as shipped: glTF's dielectric layer over diffuse, one area light"),
    ("DamagedHelmet", model("DamagedHelmet", "DamagedHelmet.glb"),
     ["--env", STUDIO, "--orbit", "0,90,2.2"],
     "textures, normal map, emission; filling the frame"),
    ("FlightHelmet", model("FlightHelmet", "FlightHelmet.gltf"),
     ["--env", STUDIO, "--orbit", "30,80,0.9"], "alpha masks, many textured materials"),
    ("SheenChair", model("SheenChair", "SheenChair.gltf"), ["--env", STUDIO],
     "sheen, texture transforms"),
    ("ClearCoatCarPaint", model("ClearCoatCarPaint", "ClearCoatCarPaint.glb"), ["--env", STUDIO],
     "clearcoat"),
    ("GlassHurricaneCandleHolder",
     model("GlassHurricaneCandleHolder", "GlassHurricaneCandleHolder.glb"), ["--env", STUDIO],
     "transmission and volume"),
]
SIZES = ["512x512", "1280x720"]
TARGETS = (1e-2, 1e-3)
RENDERERS = ["wavepath", "mitsuba", "mitsuba-ld", "cycles"]
PAGE = os.path.join(REPO, "docs", "peers_suite.md")
WORK = os.path.join(REPO, "build", "peer-suite")


def log(msg):
    print("peer_suite: " + msg, file=sys.stderr, flush=True)


def parse_args(argv):
    p = argparse.ArgumentParser(prog="peer_suite.py", description=__doc__.split("\n\n")[0],
                                epilog=__doc__.split("\n\n", 2)[2],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    keys = [s[0] for s in SCENES]
    p.add_argument("--scenes", default=",".join(keys),
                   help="comma-separated subset of %s" % ", ".join(keys))
    p.add_argument("--sizes", default=",".join(SIZES),
                   help="comma-separated WIDTHxHEIGHT (default %(default)s)")
    p.add_argument("--renderers", default=",".join(RENDERERS),
                   help="comma-separated subset of %s; Cycles may be left out at 1280x720 "
                        "where its hours do not fit (default: all)" % ", ".join(RENDERERS))
    p.add_argument("--spp", default="4,16,64,256",
                   help="the sweep's sample counts, powers of 2 for Mitsuba's ldsampler "
                        "(default %(default)s)")
    p.add_argument("--ref-spp", type=int, default=2048,
                   help="samples per pixel of each renderer's converged reference (default "
                        "%(default)s)")
    p.add_argument("--repeat", type=int, default=3,
                   help="alternated repetitions of the sweep; a run's time is their median "
                        "(default %(default)s)")
    p.add_argument("--rerun", default="",
                   help="comma-separated entries (SCENE or SCENE_WxH) to measure again")
    p.add_argument("--page-only", action="store_true",
                   help="write the page from the entries measured so far, run nothing")
    p.add_argument("--out", default=None, help="the page (default docs/peers_suite.md)")
    p.add_argument("--work", default=None, help="work folders (default build/peer-suite)")
    p.add_argument("--quick", action="store_true",
                   help="a smoke run of the whole chain: 64 x 64, spp 4,16, references of 64 "
                        "spp, no repetition, into build/peer-suite-quick/ (page included)")
    p.add_argument("--venv", help="tools/peers.py's --venv (default: its own, build/peers-venv)")
    p.add_argument("--python", help="tools/peers.py's --python (default: its own)")
    a = p.parse_args(argv)
    a.scenes = [s for s in a.scenes.split(",") if s]
    bad = [s for s in a.scenes if s not in keys]
    if bad:
        p.error("unknown scene(s) %s (the suite's: %s)" % (", ".join(bad), ", ".join(keys)))
    try:
        a.sizes = [tuple(int(x) for x in s.split("x")) for s in a.sizes.split(",") if s]
    except ValueError:
        p.error("--sizes takes WIDTHxHEIGHT, e.g. 512x512,1280x720")
    if not a.sizes or any(len(s) != 2 or min(s) < 1 for s in a.sizes):
        p.error("--sizes takes WIDTHxHEIGHT, e.g. 512x512,1280x720")
    a.renderers = [r for r in a.renderers.split(",") if r]
    if "wavepath" not in a.renderers or any(r not in RENDERERS for r in a.renderers):
        p.error("--renderers: wavepath and any of %s" % ", ".join(RENDERERS[1:]))
    a.rerun = set(r for r in a.rerun.split(",") if r)
    a.page_sizes = SIZES
    if a.quick:
        a.sizes, a.spp, a.ref_spp, a.repeat = [(64, 64)], "4,16", 64, 1
        a.page_sizes = ["64x64"]
        a.work = a.work or WORK + "-quick"
        a.out = a.out or os.path.join(a.work, "peers_suite.md")
    a.work, a.out = a.work or WORK, a.out or PAGE
    return a


def entry_key(scene, size):
    return "%s_%dx%d" % (scene, size[0], size[1])


def commit():
    try:
        return subprocess.run(["git", "-C", REPO, "rev-parse", "--short", "HEAD"],
                              stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def peers_command(a, scene, size):
    key, path, extra, _ = scene
    name = entry_key(key, size)

    def rel(p):  # the pages show the command: paths from the repository's root, where it runs
        return os.path.relpath(p, REPO)
    venv = ["--venv", a.venv] if a.venv else []
    python = ["--python", a.python] if a.python else []
    return ([sys.executable, "tools/peers.py", "--pbr", "--scene", rel(path),
             "--width", str(size[0]), "--height", str(size[1]), "--spp", a.spp,
             "--ref-spp", str(a.ref_spp), "--repeat", str(a.repeat), "--statistic", "median",
             "--ref-chunks", "8" if a.ref_spp % 8 == 0 else "2",
             "--renderers", ",".join(a.renderers)] + venv + python
            + ["--work", rel(os.path.join(a.work, name)),
               "--out", rel(os.path.join(os.path.dirname(a.out), "peers_suite", name + ".md"))]
            + [rel(x) if x.endswith(".hdr") else x for x in extra])


def summarize(rows, width, height):
    """Per renderer: times to TARGETS (seconds, mark) and the marginal cost of a pixel sample
    (ns), from tools/peers.py's runs.json rows."""
    out = {}
    for r in sorted(set(x["renderer"] for x in rows)):
        runs = sorted((x for x in rows if x["renderer"] == r), key=lambda x: x["spp"])
        points = [(x["seconds"], x["rel_mse"]) for x in runs]
        cost = None
        if len(runs) >= 2 and runs[-1]["spp"] > runs[-2]["spp"]:
            dt = runs[-1]["seconds"] - runs[-2]["seconds"]
            # None where noise outweighs the samples' time (tiny images: --quick)
            cost = (1e9 * dt / ((runs[-1]["spp"] - runs[-2]["spp"]) * width * height)
                    if dt > 0.0 else None)
        out[r] = {"targets": [peers.time_to_target(points, t) for t in TARGETS],
                  "ns_per_sample": cost, "mean_ratio": runs[-1]["mean_ratio"]}
    return out


def run_entry(a, scene, size):
    name = entry_key(scene[0], size)
    work = os.path.join(a.work, name)
    cmd = peers_command(a, scene, size)
    log("%s: %s" % (name, " ".join(cmd[1:])))
    proc = subprocess.run(cmd, cwd=REPO)
    if proc.returncode != 0:
        log("%s: tools/peers.py failed (%d); the entry is left unmeasured"
            % (name, proc.returncode))
        return False
    with open(os.path.join(work, "runs.json")) as f:
        rows = json.load(f)
    entry = {"scene": scene[0], "width": size[0], "height": size[1], "commit": commit(),
             "date": datetime.date.today().isoformat(), "command": " ".join(
                 ["tools/peer_suite.py", "--scenes", scene[0], "--sizes", "%dx%d" % size]),
             "renderers": a.renderers, "summary": summarize(rows, *size), "rows": rows}
    with open(os.path.join(work, "entry.json"), "w") as f:
        json.dump(entry, f, indent=1)
    return True


def load_entries(a):
    entries = {}
    for scene in SCENES:
        for size in a.page_sizes:
            size = tuple(int(x) for x in size.split("x"))
            path = os.path.join(a.work, entry_key(scene[0], size), "entry.json")
            if os.path.exists(path):
                with open(path) as f:
                    entries[(scene[0], size)] = json.load(f)
    return entries


def fmt(t):
    seconds, mark = t
    return "—" if seconds is None else peers.fmt_t(seconds, mark)


def write_page(a, entries):
    L = ["# wavepath against Mitsuba 3 and Cycles on the models users render", "",
         "Generated by `tools/peer_suite.py` (its `--help` says how each figure is made); each "
         "entry's own page, with its chart, every run and the comparison of the renderers' "
         "references, is linked from its row. Every renderer is measured against its own "
         "converged reference; times are whole processes (start-up and kernel or JIT "
         "compilation included, the caches warm), the median of the alternated runs. "
         "Machine: %s, %d cores." % (peers._cpu_name(), os.cpu_count() or 1), ""]
    for size in a.page_sizes:
        w, h = (int(x) for x in size.split("x"))
        have = [(s, entries[(s[0], (w, h))]) for s in SCENES if (s[0], (w, h)) in entries]
        L += ["## %d × %d" % (w, h), ""]
        if have:
            L += ["Time to relMSE (seconds) and the ratio of wavepath's time to the fastest "
                  "peer's (below 1: wavepath is faster; the target is 0.8 at 1e-3).", "",
                  "| scene | target | wavepath | Mitsuba 3 | Mitsuba 3 ldsampler | Cycles | "
                  "wavepath / fastest peer |", "|---|---|---|---|---|---|---|"]
            for scene, e in have:
                s = e["summary"]
                link = "[%s](peers_suite/%s.md)" % (scene[0], entry_key(scene[0], (w, h)))
                for k, target in enumerate(TARGETS):
                    cells = [fmt(s[r]["targets"][k]) if r in s else "not run"
                             for r in RENDERERS]
                    peer_times = [s[r]["targets"][k][0] for r in RENDERERS[1:]
                                  if r in s and s[r]["targets"][k][0]]
                    own = s["wavepath"]["targets"][k][0]
                    ratio = ("%.2f" % (own / min(peer_times)) if own and peer_times else "—")
                    L.append("| %s | %g | %s | %s |" % (link if k == 0 else "", target,
                                                        " | ".join(cells), ratio))
            L += ["", "The cost of a pixel sample (ns, marginal: start-up excluded) and each "
                  "renderer's image mean over its reference's at its largest run.", "",
                  "| scene | wavepath | Mitsuba 3 | Mitsuba 3 ldsampler | Cycles | measured at |",
                  "|---|---|---|---|---|---|"]
            for scene, e in have:
                s = e["summary"]
                cells = [("%.0f (%.3f)" % (s[r]["ns_per_sample"], s[r]["mean_ratio"])
                          if r in s and s[r]["ns_per_sample"] else "—") for r in RENDERERS]
                L.append("| %s | %s | %s, %s |" % (scene[0], " | ".join(cells), e["commit"],
                                                   e["date"]))
            L.append("")
        missing = [s for s in SCENES if (s[0], (w, h)) not in entries]
        if missing:
            L += ["Not measured yet: %s (`tools/peer_suite.py --scenes %s --sizes %s`)."
                  % (", ".join(s[0] for s in missing), ",".join(s[0] for s in missing), size),
                  ""]
    L += ["## The scenes", "", "| scene | file | options | what it exercises |", "|---|---|---|---|"]
    for key, path, extra, what in SCENES:
        L.append("| %s | `%s` | %s | %s |"
                 % (key, os.path.relpath(path, REPO), "`%s`" % " ".join(
                     os.path.relpath(x, REPO) if x.endswith(".hdr") else x for x in extra)
                     if extra else "its own camera and lamp", what))
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    peers._write_with_notes(a, L)  # the hand-written notes after peers.NOTES_MARK stay
    log("wrote %s" % a.out)


def main(argv):
    a = parse_args(argv)
    entries = load_entries(a)
    failed = []
    if not a.page_only:
        for scene in SCENES:
            if scene[0] not in a.scenes:
                continue
            if not os.path.exists(scene[1]):
                log("%s: %s is absent; skipped" % (scene[0], scene[1]))
                continue
            for size in a.sizes:
                name = entry_key(scene[0], size)
                if (scene[0], size) in entries and not (
                        scene[0] in a.rerun or name in a.rerun):
                    log("%s: measured on %s at %s (--rerun %s measures it again)"
                        % (name, entries[(scene[0], size)]["date"],
                           entries[(scene[0], size)]["commit"], name))
                    continue
                if not run_entry(a, scene, size):
                    failed.append(name)
                entries = load_entries(a)
                write_page(a, entries)
    write_page(a, entries)
    if failed:
        sys.exit("peer_suite.py: error: %s failed (their tools/peers.py output is above)"
                 % ", ".join(failed))


if __name__ == "__main__":
    main(sys.argv[1:])
