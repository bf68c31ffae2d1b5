// unit tier: the BVH module, wide layout (BuildOptions::width = 8: BvhNode8 + TriBlock4). Structure
// (check_invariants on many meshes and options), the exact layout, the statistics, bad options,
// oversized leaves, and the width-8 reference traversal against Embree's rtcIntersect1 /
// rtcOccluded1, a brute-force loop over the same triangle test and the width-2 reference; its
// order (nearest child first, ties to the lower lane) on hand-made trees.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "bvh/build_tree.h"       // internal: flatten_wide on hand-made trees
#include "bvh/traverse_common.h"  // internal: the slab and triangle tests, for the definition
#include "bvh/bvh.h"
#include "host/util/error.h"
#include "tests/bvh_test_util.h"

namespace wp::bvh {
namespace {

using namespace test;  // the shared meshes and oracles

BuildOptions wide(int leaf = WP_BVH_MAX_LEAF_SIZE, bool splits = false) {
  BuildOptions o;
  o.width = 8;
  o.max_leaf_size = leaf;
  o.spatial_splits = splits;
  return o;
}

// ---------------------------------------------------------------------------------------------
// Structure, layout and statistics

double area(const dev::BvhNode8& n, int i) {
  const float x = n.hi_x.s[i] - n.lo_x.s[i], y = n.hi_y.s[i] - n.lo_y.s[i];
  const float z = n.hi_z.s[i] - n.lo_z.s[i];
  return 2.0 * double(x * y + y * z + z * x);
}

// What the layout holds, recounted from the arrays; sah with unit costs (BuildStats::sah_cost):
// the root 1, every inner child A(child) / A(root), every leaf child blocks * A(leaf) / A(root).
struct Recount {
  std::size_t leaves = 0, used_lanes = 0, leaf_blocks = 0, largest_leaf = 0;
  double sah = 1.0;
};

Recount recount(const Bvh& bvh) {
  const glm::vec3 e = bvh.hi - bvh.lo;
  const double root = 2.0 * double(e.x * e.y + e.y * e.z + e.z * e.x);
  Recount r;
  for (const dev::BvhNode8& n : bvh.nodes8)
    for (int i = 0; i < WP_BVH8_WIDTH && n.child.s[i] != 0; ++i) {
      const double ratio = root > 0 ? area(n, i) / root : 1.0;
      if (n.child.s[i] > 0) {
        r.sah += ratio;
        continue;
      }
      const std::int32_t c = ~n.child.s[i];
      const std::size_t first = std::size_t(c >> 2), blocks = std::size_t(c & 3) + 1;
      std::size_t used = 0;
      for (std::size_t b = first; b < first + blocks; ++b)
        for (const std::uint32_t p : {bvh.blocks[b].prim.x, bvh.blocks[b].prim.y,
                                      bvh.blocks[b].prim.z, bvh.blocks[b].prim.w})
          used += p != 0xffffffffu;
      r.leaves++, r.used_lanes += used, r.leaf_blocks += blocks;
      r.largest_leaf = std::max(r.largest_leaf, used);
      r.sah += double(blocks) * ratio;
    }
  return r;
}

void expect_valid(const Mesh& mesh, const BuildOptions& options) {
  const Bvh bvh = build(mesh.input(), options);
  ASSERT_EQ(bvh.width, 8);
  EXPECT_EQ(check_invariants(bvh, mesh.triangles(), options.spatial_splits), "");
  EXPECT_TRUE(bvh.nodes.empty() && bvh.triangles.empty());
  const BuildStats& s = bvh.stats;
  const Recount r = recount(bvh);
  EXPECT_EQ(s.inner_nodes, bvh.nodes8.size());
  EXPECT_EQ(s.leaves, r.leaves);
  EXPECT_EQ(s.triangle_refs, r.used_lanes);
  EXPECT_EQ(r.leaf_blocks, bvh.blocks.size());
  EXPECT_LE(r.largest_leaf, std::size_t(options.max_leaf_size));  // Embree keeps to it
  EXPECT_GE(s.triangle_refs, mesh.triangles());
  if (!options.spatial_splits) {
    EXPECT_EQ(s.triangle_refs, mesh.triangles());
  }
  EXPECT_TRUE(std::isfinite(s.sah_cost) && s.sah_cost > 0);
  EXPECT_NEAR(s.sah_cost, r.sah, 1e-9 * s.sah_cost);
  EXPECT_TRUE(s.max_depth >= 1 && s.max_depth <= WP_BVH8_MAX_DEPTH);
}

// Every mesh with and without spatial splits, at two leaf sizes in the default suite (the
// smallest and one above the block of 4 triangles), at four in ...Exhaustive (slow).
void expect_valid_builds(std::initializer_list<int> leaves) {
  const std::vector<std::pair<const char*, Mesh>> meshes = invariant_meshes();
  for (const auto& [name, mesh] : meshes)
    for (const bool splits : {false, true})
      for (const int leaf : leaves) {
        SCOPED_TRACE(testing::Message() << name << ", splits " << splits << ", leaf " << leaf);
        expect_valid(mesh, wide(leaf, splits));
      }
}

TEST(Bvh8Build, InvariantsHoldOnManyMeshes) {
  expect_valid_builds({1, 8});
}
TEST(Bvh8Build, InvariantsHoldOnManyMeshesExhaustive) {
  expect_valid_builds({1, 4, 8, 16});
}

TEST(Bvh8Build, SingleTriangleIsARootWithOneLeafAndSevenUnusedSlots) {
  Mesh m;
  m.add({0, 0, 0}, {1, 0, 0}, {0, 1, 0.5f});
  m.flags = {WP_TRI_CULL_BACKFACE};
  const Bvh bvh = build(m.input(), wide());
  ASSERT_EQ(bvh.nodes8.size(), 1u);
  const dev::BvhNode8& root = bvh.nodes8[0];
  EXPECT_EQ(root.child.s[0], ~0);  // blocks [0, 1)
  EXPECT_EQ(root.hi_x.s[0], 1.0f);
  EXPECT_EQ(root.hi_z.s[0], 0.5f);
  for (int i = 1; i < 8; ++i) {
    EXPECT_EQ(root.child.s[i], 0);
    for (const float f : {root.lo_x.s[i], root.hi_x.s[i], root.lo_y.s[i], root.hi_y.s[i],
                          root.lo_z.s[i], root.hi_z.s[i]})
      EXPECT_EQ(f, kInf);
  }
  ASSERT_EQ(bvh.blocks.size(), 1u);
  const dev::TriBlock4& b = bvh.blocks[0];
  EXPECT_EQ(b.prim.x, 0u);
  EXPECT_EQ(b.flags.x, WP_TRI_CULL_BACKFACE);
  EXPECT_EQ(b.v1[0].x, 1.0f);
  EXPECT_EQ(b.v2[2].x, 0.5f);
  for (const std::uint32_t p : {b.prim.y, b.prim.z, b.prim.w}) EXPECT_EQ(p, 0xffffffffu);
  for (int k = 0; k < 3; ++k)
    for (const dev::float4& v : {b.v0[k], b.v1[k], b.v2[k]})
      EXPECT_TRUE(v.y == 0 && v.z == 0 && v.w == 0);
  EXPECT_TRUE(b.flags.y == 0 && b.flags.z == 0 && b.flags.w == 0);
  EXPECT_EQ(bvh.stats.max_depth, 1);
  EXPECT_EQ(bvh.stats.leaves, 1u);
  EXPECT_DOUBLE_EQ(bvh.stats.sah_cost, 2.0);  // the root, plus one block over the whole scene
}

// A scene without triangles builds without Embree: a root alone with all 8 slots unused (child 0,
// boxes +INFINITY) and no blocks.
TEST(Bvh8Build, EmptyInputIsARootWithEightUnusedSlots) {
  for (const bool splits : {false, true}) {
    const Bvh bvh = build(BuildInput{}, wide(WP_BVH_MAX_LEAF_SIZE, splits));
    EXPECT_EQ(bvh.width, 8);
    EXPECT_EQ(check_invariants(bvh, 0, splits), "");
    ASSERT_EQ(bvh.nodes8.size(), 1u);
    EXPECT_TRUE(bvh.blocks.empty() && bvh.nodes.empty() && bvh.triangles.empty());
    const dev::BvhNode8& root = bvh.nodes8[0];
    for (int i = 0; i < 8; ++i) {
      EXPECT_EQ(root.child.s[i], 0);
      for (const float f : {root.lo_x.s[i], root.hi_x.s[i], root.lo_y.s[i], root.hi_y.s[i],
                            root.lo_z.s[i], root.hi_z.s[i]})
        EXPECT_EQ(f, kInf);
    }
    EXPECT_EQ(bvh.stats.inner_nodes, 1u);
    EXPECT_EQ(bvh.stats.leaves, 0u);
    EXPECT_EQ(bvh.stats.triangle_refs, 0u);
    EXPECT_EQ(bvh.stats.max_depth, 1);
    EXPECT_TRUE(std::isfinite(bvh.stats.sah_cost) && bvh.stats.sah_cost > 0);
    EXPECT_NE(check_invariants(bvh, 1, splits), "");  // a BVH that lost its triangles
  }
  EXPECT_THROW(build(BuildInput{}, wide(4 * WP_BVH8_MAX_LEAF_BLOCKS + 1)), Error);
}

// Only the empty scene's root has no used slot.
TEST(Bvh8Build, ChildlessNodeOnlyAsTheEmptySceneRoot) {
  const Mesh m = soup(9, 3, 0.05f);
  Bvh bvh = build(m.input(), wide(1));
  ASSERT_EQ(check_invariants(bvh, m.triangles(), false), "");
  ASSERT_GT(bvh.nodes8.size(), 1u);
  // Node 1 is an inner child of the root; leave it with no children.
  const float inf = kInf;
  dev::BvhNode8& n = bvh.nodes8[1];
  for (int i = 0; i < 8; ++i) {
    n.child.s[i] = 0;
    n.lo_x.s[i] = n.hi_x.s[i] = n.lo_y.s[i] = n.hi_y.s[i] = n.lo_z.s[i] = n.hi_z.s[i] = inf;
  }
  EXPECT_NE(check_invariants(bvh, m.triangles(), false), "");
}

TEST(Bvh8Build, BlockLanesAreTheVerticesWithIndexAndFlags) {
  Mesh m = sphere(16, 32);
  for (std::size_t i = 0; i < m.triangles(); ++i) m.flags.push_back(std::uint32_t(i % 3 == 0));
  const std::vector<dev::IsectTri> stored = stored_triangles(m);
  const Bvh bvh = build(m.input(), wide(16));
  std::size_t used = 0;
  for (const dev::TriBlock4& b : bvh.blocks)
    for (int i = 0; i < 4; ++i) {
      const auto get = [i](const dev::float4& v) {
        return i == 0 ? v.x : i == 1 ? v.y : i == 2 ? v.z : v.w;
      };
      const std::uint32_t prim = i == 0   ? b.prim.x
                                 : i == 1 ? b.prim.y
                                 : i == 2 ? b.prim.z
                                          : b.prim.w;
      const std::uint32_t flags = i == 0   ? b.flags.x
                                  : i == 1 ? b.flags.y
                                  : i == 2 ? b.flags.z
                                           : b.flags.w;
      if (prim == 0xffffffffu) continue;
      ++used;
      ASSERT_LT(prim, m.triangles());
      const dev::IsectTri& t = stored[prim];
      EXPECT_EQ(glm::vec3(get(b.v0[0]), get(b.v0[1]), get(b.v0[2])),
                glm::vec3(t.v0.x, t.v0.y, t.v0.z));
      EXPECT_EQ(glm::vec3(get(b.v1[0]), get(b.v1[1]), get(b.v1[2])),
                glm::vec3(t.v1.x, t.v1.y, t.v1.z));
      EXPECT_EQ(glm::vec3(get(b.v2[0]), get(b.v2[1]), get(b.v2[2])),
                glm::vec3(t.v2.x, t.v2.y, t.v2.z));
      EXPECT_EQ(flags, m.flags[prim]);
    }
  EXPECT_EQ(used, m.triangles());
}

TEST(Bvh8Build, WidthAndLeafSizeAreChecked) {
  const Mesh m = soup(50, 1, 0.1f);
  for (const int width : {0, 1, 3, 4, 16}) {
    BuildOptions o;
    o.width = width;
    EXPECT_THROW(build(m.input(), o), Error) << width;
  }
  for (const int leaf : {0, 4 * WP_BVH8_MAX_LEAF_BLOCKS + 1})
    EXPECT_THROW(build(m.input(), wide(leaf)), Error) << leaf;
  BuildOptions binary;
  binary.max_leaf_size = 16;
  EXPECT_THROW(build(m.input(), binary), Error);
  EXPECT_NO_THROW(build(m.input(), wide(16)));
}

// A tree whose pathological input (one cluster peeled off per level) reaches Embree's switch to
// object-median "large leaf" subtrees at depth WP_BVH8_MAX_DEPTH - 8, and stays within the limit.
TEST(Bvh8Build, DeepInputStaysWithinTheDepthLimit) {
  const Mesh m = exponential_clusters(120, 2000);
  for (const bool splits : {false, true}) {
    const Bvh bvh = build(m.input(), wide(1, splits));
    EXPECT_EQ(check_invariants(bvh, m.triangles(), splits), "");
    std::printf("exponential clusters, splits %d: depth %d\n", int(splits), bvh.stats.max_depth);
    EXPECT_GE(bvh.stats.max_depth, WP_BVH8_MAX_DEPTH - 8);
    EXPECT_LE(bvh.stats.max_depth, WP_BVH8_MAX_DEPTH);
  }
}

// ---------------------------------------------------------------------------------------------
// Hand-made trees (flatten_wide directly): oversized leaves and the traversal order

// Owns the nodes of a hand-made tree over a mesh's triangles.
struct HandTree {
  std::vector<std::unique_ptr<detail::TreeLeaf>> leaves;
  std::vector<std::unique_ptr<detail::TreeInner>> inners;
  std::vector<std::unique_ptr<std::vector<std::uint32_t>>> prims;

  detail::Box bounds(const Mesh& m, const std::vector<std::uint32_t>& tris) const {
    detail::Box b{glm::vec3(kInf), glm::vec3(-kInf)};
    for (const std::uint32_t t : tris)
      for (int k = 0; k < 3; ++k) {
        b.lo = glm::min(b.lo, m.positions[m.indices[3 * t + k]]);
        b.hi = glm::max(b.hi, m.positions[m.indices[3 * t + k]]);
      }
    return b;
  }
  const detail::TreeLeaf& leaf(const Mesh& m, std::vector<std::uint32_t> tris) {
    prims.push_back(std::make_unique<std::vector<std::uint32_t>>(std::move(tris)));
    leaves.push_back(std::make_unique<detail::TreeLeaf>());
    detail::TreeLeaf& l = *leaves.back();
    l.is_leaf = true;
    l.count = unsigned(prims.back()->size());
    l.prims = prims.back()->data();
    l.bounds = bounds(m, *prims.back());
    return l;
  }
  // An inner node over `children`, each boxed by `boxes`.
  const detail::TreeInner& inner(std::vector<const detail::TreeNode*> children,
                                 std::vector<detail::Box> boxes) {
    inners.push_back(std::make_unique<detail::TreeInner>());
    detail::TreeInner& n = *inners.back();
    n.is_leaf = false;
    n.child_count = unsigned(children.size());
    for (std::size_t i = 0; i < children.size(); ++i)
      n.children[i] = children[i], n.bounds[i] = boxes[i];
    return n;
  }
};

Bvh flatten(const Mesh& m, const detail::TreeNode& root, const detail::Box& scene) {
  Bvh bvh;
  bvh.width = 8;
  bvh.lo = scene.lo, bvh.hi = scene.hi;
  detail::flatten_wide(root, scene, m.input(), wide(16), bvh);
  return bvh;
}

std::vector<std::uint32_t> range(std::uint32_t begin, std::uint32_t end) {
  std::vector<std::uint32_t> v;
  for (std::uint32_t i = begin; i < end; ++i) v.push_back(i);
  return v;
}

// Embree 3.13 keeps to maxLeafSize, but a leaf too large for WP_BVH8_MAX_LEAF_BLOCKS blocks must
// still flatten to valid nodes (it becomes a subtree).
TEST(Bvh8Build, OversizedLeavesBecomeSubtrees) {
  const Mesh m = soup(1000, 9, 0.05f);
  HandTree t;
  const detail::TreeLeaf& big = t.leaf(m, range(0, 995));
  const detail::TreeLeaf& small = t.leaf(m, range(995, 1000));
  const detail::Box scene = t.bounds(m, range(0, 1000));
  const detail::TreeInner& root = t.inner({&big, &small}, {big.bounds, small.bounds});
  const Bvh bvh = flatten(m, root, scene);
  EXPECT_EQ(check_invariants(bvh, m.triangles(), false), "");
  EXPECT_EQ(bvh.stats.triangle_refs, 1000u);
  EXPECT_EQ(bvh.stats.max_depth, 3);  // 995 -> 8 x 124 or 125 -> 8 x 15 or 16
  // A scene that is one oversized leaf.
  const detail::TreeLeaf& all = t.leaf(m, range(0, 1000));
  const Bvh single = flatten(m, all, scene);
  EXPECT_EQ(check_invariants(single, m.triangles(), false), "");
  EXPECT_EQ(single.stats.triangle_refs, 1000u);
}

// Two identical triangles (0 and 1) in the plane z = 0, under different children: a tie, which
// the lower index wins whatever the order of the visits (traverse_common.h). Triangles 2 and 3,
// in the same plane but away from the test ray, give inner children their second leaf. The root
// box reaches up to z = 2, so that a ray down from z = 1 starts inside it.
Mesh twin_triangles() {
  Mesh m;
  for (int i = 0; i < 2; ++i) m.add({0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  m.add({5, 0, 0}, {6, 0, 0}, {5, 1, 0});
  m.add({5, 3, 0}, {6, 3, 0}, {5, 4, 0});
  return m;
}
const detail::Box kTwinScene{{0, 0, 0}, {6, 6, 2}};
const Ray kDown{{0.25f, 0.25f, 1}, {0, 0, -1}};  // meets the twins at t = 1

// Leaves of one node, in either lane order, entered nearer or farther: triangle 0.
TEST(Bvh8Traverse, LeavesOfOneNodeTieToTheLowerTriangleIndex) {
  const Mesh m = twin_triangles();
  HandTree t;
  const detail::TreeLeaf& a = t.leaf(m, {0});
  const detail::TreeLeaf& b = t.leaf(m, {1});
  const detail::TreeLeaf& far = t.leaf(m, {2, 3});
  // The box of b is entered first (t = 0.5, a's at t = 1).
  const detail::Box a_box{{0, 0, 0}, {1, 1, 0}}, b_box{{0, 0, 0}, {1, 1, 0.5f}};
  const Bvh ab = flatten(m, t.inner({&a, &b, &far}, {a_box, b_box, far.bounds}), kTwinScene);
  const Bvh ba = flatten(m, t.inner({&b, &a, &far}, {b_box, a_box, far.bounds}), kTwinScene);
  EXPECT_EQ(check_invariants(ab, 4, false), "");
  EXPECT_EQ(intersect_closest(ab, kDown).triangle, 0u);
  EXPECT_EQ(intersect_closest(ba, kDown).triangle, 0u);
}

// Inner children in either lane order, either one's box entered first: triangle 0.
TEST(Bvh8Traverse, InnerChildrenTieToTheLowerTriangleIndex) {
  const Mesh m = twin_triangles();
  HandTree t;
  // Inner children A (triangle 0 and 2) and B (triangle 1 and 3).
  const auto child = [&](std::uint32_t twin, std::uint32_t far) -> const detail::TreeInner& {
    const detail::TreeLeaf& l0 = t.leaf(m, {twin});
    const detail::TreeLeaf& l1 = t.leaf(m, {far});
    return t.inner({&l0, &l1}, {l0.bounds, l1.bounds});
  };
  const detail::TreeInner& a = child(0, 2);
  const detail::TreeInner& b = child(1, 3);
  const detail::Box nearer = kTwinScene;               // entered at t = 0 (the origin is inside)
  const detail::Box farther{{0, 0, 0}, {6, 6, 0.5f}};  // entered at t = 0.5
  const auto first_hit = [&](const detail::TreeInner& c0, const detail::Box& b0,
                             const detail::TreeInner& c1, const detail::Box& b1) {
    const Bvh bvh = flatten(m, t.inner({&c0, &c1}, {b0, b1}), kTwinScene);
    EXPECT_EQ(check_invariants(bvh, 4, false), "");
    return intersect_closest(bvh, kDown).triangle;
  };
  EXPECT_EQ(first_hit(a, nearer, b, nearer), 0u);
  EXPECT_EQ(first_hit(b, nearer, a, nearer), 0u);
  EXPECT_EQ(first_hit(a, farther, b, nearer), 0u);
  EXPECT_EQ(first_hit(b, farther, a, nearer), 0u);
}

// The closest hit by its definition (traverse_common.h), with no walk: every leaf whose boxes,
// root to leaf, the ray enters within (tmin, tmax), every triangle in them at distance max(t, the
// leaf's tnear), the least (distance, triangle index); the leaves taken in slot order or reversed.
struct Definition {
  const Bvh& bvh;
  detail::PreparedRay r;
  float tmax;
  bool reversed;
  Hit best{};
  float best_t;
  float at = kInf;           // count the candidates at this distance ...
  std::size_t at_count = 0;  // ... here

  Definition(const Bvh& b, const Ray& ray, bool rev)
      : bvh(b), r(ray), tmax(ray.tmax), reversed(rev), best_t(ray.tmax) {}
  void triangle(const detail::TriangleData& tri, float tleaf) {
    Hit alone;
    if (detail::triangle_test(r, tri, tleaf, tmax, alone) && alone.t == at) ++at_count;
    if (detail::triangle_test(r, tri, tleaf, best_t, best)) best_t = best.t;
  }
  void wide(std::int32_t node) {
    const dev::BvhNode8& n = bvh.nodes8[std::size_t(node)];
    for (int k = 0; k < WP_BVH8_WIDTH; ++k) {
      const int i = reversed ? WP_BVH8_WIDTH - 1 - k : k;
      const std::int32_t child = n.child.s[i];
      float tnear;
      if (child == 0 || !detail::slab_test(r, n.lo_x.s[i], n.hi_x.s[i], n.lo_y.s[i], n.hi_y.s[i],
                                           n.lo_z.s[i], n.hi_z.s[i], tmax, tnear))
        continue;
      if (child > 0) {
        wide(child);
        continue;
      }
      const std::size_t first = std::size_t(~child >> 2), blocks = std::size_t(~child & 3) + 1;
      for (std::size_t b = first; b < first + blocks; ++b)
        for (int lane = 0; lane < 4; ++lane) {
          const dev::TriBlock4& tb = bvh.blocks[b];
          const auto of = [lane](const auto& v) {
            return lane == 0 ? v.x : lane == 1 ? v.y : lane == 2 ? v.z : v.w;
          };
          detail::TriangleData tri{};
          for (int a = 0; a < 3; ++a) {
            tri.v[0][a] = of(tb.v0[a]), tri.v[1][a] = of(tb.v1[a]), tri.v[2][a] = of(tb.v2[a]);
          }
          tri.flags = of(tb.flags), tri.prim = of(tb.prim);
          triangle(tri, tnear);
        }
    }
  }
};

Hit closest_by_definition(const Bvh& bvh, const Ray& ray, bool reversed) {
  Definition d(bvh, ray, reversed);
  if (!bvh.nodes8.empty()) d.wide(0);
  return d.best;
}

// How many candidates (triangle references) the definition finds at distance `t`.
std::size_t candidates_at(const Bvh& bvh, const Ray& ray, float t) {
  Definition d(bvh, ray, false);
  d.at = t;
  if (!bvh.nodes8.empty()) d.wide(0);
  return d.at_count;
}

bool same_hit(const Hit& a, const Hit& b) {
  return a.hit == b.hit && bits(a.t) == bits(b.t) && bits(a.u) == bits(b.u) &&
         bits(a.v) == bits(b.v) && a.triangle == b.triangle;
}

// The walk (nearest child first, culling by the closest hit so far) gives every ray the hit the
// definition gives, in either order of the leaves: so any order does (what packets of rays rely
// on, kernels/traversal/traverse8_packet.h). Rays aimed at the vertices and edge midpoints of a
// grid, flat (its leaf boxes flat too, so that a hit's t and its leaf's tnear are two roundings of
// one distance) and curved, where several triangles tie; random rays besides. Both kinds of case
// occur and are counted: ties, and hits whose leaf's tnear exceeds the triangle's own t, where
// the distance is that tnear, checked to lie within 4 ulps (tnear's three roundings and one for
// the double-precision distance) of the exact distance computed in double.
TEST(Bvh8Traverse, ClosestHitIsTheDefinitionsInAnyOrder) {
  std::size_t ties = 0, raised = 0, rays_total = 0;
  for (const bool flat : {true, false}) {
    Mesh m = grid(24);
    if (flat)
      for (glm::vec3& p : m.positions) p.z = 0.0f;
    for (const int leaf : {1, 4, 16}) {
      const Bvh bvh = build(m.input(), wide(leaf));
      std::vector<Ray> rays = make_rays(bvh, 2000, 2000, unsigned(leaf));
      std::mt19937 rng(unsigned(leaf) + 100u);
      std::uniform_real_distribution<float> u(-1, 1);
      for (std::size_t i = 0; i < m.positions.size(); ++i) {
        const glm::vec3 v = m.positions[i];
        const glm::vec3 next = m.positions[(i + 1) % m.positions.size()];
        for (const glm::vec3 target : {v, 0.5f * (v + next)}) {
          const glm::vec3 eye(0.5f + 0.4f * u(rng), 0.5f + 0.4f * u(rng), 1.0f + 0.5f * u(rng));
          rays.push_back({eye, target - eye, 0.0f, kInf});
        }
      }
      for (const Ray& ray : rays) {
        const Hit walk = intersect_closest(bvh, ray);
        const Hit forward = closest_by_definition(bvh, ray, false);
        const Hit backward = closest_by_definition(bvh, ray, true);
        ASSERT_TRUE(same_hit(walk, forward) && same_hit(walk, backward))
            << "walk " << walk.triangle << " t " << walk.t << ", definition " << forward.triangle
            << " / " << backward.triangle << " t " << forward.t << " / " << backward.t;
        EXPECT_EQ(occluded(bvh, ray), walk.hit);
        ++rays_total;
        if (!walk.hit) continue;
        // The triangle alone (no leaf): its own t; another triangle at the walk's distance.
        Hit alone;
        const std::size_t tri = walk.triangle;
        const dev::IsectTri it{
            {m.positions[m.indices[3 * tri]].x, m.positions[m.indices[3 * tri]].y,
             m.positions[m.indices[3 * tri]].z, as_float(std::uint32_t(tri))},
            {m.positions[m.indices[3 * tri + 1]].x, m.positions[m.indices[3 * tri + 1]].y,
             m.positions[m.indices[3 * tri + 1]].z, as_float(0u)},
            {m.positions[m.indices[3 * tri + 2]].x, m.positions[m.indices[3 * tri + 2]].y,
             m.positions[m.indices[3 * tri + 2]].z, 0.0f}};
        ASSERT_TRUE(intersect_triangle(it, ray, kInf, alone));
        ASSERT_LE(alone.t, walk.t);
        if (alone.t < walk.t) {
          ++raised;
          const glm::dvec3 o(ray.o), d(ray.d), a(m.positions[m.indices[3 * tri]]);
          const glm::dvec3 n = glm::cross(glm::dvec3(m.positions[m.indices[3 * tri + 1]]) - a,
                                          glm::dvec3(m.positions[m.indices[3 * tri + 2]]) - a);
          const double exact = glm::dot(n, a - o) / glm::dot(n, d);
          EXPECT_LE(double(walk.t), exact * (1.0 + 4.0 * 0x1p-24));
        }
        ties += candidates_at(bvh, ray, walk.t) > 1;
      }
    }
  }
  std::printf("%zu rays, %zu ties, %zu hits at their leaf's tnear\n", rays_total, ties, raised);
  EXPECT_GT(ties, 100u);
  EXPECT_GT(raised, 10u);
  EXPECT_GT(rays_total, 20000u);
}

// ---------------------------------------------------------------------------------------------
// Traversal against other intersectors

TEST(Bvh8Traverse, MatchesEmbree) {
  std::size_t rays = 0;
  rays += compare_with_embree(sphere(64, 128), wide(), 20000, 10000, 1);
  rays += compare_with_embree(soup(20000, 2, 0.02f), wide(16), 20000, 10000, 2);
  rays += compare_with_embree(grid(100), wide(4), 20000, 10000, 3);
  rays += compare_with_embree(long_diagonals(5000, 4, 0.25f), wide(8, true), 20000, 10000, 4);
  rays += compare_with_embree(sphere(32, 64), wide(1, true), 10000, 5000, 5);
  EXPECT_GE(rays, 100000u);
}

// Sphere and grid with every other triangle back-face culled.
Mesh culled_mix() {
  Mesh m = sphere(24, 48);
  const Mesh g = grid(30);
  const std::size_t base = m.positions.size();
  m.positions.insert(m.positions.end(), g.positions.begin(), g.positions.end());
  for (std::uint32_t i : g.indices) m.indices.push_back(std::uint32_t(base + i));
  for (std::size_t i = 0; i < m.triangles(); ++i)
    m.flags.push_back(i % 2 ? WP_TRI_CULL_BACKFACE : 0);
  return m;
}

// The BVH must find what testing every triangle finds, with the same test: including back-face
// culling flags, leaf sizes 1 and 16 and spatial splits.
TEST(Bvh8Traverse, MatchesBruteForceWithTheSameTriangleTest) {
  const Mesh m = culled_mix();
  for (const int leaf : {1, 16})
    for (const bool splits : {false, true})
      expect_matches_brute_force(m, build(m.input(), wide(leaf, splits)), unsigned(leaf));
}

// Both references use one triangle test on the same stored numbers: the same triangle gives the
// same t, u, v bit for bit; a different one must be a tie.
TEST(Bvh8Traverse, MatchesTheBinaryReference) {
  const std::vector<std::pair<Mesh, bool>> cases = {{sphere(48, 96), false},
                                                    {soup(20000, 7, 0.02f), false},
                                                    {culled_mix(), false},
                                                    {long_diagonals(3000, 8, 0.1f), true}};
  for (const auto& [m, splits] : cases) {
    BuildOptions binary;
    binary.spatial_splits = splits;
    const Bvh b2 = build(m.input(), binary), b8 = build(m.input(), wide(8, splits));
    Comparison cmp(m, b8);
    for (const Ray& ray : make_rays(b8, 10000, 10000, 9)) {
      const Hit h2 = intersect_closest(b2, ray), h8 = intersect_closest(b8, ray);
      if (h2.hit && h8.hit && h2.triangle == h8.triangle) {
        EXPECT_TRUE(h2.t == h8.t && h2.u == h8.u && h2.v == h8.v);
      }
      if (cmp.agree(ray, h8, h2)) {
        EXPECT_EQ(occluded(b8, ray), occluded(b2, ray));
      }
    }
    EXPECT_LT(double(cmp.ties()), 1e-3 * double(cmp.rays()));
  }
}

// Every ray misses the empty scene's wide BVH, the ones that enter its unused slots' +INFINITY
// boxes (tmax = +INFINITY, no negative direction component) included.
TEST(Bvh8Traverse, EmptyInputMissesEveryRay) {
  expect_every_ray_misses(build(BuildInput{}, wide()));
}

// An unused slot's box (+INFINITY) is entered, at t = +INFINITY, by a ray with tmax = +INFINITY
// and no negative direction component; its child 0 must not send traversal back to the root.
TEST(Bvh8Traverse, UnusedSlotsAreNotVisitedEvenWithAnInfiniteTmax) {
  for (const std::size_t n : {1, 9, 100}) {
    const Mesh m = soup(n, unsigned(n), 0.05f);
    const Bvh bvh = build(m.input(), wide());
    for (const glm::vec3 d : {glm::vec3(1, 1, 1), glm::vec3(0, 1, 0), glm::vec3(0.0f, 0.0f, 1)}) {
      const Ray ray{{-5, -5, -5}, glm::normalize(d), 0.0f, kInf};  // misses everything
      EXPECT_FALSE(intersect_closest(bvh, ray).hit);
      EXPECT_FALSE(occluded(bvh, ray));
    }
  }
}

TEST(Bvh8Traverse, BackFacesOfCulledTrianglesAreNotThere) {
  Mesh m;
  m.add({-1, -1, 0}, {1, -1, 0}, {0, 1, 0});  // normal +z
  m.flags = {WP_TRI_CULL_BACKFACE};
  const Bvh bvh = build(m.input(), wide());
  const Hit front = intersect_closest(bvh, {{0, 0, 1}, {0, 0, -1}});
  EXPECT_TRUE(front.hit);
  EXPECT_FLOAT_EQ(front.t, 1.0f);
  EXPECT_FALSE(intersect_closest(bvh, {{0, 0, -1}, {0, 0, 1}}).hit);
  EXPECT_FALSE(occluded(bvh, {{0, 0, -1}, {0, 0, 1}}));
  EXPECT_FALSE(intersect_closest(bvh, {{0, 0, 1}, {0, 0, -1}, 0.0f, 0.5f}).hit);  // beyond tmax
  EXPECT_FALSE(intersect_closest(bvh, {{0, 0, 1}, {0, 0, -1}, 1.5f}).hit);        // before tmin
}

// ---------------------------------------------------------------------------------------------
// Costs (printed for the record; nothing asserted beyond sanity)

// Seconds per ray of the reference traversal over `rays`.
double seconds_per_ray(const Bvh& bvh, const std::vector<Ray>& rays) {
  const auto start = std::chrono::steady_clock::now();
  std::size_t hits = 0;
  for (const Ray& r : rays) hits += intersect_closest(bvh, r).hit;
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GT(hits, 0u);
  return s / double(rays.size());
}

TEST(Bvh8Build, Soup200kWidth8AgainstWidth2) {
  const Mesh m = soup(200000, 5, 0.01f);
  for (const bool splits : {false, true})
    for (const int width : {2, 8}) {
      BuildOptions o;
      o.width = width;
      o.spatial_splits = splits;
      const Bvh bvh = build(m.input(), o);
      EXPECT_TRUE(std::isfinite(bvh.stats.sah_cost) && bvh.stats.sah_cost > 0);
      const double us = 1e6 * seconds_per_ray(bvh, make_rays(bvh, 20000, 20000, 3));
      std::printf(
          "soup 200k, width %d, splits %d: build %.3f s, SAH %.2f, %zu inner, %zu leaves, %zu "
          "refs, depth %d, reference %.2f us/ray\n",
          width, int(splits), bvh.stats.build_seconds, bvh.stats.sah_cost, bvh.stats.inner_nodes,
          bvh.stats.leaves, bvh.stats.triangle_refs, bvh.stats.max_depth, us);
    }
}

}  // namespace
}  // namespace wp::bvh
