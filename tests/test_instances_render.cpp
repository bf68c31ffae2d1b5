// Instancing renders what flattening renders (scene tier).
//
// EXT_mesh_gpu_instancing renders as the same scene written without it: the shared
// SimpleInstancing (125 instances of a cube) against a twin written at test time whose instances
// are child nodes of the instancing node, each with the instance's translation, rotation and scale.
// The extension's order (node world x T x R x S) and the node hierarchy's give the same matrices,
// so the same instances in the same order and the same image bit for bit.
//
// A scene loaded with each mesh once and its placements as instances (a two-level BVH) renders
// the image its flattened load renders, within the standard error, for both BVH layouts: smooth
// spheres stretched, rotated and mirrored, emissive quads placed three times (three lights, one
// mirrored), see-through (alpha BLEND) quads, one of them mirrored.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "host/accel/bvh_input.h"
#include "host/device/device_scene.h"
#include "host/render/render.h"
#include "tests/device_test.h"
#include "tests/gltf/compress_twin.h"
#include "tests/gltf/gltf_files.h"
#include "tests/same_estimate.h"
#include "tests/test_assets.h"

namespace {

using namespace wp;        // NOLINT(google-build-using-namespace)
using namespace wp::test;  // NOLINT(google-build-using-namespace)
using nlohmann::json;

const auto* const kCleanup = ::testing::AddGlobalTestEnvironment(new gltf_files::TempCleanup);

// The floats of accessor `index` (tightly packed FLOAT VECn, as SimpleInstancing has them).
std::vector<float> floats(const json& gltf, const std::vector<unsigned char>& bin, int index,
                          int components) {
  const json& a = gltf["accessors"][std::size_t(index)];
  const json& v = gltf["bufferViews"][a["bufferView"].get<std::size_t>()];
  const std::size_t at =
      v.value("byteOffset", std::size_t{0}) + a.value("byteOffset", std::size_t{0});
  std::vector<float> out(a["count"].get<std::size_t>() * std::size_t(components));
  std::memcpy(out.data(), bin.data() + at, out.size() * sizeof(float));
  return out;
}

// The twin: each node with the extension loses its mesh and gains one child per instance.
Glb without_instancing(const Glb& in) {
  json g = json::parse(in.json);
  json& nodes = g["nodes"];
  const std::size_t count = nodes.size();
  for (std::size_t n = 0; n < count; ++n) {
    if (!nodes[n].contains("extensions")) continue;
    const json attributes = nodes[n]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"];
    const std::vector<float> t = floats(g, in.bin, attributes["TRANSLATION"].get<int>(), 3);
    const std::vector<float> r = floats(g, in.bin, attributes["ROTATION"].get<int>(), 4);
    const std::vector<float> s = floats(g, in.bin, attributes["SCALE"].get<int>(), 3);
    const int mesh = nodes[n]["mesh"].get<int>();
    nodes[n].erase("extensions");
    nodes[n].erase("mesh");
    for (std::size_t i = 0; i < t.size() / 3; ++i) {
      nodes[n]["children"].push_back(nodes.size());
      nodes.push_back({{"mesh", mesh},
                       {"translation", {t[3 * i], t[3 * i + 1], t[3 * i + 2]}},
                       {"rotation", {r[4 * i], r[4 * i + 1], r[4 * i + 2], r[4 * i + 3]}},
                       {"scale", {s[3 * i], s[3 * i + 1], s[3 * i + 2]}}});
    }
  }
  g.erase("extensionsUsed");
  g.erase("extensionsRequired");
  return {g.dump(), in.bin};
}

class InstancesRender : public DeviceTest {};

TEST_F(InstancesRender, GpuInstancesRenderAsTheirNodeTwin) {
  WP_REQUIRE_MODEL(path, "SimpleInstancing/SimpleInstancing.glb");
  const Glb glb = read_glb(path);
  const std::string twin = (gltf_files::temp_dir() / "simple_instancing_nodes.glb").string();
  write_file(twin, glb_bytes(without_instancing(glb)));
  const Scene a = load_gltf(path), b = load_gltf(twin);
  ASSERT_EQ(a.world_triangle_count(), 125u * 12u);
  ASSERT_EQ(a.instances.size(), 125u);  // the default: each mesh once, its placements instanced
  ASSERT_EQ(b.instances.size(), a.instances.size());
  EXPECT_EQ(b.gltf.gpu_instances, 0u);
  EXPECT_EQ(b.positions, a.positions);
  for (std::size_t i = 0; i < a.instances.size(); ++i)
    EXPECT_EQ(b.instances[i].to_world, a.instances[i].to_world) << "instance " << i;
  RenderSettings s = twin_settings(48, 36, 4, 3, 1.0f);
  s.view.orbit = glm::vec3(35.0f, 60.0f, 0.0f);  // from above and aside: every row in sight
  const Rendered ra = render(*runtime_, a, s), rb = render(*runtime_, b, s);
  EXPECT_EQ(ra.image.rgb, rb.image.rgb);
  std::size_t covered = 0;  // pixels darker than the sky: the cubes are there
  for (std::size_t i = 0; i < ra.image.rgb.size(); i += 3) covered += ra.image.rgb[i] < 0.9f;
  EXPECT_GT(covered, ra.image.rgb.size() / 3 / 10);
}

// Spheres, lights and see-through quads, each mesh placed several times (the file comment).
std::string instanced_scene() {
  gltf_files::Gltf g;
  std::vector<glm::vec3> sp, sn;  // a UV sphere of radius 0.5 with smooth normals
  std::vector<std::uint16_t> si;
  const int rings = 12, segments = 24;
  for (int r = 0; r <= rings; ++r)
    for (int k = 0; k <= segments; ++k) {
      const float th = 3.14159265f * float(r) / rings, ph = 6.2831853f * float(k) / segments;
      const glm::vec3 n(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
      sn.push_back(n);
      sp.push_back(0.5f * n);
    }
  for (int r = 0; r < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      const auto a = std::uint16_t(r * (segments + 1) + k), b = std::uint16_t(a + segments + 1);
      si.insert(si.end(),
                {a, std::uint16_t(a + 1), b, std::uint16_t(a + 1), std::uint16_t(b + 1), b});
    }
  const int sphere_pos = g.vec3s(sp), sphere_nrm = g.vec3s(sn), sphere_idx = g.indices(si);
  const int quad_pos =
      g.vec3s({{-0.5f, -0.5f, 0}, {0.5f, -0.5f, 0}, {0.5f, 0.5f, 0}, {-0.5f, 0.5f, 0}});
  const int quad_nrm = g.vec3s({{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}});
  const int quad_idx = g.indices<std::uint16_t>({0, 1, 2, 0, 2, 3});
  g.materials = {
      R"({"pbrMetallicRoughness":{"baseColorFactor":[0.8,0.6,0.4,1],"metallicFactor":0.3,)"
      R"("roughnessFactor":0.4}})",
      R"({"emissiveFactor":[1,0.9,0.8],"pbrMetallicRoughness":{"baseColorFactor":[0,0,0,1]}})",
      R"({"alphaMode":"BLEND","doubleSided":true,"pbrMetallicRoughness":)"
      R"({"baseColorFactor":[0.2,0.4,0.9,0.5],"metallicFactor":0}})",
      R"({"doubleSided":true,"pbrMetallicRoughness":{"metallicFactor":0}})"};
  const auto quad = [&](int material) {
    return gltf_files::prim({{"POSITION", quad_pos}, {"NORMAL", quad_nrm}}, quad_idx, -1, material);
  };
  g.mesh({gltf_files::prim({{"POSITION", sphere_pos}, {"NORMAL", sphere_nrm}}, sphere_idx, -1, 0)});
  g.mesh({quad(1)});
  g.mesh({quad(2)});
  g.mesh({quad(3)});
  // Floor: the quad turned to face +y, 6 across.
  g.node(
      R"("mesh":3,"rotation":[-0.7071068,0,0,0.7071068],"scale":[6,6,1],"translation":[0,-0.6,0])",
      true);
  const char* const spheres[] = {
      R"("translation":[-2,0,0])",
      R"("translation":[-1.2,0.2,0.5],"scale":[1,1.6,0.7])",
      R"("translation":[-0.3,0,-0.4],"scale":[-1,1,1])",
      R"("translation":[0.6,0.1,0.3],"rotation":[0.2,0.3,0.1,0.9273618],"scale":[1.4,0.6,1])",
      R"("translation":[1.5,0,-0.2],"rotation":[0,0.3826834,0,0.9238795],"scale":[0.8,1.2,-1.1])",
      R"("translation":[2.2,0.3,0.6],"scale":[0.6,0.6,0.6])"};
  for (const char* t : spheres) g.node(std::string(R"("mesh":0,)") + t, true);
  // Lights: the quad turned to face -y, 2.2 up; the middle one mirrored in x.
  const char* const lights[] = {R"("translation":[-1.5,2.2,0],"scale":[1,0.8,1])",
                                R"("translation":[0,2.2,0.3],"scale":[-0.8,0.8,1])",
                                R"("translation":[1.6,2.2,-0.3],"scale":[0.7,1.2,1])"};
  for (const char* t : lights)
    g.node(std::string(R"("mesh":1,"rotation":[0.7071068,0,0,0.7071068],)") + t, true);
  g.node(R"("mesh":2,"translation":[-0.8,0.2,1.2],"scale":[1.5,1.2,1])", true);
  g.node(R"("mesh":2,"translation":[0.9,0.2,1.1],"rotation":[0,0.3826834,0,0.9238795],)"
         R"("scale":[-1.2,1.2,1])",
         true);
  return g.write("instanced_scene.gltf");
}

// Per pixel, the squared difference over the sum of both variances (of the pixel means), summed
// over the pixels that vary: a chi-square statistic of about one per pixel for independent
// renders of the same image; the shared random numbers correlate the two renders positively,
// which lowers it. The bound, the count plus 6 standard deviations of a chi-square of that many
// degrees of freedom (sqrt(2k)), leaves room for the noise of the variance estimates; a pixel
// that differs by far more than its noise (a wrong normal, a missed instance, a light counted
// twice) adds hundreds.
void expect_same_pixels(const Rendered& a, const Rendered& b, const char* what) {
  double chi2 = 0;
  std::size_t k = 0;
  for (std::size_t i = 0; i < a.image.rgb.size(); ++i) {
    const double var = double(a.variance.rgb[i]) + double(b.variance.rgb[i]);
    const double d = double(a.image.rgb[i]) - double(b.image.rgb[i]);
    if (var > 0) {
      chi2 += d * d / var;
      ++k;
    } else {
      EXPECT_LE(std::fabs(d), 1e-5 * std::fabs(double(a.image.rgb[i]))) << what << " value " << i;
    }
  }
  std::printf("%s: chi-square %.1f over %zu values that vary\n", what, chi2, k);
  EXPECT_GT(k, a.image.rgb.size() / 10) << what;  // the objects fill part of the view
  EXPECT_LE(chi2, double(k) + 6.0 * std::sqrt(2.0 * double(k))) << what;
}

TEST_F(InstancesRender, InstancedSceneRendersItsFlattenedImage) {
  const std::string path = instanced_scene();
  LoadOptions on, off;
  on.instancing = Instancing::kAlways;
  off.instancing = Instancing::kNever;
  const Scene a = load_gltf(path, on), b = load_gltf(path, off);
  ASSERT_EQ(a.instances.size(), 12u);  // 1 floor, 6 spheres, 3 lights, 2 panes
  ASSERT_EQ(a.meshes.size(), 4u);
  EXPECT_TRUE(b.instances.empty());
  EXPECT_EQ(a.world_triangle_count(), b.triangle_count());
  EXPECT_EQ(a.bounds_lo, b.bounds_lo);  // the same framing camera
  EXPECT_EQ(a.bounds_hi, b.bounds_hi);
  for (const int width : {2, 8}) {
    SCOPED_TRACE("BVH width " + std::to_string(width));
    RenderSettings s = twin_settings(64, 48, 32, 4, 0.05f);
    s.bvh_width = width;
    const Rendered ra = render(*runtime_, a, s), rb = render(*runtime_, b, s);
    EXPECT_EQ(ra.report.nonfinite_samples, 0u);
    expect_same_estimate(ra, rb, "instanced vs flattened");
    expect_same_pixels(ra, rb, "instanced vs flattened");
  }
}

// The instanced scene split over several scene buffers (the instance arrays among them) renders
// bit for bit as in one, and with AOVs its image is the same: both as for flattened scenes
// (PackedSize.SplitSceneRendersExactlyAsOne, Aov tests).
TEST_F(InstancesRender, InstancedSceneSplitsOverBuffersAndKeepsItsImageWithAovs) {
  LoadOptions on;
  on.instancing = Instancing::kAlways;
  const Scene a = load_gltf(instanced_scene(), on);
  for (const int width : {2, 8}) {
    SCOPED_TRACE("BVH width " + std::to_string(width));
    RenderSettings s = twin_settings(32, 24, 4, 4, 0.05f);
    s.bvh_width = width;
    const Rendered one = render(*runtime_, a, s);
    bvh::BuildOptions o;
    o.width = width;
    const bvh::Bvh b = build_scene_bvh(a, o, std::string());
    const SceneCounts c = scene_counts(a, nullptr);
    // Buffers as small as the largest array: the arrays spread over several, the instances'
    // (the last two) away from the first.
    const SceneLayout whole = scene_layout(c, bvh_bytes(b), kSceneBufferReach);
    const std::uint64_t largest = *std::max_element(whole.sizes.begin(), whole.sizes.end());
    s.scene_buffer_bytes = (largest + 63) / 64 * 64;
    const SceneLayout split = scene_layout(c, bvh_bytes(b), s.scene_buffer_bytes);
    ASSERT_GE(split.buffer_bytes.size(), 3u);
    ASSERT_EQ(split.places.size(), 20u);
    EXPECT_GT(split.places[18].buffer, 0);
    EXPECT_EQ(render(*runtime_, a, s).image.rgb, one.image.rgb);
    s.scene_buffer_bytes = 0;
    s.aov = true;
    EXPECT_EQ(render(*runtime_, a, s).image.rgb, one.image.rgb);
  }
}

}  // namespace
