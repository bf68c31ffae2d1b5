// check_invariants() for the wide layout (BvhNode8 + TriBlock4; the contract is in bvh.h and
// kernels/shared/bvh_layout.h). Walks the tree depth-first in slot order from node 0, which must
// meet the nodes in index order (preorder), and reports the first violation.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "check_common.h"

namespace wp::bvh::detail {
namespace {

constexpr std::uint32_t kUnusedPrim = 0xffffffffu;

ChildBox child_box(const dev::BvhNode8& n, int slot) {
  return ChildBox{{n.lo_x.s[slot], n.lo_y.s[slot], n.lo_z.s[slot]},
                  {n.hi_x.s[slot], n.hi_y.s[slot], n.hi_z.s[slot]}};
}

bool unused_box(const ChildBox& b) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  for (int k = 0; k < 3; ++k)
    if (!(b.lo[k] == kInf && b.hi[k] == kInf)) return false;
  return true;
}

// One lane of a block, as arrays for the fit test.
struct Lane {
  float v0[3], v1[3], v2[3];
  std::uint32_t prim, flags;
};

float get(const dev::float4& v, int i) {
  return i == 0 ? v.x : i == 1 ? v.y : i == 2 ? v.z : v.w;
}
std::uint32_t get(const dev::uint4& v, int i) {
  return i == 0 ? v.x : i == 1 ? v.y : i == 2 ? v.z : v.w;
}

Lane lane(const dev::TriBlock4& b, int i) {
  return Lane{{get(b.v0[0], i), get(b.v0[1], i), get(b.v0[2], i)},
              {get(b.v1[0], i), get(b.v1[1], i), get(b.v1[2], i)},
              {get(b.v2[0], i), get(b.v2[1], i), get(b.v2[2], i)},
              get(b.prim, i),
              get(b.flags, i)};
}

// An unused lane: all-zero vertices (zero area, never hit), prim 0xffffffff, flags 0.
bool unused_lane_is_clear(const Lane& l) {
  for (int k = 0; k < 3; ++k)
    if (l.v0[k] != 0.0f || l.v1[k] != 0.0f || l.v2[k] != 0.0f) return false;
  return l.flags == 0;
}

class WideChecker {
 public:
  WideChecker(const Bvh& bvh, std::size_t triangle_count, bool spatial_splits)
      : bvh_(bvh), splits_(spatial_splits), tolerance_(fit_tolerance(bvh)), refs_(triangle_count) {}

  std::string run() {
    if (bvh_.nodes8.empty()) return "no nodes (node 0 must be the root)";
    if (!bvh_.nodes.empty() || !bvh_.triangles.empty()) return "width 8 with binary-layout arrays";
    visited_.assign(bvh_.nodes8.size(), false);
    block_owner_.assign(bvh_.blocks.size(), false);
    visited_[0] = true;
    std::vector<Pending> todo{{0, scene_box(bvh_), 1}};
    std::int32_t next = 0;  // preorder: the walk must meet the nodes in index order
    while (!todo.empty() && error_.empty()) {
      const Pending p = todo.back();
      todo.pop_back();
      if (p.node != next++) return "node " + std::to_string(p.node) + " not in preorder";
      node(p, todo);
    }
    if (error_.empty()) finish();
    return error_;
  }

 private:
  struct Pending {
    std::int32_t node;
    ChildBox box;  // the node's own box: the one its parent stores for it
    int depth;     // root = 1
  };

  void fail(std::int32_t node, int slot, const std::string& what) {
    std::ostringstream s;
    s << "node " << node << " slot " << slot << ": " << what;
    error_ = s.str();
  }

  // Checks the slots of p.node and queues its inner children so that they pop in slot order.
  void node(const Pending& p, std::vector<Pending>& todo) {
    const dev::BvhNode8& n = bvh_.nodes8[static_cast<std::size_t>(p.node)];
    int used = 0;
    while (used < WP_BVH8_WIDTH && n.child.s[used] != 0) ++used;
    for (int slot = used; slot < WP_BVH8_WIDTH; ++slot) {
      if (n.child.s[slot] != 0) return fail(p.node, slot, "used slot after an unused one");
      if (!unused_box(child_box(n, slot))) return fail(p.node, slot, "unused slot with a box");
    }
    // Embree makes 2..8 children; only a single-leaf scene has a root with one (a leaf), and only a
    // scene without triangles one with none (then the references check finds any missing).
    const bool single_leaf_root = p.node == 0 && used == 1 && n.child.s[0] < 0;
    const bool empty_root = p.node == 0 && used == 0;
    if (used < 2 && !single_leaf_root && !empty_root)
      return fail(p.node, used, "fewer than 2 children");
    const std::size_t first_new = todo.size();
    for (int slot = 0; slot < used && error_.empty(); ++slot) child(p, n, slot, todo);
    std::reverse(todo.begin() + static_cast<std::ptrdiff_t>(first_new), todo.end());
  }

  void child(const Pending& p, const dev::BvhNode8& n, int slot, std::vector<Pending>& todo) {
    const std::int32_t c = n.child.s[slot];
    const ChildBox box = child_box(n, slot);
    if (!inside(box, p.box)) return fail(p.node, slot, "box not inside its parent's");
    if (c < 0) return leaf(p.node, slot, c, box);
    if (static_cast<std::size_t>(c) >= bvh_.nodes8.size())
      return fail(p.node, slot, "node index out of range");
    if (visited_[static_cast<std::size_t>(c)]) return fail(p.node, slot, "node reached twice");
    if (p.depth + 1 > WP_BVH8_MAX_DEPTH) return fail(p.node, slot, "deeper than WP_BVH8_MAX_DEPTH");
    visited_[static_cast<std::size_t>(c)] = true;
    todo.push_back({c, box, p.depth + 1});
  }

  // Blocks [c >> 2, (c >> 2) + (c & 3) + 1) with c = ~child: owned by no other leaf, used lanes
  // first, the unused ones (only in the last block, which has a used one) cleared.
  void leaf(std::int32_t node, int slot, std::int32_t child, const ChildBox& box) {
    const std::int32_t c = ~child;
    const auto first = static_cast<std::size_t>(c >> 2);
    const std::size_t count = static_cast<std::size_t>(c & 3) + 1;
    if (first + count > bvh_.blocks.size()) return fail(node, slot, "block range out of bounds");
    for (std::size_t b = first; b < first + count; ++b) {
      if (block_owner_[b]) return fail(node, slot, "block in two leaves");
      block_owner_[b] = true;
      const bool last = b + 1 == first + count;
      bool seen_unused = false;
      for (int i = 0; i < 4 && error_.empty(); ++i) {
        const Lane l = lane(bvh_.blocks[b], i);
        const std::string where = "block " + std::to_string(b) + " lane " + std::to_string(i);
        if (l.prim == kUnusedPrim) {
          if (!last) return fail(node, slot, "unused " + where + " before the leaf's last block");
          if (i == 0) return fail(node, slot, "no used lane in the last block, " + where);
          if (!unused_lane_is_clear(l)) return fail(node, slot, "unused " + where + " not clear");
          seen_unused = true;
          continue;
        }
        if (seen_unused) return fail(node, slot, "used " + where + " after an unused one");
        used_lane(node, slot, l, box);
      }
    }
  }

  void used_lane(std::int32_t node, int slot, const Lane& l, const ChildBox& box) {
    if (!refs_.add(l.prim)) return fail(node, slot, "triangle index out of range");
    if (!triangle_fits(l.v0, l.v1, l.v2, box, splits_, tolerance_))
      fail(node, slot, "triangle " + std::to_string(l.prim) + " outside its leaf box");
  }

  void finish() {
    error_ = first_unset(visited_, "node", "unreachable");
    if (error_.empty()) error_ = first_unset(block_owner_, "block", "in no leaf");
    if (error_.empty()) error_ = refs_.check(splits_);
  }

  const Bvh& bvh_;
  bool splits_;
  float tolerance_;
  RefCounts refs_;
  std::vector<bool> visited_, block_owner_;
  std::string error_;
};

}  // namespace

std::string check_invariants_wide(const Bvh& bvh, std::size_t triangle_count, bool spatial_splits) {
  return WideChecker(bvh, triangle_count, spatial_splits).run();
}

}  // namespace wp::bvh::detail
