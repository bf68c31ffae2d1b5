// kernel tier: the ray-tracing stage kernels (intersect_closest, trace_shadow) against Embree's own
// rtcIntersect1 / rtcOccluded1 on the same triangles, on PoCL; for instanced scenes (a two-level
// BVH, WP_BVH_INSTANCES) against Embree's own instancing (RTC_GEOMETRY_TYPE_INSTANCE).
//
// Expected agreement: the same hit/miss and the same triangle, t within 1e-4 relative plus the
// rounding every float implementation has (t_rounding below). The only
// tolerated differences are ties: a ray through a shared edge or vertex may report either
// neighbour, as may a ray through coincident faces (either way both triangles are hit at the same
// t, which is checked), and a ray grazing an edge may hit on one
// side of the rounding and miss on the other (then the hit lies within 1e-4 of the triangle's
// border in barycentric terms). Ties are counted and must stay below 1e-3 of the rays.
#include <embree3/rtcore.h>

#include <cmath>
#include <optional>
#include <random>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "bvh/bvh.h"
#include "bvh/embree_scene.h"
#include "host/accel/bvh_input.h"
#include "host/device/cl_runtime.h"
#include "host/scene/gltf_loader.h"
#include "host/render/wavefront.h"
#include "tests/scene_factory.h"
#include "tests/test_assets.h"

namespace {

using wp::dev::float4;

constexpr std::uint32_t kWave = 1u << 16;

// Embree over the scene's triangles (robust mode): the oracle.
struct EmbreeScene : wp::bvh::EmbreeScene {
  explicit EmbreeScene(const wp::Scene& s)
      : wp::bvh::EmbreeScene(s.positions.data(), s.positions.size(), s.indices.data(),
                             s.triangle_count(), /*robust=*/true) {}
};

// The oracle for an instanced scene: Embree's instances of the scene's meshes. Hits are named by
// their triangle in the scene's flattened twin (flat_twin), as the kernel's are.
struct EmbreeInstanced {
  explicit EmbreeInstanced(const wp::Scene& s)
      : scene(s), embree(wp::embree_instances(s, /*robust=*/true)) {}
  const wp::Scene& scene;
  std::unique_ptr<wp::bvh::EmbreeInstances> embree;
};

// The world of an instanced scene flattened: each instance's triangles mapped into the world, in
// instance order (what its hits are compared in), and where each instance's triangles start.
struct FlatTwin {
  wp::Scene scene;
  std::vector<std::uint32_t> base;
  std::uint32_t triangle(const wp::Scene& instanced, std::uint32_t inst, std::uint32_t tri) const {
    return base[inst] + (tri - instanced.meshes[instanced.instances[inst].mesh].first_triangle);
  }
};
FlatTwin flat_twin(const wp::Scene& s) {
  FlatTwin f;
  f.scene.materials = s.materials;
  for (const wp::Instance& inst : s.instances) {
    f.base.push_back(static_cast<std::uint32_t>(f.scene.triangle_count()));
    const wp::MeshRange& m = s.meshes[inst.mesh];
    for (std::uint32_t t = m.first_triangle; t < m.first_triangle + m.triangle_count; ++t) {
      for (int k = 0; k < 3; ++k) {
        const glm::dvec4 p(s.positions[s.indices[3 * t + k]], 1.0);
        f.scene.indices.push_back(static_cast<std::uint32_t>(f.scene.positions.size()));
        f.scene.positions.push_back(glm::vec3(inst.to_world * p));
        f.scene.normals.push_back({0, 0, 1});
      }
      f.scene.triangle_material.push_back(s.triangle_material[t]);
    }
  }
  wp::test::finish_bounds(f.scene);
  return f;
}

struct Rays {
  std::vector<float4> o, d;  // o.w = tmin, d.w = tmax
};

// Camera-like rays from outside the bounds toward random points inside, and random rays from
// random points inside the bounds in uniformly random directions.
Rays make_rays(const wp::Scene& s, std::size_t count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const glm::vec3 lo = s.bounds_lo, hi = s.bounds_hi, c = 0.5f * (lo + hi);
  const float radius = 0.5f * glm::length(hi - lo) + 1e-3f;
  const auto in_box = [&] { return lo + (hi - lo) * glm::vec3(u(rng), u(rng), u(rng)); };
  const auto on_sphere = [&] {
    const float z = 2.0f * u(rng) - 1.0f, phi = 6.2831853f * u(rng), r = std::sqrt(1 - z * z);
    return glm::vec3(r * std::cos(phi), r * std::sin(phi), z);
  };
  Rays r;
  const glm::vec3 eye = c + 2.5f * radius * on_sphere();
  for (std::size_t i = 0; i < count; ++i) {
    glm::vec3 o, d;
    if (i % 2 == 0) {
      o = eye;
      d = glm::normalize(in_box() - eye);
    } else {
      o = in_box();
      d = on_sphere();
    }
    r.o.push_back({o.x, o.y, o.z, 0.0f});
    r.d.push_back({d.x, d.y, d.z, 1e30f});
  }
  return r;
}

// Rounding in t that no float implementation avoids: a distance computed from vertices of
// magnitude ~ the scene size S carries an absolute error ~ 2^-20 S, magnified by 1/|cos| for a
// ray at angle theta to the triangle's normal. Rays starting within ~1e-6 of a surface (random
// origins do) or grazing it have t relative errors well above 1e-4 from this alone.
float t_rounding(const wp::Scene& s, float cos_theta) {
  const float size = glm::length(s.bounds_hi - s.bounds_lo);
  return std::ldexp(size, -20) / std::max(cos_theta, 1e-3f);
}

// Border distance in barycentrics of the point where the ray crosses triangle `tri`'s plane.
float border_distance(const wp::Scene& s, std::uint32_t tri, glm::vec3 o, glm::vec3 d) {
  const glm::vec3 a = s.positions[s.indices[3 * tri]], b = s.positions[s.indices[3 * tri + 1]],
                  c = s.positions[s.indices[3 * tri + 2]];
  const glm::vec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
  const float det = glm::dot(e1, p);
  if (det == 0.0f) return 0.0f;
  const glm::vec3 t = o - a;
  const float uu = glm::dot(t, p) / det, vv = glm::dot(d, glm::cross(t, e1)) / det;
  return std::min({std::fabs(uu), std::fabs(vv), std::fabs(1.0f - uu - vv)});
}

class IntersectKernel : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { runtime_ = new wp::ClRuntime(wp::select_device("")); }
  static void TearDownTestSuite() {
    delete runtime_;
    runtime_ = nullptr;
  }

  // Traces `rays` through intersect_closest and compares with rtcIntersect1.
  // Both BVH layouts: the binary one (GPUs) and the wide one (CPUs).
  void check_closest(const wp::Scene& scene, const Rays& rays) {
    for (int width : {2, 8}) {
      SCOPED_TRACE("BVH width " + std::to_string(width));
      check_closest(scene, rays, width);
    }
  }
  void check_shadow(const wp::Scene& scene, std::size_t count, std::uint32_t seed) {
    for (int width : {2, 8}) {
      SCOPED_TRACE("BVH width " + std::to_string(width));
      check_shadow(scene, count, seed, width);
    }
  }

  // A hit of the oracle or the kernel: its triangle in `world`'s numbering.
  struct WorldHit {
    bool hit = false;
    float t = 0.0f;
    std::uint32_t tri = 0;
  };

  void check_closest(const wp::Scene& scene, const Rays& rays, int width) {
    if (!scene.instances.empty()) {
      const FlatTwin twin = flat_twin(scene);
      const EmbreeInstanced embree(scene);
      check_closest(
          scene, twin.scene, rays, width,
          [&](const wp::bvh::Ray& r) {
            const wp::bvh::Hit h = embree.embree->intersect(r);
            return WorldHit{h.hit, h.t, h.hit ? twin.triangle(scene, h.instance, h.triangle) : 0};
          },
          [&](std::uint32_t inst, std::uint32_t tri) { return twin.triangle(scene, inst, tri); });
      return;
    }
    const EmbreeScene embree(scene);
    check_closest(
        scene, scene, rays, width,
        [&](const wp::bvh::Ray& r) {
          const wp::bvh::Hit h = embree.intersect(r);
          return WorldHit{h.hit, h.t, h.triangle};
        },
        [](std::uint32_t, std::uint32_t tri) { return tri; });
  }

  // The kernel's hits on `scene` against `oracle`'s, both named by their triangle in `world`
  // (the scene itself, or an instanced scene's flattened twin).
  template <class Oracle, class ToWorld>
  void check_closest(const wp::Scene& scene, const wp::Scene& world, const Rays& rays, int width,
                     Oracle oracle, ToWorld to_world) {
    const wp::bvh::Bvh bvh = build(scene, width);
    wp::Wavefront wf(*runtime_, scene, bvh, settings());
    std::size_t ties = 0, hits = 0;
    for (std::size_t first = 0; first < rays.o.size(); first += kWave) {
      const std::size_t n = std::min<std::size_t>(kWave, rays.o.size() - first);
      const auto& layout = wf.path_state().layout;
      wf.write_paths(layout.ray_o,
                     std::vector<float4>(rays.o.begin() + first, rays.o.begin() + first + n));
      wf.write_paths(layout.ray_d,
                     std::vector<float4>(rays.d.begin() + first, rays.d.begin() + first + n));
      wf.write_queue(WP_QUEUE_RAY_A, identity(n));
      auto p = wf.launch_params(0, 0, static_cast<std::uint32_t>(n));
      p.queue_in = WP_QUEUE_RAY_A;
      wf.launch_stage(wp::Stage::kIntersectClosest, static_cast<std::uint32_t>(n), p);
      const auto hit = wf.read_paths<float4>(layout.hit, n);
      const auto instance = scene.instances.empty()
                                ? std::vector<wp::dev::uint>(n, 0u)
                                : wf.read_paths<wp::dev::uint>(layout.hit_instance, n);
      for (std::size_t i = 0; i < n; ++i) {
        const float4 o = rays.o[first + i], d = rays.d[first + i];
        const glm::vec3 go(o.x, o.y, o.z), gd(d.x, d.y, d.z);
        const WorldHit theirs = oracle(wp::bvh::Ray{go, gd, o.w, d.w});
        WorldHit ours;
        ours.hit = hit[i].x < INFINITY;
        ours.t = hit[i].x;
        std::uint32_t our_tri;
        std::memcpy(&our_tri, &hit[i].w, 4);
        if (ours.hit) ours.tri = to_world(instance[i], our_tri);
        hits += theirs.hit;
        if (ours.hit != theirs.hit) {
          const std::uint32_t tri = ours.hit ? ours.tri : theirs.tri;
          ASSERT_LT(border_distance(world, tri, go, gd), 1e-4f)
              << "hit/miss differs away from an edge, ray " << first + i;
          ++ties;
        } else if (ours.hit) {
          const std::uint32_t* v = &world.indices[3 * std::size_t{theirs.tri}];
          const glm::vec3 ng =
              glm::normalize(glm::cross(world.positions[v[1]] - world.positions[v[0]],
                                        world.positions[v[2]] - world.positions[v[0]]));
          EXPECT_LE(std::fabs(ours.t - theirs.t),
                    1e-4f * theirs.t + t_rounding(world, std::fabs(glm::dot(ng, gd))))
              << "ray " << first + i << ": t " << ours.t << " vs Embree's " << theirs.t;
          // Another triangle at the same t (checked just above) is a tie: a shared edge or
          // vertex, or coincident faces (the CornellBox asset's light lies on its ceiling).
          ties += ours.tri != theirs.tri;
        }
      }
    }
    EXPECT_LT(static_cast<double>(ties), 1e-3 * static_cast<double>(rays.o.size()));
    EXPECT_GT(hits, rays.o.size() / 20) << "the rays should hit the mesh often";
  }

  // Shadow segments between random points; compares trace_shadow with rtcOccluded1.
  void check_shadow(const wp::Scene& scene, std::size_t count, std::uint32_t seed, int width) {
    const wp::bvh::Bvh bvh = build(scene, width);
    wp::Wavefront wf(*runtime_, scene, bvh, settings());
    std::optional<EmbreeScene> flat;
    std::optional<EmbreeInstanced> instanced;
    if (scene.instances.empty())
      flat.emplace(scene);
    else
      instanced.emplace(scene);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const auto in_box = [&] {
      return scene.bounds_lo +
             (scene.bounds_hi - scene.bounds_lo) * glm::vec3(u(rng), u(rng), u(rng));
    };
    std::size_t mismatches = 0, occluded = 0, total = 0;
    for (std::size_t first = 0; first < count; first += kWave) {
      const std::size_t n = std::min<std::size_t>(kWave, count - first);
      std::vector<float4> so(n), sd(n), sl(n, float4{1, 0, 0, 0}), zero(n, float4{0, 0, 0, 0});
      for (std::size_t i = 0; i < n; ++i) {
        const glm::vec3 a = in_box(), b = in_box(), d = glm::normalize(b - a);
        so[i] = {a.x, a.y, a.z, glm::length(b - a)};
        sd[i] = {d.x, d.y, d.z, 0.0f};
      }
      const auto& layout = wf.path_state().layout;
      wf.write_paths(layout.shadow_o, so);
      wf.write_paths(layout.shadow_d, sd);
      wf.write_paths(layout.shadow_l, sl);
      wf.write_paths(layout.radiance, zero);
      wf.write_queue(WP_QUEUE_SHADOW, identity(n));
      wf.launch_stage(wp::Stage::kTraceShadow, static_cast<std::uint32_t>(n),
                      wf.launch_params(0, 0, static_cast<std::uint32_t>(n)));
      const auto radiance = wf.read_paths<float4>(layout.radiance, n);
      for (std::size_t i = 0; i < n; ++i) {
        const wp::bvh::Ray ray{
            {so[i].x, so[i].y, so[i].z}, {sd[i].x, sd[i].y, sd[i].z}, 0.0f, so[i].w};
        const bool theirs = flat ? flat->occluded(ray) : instanced->embree->occluded(ray);
        const bool ours = radiance[i].x == 0.0f;
        occluded += theirs;
        mismatches += ours != theirs;
        ++total;
      }
    }
    // Differences only at grazing ties, which are rare on random segments.
    EXPECT_LT(static_cast<double>(mismatches), 1e-3 * static_cast<double>(total));
    EXPECT_GT(occluded, total / 20);
    EXPECT_LT(occluded, total - total / 20);
  }

  // The scene's BVH without culling flags (Embree culls nothing): one tree, or the two-level BVH
  // of an instanced scene.
  static wp::bvh::Bvh build(const wp::Scene& s, int width) {
    wp::bvh::BuildInput in;
    in.positions = s.positions.data();
    in.indices = s.indices.data();
    in.triangle_count = s.triangle_count();
    wp::bvh::BuildOptions options;
    options.width = width;
    if (s.instances.empty()) return wp::bvh::build(in, options);
    std::vector<wp::bvh::Bvh> meshes;
    std::vector<std::uint32_t> first;
    for (const wp::MeshRange& m : s.meshes) {
      wp::bvh::BuildInput mesh = in;
      mesh.indices += 3 * std::size_t{m.first_triangle};
      mesh.triangle_count = m.triangle_count;
      meshes.push_back(wp::bvh::build(mesh, options));
      first.push_back(m.first_triangle);
    }
    return wp::bvh::build_two_level(std::move(meshes), first, wp::bvh_instances(s), options);
  }
  static wp::RenderSettings settings() {
    wp::RenderSettings s;
    s.width = static_cast<int>(kWave);
    s.height = 1;
    s.wave_size = kWave;  // one ray a path: never a smaller wave from the machine's cache
    return s;
  }
  static std::vector<wp::dev::uint> identity(std::size_t n) {
    std::vector<wp::dev::uint> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<wp::dev::uint>(i);
    return v;
  }

  static wp::ClRuntime* runtime_;
};
wp::ClRuntime* IntersectKernel::runtime_ = nullptr;

wp::Scene one_material_scene() {
  wp::Scene s;
  s.materials.push_back(wp::test::diffuse_material(glm::vec3(0.5f)));
  return s;
}

TEST_F(IntersectKernel, SphereMatchesEmbree) {
  wp::Scene s = one_material_scene();
  wp::test::add_sphere(s, {0, 0, 0}, 1.0f, 96, 192, 0);
  wp::test::add_sphere(s, {0.7f, 0.2f, 0.1f}, 0.5f, 32, 64, 0);  // intersecting spheres
  wp::test::finish_bounds(s);
  check_closest(s, make_rays(s, 100000, 1));
}

TEST_F(IntersectKernel, RandomSoupMatchesEmbree) {
  wp::Scene s = one_material_scene();
  wp::test::add_random_soup(s, 50000, 0.05f, 7, 0);
  wp::test::finish_bounds(s);
  check_closest(s, make_rays(s, 100000, 2));
}

TEST_F(IntersectKernel, ShadowRaysMatchEmbree) {
  wp::Scene s = one_material_scene();
  wp::test::add_random_soup(s, 2000, 0.05f, 9, 0);
  wp::test::add_sphere(s, {0.5f, 0.5f, 0.5f}, 0.3f, 48, 96, 0);
  wp::test::finish_bounds(s);
  check_shadow(s, 100000, 3);
}

// Two meshes (a sphere and a soup) placed 40 times: rotated, scaled 0.3 to 1.5 per axis, one in
// three mirrored, overlapping.
wp::Scene instanced_scene(std::uint32_t seed) {
  wp::Scene s = one_material_scene();
  wp::test::add_sphere(s, {0, 0, 0}, 1.0f, 32, 64, 0);
  s.meshes.push_back({0, static_cast<std::uint32_t>(s.triangle_count())});
  const auto soup_first = static_cast<std::uint32_t>(s.triangle_count());
  wp::test::add_random_soup(s, 2000, 0.05f, seed, 0);
  s.meshes.push_back({soup_first, static_cast<std::uint32_t>(s.triangle_count()) - soup_first});
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 40; ++i) {
    const glm::dvec3 at(4.0 * u(rng), 4.0 * u(rng), 4.0 * u(rng));
    const glm::dvec3 axis = glm::normalize(glm::dvec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5));
    glm::dvec3 scale(0.3 + 1.2 * u(rng), 0.3 + 1.2 * u(rng), 0.3 + 1.2 * u(rng));
    if (i % 3 == 0) scale.z = -scale.z;
    wp::Instance inst;
    inst.to_world = glm::translate(glm::dmat4(1.0), at) *
                    glm::rotate(glm::dmat4(1.0), 6.2831853 * u(rng), axis) *
                    glm::scale(glm::dmat4(1.0), scale);
    inst.mesh = static_cast<std::uint32_t>(i % 2);
    s.instances.push_back(inst);
  }
  const FlatTwin twin = flat_twin(s);
  s.bounds_lo = twin.scene.bounds_lo;
  s.bounds_hi = twin.scene.bounds_hi;
  return s;
}

TEST_F(IntersectKernel, InstancesMatchEmbreeInstancing) {
  const wp::Scene s = instanced_scene(4);
  check_closest(s, make_rays(s, 100000, 7));
}

TEST_F(IntersectKernel, InstancedShadowRaysMatchEmbreeInstancing) {
  const wp::Scene s = instanced_scene(5);
  check_shadow(s, 100000, 8);
}

// Real models, when ../shared/assets is there.
class IntersectModel : public IntersectKernel, public ::testing::WithParamInterface<const char*> {};

TEST_P(IntersectModel, MatchesEmbree) {
  WP_REQUIRE_MODEL(path, GetParam());
  const wp::Scene s = wp::load_gltf(path);
  check_closest(s, make_rays(s, 100000, 5));
  check_shadow(s, 50000, 6);
}

std::string model_name(const ::testing::TestParamInfo<const char*>& info) {
  const std::string n = info.param;
  return n.substr(0, n.find('/'));
}

// A small model in the default suite; the helmets (15,000 and 60,000 triangles, ~20 s each with
// their Embree references) in the slow tier.
INSTANTIATE_TEST_SUITE_P(Assets, IntersectModel,
                         ::testing::Values("CornellBox/CornellBox.glb", "Duck/Duck.glb"),
                         model_name);
INSTANTIATE_TEST_SUITE_P(AssetsExhaustive, IntersectModel,
                         ::testing::Values("DamagedHelmet/DamagedHelmet.glb",
                                           "FlightHelmet/FlightHelmet.gltf"),
                         model_name);

}  // namespace
