// Tier 1: the BVH module. Structure (check_invariants on many meshes and options), the exact
// device layout, the build statistics, bad input, and the CPU reference traversal against both a
// brute-force loop over the same triangle test and Embree's own rtcIntersect1/rtcOccluded1.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include <embree3/rtcore.h>
#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "bvh/build_tree.h"  // internal: the spatial-split clipper
#include "bvh/bvh.h"
#include "host/error.h"

namespace wp::bvh {
namespace {

std::uint32_t bits(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

// ---------------------------------------------------------------------------------------------
// Meshes

struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> indices;
  std::vector<std::uint32_t> flags;  // per triangle, or empty for none

  std::size_t triangles() const { return indices.size() / 3; }
  void add(glm::vec3 a, glm::vec3 b, glm::vec3 c) {
    const auto base = static_cast<std::uint32_t>(positions.size());
    positions.insert(positions.end(), {a, b, c});
    indices.insert(indices.end(), {base, base + 1, base + 2});
  }
  BuildInput input() const {
    return BuildInput{positions.data(), indices.data(), triangles(),
                      flags.empty() ? nullptr : flags.data()};
  }
};

glm::vec3 random_in(std::mt19937& rng, float lo, float hi) {
  std::uniform_real_distribution<float> u(lo, hi);
  const float x = u(rng), y = u(rng), z = u(rng);
  return {x, y, z};
}

glm::vec3 random_direction(std::mt19937& rng) {
  std::normal_distribution<float> n;
  for (;;) {
    const float x = n(rng), y = n(rng), z = n(rng);
    const glm::vec3 d(x, y, z);
    if (glm::length(d) > 1e-3f) return glm::normalize(d);
  }
}

// Triangles with corners within `size` of a centre uniform in the unit cube.
Mesh soup(std::size_t n, unsigned seed, float size) {
  std::mt19937 rng(seed);
  Mesh m;
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3 c = random_in(rng, 0, 1);
    m.add(c + random_in(rng, -size, size), c + random_in(rng, -size, size),
          c + random_in(rng, -size, size));
  }
  return m;
}

// Long thin triangles (`width` across) along the cube's diagonals: what spatial splits are for.
Mesh long_diagonals(std::size_t n, unsigned seed, float width) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  Mesh m;
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3 sign(u(rng) < 0.5f ? -1 : 1, u(rng) < 0.5f ? -1 : 1, u(rng) < 0.5f ? -1 : 1);
    const glm::vec3 a = random_in(rng, 0, 1);
    const glm::vec3 b = a + (0.5f + 0.5f * u(rng)) * sign;
    m.add(a, b, b + random_in(rng, -width, width));
  }
  return m;
}

// A UV sphere of radius 1 with shared vertices (triangle fans at the poles, no degenerates).
Mesh sphere(int rings, int segments) {
  Mesh m;
  const float pi = 3.14159265f;
  m.positions.push_back({0, 0, 1});
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const float th = pi * float(r) / float(rings), ph = 2 * pi * float(s) / float(segments);
      m.positions.push_back(
          {std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)});
    }
  m.positions.push_back({0, 0, -1});
  const auto at = [&](int r, int s) {
    return std::uint32_t(1 + (r - 1) * segments + s % segments);
  };
  const auto south = std::uint32_t(m.positions.size() - 1);
  for (int s = 0; s < segments; ++s) {
    m.indices.insert(m.indices.end(), {0u, at(1, s), at(1, s + 1)});
    m.indices.insert(m.indices.end(), {south, at(rings - 1, s + 1), at(rings - 1, s)});
    for (int r = 1; r + 1 < rings; ++r) {
      m.indices.insert(m.indices.end(), {at(r, s), at(r + 1, s), at(r + 1, s + 1)});
      m.indices.insert(m.indices.end(), {at(r, s), at(r + 1, s + 1), at(r, s + 1)});
    }
  }
  return m;
}

// An n x n heightfield over [0,1]^2: many shared edges and vertices.
Mesh grid(int n) {
  Mesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const float x = float(i) / float(n), y = float(j) / float(n);
      m.positions.push_back({x, y, 0.1f * std::sin(6 * x) * std::cos(5 * y)});
    }
  const auto at = [&](int i, int j) { return std::uint32_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      m.indices.insert(m.indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.indices.insert(m.indices.end(), {at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return m;
}

// Zero-area triangles (points, segments, repeated ones) mixed into a small soup.
Mesh degenerate() {
  Mesh m = soup(60, 7, 0.1f);
  std::mt19937 rng(8);
  for (int i = 0; i < 40; ++i) {
    const glm::vec3 p = random_in(rng, 0, 1), q = random_in(rng, 0, 1);
    m.add(p, p, p);               // a point
    m.add(p, q, 0.5f * (p + q));  // a segment
    m.add(p, p + glm::vec3(0, 0, 1e-3f), p);
  }
  for (int i = 0; i < 30; ++i) m.add({2, 2, 2}, {2, 2, 2}, {2, 2, 2});  // all in one spot
  return m;
}

float scene_size(const Bvh& bvh) {
  return glm::length(bvh.hi - bvh.lo);
}

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

TEST(BvhBuild, InvariantsHoldOnManyMeshes) {
  const std::vector<std::pair<const char*, Mesh>> meshes = {
      {"1 triangle", soup(1, 1, 0.3f)},
      {"2 triangles", soup(2, 2, 0.3f)},
      {"7 triangles", soup(7, 3, 0.3f)},
      {"soup 1000", soup(1000, 4, 0.05f)},
      {"soup 200k", soup(200000, 5, 0.01f)},
      {"sphere", sphere(48, 96)},
      {"grid", grid(80)},
      {"degenerate", degenerate()},
      {"long diagonals", long_diagonals(3000, 6, 0.01f)}};
  for (const auto& [name, mesh] : meshes)
    for (const bool splits : {false, true})
      for (const int leaf : {1, 4, 8}) {
        SCOPED_TRACE(testing::Message() << name << ", splits " << splits << ", leaf " << leaf);
        BuildOptions o;
        o.spatial_splits = splits;
        o.max_leaf_size = leaf;
        expect_valid(mesh, o);
      }
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
  EXPECT_EQ(bits(bvh.triangles[0].e1.w), WP_TRI_CULL_BACKFACE);
  EXPECT_EQ(bits(bvh.triangles[0].e2.w), 0u);
  EXPECT_EQ(bvh.stats.max_depth, 1);
  EXPECT_EQ(bvh.hi, glm::vec3(1, 1, 0.5f));
}

TEST(BvhBuild, StoredTrianglesAreVertexAndEdgesWithIndexAndFlags) {
  Mesh m = sphere(16, 32);
  for (std::size_t i = 0; i < m.triangles(); ++i) m.flags.push_back(std::uint32_t(i % 3 == 0));
  const Bvh bvh = build(m.input());
  for (const dev::IsectTri& t : bvh.triangles) {
    const std::uint32_t i = bits(t.v0.w);
    ASSERT_LT(i, m.triangles());
    const glm::vec3 v0 = m.positions[m.indices[3 * i]];
    const glm::vec3 e1 = m.positions[m.indices[3 * i + 1]] - v0;
    const glm::vec3 e2 = m.positions[m.indices[3 * i + 2]] - v0;
    EXPECT_EQ(glm::vec3(t.v0.x, t.v0.y, t.v0.z), v0);
    EXPECT_EQ(glm::vec3(t.e1.x, t.e1.y, t.e1.z), e1);
    EXPECT_EQ(glm::vec3(t.e2.x, t.e2.y, t.e2.z), e2);
    EXPECT_EQ(bits(t.e1.w), m.flags[i]);
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
  EXPECT_THROW(build(BuildInput{m.positions.data(), m.indices.data(), 0, nullptr}), Error);
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

// Embree's own BVH and intersector over the same triangles: the independent oracle.
class EmbreeScene {
 public:
  explicit EmbreeScene(const Mesh& m) : device_(rtcNewDevice(nullptr)) {
    scene_ = rtcNewScene(device_);
    rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m.positions.size()));
    std::memcpy(v, m.positions.data(), m.positions.size() * sizeof(glm::vec3));
    auto* i = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), m.triangles()));
    std::memcpy(i, m.indices.data(), m.indices.size() * sizeof(std::uint32_t));
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene_, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene_);
  }
  ~EmbreeScene() {
    rtcReleaseScene(scene_);
    rtcReleaseDevice(device_);
  }
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  Hit intersect(const Ray& r) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh{};
    rh.ray = to_rtc(r);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &ctx, &rh);
    Hit h;
    h.hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    h.t = rh.ray.tfar, h.u = rh.hit.u, h.v = rh.hit.v, h.triangle = rh.hit.primID;
    return h;
  }
  bool occluded(const Ray& r) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay ray = to_rtc(r);
    rtcOccluded1(scene_, &ctx, &ray);
    return ray.tfar < 0;  // Embree marks an occluded ray with tfar = -inf
  }

 private:
  // Embree accepts t in [tnear, tfar], the reference (tmin, tmax): they differ only on the bounds.
  static RTCRay to_rtc(const Ray& r) {
    RTCRay ray{};
    ray.org_x = r.o.x, ray.org_y = r.o.y, ray.org_z = r.o.z, ray.tnear = r.tmin;
    ray.dir_x = r.d.x, ray.dir_y = r.d.y, ray.dir_z = r.d.z, ray.tfar = r.tmax;
    ray.mask = ~0u;
    return ray;
  }
  RTCDevice device_;
  RTCScene scene_ = nullptr;
};

// Camera rays from outside the bounds through a jittered pixel grid, and rays from random points
// inside the bounds in random directions (every other one with a finite tmax, as shadow rays).
std::vector<Ray> make_rays(const Bvh& bvh, std::size_t camera, std::size_t inside, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  const glm::vec3 centre = 0.5f * (bvh.lo + bvh.hi);
  const float size = scene_size(bvh);
  const glm::vec3 eye = centre + size * glm::normalize(glm::vec3(0.4f, -0.7f, 0.6f));
  const glm::vec3 fwd = glm::normalize(centre - eye);
  const glm::vec3 right = glm::normalize(glm::cross(fwd, glm::vec3(0, 0, 1)));
  const glm::vec3 up = glm::cross(right, fwd);
  const auto side = static_cast<std::size_t>(std::sqrt(double(camera))) + 1;
  std::vector<Ray> rays;
  for (std::size_t i = 0; i < camera; ++i) {
    const float x = (float(i % side) + u(rng)) / float(side) - 0.5f;
    const float y = (float(i / side) + u(rng)) / float(side) - 0.5f;
    rays.push_back({eye, glm::normalize(fwd + 0.6f * (x * right + y * up)), 0.0f, 1e30f});
  }
  for (std::size_t i = 0; i < inside; ++i) {
    const glm::vec3 o = bvh.lo + glm::vec3(u(rng), u(rng), u(rng)) * (bvh.hi - bvh.lo);
    rays.push_back({o, random_direction(rng), 0.0f, i % 2 ? u(rng) * size : 1e30f});
  }
  return rays;
}

float distance_to_segment(glm::vec3 p, glm::vec3 a, glm::vec3 b) {
  const glm::vec3 ab = b - a;
  const float len2 = glm::dot(ab, ab);
  const float s = len2 > 0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
  return glm::length(p - (a + s * ab));
}

// Compares the reference hit `ref` with another intersector's `other` for one ray. Equal
// triangles must agree on t (see t_tolerance). A different answer is accepted only as a tie, and
// counted: either the nearer hit lies within 1e-5 of the scene size of an edge of its triangle
// (a ray grazing an edge may or may not hit it), or both hit at the same t and one of them is that
// close to an edge or the other's triangle, tested alone with the reference test, gives that t.
class Comparison {
 public:
  Comparison(const Bvh& bvh, std::size_t triangle_count) : bvh_(bvh), slot_(triangle_count) {
    for (std::size_t i = 0; i < bvh.triangles.size(); ++i) slot_[bits(bvh.triangles[i].v0.w)] = i;
    size_ = scene_size(bvh);
    edge_eps_ = 1e-5f * size_;
  }

  // Returns false on a tie, true on agreement; fails the test on a real mismatch.
  bool agree(const Ray& ray, const Hit& ref, const Hit& other) {
    ++rays_;
    if (!ref.hit && !other.hit) return true;
    if (ref.hit && other.hit && ref.triangle == other.triangle) {
      EXPECT_NEAR(ref.t, other.t, t_tolerance(ray, ref)) << describe(ray);
      return true;
    }
    // Either the nearer hit grazes an edge of its triangle (the other intersector may pass it by),
    // or both hit at the same t across a shared edge.
    const Hit& nearer = !other.hit || (ref.hit && ref.t <= other.t) ? ref : other;
    const bool shared_edge =
        ref.hit && other.hit && std::fabs(ref.t - other.t) <= t_tolerance(ray, ref) &&
        (near_edge(ray, ref) || near_edge(ray, other) || alone_agrees(ray, ref, other));
    const bool tie = near_edge(ray, nearer) || shared_edge;
    EXPECT_TRUE(tie) << "hit " << ref.hit << " tri " << ref.triangle << " t " << ref.t << " vs hit "
                     << other.hit << " tri " << other.triangle << " t " << other.t << "; "
                     << describe(ray);
    ++ties_;
    return false;
  }
  std::size_t rays() const { return rays_; }
  std::size_t ties() const { return ties_; }

 private:
  bool near_edge(const Ray& ray, const Hit& h) const {
    const dev::IsectTri& t = bvh_.triangles[slot_[h.triangle]];
    const glm::vec3 v0(t.v0.x, t.v0.y, t.v0.z);
    const glm::vec3 v1 = v0 + glm::vec3(t.e1.x, t.e1.y, t.e1.z);
    const glm::vec3 v2 = v0 + glm::vec3(t.e2.x, t.e2.y, t.e2.z);
    const glm::vec3 p = ray.o + h.t * ray.d;
    return std::min({distance_to_segment(p, v0, v1), distance_to_segment(p, v1, v2),
                     distance_to_segment(p, v2, v0)}) < edge_eps_;
  }
  // 1e-4 relative, plus the float precision of positions in the scene (1e-6 of its size) seen
  // along the ray: that dominates for hits close to the origin and at grazing angles.
  float t_tolerance(const Ray& ray, const Hit& h) const {
    const dev::IsectTri& t = bvh_.triangles[slot_[h.triangle]];
    const glm::vec3 n =
        glm::cross(glm::vec3(t.e1.x, t.e1.y, t.e1.z), glm::vec3(t.e2.x, t.e2.y, t.e2.z));
    const float cos = std::fabs(glm::dot(n, ray.d)) / (glm::length(n) * glm::length(ray.d));
    return 1e-4f * h.t + 1e-6f * size_ / std::max(cos, 1e-3f);
  }
  // Both hit, and the other's triangle tested alone with the reference test gives the same t.
  bool alone_agrees(const Ray& ray, const Hit& ref, const Hit& other) const {
    Hit alone;
    return ref.hit && other.hit &&
           intersect_triangle(bvh_.triangles[slot_[other.triangle]], ray, 1e30f, alone) &&
           std::fabs(alone.t - ref.t) <= t_tolerance(ray, ref);
  }
  static std::string describe(const Ray& r) {
    char s[200];
    std::snprintf(s, sizeof s, "ray o (%.9g %.9g %.9g) d (%.9g %.9g %.9g) tmax %g", r.o.x, r.o.y,
                  r.o.z, r.d.x, r.d.y, r.d.z, r.tmax);
    return s;
  }

  const Bvh& bvh_;
  std::vector<std::size_t> slot_;  // scene triangle -> one of its slots in bvh.triangles
  float size_ = 0, edge_eps_ = 0;
  std::size_t rays_ = 0, ties_ = 0;
};

// Reference closest hit and occlusion vs Embree; returns the number of rays.
std::size_t compare_with_embree(const Mesh& mesh, const BuildOptions& options, std::size_t camera,
                                std::size_t inside, unsigned seed) {
  const Bvh bvh = build(mesh.input(), options);
  const EmbreeScene embree(mesh);
  Comparison cmp(bvh, mesh.triangles());
  std::size_t hits = 0;
  for (const Ray& ray : make_rays(bvh, camera, inside, seed)) {
    const Hit ref = intersect_closest(bvh, ray);
    const bool ref_occluded = occluded(bvh, ray);
    EXPECT_EQ(ref_occluded, ref.hit);  // same boxes, no tmax shrinking: exactly equal
    hits += ref.hit;
    if (cmp.agree(ray, ref, embree.intersect(ray))) {
      EXPECT_EQ(ref_occluded, embree.occluded(ray));
    }
  }
  std::printf("%zu rays, %zu hits, %zu ties\n", cmp.rays(), hits, cmp.ties());
  EXPECT_GT(hits, cmp.rays() / 10);
  EXPECT_LT(double(cmp.ties()), 1e-3 * double(cmp.rays()));
  return cmp.rays();
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
      const Bvh bvh = build(m.input(), o);
      Comparison cmp(bvh, m.triangles());
      for (const Ray& ray : make_rays(bvh, 3000, 3000, unsigned(leaf))) {
        Hit brute;
        float tmax = ray.tmax;
        for (const dev::IsectTri& t : bvh.triangles)
          if (intersect_triangle(t, ray, tmax, brute)) tmax = brute.t;
        const Hit ref = intersect_closest(bvh, ray);
        if (ref.hit && brute.hit && ref.triangle == brute.triangle) {
          EXPECT_EQ(ref.t, brute.t);
        }
        cmp.agree(ray, ref, brute);
      }
      EXPECT_LT(double(cmp.ties()), 1e-3 * double(cmp.rays()));
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
