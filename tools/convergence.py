#!/usr/bin/env python3
"""Error against time for wavepath's sampling configurations: renders a scene at sample counts in
powers of two with each configuration, measures error against a reference, and writes a CSV,
log-log charts, equal-time crops and (for the failure-scene suite) the tables of docs/accuracy.md.

Run `tools/convergence.py --help` for the options; tools/accuracy.sh regenerates every chart of
docs/accuracy.md. Needs numpy and matplotlib (Debian: python3-numpy, python3-matplotlib): when the
running interpreter lacks numpy and /usr/bin/python3 exists, the script re-runs itself with that.
"""

import os
import sys

from wavepath_tools import system_python  # noqa: E402

system_python.need_numpy("convergence.py", "python3-numpy and python3-matplotlib")

import argparse  # noqa: E402
import csv  # noqa: E402
import math  # noqa: E402
import re  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from wavepath_tools import accuracy_lib as al  # noqa: E402

DESCRIPTION = """\
Renders a scene with each configuration at every sample count, and records for each run the wall
time (the `seconds` of wavepath's --json: the sample passes, without kernel build, BVH build and
file output) and the error against a reference:

  RMSE     sqrt(mean((x - r)^2) - mean(var_r)) over all pixels and channels; subtracting the
           reference's own variance (from its variance image) leaves an unbiased estimate of the
           run's MSE, so a noisy reference does not flatten the curves
  relMSE   mean(((x - r)^2 - var_r) / (r^2 + 0.01))
  bias     mean(x) - mean(r), the image means' difference (mean of R, G, B), with its 95%
           confidence interval from the two variance images (wavepath --variance: the variance of
           each pixel's estimate); z = bias / its standard error. Bias is reported apart from
           noise: an unbiased configuration has |z| of order 1 at every sample count.

The reference is, per scene of the manifest: the closed form (tools/wavepath_tools/closed_form.py) where there is
one, black for the closed box, another scene's reference for the scaled scenes (radiance does not
depend on scale), otherwise an MIS render of --ref-spp samples per pixel with its own seed, cached
in --cache under a key of the scene file (and files its arguments name), the arguments, size,
sample count, seed and the wavepath binary's path and modification time.

Outputs, per scene NAME, in --out:
  NAME.csv           one row per run (see the header)
  NAME_error.png     RMSE and relMSE against time, log-log, one line per configuration; the grey
                     line is the Monte Carlo rate (RMSE ~ time^-1/2)
  NAME_crops.png     the manifest's crop, equal time: each configuration's run whose time is
                     closest (in ratio) to the time MIS takes for --crop-spp samples, and the
                     reference; one exposure for all panels (the reference crop's 90th percentile
                     at half of white, Reinhard's x / (1 + x), sRGB)
  summary.csv        (with several scenes) per scene and configuration: time to the target error
  and, with --doc FILE, the table of each scene replaced in FILE between the lines
  `<!-- convergence:NAME -->` and `<!-- /convergence:NAME -->`, and the robustness table (MIS's
  MSE over the best single strategy's, nee or bsdf, at equal sample count: at the largest count
  and its range over counts >= 8; a significantly biased strategy such as bsdf with point lights
  is left out) between `<!-- convergence:robustness -->` and `<!-- /convergence:robustness -->`.

Time to reach the target error: the target RMSE is --target times the reference's RMS value
(per scene; the manifest may set "target"). Monte Carlo error falls as time^-1/2 once the fixed
cost per sample pass is small, so each run with 8 or more samples per pixel predicts the time to
the target as t (RMSE / target)^2: the point where a line of slope -1/2 through that run's point
on the log-log chart crosses the target. The table gives the median of these predictions (robust
to a run slowed by other load on the machine), marked `~` when the target lies outside the range
of errors the runs reached (an extrapolation). A configuration whose bias is significant (|z| >
4.5 at its largest sample count, e.g. bsdf with point lights) has no time. "Fastest" is the
smallest time; configurations within 10% of it are listed as ties (timing noise is that large).

Configurations: STRATEGY[+key=value...], STRATEGY one of mis, nee, bsdf; keys heuristic=power|
balance (--mis-heuristic), select=power|uniform (--light-select), rr=off|N (--no-rr or
--rr-depth N), depth=N (--max-depth). Unset keys are wavepath's defaults (power heuristic, power
light selection, roulette after 5 events, max depth 12).
"""

EXAMPLES = """\
examples:
  tools/convergence.py --wavepath build/wavepath --scene veach_mis --out /tmp/veach
  tools/convergence.py --scene glossy_floor --configs mis,nee,bsdf --spp 1:64
  tools/convergence.py --gltf my.gltf --render-args="--env sky.hdr" --out /tmp/mine
  tools/convergence.py --all --out docs/accuracy --doc docs/accuracy.md   (tools/accuracy.sh)
"""


def parse_spp(text):
    """"1:128" -> [1, 2, 4, ..., 128]; "4,16,64" -> [4, 16, 64]."""
    if ":" in text:
        lo, hi = (int(t) for t in text.split(":"))
        out = []
        s = lo
        while s <= hi:
            out.append(s)
            s *= 2
        return out
    return [int(t) for t in text.split(",")]


def parse_args(argv):
    p = argparse.ArgumentParser(prog="convergence.py", description=DESCRIPTION, epilog=EXAMPLES,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--wavepath", default=os.path.join(al.REPO, "build", "wavepath"),
                   help="the wavepath binary (default: build/wavepath)")
    p.add_argument("--manifest", default=al.DEFAULT_MANIFEST,
                   help="failure-scene manifest (default: scenes/failure/manifest.json)")
    which = p.add_mutually_exclusive_group(required=True)
    which.add_argument("--scene", action="append", metavar="NAME",
                       help="a manifest scene (repeatable)")
    which.add_argument("--all", action="store_true",
                       help="every manifest scene that has a chart (all but closed_box, whose "
                            "answer is exactly 0, and scale_1, the scaled scenes' reference)")
    which.add_argument("--gltf", metavar="FILE",
                       help="any glTF scene instead; its reference is an MIS render")
    p.add_argument("--render-args", default="", metavar="ARGS",
                   help="extra wavepath arguments for --gltf, e.g. \"--env sky.hdr\"")
    p.add_argument("--configs", default=",".join(al.DEFAULT_CONFIGS),
                   help="comma-separated configurations (default: %(default)s)")
    p.add_argument("--spp", default="1:128",
                   help="sample counts: LO:HI for the powers of two from LO to HI, or a list "
                        "(default: %(default)s)")
    p.add_argument("--size", default="128x96", help="image size WxH (default: %(default)s)")
    p.add_argument("--ref-spp", type=int, default=2048,
                   help="samples per pixel of a rendered reference (default: %(default)s)")
    p.add_argument("--crop-spp", type=int, default=16,
                   help="the equal-time crops use the time MIS takes for this many samples "
                        "(default: %(default)s)")
    p.add_argument("--target", type=float, default=0.1,
                   help="target RMSE as a fraction of the reference's RMS value, for the time "
                        "tables (default: %(default)s; a manifest scene may set its own)")
    p.add_argument("--out", default="convergence-out", help="output folder (default: %(default)s)")
    p.add_argument("--cache", default=None,
                   help="reference cache folder (default: convergence-cache/ beside the binary)")
    p.add_argument("--doc", default=None,
                   help="markdown file whose per-scene tables are replaced (see above)")
    p.add_argument("--no-charts", action="store_true", help="CSV and tables only")
    p.add_argument("--from-csv", action="store_true",
                   help="render nothing: read each scene's runs back from --out/NAME.csv and "
                        "redo the error charts and tables (the crops need the images: kept)")
    a = p.parse_args(argv)
    a.configs = [c for c in a.configs.split(",") if c]
    for c in a.configs:
        al.config_args(c)  # raises on a malformed one
    a.spp = parse_spp(a.spp)
    a.width, a.height = (int(t) for t in a.size.lower().split("x"))
    if a.cache is None:
        a.cache = os.path.join(os.path.dirname(os.path.abspath(a.wavepath)), "convergence-cache")
    if not os.access(a.wavepath, os.X_OK):
        p.error("no wavepath binary at %s (build it, or pass --wavepath)" % a.wavepath)
    return a


def log(msg):
    print(msg, file=sys.stderr, flush=True)


# ---- Sweeps --------------------------------------------------------------------------------------

def sweep(a, manifest, name):
    """Renders every (sample count, configuration) of scene `name`; returns (rows, images), images
    keyed by (config, spp) -> image, and the reference (image, variance, description)."""
    entry = manifest["by_name"][name]
    ref, ref_var, ref_desc = al.reference(a.wavepath, manifest, name, a.width, a.height,
                                          a.ref_spp, a.cache, log)
    rows, images = [], {}
    # Sample counts outermost: a load change on the machine then hits every configuration alike.
    for k, spp in enumerate(a.spp):
        for config in a.configs:
            img, var, info = al.render(a.wavepath, entry["path"], entry["render_args"], a.width,
                                       a.height, spp, 1 + k, config)
            s = al.compare(img, var, ref, ref_var)
            row = {"scene": name, "config": config, "spp": spp, "seed": 1 + k,
                   "seconds": info["seconds"], "samples_per_second": info["samples_per_second"],
                   "nonfinite": info.get("nonfinite_samples", 0)}
            for key in ("rmse", "mse", "rel_mse", "mean", "ref_mean", "bias", "bias_ci95", "z"):
                row[key] = s[key]
            row["z_r"], row["z_g"], row["z_b"] = s["z_c"]
            row["ref_rms"] = s["ref_rms"]
            rows.append(row)
            images[(config, spp)] = img
            log("%s %-24s %5d spp %8.3f s  RMSE %.4g  bias %+.3g +- %.2g" %
                (name, config, spp, info["seconds"], s["rmse"], s["bias"], s["bias_ci95"]))
    return rows, images, (ref, ref_var, ref_desc)


def write_csv(path, rows):
    keys = list(rows[0].keys())
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, lineterminator="\n")
        w.writeheader()
        for r in rows:
            w.writerow({k: ("%.6g" % v if isinstance(v, float) else v) for k, v in r.items()})


# ---- Time to a target error ----------------------------------------------------------------------

def time_to_target(points, target, min_spp=8):
    """(time, mark) for a curve of (spp, seconds, rmse); see DESCRIPTION. Each run with at least
    min_spp samples predicts t (rmse / target)^2 (Monte Carlo: RMSE ~ t^-1/2); the median
    prediction is returned, marked "~" when the target is outside the errors those runs reached."""
    use = [p for p in points if p[0] >= min_spp and p[2] > 0] or [p for p in points if p[2] > 0]
    if not use:
        return None, ""
    predictions = sorted(t * (e / target) ** 2 for _, t, e in use)
    n = len(predictions)
    median = predictions[n // 2] if n % 2 else 0.5 * (predictions[n // 2 - 1] + predictions[n // 2])
    errors = [e for _, _, e in use]
    return median, "" if min(errors) <= target <= max(errors) else "~"


def scene_table(a, name, rows, target_frac):
    """Per configuration: time to target, RMSE and bias at the largest sample count."""
    ref_rms = rows[0]["ref_rms"]
    target = target_frac * ref_rms
    out = []
    for config in a.configs:
        rs = sorted((r for r in rows if r["config"] == config), key=lambda r: r["spp"])
        last = rs[-1]
        biased = abs(last["z"]) > 4.5 or (last["bias_ci95"] == 0 and last["bias"] != 0)
        t, mark = (None, "") if biased else time_to_target(
            [(r["spp"], r["seconds"], r["rmse"]) for r in rs], target)
        out.append({"scene": name, "config": config, "target_rmse": target, "time": t, "mark": mark,
                    "biased": biased, "spp": last["spp"], "seconds": last["seconds"],
                    "rmse": last["rmse"], "bias": last["bias"], "bias_ci95": last["bias_ci95"],
                    "z": last["z"]})
    return out


def fmt_time(t, mark):
    if t is None:
        return "never (biased)"
    s = "%.3g s" % t if t < 1000 else "%.0f s" % t
    return (mark + " " + s).strip() if mark else s


def markdown_table(table, ref_desc):
    timed = [r for r in table if r["time"] is not None]
    best = min(timed, key=lambda r: r["time"]) if timed else None
    lines = ["Reference: %s. Target RMSE %.3g (%.0f%% of the reference's RMS)." %
             (ref_desc, table[0]["target_rmse"], 100 * table[0]["target_frac"]), ""]
    lines.append("| configuration | time to target | RMSE at %d spp (time) | bias ± 95%% CI (z) |"
                 % table[0]["spp"])
    lines.append("|---|---|---|---|")
    for r in table:
        name = "**%s**" % r["config"] if r is best else r["config"]
        t = fmt_time(r["time"], r["mark"])
        if r is best:
            t = "**%s**" % t
        z = "%+.1f" % r["z"] if math.isfinite(r["z"]) else "∞"
        lines.append("| %s | %s | %.3g (%.3g s) | %+.2g ± %.2g (%s) |" %
                     (name, t, r["rmse"], r["seconds"], r["bias"], r["bias_ci95"], z))
    lines.append("")
    if best:
        ties = [r["config"] for r in timed if r is not best and r["time"] <= 1.1 * best["time"]]
        lines.append("Fastest to the target: **%s**%s." % (
            best["config"], " (within 10%%: %s)" % ", ".join(ties) if ties else ""))
    else:
        lines.append("No configuration reaches the target.")
    return "\n".join(lines)


def robustness(a, rows):
    """MIS's MSE over the best single strategy's (nee or bsdf; a configuration whose bias is
    significant at its largest sample count, e.g. bsdf with point lights, is left out) at each
    sample count of 8 or more: (ratio at the largest count, smallest, largest)."""
    by = {(r["config"], r["spp"]): r for r in rows}
    counts = sorted({r["spp"] for r in rows if r["spp"] >= 8})
    if "mis" not in a.configs or not counts:
        return None
    singles = []
    for c in ("nee", "bsdf"):
        if c in a.configs:
            last = by[(c, max(r["spp"] for r in rows))]
            if not (abs(last["z"]) > 4.5 or (last["bias_ci95"] == 0 and last["bias"] != 0)):
                singles.append(c)
    ratios = []
    for spp in counts:
        best = min(by[(c, spp)]["mse"] for c in singles)
        ratios.append(by[("mis", spp)]["mse"] / best if best > 0 else float("nan"))
    return ratios[-1], min(ratios), max(ratios), counts[-1]


def robustness_table(items):
    lines = ["| scene | MIS MSE / best single strategy's, at %s spp | range over 8+ spp |" %
             (items[0][1][3] if items else "?"), "|---|---|---|"]
    for name, (last, lo, hi, _) in items:
        flag = "" if last <= 1.1 else " **(over 1.1)**"
        lines.append("| %s | %.2f%s | %.2f – %.2f |" % (name, last, flag, lo, hi))
    return "\n".join(lines)


def read_csv(path):
    rows = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            for k, v in r.items():
                if k not in ("scene", "config"):
                    r[k] = float(v) if any(ch in v for ch in ".eEn") else int(v)
            rows.append(r)
    return rows


def reference_description(manifest, name, ref_spp):
    ref = manifest["by_name"][name].get("reference", {"kind": "render"})
    return {"closed_form": "closed form (tools/wavepath_tools/closed_form.py)",
            "black": "black: nothing can reach the inside",
            "scene": "%s's MIS reference (%d spp): the same scene at scale 1" %
                     (ref.get("scene"), ref_spp)}.get(ref["kind"], "MIS render, %d spp" % ref_spp)


def update_doc(path, name, text):
    with open(path) as f:
        doc = f.read()
    begin, end = "<!-- convergence:%s -->" % name, "<!-- /convergence:%s -->" % name
    pattern = re.compile(re.escape(begin) + r".*?" + re.escape(end), re.S)
    if not pattern.search(doc):
        log("%s: no %s ... %s block; table not written" % (path, begin, end))
        return
    doc = pattern.sub(lambda _: begin + "\n" + text + "\n" + end, doc)
    with open(path, "w") as f:
        f.write(doc)


# ---- Charts --------------------------------------------------------------------------------------

STYLE = {"mis": ("tab:blue", "-"), "nee": ("tab:orange", "-"), "bsdf": ("tab:green", "-")}
EXTRA = ["tab:purple", "tab:brown", "tab:pink", "tab:gray", "tab:olive", "tab:cyan", "tab:red"]


def _plt():
    try:
        import matplotlib
    except ImportError:
        sys.exit("convergence.py: error: matplotlib is missing; install Debian's python3-matplotlib")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def chart(a, name, rows, title, path):
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    extra = iter(EXTRA)
    for config in a.configs:
        rs = sorted((r for r in rows if r["config"] == config), key=lambda r: r["spp"])
        colour, ls = STYLE.get(config, (None, "--"))
        colour = colour or next(extra)
        t = [r["seconds"] for r in rs]
        for ax, key in zip(axes, ("rmse", "rel_mse")):
            v = [max(r[key], 1e-12) for r in rs]
            ax.plot(t, v, ls, color=colour, marker="o", ms=3, lw=1.6 if ls == "-" else 1.2,
                    label=config)
    for ax, key, slope in zip(axes, ("RMSE", "relMSE"), (-0.5, -1.0)):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("render time (s)")
        ax.set_ylabel(key)
        ax.grid(True, which="both", alpha=0.25)
        # The Monte Carlo rate through MIS's middle run, for reference.
        rs = sorted((r for r in rows if r["config"] == a.configs[0]), key=lambda r: r["spp"])
        mid = rs[len(rs) // 2]
        y0 = mid["rmse" if key == "RMSE" else "rel_mse"]
        if y0 > 0:
            ts = np.array([min(r["seconds"] for r in rows), max(r["seconds"] for r in rows)])
            ax.plot(ts, y0 * (ts / mid["seconds"]) ** slope, color="0.6", lw=0.8, ls=":")
    axes[0].legend(fontsize=8, loc="lower left")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def tonemap(img, exposure):
    """Reinhard's x / (1 + x) after the exposure, then sRGB encoding."""
    x = np.clip(img * exposure, 0.0, None)
    x = x / (1.0 + x)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def crops(a, name, entry, rows, images, ref, path):
    plt = _plt()
    x, y, w, h = entry.get("crop", [0, 0, a.width, a.height])
    sx, sy = a.width / 128.0, a.height / 96.0  # the manifest's crops refer to 128 x 96
    x0, y0 = int(round(x * sx)), int(round(y * sy))
    x1, y1 = x0 + max(1, int(round(w * sx))), y0 + max(1, int(round(h * sy)))
    mis = sorted((r for r in rows if r["config"] == a.configs[0]), key=lambda r: r["spp"])
    budget = min(mis, key=lambda r: abs(math.log(r["spp"] / a.crop_spp)))["seconds"]
    rc = ref[y0:y1, x0:x1]
    lum = rc.mean(2)
    level = np.percentile(lum, 90) if lum.size else 1.0
    exposure = 1.0 / level if level > 0 else 1.0  # the crop's 90th percentile at half of white
    panels = []
    for config in a.configs:
        rs = [r for r in rows if r["config"] == config]
        r = min(rs, key=lambda r: abs(math.log(max(r["seconds"], 1e-6) / budget)))
        panels.append(("%s\n%d spp, %.2f s, RMSE %.3g" % (config, r["spp"], r["seconds"], r["rmse"]),
                       images[(config, r["spp"])][y0:y1, x0:x1]))
    panels.append(("reference", rc))
    n = len(panels)
    cols = min(n, 4)
    rows_n = (n + cols - 1) // cols
    aspect = (y1 - y0) / max(1, (x1 - x0))
    fig, axes = plt.subplots(rows_n, cols, figsize=(3.0 * cols, 3.0 * aspect * rows_n + 0.6 * rows_n),
                             squeeze=False)
    for ax in axes.flat:
        ax.axis("off")
    for ax, (title, img) in zip(axes.flat, panels):
        ax.imshow(tonemap(img, exposure), interpolation="nearest")
        ax.set_title(title, fontsize=8)
    fig.suptitle("%s: equal time (%.2f s, MIS at %d spp)" % (name, budget, a.crop_spp), fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


# ---- Main ----------------------------------------------------------------------------------------

def charted_scenes(manifest):
    return [e["name"] for e in manifest["scenes"] if e.get("chart", True)]


def main(argv):
    a = parse_args(argv)
    if a.gltf:
        manifest = {"scenes": [{"name": os.path.splitext(os.path.basename(a.gltf))[0],
                                "path": os.path.abspath(a.gltf), "file": a.gltf,
                                "render_args": a.render_args.split(), "reference": {"kind": "render"}}]}
        manifest["by_name"] = {e["name"]: e for e in manifest["scenes"]}
        names = [manifest["scenes"][0]["name"]]
    else:
        manifest = al.load_manifest(a.manifest)
        names = charted_scenes(manifest) if a.all else a.scene
        for n in names:
            if n not in manifest["by_name"]:
                sys.exit("convergence.py: error: no scene %r in %s" % (n, a.manifest))
    os.makedirs(a.out, exist_ok=True)
    summary = []
    start = time.time()
    robust = []
    for name in names:
        entry = manifest["by_name"][name]
        if a.from_csv:
            rows = read_csv(os.path.join(a.out, name + ".csv"))
            a.configs = list(dict.fromkeys(r["config"] for r in rows))
            ref_desc = reference_description(manifest, name, a.ref_spp)
        else:
            rows, images, (ref, ref_var, ref_desc) = sweep(a, manifest, name)
            write_csv(os.path.join(a.out, name + ".csv"), rows)
        rb = robustness(a, rows)
        if rb:
            robust.append((name, rb))
        frac = entry.get("target", a.target)
        table = scene_table(a, name, rows, frac)
        for r in table:
            r["target_frac"] = frac
        summary += table
        if not a.no_charts:
            chart(a, name, rows, "%s: error against time (%dx%d; reference: %s)" %
                  (name, a.width, a.height, ref_desc), os.path.join(a.out, name + "_error.png"))
            if not a.from_csv:
                crops(a, name, entry, rows, images, ref, os.path.join(a.out, name + "_crops.png"))
        text = markdown_table(table, ref_desc)
        print("## %s\n\n%s\n" % (name, text))
        if a.doc:
            update_doc(a.doc, name, text)
    if robust:
        text = robustness_table(robust)
        print("## robustness\n\n%s\n" % text)
        if a.doc:
            update_doc(a.doc, "robustness", text)
    if len(names) > 1:
        with open(os.path.join(a.out, "summary.csv"), "w", newline="") as f:
            keys = ["scene", "config", "target_rmse", "time", "mark", "spp", "seconds", "rmse",
                    "bias", "bias_ci95", "z"]
            w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore", lineterminator="\n")
            w.writeheader()
            for r in summary:
                w.writerow({k: ("%.6g" % v if isinstance(v, float) else ("" if v is None else v))
                            for k, v in r.items() if k in keys})
    log("done in %.0f s" % (time.time() - start))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
