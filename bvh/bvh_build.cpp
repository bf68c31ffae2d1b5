// build(): Embree's binary tree (embree_tree.cpp) flattened into the device layout of
// kernels/shared/bvh_layout.h, with its statistics.
#include <algorithm>
#include <chrono>
#include <cstring>
#include <limits>
#include <string>

#include "build_tree.h"
#include "host/error.h"

namespace wp::bvh {
namespace {

using detail::Box;
using detail::TreeInner;
using detail::TreeLeaf;
using detail::TreeNode;

float uint_bits_as_float(std::uint32_t u) {
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}

// The empty child's box: lo > hi, as bvh_layout.h asks. Beware that the slab test, which takes
// min/max of the two slab distances per axis, does not reject an inverted box (it treats it like
// [-1e30, 1e30]^3); the child is harmless because its triangle count is 0.
const Box kEmptyChildBox{glm::vec3(1e30f), glm::vec3(-1e30f)};

void set_child(dev::BvhNode& node, int slot, const Box& b, std::int32_t link, std::int32_t count) {
  dev::float4& xy = slot == 0 ? node.c0_xy : node.c1_xy;
  xy = dev::float4{b.lo.x, b.hi.x, b.lo.y, b.hi.y};
  (slot == 0 ? node.c01_z.x : node.c01_z.z) = b.lo.z;
  (slot == 0 ? node.c01_z.y : node.c01_z.w) = b.hi.z;
  (slot == 0 ? node.link.x : node.link.y) = link;
  (slot == 0 ? node.link.z : node.link.w) = count;
}

// Depth-first preorder flattening of a binary tree, accumulating the SAH cost
//   sah = sum over inner nodes n of  traversal_cost * A(n) / A(root)
//       + sum over leaves l of       intersection_cost * count(l) * A(l) / A(root)
// where A is the surface area of a node's box (the box stored for it in its parent; the scene
// bounds for the root). A flat or point-like root (A(root) = 0) counts every ratio as 1.
class Flattener {
 public:
  Flattener(const BuildInput& input, const BuildOptions& options, const Box& root, Bvh& out)
      : input_(input), options_(options), out_(out) {
    const double a = detail::surface_area(root);
    inv_root_area_ = a > 0 ? 1.0 / a : 0.0;
  }

  // Flattens the subtree of inner node `n`, whose own box is `box`; returns its node index.
  std::int32_t inner(const TreeInner& n, const Box& box, int depth) {
    if (n.child_count != 2)
      throw Error("BVH build: expected a binary tree, got a node with " +
                  std::to_string(n.child_count) + " children");
    const auto index = static_cast<std::int32_t>(out_.nodes.size());
    out_.nodes.emplace_back();  // reserves the slot: preorder, children come after
    account_inner(box, depth);
    dev::BvhNode node{};
    for (int slot = 0; slot < 2; ++slot) {
      const TreeNode* child = n.children[slot];
      const Box& child_box = n.bounds[slot];
      if (child->is_leaf) {
        const auto& leaf = static_cast<const TreeLeaf&>(*child);
        set_child(node, slot, child_box, leaf_ref(leaf, child_box),
                  static_cast<std::int32_t>(leaf.count));
      } else {
        const std::int32_t c = inner(static_cast<const TreeInner&>(*child), child_box, depth + 1);
        set_child(node, slot, child_box, c, 0);
      }
    }
    out_.nodes[index] = node;
    return index;
  }

  // A scene that is one leaf: a root with that leaf as child 0 and an empty child 1.
  void single_leaf(const TreeLeaf& leaf, const Box& root_box) {
    account_inner(root_box, 1);
    dev::BvhNode root{};
    set_child(root, 0, leaf.bounds, leaf_ref(leaf, leaf.bounds),
              static_cast<std::int32_t>(leaf.count));
    set_child(root, 1, kEmptyChildBox, ~0, 0);
    out_.nodes.push_back(root);
  }

 private:
  void account_inner(const Box& box, int depth) {
    stats().inner_nodes++;
    stats().max_depth = std::max(stats().max_depth, depth);
    stats().sah_cost += double(options_.traversal_cost) * area_ratio(box);
  }

  // Appends the leaf's triangles; returns its child reference ~first.
  std::int32_t leaf_ref(const TreeLeaf& leaf, const Box& box) {
    const std::size_t first = out_.triangles.size();
    if (first + leaf.count > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
      throw Error("BVH build: too many triangle references for the device layout");
    for (unsigned i = 0; i < leaf.count; ++i) out_.triangles.push_back(isect_tri(leaf.prims[i]));
    stats().leaves++;
    stats().triangle_refs += leaf.count;
    stats().sah_cost += double(options_.intersection_cost) * leaf.count * area_ratio(box);
    return ~static_cast<std::int32_t>(first);
  }

  dev::IsectTri isect_tri(std::uint32_t index) const {
    const std::uint32_t* idx = input_.indices + 3 * static_cast<std::size_t>(index);
    const glm::vec3 v0 = input_.positions[idx[0]];
    const glm::vec3 e1 = input_.positions[idx[1]] - v0;
    const glm::vec3 e2 = input_.positions[idx[2]] - v0;
    const std::uint32_t flags = input_.triangle_flags ? input_.triangle_flags[index] : 0u;
    return dev::IsectTri{dev::float4{v0.x, v0.y, v0.z, uint_bits_as_float(index)},
                         dev::float4{e1.x, e1.y, e1.z, uint_bits_as_float(flags)},
                         dev::float4{e2.x, e2.y, e2.z, 0.0f}};
  }

  double area_ratio(const Box& b) const {
    return inv_root_area_ > 0 ? detail::surface_area(b) * inv_root_area_ : 1.0;
  }
  BuildStats& stats() { return out_.stats; }

  const BuildInput& input_;
  const BuildOptions& options_;
  Bvh& out_;
  double inv_root_area_ = 0;
};

}  // namespace

Bvh build(const BuildInput& input, const BuildOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const detail::EmbreeTree tree = detail::build_embree_tree(input, options, 2);

  Bvh out;
  out.lo = tree.scene_bounds.lo;
  out.hi = tree.scene_bounds.hi;
  out.triangles.reserve(input.triangle_count);
  Flattener flattener(input, options, tree.scene_bounds, out);
  if (tree.root->is_leaf)
    flattener.single_leaf(static_cast<const TreeLeaf&>(*tree.root), tree.scene_bounds);
  else
    flattener.inner(static_cast<const TreeInner&>(*tree.root), tree.scene_bounds, 1);

  out.stats.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace wp::bvh
