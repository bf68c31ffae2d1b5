// Small scenes built in code for tests whose expected answers are derived from the same numbers.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <glm/geometric.hpp>

#include "host/scene/scene.h"

namespace wp::test {

// Appends a triangle mesh with per-vertex normals and material `material` to `scene`.
inline void add_mesh(Scene& scene, const std::vector<glm::vec3>& positions,
                     const std::vector<glm::vec3>& normals,
                     const std::vector<std::uint32_t>& indices, std::uint32_t material) {
  const auto base = static_cast<std::uint32_t>(scene.positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) {
    scene.positions.push_back(positions[i]);
    scene.normals.push_back(normals[i]);
    scene.uv0.emplace_back(0.0f);
    scene.color0.emplace_back(1.0f);
  }
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    for (int k = 0; k < 3; ++k) scene.indices.push_back(base + indices[t + k]);
    scene.triangle_material.push_back(material);
  }
}

// A flat quad with corners a, b, c, d (counter-clockwise seen from the front).
inline void add_quad(Scene& scene, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d,
                     std::uint32_t material) {
  const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
  add_mesh(scene, {a, b, c, d}, {n, n, n, n}, {0, 1, 2, 0, 2, 3}, material);
}

// A UV sphere, front faces outward; smooth normals, or with `flat` each facet's own normal (then
// shading and geometric normals agree, as exact energy tests need).
inline void add_sphere(Scene& scene, glm::vec3 center, float radius, int rings, int segments,
                       std::uint32_t material, bool flat = false) {
  std::vector<glm::vec3> p, n;
  std::vector<std::uint32_t> idx;
  for (int r = 0; r <= rings; ++r) {
    const float theta =
        static_cast<float>(M_PI) * static_cast<float>(r) / static_cast<float>(rings);
    for (int s = 0; s <= segments; ++s) {
      const float phi =
          2.0f * static_cast<float>(M_PI) * static_cast<float>(s) / static_cast<float>(segments);
      const glm::vec3 d(std::sin(theta) * std::cos(phi), std::cos(theta),
                        std::sin(theta) * std::sin(phi));
      p.push_back(center + radius * d);
      n.push_back(d);
    }
  }
  const auto at = [&](int r, int s) { return static_cast<std::uint32_t>(r * (segments + 1) + s); };
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      // Listed so that cross(b - a, c - a) points outward (rings run down from +y, segments
      // toward +phi).
      if (r > 0) idx.insert(idx.end(), {at(r, s), at(r, s + 1), at(r + 1, s)});
      if (r < rings - 1) idx.insert(idx.end(), {at(r, s + 1), at(r + 1, s + 1), at(r + 1, s)});
    }
  if (flat) {
    std::vector<glm::vec3> fp, fn;
    std::vector<std::uint32_t> fi;
    for (std::size_t t = 0; t < idx.size(); t += 3) {
      const glm::vec3 a = p[idx[t]], b = p[idx[t + 1]], c = p[idx[t + 2]];
      const glm::vec3 nn = glm::normalize(glm::cross(b - a, c - a));
      for (const glm::vec3& v : {a, b, c}) {
        fi.push_back(static_cast<std::uint32_t>(fp.size()));
        fp.push_back(v);
        fn.push_back(nn);
      }
    }
    add_mesh(scene, fp, fn, fi, material);
    return;
  }
  add_mesh(scene, p, n, idx, material);
}

// `count` random triangles in the unit cube with edge lengths up to `size`.
inline void add_random_soup(Scene& scene, int count, float size, std::uint32_t seed,
                            std::uint32_t material) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), e(-size, size);
  std::vector<glm::vec3> p, n;
  std::vector<std::uint32_t> idx;
  for (int i = 0; i < count; ++i) {
    const glm::vec3 a(u(rng), u(rng), u(rng));
    const glm::vec3 b = a + glm::vec3(e(rng), e(rng), e(rng));
    const glm::vec3 c = a + glm::vec3(e(rng), e(rng), e(rng));
    glm::vec3 nn = glm::cross(b - a, c - a);
    nn = glm::length(nn) > 0 ? glm::normalize(nn) : glm::vec3(0, 0, 1);
    for (const auto& v : {a, b, c}) {
      idx.push_back(static_cast<std::uint32_t>(p.size()));
      p.push_back(v);
      n.push_back(nn);
    }
  }
  add_mesh(scene, p, n, idx, material);
}

// A cube of half size h around `center`, turned by `angle` radians about the axis (1, 1, 0), flat
// faces outward.
inline void add_cube(Scene& scene, glm::vec3 center, float h, float angle, std::uint32_t material) {
  const glm::vec3 axis = glm::normalize(glm::vec3(1.0f, 1.0f, 0.0f));
  const auto turn = [&](glm::vec3 v) {  // Rodrigues' rotation
    const float c = std::cos(angle), s = std::sin(angle);
    return center + v * c + glm::cross(axis, v) * s + axis * glm::dot(axis, v) * (1.0f - c);
  };
  const glm::vec3 corner[8] = {{-h, -h, -h}, {h, -h, -h}, {h, h, -h}, {-h, h, -h},
                               {-h, -h, h},  {h, -h, h},  {h, h, h},  {-h, h, h}};
  const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                           {3, 7, 6, 2}, {0, 4, 7, 3}, {1, 2, 6, 5}};
  for (const auto& f : faces)
    add_quad(scene, turn(corner[f[0]]), turn(corner[f[1]]), turn(corner[f[2]]), turn(corner[f[3]]),
             material);
}

inline Material diffuse_material(glm::vec3 color, bool double_sided = true) {
  Material m;
  m.base_color = glm::vec4(color, 1.0f);
  m.metallic = 0.0f;
  m.roughness = 1.0f;
  m.double_sided = double_sided;
  return m;
}

// Smooth white glass: transmission 1, ior 1.5; with `volume` it bounds a volume (thickness 1, no
// absorption), else it is thin-walled.
inline Material glass_material(bool volume) {
  Material m;
  m.base_color = glm::vec4(1.0f);
  m.metallic = 0.0f;
  m.roughness = 0.0f;
  m.transmission = 1.0f;
  m.ior = 1.5f;
  m.thickness = volume ? 1.0f : 0.0f;
  return m;
}

inline void finish_bounds(Scene& scene) {
  scene.bounds_lo = glm::vec3(1e30f);
  scene.bounds_hi = glm::vec3(-1e30f);
  for (const auto& p : scene.positions) {
    scene.bounds_lo = glm::min(scene.bounds_lo, p);
    scene.bounds_hi = glm::max(scene.bounds_hi, p);
  }
}

// A perspective camera at `eye` looking at `target`.
inline Camera look_at(glm::vec3 eye, glm::vec3 target, float yfov, glm::vec3 up = {0, 1, 0}) {
  Camera c;
  c.position = eye;
  c.forward = glm::normalize(target - eye);
  c.up = glm::normalize(up - glm::dot(up, c.forward) * c.forward);
  c.yfov = yfov;
  return c;
}

}  // namespace wp::test
