#!/usr/bin/env python3
"""What SIMD across work-items would buy on PoCL: generate_camera_rays rewritten four ways, each
checked for whether LLVM vectorises PoCL's work-item loop and timed against the others.

The probe replaces the body of start_path (kernels/integrator/generate_camera_rays.h) in copies of
kernels/ read through WAVEPATH_KERNEL_DIR. Every variant computes the same numbers as the real
kernel for a pinhole camera (the pixel jitter's Sobol' pair, the ray through it, the ray's tmin),
then stores twelve floats of them, so the variants differ only in:

  rng     "pair": the jitter from rng_get2, whose uint2 lanes LLVM 15's loop vectoriser refuses
          ("instruction return type cannot be vectorized"); "scalar": the same two chains written
          in uint, which it accepts (the same bits: the images of all four are identical)
  layout  "lanes": lanes 0 and 2 of six float4 path-state fields, as the state is laid out now
          (a field's lanes side by side, 16 bytes per path; no two stores adjacent, else PoCL's
          first -O3 SLP-merges them into one vector store, which the loop vectoriser refuses in
          turn); "arrays": twelve arrays of one float per path (one per component), so that
          neighbouring work-items store neighbouring words

The rays are wrong beyond the first store (a probe, not a renderer): the later stages' times are
meaningless, the camera stage's (--profile) is what is compared. The real kernel is timed too.

--layout-cost measures what the "arrays" layout costs the kernels as they are (no SIMD across
paths): tools/studies/simd_probe_layout.patch changes only the path-state accessors (path_state.h) and
the cache hints (stage.h) to one array per component within each field's buffer, and whole
renders with it are timed against the kernels of the tree, alternated run by run; both must give
the same image bit for bit (checked).

  python3 -m tools.studies.simd_probe                      the table of docs/performance.md (5 alternated rounds)
  python3 -m tools.studies.simd_probe --rounds 9 --spp 128
  python3 -m tools.studies.simd_probe --layout-cost        the layout's cost to the whole pipeline (5 runs each
                                           of the Cornell box, its Lambertian copy and
                                           DamagedHelmet when ../shared/assets has it)
  python3 -m tools.studies.simd_probe --check              the ctest: writes the variants, applies the layout
                                           patch and compiles one variant, which must get a
                                           verdict (fails when the kernels no longer have what
                                           the probe changes, or the probe no longer builds);
                                           what LLVM decides is not asserted

Exit status 0; 2 when wavepath fails, the kernel no longer has the text the probe replaces, or a
variant gets no verdict; 77 (CTest's skip) when wavepath's default device is not PoCL's.
Standard library only.
"""

import argparse
import hashlib
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile

from tools.wavepath_tools import peers_scene, pocl_remarks

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
LAYOUT_PATCH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "simd_probe_layout.patch")
HELMET = os.path.join(ROOT, "..", "shared", "assets", "models", "DamagedHelmet",
                      "DamagedHelmet.glb")
KERNELS = os.path.join(ROOT, "kernels")
CAMERA = os.path.join("integrator", "generate_camera_rays.h")
BEGIN = "WP_STAGE_FN void start_path("
END = "\n}\n"

RNG = {
    "pair": """  const float2 jitter = rng_get2(rng, WP_DIM_PIXEL_X);
  const float jx = jitter.x, jy = jitter.y;
""",
    "scalar": """  const uint seed = rng_group_seed(rng, WP_DIM_PIXEL_X);
  const uint index = rng_owen(rng.sample, seed);
  const uint kx = wp_hash(seed ^ WP_KEY_FIRST), ky = wp_hash(seed ^ WP_KEY_SECOND);
  const float jx = rng_float(rng_reverse_bits(rng_nested_permute(index, kx)));
  const float jy = rng_float(rng_reverse_bits(rng_nested_permute(rng_taylor_shift(index), ky)));
""",
}

LAYOUT = {
    "lanes": "#define F(field, lane) ((__global float*)(paths.field + slot))[lane]",
    "arrays": "#define F(field, lane) "
              "((__global float*)paths.field)[(lane) * launch.path_count + slot]",
}

BODY = """WP_STAGE_FN void start_path(const Camera* camera, Paths paths, Launch launch, uint slot) {
  const uint pixel = path_pixel(launch, slot);
  const uint px = pixel % launch.width, py = pixel / launch.width;
  const Rng rng = rng_make(pixel, path_sample(launch, slot), launch.seed, 0u);
@RNG@  const float nx = 2.0f * ((float)px + jx) / (float)launch.width - 1.0f;
  const float ny = 1.0f - 2.0f * ((float)py + jy) / (float)launch.height;
  const float4 fw = camera->forward, rt = camera->right, up = camera->up, pos = camera->position;
  float dx = fw.x + (nx * rt.x + ny * up.x);
  float dy = fw.y + (nx * rt.y + ny * up.y);
  float dz = fw.z + (nx * rt.z + ny * up.z);
  const float inv = 1.0f / sqrt(dx * dx + dy * dy + dz * dz);
  dx *= inv, dy *= inv, dz *= inv;
  const float tmin = pos.w / (dx * fw.x + dy * fw.y + dz * fw.z);
@LAYOUT@
  F(ray_o, 0) = pos.x, F(ray_o, 2) = pos.z;
  F(ray_d, 0) = dx, F(ray_d, 2) = dz;
  F(throughput, 0) = dy, F(throughput, 2) = 1.0f;
  F(radiance, 0) = 0.0f, F(radiance, 2) = tmin;
  F(hit, 0) = 1.0f, F(hit, 2) = 1.0f;
  F(shadow_l, 0) = 0.0f, F(shadow_l, 2) = 0.0f;
#undef F
}
"""


def fail(message, status=2):
    print("simd_probe.py: " + message, file=sys.stderr)
    sys.exit(status)


def make_variant(folder, rng, layout):
    shutil.copytree(KERNELS, folder)
    path = os.path.join(folder, CAMERA)
    with open(path) as f:
        text = f.read()
    begin = text.find(BEGIN)
    end = text.find(END, begin)
    if begin < 0 or end < 0:
        fail(f"{CAMERA} has no `{BEGIN}...`: the probe needs updating")
    body = BODY.replace("@RNG@", RNG[rng]).replace("@LAYOUT@", LAYOUT[layout])
    text = text[:begin] + body + text[end + len(END):]
    with open(path, "w") as f:
        f.write(text)


def make_arrays_layout(folder):
    """kernels/ with the path state in one array per component (tools/studies/simd_probe_layout.patch)."""
    shutil.copytree(KERNELS, folder)
    env = dict(os.environ, GIT_CEILING_DIRECTORIES=os.path.dirname(folder))
    p = subprocess.run(["git", "apply", "-p2", LAYOUT_PATCH], cwd=folder, env=env,
                       capture_output=True, text=True)
    if p.returncode != 0:
        fail(f"{os.path.relpath(LAYOUT_PATCH, ROOT)} no longer applies: {p.stderr.strip()}")


def layout_cost(a, tmp):
    """Samples/s of whole renders, the kernels of the tree against the arrays layout."""
    dirs = {"now": KERNELS, "arrays": os.path.join(tmp, "arrays")}
    make_arrays_layout(dirs["arrays"])
    lambertian = os.path.join(tmp, "lambertian.gltf")
    peers_scene.lambertian_copy(a.scene, lambertian)
    scenes = [(os.path.basename(a.scene), a.scene),
              ("Lambertian copy of " + os.path.basename(a.scene), lambertian)]
    if os.path.exists(HELMET):
        scenes.append((os.path.basename(HELMET), HELMET))
    size = ["--width", str(a.size), "--height", str(a.size), "--spp", str(a.spp)]
    print(f"Whole renders, {a.size} x {a.size} x {a.spp} spp, samples/s, medians of {a.rounds} "
          "alternated runs:\n")
    print("| scene | layout now | one array per component | ratio |")
    print("|---|--:|--:|--:|")
    for name, scene in scenes:
        rate = {k: [] for k in dirs}
        digest = {}
        for k, d in dirs.items():  # one unmeasured run each: the kernel caches
            out = os.path.join(tmp, k + ".pfm")
            run(a.wavepath, scene, size + ["-o", out], {"WAVEPATH_KERNEL_DIR": d})
            with open(out, "rb") as f:
                digest[k] = hashlib.md5(f.read()).hexdigest()
        if digest["now"] != digest["arrays"]:
            fail(f"{scene}: the arrays layout changed the image")
        for _ in range(a.rounds):
            for k, d in dirs.items():
                out = run(a.wavepath, scene, size + ["-o", os.path.join(tmp, "t.pfm")],
                          {"WAVEPATH_KERNEL_DIR": d})
                rate[k].append(json.loads(out.stdout)["samples_per_second"])
        now, arrays = statistics.median(rate["now"]), statistics.median(rate["arrays"])
        print(f"| {name} | {now:.4g} | {arrays:.4g} | {arrays / now:.3f} |")


def run(wavepath, scene, args, env_extra):
    env = dict(os.environ, **env_extra)
    p = subprocess.run([wavepath, "render", scene, "-q", "--json"] + args,
                       capture_output=True, text=True, env=env)
    if p.returncode != 0:
        fail(f"wavepath failed ({p.returncode}): {p.stderr.strip()[:400]}")
    return p


def verdict(wavepath, scene, kernel_dir, tmp):
    """LLVM's verdict on generate_camera_rays' work-item loop (tools/wavepath_tools/pocl_remarks.py's reading)."""
    cache = tempfile.mkdtemp(dir=tmp)
    env = {"POCL_CACHE_DIR": cache, "POCL_VECTORIZER_REMARKS": "1"}
    if kernel_dir:
        env["WAVEPATH_KERNEL_DIR"] = kernel_dir
    p = run(wavepath, scene, ["--width", "16", "--height", "16", "--spp", "1", "--no-kernel-cache",
                              "-o", os.path.join(tmp, "v.pfm")], env)
    k = pocl_remarks.analyse(p.stdout + p.stderr).get("generate_camera_rays")
    if not k:
        fail("no remarks for generate_camera_rays")
    v = pocl_remarks.verdict(k)
    if not v:
        fail("generate_camera_rays' work-item loop got no verdict")
    return v


def main():
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--wavepath", default=os.path.join(ROOT, "build", "wavepath"))
    p.add_argument("--scene", default=os.path.join(ROOT, "scenes", "cornell_box.gltf"))
    p.add_argument("--size", type=int, default=512, help="square image side (default 512)")
    p.add_argument("--spp", type=int,
                   help="samples per pixel (default 64; 16 with --layout-cost)")
    p.add_argument("--rounds", type=int, default=5, help="alternated rounds (default 5)")
    p.add_argument("--check", action="store_true",
                   help="write the variants and the layout, build one variant (the ctest)")
    p.add_argument("--layout-cost", action="store_true",
                   help="time whole renders with the arrays layout (default --spp 16)")
    a = p.parse_args()
    device, row = pocl_remarks.default_device(a.wavepath)
    if device is None or "Portable Computing Language" not in row:
        fail(f"wavepath's default device ({device or 'none'}) is not PoCL's", 77)
    if a.layout_cost:
        a.spp = a.spp or 16
        with tempfile.TemporaryDirectory() as tmp:
            layout_cost(a, tmp)
        return
    a.spp = a.spp or 64
    variants = [("real kernel", None)] + [(f"rng {r}, layout {l}", (r, l))
                                          for l in ("lanes", "arrays") for r in ("pair", "scalar")]
    with tempfile.TemporaryDirectory() as tmp:
        dirs = {}
        for name, v in variants:
            dirs[name] = None
            if v:
                dirs[name] = os.path.join(tmp, "%s-%s" % v)
                make_variant(dirs[name], *v)
        if a.check:  # the variant the probe is about: it must still build and get a verdict
            make_arrays_layout(os.path.join(tmp, "arrays"))
            name = "rng scalar, layout arrays"
            print(f"{name}: {verdict(a.wavepath, a.scene, dirs[name], tmp)}")
            return
        verdicts = {name: verdict(a.wavepath, a.scene, dirs[name], tmp) for name, _ in variants}
        times = {name: [] for name, _ in variants}
        for _ in range(a.rounds):
            for name, _ in variants:
                env = {"WAVEPATH_KERNEL_DIR": dirs[name]} if dirs[name] else {}
                out = run(a.wavepath, a.scene,
                          ["--width", str(a.size), "--height", str(a.size), "--spp", str(a.spp),
                           "--profile", "-o", os.path.join(tmp, "t.pfm")], env)
                times[name].append(json.loads(out.stdout)["stage_seconds"]["generate_camera_rays"])
    base = statistics.median(times["real kernel"])
    print(f"generate_camera_rays, {a.size} x {a.size} x {a.spp} spp, medians of {a.rounds} "
          "alternated rounds (`--profile`):\n")
    print("| variant | work-item loop | stage seconds | runs | real kernel / variant |")
    print("|---|---|--:|---|--:|")
    for name, _ in variants:
        m = statistics.median(times[name])
        runs = ", ".join(f"{t:.3f}" for t in sorted(times[name]))
        print(f"| {name} | {verdicts[name]} | {m:.3f} | {runs} | {base / m:.2f} |")


if __name__ == "__main__":
    main()
