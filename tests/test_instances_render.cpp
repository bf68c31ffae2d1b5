// EXT_mesh_gpu_instancing renders as the same scene written without it (scene tier): the shared
// SimpleInstancing (125 instances of a cube) against a twin written at test time whose instances
// are child nodes of the instancing node, each with the instance's translation, rotation and scale.
// The extension's order (node world x T x R x S) and the node hierarchy's give the same matrices,
// so the same triangles in the same order and the same image bit for bit. (Today instances are
// copies of the mesh; a two-level BVH must keep this test passing.)
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "host/render/render.h"
#include "tests/device_test.h"
#include "tests/gltf/compress_twin.h"
#include "tests/gltf/gltf_files.h"
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
  ASSERT_EQ(a.triangle_count(), 125u * 12u);
  ASSERT_EQ(b.triangle_count(), a.triangle_count());
  EXPECT_EQ(b.gltf.gpu_instances, 0u);
  EXPECT_EQ(b.positions, a.positions);
  RenderSettings s;
  s.width = 48;
  s.height = 36;
  s.spp = 4;
  s.background = glm::vec3(1.0f);
  s.max_depth = 3;
  s.view.orbit = glm::vec3(35.0f, 60.0f, 0.0f);  // from above and aside: every row in sight
  const Rendered ra = render(*runtime_, a, s), rb = render(*runtime_, b, s);
  EXPECT_EQ(ra.image.rgb, rb.image.rgb);
  std::size_t covered = 0;  // pixels darker than the sky: the cubes are there
  for (std::size_t i = 0; i < ra.image.rgb.size(); i += 3) covered += ra.image.rgb[i] < 0.9f;
  EXPECT_GT(covered, ra.image.rgb.size() / 3 / 10);
}

}  // namespace
