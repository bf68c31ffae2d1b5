#include "host/device/scene_features.h"

#include <algorithm>

namespace wp {

namespace {
template <class C, class P>
bool any(const C& c, P p) {
  return std::any_of(c.begin(), c.end(), p);
}

// Whether a material reads any texture of the material extensions (KHR_materials_specular,
// _clearcoat, _sheen, _anisotropy, _iridescence, _diffuse_transmission).
bool uses_extension_textures(const Material& x) {
  for (const int t : {x.specular_texture, x.specular_color_texture, x.clearcoat_texture,
                      x.clearcoat_roughness_texture, x.clearcoat_normal_texture,
                      x.sheen_color_texture, x.sheen_roughness_texture, x.anisotropy_texture,
                      x.iridescence_texture, x.iridescence_thickness_texture,
                      x.diffuse_transmission_texture, x.diffuse_transmission_color_texture})
    if (t >= 0) return true;
  return false;
}
}  // namespace

SceneFeatures SceneFeatures::of(const Scene& scene, bool has_environment_map) {
  const auto& m = scene.materials;
  SceneFeatures f;
  f.punctual_lights = !scene.lights.empty();
  f.spot_lights =
      any(scene.lights, [](const PunctualLight& l) { return l.type == LightType::kSpot; });
  f.emission = any(m, [](const Material& x) {
    return x.emission.x > 0.0f || x.emission.y > 0.0f || x.emission.z > 0.0f;
  });
  f.environment = has_environment_map;
  f.instances = !scene.instances.empty();
  f.vertex_colors = any(
      scene.color0, [](const glm::vec4& c) { return c.r != 1.0f || c.g != 1.0f || c.b != 1.0f; });
  f.textures = any(m, [](const Material& x) {
    return x.base_color_texture >= 0 || x.metallic_roughness_texture >= 0 ||
           x.normal_texture >= 0 || x.emissive_texture >= 0 || x.transmission_texture >= 0 ||
           (!x.unlit && uses_extension_textures(x));
  });
  f.normal_maps = any(m, [](const Material& x) { return x.normal_texture >= 0; });
  f.texture_lod = f.textures && any(scene.textures, [](const TextureRef& t) { return t.mipmaps; });
  f.alpha = any(m, [](const Material& x) { return x.alpha_mode != AlphaMode::kOpaque; });
  f.unlit = any(m, [](const Material& x) { return x.unlit; });
  f.transmission = any(
      m, [](const Material& x) { return x.transmission > 0.0f || x.transmission_texture >= 0; });
  f.volume = f.transmission && any(m, [](const Material& x) { return x.thickness > 0.0f; });
  // The material extensions, on materials that scatter (unlit ones scatter nothing).
  const auto lit = [&](auto p) {
    return any(m, [&](const Material& x) { return !x.unlit && p(x); });
  };
  f.specular = lit([](const Material& x) {
    return x.specular_color != glm::vec3(1.0f) || x.specular_texture >= 0 ||
           x.specular_color_texture >= 0;
  });
  f.clearcoat = lit([](const Material& x) { return x.clearcoat > 0.0f; });
  f.sheen = lit([](const Material& x) {
    return std::max(x.sheen_color.r, std::max(x.sheen_color.g, x.sheen_color.b)) > 0.0f;
  });
  f.anisotropy = lit([](const Material& x) { return x.anisotropy_strength > 0.0f; });
  f.iridescence = lit([](const Material& x) { return x.iridescence > 0.0f; });
  f.diffuse_transmission = lit([](const Material& x) { return x.diffuse_transmission > 0.0f; });
  f.dispersion = lit([](const Material& x) {
    return x.dispersion > 0.0f && x.thickness > 0.0f && x.transmission > 0.0f;
  });
  // Without a specular layer (glTF's default metallic is 1, its default specular factor 1), the
  // BSDF is Lambert's alone (kernels/bsdf/bsdf.h). Unlit materials scatter nothing.
  f.glossy = f.transmission || f.specular || f.clearcoat || f.sheen || f.anisotropy ||
             f.iridescence || f.diffuse_transmission || any(m, [](const Material& x) {
               return !x.unlit && (x.metallic > 0.0f || x.specular > 0.0f);
             });
  return f;
}

std::vector<std::pair<std::string, bool>> SceneFeatures::flags() const {
  return {{"WP_FEATURE_PUNCTUAL_LIGHTS", punctual_lights},
          {"WP_FEATURE_SPOT_LIGHTS", spot_lights},
          {"WP_FEATURE_EMISSION", emission},
          {"WP_FEATURE_ENVIRONMENT", environment},
          {"WP_FEATURE_VERTEX_COLORS", vertex_colors},
          {"WP_FEATURE_TEXTURES", textures},
          {"WP_FEATURE_TEXTURE_LOD", texture_lod},
          {"WP_FEATURE_NORMAL_MAPS", normal_maps},
          {"WP_FEATURE_ALPHA", alpha},
          {"WP_FEATURE_UNLIT", unlit},
          {"WP_FEATURE_GLOSSY", glossy},
          {"WP_FEATURE_TRANSMISSION", transmission},
          {"WP_FEATURE_VOLUME", volume},
          {"WP_FEATURE_SPECULAR", specular},
          {"WP_FEATURE_CLEARCOAT", clearcoat},
          {"WP_FEATURE_SHEEN", sheen},
          {"WP_FEATURE_ANISOTROPY", anisotropy},
          {"WP_FEATURE_IRIDESCENCE", iridescence},
          {"WP_FEATURE_DIFFUSE_TRANSMISSION", diffuse_transmission},
          {"WP_FEATURE_DISPERSION", dispersion}};
}

std::string SceneFeatures::describe() const {
  std::string out;
  for (const auto& [name, on] : flags()) {
    if (!on) continue;
    std::string lower = name.substr(std::string("WP_FEATURE_").size());
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    out += (out.empty() ? "" : " ") + lower;
  }
  return out.empty() ? "none" : out;
}

}  // namespace wp
