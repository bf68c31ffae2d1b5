#!/usr/bin/env python3
"""Mip-mapped textures against error and time: for each scene (a textured model seen small in the
frame), renders with --mipmaps on and off at several sample counts and reports each render's
relative MSE against a full-resolution reference, its time and the texture memory.

  relMSE   mean over pixels and channels of ((x - r)^2 - var_r) / (r^2 + 0.01) (accuracy_lib.
           compare), x the render and r the reference: an independent-sampler render with
           --mipmaps off (the scene's textures as the file defines them, unfiltered) of --ref-spp
           samples; averaged over --seeds seeds;
  s        the median render seconds (wavepath --json "seconds": the sample passes only);
  floor    the relMSE between what the mip-mapped image converges to and the reference (the blur
           of prefiltering, and 8-bit mip levels): the error it cannot go below, estimated from
           a --mipmaps on render of --ref-spp samples as mean(((x - r)^2 - var_x - var_r) /
           (r^2 + 0.01)), both renders' variances taken out (so it can come out slightly
           negative where it is below the estimate's noise);
  memory   the texels' bytes without and with the mip chains (--json texture_bytes, mip_bytes).

Renders alternate (on, off) for each seed, so a slow minute on a shared machine touches both
alike. Prints Markdown tables; with --chart FILE also plots relMSE against seconds (matplotlib).
Needs numpy (Debian: python3-numpy).

  python3 -m tools.studies.mip_study [--wavepath build/wavepath] [--size 256] [--spp 1,4,16,64] [--seeds 3]
                     [--ref-spp 2048] [--chart docs/mipmaps.png]
                     [--case NAME:SCENE:ARGS ...]
"""

import argparse
import os
import statistics
import sys

from tools.wavepath_tools import system_python  # noqa: E402

system_python.need_numpy("mip_study.py")

import numpy as np  # noqa: E402

from tools.wavepath_tools import accuracy_lib  # noqa: E402

REFERENCE_SEED = 0x5EEDF00D
ASSETS = os.path.join(accuracy_lib.REPO, "..", "shared", "assets")
ENV = os.path.join(ASSETS, "env", "studio_small_03_1k.hdr")
# Two textured models seen small (the whole model a few dozen pixels across in a 256 x 256 image),
# and DamagedHelmet framed whole (wavepath's framing camera, as tools/peers.py --pbr renders it),
# whose surfaces edge-on to the view test the footprint at grazing angles (kernels/texture/ray_cone.h).
HELMET = os.path.join(ASSETS, "models", "DamagedHelmet", "DamagedHelmet.glb")
DEFAULT_CASES = [
    "DamagedHelmet:%s:--orbit 30,75,14 --env %s" % (HELMET, ENV),
    "FlightHelmet:%s:--orbit 200,80,3 --env %s"
    % (os.path.join(ASSETS, "models", "FlightHelmet", "FlightHelmet.gltf"), ENV),
    "DamagedHelmet, framed:%s:--env %s"
    % (HELMET, os.path.join(ASSETS, "env", "empty_warehouse_01_1k.hdr")),
]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--wavepath", default=os.path.join(accuracy_lib.REPO, "build", "wavepath"))
    ap.add_argument("--case", action="append",
                    help="NAME:SCENE:ARGS, ARGS more wavepath arguments (repeatable; default: "
                    "DamagedHelmet and FlightHelmet, small, in studio_small_03, and "
                    "DamagedHelmet framed whole in empty_warehouse_01)")
    ap.add_argument("--size", type=int, default=256, help="image width and height")
    ap.add_argument("--spp", default="1,4,16,64", help="sample counts, comma-separated")
    ap.add_argument("--seeds", type=int, default=3, help="renders per setting and sample count")
    ap.add_argument("--ref-spp", type=int, default=2048)
    ap.add_argument("--chart", help="write a PNG of relMSE against seconds here")
    a = ap.parse_args()
    cases = [c.split(":", 2) for c in (a.case or DEFAULT_CASES)]
    spps = [int(n) for n in a.spp.split(",")]
    indep = "mis+sampler=independent"
    results = {}
    for name, scene, args in cases:
        if not os.path.isfile(scene):
            print("mip_study: %s skipped (%s not found)" % (name, scene), file=sys.stderr)
            continue
        extra = args.split()
        ref, ref_var, _ = accuracy_lib.render(a.wavepath, scene, extra + ["--mipmaps", "off"],
                                              a.size, a.size, a.ref_spp, REFERENCE_SEED, indep)
        conv, conv_var, info = accuracy_lib.render(a.wavepath, scene, extra + ["--mipmaps", "on"],
                                                   a.size, a.size, a.ref_spp, REFERENCE_SEED + 1,
                                                   indep)
        floor = float((((conv - ref) ** 2 - conv_var - ref_var)
                       / (ref * ref + accuracy_lib.REL_EPS)).mean())
        rows = []
        for spp in spps:
            rel = {"on": [], "off": []}
            secs = {"on": [], "off": []}
            for seed in range(1, a.seeds + 1):
                for mode in ("on", "off"):
                    img, var, run = accuracy_lib.render(a.wavepath, scene,
                                                        extra + ["--mipmaps", mode], a.size,
                                                        a.size, spp, seed, "mis")
                    rel[mode].append(accuracy_lib.compare(img, var, ref, ref_var)["rel_mse"])
                    secs[mode].append(run["seconds"])
            rows.append((spp, {m: (float(np.mean(rel[m])), statistics.median(secs[m]))
                               for m in rel}))
        results[name] = rows
        print("\n%s (%s %s, %dx%d; reference %d spp, --mipmaps off)\n"
              % (name, os.path.basename(scene), args, a.size, a.size, a.ref_spp))
        tex, mip = info["texture_bytes"], info["mip_bytes"]
        print("texels %.1f MiB without mip chains, %.1f MiB with (+%.1f%%); floor (relMSE of "
              "--mipmaps on at %d spp) %.3g\n"
              % ((tex - mip) / 2**20, tex / 2**20, 100.0 * mip / max(tex - mip, 1), a.ref_spp,
                 floor))
        print("| spp | relMSE on | relMSE off | off / on | s on | s off | time on / off |")
        print("|---|---|---|---|---|---|---|")
        for spp, r in rows:
            print("| %d | %.4g | %.4g | %.2f | %.3f | %.3f | %.2f |"
                  % (spp, r["on"][0], r["off"][0], r["off"][0] / r["on"][0], r["on"][1],
                     r["off"][1], r["on"][1] / r["off"][1]))
        sys.stdout.flush()
    if a.chart and results:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, axes = plt.subplots(1, len(results), figsize=(5 * len(results), 4), squeeze=False)
        for ax, (name, rows) in zip(axes[0], results.items()):
            for mode, style in (("on", "o-"), ("off", "s--")):
                ax.loglog([r[mode][1] for _, r in rows], [r[mode][0] for _, r in rows], style,
                          label="--mipmaps " + mode)
            ax.set_title(name)
            ax.set_xlabel("render seconds")
            ax.set_ylabel("relMSE")
            ax.grid(True, which="both", alpha=0.3)
            ax.legend()
        fig.tight_layout()
        fig.savefig(a.chart, dpi=100)


if __name__ == "__main__":
    main()
