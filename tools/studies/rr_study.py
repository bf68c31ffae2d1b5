#!/usr/bin/env python3
"""Russian roulette settings against variance and time: for each scene and each --rr-depth (and
no roulette), and each --rr-threshold, renders the same image with the same seeds, and reports per
configuration

  var/spp  the image's mean relative variance of one sample: mean over pixels and channels of
           spp * v / (r^2 + 0.01), v the variance of the pixel's estimate (wavepath --variance),
           r the no-roulette image (the same denominator for every configuration);
  rays/px  closest-hit rays traced per pixel sample (wavepath --json "rays"): the cost, counted,
           so that it does not depend on what else the machine is doing;
  s/spp    render seconds per sample pass (wavepath --json "seconds" / spp), for reference;
  eff      efficiency relative to --rr-depth 3 with the first threshold (else the first
           configuration after "off"): (var x rays) of that over (var x rays) of the
           configuration, > 1 is better (less error for the same work);
  eff(t)   the same with seconds in place of rays (noisy on a shared machine).

Runs are interleaved (configuration after configuration, repeated), and the seconds are the median
over the repetitions, so that a machine's slow minutes touch every configuration alike; variances
are pooled over the repetitions (different seeds). Shadow rays are not in the ray count; they
follow the closest-hit rays one for one (at most), so the ratio of costs is close. Prints a Markdown
table.

  python3 -m tools.studies.rr_study [--wavepath build/wavepath] [--scene FILE ...] [--size 256] [--spp 64]
                    [--repeat 3] [--depths 1,2,3,4,5,6,8] [--thresholds 1]

The default threshold, 1, is the rule the study in docs/accuracy.md ran with (survival
probability = throughput); wavepath's default is 0.5 since 2026-11-25.
"""

import argparse
import os
import statistics
import sys

from tools.wavepath_tools import system_python  # noqa: E402

system_python.need_numpy("rr_study.py")

import numpy as np  # noqa: E402

from tools.wavepath_tools import accuracy_lib  # noqa: E402

DEFAULT_SCENES = ("scenes/cornell_box.gltf", "scenes/failure/small_light_room.gltf",
                  "scenes/failure/glossy_floor.gltf", "scenes/failure/opening_room.gltf")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--wavepath", default=os.path.join(accuracy_lib.REPO, "build", "wavepath"))
    ap.add_argument("--scene", action="append", help="glTF scene (repeatable)")
    ap.add_argument("--size", type=int, default=256, help="image width and height")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--depths", default="1,2,3,4,5,6,8")
    ap.add_argument("--thresholds", default="1",
                    help="--rr-threshold values, comma-separated; each depth runs with each")
    a = ap.parse_args()
    scenes = a.scene or [os.path.join(accuracy_lib.REPO, s) for s in DEFAULT_SCENES]
    thresholds = a.thresholds.split(",")
    configs = ["mis+rr=off"] + ["mis+rr=%d+rrt=%s" % (int(d), t) for d in a.depths.split(",")
                                for t in thresholds]
    for c in configs:
        accuracy_lib.config_args(c)  # ValueError now for a bad threshold
    print("| scene | roulette | var/spp | rays/px | s/spp | eff | eff(t) |")
    print("|---|---|---|---|---|---|---|")
    for scene in scenes:
        var = {c: [] for c in configs}
        secs = {c: [] for c in configs}
        rays = {c: [] for c in configs}
        ref = None
        for rep in range(a.repeat):
            for c in configs:
                img, v, info = accuracy_lib.render(a.wavepath, scene, [], a.size, a.size, a.spp,
                                                   1000 + rep, c)
                if c == "mis+rr=off" and ref is None:
                    ref = img
                var[c].append(v)
                secs[c].append(info["seconds"] / a.spp)
                rays[c].append(info["rays"] / (a.spp * a.size * a.size))
        den = ref ** 2 + accuracy_lib.REL_EPS
        rows = {}
        for c in configs:
            rel = float(np.mean([np.mean(a.spp * v / den) for v in var[c]]))
            rows[c] = (rel, statistics.mean(rays[c]), statistics.median(secs[c]))
        base = rows.get("mis+rr=3+rrt=%s" % thresholds[0], rows[configs[1]])
        for c in configs:
            rel, r, s = rows[c]
            # A scene without variance (all black, or all one closed form) has no efficiency.
            eff = base[0] * base[1] / (rel * r) if rel > 0 else float("nan")
            eff_t = base[0] * base[2] / (rel * s) if rel > 0 else float("nan")
            if c.endswith("off"):
                name = "off"
            else:
                depth, threshold = (part.split("=")[1] for part in c.split("+")[1:])
                name = "from depth %s" % depth + (", threshold %s" % threshold
                                                  if len(thresholds) > 1 else "")
            print("| %s | %s | %.4f | %.3f | %.4f | %.2f | %.2f |"
                  % (os.path.basename(scene), name, rel, r, s, eff, eff_t))
        sys.stdout.flush()


if __name__ == "__main__":
    main()
