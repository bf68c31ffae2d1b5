// build(): Embree's tree (embree_tree.cpp) flattened into the device layout of
// kernels/shared/bvh_layout.h for options.width, with its statistics; the binary flattener.
#include <algorithm>
#include <chrono>
#include <cstring>
#include <limits>
#include <string>

#include "build_tree.h"

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
// [-1e30, 1e30]^3); the child is harmless because its triangle count is 0 (its reference ~0 is
// never followed into the triangle array, which may be empty).
const Box kEmptyChildBox{glm::vec3(1e30f), glm::vec3(-1e30f)};

void set_child(dev::BvhNode& node, int slot, const Box& b, std::int32_t link, std::int32_t count) {
  dev::float4& xy = slot == 0 ? node.c0_xy : node.c1_xy;
  xy = dev::float4{b.lo.x, b.hi.x, b.lo.y, b.hi.y};
  (slot == 0 ? node.c01_z.x : node.c01_z.z) = b.lo.z;
  (slot == 0 ? node.c01_z.y : node.c01_z.w) = b.hi.z;
  (slot == 0 ? node.link.x : node.link.y) = link;
  (slot == 0 ? node.link.z : node.link.w) = count;
}

// Depth-first preorder flattening of a binary tree, accumulating the SAH cost of
// BuildStats::sah_cost (work(l) = the leaf's triangle count).
class Flattener {
 public:
  Flattener(const BuildInput& input, const BuildOptions& options, const Box& root, Bvh& out)
      : input_(input), options_(options), out_(out), area_ratio_(root) {}

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

  // A scene without triangles: a root whose two children are both empty.
  void empty_root(const Box& root_box) {
    account_inner(root_box, 1);
    dev::BvhNode root{};
    set_child(root, 0, kEmptyChildBox, ~0, 0);
    set_child(root, 1, kEmptyChildBox, ~0, 0);
    out_.nodes.push_back(root);
  }

 private:
  void account_inner(const Box& box, int depth) {
    stats().inner_nodes++;
    stats().max_depth = std::max(stats().max_depth, depth);
    stats().sah_cost += double(options_.traversal_cost) * area_ratio_(box);
  }

  // Appends the leaf's triangles; returns its child reference ~first.
  std::int32_t leaf_ref(const TreeLeaf& leaf, const Box& box) {
    const std::size_t first = out_.triangles.size();
    if (first + leaf.count > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
      throw Error("BVH build: too many triangle references for the device layout");
    for (unsigned i = 0; i < leaf.count; ++i) out_.triangles.push_back(isect_tri(leaf.prims[i]));
    stats().leaves++;
    stats().triangle_refs += leaf.count;
    stats().sah_cost += double(options_.intersection_cost) * leaf.count * area_ratio_(box);
    return ~static_cast<std::int32_t>(first);
  }

  dev::IsectTri isect_tri(std::uint32_t index) const {
    const detail::StoredTriangle t = detail::stored_triangle(input_, index);
    return dev::IsectTri{dev::float4{t.v0.x, t.v0.y, t.v0.z, uint_bits_as_float(index)},
                         dev::float4{t.v1.x, t.v1.y, t.v1.z, uint_bits_as_float(t.flags)},
                         dev::float4{t.v2.x, t.v2.y, t.v2.z, 0.0f}};
  }

  BuildStats& stats() { return out_.stats; }

  const BuildInput& input_;
  const BuildOptions& options_;
  Bvh& out_;
  const detail::AreaRatio area_ratio_;
};

}  // namespace

namespace detail {

void flatten_binary(const TreeNode& root, const Box& scene, const BuildInput& input,
                    const BuildOptions& options, Bvh& out) {
  out.triangles.reserve(input.triangle_count);
  Flattener flattener(input, options, scene, out);
  if (root.is_leaf)
    flattener.single_leaf(static_cast<const TreeLeaf&>(root), scene);
  else
    flattener.inner(static_cast<const TreeInner&>(root), scene, 1);
}

void flatten_empty_binary(const Box& scene, const BuildOptions& options, Bvh& out) {
  const BuildInput none;
  Flattener(none, options, scene, out).empty_root(scene);
}

}  // namespace detail

Bvh build(const BuildInput& input, const BuildOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const detail::EmbreeTree tree = detail::build_embree_tree(input, options);

  Bvh out;
  out.width = options.width;
  out.lo = tree.scene_bounds.lo;
  out.hi = tree.scene_bounds.hi;
  const bool wide = options.width == WP_BVH8_WIDTH;
  if (!tree.root && wide)
    detail::flatten_empty_wide(tree.scene_bounds, options, out);
  else if (!tree.root)
    detail::flatten_empty_binary(tree.scene_bounds, options, out);
  else if (wide)
    detail::flatten_wide(*tree.root, tree.scene_bounds, input, options, out);
  else
    detail::flatten_binary(*tree.root, tree.scene_bounds, input, options, out);

  out.stats.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace wp::bvh
