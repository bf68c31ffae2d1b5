// Which optional kernel features a scene uses. The program is built with one -D WP_FEATURE_X=0|1
// per feature (kernels/features.h), so absent features cost no code, registers or branches.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "host/scene/scene.h"

namespace wp {

struct SceneFeatures {
  bool punctual_lights = true;
  bool spot_lights = true;
  bool emission = true;
  bool environment = true;  // an environment map (not the constant background)
  bool vertex_colors = true;
  bool textures = true;
  bool normal_maps = true;
  bool alpha = true;
  bool unlit = true;
  bool glossy = true;  // a scattering material with metallic > 0, specular > 0 or transmission
  bool transmission = true;
  bool volume = true;

  static SceneFeatures all() { return {}; }
  // The features `scene` uses; `has_environment_map` tells whether the render has a map.
  static SceneFeatures of(const Scene& scene, bool has_environment_map);

  // (macro name, enabled) in a fixed order; drives the build options and the report.
  std::vector<std::pair<std::string, bool>> flags() const;
  // "punctual_lights emission" (the enabled ones), or "none".
  std::string describe() const;
};

}  // namespace wp
