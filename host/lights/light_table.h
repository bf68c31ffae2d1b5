// The lights next-event estimation chooses from, and how it chooses.
//
// One table holds every light: the scene's punctual lights, one entry per emissive triangle, and
// the environment (the map, or a non-zero constant background). NEE picks one per shading point
// from an alias table, with probability proportional either to 1 (uniform) or to an estimate of
// the light's power (power):
//   point: 4 pi I;  spot: 2 pi (1 - cos(mean cone angle)) I;  directional: pi r^2 E;
//   triangle: pi A L (twice that when double-sided);  environment: 4 pi^2 r^2 L_mean;
// with luminances of the RGB values, r the radius of the scene's bounding sphere, A the area, L
// the emitted radiance averaged over the triangle (host/lights/emission.h: an emissive texture is
// integrated; a triangle that is black everywhere is not a light). The pmf of every light is stored
// too: MIS needs the probability with which NEE would have chosen a light that a BSDF-sampled ray
// found.
#pragma once

#include <cstdint>
#include <vector>

#include "host/lights/environment.h"
#include "host/scene/scene.h"
#include "kernels/shared/types.h"

namespace wp {

enum class LightSelect { kUniform, kPower };

struct LightTable {
  std::vector<dev::Light> lights;
  std::vector<dev::LightAlias> alias;  // one per light
  // Per scene triangle: index in lights, or WP_NO_LIGHT. In an instanced scene (Scene::instances)
  // each instance of a mesh with emissive triangles has a light per emissive triangle, sampled with
  // its world-space area, in the mesh's order from instance_light[instance] on; tri_light then
  // holds a triangle's index among its mesh's emissive triangles (types.h, SceneDesc).
  std::vector<std::uint32_t> tri_light;
  std::vector<std::uint32_t> instance_light;
  std::uint32_t env_light = WP_NO_LIGHT;  // index of the environment light
  std::size_t emissive_triangles = 0;
};

// `env` may be null (no map); `background` is the constant radiance used without a map.
LightTable build_light_table(const Scene& scene, const EnvironmentMap* env, glm::vec3 background,
                             float env_intensity, LightSelect select);

// Vose's alias method over non-negative weights (at least one positive).
std::vector<dev::LightAlias> build_alias_table(const std::vector<double>& weights);

}  // namespace wp
