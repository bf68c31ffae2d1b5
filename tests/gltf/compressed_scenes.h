// Compressed twins of the shared models as loaded scenes, for the tests that compare them with
// their originals (tests/gltf/test_gltf_compressed.cpp, tests/test_compressed_render.cpp).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include "host/scene/gltf_loader.h"
#include "host/scene/gltf_nodes.h"
#include "host/scene/scene.h"
#include "tests/gltf/compress_twin.h"
#include "tests/gltf/gltf_files.h"
#include "tests/test_assets.h"

namespace wp::test::compressed {

namespace fs = std::filesystem;

// Writes `glb` as NAME in the loader tests' temporary folder (gltf_files.h); returns its path.
inline std::string write_twin(const Glb& glb, const std::string& name) {
  const std::string path = (gltf_files::temp_dir() / name).string();
  write_file(path, glb_bytes(glb));
  return path;
}

// One triangle's corners as the scene has them (world space).
struct Corner {
  glm::vec3 p, n;
  glm::vec2 uv;
};
using Triangle = std::array<Corner, 3>;

inline std::vector<Triangle> triangles(const Scene& s) {
  std::vector<Triangle> out(s.triangle_count());
  for (std::size_t t = 0; t < out.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = s.indices[3 * t + std::size_t(k)];
      // (0, 0) where the scene keeps no TEXCOORD_0 (scene.h)
      out[t][std::size_t(k)] = {s.positions[v], s.normals[v],
                                v < s.uv0.size() ? s.uv0[v] : glm::vec2(0.0f)};
    }
  return out;
}

// How far two corners may be apart: positions (Euclidean, world units), unit normals (Euclidean),
// texture coordinates (per component).
struct Tolerance {
  double position = 0, normal = 0, uv = 0;
};

inline bool close(const Corner& a, const Corner& b, const Tolerance& tol) {
  return glm::length(glm::dvec3(a.p) - glm::dvec3(b.p)) <= tol.position &&
         glm::length(glm::dvec3(a.n) - glm::dvec3(b.n)) <= tol.normal &&
         std::abs(double(a.uv.x) - double(b.uv.x)) <= tol.uv &&
         std::abs(double(a.uv.y) - double(b.uv.y)) <= tol.uv;
}

// Whether triangle b is triangle a within `tol`, its corners possibly rotated (a codec may start a
// triangle at another corner; the winding, and so the facing, must stay).
inline bool same_triangle(const Triangle& a, const Triangle& b, const Tolerance& tol) {
  for (int r = 0; r < 3; ++r)
    if (close(a[0], b[std::size_t(r)], tol) && close(a[1], b[std::size_t((r + 1) % 3)], tol) &&
        close(a[2], b[std::size_t((r + 2) % 3)], tol))
      return true;
  return false;
}

// Every triangle of `a` matched to its own triangle of `b` within `tol` (in any order): the count
// of those without a match, and as many as both have when the counts differ.
inline std::size_t unmatched(const Scene& a, const Scene& b, const Tolerance& tol) {
  std::vector<Triangle> ta = triangles(a), tb = triangles(b);
  if (ta.size() != tb.size()) return std::max(ta.size(), tb.size());
  const auto key = [](const Triangle& t) { return double(t[0].p.x + t[1].p.x + t[2].p.x) / 3; };
  std::sort(tb.begin(), tb.end(),
            [&](const Triangle& x, const Triangle& y) { return key(x) < key(y); });
  std::vector<double> keys(tb.size());
  for (std::size_t i = 0; i < tb.size(); ++i) keys[i] = key(tb[i]);
  std::vector<bool> used(tb.size(), false);
  std::size_t missing = 0;
  for (const Triangle& t : ta) {
    const double k = key(t);  // the centroid's x moves by at most the position tolerance
    std::size_t i = std::size_t(
        std::lower_bound(keys.begin(), keys.end(), k - tol.position - 1e-6) - keys.begin());
    bool found = false;
    for (; i < tb.size() && keys[i] <= k + tol.position + 1e-6 && !found; ++i)
      if (!used[i] && same_triangle(t, tb[i], tol)) used[i] = found = true;
    missing += !found;
  }
  return missing;
}

// The largest Frobenius norm of the 3x3 part of any node placing a mesh in the default scene:
// a local-space error vector e becomes at most |e| times it in world space.
inline double placement_norm(const std::string& path) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  if (!loader.LoadBinaryFromFile(&model, &err, &warn, path)) return NAN;
  double norm = 0.0;
  struct Item {
    int node;
    glm::dmat4 parent;
  };
  std::vector<Item> stack;
  for (const int n : model.scenes[std::size_t(std::max(model.defaultScene, 0))].nodes)
    stack.push_back({n, glm::dmat4(1.0)});
  while (!stack.empty()) {
    const Item item = stack.back();
    stack.pop_back();
    const tinygltf::Node& node = model.nodes[std::size_t(item.node)];
    const glm::dmat4 world = item.parent * gltf::local_transform(node, item.node);
    if (node.mesh >= 0) {
      const glm::dmat3 m(world);
      double f = 0.0;
      for (int c = 0; c < 3; ++c) f += glm::dot(m[c], m[c]);
      norm = std::max(norm, std::sqrt(f));
    }
    for (const int child : node.children) stack.push_back({child, world});
  }
  return norm;
}

// The models the twins are made of (those present under ../shared/assets/models).
inline std::vector<std::string> twin_models() {
  std::vector<std::string> out;
  for (const char* m : {"Box/Box.glb", "BoxTextured/BoxTextured.glb", "Duck/Duck.glb",
                        "DamagedHelmet/DamagedHelmet.glb"})
    if (!model_path(m).empty()) out.push_back(model_path(m));
  return out;
}

}  // namespace wp::test::compressed
