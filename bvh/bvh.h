// The BVH: built on the host with Embree's generic builder (rtcBuildBVH), flattened into the
// device layout of kernels/shared/bvh_layout.h, plus a CPU reference traversal of that very
// layout for tests.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "../kernels/shared/bvh_layout.h"

namespace wp::bvh {

struct BuildOptions {
  // Embree's RTC_BUILD_QUALITY_HIGH with spatial splits (SBVH-like): triangles may then be
  // referenced by more than one leaf. Off: binned SAH (RTC_BUILD_QUALITY_MEDIUM), one reference
  // each.
  bool spatial_splits = false;
  int max_leaf_size = WP_BVH_MAX_LEAF_SIZE;  // 1..WP_BVH_MAX_LEAF_SIZE
  // SAH cost model (relative): one node visit vs one triangle test.
  float traversal_cost = 1.0f;
  float intersection_cost = 1.0f;
};

// Triangles to build over: world-space positions and per-triangle vertex indices.
struct BuildInput {
  const glm::vec3* positions = nullptr;
  const std::uint32_t* indices = nullptr;  // 3 per triangle
  std::size_t triangle_count = 0;
  const std::uint32_t* triangle_flags = nullptr;  // WP_TRI_* per triangle, or null for none
};

struct BuildStats {
  double build_seconds = 0;  // rtcBuildBVH plus flattening, wall clock
  double sah_cost = 0;       // SAH cost of the flattened tree, relative to the root's surface area
  std::size_t inner_nodes = 0;
  std::size_t leaves = 0;
  std::size_t triangle_refs = 0;  // > triangle_count only with spatial splits
  int max_depth = 0;              // root = depth 1
};

struct Bvh {
  std::vector<dev::BvhNode> nodes;       // depth-first, node 0 is the root
  std::vector<dev::IsectTri> triangles;  // reordered triangle references
  glm::vec3 lo{0.0f}, hi{0.0f};          // scene bounds
  BuildStats stats;
};

// Builds the BVH. Throws wp::Error on failure (e.g. no triangles, Embree error).
Bvh build(const BuildInput& input, const BuildOptions& options = {});

// CPU reference traversal of the flattened layout, with the same triangle test as the kernels.
struct Ray {
  glm::vec3 o;
  glm::vec3 d;
  float tmin = 0.0f;
  float tmax = 1e30f;
};
struct Hit {
  bool hit = false;
  float t = 0, u = 0, v = 0;   // barycentrics: p = (1-u-v) v0 + u v1 + v v2
  std::uint32_t triangle = 0;  // scene triangle index
};
Hit intersect_closest(const Bvh& bvh, const Ray& ray);
bool occluded(const Bvh& bvh, const Ray& ray);

// The traversal's triangle test (Moller-Trumbore, bvh_traverse.cpp) on one stored triangle alone:
// returns whether ray.tmin < t < tmax, and then fills `hit`. For tests that judge near-ties.
bool intersect_triangle(const dev::IsectTri& tri, const Ray& ray, float tmax, Hit& hit);

// Structural checks; returns an empty string when all hold, else a description of the first
// violation. Checked: every child box lies inside its parent's; leaves are within
// WP_BVH_MAX_LEAF_SIZE; depth <= WP_BVH_MAX_DEPTH; every scene triangle is referenced (exactly
// once unless `spatial_splits`); without spatial splits, each referenced triangle lies inside its
// leaf's box.
std::string check_invariants(const Bvh& bvh, std::size_t triangle_count, bool spatial_splits);

}  // namespace wp::bvh
