// The two-level BVH (bvh.h, build_two_level) against Embree's own instancing
// (RTC_GEOMETRY_TYPE_INSTANCE) and against the same world flattened into one tree, for both
// layouts: rotated, non-uniformly scaled, mirrored and overlapping instances of two meshes.
//
// A hit is compared by its triangle in the flattened world (the instance's first triangle there
// plus the triangle's index in its mesh), with the tolerances and tie rules of the single-level
// tests (bvh_test_util.h, Comparison): the two-level traversal tests a triangle in its mesh's
// space, so t agrees with the world's to the float rounding of the mapping, which those bounds
// (1e-4 relative plus 1e-6 of the scene size along the ray) cover.
#include <cmath>
#include <random>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

#include "tests/bvh_test_util.h"

namespace wp::bvh {
namespace {

using namespace test;

// Meshes in one vertex/index array, their placements, and the world they make flattened.
struct InstancedWorld {
  Mesh meshes;  // all meshes' triangles; mesh i is [first[i], first[i] + count[i])
  std::vector<std::uint32_t> first, count;
  std::vector<InstanceInput> instances;
  Mesh flat;  // every instance's triangles in world space, instance by instance
  std::vector<std::uint32_t> base;  // per instance: its first triangle in `flat`

  void add_mesh(const Mesh& m) {
    const auto v0 = static_cast<std::uint32_t>(meshes.positions.size());
    first.push_back(static_cast<std::uint32_t>(meshes.triangles()));
    count.push_back(static_cast<std::uint32_t>(m.triangles()));
    meshes.positions.insert(meshes.positions.end(), m.positions.begin(), m.positions.end());
    for (std::uint32_t i : m.indices) meshes.indices.push_back(v0 + i);
    meshes.flags.insert(meshes.flags.end(), m.flags.begin(), m.flags.end());
  }
  void place(std::uint32_t mesh, const glm::dmat4& to_world) {
    instances.push_back({to_world, mesh});
    base.push_back(static_cast<std::uint32_t>(flat.triangles()));
    for (std::uint32_t t = first[mesh]; t < first[mesh] + count[mesh]; ++t) {
      glm::vec3 v[3];
      for (int k = 0; k < 3; ++k)
        v[k] = glm::vec3(to_world * glm::dvec4(meshes.positions[meshes.indices[3 * t + k]], 1.0));
      flat.add(v[0], v[1], v[2]);
    }
  }
  // The flattened world's triangle of a hit of the two-level BVH or of Embree's instances.
  Hit to_flat(Hit h) const {
    if (h.hit) h.triangle = base[h.instance] + (h.triangle - first[instances[h.instance].mesh]);
    return h;
  }
  Bvh build(const BuildOptions& options) const {
    std::vector<Bvh> trees;
    for (std::size_t i = 0; i < first.size(); ++i) {
      BuildInput in = meshes.input();
      in.indices += 3 * std::size_t{first[i]};
      if (in.triangle_flags) in.triangle_flags += first[i];
      in.triangle_count = count[i];
      trees.push_back(bvh::build(in, options));
    }
    return build_two_level(std::move(trees), first, instances, options);
  }
};

// A sphere and a triangle soup, placed 48 times over a 3 x 3 x 3 region: random rotations, scales
// 0.3 to 1.5 per axis, one in three mirrored (a negative x scale), near enough to overlap.
InstancedWorld random_world(unsigned seed) {
  InstancedWorld w;
  w.add_mesh(sphere(16, 32));
  w.add_mesh(soup(400, seed, 0.1f));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 48; ++i) {
    const glm::dvec3 at(3.0 * u(rng), 3.0 * u(rng), 3.0 * u(rng));
    const glm::dquat q =
        glm::normalize(glm::dquat(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5));
    glm::dvec3 scale(0.3 + 1.2 * u(rng), 0.3 + 1.2 * u(rng), 0.3 + 1.2 * u(rng));
    if (i % 3 == 0) scale.x = -scale.x;
    const glm::dmat4 m = glm::translate(glm::dmat4(1.0), at) * glm::mat4_cast(q) *
                         glm::scale(glm::dmat4(1.0), scale);
    w.place(static_cast<std::uint32_t>(i % 2), m);
  }
  return w;
}

// The two-level reference traversal against Embree's instancing and against the flattened
// world's single-level reference, on camera and interior rays (both with closest and any hit).
std::size_t compare(const InstancedWorld& w, int width, unsigned seed) {
  BuildOptions options;
  options.width = width;
  const Bvh two = w.build(options);
  EXPECT_EQ(two.instances.size(), w.instances.size());
  const Bvh flat = bvh::build(w.flat.input(), options);
  std::vector<EmbreeInstances::MeshRange> ranges;
  for (std::size_t i = 0; i < w.first.size(); ++i) ranges.push_back({w.first[i], w.count[i]});
  const EmbreeInstances embree(w.meshes.positions.data(), w.meshes.indices.data(), ranges,
                               w.instances, /*robust=*/true);
  Comparison vs_embree(w.flat, flat), vs_flat(w.flat, flat);
  std::size_t hits = 0;
  for (const Ray& ray : make_rays(flat, 30000, 30000, seed)) {
    const Hit ref = w.to_flat(intersect_closest(two, ray));
    const bool ref_occluded = occluded(two, ray);
    EXPECT_EQ(ref_occluded, ref.hit);
    hits += ref.hit;
    if (vs_embree.agree(ray, ref, w.to_flat(embree.intersect(ray)))) {
      EXPECT_EQ(ref_occluded, embree.occluded(ray));
    }
    vs_flat.agree(ray, ref, intersect_closest(flat, ray));
  }
  std::printf("width %d: %zu rays, %zu hits, %zu ties with Embree, %zu with the flat tree\n", width,
              vs_embree.rays(), hits, vs_embree.ties(), vs_flat.ties());
  EXPECT_GT(hits, vs_embree.rays() / 10);
  EXPECT_LT(double(vs_embree.ties()), 1e-3 * double(vs_embree.rays()));
  EXPECT_LT(double(vs_flat.ties()), 1e-3 * double(vs_flat.rays()));
  return vs_embree.rays();
}

TEST(BvhInstances, MatchEmbreeInstancingAndTheFlattenedWorld) {
  std::size_t rays = 0;
  rays += compare(random_world(11), 2, 1);
  rays += compare(random_world(12), 8, 2);
  EXPECT_GE(rays, 100000u);
}

// The top-level tree's leaves reference every instance once (binary) or once among their blocks'
// lanes, the rest WP_NO_INSTANCE (wide); each instance's root is its mesh's tree's root node.
TEST(BvhInstances, TopLevelReferencesEveryInstanceOnce) {
  const InstancedWorld w = random_world(3);
  for (const int width : {2, 8}) {
    BuildOptions options;
    options.width = width;
    const Bvh two = w.build(options);
    std::vector<int> seen(w.instances.size(), 0);
    for (const std::uint32_t r : two.instance_refs) {
      if (r == WP_NO_INSTANCE) continue;
      ASSERT_LT(r, w.instances.size());
      ++seen[r];
    }
    for (std::size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], 1) << "instance " << i;
    EXPECT_EQ(two.instances[0].meta.x, two.instances[2].meta.x);  // both place mesh 0
    EXPECT_NE(two.instances[0].meta.x, two.instances[1].meta.x);
    EXPECT_EQ(two.instances[0].meta.z, std::uint32_t{WP_INSTANCE_MIRROR});  // i % 3 == 0
    EXPECT_EQ(two.instances[1].meta.z, 0u);
  }
}

// A single-sided triangle keeps its front under a mirroring instance: glTF's front is where the
// object-space normal, mapped by the inverse transpose, points (the winding reverses in the
// world). Its front is +z, also mirrored in x; mirrored (and stretched) in z it is -z.
TEST(BvhInstances, MirroredInstancesCullTheirBackFaces) {
  Mesh tri;
  tri.add({-1, -1, 0}, {1, -1, 0}, {0, 1, 0});  // counter-clockwise seen from +z
  tri.flags = {WP_TRI_CULL_BACKFACE};
  for (const int width : {2, 8}) {
    for (const glm::dvec3 scale :
         {glm::dvec3(1, 1, 1), glm::dvec3(-1, 1, 1), glm::dvec3(1, 1, -2)}) {
      InstancedWorld w;
      w.add_mesh(tri);
      w.place(0, glm::scale(glm::dmat4(1.0), scale));
      BuildOptions options;
      options.width = width;
      const Bvh two = w.build(options);
      const float front = scale.z > 0 ? 1.0f : -1.0f;
      const Hit h = intersect_closest(two, {{0, 0, 3 * front}, {0, 0, -front}});
      EXPECT_TRUE(h.hit) << "scale " << scale.x << " " << scale.z;
      EXPECT_FLOAT_EQ(h.t, 3.0f);
      EXPECT_FALSE(intersect_closest(two, {{0, 0, -3 * front}, {0, 0, front}}).hit);
      EXPECT_FALSE(occluded(two, {{0, 0, -3 * front}, {0, 0, front}}));
    }
  }
}

TEST(BvhInstances, ASingularTransformIsAnError) {
  InstancedWorld w;
  w.add_mesh(sphere(4, 8));
  w.place(0, glm::scale(glm::dmat4(1.0), glm::dvec3(1.0, 0.0, 1.0)));
  EXPECT_THROW(w.build({}), Error);
}

// An instance of a mesh without triangles is left out; a world of none misses every ray.
TEST(BvhInstances, InstancesOfAnEmptyMeshAreLeftOut) {
  InstancedWorld w;
  w.add_mesh(Mesh{});
  w.place(0, glm::dmat4(1.0));
  for (const int width : {2, 8}) {
    BuildOptions options;
    options.width = width;
    const Bvh two = w.build(options);
    EXPECT_TRUE(two.instances.empty());
    EXPECT_FALSE(intersect_closest(two, {{0, 0, 5}, {0, 0, -1}}).hit);
  }
}

}  // namespace
}  // namespace wp::bvh
