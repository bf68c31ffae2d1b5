// Which optional kernel features a scene uses. The program is built with one -D WP_FEATURE_X=0|1
// per feature (kernels/util/features.h), so absent features cost no code, registers or branches.
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
  // A texture whose sampler allows mip-maps: textures are minified through ray cones
  // (kernels/texture/ray_cone.h; emission and alpha excepted); off with --mipmaps off.
  bool texture_lod = true;
  bool normal_maps = true;
  bool alpha = true;
  bool unlit = true;
  // A scattering material with metallic > 0, specular > 0, transmission or one of the layered
  // extensions below (they need the full BSDF, kernels/bsdf/bsdf.h).
  bool glossy = true;
  bool transmission = true;
  bool volume = true;
  // The material extensions; each only for scattering (not unlit) materials that use it.
  bool specular = true;     // KHR_materials_specular: a colour other than white, or a texture
  bool clearcoat = true;    // clearcoatFactor > 0
  bool sheen = true;        // a sheen colour other than black
  bool anisotropy = true;   // anisotropyStrength > 0
  bool iridescence = true;  // iridescenceFactor > 0
  bool diffuse_transmission = true;  // diffuseTransmissionFactor > 0
  bool dispersion = true;            // dispersion > 0 on a transmissive material with a volume

  // Not a material feature but the scene's structure: a two-level BVH (Scene::instances; built
  // as -D WP_BVH_INSTANCES=1 beside WP_BVH_WIDTH). Off in all(); render_features sets it from the
  // scene either way.
  bool instances = false;

  static SceneFeatures all() { return {}; }

  // Which per-vertex arrays beyond positions and normals the program reads
  // (kernels/geom/material.h, alpha.h): tangents for a tangent frame; texture coordinates for
  // textures and wherever the layered BSDF's texture_point runs; colours for COLOR_0 and for alpha
  // (its alpha channel). An array the program cannot read is packed empty.
  bool reads_tangents() const { return normal_maps || anisotropy || clearcoat; }
  bool reads_uvs() const {
    return textures || normal_maps || texture_lod || specular || clearcoat || sheen || anisotropy ||
           iridescence || diffuse_transmission || dispersion;
  }
  bool reads_colors() const { return vertex_colors || alpha; }
  // The features `scene` uses; `has_environment_map` tells whether the render has a map.
  static SceneFeatures of(const Scene& scene, bool has_environment_map);

  // (macro name, enabled) in a fixed order; drives the build options and the report.
  std::vector<std::pair<std::string, bool>> flags() const;
  // "punctual_lights emission" (the enabled ones), or "none".
  std::string describe() const;
};

}  // namespace wp
