#!/usr/bin/env python3
"""Material fidelity against Blender Cycles: renders Khronos sample models that use the glTF
material extensions with wavepath and with Cycles (the same file through Blender's own glTF
importer, as tools/peers.py --pbr does), both converged, and writes docs/fidelity.md: per model
the relMSE between the two images over the model's pixels, its multiple of the floor (the same
figure for DamagedHelmet, which uses no extension), the ratio of the means per channel, a picture
(wavepath | Cycles | luminance ratio), which extensions the file uses and where Blender's importer
does not map them as the specification does.

    tools/fidelity.py --zero all                       # the page, docs/fidelity.md (+ docs/fidelity/)
    tools/fidelity.py --models ClearCoatTest,SheenChair --width 64 --height 64 --spp 16 \\
        --out build/fidelity-smoke/fidelity.md         # a quick look at two models
    tools/fidelity.py --list                           # the models, their files and extensions

Run `tools/fidelity.py --help` for the options. Not part of tools/test.sh: like tools/peers.py it
creates a virtual environment with PyPI's `bpy` (build/peers-venv, Python 3.11 for bpy 5.0: see
--python) and re-runs itself in it. Cycles' images are cached in --work keyed by the rendered
file's bytes (and the files it refers to), the environment map and every setting, so a rerun after
wavepath changes renders only wavepath.
"""

import argparse
import copy
import glob
import hashlib
import inspect
import json
import os
import re
import shutil
import subprocess
import sys
import time
import types

TOOLS = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(TOOLS)
import peers  # noqa: E402  (tools/, this script's folder)
from wavepath_tools import peers_scene  # noqa: E402

MODELS = ("ClearCoatTest", "ClearCoatCarPaint", "SpecularTest", "SheenChair", "GlamVelvetSofa",
          "AnisotropyStrengthTest", "AnisotropyRotationTest", "IridescenceLamp",
          "IridescenceSuzanne", "ToyCar", "MaterialsVariantsShoe", "DamagedHelmet", "WaterBottle")
FLOOR = "DamagedHelmet"      # no extension: what the two renderers' base models alone differ by
CONTROLS = ("DamagedHelmet", "WaterBottle")
FLOOR_MULTIPLE = 3.0         # a row is "within" when its relMSE is at most this times the floor
CHUNK_SEED = 7000            # Cycles' runs use seeds 7000, 7001, ... (as tools/peers.py)
NOTES_MARK = "<!-- notes: kept when the page is regenerated -->"

# --zero: what "the extension off" means for each: values set on every material that has the
# extension, and its textures removed. The result renders as if the extension were absent (the
# specification's neutral values); a zeroed extension is also taken out of extensionsRequired.
ZERO = {
    "clearcoat": ("KHR_materials_clearcoat", {"clearcoatFactor": 0.0},
                  ["clearcoatTexture", "clearcoatRoughnessTexture", "clearcoatNormalTexture"]),
    "sheen": ("KHR_materials_sheen", {"sheenColorFactor": [0.0, 0.0, 0.0]},
              ["sheenColorTexture", "sheenRoughnessTexture"]),
    "specular": ("KHR_materials_specular",
                 {"specularFactor": 1.0, "specularColorFactor": [1.0, 1.0, 1.0]},
                 ["specularTexture", "specularColorTexture"]),
    "anisotropy": ("KHR_materials_anisotropy", {"anisotropyStrength": 0.0},
                   ["anisotropyTexture"]),
    "iridescence": ("KHR_materials_iridescence", {"iridescenceFactor": 0.0},
                    ["iridescenceTexture", "iridescenceThicknessTexture"]),
    "transmission": ("KHR_materials_transmission", {"transmissionFactor": 0.0},
                     ["transmissionTexture"]),
    "dispersion": ("KHR_materials_dispersion", {"dispersion": 0.0}, []),
    "diffuse_transmission": ("KHR_materials_diffuse_transmission",
                             {"diffuseTransmissionFactor": 0.0},
                             ["diffuseTransmissionTexture", "diffuseTransmissionColorTexture"]),
    "volume": ("KHR_materials_volume", {"thicknessFactor": 0.0}, ["thicknessTexture"]),
    "ior": ("KHR_materials_ior", {"ior": 1.5}, []),
}
# --zero all: each of these the file uses, one at a time, and all of them together.
ZERO_ALL = ("clearcoat", "sheen", "specular", "anisotropy", "iridescence", "transmission",
            "dispersion", "diffuse_transmission")

IMPORTER_SRC = "bpy/5.0/scripts/addons_core/io_scene_gltf2/"
# What Blender 5.0's glTF importer (io_scene_gltf2 5.0.21, shipped in PyPI's bpy 5.0.1) makes of
# each extension, read from its source (paths under IMPORTER_SRC): (what it maps, where it
# departs from the specification or None, the function read).
IMPORTER = {
    "KHR_materials_clearcoat": (
        "clearcoatFactor (× texture R) → Principled *Coat Weight*, clearcoatRoughnessFactor "
        "(× texture G) → *Coat Roughness*, clearcoatNormalTexture → *Coat Normal*",
        "without clearcoatRoughnessFactor and texture the coat roughness is 0.03 "
        "(`BLENDER_COAT_ROUGHNESS`, io/com/constants.py) where glTF's default is 0; the coat is "
        "Blender's layer (exact Fresnel, coat IOR 1.5, base attenuated by the coat's albedo), "
        "not glTF's Schlick-weighted mix",
        "blender/imp/pbrMetallicRoughness.py: clearcoat()"),
    "KHR_materials_sheen": (
        "*Sheen Weight* 1, sheenColorFactor (× texture) → *Sheen Tint*, sheenRoughnessFactor "
        "(× texture A) → *Sheen Roughness*",
        "the parameters map, the lobe does not: Principled's sheen is Cycles' microfiber sheen "
        "model, not glTF's Charlie distribution with its albedo scaling",
        "blender/imp/pbrMetallicRoughness.py: sheen()"),
    "KHR_materials_specular": (
        "0.5 × specularFactor (× texture A) → *Specular IOR Level*, specularColorFactor "
        "(× texture) → *Specular Tint*",
        "glTF scales the whole dielectric Fresnel term (F0 and F90) by specularFactor and F0 by "
        "specularColor (clamped to 1); Blender's IOR Level changes the effective IOR (F0 scales, "
        "F90 stays 1 unless the level is 0) and its tint colours F0: equal only at the defaults",
        "blender/imp/pbrMetallicRoughness.py: specular()"),
    "KHR_materials_anisotropy": (
        "anisotropyStrength (× texture B) → *Anisotropic*; anisotropyRotation → *Anisotropic "
        "Rotation* (÷ 2π); with anisotropyTexture the direction (texture RG, ArcTan2, plus the "
        "rotation) and a UV-map Tangent node → *Tangent*",
        "the strength goes into Blender's own anisotropy parameter unconverted (glTF: "
        "α_t = mix(α, 1, strength²), α_b = α; Blender stretches α by an aspect ratio of its "
        "own); without anisotropyTexture the *Tangent* input is left unlinked, and Cycles then "
        "uses a radial tangent about the object's Z axis (measured: the same image as a Tangent "
        "node set to Radial Z, not as one set to the UV map), not glTF's tangent (the TANGENT "
        "attribute or the UV direction)",
        "blender/imp/KHR_materials_anisotropy.py: anisotropy()"),
    "KHR_materials_iridescence": (
        "nothing: not in the importer's managed extensions (commented out in its list of "
        "material extensions); Principled's *Thin Film Thickness* / *Thin Film IOR* stay 0",
        "not mapped at all: ignored when optional; a file that *requires* it is refused "
        "(\"Extension KHR_materials_iridescence is not available on this addon version\")",
        "io/imp/gltf2_io_gltf.py: glTFImporter.__init__ (extensions_managed), "
        "glTFImporter.checks; blender/imp/blender_gltf.py"),
    "KHR_materials_transmission": (
        "transmissionFactor (× texture R) → *Transmission Weight*",
        "Principled transmission is a refracting solid interface always; glTF transmission "
        "without KHR_materials_volume (or with thicknessFactor 0) is thin-walled (no bending, "
        "no absorption), which the importer does not set up",
        "blender/imp/pbrMetallicRoughness.py: transmission()"),
    "KHR_materials_volume": (
        "only when thicknessFactor ≠ 0: a Volume Absorption node on the material's Volume "
        "output, Color = attenuationColor, Density = 1 / attenuationDistance; the thickness "
        "itself goes to a glTF Material Output group (kept for export only)",
        "glTF absorbs as attenuationColor^(d / attenuationDistance) (σ_a = −ln(c) / distance); "
        "Cycles' Volume Absorption as σ_a = (1 − c) × density: equal only as c → 1",
        "blender/imp/pbrMetallicRoughness.py: pbr_metallic_roughness(), volume()"),
    "KHR_materials_ior": (
        "ior → *IOR*", None, "blender/imp/pbrMetallicRoughness.py: pbr_metallic_roughness()"),
    "KHR_materials_emissive_strength": (
        "emissiveStrength × emissiveFactor → *Emission Strength* / *Emission Color*", None,
        "blender/imp/pbrMetallicRoughness.py: emission()"),
    "KHR_materials_dispersion": (
        "nothing: not in the managed extensions (Principled BSDF has no dispersion input)",
        "not mapped: ignored when optional, the file refused when required",
        "io/imp/gltf2_io_gltf.py: glTFImporter.__init__"),
    "KHR_materials_diffuse_transmission": (
        "nothing: not in the managed extensions",
        "not mapped: ignored when optional, the file refused when required",
        "io/imp/gltf2_io_gltf.py: glTFImporter.__init__"),
    "KHR_materials_variants": (
        "each primitive gets its default material (`primitive.material`); the variants are "
        "kept as mesh data for Blender's variant switcher", None,
        "blender/imp/mesh.py: do_primitives(); blender/imp/material.py: BlenderMaterial.create()"),
    "KHR_texture_transform": (
        "a Mapping node before the Image Texture (offset, rotation, scale, texCoord)", None,
        "blender/imp/texture.py: texture()"),
    "KHR_lights_punctual": (
        "Blender lights; by default (lighting mode *Standard*) the intensity is divided by "
        "683 lm/W (and × 4π for point and spot lights); sun lights get Blender's default "
        "angular diameter of 0.526°",
        "this tool imports with lighting mode *Unitless* (`COMPAT`: sun strength = the lux "
        "value as W/m², point/spot power = 4π × candela as W), wavepath's units, and sets every "
        "sun's angle and every point/spot radius to 0 (delta lights, as in glTF)",
        "blender/imp/light.py: BlenderLight.calc_energy_directional(), calc_energy_pointlike()"),
    "KHR_mesh_quantization": ("dequantized on import", None, "io/imp/gltf2_io_gltf.py"),
}


def log(msg):
    print("fidelity: " + msg, file=sys.stderr, flush=True)


# ---- The Cycles worker (runs in the venv: `fidelity.py --worker JOB.json`) -----------------------

def worker_main(job_path):
    """Imports job["gltf"] with Blender's glTF importer, sets it up as tools/peers.py --pbr does
    (single-scatter GGX, no subsurface, back faces of culled materials transparent, the
    environment as the world, the given camera), lights in glTF's units as delta lights, then
    renders len(job["seeds"]) images of job["chunk_spp"] samples into job["outs"] (.npy). Writes
    job["result"]: {"import_seconds", "chunk_seconds", "materials"} or {"error"} when the
    importer refuses the file."""
    with open(job_path) as f:
        job = json.load(f)
    import bpy
    t0 = time.perf_counter()
    sc = peers._cycles_settings(bpy, {"spp": job["chunk_spp"], "seed": job["seeds"][0],
                                      "max_depth": job["max_depth"], "width": job["width"],
                                      "height": job["height"]})
    sc.cycles.use_light_tree = False
    try:
        bpy.ops.import_scene.gltf(filepath=job["gltf"],
                                  export_import_convert_lighting_mode="COMPAT")
    except RuntimeError as e:
        with open(job["result"], "w") as f:
            json.dump({"error": str(e).strip().splitlines()[-1]}, f)
        return
    sc = bpy.context.scene
    peers._cycles_gltf_materials(bpy)
    for light in bpy.data.lights:  # glTF's punctual lights are delta lights
        if light.type == "SUN":
            light.angle = 0.0
        else:
            light.shadow_soft_size = 0.0
    peers._cycles_world(bpy, sc, job["world"])
    peers._cycles_camera(bpy, sc, job["camera"], lambda v: (v[0], -v[2], v[1]))
    materials = sorted({s.material.name for o in sc.objects if o.type == "MESH"
                        for s in o.material_slots if s.material})
    import_seconds = time.perf_counter() - t0
    chunk_seconds = []
    for seed, out in zip(job["seeds"], job["outs"]):
        sc.cycles.seed = seed
        t = time.perf_counter()
        peers._cycles_render(bpy, sc, {"out": out, "width": job["width"],
                                       "height": job["height"]})
        chunk_seconds.append(time.perf_counter() - t)
    with open(job["result"], "w") as f:
        json.dump({"import_seconds": import_seconds, "chunk_seconds": chunk_seconds,
                   "materials": materials}, f)


WORKER_CODE = (worker_main, peers._cycles_settings, peers._cycles_camera, peers._cycles_render,
               peers._cycles_backface_transparent, peers._cycles_gltf_materials,
               peers._cycles_world)


# ---- glTF files ----------------------------------------------------------------------------------

def model_file(models_dir, name):
    """The .gltf or .glb of model folder `name` (the shallowest; .glb before .gltf at a depth)."""
    found = [p for p in glob.glob(os.path.join(models_dir, name, "**", "*"), recursive=True)
             if p.lower().endswith((".gltf", ".glb"))]
    if not found:
        raise FileNotFoundError("%s: no .gltf or .glb in %s" % (name, os.path.join(models_dir,
                                                                                   name)))
    return min(found, key=lambda p: (p.count(os.sep), not p.lower().endswith(".glb"), p))


def document(path):
    doc, _ = peers_scene._read_document(path)
    return doc


def referenced_files(path):
    """`path` and the files it refers to (buffers and images outside it)."""
    from urllib.parse import unquote
    doc = document(path)
    base = os.path.dirname(os.path.abspath(path))
    out = [path]
    for item in doc.get("buffers", []) + doc.get("images", []):
        uri = item.get("uri")
        if uri and not uri.startswith("data:"):
            out.append(os.path.join(base, unquote(uri)))
    return out


def file_digest(paths):
    h = hashlib.sha256()
    for p in paths:
        with open(p, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
    return h.hexdigest()


def zero_edit(names):
    """A peers_scene.copy_gltf edit: the extensions `names` (keys of ZERO) off (see ZERO)."""
    def edit(doc):
        for name in names:
            ext, values, drop = ZERO[name]
            for m in doc.get("materials", []):
                e = m.get("extensions", {}).get(ext)
                if e is None:
                    continue
                for k in drop:
                    e.pop(k, None)
                e.update(copy.deepcopy(values))
            demote(ext)(doc)
    return edit


def demote(ext):
    """A copy_gltf edit: `ext` no longer in extensionsRequired (still in extensionsUsed)."""
    def edit(doc):
        req = doc.get("extensionsRequired")
        if req and ext in req:
            req.remove(ext)
            if not req:
                del doc["extensionsRequired"]
    return edit


def zero_sets(a, used):
    """The --zero cases of a file whose extensionsUsed is `used`: a list of tuples of ZERO keys."""
    out = []
    for spec in a.zero:
        if spec == "all":
            names = [n for n in ZERO_ALL if ZERO[n][0] in used]
            out += [(n,) for n in names]
            if len(names) > 1:
                out.append(tuple(names))
        else:
            names = tuple(spec.split("+"))
            if all(ZERO[n][0] in used for n in names):
                out.append(names)
    seen, unique = set(), []
    for z in out:
        if z not in seen:
            seen.add(z)
            unique.append(z)
    return unique


# ---- Rendering -----------------------------------------------------------------------------------

def run(cmd):
    """(returncode, stdout, stderr, wall seconds)."""
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return proc.returncode, proc.stdout, proc.stderr, time.perf_counter() - t0


def env_args(a):
    return ["--env", a.env, "--env-intensity", "1", "--env-rotation", "0"] if a.env else []


def render_wavepath(a, scene, work, name):
    """wavepath's converged image: --spp independent samples (so that its variance image is the
    error's) with --variance. {"img", "var", "seconds", "ignored": [extensions it warned it
    ignores]} or {"refused": its error line, "seconds"}."""
    from wavepath_tools import accuracy_lib as al
    out = os.path.join(work, "wavepath.pfm")
    cmd = ([a.wavepath, "render", scene, "--width", str(a.width), "--height", str(a.height),
            "--spp", str(a.spp), "--seed", str(al.REFERENCE_SEED), "--max-depth",
            str(a.max_depth), "--rr-depth", str(a.rr_depth), "-o", out, "--variance",
            "--progress-every", "3600", "--mipmaps", a.mipmaps] + env_args(a)
           + al.config_args("mis"))
    rc, _, err, t = run(cmd)
    if rc != 0:
        lines = [l for l in err.splitlines() if "error:" in l] or err.strip().splitlines()[-1:]
        line = lines[0] if lines else "exit status %d" % rc
        # The file's own name where wavepath names a copy of it.
        return {"refused": line.replace(os.path.abspath(scene), name).replace(scene, name),
                "seconds": t}
    ignored = sorted(set(re.findall(r"ignoring unsupported extension (\S+)", err)))
    return {"img": al.read_pfm(out), "var": al.read_pfm(out[:-4] + ".variance.pfm"),
            "seconds": t, "ignored": ignored}


def object_masks(a, scene, work):
    """(background, object) masks from wavepath's depth AOV (tools/peers.py background_mask)
    and the seconds it took (only for a file wavepath renders)."""
    ns = types.SimpleNamespace(work=work, render_scene=scene, width=a.width, height=a.height,
                               wavepath=a.wavepath, env=a.env, env_intensity=1.0,
                               env_rotation=0.0)
    t0 = time.perf_counter()
    masks = peers.background_mask(ns)
    return masks, time.perf_counter() - t0


def cycles_key(a, scene, camera):
    h = hashlib.sha256()
    h.update(file_digest(referenced_files(scene)).encode())
    if a.env:
        h.update(file_digest([a.env]).encode())
    h.update(json.dumps([a.width, a.height, a.spp, a.chunks, a.max_depth, a.rr_depth, camera,
                         a.bpy_version]).encode())
    for f in WORKER_CODE:
        h.update(inspect.getsource(f).encode())
    return h.hexdigest()[:16]


def render_cycles(a, scene, camera, work, label):
    """Cycles' converged image: the mean of --chunks runs of --spp / --chunks samples (seeds
    7000, ...), its variance image the runs' per-pixel sample variance over their number, from
    one Blender process. Cached in --work/cycles-cache. {"img", "var", "seconds" (the process's
    wall time when it was rendered), "cached", "import_seconds", "chunk_seconds"} or
    {"error": the importer's message}."""
    import numpy as np
    key = cycles_key(a, scene, camera)
    cache_dir = os.path.join(a.work, "cycles-cache")
    os.makedirs(cache_dir, exist_ok=True)
    path = os.path.join(cache_dir, "%s-%dx%d-%dspp-%s.npz" % (label, a.width, a.height, a.spp,
                                                              key))
    if os.path.exists(path):
        d = np.load(path)
        info = json.loads(str(d["info"]))
        info.update(img=d["img"], var=d["var"], cached=True)
        return info
    err_path = path[:-4] + ".error.json"
    if os.path.exists(err_path):  # the importer refused this very file before
        with open(err_path) as f:
            return dict(json.load(f), cached=True)
    job = {"gltf": os.path.abspath(scene), "camera": camera, "width": a.width,
           "height": a.height, "max_depth": a.max_depth, "chunk_spp": a.spp // a.chunks,
           "seeds": [CHUNK_SEED + k for k in range(a.chunks)],
           "outs": [os.path.join(work, "cycles-%d.npy" % k) for k in range(a.chunks)],
           "world": {"env": os.path.abspath(a.env) if a.env else None, "env_intensity": 1.0,
                     "env_rotation": 0.0, "env_color": [0.0, 0.0, 0.0]},
           "result": os.path.join(work, "cycles-result.json")}
    if os.path.exists(job["result"]):
        os.remove(job["result"])
    job_path = os.path.join(work, "cycles-job.json")
    with open(job_path, "w") as f:
        json.dump(job, f)
    log("  cycles: %d runs of %d spp, %dx%d" % (a.chunks, job["chunk_spp"], a.width, a.height))
    rc, out, err, t = run([sys.executable, os.path.abspath(__file__), "--worker", job_path])
    if rc != 0 or not os.path.exists(job["result"]):  # recorded, not cached: the next run retries
        log("  cycles worker failed (%d):\n%s" % (rc, (out + err)[-3000:]))
        tail = [l for l in (out + err).strip().splitlines() if l.strip()][-1:] or ["?"]
        return {"error": "the Blender process failed (%d): %s" % (rc, tail[0][:200]),
                "seconds": t, "cached": False}
    with open(job["result"]) as f:
        res = json.load(f)
    if "error" in res:
        with open(err_path, "w") as f:
            json.dump({"error": res["error"], "seconds": t}, f)
        return {"error": res["error"], "seconds": t, "cached": False}
    runs = np.array([np.load(p) for p in job["outs"]])
    img, var = runs.mean(0), runs.var(0, ddof=1) / len(runs)
    info = {"seconds": t, "import_seconds": res["import_seconds"],
            "chunk_seconds": res["chunk_seconds"], "materials": res["materials"]}
    np.savez(path, img=img, var=var, info=json.dumps(info))
    for p in job["outs"]:
        os.remove(p)
    info.update(img=img, var=var, cached=False)
    return info


def render_case(a, model, src, camera, edits, tag, masks_cache):
    """Renders one case (the model's file with `edits` applied) in both renderers and compares
    them; returns its row."""
    import numpy as np
    work = os.path.join(a.work, model, tag)
    os.makedirs(work, exist_ok=True)
    ext = os.path.splitext(src)[1].lower()
    scene = src
    if edits:
        scene = os.path.join(work, "scene" + ext)
        peers_scene.copy_gltf(src, scene, edits)
    row = {"model": model, "tag": tag, "file": os.path.relpath(src, REPO)}
    log("%s%s" % (model, "" if tag == "as-is" else " (%s)" % tag))
    w = render_wavepath(a, scene, work, os.path.basename(src))
    row["wavepath_seconds"] = w["seconds"]
    if "refused" in w:
        row["refused"] = w["refused"]
        log("  wavepath refused: " + w["refused"])
    else:
        row["ignored"] = w["ignored"]
        log("  wavepath: %.1f s%s" % (w["seconds"], ", ignores " + ", ".join(w["ignored"])
                                      if w["ignored"] else ""))
        if masks_cache.get(model) is None:
            masks, t = object_masks(a, scene, work)
            masks_cache[model] = masks
            row["mask_seconds"] = t
    c = render_cycles(a, scene, camera, work, "%s-%s" % (model, tag))
    demoted = []
    while "error" in c:
        m = re.search(r"Extension (\S+) is not available", c["error"])
        if not m or m.group(1) in demoted:
            row["cycles_error"] = c["error"]
            log("  cycles refused: " + c["error"])
            break
        # The importer refuses a file that requires an extension it lacks: Cycles renders a
        # copy in which that extension is optional (so ignored, as the importer ignores it in
        # a file that does not require it).
        demoted.append(m.group(1))
        log("  cycles: the importer refuses required %s; rendering with it optional"
            % m.group(1))
        scene2 = os.path.join(work, "cycles-optional" + ext)
        peers_scene.copy_gltf(src, scene2, list(edits) + [demote(x) for x in demoted])
        c = render_cycles(a, scene2, camera, work, "%s-%s-optional" % (model, tag))
    row["cycles_demoted"] = demoted
    if "error" not in c:
        row.update(cycles_seconds=c["seconds"], cycles_cached=c["cached"],
                   cycles_materials=c.get("materials"))
        log("  cycles: %.1f s%s" % (c["seconds"], " (cached)" if c["cached"] else ""))
    else:
        row.update(cycles_seconds=c.get("seconds", 0.0), cycles_cached=c.get("cached", False))
    row["images"] = (w.get("img"), c.get("img"))
    masks = masks_cache.get(model)
    if "refused" not in row and "cycles_error" not in row and masks is not None:
        cmp = peers.compare_references({"wavepath": (w["img"], w["var"]),
                                        "cycles": (c["img"], c["var"])}, masks)
        row["regions"] = cmp
        o = cmp.get("object")
        if o:
            row["rel_mse"] = o["rel_mse"]
            row["ratio"] = o["ratio"]
            row["ratio_se"] = o["se"]
            row.update(concentration(w["img"], w["var"], c["img"], c["var"], masks[1]))
            log("  object relMSE %.4g (10 largest pixels %.0f%% of it; without the largest "
                "%.1f%%: %.3g), Cycles / wavepath %s"
                % (o["rel_mse"], 100 * row["top10_share"], 100 * TRIM, row["rel_mse_trimmed"],
                   " ".join("%.3f" % x for x in o["ratio"])))
    return row


TRIM = 0.002  # the share of the model's pixels left out of the trimmed relMSE (the largest terms)


def concentration(w, wv, c, cv, obj):
    """How relMSE over the mask `obj` is made up: the share of its sum from the 10 largest
    per-pixel terms (near 1: a few pixels, typically one renderer's rare fireflies, decide it), and
    the mean without the largest TRIM of the terms (what is spread over the model; biased low by
    the cut, so about 0 where the images agree within noise)."""
    import numpy as np
    t = (((c - w) ** 2 - cv - wv) / (w * w + 0.01)).mean(2)[obj]
    order = np.argsort(t)[::-1]
    s = t[order]
    k = int(np.ceil(TRIM * s.size))
    total = float(s.sum())
    top = order[:10]
    brighter = int((c.mean(2)[obj][top] > w.mean(2)[obj][top]).sum())
    return {"top10_share": float(s[:10].sum()) / total if total > 0 else float("nan"),
            "rel_mse_trimmed": float(s[k:].sum()) / (s.size - k), "trimmed_pixels": k,
            "top10_cycles_brighter": brighter}


# ---- Pictures ------------------------------------------------------------------------------------

def picture(a, row, path):
    """wavepath | Cycles | log2 of Cycles' luminance over wavepath's (blue: Cycles darker, red:
    brighter, full colour at 1 stop), sRGB of the linear values clamped to [0, 1], a one-line
    header; a palette PNG (small)."""
    import numpy as np
    from PIL import Image, ImageDraw
    from matplotlib import colormaps
    w, c = row["images"]
    h, wd = a.height, a.width
    gap, head = 4, 14

    def srgb(x):
        x = np.clip(x, 0.0, 1.0)
        return (255 * np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)
                + 0.5).astype(np.uint8)

    blank = np.full((h, wd, 3), 96, np.uint8)
    panels = [srgb(w) if w is not None else blank, srgb(c) if c is not None else blank]
    if w is not None and c is not None:
        lum = np.array([0.2126, 0.7152, 0.0722])
        stops = np.log2((c @ lum + 1e-3) / (w @ lum + 1e-3))
        rgba = colormaps["coolwarm"]((np.clip(stops, -1.0, 1.0) + 1.0) / 2.0)
        panels.append((255 * rgba[:, :, :3] + 0.5).astype(np.uint8))
    else:
        panels.append(blank)
    canvas = np.full((h + head, 3 * wd + 2 * gap, 3), 255, np.uint8)
    for k, p in enumerate(panels):
        canvas[head:, k * (wd + gap):k * (wd + gap) + wd] = p
    im = Image.fromarray(canvas)
    draw = ImageDraw.Draw(im)
    titles = ["wavepath" if w is not None else "wavepath: refused",
              "Cycles" if c is not None else "Cycles: refused", "log2 Cycles/wavepath ±1"]
    for k, t in enumerate(titles):
        draw.text((k * (wd + gap) + 2, 1), t, fill=(0, 0, 0))
    im = im.quantize(colors=128, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
    im.save(path, optimize=True)


# ---- The page ------------------------------------------------------------------------------------

def fmt(x, spec="%.3g"):
    return "—" if x is None else spec % x


def status_of(row):
    if "refused" in row:
        return "refused: `%s`" % row["refused"]
    if "cycles_error" in row:
        return "Cycles refused: `%s`" % row["cycles_error"]
    if "rel_mse" not in row:
        return "no object pixels"
    return None


def ext_short(ext):
    return ext.replace("KHR_materials_", "").replace("KHR_", "")


def write_page(a, rows, zero_rows, info):
    page_dir = os.path.dirname(os.path.abspath(a.out))
    floor_row = next((r for r in rows if r["model"] == FLOOR and "rel_mse" in r), None)
    floor = floor_row["rel_mse"] if floor_row else None

    def multiple(r):
        if "rel_mse" not in r or not floor or floor <= 0:
            return None
        return r["rel_mse"] / floor

    def within(r):
        m = multiple(r)
        return "—" if m is None else ("yes" if m <= FLOOR_MULTIPLE else "**no**")

    def share(r):
        x = r.get("top10_share")
        return "—" if x is None or x != x else "%.0f%%" % (100 * min(x, 9.99))

    L = ["# Material fidelity: wavepath against Blender Cycles", "",
         "Written by `tools/fidelity.py` (see its `--help`); regenerate (after building "
         "`build/wavepath`; Cycles' images come from the cache in `build/fidelity-work` when "
         "nothing they depend on changed) with", "", "    " + info["command"], ""]
    L += ["Each model is rendered under `%s` (intensity 1, rotation 0) at %d × %d, max depth %d "
          "scattering events, roulette after %d, by wavepath (%d independent samples per pixel, "
          "with its variance image) and by Cycles (%d samples as the mean of %d runs of %d with "
          "seeds %d…, their spread its variance image). Both images are converged to the "
          "point where what is left of their noise is subtracted: relMSE = mean over the "
          "model's pixels of ((Cycles − wavepath)² − var_Cycles − var_wavepath) / (wavepath² + "
          "0.01), the difference beyond both images' noise (tools/peers.py's comparison of "
          "references). The model's pixels are those at least two pixels inside its "
          "silhouette in a wavepath depth AOV (64 spp); the background pixels (every sample "
          "missed the model) test the environment's conversion and are in the details table. "
          "The ratio is Cycles' mean over wavepath's, per channel, over the model's pixels."
          % (os.path.relpath(a.env, REPO) if a.env else "a black background", a.width,
             a.height, a.max_depth, a.rr_depth, a.spp, a.spp, a.chunks, a.spp // a.chunks,
             CHUNK_SEED), ""]
    L += ["**Floor**: %s. The two renderers do not share the base material model (Blender's "
          "Principled BSDF is not glTF's BRDF: exact dielectric Fresnel, albedo-scaled diffuse, "
          "texture filtering before sRGB decoding, MikkTSpace tangents; see "
          "[peers_helmet.md](peers_helmet.md)), so even a file without extensions differs by "
          "this much. A row is *within* when its relMSE is at most %g× the floor."
          % ("DamagedHelmet's relMSE in this run, **%.4g**" % floor if floor is not None
             else "not measured in this run (DamagedHelmet was not rendered)", FLOOR_MULTIPLE),
          ""]
    if floor_row and floor_row.get("top10_share", 0) > 0.5:
        nb = floor_row.get("top10_cycles_brighter", 0)
        L += ["**Caution: at these settings the floor is noise.** %.0f%% of DamagedHelmet's "
              "relMSE comes from its 10 largest pixels (%d of which are brighter in Cycles' "
              "image), and without the largest %.1f%% of its pixels it is %.2g: a few rare "
              "bright samples (fireflies) that the variance images, estimated from %d runs, do "
              "not subtract, not a "
              "difference spread over the material. Rows whose *10 px* share is high are "
              "decided the same way; their *trimmed* relMSE (details table) says whether "
              "anything is left once those pixels are out. More samples resolve it (the noise "
              "term falls as 1/spp; see the notes below)."
              % (100 * floor_row["top10_share"], nb, 100 * TRIM, floor_row["rel_mse_trimmed"],
                 a.chunks), ""]
    L += ["How each renderer gets the file: wavepath renders it as it is; Cycles imports it "
          "with Blender's glTF importer, set up as `tools/peers.py --pbr` does (every "
          "Principled BSDF single-scatter GGX, subsurface off, back faces of single-sided "
          "materials transparent, the map as the world with the same orientation, every image "
          "looked up with Blender's default Linear interpolation (wavepath: bilinear "
          "environment, its default `--env-filter`, and %s), a one-pixel box filter, max bounces = max depth − 1, no "
          "clamping, denoising or adaptive sampling, light tree off), with punctual lights in "
          "wavepath's units (below). A file without a camera is rendered by both from a copy "
          "with wavepath's framing camera written into it (`peers_scene.with_camera`); "
          "otherwise both use its first camera. Models with KHR_materials_variants render their "
          "default materials in both. A file that *requires* an extension the renderer does not "
          "have is refused; where Blender's importer refuses one, Cycles renders a copy with "
          "that extension merely optional (so ignored, as the importer ignores it elsewhere), "
          "marked in the table."
          % ("textures at full resolution, `--mipmaps off`, as Cycles looks them up on the CPU"
             if a.mipmaps == "off" else
             "mip-mapped textures, `--mipmaps on`, where Cycles' are at full resolution"), ""]
    other = info.get("other")
    L += ["Machine: %s, %d cores; both render on the CPU. Versions: Blender %s (glTF importer "
          "%s); wavepath `%s` (%s). This run: %.0f s in all, Cycles' images %d rendered and "
          "%d from the cache%s."
          % (peers._cpu_name(), os.cpu_count(), a.bpy_version, info["importer_version"],
             os.path.relpath(a.wavepath, REPO) if a.wavepath.startswith(REPO)
             else a.wavepath, info["wavepath_version"], info["total_seconds"],
             info["cycles_rendered"], info["cycles_cached"],
             "" if not other else "; other work took %.0f%% of the machine's CPU time meanwhile "
             "(its busy time in /proc/stat less this tool's processes), which slows every wall "
             "time below" % (100 * other["other"] / other["capacity"])), ""]
    L += ["## Results", "",
          "| model | extensions used (file) | wavepath ignores | relMSE | × floor | within %g× "
          "| 10 px | Cycles / wavepath R, G, B | picture |" % FLOOR_MULTIPLE,
          "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        used = info["used"][r["model"]]
        req = info["required"][r["model"]]
        exts = ", ".join(("**%s** (required)" if e in req else "%s") % ext_short(e)
                         for e in used) or "none"
        st = status_of(r)
        pic = "[png](%s)" % os.path.relpath(r["picture"], page_dir) if r.get("picture") else ""
        ign = ", ".join(ext_short(e) for e in r.get("ignored", [])) or ("—" if st else "none")
        mark = " ¹" if r.get("cycles_demoted") else ""
        if st:
            L.append("| %s%s | %s | %s | %s | — | — | — | — | %s |"
                     % (r["model"], mark, exts, ign, st, pic))
            continue
        m = multiple(r)
        L.append("| %s%s | %s | %s | %.4g | %s | %s | %s | %s | %s |"
                 % (r["model"], mark, exts, ign, r["rel_mse"], fmt(m, "%.2f"), within(r),
                    share(r), ", ".join("%.3f" % x for x in r["ratio"]), pic))
    L += ["", "*relMSE*: over the model's pixels, as above. *× floor*: over DamagedHelmet's. "
          "*10 px*: the share of the relMSE's sum that its 10 largest pixels make (above 100% "
          "where the other pixels sum below 0); high: a few pixels decide the row (fireflies, "
          "or a small feature such as a highlight or caustic: the picture tells which). "
          "*Cycles / wavepath*: the ratio of the means over the model's pixels. *wavepath "
          "ignores*: the extensions wavepath warned it skips (partial support, e.g. "
          "KHR_materials_specular's colour, gives no warning)."]
    demoted = sorted({e for r in rows + zero_rows for e in r.get("cycles_demoted", [])})
    if demoted:
        L += ["", "¹ Blender's importer refuses the file (it requires %s); Cycles rendered a copy "
              "with the extension optional, i.e. without it." % ", ".join(demoted)]
    if zero_rows:
        L += ["", "## With an extension off (`--zero`)", "",
              "The same comparison on copies of the file (in the work folder) with the named "
              "extensions' factors set to their neutral values and their textures removed "
              "(clearcoatFactor 0, sheenColorFactor 0, specularFactor 1 and specularColorFactor "
              "1, anisotropyStrength 0, iridescenceFactor 0, transmissionFactor 0, …; the "
              "extension no longer required), in both renderers. Where a row falls to the floor, "
              "the difference above comes from that extension.", "",
              "| model | off | relMSE | × floor | within %g× | 10 px | Cycles / wavepath R, G, B |"
              % FLOOR_MULTIPLE, "|---|---|---|---|---|---|---|"]
        full = {r["model"]: r for r in rows}
        for r in zero_rows:
            st = status_of(r)
            off = " + ".join(r["zero"])
            if st:
                L.append("| %s%s | %s | %s | — | — | — | — |" % (
                    r["model"], " ¹" if r.get("cycles_demoted") else "", off, st))
                continue
            base = full.get(r["model"], {}).get("rel_mse")
            L.append("| %s%s | %s | %.4g%s | %s | %s | %s | %s |"
                     % (r["model"], " ¹" if r.get("cycles_demoted") else "", off, r["rel_mse"],
                        " (with: %.3g)" % base if base is not None else "",
                        fmt(multiple(r), "%.2f"), within(r), share(r),
                        ", ".join("%.3f" % x for x in r["ratio"])))
    L += ["", "## Details and wall times", "",
          "Wall times of whole processes, measured by the tool: wavepath's render (start-up, "
          "scene and map loading, kernels from its cache or compiled, %d spp, the PFMs written), "
          "the depth-AOV mask, and Cycles' one Blender process (Python and `bpy`, the import, "
          "%d runs, reading them back); a cached Cycles image shows the time it took when it "
          "was rendered. *background*: relMSE over the background pixels (the environment's "
          "conversion; ≈ 0). *trimmed*: the model's relMSE without its largest %.1f%% of "
          "pixels (what is spread over the material; biased low by the cut, so ≈ 0 or below "
          "where the images agree within noise)." % (a.spp, a.chunks, 100 * TRIM), "",
          "| model | case | object px | trimmed relMSE | background relMSE "
          "| all-pixel relMSE | ± ratio (1 s.e.) | wavepath s | mask s | Cycles s |",
          "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows + zero_rows:
        reg = r.get("regions", {})
        o, b, al_ = reg.get("object"), reg.get("background"), reg.get("all")
        L.append("| %s | %s | %s | %s | %s | %s | %s | %.1f | %s | %s |"
                 % (r["model"], "as is" if r["tag"] == "as-is" else " + ".join(r["zero"]) + " off",
                    o["pixels"] if o else "—", fmt(r.get("rel_mse_trimmed")),
                    fmt(b and b["rel_mse"]),
                    fmt(al_ and al_["rel_mse"]), fmt(o and max(o["se"]), "%.2g"),
                    r["wavepath_seconds"], fmt(r.get("mask_seconds"), "%.1f"),
                    ("%.1f%s" % (r["cycles_seconds"], " (cached)" if r["cycles_cached"] else ""))
                    if r.get("cycles_seconds") is not None else "—"))
    L += ["", "## What Blender's importer does with each extension", "",
          "Read from the importer's Python source in the venv (`site-packages/%s`, version %s). "
          "*Maps* is what it builds on the Principled BSDF; *differs* is where that is not what "
          "the glTF specification asks for (these differences are in Cycles' image, not "
          "wavepath's errors)." % (IMPORTER_SRC, info["importer_version"]), "",
          "| extension | used by | maps | differs | source |", "|---|---|---|---|---|"]
    users = {}
    for m, used in info["used"].items():
        for e in used:
            users.setdefault(e, []).append(m)
    for e in sorted(IMPORTER, key=lambda e: (e not in users, e)):
        maps, differs, src = IMPORTER[e]
        L.append("| `%s` | %s | %s | %s | `%s` |" % (e, ", ".join(users.get(e, [])) or "—", maps,
                                                    differs or "as specified", src))
    unknown = sorted(set(users) - set(IMPORTER))
    if unknown:
        L += ["", "Not reviewed: " + ", ".join("`%s`" % e for e in unknown) + "."]
    L += ["", "## Pictures", "",
          "Left wavepath, middle Cycles (linear values clamped to [0, 1], sRGB), right "
          "log2 of Cycles' luminance over wavepath's (blue: Cycles darker, red: Cycles "
          "brighter, full colour at ±1 stop).", ""]
    for r in rows:
        if r.get("picture"):
            L += ["### %s" % r["model"], "",
                  "![%s](%s)" % (r["model"], os.path.relpath(r["picture"], page_dir)), ""]
    notes = NOTES_MARK + "\n"
    if os.path.exists(a.out):
        with open(a.out) as f:
            old = f.read()
        if NOTES_MARK in old:
            notes = old[old.index(NOTES_MARK):]
    with open(a.out, "w") as f:
        f.write("\n".join(L + ["", notes]))


# ---- Main ----------------------------------------------------------------------------------------

def default_python():
    return shutil.which("python3.11") or sys.executable


def parse_args(argv):
    p = argparse.ArgumentParser(
        prog="fidelity.py", description=__doc__.split("\n\n")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="Models (default: all): %s. The floor, %s, is rendered whatever --models says. "
               "--zero EXT: also render copies of each file that uses EXT with it off, in both "
               "renderers (EXT: %s; A+B for several at once; `all`: each of %s the file uses, "
               "then all of those together); repeatable or comma-separated."
               % (", ".join(MODELS), FLOOR, ", ".join(ZERO), ", ".join(ZERO_ALL)))
    p.add_argument("--models", default=",".join(MODELS),
                   help="comma-separated model folder names (default: the 13 of issue 20)")
    p.add_argument("--models-dir", default=os.path.join(REPO, "..", "shared", "assets",
                                                        "models"))
    p.add_argument("--env", default=os.path.join(REPO, "..", "shared", "assets", "env",
                                                 "studio_small_03_1k.hdr"),
                   help="equirectangular environment map (default %(default)s)")
    p.add_argument("--width", type=int, default=160)
    p.add_argument("--height", type=int, default=160)
    p.add_argument("--spp", type=int, default=256,
                   help="samples per pixel of each renderer's converged image (default 256)")
    p.add_argument("--chunks", type=int, default=8,
                   help="Cycles' image is the mean of this many runs of --spp / N samples; "
                        "their spread is its variance image (default %(default)s)")
    p.add_argument("--max-depth", type=int, default=12)
    p.add_argument("--rr-depth", type=int, default=5)
    p.add_argument("--zero", action="append", default=[], metavar="EXT",
                   help="diagnostic: also render copies with EXT off (see below)")
    p.add_argument("--wavepath", default=os.path.join(REPO, "build", "wavepath"))
    p.add_argument("--mipmaps", choices=("on", "off"), default="off",
                   help="wavepath's --mipmaps (default off: Cycles on the CPU looks its image "
                        "textures up at full resolution, so that both converge to the same "
                        "image; with on, the difference includes the bias of wavepath's "
                        "texture filtering, measured on its own in docs/performance.md)")
    p.add_argument("--venv", default=os.path.join(REPO, "build", "peers-venv"))
    p.add_argument("--python", default=default_python(),
                   help="interpreter the venv is created with (default: python3.11 if found)")
    p.add_argument("--work", default=os.path.join(REPO, "build", "fidelity-work"),
                   help="scratch folder: copies of the files, images, Cycles' cache")
    p.add_argument("--out", default=os.path.join(REPO, "docs", "fidelity.md"),
                   help="the page; pictures go to a folder of its name without .md")
    p.add_argument("--list", action="store_true",
                   help="print each model's file and extensions and exit (renders nothing)")
    a = p.parse_args(argv)
    a.models = [m for m in a.models.split(",") if m]
    if FLOOR not in a.models:
        a.models.append(FLOOR)
    a.zero = [z for spec in a.zero for z in spec.split(",") if z]
    for z in a.zero:
        if z != "all" and any(n not in ZERO for n in z.split("+")):
            p.error("--zero %s: unknown extension (one of %s, or all)" % (z, ", ".join(ZERO)))
    if a.chunks < 2 or a.spp % a.chunks:
        p.error("--chunks must be at least 2 and divide --spp")
    if a.env and not os.path.isfile(a.env):
        p.error("--env %s: no such file" % a.env)
    if not a.list and not os.access(a.wavepath, os.X_OK):
        p.error("%s is not an executable (build it: cmake --build build --target wavepath)"
                % a.wavepath)
    a.env = os.path.abspath(a.env) if a.env else None
    a.models_dir = os.path.abspath(a.models_dir)
    a.wavepath = os.path.abspath(a.wavepath)
    a.work = os.path.abspath(a.work)
    a.out = os.path.abspath(a.out)
    a.argv = argv
    return a


def regen_command(a):
    """The command line of this run less the options that name this machine's paths when they
    are the defaults anyway."""
    out, skip = [], False
    for k, x in enumerate(a.argv):
        if skip:
            skip = False
            continue
        if x in ("--wavepath", "--venv", "--python", "--work"):
            skip = True
            continue
        if x.split("=")[0] in ("--wavepath", "--venv", "--python", "--work"):
            continue
        out.append(x)
    return " ".join(["tools/fidelity.py"] + out)


def main(argv):
    if len(argv) == 2 and argv[0] == "--worker":
        worker_main(argv[1])
        return
    a = parse_args(argv)
    files = {m: model_file(a.models_dir, m) for m in a.models}
    docs = {m: document(f) for m, f in files.items()}
    if a.list:
        for m in a.models:
            d = docs[m]
            print("%-24s %s\n    used: %s\n    required: %s\n    zero cases: %s"
                  % (m, os.path.relpath(files[m], REPO), ", ".join(d.get("extensionsUsed", []))
                     or "none", ", ".join(d.get("extensionsRequired", [])) or "none",
                     "; ".join("+".join(z) for z in zero_sets(
                         types.SimpleNamespace(zero=a.zero or ["all"]),
                         d.get("extensionsUsed", []))) or "none"))
        return
    peers.ensure_venv(types.SimpleNamespace(venv=a.venv, python=a.python, renderers=["cycles"]),
                      script=__file__)
    t_start, cpu_start = time.perf_counter(), peers.cpu_snapshot()
    a.bpy_version = subprocess.run(
        [sys.executable, "-c", "import bpy; print(bpy.app.version_string)"],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True).stdout.strip()
    importer_version = subprocess.run(
        [sys.executable, "-c", "import bpy, addon_utils; m = [m for m in addon_utils.modules() "
         "if m.__name__.endswith('io_scene_gltf2')][0]; print('.'.join(map(str, "
         "m.bl_info['version'])))"],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True).stdout.strip()
    wp_version = subprocess.run([a.wavepath, "--version"], stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True).stdout.strip()
    rev = subprocess.run(["git", "-C", REPO, "rev-parse", "--short", "HEAD"],
                         stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True).stdout.strip()
    pic_dir = os.path.splitext(a.out)[0]
    os.makedirs(pic_dir, exist_ok=True)
    os.makedirs(a.work, exist_ok=True)
    rows, zero_rows, masks_cache = [], [], {}
    for m in a.models:
        src = files[m]
        used = docs[m].get("extensionsUsed", [])
        cam = peers_scene.camera(src)
        edits = []
        if cam is None:
            lo, hi = peers_scene.bounds(src)
            cam = peers_scene.framing_camera(lo, hi, a.width / a.height)
            edits.append(peers_scene.add_camera(cam))
        row = render_case(a, m, src, cam, edits, "as-is", masks_cache)
        row["picture"] = os.path.join(pic_dir, m + ".png")
        picture(a, row, row["picture"])
        rows.append(row)
        for z in zero_sets(a, used):
            zr = render_case(a, m, src, cam, edits + [zero_edit(z)], "zero-" + "+".join(z),
                             masks_cache)
            zr["zero"] = list(z)
            zero_rows.append(zr)
    total = time.perf_counter() - t_start
    other = peers.other_work(cpu_start, peers.cpu_snapshot(), total)
    every = rows + zero_rows
    cached = sum(1 for r in every if r.get("cycles_cached"))
    info = {"command": regen_command(a), "date": time.strftime("%Y-%m-%d %H:%M UTC",
                                                               time.gmtime()),
            "total_seconds": total, "cycles_cached": cached, "other": other,
            "cycles_rendered": len(every) - cached, "importer_version": importer_version,
            "wavepath_version": "%s; repository at git %s" % (
                wp_version.splitlines()[0] if wp_version else "?", rev),
            "used": {m: docs[m].get("extensionsUsed", []) for m in a.models},
            "required": {m: docs[m].get("extensionsRequired", []) for m in a.models}}
    write_page(a, rows, zero_rows, info)
    with open(os.path.join(a.work, "results.json"), "w") as f:
        json.dump({"info": info, "rows": [{k: v for k, v in r.items() if k != "images"}
                                          for r in every]}, f, indent=1, default=str)
    log("wrote %s (%d models, %d --zero cases) in %.0f s; Cycles: %d rendered, %d from the cache"
        % (os.path.relpath(a.out), len(rows), len(zero_rows), total, len(every) - cached,
           cached))


if __name__ == "__main__":
    main(sys.argv[1:])
