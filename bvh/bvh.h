// The BVH: built on the host with Embree's generic builder (rtcBuildBVH), flattened into one of
// the two device layouts of kernels/shared/bvh_layout.h (binary for GPUs, 8-wide for CPU devices),
// plus a CPU reference traversal of each layout for tests.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "../kernels/shared/bvh_layout.h"

namespace wp::bvh {

// What the BVH library throws: bad build input or options, an Embree failure, a traversal past
// the stack. The library is below the host and knows nothing of its error type; main() prints any
// std::exception in the same one line.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct BuildOptions {
  // The layout: 2 (BvhNode + IsectTri) or 8 (BvhNode8 + TriBlock4); anything else is an error.
  int width = 2;
  // Embree's RTC_BUILD_QUALITY_HIGH with spatial splits (SBVH-like): triangles may then be
  // referenced by more than one leaf. Off: binned SAH (RTC_BUILD_QUALITY_MEDIUM), one reference
  // each.
  bool spatial_splits = false;
  // Width 2: 1..WP_BVH_MAX_LEAF_SIZE triangles; width 8: 1..4 * WP_BVH8_MAX_LEAF_BLOCKS.
  int max_leaf_size = WP_BVH_MAX_LEAF_SIZE;
  // SAH cost model (relative), in the unit of each layout's work: one node visit (binary or
  // 8-wide) vs one triangle test (width 2) or one 4-triangle block test (width 8); Embree's SAH
  // then counts a width-8 leaf as ceil(n / 4) blocks. Why 1 and 1 suit both: embree_tree.cpp.
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
  // SAH cost of the flattened tree, with A(x) the surface area of x's box (as stored in its
  // parent; the scene bounds for the root):
  //   sum over inner nodes n of traversal_cost * A(n) / A(root)
  //   + sum over leaves l of intersection_cost * work(l) * A(l) / A(root),
  // work(l) = its triangle count (width 2) or its block count ceil(count / 4) (width 8).
  double sah_cost = 0;
  std::size_t inner_nodes = 0;    // nodes in the layout
  std::size_t leaves = 0;         // leaf child references (width 8: ranges of blocks)
  std::size_t triangle_refs = 0;  // > triangle_count only with spatial splits (no unused lanes)
  int max_depth = 0;              // of inner nodes, root = depth 1
};

// One layout is filled, the other's arrays stay empty.
struct Bvh {
  int width = 2;
  std::vector<dev::BvhNode> nodes;       // width 2: depth-first, node 0 is the root
  std::vector<dev::IsectTri> triangles;  // width 2: reordered triangle references
  std::vector<dev::BvhNode8> nodes8;     // width 8: depth-first preorder, node 0 is the root
  std::vector<dev::TriBlock4> blocks;    // width 8: each leaf's triangles, 4 per block
  glm::vec3 lo{0.0f}, hi{0.0f};          // scene bounds
  BuildStats stats;
  // A two-level BVH (build_two_level) has instances; the arrays above then hold the top-level
  // tree and every mesh's tree (bvh_layout.h), and the top-level leaves reference instance_refs.
  std::vector<dev::BvhInstance> instances;
  std::vector<std::uint32_t> instance_refs;
};

// Builds the BVH. Throws bvh::Error on failure (e.g. bad options, Embree error). An input without
// triangles is valid: its BVH is a root alone whose children are all empty (binary: two leaves of
// count 0 with lo > hi boxes; wide: 8 unused slots), which every ray misses, with bounds at the
// origin.
Bvh build(const BuildInput& input, const BuildOptions& options = {});

// One placement of a mesh in a two-level BVH.
struct InstanceInput {
  glm::dmat4 to_world;     // affine, invertible: object space to world space
  std::uint32_t mesh = 0;  // index into build_two_level's meshes
};

// A two-level BVH: a top-level tree (built like the meshes' trees, one instance per leaf) over
// the instances' world-space boxes (each mesh's box through its transform), followed by the
// meshes' trees, merged into one Bvh of their layout (bvh_layout.h). meshes[i] is built over mesh
// i's triangles alone (its triangle indices from 0); first_triangle[i] is added to them, giving
// the scene's triangle indices. BvhInstance.meta.y is left WP_NO_LIGHT (the light table's to
// fill). The stats add up those of the trees (sah_cost and max_depth: the top-level tree's).
// Instances of a mesh without triangles are left out. Throws bvh::Error for a singular transform
// or references past the layout's index range.
Bvh build_two_level(std::vector<Bvh> meshes, const std::vector<std::uint32_t>& first_triangle,
                    const std::vector<InstanceInput>& instances, const BuildOptions& options);

// CPU reference traversal of the flattened layout (either width, by bvh.width), with the same
// arithmetic as the kernels: the specification they copy (arithmetic: traverse_common.h; order:
// bvh_traverse.cpp for width 2, bvh_traverse_wide.cpp for width 8).
// A two-level BVH's reference traverses every instance in index order (the kernels follow the
// top-level tree): the same closest t, the same instance and triangle unless two instances'
// hits tie.
struct Ray {
  glm::vec3 o;
  glm::vec3 d;
  float tmin = 0.0f;
  float tmax = 1e30f;  // may be +INFINITY
};
struct Hit {
  bool hit = false;
  float t = 0, u = 0, v = 0;                // barycentrics: p = (1-u-v) v0 + u v1 + v v2
  std::uint32_t triangle = 0;               // scene triangle index
  std::uint32_t instance = WP_NO_INSTANCE;  // two-level BVHs: the instance hit
};
// The ray in an instance's object space, in the kernels' arithmetic (traverse.h, object_ray):
// o' = to_object x o, d' = its 3x3 part x d, each row's products summed left to right, no fused
// multiply-add.
Ray object_ray(const dev::BvhInstance& instance, const Ray& ray);
Hit intersect_closest(const Bvh& bvh, const Ray& ray);
bool occluded(const Bvh& bvh, const Ray& ray);

// The traversal's triangle test (Moller-Trumbore, traverse_common.h) on one stored triangle alone:
// returns whether ray.tmin < t < tmax, and then fills `hit`. For tests that judge near-ties.
bool intersect_triangle(const dev::IsectTri& tri, const Ray& ray, float tmax, Hit& hit);

// Structural checks; returns an empty string when all hold, else a description of the first
// violation. Checked for both widths: every child box lies inside its parent's; no node is reached
// twice and every node is reached; depth-first order (width 2: a node's first inner child follows
// it; width 8: the exact preorder, children in slot order); inner-node depth <=
// WP_BVH_MAX_DEPTH / WP_BVH8_MAX_DEPTH; every scene triangle is referenced (exactly once unless
// `spatial_splits`); without spatial splits, each referenced triangle lies inside its leaf's box.
// Width 2: leaves of 1..WP_BVH_MAX_LEAF_SIZE triangles; empty children (count 0, lo > hi) only in
// the root: child 1 beside a leaf, or both. Width 8: used slots first, unused slots (child 0,
// boxes +INFINITY) last, at least 2 used except in the root (1, a leaf, or none); leaves of
// 1..WP_BVH8_MAX_LEAF_BLOCKS blocks that no two leaves share, with the unused lanes (all-zero
// vertices, prim 0xffffffff, flags 0) only at the end of a leaf's last block, which has at least
// one used lane.
std::string check_invariants(const Bvh& bvh, std::size_t triangle_count, bool spatial_splits);

}  // namespace wp::bvh
