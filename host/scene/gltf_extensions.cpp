#include "host/scene/gltf_extensions.h"

#include <algorithm>
#include <cstring>

namespace wp {

const char* extension_support_name(ExtensionSupport support) {
  switch (support) {
    case ExtensionSupport::kSupported:
      return "supported";
    case ExtensionSupport::kIgnored:
      return "ignored";
    case ExtensionSupport::kRefused:
      return "refused";
  }
  return "unknown";
}

const std::vector<KnownExtension>& known_extensions() {
  // Sorted by name once made (for look-ups). The notes of ignored extensions say what the file
  // loads as.
  static const std::vector<KnownExtension> kTable = [] {
    std::vector<KnownExtension> t = {
        {"EXT_lights_image_based", false, "the image-based light is not used (give --env)"},
        {"EXT_mesh_gpu_instancing", true,
         "every instance placed: of the mesh in a two-level BVH, or a copy (--instancing)"},
        {"EXT_meshopt_compression", true,
         "buffer views decoded with meshoptimizer (all modes and filters)"},
        {"EXT_texture_avif", false,
         "AVIF images are not decoded: a texture's PNG or JPEG source is used, one without is "
         "skipped"},
        {"EXT_texture_webp", true, "WebP images decoded with libwebp"},
        {"KHR_animation_pointer", false, "animations are not played: the scene at rest"},
        {"KHR_draco_mesh_compression", true, "Draco meshes decoded with Draco"},
        {"KHR_lights_punctual", true, "point, spot and directional lights"},
        {"KHR_materials_anisotropy", true, "anisotropic GGX in the mesh's tangent frame"},
        {"KHR_materials_clearcoat", true, "a GGX dielectric coat with its own normal texture"},
        {"KHR_materials_diffuse_transmission", true, "a Lambertian transmission lobe"},
        {"KHR_materials_dispersion", true, "an index per wavelength, with KHR_materials_volume"},
        {"KHR_materials_emissive_strength", true, "emission times the strength"},
        {"KHR_materials_ior", true, "dielectric Fresnel and refraction"},
        {"KHR_materials_iridescence", true, "thin-film Fresnel on the specular lobes"},
        {"KHR_materials_pbrSpecularGlossiness", false,
         "the material's pbrMetallicRoughness is used (glTF's defaults without one)"},
        {"KHR_materials_sheen", true, "the Charlie sheen lobe"},
        {"KHR_materials_specular", true, "specular factor, colour and their textures"},
        {"KHR_materials_transmission", true, "smooth and rough dielectric transmission"},
        {"KHR_materials_unlit", true, "unshaded materials"},
        {"KHR_materials_variants", true, "--variant NAME picks a variant's materials"},
        {"KHR_materials_volume", true,
         "refraction into volumes and absorption; thicknessTexture is not read"},
        {"KHR_mesh_quantization", true, "integer vertex attributes"},
        {"KHR_texture_basisu", true,
         "KTX2 images are not decoded (no decoder in Debian): each texture's fallback source is "
         "used; a texture in use without one is an error"},
        {"KHR_texture_transform", true, "offset, rotation, scale and texCoord"},
        {"KHR_xmp_json_ld", false, "metadata, not needed to render"},
    };
    std::sort(t.begin(), t.end(), [](const KnownExtension& a, const KnownExtension& b) {
      return std::strcmp(a.name, b.name) < 0;
    });
    return t;
  }();
  return kTable;
}

namespace {

const KnownExtension* find_known(const std::string& name) {
  const std::vector<KnownExtension>& table = known_extensions();
  const auto it = std::lower_bound(
      table.begin(), table.end(), name,
      [](const KnownExtension& e, const std::string& n) { return n.compare(e.name) > 0; });
  return it != table.end() && name == it->name ? &*it : nullptr;
}

ExtensionUse use_of(const std::string& name, bool required) {
  ExtensionUse use;
  use.name = name;
  use.required = required;
  const KnownExtension* known = find_known(name);
  use.note = known ? known->note : "unknown to wavepath";
  if (known && known->supported)
    use.support = ExtensionSupport::kSupported;
  else
    use.support = required ? ExtensionSupport::kRefused : ExtensionSupport::kIgnored;
  if (use.support == ExtensionSupport::kRefused)
    use.note =
        known ? "required, and wavepath does not read it" : "required, and unknown to wavepath";
  return use;
}

}  // namespace

std::vector<ExtensionUse> extension_uses(const std::vector<std::string>& used,
                                         const std::vector<std::string>& required) {
  std::vector<ExtensionUse> uses;
  const auto listed = [&](const std::string& name) {
    return std::any_of(uses.begin(), uses.end(),
                       [&](const ExtensionUse& u) { return u.name == name; });
  };
  const auto is_required = [&](const std::string& name) {
    return std::find(required.begin(), required.end(), name) != required.end();
  };
  for (const std::vector<std::string>* names : {&used, &required})
    for (const std::string& name : *names)
      if (!listed(name)) uses.push_back(use_of(name, is_required(name)));
  return uses;
}

}  // namespace wp
