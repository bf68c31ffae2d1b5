#include "host/scene_features.h"

#include <algorithm>

namespace wp {

SceneFeatures SceneFeatures::of(const Scene& scene) {
  SceneFeatures f;
  f.punctual_lights = !scene.lights.empty();
  f.spot_lights = std::any_of(scene.lights.begin(), scene.lights.end(),
                              [](const PunctualLight& l) { return l.type == LightType::kSpot; });
  f.emission = std::any_of(scene.materials.begin(), scene.materials.end(), [](const Material& m) {
    return m.emission.x > 0.0f || m.emission.y > 0.0f || m.emission.z > 0.0f;
  });
  f.vertex_colors = std::any_of(scene.color0.begin(), scene.color0.end(), [](const glm::vec4& c) {
    return c.r != 1.0f || c.g != 1.0f || c.b != 1.0f;
  });
  return f;
}

std::vector<std::pair<std::string, bool>> SceneFeatures::flags() const {
  return {{"WP_FEATURE_PUNCTUAL_LIGHTS", punctual_lights},
          {"WP_FEATURE_SPOT_LIGHTS", spot_lights},
          {"WP_FEATURE_EMISSION", emission},
          {"WP_FEATURE_VERTEX_COLORS", vertex_colors}};
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
