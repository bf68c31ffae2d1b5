#!/usr/bin/env python3
"""The figures of docs/denoise.md: relMSE of `wavepath render --denoise`'s raw and denoised images
against a converged reference, on the scenes of tests/test_denoise.cpp and one where the denoiser
gains little.

    python3 -m tools.studies.denoise_study [--wavepath build/wavepath] [--size 128] [--spp 16] [--ref-spp 4096]
                           [--seeds 5] [--assets ../shared/assets]

For each scene: one reference (--ref-spp samples, --variance, seed REFERENCE_SEED, which no
compared render uses), then --seeds renders of --spp samples with --denoise (seeds 1..N), each
compared with the reference as tools/wavepath_tools/accuracy_lib.py does: relMSE = mean over pixels and channels
of ((x - r)^2 - v_r) / (r^2 + 0.01), v_r the reference's variance (subtracted: the reference's
own noise adds v_r to (x - r)^2 on average). Prints a Markdown table (mean, min and max over the
seeds) and the commands it ran (S: each seed). Needs Open Image Denoise (tools/setup.sh --denoise).
"""

import argparse
import os
import subprocess
import sys
import tempfile

from tools.wavepath_tools.system_python import need_numpy  # noqa: E402

need_numpy("denoise_study.py")
import numpy as np  # noqa: E402

from tools.wavepath_tools.accuracy_lib import REFERENCE_SEED, REL_EPS, REPO, read_pfm  # noqa: E402

# name, scene (relative to the repository, or "assets:" + a path under the assets folder), options.
SCENES = [
    ("Cornell box", "scenes/cornell_box.gltf", []),
    ("SheenChair, warehouse", "assets:models/SheenChair/SheenChair.gltf",
     ["--env", "assets:env/empty_warehouse_01_1k.hdr"]),
    ("DamagedHelmet, warehouse", "assets:models/DamagedHelmet/DamagedHelmet.glb",
     ["--env", "assets:env/empty_warehouse_01_1k.hdr"]),
]


def rel_mse(x, r, v_r):
    return float((((x - r) ** 2 - v_r) / (r * r + REL_EPS)).mean())


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--wavepath", default=os.path.join(REPO, "build", "wavepath"))
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--assets", default=os.path.join(REPO, "..", "shared", "assets"))
    args = ap.parse_args()

    def path(p):
        if p.startswith("assets:"):
            return os.path.join(args.assets, p[len("assets:"):])
        return os.path.join(REPO, p)

    commands, rows = [], []
    with tempfile.TemporaryDirectory(prefix="wp-denoise-") as tmp:
        def run(scene, options, spp, seed, out, extra):
            cmd = [args.wavepath, "render", path(scene)]
            cmd += [path(o) if o.startswith("assets:") else o for o in options]
            cmd += ["--width", str(args.size), "--height", str(args.size), "--spp", str(spp),
                    "--seed", str(seed), "-o", os.path.join(tmp, out), "-q"] + extra
            line = " ".join(c.replace(tmp + "/", "").replace(REPO + "/", "") for c in cmd)
            if seed != REFERENCE_SEED:
                line = line.replace("--seed %d " % seed, "--seed S ")
            if line not in commands:
                commands.append(line)
            subprocess.run(cmd, check=True)

        for name, scene, options in SCENES:
            if not os.path.exists(path(scene)):
                print("skipped %s: %s not found" % (name, path(scene)), file=sys.stderr)
                continue
            run(scene, options, args.ref_spp, REFERENCE_SEED, "ref.pfm", ["--variance"])
            r = read_pfm(os.path.join(tmp, "ref.pfm"))
            v_r = read_pfm(os.path.join(tmp, "ref.variance.pfm"))
            raw, den = [], []
            for seed in range(1, args.seeds + 1):
                run(scene, options, args.spp, seed, "x.pfm", ["--denoise"])
                raw.append(rel_mse(read_pfm(os.path.join(tmp, "x.pfm")), r, v_r))
                den.append(rel_mse(read_pfm(os.path.join(tmp, "x.denoised.pfm")), r, v_r))
            ratios = [d / x for d, x in zip(den, raw)]
            rows.append((name, raw, den, ratios, float((v_r / (r * r + REL_EPS)).mean())))

    def cell(v):
        return "%.3g (%.3g–%.3g)" % (np.mean(v), min(v), max(v))

    print("| scene | raw relMSE | denoised relMSE | denoised / raw | reference's own relMSE |")
    print("|---|---|---|---|---|")
    for name, raw, den, ratios, ref_err in rows:
        print("| %s | %s | %s | %s | %.2g |" % (name, cell(raw), cell(den), cell(ratios), ref_err))
    print("\n%dx%d, %d spp (seeds 1-%d; mean, then min-max), references of %d spp:\n"
          % (args.size, args.size, args.spp, args.seeds, args.ref_spp))
    for c in commands:
        print("    " + c)


if __name__ == "__main__":
    main()
