#!/usr/bin/env python3
"""Peer benchmark: wavepath against Mitsuba 3 (LLVM variant, CPU) and Blender Cycles (CPU) on one of
the project's own glTF scenes, converted exactly; error against whole-process time, written as a
Markdown page with a chart and a table of time-to-target ratios.

    tools/peers.py --scene scenes/cornell_box.gltf --width 128 --height 128 --out docs/peers.md

Run `tools/peers.py --help` for the options. Not part of tools/test.sh: the peers come from PyPI
(`mitsuba`, `bpy`, with numpy and matplotlib) into a virtual environment the script creates
(--venv, default build/peers-venv) and then re-runs itself in. Mitsuba's LLVM variant needs a
libLLVM shared library (DRJIT_LIBLLVM_PATH when set, else the newest
/usr/lib/x86_64-linux-gnu/libLLVM-*.so*; Debian: libllvm19, with which it was run: with LLVM 15,
Dr.Jit 1.5's kernels stop with "LLVM ERROR: Cannot select ... fminimum"); bpy 5.0 needs Python
3.11 (--python). The converter is tools/peers_scene.py, tested by tests/test_peers_scene.py.
"""

import argparse
import glob
import hashlib
import json
import math
import os
import platform
import re
import subprocess
import sys
import time

TOOLS = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(TOOLS)
sys.path.insert(0, TOOLS)
import peers_scene  # noqa: E402

PACKAGES = {"mitsuba": ["mitsuba"], "cycles": ["bpy"]}
BASE_PACKAGES = ["numpy", "matplotlib"]
RENDERERS = ("wavepath", "mitsuba", "cycles")
LABELS = {"wavepath": "wavepath", "mitsuba": "Mitsuba 3 (llvm_ad_rgb)", "cycles": "Cycles (CPU)"}
VENV_MARK = "WP_PEERS_IN_VENV"

DESCRIPTION = """\
Converts the scene (tools/peers_scene.py: world-space triangle meshes, Lambertian materials,
emitters, point lights, the first perspective camera; anything else is refused) for each peer.
A glTF material with metallic 0 is not Lambertian: glTF, and wavepath, put a rough specular layer
(Fresnel 0.04 at normal incidence, 1 at grazing) over the diffuse one, which neither peer's diffuse
BSDF has. So when a material lacks KHR_materials_specular specularFactor 0, the benchmark renders
a copy of the scene with that factor 0 on every material (written to --work/lambertian.gltf), in
wavepath too: all three render the same purely Lambertian scene.

  Mitsuba 3  PLY meshes, `diffuse` BSDF with the base colour, an `area` emitter (one-sided, front =
             counter-clockwise side, as in wavepath) with the emission as radiance, `point`
             emitters with the intensity in W/sr, a `perspective` sensor (fov_axis y = the
             glTF yfov), box reconstruction filter (one pixel, wavepath's), `independent`
             sampler, `path` integrator with max_depth = --max-depth + 1 and rr_depth =
             --rr-depth + 1 (Mitsuba counts path segments from the camera, so max_depth 1 sees
             emitters only and 2 adds direct light; wavepath counts scattering events, so
             wavepath's depth d is Mitsuba's d + 1).
  Cycles     Mesh objects with a material Diffuse BSDF (roughness 0: Lambert) + Emission
             (colour = the radiance, strength 1), and, for a material that is not double-sided,
             a Mix Shader that turns back faces into a Transparent BSDF: wavepath culls back
             faces, rays pass through them (emission sampling set to front faces only). Camera
             with vertical sensor fit and angle = yfov; Box pixel filter of width 1; max
             bounces and diffuse bounces = --max-depth - 1 (Cycles counts indirect bounces:
             0 is direct light only, wavepath's depth 1; measured: with max bounces 1 against
             wavepath's depth 1 the image mean was 15% brighter, an extra bounce); no clamping,
             no adaptive sampling, no denoising; black world; view
             transform Standard, exposure 0 (the EXR is scene-linear anyway). Point lights are
             refused (Blender's watt convention is not verified here).

Each renderer renders the sweep of --spp counts; each run is a separate process and its wall time,
from start to the image on disk (start-up, kernel or JIT compilation, scene load included), is
measured by this script. One unmeasured 1-spp run of each renderer first fills the caches that
persist between processes (wavepath's kernel binary and BVH caches, Dr.Jit's kernel cache), so that
no measured run pays a one-off compilation. relMSE is tools/accuracy_lib.py's: mean(((x - r)^2 -
var_r) / (r^2 + 0.01)) against one common reference, a wavepath render of --ref-spp samples with its
variance image (so the reference's own noise is subtracted). The conversion is checked by the image
means: each peer's largest run against the reference, per channel (their ratio must be 1 within
noise; a wrong conversion also shows as relMSE that stops falling). Time to reach a relMSE target:
interpolated linearly on log-log between the two runs around it; beyond the last run, extrapolated
as relMSE ~ 1 / time from it (marked ~).

The page (--out) is rewritten on every run except for what follows its line
"<!-- notes: kept when the page is regenerated -->": hand-written notes on the figures.
"""


# ---- Virtual environment -------------------------------------------------------------------------

def log(msg):
    print("peers: " + msg, file=sys.stderr, flush=True)


def venv_python(venv):
    return os.path.join(venv, "bin", "python")


def ensure_venv(a):
    """Creates --venv with the packages the renderers need (pip install is a no-op when present)
    and re-executes this script inside it, unless already there."""
    if os.environ.get(VENV_MARK) == "1":
        return
    py = venv_python(a.venv)
    if not os.path.exists(py):
        log("creating %s with %s" % (a.venv, a.python))
        subprocess.run([a.python, "-m", "venv", a.venv], check=True)
    packages = list(BASE_PACKAGES)
    for r in a.renderers:
        packages += PACKAGES.get(r, [])
    proc = subprocess.run([py, "-m", "pip", "install", "-q", "--disable-pip-version-check"]
                          + packages)
    if proc.returncode != 0:
        sys.exit("peers.py: error: pip install %s failed in %s (bpy needs the Python version its "
                 "wheel was built for, 3.11 for bpy 5.0: see --python; --renderers can leave a "
                 "peer out)" % (" ".join(packages), a.venv))
    os.environ[VENV_MARK] = "1"
    os.execv(py, [py, os.path.abspath(__file__)] + sys.argv[1:])


def find_libllvm():
    path = os.environ.get("DRJIT_LIBLLVM_PATH")
    if path:
        return path
    found = (glob.glob("/usr/lib/x86_64-linux-gnu/libLLVM-*.so*")
             + glob.glob("/usr/lib/llvm-*/lib/libLLVM*.so*"))

    def version(p):
        m = re.search(r"libLLVM-?(\d+)", p)
        return (int(m.group(1)) if m else 0, -len(p))
    return max(found, key=version) if found else None


# ---- Workers (run as `peers.py --worker RENDERER JOB.json`, one process per render) -------------

def worker_mitsuba(job, scene):
    import mitsuba as mi
    import numpy as np
    mi.set_variant(job["variant"])
    cam = scene["camera"]
    target = [cam["position"][i] + cam["forward"][i] for i in range(3)]
    d = {"type": "scene",
         "integrator": {"type": "path", "max_depth": job["max_depth"] + 1,
                        "rr_depth": job["rr_depth"] + 1},
         "sensor": {"type": "perspective", "fov_axis": "y", "fov": math.degrees(cam["yfov"]),
                    "near_clip": 1e-3, "far_clip": 1e4,
                    "to_world": mi.ScalarTransform4f().look_at(origin=cam["position"],
                                                               target=target, up=cam["up"]),
                    "sampler": {"type": "independent", "sample_count": job["spp"]},
                    "film": {"type": "hdrfilm", "width": job["width"], "height": job["height"],
                             "pixel_format": "rgb", "rfilter": {"type": "box"}}}}
    for k, mesh in enumerate(scene["meshes"]):
        mat = scene["materials"][mesh["material"]]
        bsdf = {"type": "diffuse", "reflectance": {"type": "rgb", "value": mat["reflectance"]}}
        if mat["double_sided"]:
            bsdf = {"type": "twosided", "bsdf": bsdf}
        shape = {"type": "ply", "filename": mesh["ply"], "face_normals": True, "bsdf": bsdf}
        if max(mat["emission"]) > 0.0:
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb",
                                                              "value": mat["emission"]}}
        d["shape%d" % k] = shape
    for k, light in enumerate(scene["point_lights"]):
        d["light%d" % k] = {"type": "point", "position": light["position"],
                            "intensity": {"type": "rgb", "value": light["intensity"]}}
    img = mi.render(mi.load_dict(d), spp=job["spp"], seed=job["seed"])
    np.save(job["out"], np.array(img, dtype=np.float64)[:, :, :3])


def _cycles_material(bpy, mat):
    m = bpy.data.materials.new(mat["name"])
    m.use_nodes = True
    nodes, links = m.node_tree.nodes, m.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    out.target = "CYCLES"
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = tuple(mat["reflectance"]) + (1.0,)
    diffuse.inputs["Roughness"].default_value = 0.0
    shader = diffuse.outputs[0]
    if max(mat["emission"]) > 0.0:
        emission = nodes.new("ShaderNodeEmission")
        emission.inputs["Color"].default_value = tuple(mat["emission"]) + (1.0,)
        emission.inputs["Strength"].default_value = 1.0
        add = nodes.new("ShaderNodeAddShader")
        links.new(diffuse.outputs[0], add.inputs[0])
        links.new(emission.outputs[0], add.inputs[1])
        shader = add.outputs[0]
        m.cycles.emission_sampling = "FRONT_AND_BACK" if mat["double_sided"] else "FRONT"
    else:
        m.cycles.emission_sampling = "NONE"
    if not mat["double_sided"]:
        geometry = nodes.new("ShaderNodeNewGeometry")
        transparent = nodes.new("ShaderNodeBsdfTransparent")
        mix = nodes.new("ShaderNodeMixShader")
        links.new(geometry.outputs["Backfacing"], mix.inputs[0])
        links.new(shader, mix.inputs[1])
        links.new(transparent.outputs[0], mix.inputs[2])
        shader = mix.outputs[0]
    links.new(shader, out.inputs["Surface"])
    return m


def worker_cycles(job, scene):
    import bpy
    import numpy as np
    if scene["point_lights"]:
        raise SystemExit("peers.py: error: Cycles: point lights are not converted (Blender's "
                         "point light power convention is not verified here)")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    sc.render.engine = "CYCLES"
    cy = sc.cycles
    cy.device = "CPU"
    cy.samples = job["spp"]
    cy.seed = job["seed"]
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    bounces = job["max_depth"] - 1  # Cycles' 0 bounces: direct light, wavepath's depth 1
    cy.max_bounces = cy.diffuse_bounces = bounces
    cy.glossy_bounces = cy.transmission_bounces = cy.volume_bounces = bounces
    cy.transparent_max_bounces = 64
    cy.sample_clamp_direct = cy.sample_clamp_indirect = 0.0
    cy.blur_glossy = 0.0
    cy.pixel_filter_type = "BOX"
    cy.filter_width = 1.0
    cy.film_exposure = 1.0
    sc.render.resolution_x, sc.render.resolution_y = job["width"], job["height"]
    sc.render.resolution_percentage = 100
    sc.render.film_transparent = False
    sc.view_settings.view_transform = "Standard"
    sc.view_settings.look = "None"
    sc.view_settings.exposure = 0.0
    sc.view_settings.gamma = 1.0
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    sc.world = world

    materials = [_cycles_material(bpy, m) for m in scene["materials"]]
    for mesh in scene["meshes"]:
        me = bpy.data.meshes.new(mesh["name"])
        me.from_pydata([tuple(p) for p in mesh["positions"]], [],
                       [tuple(t) for t in mesh["triangles"]])
        me.materials.append(materials[mesh["material"]])
        me.update()
        ob = bpy.data.objects.new(mesh["name"], me)
        sc.collection.objects.link(ob)

    cam = scene["camera"]
    data = bpy.data.cameras.new("camera")
    data.type = "PERSP"
    data.sensor_fit = "VERTICAL"
    data.angle_y = cam["yfov"]
    data.clip_start = 1e-3
    data.clip_end = 1e4
    ob = bpy.data.objects.new("camera", data)
    f, u = cam["forward"], cam["up"]
    right = (f[1] * u[2] - f[2] * u[1], f[2] * u[0] - f[0] * u[2], f[0] * u[1] - f[1] * u[0])
    from mathutils import Matrix
    ob.matrix_world = Matrix([[right[i], u[i], -f[i], cam["position"][i]] for i in range(3)]
                             + [[0.0, 0.0, 0.0, 1.0]])
    sc.collection.objects.link(ob)
    sc.camera = ob

    exr = job["out"][:-4] + ".exr"
    sc.render.image_settings.file_format = "OPEN_EXR"
    sc.render.image_settings.color_depth = "32"
    sc.render.image_settings.color_mode = "RGB"
    sc.render.filepath = exr
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(exr)
    pix = np.empty(job["width"] * job["height"] * img.channels, dtype=np.float32)
    img.pixels.foreach_get(pix)
    pix = pix.reshape(job["height"], job["width"], img.channels)[::-1, :, :3]  # rows bottom-up
    np.save(job["out"], pix.astype(np.float64))
    os.remove(exr)


def worker_main(renderer, job_path):
    with open(job_path) as f:
        job = json.load(f)
    with open(job["scene"]) as f:
        scene = json.load(f)
    {"mitsuba": worker_mitsuba, "cycles": worker_cycles}[renderer](job, scene)


# ---- The sweep -----------------------------------------------------------------------------------

def parse_args(argv):
    p = argparse.ArgumentParser(prog="peers.py", description=__doc__.split("\n\n")[0],
                                epilog=DESCRIPTION,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scene", default=os.path.join(REPO, "scenes", "cornell_box.gltf"))
    p.add_argument("--width", type=int, default=128)
    p.add_argument("--height", type=int, default=128)
    p.add_argument("--spp", default="4,16,64,256",
                   help="comma-separated sample counts of the sweep (default %(default)s)")
    p.add_argument("--ref-spp", type=int, default=2048,
                   help="samples per pixel of the wavepath reference (default %(default)s)")
    p.add_argument("--max-depth", type=int, default=12,
                   help="scattering events, wavepath's --max-depth (default %(default)s)")
    p.add_argument("--rr-depth", type=int, default=5,
                   help="Russian roulette after this many scattering events (wavepath's default)")
    p.add_argument("--targets", default="1e-2,3e-3,1e-3",
                   help="relMSE targets of the time table (default %(default)s)")
    p.add_argument("--renderers", default=",".join(RENDERERS),
                   help="comma-separated subset of %s" % ", ".join(RENDERERS))
    p.add_argument("--wavepath", default=os.path.join(REPO, "build", "wavepath"))
    p.add_argument("--venv", default=os.path.join(REPO, "build", "peers-venv"))
    p.add_argument("--python", default=sys.executable,
                   help="interpreter the venv is created with (default: this one)")
    p.add_argument("--work", default=os.path.join(REPO, "build", "peers-work"),
                   help="scratch folder: converted scene, images, the cached reference")
    p.add_argument("--mitsuba-variant", default="llvm_ad_rgb")
    p.add_argument("--out", default=os.path.join(REPO, "docs", "peers.md"),
                   help="the Markdown page; the chart is written next to it")
    p.add_argument("--quick", action="store_true",
                   help="a smoke run: 64 x 64, spp 4,16, reference 256 spp")
    a = p.parse_args(argv)
    if a.quick:
        a.width, a.height, a.spp, a.ref_spp = 64, 64, "4,16", 256
    a.spp = [int(s) for s in a.spp.split(",")]
    a.targets = [float(t) for t in a.targets.split(",")]
    a.renderers = [r for r in a.renderers.split(",") if r]
    if "cycles" in a.renderers and a.max_depth < 1:
        p.error("Cycles cannot render --max-depth 0 (emission only): its least is direct light")
    bad = [r for r in a.renderers if r not in RENDERERS]
    if bad:
        p.error("unknown renderer(s) %s" % ", ".join(bad))
    if not os.access(a.wavepath, os.X_OK):
        p.error("%s is not an executable (build it: cmake --build build --target wavepath)"
                % a.wavepath)
    a.argv = argv
    return a


def timed(cmd, env=None):
    """Runs cmd; its wall time in seconds. Exits with its output when it fails."""
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          env=env)
    t = time.perf_counter() - t0
    if proc.returncode != 0:
        sys.exit("peers.py: error: %s failed (%d):\n%s" % (" ".join(cmd), proc.returncode,
                                                          proc.stdout[-4000:]))
    return t, proc.stdout


def convert(a):
    """Converts the scene into --work (scene.json with PLY paths); returns the description and
    its path. Sets a.render_scene, the glTF wavepath renders: --scene itself, or its Lambertian
    copy (specularFactor 0) when a material has glTF's default specular layer."""
    os.makedirs(a.work, exist_ok=True)
    a.render_scene = a.scene
    scene = peers_scene.load(a.scene)
    if any(m["specular"] != 0.0 for m in scene["materials"]):
        if not a.scene.endswith(".gltf"):
            sys.exit("peers.py: error: %s has materials with glTF's specular layer; the Lambertian "
                     "copy is written for .gltf files only" % a.scene)
        a.render_scene = os.path.join(a.work, "lambertian.gltf")
        peers_scene.lambertian_copy(a.scene, a.render_scene)
        scene = peers_scene.load(a.render_scene)
    for k, mesh in enumerate(scene["meshes"]):
        mesh["ply"] = os.path.join(a.work, "mesh%d.ply" % k)
        peers_scene.write_ply(mesh["ply"], mesh)
    for m in scene["materials"]:
        if m["double_sided"] and max(m["emission"]) > 0.0:
            sys.exit("peers.py: error: material %r: double-sided emission has no exact Mitsuba "
                     "equivalent" % m["name"])
    path = os.path.join(a.work, "scene.json")
    with open(path, "w") as f:
        json.dump(scene, f)
    return scene, path


def run_one(a, renderer, spp, seed, scene_json, env):
    """(wall seconds, image top row first)."""
    import numpy as np
    import accuracy_lib as al
    out = os.path.join(a.work, "%s-%d.npy" % (renderer, spp))
    if renderer == "wavepath":
        pfm = out[:-4] + ".pfm"
        t, _ = timed([a.wavepath, "render", a.render_scene, "--width", str(a.width), "--height",
                      str(a.height), "--spp", str(spp), "--seed", str(seed), "--max-depth",
                      str(a.max_depth), "--rr-depth", str(a.rr_depth), "-o", pfm, "--json", "-q"])
        return t, al.read_pfm(pfm)
    job = {"scene": scene_json, "spp": spp, "seed": seed, "width": a.width, "height": a.height,
           "max_depth": a.max_depth, "rr_depth": a.rr_depth, "out": out,
           "variant": a.mitsuba_variant}
    job_path = out[:-4] + ".json"
    with open(job_path, "w") as f:
        json.dump(job, f)
    t, _ = timed([sys.executable, os.path.abspath(__file__), "--worker", renderer, job_path], env)
    return t, np.load(out)


def reference(a):
    """(image, variance) of the wavepath reference, cached in --work by its settings."""
    import numpy as np
    import accuracy_lib as al
    h = hashlib.sha256()
    with open(a.render_scene, "rb") as f:
        h.update(f.read())
    h.update(json.dumps([a.width, a.height, a.ref_spp, a.max_depth, a.rr_depth,
                         os.stat(a.wavepath).st_mtime_ns]).encode())
    key = h.hexdigest()[:16]
    path = os.path.join(a.work, "reference-%d-%s.npz" % (a.ref_spp, key))
    if not os.path.exists(path):
        log("reference: wavepath, %d spp, %dx%d" % (a.ref_spp, a.width, a.height))
        img, var, info = al.render(a.wavepath, a.render_scene, ["--max-depth", str(a.max_depth),
                                                         "--rr-depth", str(a.rr_depth)],
                                   a.width, a.height, a.ref_spp, al.REFERENCE_SEED)
        np.savez(path, img=img, var=var, seconds=info["total_seconds"])
    data = np.load(path)
    return data["img"], data["var"], float(data["seconds"])


def time_to_target(points, target):
    """(seconds, mark) from [(seconds, relMSE)] sorted by sample count; mark '' interpolated,
    '~' extrapolated past the last run, '<=' reached by the first run."""
    if not points:
        return None, ""
    if points[0][1] <= target:
        return points[0][0], "<="
    for (t0, e0), (t1, e1) in zip(points, points[1:]):
        if e0 > target >= e1 and e0 > 0 and e1 > 0:
            f = math.log(target / e0) / math.log(e1 / e0)
            return math.exp(math.log(t0) + f * math.log(t1 / t0)), ""
    t, e = points[-1]
    return (t * e / target, "~") if e > 0 else (None, "")


def versions(renderers, env):
    out = {}
    if "mitsuba" in renderers:
        out["mitsuba"] = subprocess.run(
            [sys.executable, "-c", "import mitsuba, drjit; print(mitsuba.__version__, "
             "'(drjit', drjit.__version__ + ')')"],
            stdout=subprocess.PIPE, text=True, env=env).stdout.strip()
    if "cycles" in renderers:
        out["cycles"] = subprocess.run(
            [sys.executable, "-c", "import bpy; print('bpy', bpy.app.version_string)"],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True).stdout.strip()
    rev = subprocess.run(["git", "-C", REPO, "rev-parse", "--short", "HEAD"],
                         stdout=subprocess.PIPE, text=True).stdout.strip()
    out["wavepath"] = "git " + rev
    return out


def chart(a, rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.5), dpi=100)
    for r in a.renderers:
        pts = [(x["seconds"], x["rel_mse"], x["spp"]) for x in rows if x["renderer"] == r]
        ax.loglog([p[0] for p in pts], [p[1] for p in pts], "o-", label=LABELS[r])
        for t, e, spp in pts:
            ax.annotate(str(spp), (t, e), textcoords="offset points", xytext=(4, 4), fontsize=7)
    for target in a.targets:
        ax.axhline(target, color="0.7", lw=0.8, ls="--")
    ax.set_xlabel("wall time of the whole process (s)")
    ax.set_ylabel("relMSE against the reference")
    ax.set_title("%s, %d x %d (labels: samples per pixel)"
                 % (os.path.basename(a.scene), a.width, a.height))
    ax.grid(True, which="both", lw=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def fmt_t(t, mark=""):
    if t is None:
        return "—"
    return "%s%.3g s" % ({"~": "~", "<=": "≤ "}.get(mark, ""), t)


NOTES_MARK = "<!-- notes: kept when the page is regenerated -->"


def write_doc(a, rows, checks, ref_seconds, vers, chart_name, load):
    by = {r: sorted((x for x in rows if x["renderer"] == r), key=lambda x: x["spp"])
          for r in a.renderers}
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            cpu = re.search(r"model name\s*:\s*(.*)", f.read()).group(1)
    except (OSError, AttributeError):
        pass
    cmd = "tools/peers.py " + " ".join(a.argv)
    L = ["# Peer benchmark: wavepath, Mitsuba 3, Cycles", "",
         "Written by `tools/peers.py` (see its `--help`); regenerate with", "",
         "    " + cmd, "",
         "Scene `%s`, %d × %d, max depth %d scattering events, Russian roulette after %d; "
         "sweep %s samples per pixel; reference: wavepath, %d spp (%.0f s). "
         "Machine: %s, %d cores, load average %.1f before the sweep and %.1f after it "
         "(1 minute; anything above 0 is other work sharing the cores, which slows whichever "
         "renderer runs then); all three render on the CPU. "
         "Versions: %s." % (os.path.relpath(a.scene, REPO), a.width, a.height, a.max_depth,
                            a.rr_depth, ", ".join(map(str, a.spp)), a.ref_spp, ref_seconds,
                            cpu, os.cpu_count(), load[0], load[1],
                            "; ".join("%s: %s" % kv for kv in vers.items())),
         "",
         "Time is the wall time of each render's whole process (start-up, kernel or JIT "
         "compilation, scene load, rendering, writing the image), measured by the script; "
         "relMSE = mean(((x − r)² − var_r) / (r² + 0.01)) against the common reference "
         "(tools/accuracy_lib.py). One unmeasured 1-spp run of each renderer first fills the "
         "caches kept between processes (wavepath's kernel binary and BVH, Dr.Jit's kernels).", "",
         "The scene is converted exactly (`tools/peers_scene.py`, tested by "
         "`tests/test_peers_scene.py`; the mapping is in `tools/peers.py --help`): triangle "
         "meshes, Lambertian reflectance, the emissive quad as a one-sided area light with the "
         "same radiance, the camera's vertical field of view, a one-pixel box filter, the same "
         "maximum depth. %s" % ("**All three render a Lambertian copy of the scene**: glTF's "
         "metallic-0 material, as wavepath renders it, has a rough specular layer (Fresnel 0.04 "
         "at normal incidence, 1 at grazing angles) over the diffuse one, which the peers' diffuse "
         "BSDFs do not; the copy sets KHR_materials_specular specularFactor 0 on every material "
         "(wavepath then evaluates a pure Lambertian BSDF)." if a.render_scene != a.scene
                                else ""), "",
         "![relMSE against time](%s)" % chart_name, "",
         "## Time to reach a relMSE target", "",
         "Interpolated on log-log between the runs around the target; `~`: extrapolated past "
         "the largest run as relMSE ∝ 1/time; `≤`: reached by the smallest run. The ratio is the "
         "peer's time over wavepath's (above 1: wavepath is faster).", ""]
    head = "| relMSE target |" + "".join(" %s |" % LABELS[r] for r in a.renderers)
    peers = [r for r in a.renderers if r != "wavepath"]
    if "wavepath" in a.renderers:
        head += "".join(" %s / wavepath |" % LABELS[r].split(" (")[0] for r in peers)
    L += [head, "|" + "---|" * (head.count("|") - 1)]
    for target in a.targets:
        tt = {r: time_to_target([(x["seconds"], x["rel_mse"]) for x in by[r]], target)
              for r in a.renderers}
        line = "| %g |" % target + "".join(" %s |" % fmt_t(*tt[r]) for r in a.renderers)
        if "wavepath" in a.renderers:
            w = tt["wavepath"][0]
            for r in peers:
                p = tt[r][0]
                line += " %s |" % ("%.2f" % (p / w) if p and w else "—")
        L.append(line)
    L += ["", "## Every run", "", "| renderer | spp | time (s) | relMSE | image mean / reference |",
          "|---|---|---|---|---|"]
    for r in a.renderers:
        for x in by[r]:
            L.append("| %s | %d | %.2f | %.3g | %.4f |" % (LABELS[r], x["spp"], x["seconds"],
                                                         x["rel_mse"], x["mean_ratio"]))
    L += ["", "## Conversion check: image means", "",
          "Each renderer's largest run against the reference, per channel (mean over all pixels, "
          "ratio to the reference's). The standard error of the ratio is estimated from the "
          "reference's variance image scaled to the run's sample count, assuming a per-sample "
          "variance like wavepath's.", "",
          "| renderer | spp | R | G | B | ± (1 s.e.) |", "|---|---|---|---|---|---|"]
    for r in a.renderers:
        c = checks[r]
        L.append("| %s | %d | %.4f | %.4f | %.4f | %.4f |" % (LABELS[r], c["spp"], *c["ratio"],
                                                             c["se"]))
    notes = NOTES_MARK + "\n"
    if os.path.exists(a.out):
        with open(a.out) as f:
            old = f.read()
        if NOTES_MARK in old:
            notes = old[old.index(NOTES_MARK):]
    L += ["", notes]
    with open(a.out, "w") as f:
        f.write("\n".join(L))


def main(argv):
    if len(argv) >= 3 and argv[0] == "--worker":
        worker_main(argv[1], argv[2])
        return
    a = parse_args(argv)
    ensure_venv(a)
    import numpy as np
    import accuracy_lib as al

    env = dict(os.environ)
    if "mitsuba" in a.renderers and a.mitsuba_variant.startswith("llvm"):
        llvm = find_libllvm()
        if llvm is None:
            sys.exit("peers.py: error: Mitsuba's %s variant needs libLLVM (Debian: libllvm19; or "
                     "set DRJIT_LIBLLVM_PATH), or use --mitsuba-variant scalar_rgb"
                     % a.mitsuba_variant)
        env["DRJIT_LIBLLVM_PATH"] = llvm
        log("libLLVM: " + llvm)
    scene, scene_json = convert(a)
    s = peers_scene.summary(scene)
    log("scene: %d triangles, %d emitters, %d point lights"
        % (s["triangles"], len(s["emitters"]), len(scene["point_lights"])))
    ref, ref_var, ref_seconds = reference(a)
    n = ref.shape[0] * ref.shape[1]
    ref_mean = ref.reshape(-1, 3).mean(0)
    rows, checks = [], {}
    load_before = os.getloadavg()[0]
    for r in a.renderers:
        run_one(a, r, 1, 999, scene_json, env)  # warm-up, not measured: fills kernel caches
        for k, spp in enumerate(a.spp):
            seed = 1000 + k
            t, img = run_one(a, r, spp, seed, scene_json, env)
            if img.shape != ref.shape:
                sys.exit("peers.py: error: %s gave an image of shape %s, not %s"
                         % (r, img.shape, ref.shape))
            st = al.compare(img, np.zeros_like(img), ref, ref_var)
            ratio = img.reshape(-1, 3).mean(0) / ref_mean
            rows.append({"renderer": r, "spp": spp, "seconds": t, "rel_mse": st["rel_mse"],
                         "mean_ratio": float(img.mean() / ref.mean())})
            log("%-8s %5d spp  %7.2f s  relMSE %.4g  mean ratio %.4f"
                % (r, spp, t, st["rel_mse"], rows[-1]["mean_ratio"]))
            if spp == max(a.spp):
                # Var of a channel's image mean, run and reference: sum of pixel variances / n^2.
                v = ref_var.reshape(-1, 3).sum(0) / n ** 2
                se = np.sqrt(v * a.ref_spp / spp + v) / ref_mean
                checks[r] = {"spp": spp, "ratio": [float(x) for x in ratio],
                             "se": float(se.max())}
    with open(os.path.join(a.work, "runs.json"), "w") as f:
        json.dump(rows, f, indent=1)
    base = os.path.splitext(a.out)[0]
    chart_path = base + "_" + os.path.splitext(os.path.basename(a.scene))[0] + ".png"
    chart(a, rows, chart_path)
    write_doc(a, rows, checks, ref_seconds, versions(a.renderers, env),
              os.path.relpath(chart_path, os.path.dirname(os.path.abspath(a.out))),
              (load_before, os.getloadavg()[0]))
    log("wrote %s and %s" % (a.out, chart_path))


if __name__ == "__main__":
    main(sys.argv[1:])
