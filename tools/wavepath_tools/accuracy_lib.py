"""Shared pieces of tools/convergence.py and tests/test_accuracy.py: running wavepath, reading its
PFM output, the failure-scene manifest, references (closed form, cached MIS render, black) and
the error statistics.

Statistics (all over every pixel and colour channel of an image x with per-pixel variance image
v_x, against a reference r with variance image v_r, which is 0 for a closed form):

- MSE = mean((x - r)^2) - mean(v_r). For independent unbiased x and r, E[(x - r)^2] =
  Var x + Var r per pixel, so subtracting the reference's own (estimated) variance leaves an
  unbiased estimate of x's MSE; RMSE = sqrt(max(MSE, 0)).
- relMSE = mean(((x - r)^2 - v_r) / (r^2 + 0.01)): the MSE relative to the pixel's squared value;
  the 0.01 keeps pixels darker than ~0.1 from dominating.
- bias: the image mean's difference d = mean(x) - mean(r), for each channel and for the mean of
  the three. Pixels are independent (with --sampler independent, the default here, wavepath's
  random numbers are a hash of pixel, sample and seed), so Var d = (sum v_x + sum v_r) / n_pixels^2 per channel. For the mean of the channels,
  whose covariance the variance images do not give, each pixel's variance is bounded by
  (mean of the channel standard deviations)^2 (full correlation, Cauchy-Schwarz): that CI is
  conservative. The 95% interval is d +- 1.96 sqrt(Var d); z = d / sqrt(Var d).
"""

import hashlib
import json
import os
import re
import subprocess
import tempfile

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEFAULT_MANIFEST = os.path.join(REPO, "scenes", "failure", "manifest.json")
REL_EPS = 0.01
REFERENCE_SEED = 987654321  # never used for the runs compared with a reference

# ---- Configurations ------------------------------------------------------------------------------
# A configuration is a strategy with optional settings: "mis", "nee", "bsdf", then any of
# "+heuristic=power|balance", "+select=power|uniform", "+rr=off|N" (Russian roulette after N
# scattering events; off: none), "+depth=N" (--max-depth), "+sampler=independent|sobol". Unset
# settings are wavepath's defaults (power heuristic, power light selection, roulette after 5, max
# depth 12) except the sampler: independent, because every statistic here takes a pixel's error
# variance from wavepath's variance image, which is that only for independent samples (Sobol'
# points have less error than their sample variance says, so MSEs net of the reference's variance
# and z-scores would be wrong).

DEFAULT_CONFIGS = ("mis", "nee", "bsdf", "mis+heuristic=balance", "mis+select=uniform",
                   "mis+rr=off", "mis+rr=1")


def config_args(config):
    """wavepath command-line arguments of a configuration string; ValueError when malformed."""
    parts = config.split("+")
    strategy = parts[0]
    if strategy not in ("mis", "nee", "bsdf"):
        raise ValueError("configuration %r: strategy must be mis, nee or bsdf" % config)
    args = ["--strategy", strategy]
    sampler = "independent"
    for part in parts[1:]:
        key, sep, value = part.partition("=")
        if not sep:
            raise ValueError("configuration %r: %r is not key=value" % (config, part))
        if key == "heuristic" and value in ("power", "balance"):
            args += ["--mis-heuristic", value]
        elif key == "select" and value in ("power", "uniform"):
            args += ["--light-select", value]
        elif key == "rr" and value == "off":
            args += ["--no-rr"]
        elif key == "rr" and value.isdigit():
            args += ["--rr-depth", value]
        elif key == "rrt" and re.fullmatch(r"[0-9]*\.?[0-9]+", value):
            args += ["--rr-threshold", value]  # wavepath checks the range
        elif key == "depth" and value.isdigit():
            args += ["--max-depth", value]
        elif key == "sampler" and value in ("independent", "sobol", "sobol-padded"):
            sampler = value
        else:
            raise ValueError("configuration %r: unknown setting %r" % (config, part))
    return args + ["--sampler", sampler]


# ---- Manifest ------------------------------------------------------------------------------------

def load_manifest(path=DEFAULT_MANIFEST):
    """The manifest dict, each scene entry given absolute 'path' and 'render_args'."""
    with open(path) as f:
        manifest = json.load(f)
    base = os.path.dirname(os.path.abspath(path))
    for entry in manifest["scenes"]:
        entry["path"] = os.path.join(base, entry["file"])
        args = list(entry.get("args", []))
        for i, a in enumerate(args):  # the argument after --env is a file next to the manifest
            if i > 0 and args[i - 1] == "--env":
                args[i] = os.path.join(base, a)
        entry["render_args"] = args
    manifest["by_name"] = {e["name"]: e for e in manifest["scenes"]}
    return manifest


# ---- Images --------------------------------------------------------------------------------------

def read_pfm(path):
    """A colour PFM file ("PF", "W H", scale; negative scale: little-endian) as an
    (height, width, 3) float64 array, top row first (PFM stores rows bottom-up)."""
    with open(path, "rb") as f:
        data = f.read()
    lines = data.split(b"\n", 3)
    if lines[0].strip() != b"PF" or len(lines) < 4:
        raise ValueError("%s: not a colour PFM" % path)
    width, height = (int(t) for t in lines[1].split())
    dtype = "<f4" if float(lines[2]) < 0 else ">f4"
    pix = np.frombuffer(lines[3], dtype=dtype, count=width * height * 3)
    return pix.reshape(height, width, 3)[::-1].astype(np.float64)


class RenderError(RuntimeError):
    pass


def render(wavepath, scene, args, width, height, spp, seed, config="mis", workdir=None):
    """Renders with wavepath; returns (image, variance image, the --json dict). RenderError
    (with wavepath's message) when it fails."""
    own = workdir is None
    workdir = workdir or tempfile.mkdtemp(prefix="wp-acc-")
    out = os.path.join(workdir, "out.pfm")
    cmd = [wavepath, "render", scene, "--width", str(width), "--height", str(height),
           "--spp", str(spp), "--seed", str(seed), "-o", out, "--variance", "--json", "-q"]
    cmd += list(args) + config_args(config)
    try:
        proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        if proc.returncode != 0:
            raise RenderError("%s failed (%d): %s" % (" ".join(cmd), proc.returncode,
                                                     proc.stderr.strip() or proc.stdout.strip()))
        info = json.loads(proc.stdout.strip().splitlines()[-1])
        return read_pfm(out), read_pfm(out[:-4] + ".variance.pfm"), info
    finally:
        if own:
            for f in (out, out[:-4] + ".variance.pfm"):
                if os.path.exists(f):
                    os.remove(f)
            os.rmdir(workdir)


# ---- References ----------------------------------------------------------------------------------

def _file_digest(h, path):
    with open(path, "rb") as f:
        h.update(f.read())


def reference_key(wavepath, entry, width, height, spp):
    """Cache key: the scene file and the files its arguments name, the arguments, the size, the
    sample count and seed, and the wavepath binary's path and modification time."""
    h = hashlib.sha256()
    _file_digest(h, entry["path"])
    for a in entry["render_args"]:
        if os.path.isfile(a):
            _file_digest(h, a)
    st = os.stat(wavepath)
    h.update(json.dumps([entry["render_args"], width, height, spp, REFERENCE_SEED,
                         os.path.abspath(wavepath), st.st_mtime_ns]).encode())
    return h.hexdigest()[:24]


def reference(wavepath, manifest, name, width, height, spp, cache_dir, log=None):
    """(image, variance image, description) of scene `name`'s reference at width x height:
    its closed form (variance 0), black (closed_box), another scene's reference, or an MIS render
    of `spp` samples per pixel, cached in cache_dir."""
    entry = manifest["by_name"][name]
    ref = entry.get("reference", {"kind": "render"})
    kind = ref["kind"]
    if kind == "closed_form":
        from . import closed_form
        img = closed_form.image(ref["model"], width, height)
        return img, np.zeros_like(img), "closed form (tools/wavepath_tools/closed_form.py)"
    if kind == "black":
        img = np.zeros((height, width, 3))
        return img, np.zeros_like(img), "black: nothing can reach the inside"
    if kind == "scene":
        img, var, _ = reference(wavepath, manifest, ref["scene"], width, height, spp, cache_dir, log)
        return img, var, "%s's MIS reference (%d spp): the same scene at scale 1" % (ref["scene"], spp)
    key = reference_key(wavepath, entry, width, height, spp)
    os.makedirs(cache_dir, exist_ok=True)
    base = os.path.join(cache_dir, "%s-%s" % (name, key))
    if not (os.path.exists(base + ".npz")):
        if log:
            log("%s: rendering the reference (MIS, %d spp, %dx%d)" % (name, spp, width, height))
        img, var, info = render(wavepath, entry["path"], entry["render_args"], width, height, spp,
                                REFERENCE_SEED, "mis")
        tmp = base + ".tmp.npz"
        np.savez(tmp, img=img, var=var, info=json.dumps(info))
        os.replace(tmp, base + ".npz")
    data = np.load(base + ".npz")
    return data["img"], data["var"], "MIS render, %d spp" % spp


# ---- Statistics ----------------------------------------------------------------------------------

def compare(img, var, ref, ref_var):
    """The error statistics of the module docstring, as a dict of floats (and 3-lists)."""
    n = img.shape[0] * img.shape[1]
    sq = (img - ref) ** 2
    mse_raw = float(sq.mean())
    mse = mse_raw - float(ref_var.mean())
    rel = float(((sq - ref_var) / (ref * ref + REL_EPS)).mean())
    d_c = img.reshape(-1, 3).mean(0) - ref.reshape(-1, 3).mean(0)
    var_c = (var.reshape(-1, 3).sum(0) + ref_var.reshape(-1, 3).sum(0)) / (n * n)
    # The mean of the channels: each pixel's variance bounded by (mean channel sd)^2 (see the
    # docstring); x's and r's errors are independent, so their bounds add.
    var_mean = float((np.sqrt(var).mean(2) ** 2).sum() + (np.sqrt(ref_var).mean(2) ** 2).sum()) / (n * n)
    d = float(d_c.mean())
    sd = float(np.sqrt(var_mean))
    with np.errstate(divide="ignore", invalid="ignore"):
        z_c = np.where(var_c > 0, d_c / np.sqrt(var_c), np.where(d_c == 0, 0.0, np.inf))
    return {
        "mse_raw": mse_raw, "mse": mse, "rmse": float(np.sqrt(max(mse, 0.0))), "rel_mse": rel,
        "mean": float(img.mean()), "ref_mean": float(ref.mean()),
        "bias": d, "bias_ci95": 1.96 * sd, "z": d / sd if sd > 0 else (0.0 if d == 0 else float("inf")),
        "bias_c": [float(x) for x in d_c], "z_c": [float(x) for x in z_c],
        "ref_rms": float(np.sqrt((ref * ref).mean())),
    }
