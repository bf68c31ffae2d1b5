// flatten_wide(): Embree's 8-ary tree (embree_tree.cpp) flattened into the wide layout of
// kernels/shared/bvh_layout.h (BvhNode8 + TriBlock4), with its statistics.
//
// Nodes are written in depth-first preorder (a node, then the subtrees of its children in slot
// order), node 0 the root; a node's children keep Embree's order, unused slots last. A leaf's
// triangles are packed into ceil(n / 4) consecutive blocks, appended when the leaf is met in that
// same order; the unused lanes of its last block hold zero vertices, prim 0xffffffff and flags
// 0.
#include <algorithm>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "build_tree.h"

namespace wp::bvh::detail {
namespace {

constexpr unsigned kMaxLeafRefs = 4 * WP_BVH8_MAX_LEAF_BLOCKS;
// child.s[i] = ~((first_block << 2) | (blocks - 1)) must be a negative int32.
constexpr std::size_t kMaxBlocks = std::size_t(1) << 29;
constexpr float kInf = std::numeric_limits<float>::infinity();

void set_lane(dev::float4& v, unsigned lane, float f) {
  (lane == 0 ? v.x : lane == 1 ? v.y : lane == 2 ? v.z : v.w) = f;
}
void set_lane(dev::uint4& v, unsigned lane, std::uint32_t u) {
  (lane == 0 ? v.x : lane == 1 ? v.y : lane == 2 ? v.z : v.w) = u;
}

void set_child(dev::BvhNode8& node, unsigned slot, const Box& b, std::int32_t child) {
  node.lo_x.s[slot] = b.lo.x, node.hi_x.s[slot] = b.hi.x;
  node.lo_y.s[slot] = b.lo.y, node.hi_y.s[slot] = b.hi.y;
  node.lo_z.s[slot] = b.lo.z, node.hi_z.s[slot] = b.hi.z;
  node.child.s[slot] = child;
}

// A node with every slot unused: child 0, box lo = hi = +INFINITY (bvh_layout.h).
dev::BvhNode8 empty_node() {
  dev::BvhNode8 node{};
  for (unsigned slot = 0; slot < WP_BVH8_WIDTH; ++slot)
    set_child(node, slot, Box{glm::vec3(kInf), glm::vec3(kInf)}, 0);
  return node;
}

// An all-unused block: zero vertex and edges, prim 0xffffffff, flags 0.
dev::TriBlock4 empty_block() {
  dev::TriBlock4 b{};
  b.prim = dev::uint4{~0u, ~0u, ~0u, ~0u};
  return b;
}

class WideFlattener {
 public:
  WideFlattener(const BuildInput& input, const BuildOptions& options, const Box& root, Bvh& out)
      : input_(input), options_(options), out_(out), area_ratio_(root) {}

  // Flattens the subtree of inner node `n`, whose own box is `box`; returns its node index.
  std::int32_t inner(const TreeInner& n, const Box& box, int depth) {
    if (n.child_count < 2 || n.child_count > WP_BVH8_WIDTH)
      throw Error("BVH build: expected 2 to 8 children per node, got " +
                  std::to_string(n.child_count));
    if (depth > WP_BVH8_MAX_DEPTH)
      throw Error("BVH build: the wide tree is deeper than WP_BVH8_MAX_DEPTH");
    const auto index = static_cast<std::int32_t>(out_.nodes8.size());
    out_.nodes8.emplace_back();  // reserves the slot: preorder, children come after
    account_inner(box, depth);
    dev::BvhNode8 node = empty_node();
    for (unsigned slot = 0; slot < n.child_count; ++slot)
      set_child(node, slot, n.bounds[slot], child_ref(*n.children[slot], n.bounds[slot], depth));
    out_.nodes8[static_cast<std::size_t>(index)] = node;
    return index;
  }

  // A scene that is one leaf: a root (box `scene`) with that leaf in slot 0 and the other slots
  // unused.
  void single_leaf(const TreeLeaf& leaf, const Box& scene) {
    if (leaf.count > kMaxLeafRefs) {
      inner(split_leaf(leaf, leaf.bounds), scene, 1);
      return;
    }
    account_inner(scene, 1);
    dev::BvhNode8 root = empty_node();
    set_child(root, 0, leaf.bounds, leaf_ref(leaf, leaf.bounds));
    out_.nodes8.push_back(root);
  }

  // A scene without triangles: a root (box `scene`) with every slot unused.
  void empty_root(const Box& scene) {
    account_inner(scene, 1);
    out_.nodes8.push_back(empty_node());
  }

 private:
  // The reference to a child of a node at `depth`: a leaf's block range, or its node index.
  std::int32_t child_ref(const TreeNode& child, const Box& box, int depth) {
    if (!child.is_leaf) return inner(static_cast<const TreeInner&>(child), box, depth + 1);
    const auto& leaf = static_cast<const TreeLeaf&>(child);
    if (leaf.count <= kMaxLeafRefs) return leaf_ref(leaf, box);
    return inner(split_leaf(leaf, box), box, depth + 1);
  }

  // A leaf too large for WP_BVH8_MAX_LEAF_BLOCKS blocks becomes an inner node over up to 8 equal
  // runs of its references (recursively, through inner()), each boxed by its triangles' bounds
  // clipped to the leaf's box (a spatial-split reference may be a piece of its triangle). Embree
  // 3.13 never makes such leaves (embree_tree.cpp): this keeps any tree valid, not fast.
  const TreeInner& split_leaf(const TreeLeaf& leaf, const Box& box) {
    const unsigned parts =
        std::min<unsigned>(WP_BVH8_WIDTH, (leaf.count + kMaxLeafRefs - 1) / kMaxLeafRefs);
    pieces_.emplace_back(std::make_unique<Piece>());
    Piece& p = *pieces_.back();
    p.node.is_leaf = false;
    p.node.child_count = parts;
    for (unsigned i = 0; i < parts; ++i) {
      const unsigned begin = leaf.count * i / parts, end = leaf.count * (i + 1) / parts;
      TreeLeaf& l = p.leaves[i];
      l.is_leaf = true;
      l.count = end - begin;
      l.prims = leaf.prims + begin;
      l.bounds = clipped_bounds(l, box);
      p.node.children[i] = &l;
      p.node.bounds[i] = l.bounds;
    }
    return p.node;
  }

  Box clipped_bounds(const TreeLeaf& leaf, const Box& clip) const {
    Box b{glm::vec3(kInf), glm::vec3(-kInf)};
    for (unsigned i = 0; i < leaf.count; ++i) {
      const StoredTriangle t = stored_triangle(input_, leaf.prims[i]);
      b.lo = glm::min(b.lo, glm::min(t.v0, glm::min(t.v1, t.v2)));
      b.hi = glm::max(b.hi, glm::max(t.v0, glm::max(t.v1, t.v2)));
    }
    b.lo = glm::max(b.lo, clip.lo);
    b.hi = glm::min(b.hi, clip.hi);
    // Clipped pieces are rounded outwards, which may leave an axis empty by an ulp: fall back to
    // the clip box there.
    for (int k = 0; k < 3; ++k)
      if (!(b.lo[k] <= b.hi[k])) b.lo[k] = clip.lo[k], b.hi[k] = clip.hi[k];
    return b;
  }

  void account_inner(const Box& box, int depth) {
    stats().inner_nodes++;
    stats().max_depth = std::max(stats().max_depth, depth);
    stats().sah_cost += double(options_.traversal_cost) * area_ratio_(box);
  }

  // Appends the leaf's blocks; returns its child reference.
  std::int32_t leaf_ref(const TreeLeaf& leaf, const Box& box) {
    const std::size_t first = out_.blocks.size();
    const unsigned blocks = (leaf.count + 3) / 4;
    if (first + blocks > kMaxBlocks)
      throw Error("BVH build: too many triangle blocks for the wide layout");
    for (unsigned b = 0; b < blocks; ++b) out_.blocks.push_back(empty_block());
    for (unsigned i = 0; i < leaf.count; ++i)
      set_triangle(out_.blocks[first + i / 4], i % 4, leaf.prims[i]);
    stats().leaves++;
    stats().triangle_refs += leaf.count;
    stats().sah_cost += double(options_.intersection_cost) * blocks * area_ratio_(box);
    return ~static_cast<std::int32_t>((first << 2) | (blocks - 1));
  }

  void set_triangle(dev::TriBlock4& b, unsigned lane, std::uint32_t index) const {
    const StoredTriangle t = stored_triangle(input_, index);
    for (int k = 0; k < 3; ++k) {
      set_lane(b.v0[k], lane, t.v0[k]);
      set_lane(b.v1[k], lane, t.v1[k]);
      set_lane(b.v2[k], lane, t.v2[k]);
    }
    set_lane(b.prim, lane, index);
    set_lane(b.flags, lane, t.flags);
  }

  BuildStats& stats() { return out_.stats; }

  // The nodes split_leaf() makes; they must outlive the flattening of their subtree.
  struct Piece {
    TreeInner node{};
    TreeLeaf leaves[WP_BVH8_WIDTH]{};
  };

  const BuildInput& input_;
  const BuildOptions& options_;
  Bvh& out_;
  const AreaRatio area_ratio_;
  std::vector<std::unique_ptr<Piece>> pieces_;
};

}  // namespace

namespace {

// The blocks and inner nodes flatten_wide makes of `root`'s tree (a leaf split by split_leaf
// counts as its parts), so that each array is allocated once, at its size: the blocks are most of
// a large scene's BVH, and a vector that doubles holds both copies while it moves.
std::pair<std::size_t, std::size_t> count_wide(const TreeNode& root) {
  std::size_t blocks = 0, nodes = 0;
  std::vector<const TreeNode*> stack = {&root};
  while (!stack.empty()) {
    const TreeNode* n = stack.back();
    stack.pop_back();
    if (n->is_leaf) {
      const unsigned count = static_cast<const TreeLeaf*>(n)->count;
      if (count > kMaxLeafRefs) {
        const unsigned parts =
            std::min<unsigned>(WP_BVH8_WIDTH, (count + kMaxLeafRefs - 1) / kMaxLeafRefs);
        for (unsigned i = 0; i < parts; ++i) {
          const unsigned part = count * (i + 1) / parts - count * i / parts;
          blocks += (part + 3) / 4;
        }
        ++nodes;
      } else {
        blocks += (count + 3) / 4;
      }
      continue;
    }
    const auto& inner = *static_cast<const TreeInner*>(n);
    ++nodes;
    for (unsigned i = 0; i < inner.child_count; ++i) stack.push_back(inner.children[i]);
  }
  return {blocks, nodes};
}

}  // namespace

void flatten_wide(const TreeNode& root, const Box& scene, const BuildInput& input,
                  const BuildOptions& options, Bvh& out) {
  const auto [blocks, nodes] = count_wide(root);
  out.blocks.reserve(blocks);
  out.nodes8.reserve(nodes + 1);
  WideFlattener flattener(input, options, scene, out);
  if (root.is_leaf)
    flattener.single_leaf(static_cast<const TreeLeaf&>(root), scene);
  else
    flattener.inner(static_cast<const TreeInner&>(root), scene, 1);
}

void flatten_empty_wide(const Box& scene, const BuildOptions& options, Bvh& out) {
  const BuildInput none;
  WideFlattener(none, options, scene, out).empty_root(scene);
}

}  // namespace wp::bvh::detail
