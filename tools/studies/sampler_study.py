#!/usr/bin/env python3
"""Sample patterns against error: for each scene, sample count and --sampler, renders the same
image with several seeds and reports the relative MSE against a common reference.

  relMSE   mean over pixels and channels of ((x - r)^2 - var_r) / (r^2 + 0.01), x the render, r
           the reference and var_r its variance image (accuracy_lib.compare), averaged over the
           seeds, with its standard error over them;
  ratio    the pattern's relMSE over the first pattern's, averaged per seed (the patterns share
           each seed, so scene-wide luck cancels), with its standard error over the seeds: below 1
           means less error for the same samples;
  s        the median render seconds (wavepath --json "seconds": the sample passes only).

The reference is an independent-sampler MIS render of --ref-spp samples with its own seed (an
independent pattern's variance image is the variance of its estimate, which the subtraction of
var_r needs). Renders are interleaved (pattern after pattern for each seed), so a slow minute on a
shared machine touches every pattern alike. Prints a Markdown table. Needs numpy (Debian:
python3-numpy).

  python3 -m tools.studies.sampler_study [--wavepath build/wavepath] [--scene FILE ...] [--size 128]
                         [--spp 64,256] [--seeds 12] [--ref-spp 4096]
                         [--samplers sobol,sobol-padded]
"""

import argparse
import os
import statistics
import sys

from tools.wavepath_tools import system_python  # noqa: E402

system_python.need_numpy("sampler_study.py")

import numpy as np  # noqa: E402

from tools.wavepath_tools import accuracy_lib  # noqa: E402

REFERENCE_SEED = 0x5EEDF00D


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--wavepath", default=os.path.join(accuracy_lib.REPO, "build", "wavepath"))
    ap.add_argument("--scene", action="append", help="glTF scene (repeatable; default: the "
                    "Cornell box)")
    ap.add_argument("--render-args", default="", help="more wavepath arguments for every render, "
                    "reference included (e.g. \"--env FILE\")")
    ap.add_argument("--size", type=int, default=128, help="image width and height")
    ap.add_argument("--spp", default="64,256", help="sample counts, comma-separated")
    ap.add_argument("--seeds", type=int, default=12, help="renders per pattern and sample count")
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--samplers", default="sobol,sobol-padded",
                    help="--sampler values, the first the one the ratios divide by")
    a = ap.parse_args()
    scenes = a.scene or [os.path.join(accuracy_lib.REPO, "scenes", "cornell_box.gltf")]
    samplers = a.samplers.split(",")
    extra = a.render_args.split()
    for s in samplers:
        accuracy_lib.config_args("mis+sampler=" + s)  # ValueError now for a bad name
    print("| scene | spp | sampler | relMSE | ratio to %s | s |" % samplers[0])
    print("|---|---|---|---|---|---|")
    for scene in scenes:
        ref, ref_var, _ = accuracy_lib.render(a.wavepath, scene, extra, a.size, a.size, a.ref_spp,
                                              REFERENCE_SEED, "mis+sampler=independent")
        for spp in (int(n) for n in a.spp.split(",")):
            rel = {s: [] for s in samplers}
            secs = {s: [] for s in samplers}
            for seed in range(1, a.seeds + 1):
                for s in samplers:
                    img, var, info = accuracy_lib.render(a.wavepath, scene, extra, a.size, a.size,
                                                         spp, seed, "mis+sampler=" + s)
                    rel[s].append(accuracy_lib.compare(img, var, ref, ref_var)["rel_mse"])
                    secs[s].append(info["seconds"])
            base = np.array(rel[samplers[0]])
            n = len(base)

            def se(x):  # standard error of the mean over the seeds
                return float(np.std(x, ddof=1) / np.sqrt(n)) if n > 1 else float("nan")

            for s in samplers:
                r = np.array(rel[s])
                q = r / base
                print("| %s | %d | %s | %.4g ± %.2g | %.4f ± %.4f | %.3f |"
                      % (os.path.basename(scene), spp, s, r.mean(), se(r), q.mean(), se(q),
                         statistics.median(secs[s])))
            sys.stdout.flush()


if __name__ == "__main__":
    main()
