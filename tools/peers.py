#!/usr/bin/env python3
"""Peer benchmark: wavepath against Mitsuba 3 (LLVM variant, CPU) and Blender Cycles (CPU) on one of
the project's own glTF scenes, converted exactly; error against whole-process time, written as a
Markdown page with a chart and a table of time-to-target ratios.

    tools/peers.py --scene scenes/cornell_box.gltf --width 512 --height 512 --out docs/peers_512.md
    tools/peers.py --pbr --renderers wavepath,cycles --scene MODEL.glb --env MAP.hdr \
        --out docs/peers_helmet.md

Run `tools/peers.py --help` for the options. Not part of tools/test.sh: the peers come from PyPI
(`mitsuba`, `bpy`, with numpy and matplotlib) into a virtual environment the script creates
(--venv, default build/peers-venv) and then re-runs itself in. Mitsuba's LLVM variant needs a
libLLVM shared library (DRJIT_LIBLLVM_PATH when set, else the newest
/usr/lib/x86_64-linux-gnu/libLLVM-*.so*; Debian: libllvm19, with which it was run: with LLVM 15,
Dr.Jit 1.5's kernels stop with "LLVM ERROR: Cannot select ... fminimum"); bpy 5.0 needs Python
3.11 (--python). The converters are tools/wavepath_tools/peers_scene.py (tests/test_peers_scene.py)
and, for Mitsuba with --pbr, tools/wavepath_tools/peers_pbr.py (tests/test_peers_pbr.py).
"""

import argparse
import glob
import hashlib
import json
import math
import os
import platform
import re
import statistics
import subprocess
import sys
import time

TOOLS = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(TOOLS)
from wavepath_tools import peers_pbr, peers_scene  # noqa: E402

PACKAGES = {"mitsuba": ["mitsuba"], "mitsuba-ld": ["mitsuba"], "cycles": ["bpy"]}
BASE_PACKAGES = ["numpy", "matplotlib"]
RENDERERS = ("wavepath", "mitsuba", "mitsuba-ld", "cycles")
LABELS = {"wavepath": "wavepath", "mitsuba": "Mitsuba 3 (llvm_ad_rgb)",
          "mitsuba-ld": "Mitsuba 3 ldsampler (llvm_ad_rgb)", "cycles": "Cycles (CPU)"}
# Mitsuba's sampler per renderer key: its default (independent), and its low-discrepancy one
# (scrambled (0,2)-sequences), the counterpart of wavepath's default Sobol' points.
MITSUBA_SAMPLERS = {"mitsuba": "independent", "mitsuba-ld": "ldsampler"}
VENV_MARK = "WP_PEERS_IN_VENV"

DESCRIPTION = """\
Converts the scene (tools/wavepath_tools/peers_scene.py: world-space triangle meshes, Lambertian materials,
emitters, point lights, the first perspective camera; anything else is refused, and so is an
emitter coplanar with and overlapping another surface, which each renderer resolves its own way:
docs/peers.md, Coincident emitters) for each peer.
A glTF material with metallic 0 is not Lambertian: glTF, and wavepath, put a rough specular layer
(Fresnel 0.04 at normal incidence, 1 at grazing) over the diffuse one, which neither peer's diffuse
BSDF has. So when a material lacks KHR_materials_specular specularFactor 0, the benchmark renders
a copy of the scene with that factor 0 on every material (written to --work/lambertian.gltf), in
wavepath too: all three render the same purely Lambertian scene.

  Mitsuba 3  PLY meshes, `diffuse` BSDF with the base colour, an `area` emitter (one-sided, front =
             counter-clockwise side, as in wavepath) with the emission as radiance, `point`
             emitters with the intensity in W/sr, a `perspective` sensor (fov_axis y = the
             glTF yfov), box reconstruction filter (one pixel, wavepath's), the `independent`
             sampler (renderer `mitsuba`, Mitsuba's default) or `ldsampler` (renderer
             `mitsuba-ld`: scrambled (0,2)-sequences, like wavepath's default Sobol' points;
             sample counts must be powers of 2), `path` integrator with max_depth = --max-depth + 1 and rr_depth =
             --rr-depth (Mitsuba counts path segments from the camera, so max_depth 1 sees
             emitters only and 2 adds direct light; wavepath counts scattering events, so
             wavepath's depth d is Mitsuba's d + 1; but Mitsuba's roulette, like wavepath's,
             decides on the ray leaving the rr_depth-th scattering event: its path.cpp counts
             the event before the test `depth >= rr_depth`, and its docs say rr_depth 1 may end
             a path after the directly visible surface).
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

PBR MODE (--pbr): the scene is given to wavepath and Cycles as the glTF file it is, and
converted for Mitsuba (tools/wavepath_tools/peers_pbr.py), textures and metallic-roughness
materials included, optionally
under an environment map (--env, --env-intensity, --env-rotation, wavepath's options). A file
without a camera is rendered by both from a copy with wavepath's framing camera written into it
(tools/wavepath_tools/peers_scene.py: bounds, framing_camera, with_camera; --work/with_camera.glb).
  Cycles     bpy.ops.import_scene.gltf (Blender's glTF importer, shipped with bpy): Principled
             BSDFs, set to single-scatter GGX (`distribution` GGX; Blender's default is
             multiscatter) with subsurface weight 0; a material the importer marks as
             backface-culled (glTF doubleSided false) gets the Mix Shader with a Transparent BSDF
             on back faces described above. World: an Environment Texture of the map (colour
             space Linear Rec.709, interpolation Linear, Blender's default: bilinear, as
             wavepath's default --env-filter) times --env-intensity, its direction turned by a Mapping node (type Point,
             rotation about Z of -(90 + --env-rotation) degrees): the importer turns glTF's +Y
             up into Blender's +Z up, and Blender's equirectangular map has its centre at +X
             where wavepath's has it at glTF's -Z (Blender's +Y). Black world without --env. The
             camera as above, its vectors turned with the importer's axes. Light tree off
             unless --cycles-light-tree (on DamagedHelmet it was slower and noisier; the
             commands that measured it are in docs/peers_helmet.md). Settings otherwise as above.
  Mitsuba 3  peers_pbr.py (its docstring has the whole table and every gap): world-space PLY
             meshes (normals, UVs; no tangents: normal maps use dp/du), `principled` BSDF:
             base colour x texture (sRGB) -> base_color, metallic/roughness x texture B/G
             (linear) -> metallic/roughness, KHR_materials_ior -> eta, specularFactor -> eta of
             the scaled F0, transmission -> spec_trans (`principledthin` without
             KHR_materials_volume), clearcoat -> clearcoat and clearcoat_gloss (GTR1 alpha =
             roughness^2), sheen -> sheen (white), anisotropy strength -> anisotropic and
             roughness (same alpha_t, alpha_b); normalTexture -> `normalmap` (scale baked),
             alphaMode MASK -> `mask` with opacity (alpha >= cutoff) per texel, BLEND -> `mask`
             with alpha; doubleSided -> `twosided`; emission x texture -> textured `area`
             emitter; samplers' magFilter and wrapS; KHR_lights_punctual -> `point`, `spot`,
             `directional`; the environment -> `envmap` with scale --env-intensity and
             to_world a rotation about +Y by 180 + --env-rotation degrees (Mitsuba's map
             centre is +Z, wavepath's -Z; checked against wavepath renders of the bare map in
             six directions). Gaps: Disney's material model (not glTF's), specular colour,
             sheen colour and roughness, anisotropy rotation, iridescence, dispersion, volume
             attenuation, mipmaps, wrapT, file tangents, back faces of one-sided materials
             (black, not culled), spot falloff (linear in angle), light range: each that
             applies is logged and listed on the page. KHR_texture_transform -> the bitmap's
             to_uv. Refused: texCoord 1, Draco, meshopt, quantized or sparse attributes,
             instancing, KTX2/WebP, unlit, specular-glossiness. The camera and settings as
             without --pbr; the `mitsuba` (independent) and `mitsuba-ld` (ldsampler) renderers
             share one reference, rendered as Cycles' below with the independent sampler.
  Errors     The two do not render the same material model (Blender's Principled BSDF is not
             glTF's BRDF: exact dielectric Fresnel and albedo-scaled diffuse, F82 metals,
             MikkTSpace tangents), so each renderer's relMSE is measured against its own
             reference: wavepath's as above, Cycles' the mean of --ref-chunks runs of --ref-spp /
             --ref-chunks samples with seeds 7000, 7001, ..., with the runs' per-pixel sample
             variance over their number as its variance image (cached in --work). The page also
             compares the two references: the ratio of their image means per channel and their
             relMSE beyond both variance images, over all pixels, over the background pixels
             (environment only: tests its conversion) and over the pixels inside the model's
             silhouette (the materials), masks from a wavepath depth-AOV render. A picture of
             the two references and their luminance ratio goes next to the page
             (<page>_references.png).
  Diagnostics --nearest-textures and --no-normal-maps render copies of the file (nearest-texel
             samplers; no normal textures) in both, to find where the references' difference
             comes from.

Each renderer renders the sweep of --spp counts; each run is a separate process and its wall time,
from start to the image on disk (start-up, kernel or JIT compilation, scene load included), is
measured by this script. One unmeasured 1-spp run of each renderer first fills the caches that
persist between processes (wavepath's kernel binary and BVH caches, Dr.Jit's kernel cache), so that
no measured run pays a one-off compilation. relMSE is tools/wavepath_tools/accuracy_lib.py's: mean(((x - r)^2 -
var_r) / (r^2 + 0.01)) against one common reference (without --pbr), a wavepath render of --ref-spp
samples with its variance image (so the reference's own noise is subtracted). The conversion is
checked by the image means: each peer's largest run against the reference, per channel (their
ratio must be 1 within noise; a wrong conversion also shows as relMSE that stops falling). Time
to reach a relMSE target: interpolated linearly on log-log between the two runs around it; beyond
the last run, extrapolated as relMSE ~ 1 / time from it (marked ~).

The page (--out) is rewritten on every run except for what follows its line
"<!-- notes: kept when the page is regenerated -->": hand-written notes on the figures.
"""


# ---- Virtual environment -------------------------------------------------------------------------

def log(msg):
    print("peers: " + msg, file=sys.stderr, flush=True)


def venv_python(venv):
    return os.path.join(venv, "bin", "python")


def ensure_venv(a, script=None):
    """Creates --venv with the packages the renderers need (pip install is a no-op when present)
    and re-executes this script (or `script`, another tool built on this one) inside it, unless
    already there."""
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
    os.execv(py, [py, os.path.abspath(script or __file__)] + sys.argv[1:])


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
    if scene.get("gltf"):
        worker_mitsuba_pbr(mi, job, scene)
        return
    cam = scene["camera"]
    target = [cam["position"][i] + cam["forward"][i] for i in range(3)]
    d = {"type": "scene",
         "integrator": {"type": "path", "max_depth": job["max_depth"] + 1,
                        "rr_depth": job["rr_depth"]},
         "sensor": {"type": "perspective", "fov_axis": "y", "fov": math.degrees(cam["yfov"]),
                    "near_clip": 1e-3, "far_clip": 1e4,
                    "to_world": mi.ScalarTransform4f().look_at(origin=cam["position"],
                                                               target=target, up=cam["up"]),
                    "sampler": {"type": job.get("sampler", "independent"),
                                "sample_count": job["spp"]},
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


def worker_mitsuba_pbr(mi, job, scene):
    """--pbr: the scene peers_pbr.convert() made of the glTF (scene["mitsuba"]), seen by
    scene["camera"], under scene["env"] (see the --help text)."""
    import numpy as np
    from wavepath_tools import peers_pbr
    env = ({"path": scene["env"], "intensity": scene["env_intensity"],
            "rotation": scene["env_rotation"]} if scene.get("env") else None)
    d = peers_pbr.mitsuba_scene(scene["mitsuba"], scene["camera"], job, env)
    img = mi.render(mi.load_dict(peers_pbr.realize(d, mi)), spp=job["spp"], seed=job["seed"])
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
        m.cycles.emission_sampling = "FRONT_BACK" if mat["double_sided"] else "FRONT"
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


def _cycles_settings(bpy, job):
    """An empty Blender scene with the Cycles settings of the --help text; returns it."""
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
    return sc


def _cycles_camera(bpy, sc, cam, axes):
    """The camera `cam` (scene["camera"]) as the scene's camera; `axes` maps a glTF vector to
    Blender's (identity for meshes built here, glTF's +Y up to Blender's +Z up for imports)."""
    data = bpy.data.cameras.new("camera")
    data.type = "PERSP"
    data.sensor_fit = "VERTICAL"
    data.angle_y = cam["yfov"]
    data.clip_start = 1e-3
    data.clip_end = 1e4
    ob = bpy.data.objects.new("camera", data)
    f, u, p = axes(cam["forward"]), axes(cam["up"]), axes(cam["position"])
    right = (f[1] * u[2] - f[2] * u[1], f[2] * u[0] - f[0] * u[2], f[0] * u[1] - f[1] * u[0])
    from mathutils import Matrix
    ob.matrix_world = Matrix([[right[i], u[i], -f[i], p[i]] for i in range(3)]
                             + [[0.0, 0.0, 0.0, 1.0]])
    sc.collection.objects.link(ob)
    sc.camera = ob


def _cycles_render(bpy, sc, job):
    """Renders, and saves the image (top row first) as job["out"] (.npy)."""
    import numpy as np
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


def worker_cycles(job, scene):
    import bpy
    if scene.get("gltf"):
        worker_cycles_gltf(bpy, job, scene)
        return
    if scene["point_lights"]:
        raise SystemExit("peers.py: error: Cycles: point lights are not converted (Blender's "
                         "point light power convention is not verified here)")
    sc = _cycles_settings(bpy, job)
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
    _cycles_camera(bpy, sc, scene["camera"], lambda v: v)
    _cycles_render(bpy, sc, job)


def _cycles_backface_transparent(m):
    """Makes back faces of material m a Transparent BSDF (wavepath culls the back faces of a
    material that is not double-sided: rays pass through them)."""
    nodes, links = m.node_tree.nodes, m.node_tree.links
    outs = [n for n in nodes if n.bl_idname == "ShaderNodeOutputMaterial"]
    for out in outs:
        if not out.inputs["Surface"].is_linked:
            continue
        shader = out.inputs["Surface"].links[0].from_socket
        geometry = nodes.new("ShaderNodeNewGeometry")
        transparent = nodes.new("ShaderNodeBsdfTransparent")
        mix = nodes.new("ShaderNodeMixShader")
        links.new(geometry.outputs["Backfacing"], mix.inputs[0])
        links.new(shader, mix.inputs[1])
        links.new(transparent.outputs[0], mix.inputs[2])
        links.new(mix.outputs[0], out.inputs["Surface"])


def worker_cycles_gltf(bpy, job, scene):
    """--pbr: the glTF through Blender's own importer (io_scene_gltf2), Principled BSDFs set to
    single-scatter GGX, the environment map as the world (see the --help text)."""
    sc = _cycles_settings(bpy, job)
    sc.cycles.use_light_tree = bool(scene.get("light_tree"))  # --cycles-light-tree
    bpy.ops.import_scene.gltf(filepath=scene["gltf"])
    sc = bpy.context.scene
    _cycles_gltf_materials(bpy)
    _cycles_world(bpy, sc, scene)
    _cycles_camera(bpy, sc, scene["camera"], lambda v: (v[0], -v[2], v[1]))
    _cycles_render(bpy, sc, job)


def _cycles_gltf_materials(bpy):
    """The imported materials as --pbr renders them: every Principled BSDF single-scatter GGX with
    subsurface weight 0; back faces of backface-culled materials transparent."""
    for m in bpy.data.materials:
        if not m.use_nodes:
            continue
        for n in m.node_tree.nodes:
            if n.bl_idname == "ShaderNodeBsdfPrincipled":
                n.distribution = "GGX"  # Blender's default is multiscatter GGX
                n.inputs["Subsurface Weight"].default_value = 0.0
        if m.use_backface_culling:  # the importer's mark of a glTF material not double-sided
            _cycles_backface_transparent(m)


def _cycles_world(bpy, sc, scene):
    """The world of --pbr: scene["env"] (an equirectangular map, scene["env_intensity"],
    scene["env_rotation"]) as wavepath's --env, or the constant scene["env_color"]."""
    import math
    world = bpy.data.worlds.new("env")
    world.use_nodes = True
    nt = world.node_tree
    bg = nt.nodes["Background"]
    if scene.get("env"):
        env = nt.nodes.new("ShaderNodeTexEnvironment")
        env.image = bpy.data.images.load(scene["env"])
        env.image.colorspace_settings.name = "Linear Rec.709"
        env.interpolation = "Linear"  # bilinear, as wavepath's default --env-filter
        env.projection = "EQUIRECTANGULAR"
        coord = nt.nodes.new("ShaderNodeTexCoord")
        mapping = nt.nodes.new("ShaderNodeMapping")
        mapping.vector_type = "POINT"
        # wavepath's map centre is glTF's -Z, Blender's +X: 90 degrees about the up axis, plus
        # --env-rotation (wavepath turns the map by R about +Y; the lookup turns by -R).
        mapping.inputs["Rotation"].default_value = (
            0.0, 0.0, -math.radians(scene["env_rotation"] + 90.0))
        nt.links.new(coord.outputs["Generated"], mapping.inputs["Vector"])
        nt.links.new(mapping.outputs["Vector"], env.inputs["Vector"])
        nt.links.new(env.outputs["Color"], bg.inputs["Color"])
        bg.inputs["Strength"].default_value = scene["env_intensity"]
    else:
        bg.inputs["Color"].default_value = tuple(scene.get("env_color", (0.0, 0.0, 0.0))) + (1.0,)
        bg.inputs["Strength"].default_value = 1.0
    sc.world = world


def worker_main(renderer, job_path):
    with open(job_path) as f:
        job = json.load(f)
    with open(job["scene"]) as f:
        scene = json.load(f)
    {"mitsuba": worker_mitsuba, "mitsuba-ld": worker_mitsuba,
     "cycles": worker_cycles}[renderer](job, scene)


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
                   help="samples per pixel of the wavepath reference (and, with --pbr, of Cycles' "
                        "own) (default %(default)s)")
    p.add_argument("--max-depth", type=int, default=12,
                   help="scattering events, wavepath's --max-depth (default %(default)s)")
    p.add_argument("--rr-depth", type=int, default=5,
                   help="Russian roulette after this many scattering events (wavepath's default)")
    p.add_argument("--targets", default="1e-2,3e-3,1e-3",
                   help="relMSE targets of the time table (default %(default)s)")
    p.add_argument("--renderers", default=",".join(RENDERERS),
                   help="comma-separated subset of %s" % ", ".join(RENDERERS))
    p.add_argument("--wavepath", default=os.path.join(REPO, "build", "wavepath"))
    p.add_argument("--wavepath-sampler", choices=["sobol", "sobol-padded", "independent"],
                   help="wavepath's --sampler in the sweep (default: its own, sobol); e.g. "
                        "independent for the cost of a sample like Mitsuba's default sampler's. "
                        "The reference is rendered as without it")
    p.add_argument("--venv", default=os.path.join(REPO, "build", "peers-venv"))
    p.add_argument("--python", default=sys.executable,
                   help="interpreter the venv is created with (default: this one)")
    p.add_argument("--work", default=os.path.join(REPO, "build", "peers-work"),
                   help="scratch folder: converted scene, images, the cached reference")
    p.add_argument("--mitsuba-variant", default="llvm_ad_rgb")
    p.add_argument("--out", default=None,
                   help="the Markdown page; the chart is written next to it (default: peers.md "
                        "in the --work folder)")
    p.add_argument("--quick", action="store_true",
                   help="a smoke run: 64 x 64, spp 4,16, reference 256 spp")
    p.add_argument("--repeat", type=int, default=1,
                   help="run the sweep this many times (the renderers taking turns at each "
                        "sample count, the same seeds) and take each run's least wall time: less "
                        "of other work on a shared machine; the page then also gives CPU times "
                        "(default %(default)s)")
    p.add_argument("--statistic", choices=["least", "median"], default="least",
                   help="with --repeat: a run's time is the least of its repetitions' (the run "
                        "least disturbed by other work) or their median (default %(default)s)")
    p.add_argument("--pbr", action="store_true",
                   help="render the glTF's own materials (textures, metallic-roughness): Cycles "
                        "loads the file with Blender's glTF importer, Mitsuba a conversion "
                        "(tools/wavepath_tools/peers_pbr.py); each measured against its own "
                        "reference (see PBR MODE below)")
    p.add_argument("--env", metavar="PATH",
                   help="equirectangular environment map (.hdr, .exr) lighting the scene, "
                        "wavepath's --env (with --pbr only)")
    p.add_argument("--env-intensity", type=float, default=1.0,
                   help="scale of the environment map, wavepath's --env-intensity (default 1)")
    p.add_argument("--env-rotation", type=float, default=0.0,
                   help="rotation of the map about +Y in degrees, wavepath's --env-rotation "
                        "(default 0)")
    p.add_argument("--orbit", metavar="THETA,PHI,DISTANCE",
                   help="--pbr: every renderer sees the scene from wavepath's --orbit camera "
                        "(tools/wavepath_tools/peers_scene.py, orbit_camera), written into a copy "
                        "of the file in place of its own cameras (--work/orbit.glb or .gltf)")
    p.add_argument("--cycles-light-tree", action="store_true",
                   help="--pbr: Cycles samples lights with its light tree (Blender's default; "
                        "off without this option)")
    p.add_argument("--nearest-textures", action="store_true",
                   help="--pbr, a diagnostic: both render a copy of the file whose samplers are "
                        "all NEAREST (wavepath looks up the nearest texel; Blender's importer makes "
                        "the Image Texture nodes interpolation Closest), which takes the order of "
                        "filtering and sRGB decoding out of the comparison")
    p.add_argument("--no-normal-maps", action="store_true",
                   help="--pbr, a diagnostic: both render a copy of the file without its normal "
                        "textures, which takes the tangent frames (each renderer makes its own) "
                        "out of the comparison")
    p.add_argument("--ref-chunks", type=int, default=8,
                   help="--pbr: the Cycles reference is the mean of this many runs of "
                        "--ref-spp / N samples with different seeds; their spread gives its "
                        "variance image (default %(default)s)")
    a = p.parse_args(argv)
    if a.out is None:
        a.out = os.path.join(a.work, "peers.md")
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
    for r in MITSUBA_SAMPLERS:
        LABELS[r] = LABELS[r].replace("llvm_ad_rgb", a.mitsuba_variant)
    if a.wavepath_sampler:
        LABELS["wavepath"] = "wavepath (%s sampler)" % a.wavepath_sampler
    if a.env and not a.pbr:
        p.error("--env needs --pbr (the environment's conversion is verified for that mode only)")
    if a.env and not os.path.isfile(a.env):
        p.error("--env %s: no such file" % a.env)
    if a.orbit:
        try:
            a.orbit = [float(x) for x in a.orbit.split(",")]
        except ValueError:
            a.orbit = None
        if not a.orbit or len(a.orbit) != 3 or a.orbit[2] < 0.0:
            p.error("--orbit takes THETA,PHI,DISTANCE in degrees, degrees and scene units "
                    "(distance >= 0; 0 fits the scene)")
        if not a.pbr:
            p.error("--orbit needs --pbr")
    if a.repeat < 1:
        p.error("--repeat must be at least 1")
    if (a.nearest_textures or a.no_normal_maps or a.cycles_light_tree) and not a.pbr:
        p.error("--nearest-textures, --no-normal-maps and --cycles-light-tree need --pbr")
    if a.pbr and (a.ref_chunks < 2 or a.ref_spp % a.ref_chunks):
        p.error("--ref-chunks must be at least 2 and divide --ref-spp")
    if not os.access(a.wavepath, os.X_OK):
        p.error("%s is not an executable (build it: cmake --build build --target wavepath)"
                % a.wavepath)
    a.argv = argv
    return a


def timed(cmd, env=None):
    """Runs cmd; (its wall time in seconds, its output, its CPU time: user + system seconds of
    the process and the children it waited for). Exits with its output when it fails."""
    import resource
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          env=env)
    t = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        sys.exit("peers.py: error: %s failed (%d):\n%s" % (" ".join(cmd), proc.returncode,
                                                          proc.stdout[-4000:]))
    return t, proc.stdout, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)


def pbr_peers(a):
    """--pbr: the peers with references of their own: "cycles", and "mitsuba" for either
    Mitsuba renderer (both samplers converge to one image)."""
    if not a.pbr:
        return []
    return (["mitsuba"] if any(r in a.renderers for r in MITSUBA_SAMPLERS) else []) + (
        ["cycles"] if "cycles" in a.renderers else [])


def cpu_snapshot():
    """(busy, steal, own) CPU seconds so far: the machine's busy time over all cores (user, nice,
    system, irq, softirq in /proc/stat), the time the hypervisor took (steal), and this script's
    own (this process and the children it waited for); None where /proc/stat is missing."""
    import resource
    try:
        with open("/proc/stat") as f:
            v = [int(x) for x in f.readline().split()[1:9]]
    except (OSError, ValueError):
        return None
    tick = os.sysconf("SC_CLK_TCK")
    own = sum(getattr(resource.getrusage(w), k) for w in (resource.RUSAGE_SELF,
                                                          resource.RUSAGE_CHILDREN)
              for k in ("ru_utime", "ru_stime"))
    return (v[0] + v[1] + v[2] + v[5] + v[6]) / tick, v[7] / tick, own


def other_work(before, after, wall):
    """{"other", "steal", "capacity"} CPU seconds between two cpu_snapshot()s `wall` seconds
    apart: busy time not this script's, hypervisor steal, and cores x wall."""
    if before is None or after is None:
        return None
    return {"other": max(0.0, (after[0] - before[0]) - (after[2] - before[2])),
            "steal": after[1] - before[1], "capacity": wall * (os.cpu_count() or 1)}


def convert_pbr(a):
    """--pbr: the scene as Cycles' worker reads it (the glTF itself, the camera, the environment).
    A file without a camera is rendered by both from a copy (--work/with_camera.glb or .gltf)
    holding wavepath's framing camera, so that both see it through the same one."""
    os.makedirs(a.work, exist_ok=True)
    a.render_scene = a.scene
    cam = peers_scene.camera(a.scene)
    edits, name = [], []
    if a.orbit:
        cam = peers_scene.orbit_camera(*peers_scene.bounds(a.scene), *a.orbit, a.width / a.height)
        edits.append(peers_scene.add_camera(cam, replace=True))
        name.append("orbit")
    elif cam is None:
        lo, hi = peers_scene.bounds(a.scene)
        cam = peers_scene.framing_camera(lo, hi, a.width / a.height)
        edits.append(peers_scene.add_camera(cam))
        name.append("with_camera")
    if a.nearest_textures:
        edits.append(peers_scene.nearest_textures)
        name.append("nearest")
    if a.no_normal_maps:
        edits.append(peers_scene.no_normal_maps)
        name.append("no_normal_maps")
    if edits:
        a.render_scene = os.path.join(a.work, "_".join(name)
                                      + os.path.splitext(a.scene)[1].lower())
        peers_scene.copy_gltf(a.scene, a.render_scene, edits)
    scene = {"gltf": os.path.abspath(a.render_scene), "camera": cam,
             "env": os.path.abspath(a.env) if a.env else None,
             "env_intensity": a.env_intensity, "env_rotation": a.env_rotation,
             "light_tree": a.cycles_light_tree}
    if any(r in a.renderers for r in MITSUBA_SAMPLERS):
        try:
            scene["mitsuba"] = peers_pbr.convert(a.render_scene, os.path.join(a.work, "mitsuba"))
        except peers_pbr.ConversionError as e:
            sys.exit("peers.py: error: Mitsuba: %s" % e)
        for note in scene["mitsuba"]["notes"]:
            log("Mitsuba approximates: " + note)
    path = os.path.join(a.work, "scene.json")
    with open(path, "w") as f:
        json.dump(scene, f)
    return scene, path


def wavepath_scene_args(a):
    """wavepath's options for the environment (none without --env)."""
    if not a.env:
        return []
    return ["--env", a.env, "--env-intensity", repr(a.env_intensity), "--env-rotation",
            repr(a.env_rotation)]


def convert(a):
    """Converts the scene into --work (scene.json with PLY paths); returns the description and
    its path. Sets a.render_scene, the glTF wavepath renders: --scene itself, or its Lambertian
    copy (specularFactor 0) when a material has glTF's default specular layer."""
    os.makedirs(a.work, exist_ok=True)
    a.render_scene = a.scene
    try:
        scene = peers_scene.load(a.scene)
    except peers_scene.ConversionError as e:
        sys.exit("peers.py: error: %s" % e)
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


def run_one(a, renderer, spp, seed, scene_json, env, name=None):
    """(wall seconds, image top row first, CPU seconds)."""
    import numpy as np
    from wavepath_tools import accuracy_lib as al
    out = os.path.join(a.work, "%s-%s.npy" % (renderer, name or spp))
    if renderer == "wavepath":
        pfm = out[:-4] + ".pfm"
        sampler = ["--sampler", a.wavepath_sampler] if a.wavepath_sampler else []
        t, _, cpu = timed([a.wavepath, "render", a.render_scene, "--width", str(a.width), "--height",
                      str(a.height), "--spp", str(spp), "--seed", str(seed), "--max-depth",
                      str(a.max_depth), "--rr-depth", str(a.rr_depth), "-o", pfm, "--json", "-q"]
                     + sampler + wavepath_scene_args(a))
        return t, al.read_pfm(pfm), cpu
    job = {"scene": scene_json, "spp": spp, "seed": seed, "width": a.width, "height": a.height,
           "max_depth": a.max_depth, "rr_depth": a.rr_depth, "out": out,
           "variant": a.mitsuba_variant, "sampler": MITSUBA_SAMPLERS.get(renderer)}
    job_path = out[:-4] + ".json"
    with open(job_path, "w") as f:
        json.dump(job, f)
    t, _, cpu = timed([sys.executable, os.path.abspath(__file__), "--worker", renderer, job_path],
                      env)
    return t, np.load(out), cpu


def reference(a):
    """(image, variance) of the wavepath reference, cached in --work by its settings."""
    import numpy as np
    from wavepath_tools import accuracy_lib as al
    h = hashlib.sha256()
    with open(a.render_scene, "rb") as f:
        h.update(f.read())
    h.update(json.dumps([a.width, a.height, a.ref_spp, a.max_depth, a.rr_depth,
                         os.stat(a.wavepath).st_mtime_ns]).encode())
    if a.env:
        with open(a.env, "rb") as f:
            h.update(f.read())
        h.update(json.dumps(wavepath_scene_args(a)[2:]).encode())
    key = h.hexdigest()[:16]
    path = os.path.join(a.work, "reference-%d-%s.npz" % (a.ref_spp, key))
    if not os.path.exists(path):
        log("reference: wavepath, %d spp, %dx%d" % (a.ref_spp, a.width, a.height))
        img, var, info = al.render(a.wavepath, a.render_scene, ["--max-depth", str(a.max_depth),
                                                         "--rr-depth", str(a.rr_depth)]
                                   + wavepath_scene_args(a),
                                   a.width, a.height, a.ref_spp, al.REFERENCE_SEED)
        np.savez(path, img=img, var=var, seconds=info["total_seconds"])
    data = np.load(path)
    return data["img"], data["var"], float(data["seconds"])


def peer_reference(a, peer, scene_json, env):
    """--pbr: (image, variance image, seconds) of a peer's own reference (peer "cycles" or
    "mitsuba": Mitsuba's independent sampler, the reference of both Mitsuba renderers): the mean
    of --ref-chunks runs of --ref-spp / --ref-chunks samples, seeds 7000, 7001, ...; the variance
    image is the per-pixel sample variance of the runs over their number. Cached in --work by
    its settings, the peer's version and the code that converts the scene for it."""
    import inspect
    import numpy as np
    h = hashlib.sha256()
    for f in [a.render_scene] + ([a.env] if a.env else []):
        with open(f, "rb") as fh:
            h.update(fh.read())
    h.update(json.dumps([a.width, a.height, a.ref_spp, a.ref_chunks, a.max_depth, a.rr_depth,
                         a.env_intensity, a.env_rotation, versions([peer], env)[peer]]
                        + ([a.cycles_light_tree] if peer == "cycles" else [a.mitsuba_variant]))
             .encode())
    if peer == "cycles":
        code = (_cycles_settings, _cycles_camera, _cycles_render, worker_cycles,
                _cycles_backface_transparent, worker_cycles_gltf, _cycles_gltf_materials,
                _cycles_world)
    else:
        code = (worker_mitsuba, worker_mitsuba_pbr, peers_pbr, peers_scene)
    for f in code:  # so that a change to the conversion renders afresh
        h.update(inspect.getsource(f).encode())
    path = os.path.join(a.work, "reference-%s-%d-%s.npz" % (peer, a.ref_spp, h.hexdigest()[:16]))
    if not os.path.exists(path):
        spp = a.ref_spp // a.ref_chunks
        runs, seconds = [], 0.0
        for k in range(a.ref_chunks):
            log("reference: %s, run %d of %d, %d spp, %dx%d" % (peer, k + 1, a.ref_chunks, spp,
                                                                a.width, a.height))
            t, img, _ = run_one(a, peer, spp, 7000 + k, scene_json, env, name="ref%d" % k)
            runs.append(img)
            seconds += t
        runs = np.array(runs)
        np.savez(path, img=runs.mean(0), var=runs.var(0, ddof=1) / len(runs), seconds=seconds)
    data = np.load(path)
    return data["img"], data["var"], float(data["seconds"])


def background_mask(a):
    """--pbr: (background, object) boolean masks from wavepath's depth AOV (64 spp). A pixel's
    depth is the mean over its samples, 0 for a miss, so it is 0 exactly when every sample saw
    the background. Background: such pixels whose 4-neighbours are too; object: pixels at least
    two pixels (4-connected) away from any such pixel. The band along silhouettes, where a pixel
    sees both, belongs to neither."""
    import numpy as np
    out = os.path.join(a.work, "mask.pfm")
    timed([a.wavepath, "render", a.render_scene, "--width", str(a.width), "--height",
           str(a.height), "--spp", "64", "--seed", "1", "--max-depth", "1", "-o", out,
           "--aov", "depth", "-q"] + wavepath_scene_args(a))
    with open(out[:-4] + ".depth.pfm", "rb") as f:
        data = f.read()
    head = data.split(b"\n", 3)
    w, hgt = (int(t) for t in head[1].split())
    depth = np.frombuffer(head[3], dtype="<f4" if float(head[2]) < 0 else ">f4",
                          count=w * hgt).reshape(hgt, w)[::-1]

    def erode(m):
        e = m.copy()
        e[1:, :] &= m[:-1, :]
        e[:-1, :] &= m[1:, :]
        e[:, 1:] &= m[:, :-1]
        e[:, :-1] &= m[:, 1:]
        return e
    bg = depth == 0.0
    return erode(bg), erode(erode(~bg))


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
    if any(r in renderers for r in MITSUBA_SAMPLERS):
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
    ax.set_ylabel("relMSE against the renderer's own reference" if a.pbr
                  else "relMSE against the reference")
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


def _cpu_name():
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            cpu = re.search(r"model name\s*:\s*(.*)", f.read()).group(1)
    except (OSError, AttributeError):
        pass
    return cpu


def _by_renderer(a, rows):
    return {r: sorted((x for x in rows if x["renderer"] == r), key=lambda x: x["spp"])
            for r in a.renderers}


def _time_table(a, by, key="seconds"):
    """The time-to-target table's lines (from each run's `key`: wall or CPU seconds)."""
    head = "| relMSE target |" + "".join(" %s |" % LABELS[r] for r in a.renderers)
    peers = [r for r in a.renderers if r != "wavepath"]
    if "wavepath" in a.renderers:
        head += "".join(" %s / wavepath |" % LABELS[r].split(" (")[0] for r in peers)
    L = [head, "|" + "---|" * (head.count("|") - 1)]
    for target in a.targets:
        tt = {r: time_to_target([(x[key], x["rel_mse"]) for x in by[r]], target)
              for r in a.renderers}
        line = "| %g |" % target + "".join(" %s |" % fmt_t(*tt[r]) for r in a.renderers)
        if "wavepath" in a.renderers:
            w = tt["wavepath"][0]
            for r in peers:
                p = tt[r][0]
                line += " %s |" % ("%.2f" % (p / w) if p and w else "—")
        L.append(line)
    return L


def _runs_table(a, by, ref_word="reference"):
    if a.repeat > 1:
        L = ["| renderer | spp | time (s) | times of the %d repetitions (s) | CPU time (s) | "
             "relMSE | image mean / %s |" % (a.repeat, ref_word), "|---|---|---|---|---|---|---|"]
        for r in a.renderers:
            for x in by[r]:
                L.append("| %s | %d | %.2f | %s | %.2f | %.3g | %.4f |"
                         % (LABELS[r], x["spp"], x["seconds"],
                            ", ".join("%.2f" % t for t in x["all_seconds"]), x["cpu_seconds"],
                            x["rel_mse"], x["mean_ratio"]))
        return L
    L = ["| renderer | spp | time (s) | relMSE | image mean / %s |" % ref_word,
         "|---|---|---|---|---|"]
    for r in a.renderers:
        for x in by[r]:
            L.append("| %s | %d | %.2f | %.3g | %.4f |" % (LABELS[r], x["spp"], x["seconds"],
                                                         x["rel_mse"], x["mean_ratio"]))
    return L


def _repeat_sentence(a):
    if a.repeat == 1:
        return ""
    word = "least" if a.statistic == "least" else "median"
    return (" Each run's time is the %s of %d: the sweep was run %d times, the renderers "
            "taking turns at each sample count, with the same seeds (so the same images); all "
            "times are listed under *Every run*, with the %s CPU time (user + system seconds "
            "of the process and its children), which other work on the machine changes much "
            "less than the wall time.%s" % (word, a.repeat, a.repeat, word,
                                             " The least wall time is the run least disturbed "
                                             "by other work." if word == "least" else ""))


def _write_with_notes(a, L):
    """Writes the page's lines L and then the kept notes (see NOTES_MARK)."""
    notes = NOTES_MARK + "\n"
    if os.path.exists(a.out):
        with open(a.out) as f:
            old = f.read()
        if NOTES_MARK in old:
            notes = old[old.index(NOTES_MARK):]
    L += ["", notes]
    with open(a.out, "w") as f:
        f.write("\n".join(L))


def write_doc(a, rows, checks, ref_seconds, vers, chart_name, load):
    by = _by_renderer(a, rows)
    cpu = _cpu_name()
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
         "(tools/wavepath_tools/accuracy_lib.py). One unmeasured 1-spp run of each renderer first fills the "
         "caches kept between processes (wavepath's kernel binary and BVH, Dr.Jit's kernels)."
         + _repeat_sentence(a), "",
         "The scene is converted exactly (`tools/wavepath_tools/peers_scene.py`, tested by "
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
    L += _time_table(a, by)
    L += ["", "## Every run", ""] + _runs_table(a, by)
    L += ["", "## Conversion check: image means", "",
          "Each renderer's largest run against the reference, per channel (mean over all pixels, "
          "ratio to the reference's). The standard error of the ratio is estimated from the "
          "reference's variance image scaled to the run's sample count, assuming a per-sample "
          "variance like wavepath's.", "",
          ] + _means_table(a, checks)
    _write_with_notes(a, L)


def _means_table(a, checks):
    """Rows of the image-mean check: each renderer's largest run over its reference, per
    channel, with the ratio's standard error."""
    L = ["| renderer | spp | R | G | B | ± (1 s.e.) |", "|---|---|---|---|---|---|"]
    for r in a.renderers:
        c = checks[r]
        L.append("| %s | %d | %.4f | %.4f | %.4f | %.4f |" % (LABELS[r], c["spp"], *c["ratio"],
                                                             c["se"]))
    return L


PEER_NAMES = {"cycles": "Cycles", "mitsuba": "Mitsuba"}


def compare_references(refs, peer, masks):
    """--pbr: a peer's reference against wavepath's, per region ("all", "background",
    "object"): pixel count, the peer's mean over wavepath's per channel with 1 s.e. (from both
    variance images), and relMSE = mean(((c - w)^2 - var_c - var_w) / (w^2 + 0.01)), the
    difference beyond both references' noise."""
    import numpy as np
    (w, wv), (c, cv) = refs["wavepath"], refs[peer]
    regions = {"all": np.ones(w.shape[:2], bool), "background": masks[0], "object": masks[1]}
    out = {}
    for name, m in regions.items():
        n = int(m.sum())
        mw, mc = w[m].mean(0) if n else 0.0, c[m].mean(0) if n else 0.0
        if n == 0 or not np.all(mw > 0.0):
            continue  # no such pixels, or black ones (the background without --env)
        vw, vc = wv[m].sum(0) / n ** 2, cv[m].sum(0) / n ** 2
        ratio = mc / mw
        se = ratio * np.sqrt(vc / mc ** 2 + vw / mw ** 2)
        rel = float((((c - w) ** 2 - cv - wv) / (w * w + 0.01))[m].mean())
        out[name] = {"pixels": n, "ratio": [float(x) for x in ratio],
                     "se": [float(x) for x in se], "rel_mse": rel}
    return out


def references_image(a, refs, peer, path):
    """--pbr: wavepath's and a peer's references side by side (linear values clamped to [0, 1],
    sRGB-encoded) and the ratio of their luminances as a map of stops."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    def srgb(x):
        x = np.clip(x, 0.0, 1.0)
        return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)

    lum = np.array([0.2126, 0.7152, 0.0722])
    w, c = refs["wavepath"][0], refs[peer][0]
    name = PEER_NAMES[peer]
    stops = np.log2((c @ lum + 1e-3) / (w @ lum + 1e-3))
    fig, axes = plt.subplots(1, 3, figsize=(12, 4.3), dpi=100)
    for ax, img, title in ((axes[0], w, "wavepath reference"), (axes[1], c, name + " reference")):
        ax.imshow(srgb(img), interpolation="nearest")
        ax.set_title(title)
    im = axes[2].imshow(stops, cmap="coolwarm", vmin=-0.5, vmax=0.5, interpolation="nearest")
    axes[2].set_title("log2(%s / wavepath), luminance" % name)
    fig.colorbar(im, ax=axes[2], fraction=0.046, pad=0.04, label="stops")
    for ax in axes:
        ax.set_xticks([])
        ax.set_yticks([])
    fig.suptitle("%s under %s, %d x %d (clamped to [0, 1], sRGB)"
                 % (os.path.basename(a.scene), os.path.basename(a.env) if a.env else "black",
                    a.width, a.height))
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def write_doc_pbr(a, rows, checks, ref_info, ref_cmp, vers, names, other, notes=()):
    """The page of a --pbr run (notes: the Mitsuba conversion's approximations)."""
    by = _by_renderer(a, rows)
    cmd = "tools/peers.py " + " ".join(a.argv)
    cam_copy = "with_camera" in os.path.basename(a.render_scene)
    env = ("under the environment map `%s` (intensity %g, rotation %g°)"
           % (os.path.relpath(a.env, REPO), a.env_intensity, a.env_rotation) if a.env
           else "with a black background")
    chunks = ("%%s: %%d spp as the mean of %d runs of %d spp with different seeds (%%.0f s)"
              % (a.ref_chunks, a.ref_spp // a.ref_chunks))
    refs = "; ".join(
        ["wavepath: %d spp, one run (%.0f s)" % (a.ref_spp, ref_info["wavepath"])]
        * ("wavepath" in a.renderers)
        + [chunks % (PEER_NAMES[p] + (" (independent sampler; the reference of both Mitsuba "
                                      "renderers)" if p == "mitsuba" else ""),
                     a.ref_spp, ref_info[p]) for p in pbr_peers(a)])
    peers = " and ".join(PEER_NAMES[p] for p in pbr_peers(a))
    L = ["# Peer benchmark: wavepath and %s on a textured model" % peers, "",
         "Written by `tools/peers.py --pbr` (see its `--help`); regenerate with", "",
         "    " + cmd, "",
         "Scene `%s` %s, %d × %d, max depth %d scattering events, Russian roulette after %d "
         "(wavepath's); sweep %s samples per pixel; references: %s. Machine: %s, %d cores%s; "
         "all render on the CPU. Versions: %s."
         % (os.path.relpath(a.scene, REPO), env, a.width, a.height, a.max_depth, a.rr_depth,
            ", ".join(map(str, a.spp)), refs, _cpu_name(), os.cpu_count(),
            "" if other is None else
            "; other work used %.0f%% of the machine's CPU time during the sweep (%.0f of %.0f "
            "core-seconds: its busy time in /proc/stat less this script's own processes; "
            "whichever renderer runs then is slowed), the hypervisor took %.1f%% (steal)"
            % (100 * other["other"] / other["capacity"], other["other"], other["capacity"],
               100 * other["steal"] / other["capacity"]),
            "; ".join("%s: %s" % kv for kv in vers.items())), "",
         "Time is the wall time of each render's whole process, measured by the script from "
         "its start to the image on disk. wavepath: start-up, loading the glTF and decoding its "
         "textures, loading the environment map and building its sampling tables, the kernel "
         "binary and BVH (both from wavepath's caches, filled by an unmeasured 1-spp run "
         "first), rendering, writing a PFM. Cycles: starting Python and importing `bpy`, "
         "Blender's glTF importer, the scene set-up below, rendering (with Cycles' own BVH "
         "build and texture loading), writing an EXR and reading it back into a NumPy file; "
         "also after an unmeasured 1-spp run. Mitsuba: starting Python and importing "
         "`mitsuba`, decoding the textures (Pillow) and loading the converted PLY meshes, "
         "Dr.Jit's kernels (from its cache, after an unmeasured 1-spp run), rendering, writing "
         "a NumPy file." + _repeat_sentence(a), "",
         "**Each renderer's error is measured against its own reference** (relMSE = "
         "mean(((x − r)² − var_r) / (r² + 0.01)), tools/wavepath_tools/accuracy_lib.py, with r and var_r that "
         "renderer's reference and its variance image; wavepath's reference is rendered with "
         "independent samples, as tools/wavepath_tools/accuracy_lib.py renders references, because only then "
         "is its variance image the error's, while the sweep runs use wavepath's default "
         "sampler; Cycles' variance image is the spread of independently seeded runs, right "
         "for any sampler, and all its runs use its default sampler): the two do not render exactly the same "
         "material model (below), so one common reference would charge the model difference to "
         "one of them as error that no number of samples removes. The comparison is noise "
         "against time: how long each needs to get within a relMSE of its own converged image. "
         "How far the two converged images are apart is measured separately below.", "",
         "How the scene is given to each (`tools/peers.py --help`, PBR MODE): wavepath renders "
         "the glTF; Cycles imports the same file with Blender's glTF importer (textures, "
         "metallic-roughness as a Principled BSDF, the normal map as a tangent-space Normal "
         "Map node), with every Principled BSDF switched to single-scatter GGX (Blender's "
         "default is multiscatter GGX), subsurface off, and back faces of materials that are not "
         "double-sided made transparent (wavepath culls them). %s"
         "The environment is the world's Environment Texture with the same intensity, "
         "bilinear lookup (`Linear`, Blender's default, as wavepath's default `--env-filter`) "
         "and the same orientation (a Mapping node "
         "turns Blender's equirectangular convention into wavepath's; checked by the background "
         "pixels below). One-pixel box filter, max bounces = max depth − 1 (Cycles counts "
         "bounces after the first hit), no clamping, no filter glossy, no adaptive sampling, no "
         "denoising; Cycles' light tree %s."
         % ("Every renderer sees the scene from wavepath's `--orbit %s` camera (45° vertical "
            "field of view), written into a copy of the file in place of its own cameras "
            "(`peers_scene.orbit_camera`). " % ",".join("%g" % x for x in a.orbit) if a.orbit
            else "The file has no camera: both render a copy with wavepath's framing camera "
            "(45° vertical field of view, the bounding sphere fitted) written into it "
            "(`peers_scene.with_camera`). " if cam_copy else "",
            "on (Blender's default)" if a.cycles_light_tree else
            "off (--cycles-light-tree turns it on, as Blender's default and the Cornell box page "
            "have it)")
         + (" **Both sample every texture at its nearest texel** (--nearest-textures: a copy "
            "of the file with NEAREST samplers, which Blender's importer turns into Closest "
            "interpolation), unlike the file's own (linear) filtering." if a.nearest_textures
            else "")
         + (" **Both render the model without its normal map** (--no-normal-maps: a copy of "
            "the file without normal textures)." if a.no_normal_maps else ""), "",
         "What the two material models do not share: Blender's Principled BSDF reflects "
         "dielectrics with the exact Fresnel equations (IOR 1.5, the importer's \"Specular IOR "
         "Level\" 0.5) and scales the diffuse base by the specular layer's albedo, where glTF "
         "(and wavepath) mix diffuse and specular with Schlick's Fresnel at the half-vector "
         "(`kernels/bsdf/bsdf.h`); its metals use the F82-tint model, whose correction to Schlick's "
         "Fresnel is proportional to one minus the tint, so with the importer's white Specular "
         "Tint they reflect as glTF's (Schlick, base colour as F0); the "
         "tangent frames of the normal map come from different tangent generators (Blender's "
         "MikkTSpace, wavepath's own, the file has no tangents); the occlusion texture is used "
         "by neither.", "",
         "![relMSE against time](%s)" % names["chart"], "",
         "## Time to reach a relMSE target", "",
         "Interpolated on log-log between the runs around the target; `~`: extrapolated past "
         "the largest run as relMSE ∝ 1/time; `≤`: reached by the smallest run. The ratio is "
         "the peer's time over wavepath's (above 1: wavepath is faster).", ""]
    L += _time_table(a, by)
    if a.repeat > 1:
        L += ["", "The same by CPU time (user + system seconds, the %s of the repetitions): "
              "the work each process did on the 2 cores, whatever else was running; with both "
              "cores busy all along it would be about twice the wall time." % a.statistic, ""]
        L += _time_table(a, by, "cpu_seconds")
    L += ["", "## Every run", "", "relMSE and image mean against the renderer's own reference.",
          ""] + _runs_table(a, by, "own reference")
    L += ["", "## Each renderer against its own reference: image means", "",
          "Each renderer's largest run against its own reference, per channel. The standard "
          "error of the ratio is estimated from the reference's variance image scaled to the "
          "run's sample count (for wavepath's runs, whose default sampler has less error than "
          "independent samples, an overestimate).", "",
          ] + _means_table(a, checks)
    if "mitsuba" in pbr_peers(a):
        L += ["", "## How Mitsuba is given the scene", "",
              "`tools/wavepath_tools/peers_pbr.py` converts the glTF for Mitsuba 3 (its "
              "docstring and `tools/peers.py --help` give the mapping and its gaps): world-space "
              "PLY meshes with normals and UVs, metallic-roughness on the `principled` BSDF "
              "(Disney's model: not glTF's, hence Mitsuba's own reference), textures as bitmaps "
              "decoded in their colour spaces, normal maps through `normalmap`, alpha through "
              "`mask`, emission as `area` emitters, the environment as `envmap` turned by 180° + "
              "the rotation to wavepath's orientation. Approximations made on this file:", ""]
        L += ["- " + n for n in notes] if notes else ["- none"]
    for peer, cmp in ref_cmp.items():
        name = PEER_NAMES[peer]
        L += ["", "## Conversion check: %s's reference against wavepath's" % name, "",
              "Per channel the ratio of the image means "
              "(± 1 s.e. from both variance images), and relMSE between the two, (%s − "
              "wavepath)² less both variance images over (wavepath² + 0.01), the difference "
              % name +
              "beyond the references' noise. Regions from wavepath's depth AOV: *background* are "
              "pixels where every sample missed the model (their 4-neighbours too): they see the "
              "environment map only and test its conversion (orientation, intensity, "
              "lookup); *object* are pixels at least two pixels inside the model's silhouette: "
              "they test the materials. The silhouette band between them counts in *all* only.",
              "",
              "| region | pixels | R | G | B | ± (1 s.e., largest) | relMSE between references |",
              "|---|---|---|---|---|---|---|"]
        for region, c in cmp.items():
            L.append("| %s | %d | %.4f | %.4f | %.4f | %.2g | %.3g |"
                     % (region, c["pixels"], *c["ratio"], max(c["se"]), c["rel_mse"]))
        L += ["", "![the two references and their ratio](%s)" % names["references_" + peer]]
    _write_with_notes(a, L)


def main(argv):
    if len(argv) >= 3 and argv[0] == "--worker":
        worker_main(argv[1], argv[2])
        return
    a = parse_args(argv)
    ensure_venv(a)
    import numpy as np
    from wavepath_tools import accuracy_lib as al

    env = dict(os.environ)
    if any(r in a.renderers for r in MITSUBA_SAMPLERS) and a.mitsuba_variant.startswith("llvm"):
        llvm = find_libllvm()
        if llvm is None:
            sys.exit("peers.py: error: Mitsuba's %s variant needs libLLVM (Debian: libllvm19; or "
                     "set DRJIT_LIBLLVM_PATH), or use --mitsuba-variant scalar_rgb"
                     % a.mitsuba_variant)
        env["DRJIT_LIBLLVM_PATH"] = llvm
        log("libLLVM: " + llvm)
    if a.pbr:
        scene, scene_json = convert_pbr(a)
        log("scene: %s (%s camera), environment %s"
            % (a.render_scene, "--orbit" if a.orbit else "its own" if a.render_scene == a.scene
               else "wavepath's framing",
               a.env or "black"))
    else:
        scene, scene_json = convert(a)
        s = peers_scene.summary(scene)
        log("scene: %d triangles, %d emitters, %d point lights"
            % (s["triangles"], len(s["emitters"]), len(scene["point_lights"])))
    # Without --pbr every renderer is measured against wavepath's reference; with it, each
    # against its own.
    refs, ref_info = {}, {}
    if not a.pbr or "wavepath" in a.renderers:
        ref, ref_var, ref_seconds = reference(a)
        refs = {r: (ref, ref_var) for r in a.renderers}
        ref_info = {"wavepath": ref_seconds}
    for peer in pbr_peers(a):
        pimg, pvar, ref_info[peer] = peer_reference(a, peer, scene_json, env)
        for r in a.renderers:
            if r == peer or MITSUBA_SAMPLERS.get(r) and peer == "mitsuba":
                refs[r] = (pimg, pvar)
                ref_info[r] = ref_info[peer]
    rows, checks = [], {}

    def score(row, img):
        """Fills row's relMSE and mean ratio from its image (and checks[] for the largest)."""
        r, spp = row["renderer"], row["spp"]
        rimg, rvar = refs[r]
        if img.shape != rimg.shape:
            sys.exit("peers.py: error: %s gave an image of shape %s, not %s"
                     % (r, img.shape, rimg.shape))
        st = al.compare(img, np.zeros_like(img), rimg, rvar)
        row.update(rel_mse=st["rel_mse"], mean_ratio=float(img.mean() / rimg.mean()))
        log("%-8s %5d spp  %7.2f s%s  relMSE %.4g  mean ratio %.4f"
            % (r, spp, row["seconds"], " (%s of %s)" % (a.statistic, " ".join(
                "%.2f" % x for x in row["all_seconds"])) if a.repeat > 1 else "",
               row["rel_mse"], row["mean_ratio"]))
        if spp == max(a.spp):
            # Var of a channel's image mean, run and reference: sum of pixel variances / n^2.
            n = rimg.shape[0] * rimg.shape[1]
            rmean = rimg.reshape(-1, 3).mean(0)
            v = rvar.reshape(-1, 3).sum(0) / n ** 2
            se = np.sqrt(v * a.ref_spp / spp + v) / rmean
            checks[r] = {"spp": spp, "ratio": [float(x) for x in img.reshape(-1, 3).mean(0)
                                               / rmean], "se": float(se.max())}

    load_before = os.getloadavg()[0]
    cpu_before, wall_before = cpu_snapshot(), time.perf_counter()
    if a.repeat == 1:
        for r in a.renderers:
            run_one(a, r, 1, 999, scene_json, env)  # warm-up, not measured: fills kernel caches
            for k, spp in enumerate(a.spp):
                t, img, cpu = run_one(a, r, spp, 1000 + k, scene_json, env)
                rows.append({"renderer": r, "spp": spp, "seconds": t, "cpu_seconds": cpu})
                score(rows[-1], img)
    else:
        # --repeat: every renderer's warm-up, then the sweep N times, the renderers taking turns
        # at each sample count (so that both meet much the same other work), with the same
        # seeds (the same images: both renderers are deterministic); a run's time is the least
        # (or median: --statistic) of its repetitions.
        for r in a.renderers:
            run_one(a, r, 1, 999, scene_json, env)  # warm-up, not measured: fills kernel caches
        rows = [{"renderer": r, "spp": spp, "all_seconds": [], "all_cpu_seconds": []}
                for r in a.renderers for spp in a.spp]
        row_of = {(x["renderer"], x["spp"]): x for x in rows}
        images = {}
        for rep in range(a.repeat):
            for k, spp in enumerate(a.spp):
                for r in a.renderers:
                    t, img, cpu = run_one(a, r, spp, 1000 + k, scene_json, env)
                    row_of[(r, spp)]["all_seconds"].append(t)
                    row_of[(r, spp)]["all_cpu_seconds"].append(cpu)
                    images.setdefault((r, spp), img)
                    log("%-8s %5d spp  %7.2f s  CPU %7.2f s  (repetition %d of %d)"
                        % (r, spp, t, cpu, rep + 1, a.repeat))
        pick = min if a.statistic == "least" else statistics.median
        for row in rows:
            row["seconds"] = pick(row["all_seconds"])
            row["cpu_seconds"] = pick(row["all_cpu_seconds"])
            score(row, images[(row["renderer"], row["spp"])])
    load_after = os.getloadavg()[0]
    other = other_work(cpu_before, cpu_snapshot(), time.perf_counter() - wall_before)
    with open(os.path.join(a.work, "runs.json"), "w") as f:
        json.dump(rows, f, indent=1)
    base = os.path.splitext(a.out)[0]
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    chart_path = base + "_" + os.path.splitext(os.path.basename(a.scene))[0] + ".png"
    chart(a, rows, chart_path)
    page_dir = os.path.dirname(os.path.abspath(a.out))
    if a.pbr:
        names = {"chart": os.path.relpath(chart_path, page_dir)}
        ref_cmp = {}
        if "wavepath" in a.renderers and pbr_peers(a):
            masks = background_mask(a)
            for peer in pbr_peers(a):
                ref_cmp[peer] = compare_references(refs, peer, masks)
                refs_path = base + ("_references.png" if peer == "cycles"
                                    else "_references_%s.png" % peer)
                references_image(a, refs, peer, refs_path)
                names["references_" + peer] = os.path.relpath(refs_path, page_dir)
                for name, c in ref_cmp[peer].items():
                    log("references, %-10s %s / wavepath %s  relMSE %.3g"
                        % (name, PEER_NAMES[peer], " ".join("%.4f" % x for x in c["ratio"]),
                           c["rel_mse"]))
        write_doc_pbr(a, rows, checks, ref_info, ref_cmp, versions(a.renderers, env), names,
                      other, scene.get("mitsuba", {}).get("notes", []))
    else:
        write_doc(a, rows, checks, ref_seconds, versions(a.renderers, env),
                  os.path.relpath(chart_path, page_dir), (load_before, load_after))
    log("wrote %s and %s" % (a.out, chart_path))


if __name__ == "__main__":
    main(sys.argv[1:])
