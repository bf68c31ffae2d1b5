// check_invariants(): structural checks of a flattened BVH (the contract is in bvh.h and
// kernels/shared/bvh_layout.h), the binary layout here, the wide one in bvh_check_wide.cpp. Walks
// the tree from node 0 and reports the first violation.
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "check_common.h"

namespace wp::bvh {
namespace {

using detail::ChildBox;

ChildBox child_box(const dev::BvhNode& n, int slot) {
  const dev::float4& xy = slot == 0 ? n.c0_xy : n.c1_xy;
  const float loz = slot == 0 ? n.c01_z.x : n.c01_z.z;
  const float hiz = slot == 0 ? n.c01_z.y : n.c01_z.w;
  return ChildBox{{xy.x, xy.z, loz}, {xy.y, xy.w, hiz}};
}

std::uint32_t bits(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

class Checker {
 public:
  Checker(const Bvh& bvh, std::size_t triangle_count, bool spatial_splits)
      : bvh_(bvh),
        splits_(spatial_splits),
        tolerance_(detail::fit_tolerance(bvh)),
        refs_(triangle_count) {}

  std::string run() {
    if (bvh_.nodes.empty()) return "no nodes (node 0 must be the root)";
    if (!bvh_.nodes8.empty() || !bvh_.blocks.empty()) return "width 2 with wide-layout arrays";
    visited_.assign(bvh_.nodes.size(), false);
    slot_owner_.assign(bvh_.triangles.size(), false);
    std::vector<Pending> todo{{0, detail::scene_box(bvh_), 1}};
    visited_[0] = true;
    while (!todo.empty() && error_.empty()) {
      const Pending p = todo.back();
      todo.pop_back();
      for (int slot = 0; slot < 2 && error_.empty(); ++slot) child(p, slot, todo);
    }
    if (error_.empty()) finish();
    return error_;
  }

 private:
  struct Pending {
    std::int32_t node;
    ChildBox box;
    int depth;
  };

  void fail(std::int32_t node, int slot, const std::string& what) {
    std::ostringstream s;
    s << "node " << node << " child " << slot << ": " << what;
    error_ = s.str();
  }

  void child(const Pending& p, int slot, std::vector<Pending>& todo) {
    const dev::BvhNode& n = bvh_.nodes[static_cast<std::size_t>(p.node)];
    const std::int32_t link = slot == 0 ? n.link.x : n.link.y;
    const std::int32_t count = slot == 0 ? n.link.z : n.link.w;
    const ChildBox box = child_box(n, slot);
    if (link < 0 && count == 0) return empty_child(p, slot, box);
    if (!detail::inside(box, p.box)) return fail(p.node, slot, "box not inside its parent's");
    if (link < 0) return leaf(p.node, slot, ~link, count, box);
    if (count != 0) return fail(p.node, slot, "inner child with a triangle count");
    if (static_cast<std::size_t>(link) >= bvh_.nodes.size())
      return fail(p.node, slot, "node index out of range");
    if (visited_[static_cast<std::size_t>(link)]) return fail(p.node, slot, "node reached twice");
    const bool first_inner = slot == 0 || n.link.x < 0;
    if (first_inner && link != p.node + 1) return fail(p.node, slot, "not in depth-first preorder");
    if (p.depth + 1 > WP_BVH_MAX_DEPTH) return fail(p.node, slot, "deeper than WP_BVH_MAX_DEPTH");
    visited_[static_cast<std::size_t>(link)] = true;
    todo.push_back({link, box, p.depth + 1});
  }

  // Count 0, lo > hi, and only in a root: child 1 beside a leaf (a single-leaf scene), or both
  // children (a scene without triangles; then the references check finds any triangle missing).
  void empty_child(const Pending& p, int slot, const ChildBox& box) {
    const dev::BvhNode& n = bvh_.nodes[static_cast<std::size_t>(p.node)];
    const bool other_empty = slot == 0 ? n.link.y < 0 && n.link.w == 0 : n.link.x < 0;
    if (p.node != 0 || !(slot == 1 ? n.link.x < 0 : other_empty))
      return fail(p.node, slot, "empty child outside a single-leaf or empty root");
    for (int k = 0; k < 3; ++k)
      if (!(box.lo[k] > box.hi[k])) return fail(p.node, slot, "empty child with a non-empty box");
  }

  void leaf(std::int32_t node, int slot, std::int32_t first, std::int32_t count,
            const ChildBox& box) {
    if (count < 1 || count > WP_BVH_MAX_LEAF_SIZE)
      return fail(node, slot, "leaf size " + std::to_string(count));
    const auto begin = static_cast<std::size_t>(first);
    if (begin + static_cast<std::size_t>(count) > bvh_.triangles.size())
      return fail(node, slot, "triangle range out of bounds");
    for (std::size_t i = begin; i < begin + static_cast<std::size_t>(count); ++i) {
      if (slot_owner_[i]) return fail(node, slot, "triangle slot in two leaves");
      slot_owner_[i] = true;
      const dev::IsectTri& t = bvh_.triangles[i];
      const std::uint32_t index = bits(t.v0.w);
      if (!refs_.add(index)) return fail(node, slot, "triangle index out of range");
      if (bits(t.v2.w) != 0) return fail(node, slot, "v2.w not 0");
      if (!triangle_fits(t, box))
        return fail(node, slot, "triangle " + std::to_string(index) + " outside its leaf box");
    }
  }

  bool triangle_fits(const dev::IsectTri& t, const ChildBox& box) const {
    const float v0[3] = {t.v0.x, t.v0.y, t.v0.z};
    const float v1[3] = {t.v1.x, t.v1.y, t.v1.z};
    const float v2[3] = {t.v2.x, t.v2.y, t.v2.z};
    return detail::triangle_fits(v0, v1, v2, box, splits_, tolerance_);
  }

  void finish() {
    error_ = detail::first_unset(visited_, "node", "unreachable");
    if (error_.empty()) error_ = detail::first_unset(slot_owner_, "triangle slot", "in no leaf");
    if (error_.empty()) error_ = refs_.check(splits_);
  }

  const Bvh& bvh_;
  bool splits_;
  float tolerance_;
  detail::RefCounts refs_;
  std::vector<bool> visited_, slot_owner_;
  std::string error_;
};

}  // namespace

std::string check_invariants(const Bvh& bvh, std::size_t triangle_count, bool spatial_splits) {
  if (bvh.width == WP_BVH8_WIDTH)
    return detail::check_invariants_wide(bvh, triangle_count, spatial_splits);
  if (bvh.width != 2) return "width " + std::to_string(bvh.width) + " is not 2 or 8";
  return Checker(bvh, triangle_count, spatial_splits).run();
}

}  // namespace wp::bvh
