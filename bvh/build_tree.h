// Internal to bvh/: the intermediate tree that Embree's generic builder (rtcBuildBVH) produces
// through our callbacks, before it is flattened into a device layout.
//
// The tree is N-ary (up to kMaxBranching children per inner node) so that the same build feeds
// both layouts: build() in bvh_build.cpp asks Embree for options.width children per node and
// hands the tree to flatten_binary (bvh_build.cpp) or flatten_wide (bvh_flatten_wide.cpp). All
// nodes live in memory owned by the RTCBVH inside EmbreeTree and die with it.
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

// What both layouts store of scene triangle `index`: its vertices, unchanged, and its WP_TRI_*
// flags (0 without BuildInput::triangle_flags).
struct StoredTriangle {
  glm::vec3 v0, v1, v2;
  std::uint32_t flags;
};
inline StoredTriangle stored_triangle(const BuildInput& input, std::uint32_t index) {
  const std::uint32_t* idx = input.indices + 3 * static_cast<std::size_t>(index);
  return StoredTriangle{input.positions[idx[0]], input.positions[idx[1]], input.positions[idx[2]],
                        input.triangle_flags ? input.triangle_flags[index] : 0u};
}

// The surface-area ratio A(b) / A(root) of BuildStats::sah_cost; a flat or point-like root
// (A(root) = 0) counts every ratio as 1.
class AreaRatio {
 public:
  explicit AreaRatio(const Box& root) {
    const double a = surface_area(root);
    inv_root_ = a > 0 ? 1.0 / a : 0.0;
  }
  double operator()(const Box& b) const {
    return inv_root_ > 0 ? surface_area(b) * inv_root_ : 1.0;
  }

 private:
  double inv_root_ = 0;
};

struct TreeNode {
  bool is_leaf;
};

struct TreeInner : TreeNode {
  unsigned child_count;  // 2..kMaxBranching
  const TreeNode* children[kMaxBranching];
  Box bounds[kMaxBranching];  // bounds of each child's (possibly clipped) triangle references
};

struct TreeLeaf : TreeNode {
  unsigned count;              // 1..max_leaf_size (Embree 3.13 keeps to it: embree_tree.cpp)
  const std::uint32_t* prims;  // `count` scene triangle indices
  Box bounds;                  // union of the references' (possibly clipped) boxes
};

// Owns the Embree device and BVH whose allocator holds the tree; `root` is valid while it lives.
struct EmbreeTree {
  struct Handles;
  std::unique_ptr<Handles> handles;
  const TreeNode* root = nullptr;  // null for an input without triangles
  Box scene_bounds{};              // bounds of all input triangles; without any, the origin

  EmbreeTree();
  EmbreeTree(EmbreeTree&&) noexcept;
  ~EmbreeTree();
};

// Validates `input` and `options` (throws bvh::Error naming the first problem) and runs Embree's
// builder with at most options.width children per node. Leaves hold up to options.max_leaf_size
// references; with options.spatial_splits a triangle may be referenced by several leaves. An input
// without triangles (a valid glTF scene may have none) is not given to Embree: the tree has no
// root.
EmbreeTree build_embree_tree(const BuildInput& input, const BuildOptions& options);

// The flatteners: fill out.nodes/triangles (binary; the tree must be binary) or out.nodes8/blocks
// (8-wide; any tree with 2..8 children per node, leaves of any size) and out.stats except
// build_seconds. `scene` is the root's box; out.lo/hi and out.width are the caller's.
void flatten_binary(const TreeNode& root, const Box& scene, const BuildInput& input,
                    const BuildOptions& options, Bvh& out);
void flatten_wide(const TreeNode& root, const Box& scene, const BuildInput& input,
                  const BuildOptions& options, Bvh& out);
// The layouts of a tree without a root (no triangles): a root node alone, every child of it empty
// (binary: both children, count 0 and lo > hi, like the single-leaf root's child 1; wide: all 8
// slots unused), so that every ray misses. `scene` is the root's box.
void flatten_empty_binary(const Box& scene, const BuildOptions& options, Bvh& out);
void flatten_empty_wide(const Box& scene, const BuildOptions& options, Bvh& out);

// The spatial-split clipper: the part of triangle `v` inside `box` is cut by the plane
// x[dim] = pos, and `left`/`right` receive the bounds of the parts with x[dim] <= pos and
// x[dim] >= pos: exact in double, rounded outwards by an ulp or two to float (so they always
// contain the piece), then intersected with `box`.
// An empty part gets an empty box (lo = +inf, hi = -inf).
void split_triangle_bounds(const glm::vec3 v[3], const Box& box, unsigned dim, float pos, Box& left,
                           Box& right);

}  // namespace wp::bvh::detail
