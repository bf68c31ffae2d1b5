// CPU reference traversal of the wide layout (BvhNode8 + TriBlock4). The arithmetic is that of
// traverse_common.h; the order below is the specification kernels/traversal/traverse8.h copies:
//
//   1. At a node, the slab test of all 8 lanes against tmax_current (the current closest t; the
//      ray's tmax before any hit).
//   2. Then in lane order 0..7, for each entered lane: a leaf (child < 0) is intersected right
//      away, its blocks in order and lanes 0..3 of each block in order, each triangle against the
//      closest t so far (which earlier leaves of this very node may have lowered; their boxes
//      were all tested in step 1 against the value before the loop); an inner node (child > 0)
//      is collected with its tnear.
//   3. The collected inner children are pushed on a stack of (node, tnear) entries in decreasing
//      tnear order, a tie putting the lower lane above: the smallest tnear (then lowest lane)
//      ends on top.
//   4. The next node is popped; an entry whose tnear > the current closest t is skipped;
//      traversal ends when the stack is empty. Any-hit (occluded) returns at the first hit.
//
// An any-hit answer does not depend on this order: until its first hit the closest t stays the
// ray's tmax, so every box it enters is entered in whatever order the nodes come, and nothing is
// skipped; kernels/traversal/traverse8.h visits the children in lane order there, unsorted.
//
// child == 0 is an unused slot (node 0 is the root, nobody's child) and is never visited. Its box
// (lo = hi = +INFINITY) keeps out every ray with a finite tmax, but a ray with tmax = +INFINITY
// and no negative direction component enters it (all slab distances +INFINITY, so tnear = tfar =
// +INFINITY); visiting "node 0" then would restart at the root and never end.
#include <cassert>

#include "traverse_common.h"

namespace wp::bvh::detail {
namespace {

float lane(const dev::float4& v, int i) {
  return i == 0 ? v.x : i == 1 ? v.y : i == 2 ? v.z : v.w;
}
std::uint32_t lane(const dev::uint4& v, int i) {
  return i == 0 ? v.x : i == 1 ? v.y : i == 2 ? v.z : v.w;
}

TriangleData triangle_data(const dev::TriBlock4& b, int i) {
  TriangleData t{};
  for (int k = 0; k < 3; ++k) {
    t.v[0][k] = lane(b.v0[k], i);
    t.v[1][k] = lane(b.v1[k], i);
    t.v[2][k] = lane(b.v2[k], i);
  }
  t.flags = lane(b.flags, i);
  t.prim = lane(b.prim, i);
  return t;
}

// Intersects the leaf `child` (< 0), entered at `tleaf`, against the closest hit so far (tmax its
// distance), lowering tmax at each closer hit (triangle_test's rule); with `any`, stops at the
// first hit. Unused lanes (zero area: det = 0) never hit. Returns whether
// anything was hit.
bool leaf_test(const Bvh& bvh, const PreparedRay& r, std::int32_t child, float tleaf, Hit& hit,
               float& tmax, bool any) {
  const std::int32_t c = ~child;
  const auto first = static_cast<std::size_t>(c >> 2);
  const std::size_t count = static_cast<std::size_t>(c & 3) + 1;
  bool found = false;
  for (std::size_t b = first; b < first + count; ++b) {
    for (int i = 0; i < 4; ++i) {
      if (triangle_test(r, triangle_data(bvh.blocks[b], i), tleaf, tmax, hit)) {
        found = true;
        tmax = hit.t;
        if (any) return true;
      }
    }
  }
  return found;
}

struct Entry {
  std::int32_t node;
  float tnear;
};

// Step 1: which lanes of `n` the ray enters, with their entry distances.
int slab_test_lanes(const PreparedRay& r, const dev::BvhNode8& n, float tmax, float tnear[8]) {
  int entered = 0;
  for (int i = 0; i < WP_BVH8_WIDTH; ++i) {
    const bool in = slab_test(r, n.lo_x.s[i], n.hi_x.s[i], n.lo_y.s[i], n.hi_y.s[i], n.lo_z.s[i],
                              n.hi_z.s[i], tmax, tnear[i]);
    entered |= int(in) << i;
  }
  return entered;
}

// Step 3, one child: inner[0..count) is kept in push order (decreasing tnear, the later lane
// first among equals); the new child, from a later lane than all, goes below every entry whose
// tnear is smaller or equal.
void insert(Entry inner[8], int& count, Entry e) {
  int j = count++;
  for (; j > 0 && inner[j - 1].tnear <= e.tnear; --j) inner[j] = inner[j - 1];
  inner[j] = e;
}

}  // namespace

Hit trace_wide(const Bvh& bvh, const Ray& ray, bool any, std::int32_t root) {
  Hit hit;
  if (bvh.nodes8.empty()) return hit;
  const PreparedRay r(ray);
  float tmax = ray.tmax;  // the current closest t
  Entry stack[WP_BVH8_STACK_SIZE];
  int sp = 0;
  std::int32_t node = root;
  for (;;) {
    const dev::BvhNode8& n = bvh.nodes8[static_cast<std::size_t>(node)];
    float tnear[WP_BVH8_WIDTH];
    const int entered = slab_test_lanes(r, n, tmax, tnear);
    Entry inner[WP_BVH8_WIDTH];
    int count = 0;
    for (int i = 0; i < WP_BVH8_WIDTH; ++i) {
      if (!(entered >> i & 1)) continue;
      const std::int32_t child = n.child.s[i];
      if (child < 0) {
        if (leaf_test(bvh, r, child, tnear[i], hit, tmax, any) && any) return hit;
      } else if (child > 0) {
        insert(inner, count, Entry{child, tnear[i]});
      }
    }
    // The builder bounds the depth so that this cannot happen (bvh_layout.h).
    assert(sp + count <= WP_BVH8_STACK_SIZE);
    if (sp + count > WP_BVH8_STACK_SIZE)
      throw Error("BVH traversal: stack overflow (wide tree too deep)");
    for (int j = 0; j < count; ++j) stack[sp++] = inner[j];
    // Step 4: the top entry that can still hold something closer.
    do {
      if (sp == 0) return hit;
      --sp;
    } while (stack[sp].tnear > tmax);
    node = stack[sp].node;
  }
}

}  // namespace wp::bvh::detail
