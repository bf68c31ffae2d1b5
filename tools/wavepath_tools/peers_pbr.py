"""glTF 2.0 to Mitsuba 3 for the --pbr mode of tools/peers.py: textured metallic-roughness
materials on Mitsuba's `principled` BSDF, under wavepath's environment map and camera.

    from wavepath_tools import peers_pbr
    desc = peers_pbr.convert("model.glb", "work/")   # PLY meshes and images written into work/
    desc["notes"]         # every approximation made, one line each (also on the peers page)
    d = peers_pbr.mitsuba_scene(desc, cam, job)     # a Mitsuba scene dict with placeholders
    d = peers_pbr.realize(d, mi)                     # (in the venv) ready for mi.load_dict

convert() and mitsuba_scene() need the standard library only (tests/test_peers_pbr.py checks the
mapping with plain python3); realize() turns the placeholders into Mitsuba objects: textures into
`bitmap` plugins with float `data` (decoded with Pillow and NumPy, factors and channel selections
baked in), look-at and rotation transforms into mi.ScalarTransform4f, texture transforms
(KHR_texture_transform) into mi.ScalarTransform3f.

Reading: .gltf (embedded or external buffers and images) and .glb, through peers_scene's reader;
PNG and JPEG images. Refused (ConversionError naming it): a texCoord other than 0 (a textureInfo's,
or KHR_texture_transform's override of it), KHR_draco_mesh_compression, EXT_meshopt_compression,
KHR_mesh_quantization, EXT_mesh_gpu_instancing, KHR_texture_basisu, EXT_texture_webp,
KHR_materials_unlit, KHR_materials_pbrSpecularGlossiness, any other extension the file requires,
sparse accessors, primitives that are not triangles, cameras that are not perspective.

Geometry: every triangle primitive of the default scene becomes one binary PLY in world space
(node transforms applied; normals by the inverse transpose; a mirroring transform reverses the
winding, as in peers_scene.load), with its NORMAL (else flat shading: face_normals) and
TEXCOORD_0 (written as it is: Mitsuba's PLY reader keeps it, and its bitmaps put v = 0 at the
image's top row, glTF's convention). TANGENT is not used: Mitsuba has no vertex tangents; its
normal maps use the frame of dp/du (from the UVs, per triangle) and cross(n, dp/du).

Material mapping (glTF -> Mitsuba `principled`; "tex" means the parameter becomes a bitmap):

  baseColorFactor x baseColorTexture.rgb (sRGB) -> base_color (linear; tex)
  metallicFactor x metallicRoughnessTexture.b (linear) -> metallic (tex)
  roughnessFactor x metallicRoughnessTexture.g (linear) -> roughness (both: alpha = roughness^2)
  KHR_materials_ior ior (default 1.5) -> eta (specular 0.5 is F0 0.04, eta 1.5)
  KHR_materials_specular specularFactor s -> eta of the F0 ((ior-1)/(ior+1))^2 x s
                                             (not for transmissive materials: eta stays the ior)
  KHR_materials_transmission transmissionFactor (x texture .r) -> spec_trans (tex); with
      KHR_materials_volume (thickness > 0) `principled` (refracting solid), without it
      `principledthin` (thin-walled, as glTF's transmission without volume)
  KHR_materials_diffuse_transmission factor -> principledthin diff_trans
  KHR_materials_clearcoat clearcoatFactor (x texture .r) -> clearcoat (tex);
      clearcoatRoughness r -> clearcoat_gloss g with GTR1 alpha lerp(0.1, 0.001, g) = r^2
  KHR_materials_sheen sheenColorFactor -> sheen = its largest component, sheen_tint 0
  KHR_materials_anisotropy strength a (constant roughness) -> glTF's alpha_t = mix(alpha, 1, a^2),
      alpha_b = alpha as Mitsuba's alpha_u = r'^2 / aspect, alpha_v = r'^2 x aspect:
      roughness r' = (alpha_t alpha_b)^(1/4), anisotropic = (1 - alpha_b / alpha_t) / 0.9 (<= 1)
  normalTexture (linear, x scale on x and y) -> `normalmap` BSDF around the material
  alphaMode MASK -> `mask` BSDF, opacity = (alpha >= alphaCutoff) per texel, nearest filtering;
      BLEND -> `mask` with opacity = alpha (stochastic); alpha = baseColorFactor.a x texture.a
  doubleSided -> `twosided` (not for transmissive materials, which have two sides already)
  emissiveFactor x KHR_materials_emissive_strength x emissiveTexture (sRGB) -> `area` emitter
      radiance (tex)
  sampler: magFilter NEAREST -> filter_type nearest, else bilinear; wrapS -> wrap_mode
      (REPEAT repeat, CLAMP_TO_EDGE clamp, MIRRORED_REPEAT mirror)
  KHR_texture_transform (on any texture converted) offset, rotation, scale -> the bitmap's
      to_uv = uv_transform() (exact: see there), each texture use its own
  KHR_lights_punctual point -> `point` (intensity x colour, W/sr); spot -> `spot` (cutoff_angle =
      outerConeAngle, beam_width = innerConeAngle); directional -> `directional` (irradiance
      W/m^2); each at its node's world transform, shining down the node's -Z
  environment (wavepath's --env, --env-intensity, --env-rotation R) -> `envmap`, scale =
      intensity, to_world = rotation about +Y by 180 + R degrees (env_to_world_degrees())

Gaps (each that applies to a file is listed in desc["notes"]):
  - Material model: Mitsuba's principled is Disney's: retro-reflective diffuse not scaled by
    the specular layer's Fresnel, exact dielectric Fresnel, GTR1 clearcoat added on top with
    Disney's 0.25 weight, Disney sheen (colour and roughness not used); glTF's (wavepath's) is
    Lambert x (1 - F) with Schlick's Fresnel. Hence each renderer is measured against its own
    reference.
  - KHR_materials_specular colour and textures, sheen textures, anisotropy textures and rotation,
    iridescence, dispersion, volume attenuation, diffuse transmission colour and texture,
    clearcoat normal textures, the occlusion texture: not used.
  - A texture's wrapT when it differs from wrapS (Mitsuba has one wrap mode); minification
    filters (no mipmaps in Mitsuba's bitmap: it magnifies bilinearly or nearest, always).
  - Normal maps: tangent frames from per-triangle dp/du, not the file's (or MikkTSpace)
    tangents; mirrored UV charts get a flipped bitangent.
  - A material that is not double-sided is black from behind in Mitsuba; wavepath culls back
    faces (rays pass through them). Mitsuba's area emitters emit from the front only.
  - MASK: the cut-off is applied per texel (nearest), not to the filtered alpha.
  - Spot lights: Mitsuba's falloff is linear in angle between beam_width and cutoff_angle,
    glTF's (wavepath's) the square of a ramp linear in cosine. A light's range is ignored.
"""

import math
import os

from wavepath_tools import peers_scene as ps
from wavepath_tools.peers_scene import ConversionError

REFUSED = {
    "KHR_draco_mesh_compression": "compressed meshes are not decoded",
    "EXT_meshopt_compression": "compressed meshes are not decoded",
    "KHR_mesh_quantization": "quantized attributes are not read",
    "EXT_mesh_gpu_instancing": "instancing is not converted",
    "KHR_texture_basisu": "KTX2 images are not decoded",
    "EXT_texture_webp": "WebP images are not converted",
    "KHR_materials_unlit": "unlit materials are not converted",
    "KHR_materials_pbrSpecularGlossiness": "specular-glossiness materials are not converted",
}
# Extensions read (exactly or as the docstring's mapping approximates them).
CONVERTED = {"KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_ior",
             "KHR_materials_specular", "KHR_materials_transmission", "KHR_materials_volume",
             "KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_anisotropy",
             "KHR_materials_diffuse_transmission", "KHR_materials_iridescence",
             "KHR_materials_dispersion", "KHR_materials_variants", "KHR_xmp_json_ld",
             "EXT_lights_image_based", "KHR_texture_transform"}

NEAREST = 9728
WRAP = {10497: "repeat", 33071: "clamp", 33648: "mirror"}


def env_to_world_degrees(rotation):
    """The angle (degrees, about +Y) of Mitsuba's envmap to_world that matches wavepath's map
    turned by `rotation` degrees. wavepath (kernels/lights/environment.h) looks a world direction
    w up at m = Ry(-R) w, u = (atan2(m.x, -m.z) + pi) / 2 pi, so the map's centre is -Z; Mitsuba's
    envmap at d = to_world^-1 w, u = atan2(d.x, -d.z) / 2 pi (mod 1), its centre +Z. Both take
    v = acos(y) / pi. A half turn more makes them one."""
    return 180.0 + rotation


def wavepath_env_uv(w, rotation):
    """wavepath's (u, v) of world direction w (env_dir_uv, in Python: for the tests)."""
    c, s = math.cos(math.radians(rotation)), math.sin(math.radians(rotation))
    m = (c * w[0] - s * w[2], w[1], s * w[0] + c * w[2])
    r = math.hypot(m[0], m[2])
    return (max(0.0, math.atan2(m[0], -m[2]) + math.pi) / (2 * math.pi), math.atan2(r, m[1]) / math.pi)


def mitsuba_env_uv(w, to_world_degrees):
    """Mitsuba envmap's (u, v) of world direction w (direction_to_uv after to_world's inverse)."""
    a = math.radians(-to_world_degrees)  # the inverse rotation about +Y
    c, s = math.cos(a), math.sin(a)
    d = (c * w[0] + s * w[2], w[1], -s * w[0] + c * w[2])
    n = math.sqrt(sum(x * x for x in d))
    u = math.atan2(d[0], -d[2]) / (2 * math.pi)
    return u - math.floor(u), math.acos(max(-1.0, min(1.0, d[1] / n))) / math.pi


# ---- Checks --------------------------------------------------------------------------------------

def check_extensions(doc):
    """ConversionError for an extension the converter refuses or a required one it does not
    know; [notes] for the used ones it ignores."""
    used = set(doc.get("extensionsUsed", [])) | set(doc.get("extensionsRequired", []))
    for name in sorted(used):
        if name in REFUSED:
            raise ConversionError("%s: %s" % (name, REFUSED[name]))
    unknown = sorted(used - CONVERTED)
    required = [n for n in unknown if n in doc.get("extensionsRequired", [])]
    if required:
        raise ConversionError("required extension(s) not converted: " + ", ".join(required))
    return ["extension %s is ignored" % n for n in unknown]


# ---- Images and textures -------------------------------------------------------------------------

def _image_files(doc, buffers, path, work):
    """The path of every image (external files as they are; embedded ones written to work)."""
    import base64
    from urllib.parse import unquote
    base = os.path.dirname(os.path.abspath(path))
    out = []
    for i, im in enumerate(doc.get("images", [])):
        mime = im.get("mimeType", "")
        uri = im.get("uri")
        if uri is not None and not uri.startswith("data:"):
            out.append(os.path.join(base, unquote(uri)))
            continue
        if uri is not None:
            mime = uri[5:].split(";")[0] or mime
            data = base64.b64decode(uri.split(",", 1)[1])
        else:
            view = doc["bufferViews"][im["bufferView"]]
            start = view.get("byteOffset", 0)
            data = buffers[view["buffer"]][start:start + view["byteLength"]]
        ext = {"image/png": ".png", "image/jpeg": ".jpg"}.get(mime)
        if ext is None:
            raise ConversionError("image %d: MIME type %r (PNG and JPEG convert)" % (i, mime))
        out.append(os.path.join(work, "image%d%s" % (i, ext)))
        with open(out[-1], "wb") as f:
            f.write(data)
    return out


def uv_transform(xf):
    """KHR_texture_transform `xf` as the row-major 3 x 3 matrix M (last row 0 0 1) that glTF
    applies to a texture coordinate: it looks (u, v) up at M (u, v, 1). M = T(offset) R(rotation)
    S(scale) has rows (c sx, s sy, ox), (-s sx, c sy, oy), c = cos(rotation), s = sin(rotation):
    the UVs turn counter-clockwise, the image clockwise, as the extension's text and its example
    (offset (0, 1), rotation pi/2, scale 0.5 selects the lower left quadrant) have it, and as
    wavepath's loader (host/scene/gltf_textures.cpp) does. (The extension's GLSL listing, read as
    GLSL's column-major constructor, turns the other way and contradicts that example.)

    M is Mitsuba's bitmap to_uv as it is: to_uv maps the mesh's UV to the lookup UV (bitmap.cpp:
    uv = to_uv @ si.uv); the PLY keeps glTF's (u, v) (write_ply) and the bitmap looks v = 0 up in
    the data's row 0, the image's top, glTF's origin (texture_data keeps the rows). Neither side
    flips v, so the conjugation F M F (F: v -> 1 - v) that a flipped convention would need is M
    itself, and Mitsuba samples the texel glTF's transform names."""
    ox, oy = (float(x) for x in xf.get("offset", (0.0, 0.0)))
    sx, sy = (float(x) for x in xf.get("scale", (1.0, 1.0)))
    r = float(xf.get("rotation", 0.0))
    c, s = math.cos(r), math.sin(r)
    return [[c * sx, s * sy, ox], [-s * sx, c * sy, oy], [0.0, 0.0, 1.0]]


IDENTITY3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]


class Textures:
    """Makes the bitmap placeholders of one document; collects the notes on their samplers."""

    def __init__(self, doc, images, notes):
        self.doc, self.images, self.notes = doc, images, notes

    def get(self, info, where, channels, srgb, factor, op=None, arg=None, filter_type=None):
        """A placeholder dict for textureInfo `info`: channels (0 R .. 3 A) of its image,
        decoded from sRGB when `srgb`, times `factor` (one per channel), then `op`; with
        KHR_texture_transform, to_uv (a placeholder) is its matrix."""
        xf = info.get("extensions", {}).get("KHR_texture_transform")
        if xf is not None and "texCoord" in xf:  # the extension's override replaces texCoord
            if xf["texCoord"] != 0:
                raise ConversionError("%s: KHR_texture_transform texCoord %d (only TEXCOORD_0 "
                                      "converts)" % (where, xf["texCoord"]))
        elif info.get("texCoord", 0) != 0:
            raise ConversionError("%s: texCoord %d (only TEXCOORD_0 converts)"
                                  % (where, info["texCoord"]))
        tex = self.doc["textures"][info["index"]]
        if "source" not in tex:
            raise ConversionError("%s: texture %d has no source image" % (where, info["index"]))
        sampler = self.doc.get("samplers", [])[tex["sampler"]] if "sampler" in tex else {}
        wrap_s, wrap_t = sampler.get("wrapS", 10497), sampler.get("wrapT", 10497)
        if wrap_s != wrap_t:
            self.notes.append("%s: wrapT %d differs from wrapS %d; Mitsuba uses wrapS"
                              % (where, wrap_t, wrap_s))
        if sampler.get("minFilter", NEAREST) not in (NEAREST, 9729):
            self.notes.append("%s: minFilter %d (mipmaps) is not used" % (where,
                                                                          sampler["minFilter"]))
        if filter_type is None:
            filter_type = "nearest" if sampler.get("magFilter") == NEAREST else "bilinear"
        out = {"type": "bitmap", "raw": True, "filter_type": filter_type,
               "wrap_mode": WRAP.get(wrap_s, "repeat"),
               "peers": {"image": self.images[tex["source"]], "channels": list(channels),
                         "srgb": srgb, "factor": [float(f) for f in factor], "op": op,
                         "arg": arg}}
        if xf is not None and uv_transform(xf) != IDENTITY3:
            out["to_uv"] = {"peers_to_uv": uv_transform(xf)}
        return out


def _value(x):
    """A constant parameter: a float, or an `rgb` dict for a colour."""
    if isinstance(x, (tuple, list)):
        return {"type": "rgb", "value": [float(c) for c in x]}
    return float(x)


# ---- Materials -----------------------------------------------------------------------------------

def material(doc, index, textures):
    """{"name", "bsdf": Mitsuba BSDF dict (placeholders for textures), "emitter": area emitter
    dict or None} of material `index`; notes go to textures.notes."""
    m = doc["materials"][index]
    name = m.get("name", "material%d" % index)
    where = "material %r" % name
    notes = textures.notes
    pbr = m.get("pbrMetallicRoughness", {})
    ext = m.get("extensions", {})
    for key in sorted(ext):
        if key in REFUSED:
            raise ConversionError("%s: %s: %s" % (where, key, REFUSED[key]))
    factor = [float(c) for c in pbr.get("baseColorFactor", (1.0, 1.0, 1.0, 1.0))]
    p = {}
    if "baseColorTexture" in pbr:
        p["base_color"] = textures.get(pbr["baseColorTexture"], where + " baseColorTexture",
                                       (0, 1, 2), True, factor[:3])
    else:
        p["base_color"] = _value(factor[:3])
    metallic = float(pbr.get("metallicFactor", 1.0))
    roughness = float(pbr.get("roughnessFactor", 1.0))
    if "metallicRoughnessTexture" in pbr:
        info = pbr["metallicRoughnessTexture"]
        p["metallic"] = textures.get(info, where + " metallicRoughnessTexture.b", (2,), False,
                                     (metallic,))
        p["roughness"] = textures.get(info, where + " metallicRoughnessTexture.g", (1,), False,
                                      (roughness,))
    else:
        p["metallic"], p["roughness"] = metallic, roughness
    thin = _transmission(m, p, textures, where)
    _specular(m, p, thin is not None, notes, where)
    if thin is None:
        _clearcoat(ext.get("KHR_materials_clearcoat"), p, textures, where)
    elif "KHR_materials_clearcoat" in ext:
        notes.append("%s: clearcoat on a thin transmissive material is not used" % where)
    _sheen(ext.get("KHR_materials_sheen"), p, notes, where)
    _anisotropy(ext.get("KHR_materials_anisotropy"), p, "metallicRoughnessTexture" in pbr,
                notes, where)
    for key in ("KHR_materials_iridescence", "KHR_materials_dispersion"):
        if key in ext:
            notes.append("%s: %s is not used" % (where, key))
    if "occlusionTexture" in m:
        notes.append("%s: occlusionTexture is not used (by wavepath either)" % where)
    bsdf = dict(p, type="principledthin" if thin else "principled")
    if thin:
        bsdf.pop("metallic")
        if metallic != 0.0 or "metallicRoughnessTexture" in pbr:
            notes.append("%s: principledthin has no metallic parameter" % where)
    bsdf = _wrap(m, bsdf, textures, where, factor[3], thin is not None)
    return {"name": name, "bsdf": bsdf, "emitter": _emitter(m, textures, where)}


def _transmission(m, p, textures, where):
    """Sets spec_trans (and diff_trans) in p; None for an opaque material, else True for a thin
    one (principledthin) or False for a refracting solid (principled)."""
    ext = m.get("extensions", {})
    tr, dt = ext.get("KHR_materials_transmission"), ext.get("KHR_materials_diffuse_transmission")
    if tr is None and dt is None:
        return None
    if tr is not None:
        f = float(tr.get("transmissionFactor", 0.0))
        p["spec_trans"] = (textures.get(tr["transmissionTexture"], where + " transmissionTexture",
                                        (0,), False, (f,))
                           if "transmissionTexture" in tr else f)
    thick = float(ext.get("KHR_materials_volume", {}).get("thicknessFactor", 0.0)) > 0.0
    if "KHR_materials_volume" in ext and "attenuationDistance" in ext["KHR_materials_volume"]:
        textures.notes.append("%s: volume attenuation is not used" % where)
    if dt is not None:
        p["diff_trans"] = float(dt.get("diffuseTransmissionFactor", 0.0))
        if any(k in dt for k in ("diffuseTransmissionTexture", "diffuseTransmissionColorFactor",
                                 "diffuseTransmissionColorTexture")):
            textures.notes.append("%s: diffuse transmission colour and textures are not used"
                                  % where)
        if thick:
            textures.notes.append("%s: diffuse transmission makes it principledthin (volume "
                                  "not used)" % where)
        return True
    return not thick


def _ior(m):
    return float(m.get("extensions", {}).get("KHR_materials_ior", {}).get("ior", 1.5))


def f0_to_eta(f0):
    """The index of refraction whose normal-incidence Fresnel reflectance is f0."""
    r = math.sqrt(max(0.0, min(f0, 0.999999)))
    return (1.0 + r) / (1.0 - r)


def _specular(m, p, transmissive, notes, where):
    """eta from KHR_materials_ior and KHR_materials_specular's factor."""
    ior = _ior(m)
    spec = m.get("extensions", {}).get("KHR_materials_specular")
    eta = ior
    if spec is not None:
        s = float(spec.get("specularFactor", 1.0))
        if transmissive and s != 1.0:
            notes.append("%s: specularFactor on a transmissive material is not used" % where)
        elif s != 1.0:
            eta = f0_to_eta(((ior - 1.0) / (ior + 1.0)) ** 2 * s)
        if any(k in spec for k in ("specularTexture", "specularColorTexture")) or any(
                float(c) != 1.0 for c in spec.get("specularColorFactor", (1.0, 1.0, 1.0))):
            notes.append("%s: specular colour and textures are not used" % where)
    p["eta"] = max(eta, 1.0)


def clearcoat_gloss(roughness):
    """Mitsuba's clearcoat_gloss whose GTR1 alpha lerp(0.1, 0.001, gloss) is roughness^2
    (clamped to [0, 1])."""
    return min(1.0, max(0.0, (0.1 - roughness * roughness) / 0.099))


def _clearcoat(cc, p, textures, where):
    if cc is None:
        return
    f = float(cc.get("clearcoatFactor", 0.0))
    r = float(cc.get("clearcoatRoughnessFactor", 0.0))
    p["clearcoat"] = (textures.get(cc["clearcoatTexture"], where + " clearcoatTexture", (0,),
                                   False, (f,)) if "clearcoatTexture" in cc else f)
    p["clearcoat_gloss"] = (textures.get(cc["clearcoatRoughnessTexture"],
                                         where + " clearcoatRoughnessTexture", (1,), False, (r,),
                                         op="gloss")
                            if "clearcoatRoughnessTexture" in cc else clearcoat_gloss(r))
    if "clearcoatNormalTexture" in cc:
        textures.notes.append("%s: clearcoatNormalTexture is not used" % where)


def _sheen(sh, p, notes, where):
    if sh is None:
        return
    color = [float(c) for c in sh.get("sheenColorFactor", (0.0, 0.0, 0.0))]
    p["sheen"], p["sheen_tint"] = max(color), 0.0
    notes.append("%s: sheen as Disney's (weight %g, white; colour, roughness, textures not "
                 "used)" % (where, max(color)))


def anisotropy(roughness, strength):
    """(roughness, anisotropic) of Mitsuba's principled for glTF's roughness and anisotropy
    strength (see the docstring)."""
    a = roughness * roughness
    at = a + (1.0 - a) * strength * strength
    if at <= 0.0:
        return roughness, 0.0
    return (at * a) ** 0.25, min(1.0, (1.0 - a / at) / 0.9)


def _anisotropy(an, p, textured, notes, where):
    if an is None:
        return
    strength = float(an.get("anisotropyStrength", 0.0))
    if an.get("anisotropyRotation", 0.0) != 0.0 or "anisotropyTexture" in an:
        notes.append("%s: anisotropy rotation and texture are not used" % where)
    if strength == 0.0:
        return
    if textured:
        _, p["anisotropic"] = anisotropy(p["roughness"]["peers"]["factor"][0], strength)
        notes.append("%s: anisotropy with textured roughness: aspect from roughnessFactor"
                     % where)
        return
    p["roughness"], p["anisotropic"] = anisotropy(p["roughness"], strength)


def _wrap(m, bsdf, textures, where, alpha, transmissive):
    """The BSDF inside twosided, normalmap and mask, as the material asks."""
    pbr = m.get("pbrMetallicRoughness", {})
    if m.get("doubleSided", False) and not transmissive:
        bsdf = {"type": "twosided", "bsdf": bsdf}
    if "normalTexture" in m:
        info = m["normalTexture"]
        tex = textures.get(info, where + " normalTexture", (0, 1, 2), False, (1.0, 1.0, 1.0),
                           op="normal", arg=float(info.get("scale", 1.0)))
        bsdf = {"type": "normalmap", "normalmap": tex, "bsdf": bsdf}
    mode = m.get("alphaMode", "OPAQUE")
    if mode == "OPAQUE":
        return bsdf
    cutoff = float(m.get("alphaCutoff", 0.5))
    if "baseColorTexture" in pbr:
        info = pbr["baseColorTexture"]
        if mode == "MASK":
            opacity = textures.get(info, where + " alpha", (3,), False, (alpha,), op="cutoff",
                                   arg=cutoff, filter_type="nearest")
        else:
            opacity = textures.get(info, where + " alpha", (3,), False, (alpha,))
    else:
        opacity = (1.0 if alpha >= cutoff else 0.0) if mode == "MASK" else alpha
    if opacity == 1.0:
        return bsdf
    return {"type": "mask", "opacity": _value(opacity) if isinstance(opacity, float)
            else opacity, "bsdf": bsdf}


def _emitter(m, textures, where):
    strength = float(m.get("extensions", {}).get("KHR_materials_emissive_strength", {}).get(
        "emissiveStrength", 1.0))
    e = [float(c) * strength for c in m.get("emissiveFactor", (0.0, 0.0, 0.0))]
    if max(e) <= 0.0:
        return None
    if m.get("doubleSided", False):
        textures.notes.append("%s: double-sided emission: Mitsuba emits from the front only"
                              % where)
    if "emissiveTexture" in m:
        radiance = textures.get(m["emissiveTexture"], where + " emissiveTexture", (0, 1, 2),
                                True, e)
    else:
        radiance = _value(e)
    return {"type": "area", "radiance": radiance}


# ---- Geometry ------------------------------------------------------------------------------------

def _normal_matrix(world):
    """The 3 x 3 cofactor matrix of world's upper 3 x 3 times the sign of its determinant: the
    inverse transpose up to a positive scale (normals are normalised after it)."""
    m = [row[:3] for row in world[:3]]
    sign = 1.0 if ps._det3(world) >= 0.0 else -1.0

    def cof(i, j):
        r = [k for k in range(3) if k != i]
        c = [k for k in range(3) if k != j]
        return ((-1) ** (i + j)) * (m[r[0]][c[0]] * m[r[1]][c[1]] - m[r[0]][c[1]] * m[r[1]][c[0]])
    return [[sign * cof(i, j) for j in range(3)] for i in range(3)]


def _unit(v):
    n = math.sqrt(sum(c * c for c in v))
    return tuple(c / n for c in v) if n > 0.0 else (0.0, 0.0, 1.0)


def primitive(doc, buffers, prim, world, where):
    """{"positions", "normals" (or None), "uvs" (or None), "triangles"} of one triangle
    primitive in world space (winding reversed under a mirroring transform)."""
    if prim.get("mode", 4) != 4:
        raise ConversionError("%s: primitive mode %d is not triangles" % (where, prim["mode"]))
    for key in prim.get("extensions", {}):
        if key in REFUSED:
            raise ConversionError("%s: %s: %s" % (where, key, REFUSED[key]))
    attrs = prim["attributes"]
    for key in ("POSITION", "NORMAL", "TEXCOORD_0"):
        acc = doc["accessors"][attrs[key]] if key in attrs else None
        if acc is not None and acc["componentType"] != 5126:
            raise ConversionError("%s: %s is not float (KHR_mesh_quantization is not read)"
                                  % (where, key))
    positions = [ps._point(world, v) for v in ps._accessor(doc, buffers, attrs["POSITION"])]
    normals = None
    if "NORMAL" in attrs:
        nm = _normal_matrix(world)
        normals = [_unit([sum(nm[i][k] * n[k] for k in range(3)) for i in range(3)])
                   for n in ps._accessor(doc, buffers, attrs["NORMAL"])]
    uvs = ps._accessor(doc, buffers, attrs["TEXCOORD_0"]) if "TEXCOORD_0" in attrs else None
    idx = (ps._accessor(doc, buffers, prim["indices"]) if "indices" in prim
           else list(range(len(positions))))
    tris = [tuple(idx[k:k + 3]) for k in range(0, len(idx) - 2, 3)]
    if ps._det3(world) < 0.0:
        tris = [(a, c, b) for a, b, c in tris]
    return {"positions": positions, "normals": normals, "uvs": uvs, "triangles": tris}


def write_ply(path, mesh):
    """One primitive as binary little-endian PLY: x y z [nx ny nz] [u v] floats (glTF's u, v:
    Mitsuba reads them as they are), uint32 triangle lists."""
    import struct
    from array import array
    props = ["x", "y", "z"]
    if mesh["normals"] is not None:
        props += ["nx", "ny", "nz"]
    if mesh["uvs"] is not None:
        props += ["u", "v"]
    head = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\n%selement face %d\n"
            "property list uchar uint vertex_indices\nend_header\n"
            % (len(mesh["positions"]), "".join("property float %s\n" % p for p in props),
               len(mesh["triangles"])))
    values = array("f")
    for k, p in enumerate(mesh["positions"]):
        values.extend(p)
        if mesh["normals"] is not None:
            values.extend(mesh["normals"][k])
        if mesh["uvs"] is not None:
            u, v = mesh["uvs"][k]
            values.extend((u, v))
    if values.itemsize != 4 or struct.pack("=f", 1.0) != struct.pack("<f", 1.0):
        raise RuntimeError("write_ply needs 4-byte little-endian floats")
    with open(path, "wb") as f:
        f.write(head.encode("ascii"))
        f.write(values.tobytes())
        f.write(b"".join(struct.pack("<B3I", 3, *t) for t in mesh["triangles"]))


# ---- Lights --------------------------------------------------------------------------------------

def light(l, world, notes):
    """The Mitsuba emitter dict of KHR_lights_punctual light `l` at node transform `world`."""
    name = l.get("name", "light")
    value = _value([float(c) * float(l.get("intensity", 1.0))
                    for c in l.get("color", (1.0, 1.0, 1.0))])
    if "range" in l:
        notes.append("light %r: range %g is not used" % (name, l["range"]))
    position = ps._point(world, (0.0, 0.0, 0.0))
    direction = _unit(ps._vector(world, (0.0, 0.0, -1.0)))
    kind = l.get("type")
    if kind == "point":
        return {"type": "point", "position": list(position), "intensity": value}
    if kind == "directional":
        return {"type": "directional", "direction": list(direction), "irradiance": value}
    if kind == "spot":
        spot = l.get("spot", {})
        up = (0.0, 1.0, 0.0) if abs(direction[1]) < 0.9 else (1.0, 0.0, 0.0)
        notes.append("light %r: Mitsuba's spot falloff is linear in angle" % name)
        return {"type": "spot", "intensity": value,
                "cutoff_angle": math.degrees(float(spot.get("outerConeAngle", math.pi / 4))),
                "beam_width": math.degrees(float(spot.get("innerConeAngle", 0.0))),
                "to_world": {"peers_look_at": [list(position),
                                               [position[i] + direction[i] for i in range(3)],
                                               list(up)]}}
    raise ConversionError("light %r: type %r" % (name, kind))


# ---- The scene -----------------------------------------------------------------------------------

def convert(path, work):
    """The converted scene: {"shapes": [{"name", "ply", "normals", "material"}], "materials":
    [material()], "emitters": [Mitsuba emitter dicts], "notes": [str]}. PLY files and embedded
    images go into `work`."""
    os.makedirs(work, exist_ok=True)
    doc, buffers = ps._read_document(path)
    notes = check_extensions(doc)
    textures = Textures(doc, _image_files(doc, buffers, path, work), notes)
    materials = [material(doc, i, textures) for i in range(len(doc.get("materials", [])))]
    lights = doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    out = {"shapes": [], "materials": materials, "emitters": [], "notes": notes}

    def visit(node, world):
        if "mesh" in node:
            mesh = doc["meshes"][node["mesh"]]
            name = mesh.get("name", "mesh%d" % node["mesh"])
            for p, prim in enumerate(mesh["primitives"]):
                where = "mesh %r primitive %d" % (name, p)
                geo = primitive(doc, buffers, prim, world, where)
                ply = os.path.join(work, "shape%d.ply" % len(out["shapes"]))
                write_ply(ply, geo)
                out["shapes"].append({"name": "%s_%d" % (name, p), "ply": ply,
                                      "normals": geo["normals"] is not None,
                                      "material": prim.get("material")})
        punctual = node.get("extensions", {}).get("KHR_lights_punctual")
        if punctual is not None:
            out["emitters"].append(light(lights[punctual["light"]], world, notes))

    ps._walk(doc, visit)
    if any(s["material"] is None for s in out["shapes"]):
        out["default_material"] = {"name": "default", "emitter": None,
                                   "bsdf": {"type": "principled", "base_color": 1.0,
                                            "metallic": 1.0, "roughness": 1.0, "eta": 1.5}}
    return out


def sensor(cam, job):
    """Mitsuba's perspective sensor for camera `cam` (peers_scene's camera dict) and the job's
    film and sampler (as tools/peers.py's Cornell box worker)."""
    target = [cam["position"][i] + cam["forward"][i] for i in range(3)]
    return {"type": "perspective", "fov_axis": "y", "fov": math.degrees(cam["yfov"]),
            "near_clip": 1e-3, "far_clip": 1e4,
            "to_world": {"peers_look_at": [list(cam["position"]), target, list(cam["up"])]},
            "sampler": {"type": job.get("sampler") or "independent",
                        "sample_count": job["spp"]},
            "film": {"type": "hdrfilm", "width": job["width"], "height": job["height"],
                     "pixel_format": "rgb", "rfilter": {"type": "box"}}}


def mitsuba_scene(desc, cam, job, env=None):
    """The Mitsuba scene dict (with placeholders for realize()) of convert()'s `desc`, seen by
    `cam`; job: spp, width, height, max_depth and rr_depth (wavepath's: Mitsuba's max_depth is
    one more), sampler. env: {"path", "intensity", "rotation"} or None (black)."""
    d = {"type": "scene",
         "integrator": {"type": "path", "max_depth": job["max_depth"] + 1,
                        "rr_depth": job["rr_depth"]},
         "sensor": sensor(cam, job)}
    for k, shape in enumerate(desc["shapes"]):
        mat = (desc["materials"][shape["material"]] if shape["material"] is not None
               else desc["default_material"])
        s = {"type": "ply", "filename": shape["ply"], "face_normals": not shape["normals"],
             "bsdf": mat["bsdf"]}
        if mat["emitter"] is not None:
            s["emitter"] = mat["emitter"]
        d["shape%d" % k] = s
    for k, e in enumerate(desc["emitters"]):
        d["light%d" % k] = e
    if env:
        d["environment"] = {"type": "envmap", "filename": env["path"],
                            "scale": float(env["intensity"]),
                            "to_world": {"peers_rotate_y": env_to_world_degrees(env["rotation"])}}
    return d


# ---- Realising the placeholders (in the venv: Mitsuba, NumPy, Pillow) ----------------------------

def srgb_to_linear(x):
    """The sRGB transfer function's inverse, on a NumPy array in [0, 1]."""
    import numpy as np
    return np.where(x <= 0.04045, x / 12.92, ((x + 0.055) / 1.055) ** 2.4)


def decode_image(path):
    """An image as a float32 H x W x 4 NumPy array in [0, 1] (RGBA; 8 or 16 bits)."""
    import numpy as np
    from PIL import Image
    with Image.open(path) as im:
        if im.mode in ("I;16", "I;16B", "I"):
            g = np.asarray(im, dtype=np.float32) / 65535.0
            return np.dstack([g, g, g, np.ones_like(g)])
        return np.asarray(im.convert("RGBA"), dtype=np.float32) / 255.0


def texture_data(spec, cache):
    """The float32 H x W x C array of a placeholder's "peers" spec (C = 1 or 3)."""
    import numpy as np
    if spec["image"] not in cache:
        cache[spec["image"]] = decode_image(spec["image"])
    x = cache[spec["image"]][:, :, spec["channels"]]
    if spec["srgb"]:
        x = srgb_to_linear(x)
    x = x * np.asarray(spec["factor"], dtype=np.float32)
    op, arg = spec.get("op"), spec.get("arg")
    if op == "normal":  # glTF: normalize((2 c - 1) x (scale, scale, 1)); normalmap normalises
        n = 2.0 * x - 1.0
        n[:, :, :2] *= arg
        x = 0.5 * (n + 1.0)
    elif op == "cutoff":
        x = (x >= arg).astype(np.float32)
    elif op == "gloss":
        x = np.clip((0.1 - x * x) / 0.099, 0.0, 1.0)
    return np.ascontiguousarray(x, dtype=np.float32)


def realize(d, mi, cache=None):
    """A copy of dict `d` with the placeholders made Mitsuba's: {"peers": spec} bitmaps get
    their data, {"peers_look_at": [o, t, up]} and {"peers_rotate_y": degrees} become
    mi.ScalarTransform4f, {"peers_to_uv": 3 x 3 rows} (a bitmap's to_uv) mi.ScalarTransform3f."""
    cache = {} if cache is None else cache
    if isinstance(d, dict):
        if "peers_look_at" in d:
            o, t, up = d["peers_look_at"]
            return mi.ScalarTransform4f().look_at(origin=o, target=t, up=up)
        if "peers_rotate_y" in d:
            return mi.ScalarTransform4f().rotate([0.0, 1.0, 0.0], d["peers_rotate_y"])
        if "peers_to_uv" in d:
            return mi.ScalarTransform3f(d["peers_to_uv"])
        out = {k: realize(v, mi, cache) for k, v in d.items() if k != "peers"}
        if "peers" in d:
            out["data"] = mi.TensorXf(texture_data(d["peers"], cache))
        return out
    if isinstance(d, list):
        return [realize(v, mi, cache) for v in d]
    return d
