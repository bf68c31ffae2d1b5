// unit tier: the BVH module, binary layout (the wide one: test_bvh8.cpp). Structure
// (check_invariants on many meshes and options), the exact device layout, the build statistics,
// bad input, and the CPU reference traversal against both a brute-force loop over the same
// triangle test and Embree's own rtcIntersect1/rtcOccluded1.
#include <cmath>
#include <cstdio>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "bvh/build_tree.h"  // internal: the spatial-split clipper
#include "bvh/bvh.h"
#include "host/util/error.h"
#include "tests/bvh_test_util.h"

namespace wp::bvh {
namespace {

using namespace test;  // NOLINT: the shared meshes and oracles

// ---------------------------------------------------------------------------------------------
// Structure, layout and statistics

// The SAH cost with unit costs, recomputed from the flattened boxes: the root counts 1, every
// inner child A(child) / A(root), every leaf child count * A(leaf) / A(root).
double recomputed_sah(const Bvh& bvh) {
  const auto area = [](float lx, float hx, float ly, float hy, float lz, float hz) {
    const float x = hx - lx, y = hy - ly, z = hz - lz;
    return 2.0 * double(x * y + y * z + z * x);
  };
  const glm::vec3 lo = bvh.lo, hi = bvh.hi;
  const double root = area(lo.x, hi.x, lo.y, hi.y, lo.z, hi.z);
  double sah = 1.0;
  for (const dev::BvhNode& n : bvh.nodes) {
    const double a0 = area(n.c0_xy.x, n.c0_xy.y, n.c0_xy.z, n.c0_xy.w, n.c01_z.x, n.c01_z.y);
    const double a1 = area(n.c1_xy.x, n.c1_xy.y, n.c1_xy.z, n.c1_xy.w, n.c01_z.z, n.c01_z.w);
    sah += (n.link.x >= 0 ? 1.0 : n.link.z) * a0 / root;
    if (n.link.y >= 0 || n.link.w > 0) sah += (n.link.y >= 0 ? 1.0 : n.link.w) * a1 / root;
  }
  return sah;
}

void expect_valid(const Mesh& mesh, const BuildOptions& options) {
  const Bvh bvh = build(mesh.input(), options);
  EXPECT_EQ(check_invariants(bvh, mesh.triangles(), options.spatial_splits), "");
  const BuildStats& s = bvh.stats;
  EXPECT_EQ(s.inner_nodes, bvh.nodes.size());
  EXPECT_EQ(s.triangle_refs, bvh.triangles.size());
  const bool single_leaf = bvh.nodes[0].link.y < 0 && bvh.nodes[0].link.w == 0;
  EXPECT_EQ(s.leaves, single_leaf ? 1 : bvh.nodes.size() + 1);  // a full binary tree
  EXPECT_GE(s.triangle_refs, mesh.triangles());
  if (!options.spatial_splits) {
    EXPECT_EQ(s.triangle_refs, mesh.triangles());
  }
  EXPECT_TRUE(std::isfinite(s.sah_cost) && s.sah_cost > 0);
  EXPECT_NEAR(s.sah_cost, recomputed_sah(bvh), 1e-9 * s.sah_cost);
  EXPECT_TRUE(s.max_depth >= 1 && s.max_depth <= WP_BVH_MAX_DEPTH);
}

// Every mesh with and without spatial splits, at leaf sizes 1 and 4 in the default suite, also 8
// in ...Exhaustive (slow).
void expect_valid_builds(std::initializer_list<int> leaves) {
  const std::vector<std::pair<const char*, Mesh>> meshes = invariant_meshes();
  for (const auto& [name, mesh] : meshes)
    for (const bool splits : {false, true})
      for (const int leaf : leaves) {
        SCOPED_TRACE(testing::Message() << name << ", splits " << splits << ", leaf " << leaf);
        BuildOptions o;
        o.spatial_splits = splits;
        o.max_leaf_size = leaf;
        expect_valid(mesh, o);
      }
}

TEST(BvhBuild, InvariantsHoldOnManyMeshes) {
  expect_valid_builds({1, 4});
}
TEST(BvhBuild, InvariantsHoldOnManyMeshesExhaustive) {
  expect_valid_builds({1, 4, 8});
}

TEST(BvhBuild, SingleTriangleIsARootWithOneLeafAndAnEmptyChild) {
  Mesh m;
  m.add({0, 0, 0}, {1, 0, 0}, {0, 1, 0.5f});
  m.flags = {WP_TRI_CULL_BACKFACE};
  const Bvh bvh = build(m.input());
  ASSERT_EQ(bvh.nodes.size(), 1u);
  const dev::BvhNode& root = bvh.nodes[0];
  EXPECT_EQ(root.link.x, ~0);
  EXPECT_EQ(root.link.z, 1);
  EXPECT_LT(root.link.y, 0);
  EXPECT_EQ(root.link.w, 0);
  EXPECT_GT(root.c1_xy.x, root.c1_xy.y);  // empty box: lo > hi
  EXPECT_GT(root.c01_z.z, root.c01_z.w);
  EXPECT_EQ(root.c0_xy.y, 1.0f);
  EXPECT_EQ(root.c01_z.y, 0.5f);
  ASSERT_EQ(bvh.triangles.size(), 1u);
  EXPECT_EQ(bits(bvh.triangles[0].v0.w), 0u);
  EXPECT_EQ(bits(bvh.triangles[0].v1.w), WP_TRI_CULL_BACKFACE);
  EXPECT_EQ(bits(bvh.triangles[0].v2.w), 0u);
  EXPECT_EQ(bvh.stats.max_depth, 1);
  EXPECT_EQ(bvh.hi, glm::vec3(1, 1, 0.5f));
}

// A scene without triangles (valid glTF: no nodes, only a camera, only lines) builds without
// Embree: a root alone whose two children are empty (count 0, lo > hi), as the single-leaf root's
// child 1. Its options are still checked.
TEST(BvhBuild, EmptyInputIsARootWithTwoEmptyChildren) {
  for (const bool splits : {false, true}) {
    BuildOptions o;
    o.spatial_splits = splits;
    const Bvh bvh = build(BuildInput{}, o);
    EXPECT_EQ(bvh.width, 2);
    EXPECT_EQ(check_invariants(bvh, 0, splits), "");
    ASSERT_EQ(bvh.nodes.size(), 1u);
    EXPECT_TRUE(bvh.triangles.empty() && bvh.nodes8.empty() && bvh.blocks.empty());
    const dev::BvhNode& root = bvh.nodes[0];
    EXPECT_LT(root.link.x, 0);
    EXPECT_LT(root.link.y, 0);
    EXPECT_EQ(root.link.z, 0);
    EXPECT_EQ(root.link.w, 0);
    EXPECT_GT(root.c0_xy.x, root.c0_xy.y);  // empty boxes: lo > hi
    EXPECT_GT(root.c1_xy.x, root.c1_xy.y);
    EXPECT_GT(root.c01_z.x, root.c01_z.y);
    EXPECT_GT(root.c01_z.z, root.c01_z.w);
    EXPECT_EQ(bvh.stats.inner_nodes, 1u);
    EXPECT_EQ(bvh.stats.leaves, 0u);
    EXPECT_EQ(bvh.stats.triangle_refs, 0u);
    EXPECT_EQ(bvh.stats.max_depth, 1);
    EXPECT_TRUE(std::isfinite(bvh.stats.sah_cost) && bvh.stats.sah_cost > 0);
    // The checks still tell it from a BVH that lost its triangles.
    EXPECT_NE(check_invariants(bvh, 1, splits), "");
  }
  BuildOptions bad;
  bad.max_leaf_size = 0;
  EXPECT_THROW(build(BuildInput{}, bad), Error);
  bad = {};
  bad.width = 3;
  EXPECT_THROW(build(BuildInput{}, bad), Error);
}

// Only a root may have empty children, and child 0 only when child 1 is empty too (the empty
// scene's root).
TEST(BvhBuild, EmptyChildOnlyAtTheRoot) {
  Mesh m;
  m.add({0, 0, 0}, {1, 0, 0}, {0, 1, 0.5f});
  Bvh bvh = build(m.input());
  ASSERT_EQ(check_invariants(bvh, 1, false), "");
  std::swap(bvh.nodes[0].c0_xy, bvh.nodes[0].c1_xy);  // the leaf as child 1, the empty as child 0
  std::swap(bvh.nodes[0].link.x, bvh.nodes[0].link.y);
  std::swap(bvh.nodes[0].link.z, bvh.nodes[0].link.w);
  const float z[4] = {bvh.nodes[0].c01_z.z, bvh.nodes[0].c01_z.w, bvh.nodes[0].c01_z.x,
                      bvh.nodes[0].c01_z.y};
  bvh.nodes[0].c01_z = {z[0], z[1], z[2], z[3]};
  EXPECT_NE(check_invariants(bvh, 1, false), "");
}

TEST(BvhBuild, StoredTrianglesAreTheVerticesWithIndexAndFlags) {
  Mesh m = sphere(16, 32);
  for (std::size_t i = 0; i < m.triangles(); ++i) m.flags.push_back(std::uint32_t(i % 3 == 0));
  const Bvh bvh = build(m.input());
  for (const dev::IsectTri& t : bvh.triangles) {
    const std::uint32_t i = bits(t.v0.w);
    ASSERT_LT(i, m.triangles());
    const glm::vec3 v0 = m.positions[m.indices[3 * i]];
    EXPECT_EQ(glm::vec3(t.v0.x, t.v0.y, t.v0.z), v0);
    EXPECT_EQ(glm::vec3(t.v1.x, t.v1.y, t.v1.z), m.positions[m.indices[3 * i + 1]]);
    EXPECT_EQ(glm::vec3(t.v2.x, t.v2.y, t.v2.z), m.positions[m.indices[3 * i + 2]]);
    EXPECT_EQ(bits(t.v1.w), m.flags[i]);
  }
}

TEST(BvhBuild, SpatialSplitsHappenAndLowerTheSahCostOnLongDiagonals) {
  const Mesh m = long_diagonals(20000, 11, 0.01f);
  BuildOptions o;
  const Bvh plain = build(m.input(), o);
  o.spatial_splits = true;
  const Bvh split = build(m.input(), o);
  EXPECT_EQ(plain.stats.triangle_refs, m.triangles());
  EXPECT_GT(split.stats.triangle_refs, m.triangles());
  EXPECT_LT(split.stats.sah_cost, plain.stats.sah_cost);
  std::printf("long diagonals (%zu): SAH %.1f -> %.1f with splits, %zu refs\n", m.triangles(),
              plain.stats.sah_cost, split.stats.sah_cost, split.stats.triangle_refs);
}

TEST(BvhBuild, Soup200kTimingsAndCosts) {
  const Mesh m = soup(200000, 5, 0.01f);
  for (const bool splits : {false, true}) {
    BuildOptions o;
    o.spatial_splits = splits;
    const Bvh bvh = build(m.input(), o);
    EXPECT_TRUE(std::isfinite(bvh.stats.sah_cost) && bvh.stats.sah_cost > 0);
    std::printf(
        "soup 200k, splits %d: %.3f s, SAH %.2f, %zu inner, %zu leaves, %zu refs, depth %d\n",
        int(splits), bvh.stats.build_seconds, bvh.stats.sah_cost, bvh.stats.inner_nodes,
        bvh.stats.leaves, bvh.stats.triangle_refs, bvh.stats.max_depth);
  }
}

TEST(BvhBuild, ClipperBoundsTheTrianglePieceNotJustTheBox) {
  const glm::vec3 v[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  detail::Box left, right;
  detail::split_triangle_bounds(v, {{0, 0, 0}, {1, 1, 0}}, 0, 0.5f, left, right);
  EXPECT_EQ(left.lo, glm::vec3(0, 0, 0));
  EXPECT_EQ(left.hi, glm::vec3(0.5f, 1, 0));
  EXPECT_EQ(right.lo, glm::vec3(0.5f, 0, 0));
  EXPECT_NEAR(right.hi.y, 0.5f, 1e-7f);  // the piece right of x = 0.5 reaches y = 0.5 only
  EXPECT_EQ(right.hi.x, 1.0f);
  // Clipped to a box first: the part with y <= 0.25 and x >= 0.9 reaches y = 0.1 only.
  detail::split_triangle_bounds(v, {{0, 0, 0}, {1, 0.25f, 0}}, 0, 0.9f, left, right);
  EXPECT_EQ(left.hi, glm::vec3(0.9f, 0.25f, 0));
  EXPECT_NEAR(right.hi.y, 0.1f, 1e-7f);
  EXPECT_GE(right.hi.y, 0.1f - 1e-8f);
  // A plane beyond the piece leaves one side empty.
  detail::split_triangle_bounds(v, {{0.6f, 0, 0}, {1, 0.4f, 0}}, 0, 0.5f, left, right);
  EXPECT_GT(left.lo.x, left.hi.x);
  EXPECT_EQ(right.lo, glm::vec3(0.6f, 0, 0));
}

TEST(BvhBuild, BadInputThrows) {
  Mesh m = soup(10, 1, 0.1f);
  BuildOptions o;
  EXPECT_THROW(build(BuildInput{nullptr, m.indices.data(), m.triangles(), nullptr}), Error);
  for (const int leaf : {0, -1, WP_BVH_MAX_LEAF_SIZE + 1}) {
    o.max_leaf_size = leaf;
    EXPECT_THROW(build(m.input(), o), Error) << leaf;
  }
  o.max_leaf_size = 4;
  o.traversal_cost = 0;
  EXPECT_THROW(build(m.input(), o), Error);
  m.positions[7].y = std::nanf("");
  EXPECT_THROW(build(m.input()), Error);
  m.positions[7].y = INFINITY;
  EXPECT_THROW(build(m.input()), Error);
  try {
    build(m.input());
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("triangle 2"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// Traversal

// Every ray misses the empty scene's BVH: from anywhere, in any direction (the axis-aligned
// positive ones with tmax = +INFINITY included), whatever its tmax.
TEST(BvhTraverse, EmptyInputMissesEveryRay) {
  expect_every_ray_misses(build(BuildInput{}));
}

TEST(BvhTraverse, MatchesEmbree) {
  BuildOptions splits;
  splits.spatial_splits = true;
  std::size_t rays = 0;
  rays += compare_with_embree(sphere(64, 128), {}, 20000, 10000, 1);
  rays += compare_with_embree(soup(20000, 2, 0.02f), {}, 20000, 10000, 2);
  rays += compare_with_embree(grid(100), {}, 20000, 10000, 3);
  rays += compare_with_embree(long_diagonals(5000, 4, 0.25f), splits, 20000, 10000, 4);
  rays += compare_with_embree(sphere(32, 64), splits, 10000, 5000, 5);
  EXPECT_GE(rays, 100000u);
}

// The BVH must find what testing every stored triangle finds, with the same test: including
// back-face culling flags and leaf sizes 1 and 8.
TEST(BvhTraverse, MatchesBruteForceWithTheSameTriangleTest) {
  Mesh m = sphere(24, 48);
  const Mesh g = grid(30);
  const std::size_t base = m.positions.size();
  m.positions.insert(m.positions.end(), g.positions.begin(), g.positions.end());
  for (std::uint32_t i : g.indices) m.indices.push_back(std::uint32_t(base + i));
  for (std::size_t i = 0; i < m.triangles(); ++i)
    m.flags.push_back(i % 2 ? WP_TRI_CULL_BACKFACE : 0);
  for (const int leaf : {1, 8})
    for (const bool splits : {false, true}) {
      BuildOptions o;
      o.max_leaf_size = leaf;
      o.spatial_splits = splits;
      expect_matches_brute_force(m, build(m.input(), o), unsigned(leaf));
    }
}

TEST(BvhTraverse, BackFacesOfCulledTrianglesAreNotThere) {
  Mesh m;
  m.add({-1, -1, 0}, {1, -1, 0}, {0, 1, 0});  // normal +z
  m.flags = {WP_TRI_CULL_BACKFACE};
  const Bvh bvh = build(m.input());
  const Hit front = intersect_closest(bvh, {{0, 0, 1}, {0, 0, -1}});
  EXPECT_TRUE(front.hit);
  EXPECT_FLOAT_EQ(front.t, 1.0f);
  EXPECT_FALSE(intersect_closest(bvh, {{0, 0, -1}, {0, 0, 1}}).hit);
  EXPECT_FALSE(occluded(bvh, {{0, 0, -1}, {0, 0, 1}}));
  EXPECT_FALSE(intersect_closest(bvh, {{0, 0, 1}, {0, 0, -1}, 0.0f, 0.5f}).hit);  // beyond tmax
  EXPECT_FALSE(intersect_closest(bvh, {{0, 0, 1}, {0, 0, -1}, 1.5f}).hit);        // before tmin
}

}  // namespace
}  // namespace wp::bvh
