// The size check of the packed scene (host/device_scene.h), run before the BVH build: its
// arithmetic agrees with pack_scene's, its BVH estimate never exceeds a real BVH (so no scene that
// fits is refused), counts past 4 GiB are refused, and render() refuses them before it builds or
// caches a BVH. Counts stand in for scenes of tens of millions of triangles: nothing large is
// allocated.
#include <cstdlib>
#include <filesystem>
#include <memory>

#include <gtest/gtest.h>

#include "bvh/bvh_cache.h"
#include "host/cl_runtime.h"
#include "host/device_scene.h"
#include "host/error.h"
#include "host/light_table.h"
#include "host/render.h"
#include "tests/scene_factory.h"

namespace {

namespace fs = std::filesystem;
using namespace wp;

constexpr const char* kTooLarge = "scene too large for 32-bit buffer offsets";
constexpr std::uint64_t kMaxEnd = 0xffffffffu;

// A soup of `triangles` random triangles, one (non-emissive) material, a punctual light and a
// 3 x 2 texture.
Scene small_scene(int triangles) {
  Scene s;
  s.materials.push_back(test::diffuse_material({0.5f, 0.5f, 0.5f}));
  test::add_random_soup(s, triangles, 0.1f, 3, 0);
  PunctualLight light;
  light.position = {0.5f, 2.0f, 0.5f};
  s.lights.push_back(light);
  Image img;
  img.width = 3;
  img.height = 2;
  img.rgba.assign(4 * 3 * 2, 200);
  s.images.push_back(img);
  TextureRef t;
  t.image = 0;
  s.textures.push_back(t);
  s.materials[0].base_color_texture = 0;
  test::finish_bounds(s);
  s.cameras.push_back(test::look_at({0.5f, 0.5f, 3.0f}, {0.5f, 0.5f, 0.5f}, 0.8f));
  return s;
}

bvh::Bvh build_bvh(const Scene& s, int width, bool splits = false, int max_leaf = 0) {
  std::vector<std::uint32_t> flags;
  bvh::BuildOptions o;
  o.width = width;
  o.spatial_splits = splits;
  if (max_leaf) o.max_leaf_size = max_leaf;
  return bvh::build(bvh_input(s, flags), o);
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// With the BVH's real sizes and the light table's real light count, packed_end is exactly where
// pack_scene's last array ends, with and without an environment map (whose three arrays come last).
TEST(PackedSize, EndAgreesWithPackScene) {
  const Scene s = small_scene(300);
  auto env = std::make_unique<EnvironmentMap>();
  env->width = 8;
  env->height = 4;
  env->texels.assign(8 * 4, glm::vec4(0.5f, 0.5f, 0.5f, 0.0f));
  build_environment_tables(*env);
  const std::vector<const EnvironmentMap*> maps = {nullptr, env.get()};
  for (int width : {2, 8}) {
    const bvh::Bvh b = build_bvh(s, width);
    for (const EnvironmentMap* map : maps) {
      const LightTable lights =
          build_light_table(s, map, glm::vec3(0.0f), 1.0f, LightSelect::kPower);
      SceneExtras x;
      x.env = map;
      x.lights = &lights;
      const PackedScene packed = pack_scene(s, b, x);
      SceneCounts c = scene_counts(s, map);
      EXPECT_EQ(c.triangles, 300u);
      EXPECT_EQ(c.texels, 6u);
      EXPECT_EQ(c.env_texels, map ? 32u : 0u);
      // Only the punctual light is counted up front: a lower bound.
      EXPECT_LE(packed_end(c, bvh_bytes(b)), packed.bytes.size());
      c.punctual_lights = lights.lights.size();
      // The last array (tri_light, or the environment's conditional table) is over 16 bytes, so
      // it ends where the bytes do.
      EXPECT_EQ(packed_end(c, bvh_bytes(b)), packed.bytes.size())
          << "width " << width << (map ? " with" : " without") << " a map";
      EXPECT_EQ(packed.desc.triangle_count, 300u);
    }
  }
}

// The BVH estimate used before the build is at most what any build makes: both layouts, with and
// without spatial splits, the largest and the smallest leaves, from 1 triangle up.
TEST(PackedSize, MinBvhBytesBoundsEveryBuild) {
  for (int n : {1, 2, 3, 5, 9, 17, 100, 2000}) {
    const Scene s = small_scene(n);
    for (int width : {2, 8}) {
      for (bool splits : {false, true}) {
        for (int max_leaf : {0, 1}) {
          const BvhBytes real = bvh_bytes(build_bvh(s, width, splits, max_leaf));
          const BvhBytes least = min_bvh_bytes(static_cast<std::uint64_t>(n), width);
          EXPECT_LE(least.nodes, real.nodes) << n << " triangles, width " << width;
          EXPECT_LE(least.primitives, real.primitives) << n << " triangles, width " << width;
          EXPECT_GT(least.nodes, 0u);
        }
      }
    }
  }
  // Its per-triangle cost for large counts: every triangle's 48 bytes (width 2) or a quarter of a
  // 176-byte block (width 8), plus the nodes of leaves as full as they can be.
  EXPECT_EQ(min_bvh_bytes(8000000, 2).primitives, 8000000u * 48u);
  EXPECT_EQ(min_bvh_bytes(8000000, 2).nodes, 999999u * 64u);
  EXPECT_EQ(min_bvh_bytes(8000000, 8).primitives, 2000000u * 176u);
  EXPECT_EQ(min_bvh_bytes(8000000, 8).nodes, 71429u * 224u);  // ceil((500000 - 1) / 7) nodes
}

// A scene of 20 million unshared triangles (60 million vertices, 80 bytes each on the device)
// cannot fit, whatever its BVH: refused from its counts alone. A million fit.
TEST(PackedSize, CountsPastFourGibAreRefused) {
  SceneCounts big;
  big.triangles = 20000000;
  big.vertices = 60000000;
  big.materials = 1;
  for (int width : {2, 8}) {
    EXPECT_GT(packed_end(big, min_bvh_bytes(big.triangles, width)), kMaxEnd);
    EXPECT_EQ(error_of([&] { check_packed_size(big, min_bvh_bytes(big.triangles, width)); }),
              kTooLarge);
    SceneCounts small = big;
    small.triangles = 1000000;
    small.vertices = 3000000;
    EXPECT_EQ(error_of([&] { check_packed_size(small, min_bvh_bytes(small.triangles, width)); }),
              "");
  }
  // Textures count too: one 32768 x 32768 image is 4 GiB of texels.
  SceneCounts textured;
  textured.triangles = 2;
  textured.vertices = 4;
  textured.images = 1;
  textured.texels = std::uint64_t(32768) * 32768;
  EXPECT_EQ(error_of([&] { check_packed_size(textured, min_bvh_bytes(2, 8)); }), kTooLarge);
  // The limit is the last byte a 32-bit offset reaches: find the most texels that fit.
  std::uint64_t lo = 0, hi = textured.texels;  // fits, does not
  while (hi - lo > 1) {
    textured.texels = lo + (hi - lo) / 2;
    (packed_end(textured, min_bvh_bytes(2, 8)) <= kMaxEnd ? lo : hi) = textured.texels;
  }
  textured.texels = lo;
  EXPECT_EQ(error_of([&] { check_packed_size(textured, min_bvh_bytes(2, 8)); }), "");
  EXPECT_GT(packed_end(textured, min_bvh_bytes(2, 8)), kMaxEnd - 64);
  textured.texels = hi;
  EXPECT_EQ(error_of([&] { check_packed_size(textured, min_bvh_bytes(2, 8)); }), kTooLarge);
}

// render() refuses a scene too large to pack before it builds its BVH: nothing reaches the BVH
// cache. The scene is small but for an image that claims 65536 x 65536 texels (16 GiB; its pixels
// are never read, as the check comes first).
TEST(PackedSize, RenderRefusesBeforeBuildingTheBvh) {
  const fs::path dir = fs::temp_directory_path() / ("wp_packed_size_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  ASSERT_EQ(setenv("WAVEPATH_CACHE_DIR", dir.c_str(), 1), 0);
  Scene s = small_scene(50);
  s.images[0].width = 65536;
  s.images[0].height = 65536;
  s.images[0].rgba.clear();
  ClRuntime runtime(select_device(""));
  RenderSettings settings;
  settings.width = 8;
  settings.height = 8;
  settings.spp = 1;
  RenderOptions options;
  options.bvh_cache = true;
  EXPECT_EQ(error_of([&] { render(runtime, s, settings, options); }), kTooLarge);
  EXPECT_TRUE(!fs::exists(dir) || fs::is_empty(dir)) << "a BVH was built and cached";
  fs::remove_all(dir);
  unsetenv("WAVEPATH_CACHE_DIR");
}

}  // namespace
