// Internal to bvh/: the intermediate tree that Embree's generic builder (rtcBuildBVH) produces
// through our callbacks, before it is flattened into a device layout.
//
// The tree is N-ary (up to kMaxBranching children per inner node) so that the same build can feed
// layouts of different widths; build() in bvh_build.cpp asks for a binary one. All nodes live in
// memory owned by the RTCBVH inside EmbreeTree and die with it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include "bvh.h"

namespace wp::bvh::detail {

// Widest node Embree's generic builder makes (its MAX_BRANCHING_FACTOR).
constexpr unsigned kMaxBranching = 8;

struct Box {
  glm::vec3 lo, hi;
};

// Full surface area; the SAH only uses ratios of it.
inline float surface_area(const Box& b) {
  const glm::vec3 e = b.hi - b.lo;
  return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
}

struct TreeNode {
  bool is_leaf;
};

struct TreeInner : TreeNode {
  unsigned child_count;  // 2..kMaxBranching
  const TreeNode* children[kMaxBranching];
  Box bounds[kMaxBranching];  // bounds of each child's (possibly clipped) triangle references
};

struct TreeLeaf : TreeNode {
  unsigned count;              // 1..max_leaf_size
  const std::uint32_t* prims;  // `count` scene triangle indices
  Box bounds;                  // union of the references' (possibly clipped) boxes
};

// Owns the Embree device and BVH whose allocator holds the tree; `root` is valid while it lives.
struct EmbreeTree {
  struct Handles;
  std::unique_ptr<Handles> handles;
  const TreeNode* root = nullptr;
  Box scene_bounds{};  // bounds of all input triangles

  EmbreeTree();
  EmbreeTree(EmbreeTree&&) noexcept;
  ~EmbreeTree();
};

// Validates `input` and `options` (throws wp::Error naming the first problem) and runs Embree's
// builder with at most `branching` children per node. Leaves hold up to options.max_leaf_size
// references; with options.spatial_splits a triangle may be referenced by several leaves.
EmbreeTree build_embree_tree(const BuildInput& input, const BuildOptions& options,
                             unsigned branching);

// The spatial-split clipper: the part of triangle `v` inside `box` is cut by the plane
// x[dim] = pos, and `left`/`right` receive the bounds of the parts with x[dim] <= pos and
// x[dim] >= pos: exact in double, rounded outwards by an ulp or two to float (so they always
// contain the piece), then intersected with `box`.
// An empty part gets an empty box (lo = +inf, hi = -inf).
void split_triangle_bounds(const glm::vec3 v[3], const Box& box, unsigned dim, float pos, Box& left,
                           Box& right);

}  // namespace wp::bvh::detail
