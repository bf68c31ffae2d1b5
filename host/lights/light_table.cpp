#include "host/lights/light_table.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "host/lights/emission.h"
#include "host/util/error.h"
#include "host/util/parallel.h"

namespace wp {

namespace {

constexpr double kPi = 3.14159265358979323846;

double luminance(glm::vec3 c) {
  return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}
dev::float4 f4(glm::vec3 v, float w = 0.0f) {
  return {v.x, v.y, v.z, w};
}

dev::Light punctual(const PunctualLight& l) {
  dev::Light d{};
  d.position = f4(l.position, l.range);
  d.direction = f4(glm::normalize(l.direction));
  d.intensity = f4(l.intensity);
  // KHR_lights_punctual's recommended spot falloff: saturate(cd * scale + offset)^2.
  const float cos_outer = std::cos(l.outer_cone), cos_inner = std::cos(l.inner_cone);
  const float scale = 1.0f / std::max(0.001f, cos_inner - cos_outer);
  d.spot = {scale, -cos_outer * scale, 0.0f, 0.0f};
  d.meta.x = l.type == LightType::kPoint  ? WP_LIGHT_POINT
             : l.type == LightType::kSpot ? WP_LIGHT_SPOT
                                          : WP_LIGHT_DIRECTIONAL;
  return d;
}

double punctual_power(const PunctualLight& l, double radius) {
  const double i = luminance(l.intensity);
  switch (l.type) {
    case LightType::kPoint:
      return 4.0 * kPi * i;
    case LightType::kSpot:
      return 2.0 * kPi * (1.0 - std::cos(0.5 * (l.inner_cone + l.outer_cone))) * i;
    default:
      return kPi * radius * radius * i;
  }
}

}  // namespace

std::vector<dev::LightAlias> build_alias_table(const std::vector<double>& weights) {
  const std::size_t n = weights.size();
  const double total = std::accumulate(weights.begin(), weights.end(), 0.0);
  if (n == 0 || !(total > 0.0) || !std::isfinite(total))
    throw Error("light selection: no light with positive finite power");
  std::vector<dev::LightAlias> table(n);
  std::vector<double> scaled(n);
  std::vector<std::size_t> small, large;
  for (std::size_t i = 0; i < n; ++i) {
    table[i].pmf = static_cast<float>(weights[i] / total);
    table[i].alias = static_cast<dev::uint>(i);
    scaled[i] = weights[i] / total * static_cast<double>(n);
    (scaled[i] < 1.0 ? small : large).push_back(i);
  }
  while (!small.empty() && !large.empty()) {
    const std::size_t s = small.back(), l = large.back();
    small.pop_back();
    table[s].prob = static_cast<float>(scaled[s]);
    table[s].alias = static_cast<dev::uint>(l);
    scaled[l] -= 1.0 - scaled[s];
    if (scaled[l] < 1.0) {
      large.pop_back();
      small.push_back(l);
    }
  }
  for (std::size_t i : small) table[i].prob = 1.0f;  // rounding leftovers
  for (std::size_t i : large) table[i].prob = 1.0f;
  return table;
}

LightTable build_light_table(const Scene& scene, const EnvironmentMap* env, glm::vec3 background,
                             float env_intensity, LightSelect select) {
  LightTable t;
  std::vector<double> power;
  // The scene's bounding radius; 0 for inverted bounds (a scene without triangles built in code).
  const glm::vec3 extent = glm::max(scene.bounds_hi - scene.bounds_lo, glm::vec3(0.0f));
  const double radius = 0.5 * glm::length(extent);
  for (const PunctualLight& l : scene.lights) {
    t.lights.push_back(punctual(l));
    power.push_back(punctual_power(l, radius));
  }
  t.tri_light.assign(scene.triangle_count(), WP_NO_LIGHT);
  // The emissive triangles: the scene's, or each mesh's once for all its instances.
  struct Emitter {
    std::uint32_t triangle;
    double luminance;  // power / (pi x area)
  };
  std::vector<Emitter> emitters;
  std::vector<std::uint32_t> mesh_emitters;  // instanced: each mesh's first in emitters, + 1 end
  const auto vertex = [&](std::size_t i, int k) {
    return scene.positions[scene.indices[3 * i + k]];
  };
  const auto area = [&](std::size_t i) {  // in the scene's arrays (the world, unless instanced)
    const glm::vec3 a = vertex(i, 0), b = vertex(i, 1), c = vertex(i, 2);
    return 0.5 * glm::length(glm::cross(b - a, c - a));
  };
  // The triangles' emission, a block at a time on the hardware threads (a textured emitter's
  // mean takes hundreds of texture lookups, and a model can have tens of thousands), in order.
  constexpr std::size_t kBlock = std::size_t(1) << 14;
  std::vector<TriangleEmission> block(kBlock);
  for (std::size_t first = 0; first < scene.triangle_count(); first += kBlock) {
    const std::size_t n = std::min(kBlock, scene.triangle_count() - first);
    parallel_for(n, [&](std::size_t k) { block[k] = triangle_emission(scene, first + k); });
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t i = first + k;
      const Material& m = scene.materials[scene.triangle_material[i]];
      const TriangleEmission& e = block[k];
      if (e.zero()) continue;  // black everywhere (an emissive texture's dark part): not a light
      if (!(area(i) > 0.0)) continue;  // a degenerate triangle emits nothing
      // The integrated emission; a triangle whose sampled mean is 0 but whose peak is not (a lit
      // spot between the grid points) keeps a small chance of being chosen.
      const double l = std::max(luminance(e.mean), 1e-3 * e.peak);
      emitters.push_back({static_cast<std::uint32_t>(i), l * (m.double_sided ? 2.0 : 1.0)});
    }
  }
  const auto add = [&](const Emitter& e, double world_area, std::uint32_t instance) {
    dev::Light d{};
    d.meta.x = WP_LIGHT_TRIANGLE;
    d.meta.y = e.triangle;
    d.meta.z = instance;
    t.lights.push_back(d);
    power.push_back(kPi * world_area * e.luminance);
    ++t.emissive_triangles;
  };
  if (scene.instances.empty()) {
    for (const Emitter& e : emitters) {
      t.tri_light[e.triangle] = static_cast<std::uint32_t>(t.lights.size());
      add(e, area(e.triangle), WP_NO_INSTANCE);
    }
  } else {
    // Emitters are in triangle order, and meshes are triangle ranges in order.
    std::size_t next = 0;
    for (const MeshRange& mesh : scene.meshes) {
      mesh_emitters.push_back(static_cast<std::uint32_t>(next));
      for (std::uint32_t local = 0;
           next < emitters.size() &&
           emitters[next].triangle < mesh.first_triangle + mesh.triangle_count;
           ++next, ++local)
        t.tri_light[emitters[next].triangle] = local;
    }
    mesh_emitters.push_back(static_cast<std::uint32_t>(next));
    t.instance_light.assign(scene.instances.size(), WP_NO_LIGHT);
    for (std::size_t k = 0; k < scene.instances.size(); ++k) {
      const Instance& inst = scene.instances[k];
      const std::uint32_t first = mesh_emitters[inst.mesh], end = mesh_emitters[inst.mesh + 1];
      if (first == end) continue;
      t.instance_light[k] = static_cast<std::uint32_t>(t.lights.size());
      for (std::uint32_t j = first; j < end; ++j) {
        glm::dvec3 v[3];
        for (int c = 0; c < 3; ++c)
          v[c] = glm::dvec3(inst.to_world * glm::dvec4(vertex(emitters[j].triangle, c), 1.0));
        const double world_area = 0.5 * glm::length(glm::cross(v[1] - v[0], v[2] - v[0]));
        add(emitters[j], world_area, static_cast<std::uint32_t>(k));
      }
    }
  }
  const double env_luminance = env ? env->mean_luminance * env_intensity : luminance(background);
  if (env_luminance > 0.0) {
    dev::Light d{};
    d.meta.x = WP_LIGHT_ENVIRONMENT;
    t.env_light = static_cast<std::uint32_t>(t.lights.size());
    t.lights.push_back(d);
    power.push_back(4.0 * kPi * kPi * radius * radius * env_luminance);
  }
  if (t.lights.empty()) return t;
  if (select == LightSelect::kUniform) power.assign(power.size(), 1.0);
  for (double& p : power)  // a light NEE could reach must keep a chance of being picked
    if (!(p > 0.0)) p = 1e-12;
  t.alias = build_alias_table(power);
  return t;
}

}  // namespace wp
