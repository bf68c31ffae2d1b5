// Shared by the BVH tests (test_bvh.cpp: binary layout, test_bvh8.cpp: wide layout): test
// meshes, Embree's own intersector as an independent oracle, test rays and the comparison of two
// intersectors' answers that tells ties from mismatches.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <embree3/rtcore.h>

#include "bvh/embree_scene.h"
#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "tests/float_bits.h"

namespace wp::bvh::test {

constexpr float kInf = std::numeric_limits<float>::infinity();

using wp::test::as_float;
using wp::test::bits;

// ---------------------------------------------------------------------------------------------
// Meshes

struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> indices;
  std::vector<std::uint32_t> flags;  // per triangle, or empty for none

  std::size_t triangles() const { return indices.size() / 3; }
  void add(glm::vec3 a, glm::vec3 b, glm::vec3 c) {
    const auto base = static_cast<std::uint32_t>(positions.size());
    positions.insert(positions.end(), {a, b, c});
    indices.insert(indices.end(), {base, base + 1, base + 2});
  }
  BuildInput input() const {
    return BuildInput{positions.data(), indices.data(), triangles(),
                      flags.empty() ? nullptr : flags.data()};
  }
};

inline glm::vec3 random_in(std::mt19937& rng, float lo, float hi) {
  std::uniform_real_distribution<float> u(lo, hi);
  const float x = u(rng), y = u(rng), z = u(rng);
  return {x, y, z};
}

inline glm::vec3 random_direction(std::mt19937& rng) {
  std::normal_distribution<float> n;
  for (;;) {
    const float x = n(rng), y = n(rng), z = n(rng);
    const glm::vec3 d(x, y, z);
    if (glm::length(d) > 1e-3f) return glm::normalize(d);
  }
}

// Triangles with corners within `size` of a centre uniform in the unit cube.
inline Mesh soup(std::size_t n, unsigned seed, float size) {
  std::mt19937 rng(seed);
  Mesh m;
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3 c = random_in(rng, 0, 1);
    m.add(c + random_in(rng, -size, size), c + random_in(rng, -size, size),
          c + random_in(rng, -size, size));
  }
  return m;
}

// Long thin triangles (`width` across) along the cube's diagonals: what spatial splits are for.
inline Mesh long_diagonals(std::size_t n, unsigned seed, float width) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  Mesh m;
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3 sign(u(rng) < 0.5f ? -1 : 1, u(rng) < 0.5f ? -1 : 1, u(rng) < 0.5f ? -1 : 1);
    const glm::vec3 a = random_in(rng, 0, 1);
    const glm::vec3 b = a + (0.5f + 0.5f * u(rng)) * sign;
    m.add(a, b, b + random_in(rng, -width, width));
  }
  return m;
}

// A UV sphere of radius 1 with shared vertices (triangle fans at the poles, no degenerates).
inline Mesh sphere(int rings, int segments) {
  Mesh m;
  const float pi = 3.14159265f;
  m.positions.push_back({0, 0, 1});
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const float th = pi * float(r) / float(rings), ph = 2 * pi * float(s) / float(segments);
      m.positions.push_back(
          {std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)});
    }
  m.positions.push_back({0, 0, -1});
  const auto at = [&](int r, int s) {
    return std::uint32_t(1 + (r - 1) * segments + s % segments);
  };
  const auto south = std::uint32_t(m.positions.size() - 1);
  for (int s = 0; s < segments; ++s) {
    m.indices.insert(m.indices.end(), {0u, at(1, s), at(1, s + 1)});
    m.indices.insert(m.indices.end(), {south, at(rings - 1, s + 1), at(rings - 1, s)});
    for (int r = 1; r + 1 < rings; ++r) {
      m.indices.insert(m.indices.end(), {at(r, s), at(r + 1, s), at(r + 1, s + 1)});
      m.indices.insert(m.indices.end(), {at(r, s), at(r + 1, s + 1), at(r, s + 1)});
    }
  }
  return m;
}

// An n x n heightfield over [0,1]^2: many shared edges and vertices.
inline Mesh grid(int n) {
  Mesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const float x = float(i) / float(n), y = float(j) / float(n);
      m.positions.push_back({x, y, 0.1f * std::sin(6 * x) * std::cos(5 * y)});
    }
  const auto at = [&](int i, int j) { return std::uint32_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      m.indices.insert(m.indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.indices.insert(m.indices.end(), {at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return m;
}

// Zero-area triangles (points, segments, repeated ones) mixed into a small soup.
inline Mesh degenerate() {
  Mesh m = soup(60, 7, 0.1f);
  std::mt19937 rng(8);
  for (int i = 0; i < 40; ++i) {
    const glm::vec3 p = random_in(rng, 0, 1), q = random_in(rng, 0, 1);
    m.add(p, p, p);               // a point
    m.add(p, q, 0.5f * (p + q));  // a segment
    m.add(p, p + glm::vec3(0, 0, 1e-3f), p);
  }
  for (int i = 0; i < 30; ++i) m.add({2, 2, 2}, {2, 2, 2}, {2, 2, 2});  // all in one spot
  return m;
}

// Clusters of identical triangles at x = 2^-k: the SAH peels one cluster off per level, so the
// tree runs into Embree's depth limit and its object-median "large leaf" mode (embree_tree.cpp).
inline Mesh exponential_clusters(int clusters, int per_cluster) {
  Mesh m;
  for (int k = 0; k < clusters; ++k) {
    const float x = std::ldexp(1.0f, -k), s = std::ldexp(1.0f, -k - 2);
    for (int i = 0; i < per_cluster; ++i) m.add({x, 0, 0}, {x + s, 1, 0}, {x, 0, 1});
  }
  return m;
}

// The meshes every layout's invariants are checked on: tiny, large, smooth, regular, degenerate,
// long and thin, and deep (clusters at exponentially shrinking scales).
inline std::vector<std::pair<const char*, Mesh>> invariant_meshes() {
  return {{"1 triangle", soup(1, 1, 0.3f)},
          {"2 triangles", soup(2, 2, 0.3f)},
          {"7 triangles", soup(7, 3, 0.3f)},
          {"soup 1000", soup(1000, 4, 0.05f)},
          {"soup 200k", soup(200000, 5, 0.01f)},
          {"sphere", sphere(48, 96)},
          {"grid", grid(80)},
          {"degenerate", degenerate()},
          {"long diagonals", long_diagonals(3000, 6, 0.01f)},
          {"exponential clusters", exponential_clusters(100, 500)}};
}

inline float scene_size(const Bvh& bvh) {
  return glm::length(bvh.hi - bvh.lo);
}

// Each scene triangle as both layouts store it (vertices, flags; v0.w its index): what the
// comparison and the brute-force loops test.
inline std::vector<dev::IsectTri> stored_triangles(const Mesh& m) {
  std::vector<dev::IsectTri> out;
  for (std::size_t i = 0; i < m.triangles(); ++i) {
    const glm::vec3 v0 = m.positions[m.indices[3 * i]];
    const glm::vec3 v1 = m.positions[m.indices[3 * i + 1]];
    const glm::vec3 v2 = m.positions[m.indices[3 * i + 2]];
    const std::uint32_t flags = m.flags.empty() ? 0u : m.flags[i];
    out.push_back({{v0.x, v0.y, v0.z, as_float(std::uint32_t(i))},
                   {v1.x, v1.y, v1.z, as_float(flags)},
                   {v2.x, v2.y, v2.z, 0.0f}});
  }
  return out;
}

// Closest hit by testing every triangle of `tris` in order with the reference triangle test.
inline Hit brute_force(const std::vector<dev::IsectTri>& tris, const Ray& ray) {
  Hit hit;
  float tmax = ray.tmax;
  for (const dev::IsectTri& t : tris)
    if (intersect_triangle(t, ray, tmax, hit)) tmax = hit.t;
  return hit;
}

// ---------------------------------------------------------------------------------------------
// Intersectors

// Embree's own BVH and intersector over the same triangles: the independent oracle.
class EmbreeScene : public wp::bvh::EmbreeScene {
 public:
  explicit EmbreeScene(const Mesh& m)
      : wp::bvh::EmbreeScene(m.positions.data(), m.positions.size(), m.indices.data(),
                             m.triangles(), /*robust=*/true) {}
};

// Camera rays from outside the bounds through a jittered pixel grid, with tmax = +INFINITY as the
// renderer's, and rays from random points inside the bounds in random directions: every other
// one with a finite tmax, as shadow rays, the others with tmax 1e30 or +INFINITY (the case where
// the wide layout's unused slots are entered).
// An empty scene's BVH (either layout) misses every ray: from anywhere, in any direction, whatever
// its tmax, the axis-aligned positive ones with tmax = +INFINITY included (they enter the wide
// layout's unused slots, whose boxes lie at +INFINITY).
inline void expect_every_ray_misses(const Bvh& bvh) {
  std::mt19937 rng(7);
  std::vector<Ray> rays;
  for (int i = 0; i < 2000; ++i) {
    const float tmax = i % 3 == 0 ? kInf : i % 3 == 1 ? 1e30f : 5.0f;
    const glm::vec3 o = i % 2 ? glm::vec3(0.0f) : random_in(rng, -10.0f, 10.0f);
    rays.push_back({o, random_direction(rng), 0.0f, tmax});
  }
  for (const glm::vec3 d : {glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, 0, 1),
                            glm::normalize(glm::vec3(1, 1, 1))})
    for (const glm::vec3 o : {glm::vec3(-5.0f), glm::vec3(0.0f), glm::vec3(1e30f)})
      rays.push_back({o, d, 0.0f, kInf});
  for (const Ray& ray : rays) {
    EXPECT_FALSE(intersect_closest(bvh, ray).hit);
    EXPECT_FALSE(occluded(bvh, ray));
  }
}

inline std::vector<Ray> make_rays(const Bvh& bvh, std::size_t camera, std::size_t inside,
                                  unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  const glm::vec3 centre = 0.5f * (bvh.lo + bvh.hi);
  const float size = scene_size(bvh);
  const glm::vec3 eye = centre + size * glm::normalize(glm::vec3(0.4f, -0.7f, 0.6f));
  const glm::vec3 fwd = glm::normalize(centre - eye);
  const glm::vec3 right = glm::normalize(glm::cross(fwd, glm::vec3(0, 0, 1)));
  const glm::vec3 up = glm::cross(right, fwd);
  const auto side = static_cast<std::size_t>(std::sqrt(double(camera))) + 1;
  std::vector<Ray> rays;
  for (std::size_t i = 0; i < camera; ++i) {
    const float x = (float(i % side) + u(rng)) / float(side) - 0.5f;
    const float y = (float(i / side) + u(rng)) / float(side) - 0.5f;
    rays.push_back({eye, glm::normalize(fwd + 0.6f * (x * right + y * up)), 0.0f, kInf});
  }
  for (std::size_t i = 0; i < inside; ++i) {
    const glm::vec3 o = bvh.lo + glm::vec3(u(rng), u(rng), u(rng)) * (bvh.hi - bvh.lo);
    const float tmax = i % 2 ? u(rng) * size : i % 4 ? 1e30f : kInf;
    rays.push_back({o, random_direction(rng), 0.0f, tmax});
  }
  return rays;
}

inline float distance_to_segment(glm::vec3 p, glm::vec3 a, glm::vec3 b) {
  const glm::vec3 ab = b - a;
  const float len2 = glm::dot(ab, ab);
  const float s = len2 > 0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
  return glm::length(p - (a + s * ab));
}

// Compares the reference hit `ref` with another intersector's `other` for one ray. Equal
// triangles must agree on t (see t_tolerance). A different answer is accepted only as a tie, and
// counted: either the nearer hit lies within 1e-5 of the scene size of an edge of its triangle
// (a ray grazing an edge may or may not hit it), or both hit at the same t and one of them is that
// close to an edge or the other's triangle, tested alone with the reference test, gives that t.
class Comparison {
 public:
  Comparison(const Mesh& mesh, const Bvh& bvh)
      : tris_(stored_triangles(mesh)), size_(scene_size(bvh)), edge_eps_(1e-5f * size_) {}

  // Returns false on a tie, true on agreement; fails the test on a real mismatch.
  bool agree(const Ray& ray, const Hit& ref, const Hit& other) {
    ++rays_;
    if (!ref.hit && !other.hit) return true;
    if (ref.hit && other.hit && ref.triangle == other.triangle) {
      EXPECT_NEAR(ref.t, other.t, t_tolerance(ray, ref)) << describe(ray);
      return true;
    }
    // Either the nearer hit grazes an edge of its triangle (the other intersector may pass it by),
    // or both hit at the same t across a shared edge.
    const Hit& nearer = !other.hit || (ref.hit && ref.t <= other.t) ? ref : other;
    const bool shared_edge =
        ref.hit && other.hit && std::fabs(ref.t - other.t) <= t_tolerance(ray, ref) &&
        (near_edge(ray, ref) || near_edge(ray, other) || alone_agrees(ray, ref, other));
    const bool tie = near_edge(ray, nearer) || shared_edge;
    EXPECT_TRUE(tie) << "hit " << ref.hit << " tri " << ref.triangle << " t " << ref.t << " vs hit "
                     << other.hit << " tri " << other.triangle << " t " << other.t << "; "
                     << describe(ray);
    ++ties_;
    return false;
  }
  std::size_t rays() const { return rays_; }
  std::size_t ties() const { return ties_; }

 private:
  bool near_edge(const Ray& ray, const Hit& h) const {
    const dev::IsectTri& t = tris_[h.triangle];
    const glm::vec3 v0(t.v0.x, t.v0.y, t.v0.z);
    const glm::vec3 v1(t.v1.x, t.v1.y, t.v1.z);
    const glm::vec3 v2(t.v2.x, t.v2.y, t.v2.z);
    const glm::vec3 p = ray.o + h.t * ray.d;
    return std::min({distance_to_segment(p, v0, v1), distance_to_segment(p, v1, v2),
                     distance_to_segment(p, v2, v0)}) < edge_eps_;
  }
  // 1e-4 relative, plus the float precision of positions in the scene (1e-6 of its size) seen
  // along the ray: that dominates for hits close to the origin and at grazing angles.
  float t_tolerance(const Ray& ray, const Hit& h) const {
    const dev::IsectTri& t = tris_[h.triangle];
    const glm::vec3 v0(t.v0.x, t.v0.y, t.v0.z);
    const glm::vec3 n =
        glm::cross(glm::vec3(t.v1.x, t.v1.y, t.v1.z) - v0, glm::vec3(t.v2.x, t.v2.y, t.v2.z) - v0);
    const float cos = std::fabs(glm::dot(n, ray.d)) / (glm::length(n) * glm::length(ray.d));
    return 1e-4f * h.t + 1e-6f * size_ / std::max(cos, 1e-3f);
  }
  // Both hit, and the other's triangle tested alone with the reference test gives the same t.
  bool alone_agrees(const Ray& ray, const Hit& ref, const Hit& other) const {
    Hit alone;
    return ref.hit && other.hit && intersect_triangle(tris_[other.triangle], ray, 1e30f, alone) &&
           std::fabs(alone.t - ref.t) <= t_tolerance(ray, ref);
  }
  static std::string describe(const Ray& r) {
    char s[200];
    std::snprintf(s, sizeof s, "ray o (%.9g %.9g %.9g) d (%.9g %.9g %.9g) tmax %g", r.o.x, r.o.y,
                  r.o.z, r.d.x, r.d.y, r.d.z, r.tmax);
    return s;
  }

  std::vector<dev::IsectTri> tris_;  // by scene triangle index
  float size_, edge_eps_;
  std::size_t rays_ = 0, ties_ = 0;
};

// Reference closest hit and occlusion (built with `options`, either width) vs Embree; returns the
// number of rays.
inline std::size_t compare_with_embree(const Mesh& mesh, const BuildOptions& options,
                                       std::size_t camera, std::size_t inside, unsigned seed) {
  const Bvh bvh = build(mesh.input(), options);
  const EmbreeScene embree(mesh);
  Comparison cmp(mesh, bvh);
  std::size_t hits = 0;
  for (const Ray& ray : make_rays(bvh, camera, inside, seed)) {
    const Hit ref = intersect_closest(bvh, ray);
    const bool ref_occluded = occluded(bvh, ray);
    EXPECT_EQ(ref_occluded, ref.hit);  // same boxes, no tmax shrinking: exactly equal
    hits += ref.hit;
    if (cmp.agree(ray, ref, embree.intersect(ray))) {
      EXPECT_EQ(ref_occluded, embree.occluded(ray));
    }
  }
  std::printf("width %d: %zu rays, %zu hits, %zu ties\n", bvh.width, cmp.rays(), hits, cmp.ties());
  EXPECT_GT(hits, cmp.rays() / 10);
  EXPECT_LT(double(cmp.ties()), 1e-3 * double(cmp.rays()));
  return cmp.rays();
}

// The reference traversal of `bvh` (either width) against testing every stored triangle with the
// same triangle test: the same triangle gives the same t bit for bit, a different one is a tie
// (rare).
inline void expect_matches_brute_force(const Mesh& mesh, const Bvh& bvh, unsigned seed) {
  const std::vector<dev::IsectTri> all = stored_triangles(mesh);
  Comparison cmp(mesh, bvh);
  for (const Ray& ray : make_rays(bvh, 3000, 3000, seed)) {
    const Hit brute = brute_force(all, ray);
    const Hit ref = intersect_closest(bvh, ray);
    if (ref.hit && brute.hit && ref.triangle == brute.triangle) {
      EXPECT_EQ(ref.t, brute.t);
    }
    cmp.agree(ray, ref, brute);
  }
  EXPECT_LT(double(cmp.ties()), 1e-3 * double(cmp.rays()));
}

}  // namespace wp::bvh::test
