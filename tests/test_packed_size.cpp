// The path state's layout (host/render/path_state.h): its size per path and which fields share
// memory. The scene's split into device buffers (host/device/device_scene.h), checked before the
// BVH build:
// the layout from counts agrees with pack_scene's, its BVH estimate never exceeds a real BVH (so no
// scene that fits is refused), arrays never cross or exceed a buffer, scenes past the device's
// buffers are refused before render() builds or caches a BVH, and a scene split over several
// buffers renders exactly as in one. Counts stand in for scenes of tens of millions of
// triangles: nothing large is allocated.
#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>

#include <gtest/gtest.h>

#include "host/accel/bvh_cache.h"
#include "host/accel/bvh_input.h"
#include "host/device/cl_runtime.h"
#include "host/device/device_scene.h"
#include "host/util/error.h"
#include "host/lights/light_table.h"
#include "host/render/path_state.h"
#include "host/render/render.h"
#include "tests/scene_factory.h"

namespace {

namespace fs = std::filesystem;
using namespace wp;

constexpr std::uint64_t kGiB = std::uint64_t(1) << 30;
constexpr const char* kTooLarge = "scene too large for the device";

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

// The error f throws, or "" when it returns.
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

bool refused(const std::function<void()>& f) {
  return error_of(f).rfind(kTooLarge, 0) == 0;
}

std::unique_ptr<EnvironmentMap> small_map() {
  auto env = std::make_unique<EnvironmentMap>();
  env->width = 8;
  env->height = 4;
  env->texels.resize(8 * 4);
  for (std::size_t i = 0; i < env->texels.size(); ++i)
    env->texels[i] = glm::vec4(0.2f + 0.1f * float(i % 5), 0.5f, 0.3f + 0.05f * float(i % 3), 0);
  build_environment_tables(*env);
  return env;
}

// With the BVH's real sizes and the light table's real light count, scene_layout places every
// array where pack_scene does and sizes every buffer alike: with and without an environment map
// (whose three arrays come last), in one buffer and split over several.
TEST(PackedSize, LayoutAgreesWithPackScene) {
  const Scene s = small_scene(300);
  const auto env = small_map();
  const std::vector<const EnvironmentMap*> maps = {nullptr, env.get()};
  for (int width : {2, 8}) {
    const bvh::Bvh b = build_bvh(s, width);
    for (const EnvironmentMap* map : maps) {
      const LightTable lights =
          build_light_table(s, map, glm::vec3(0.0f), 1.0f, LightSelect::kPower);
      SceneExtras x;
      x.env = map;
      x.lights = &lights;
      SceneCounts c = scene_counts(s, map);
      EXPECT_EQ(c.triangles, 300u);
      EXPECT_EQ(c.texels, 6u);
      EXPECT_EQ(c.env_texels, map ? 32u : 0u);
      const std::uint64_t one = scene_layout(c, bvh_bytes(b), kSceneBufferReach).total_bytes();
      for (std::uint64_t max_buffer : {kSceneBufferReach, one / 2, one / 3}) {
        const PackedScene packed = pack_scene(s, b, x, max_buffer);
        // Only the punctual light is counted up front: a lower bound.
        c.lights = s.lights.size();
        EXPECT_LE(scene_layout(c, bvh_bytes(b), max_buffer).total_bytes(), one);
        c.lights = lights.lights.size();
        const SceneLayout layout = scene_layout(c, bvh_bytes(b), max_buffer);
        ASSERT_EQ(layout.buffer_bytes.size(), packed.buffers.size());
        for (std::size_t i = 0; i < packed.buffers.size(); ++i) {
          EXPECT_EQ(layout.buffer_bytes[i], packed.buffers[i].size());
          EXPECT_LE(packed.buffers[i].size(), max_buffer);
        }
        if (max_buffer < one) {
          EXPECT_GE(packed.buffers.size(), 3u);
        }
        EXPECT_EQ(packed.buffer_map, layout.buffer_map());
        EXPECT_EQ(packed.buffer_map != 0, packed.buffers.size() > 1);
        const dev::uint offsets[] = {packed.desc.bvh_nodes,    packed.desc.isect_tris,
                                     packed.desc.tri_vertices, packed.desc.positions,
                                     packed.desc.tri_light,    packed.desc.env_conditional};
        const std::size_t indices[] = {0, 1, 2, 3, 14, 17};
        for (std::size_t k = 0; k < std::size(indices); ++k) {
          if (indices[k] < layout.places.size()) {
            EXPECT_EQ(offsets[k] * std::uint64_t(64), layout.places[indices[k]].offset) << k;
          }
        }
        EXPECT_EQ(packed.desc.triangle_count, 300u);
      }
    }
  }
}

// Packing that frees the host arrays (HostArrays::kRelease, the CLI's) packs the same bytes as
// packing that keeps them, leaves every padding byte zero (the buffers are not initialised before
// they are written), and returns the memory of exactly the arrays it names: positions, normals,
// tangents, UVs, colours, indices, triangle materials, image texels and the BVH's nodes and
// primitives. In one buffer and split over several, with every vertex array packed, both layouts.
TEST(PackedSize, ReleasingPackPacksTheSameBytesAndFreesTheHostArrays) {
  const Scene s = small_scene(300);
  const auto env = small_map();
  for (int width : {2, 8}) {
    const bvh::Bvh b = build_bvh(s, width);
    const LightTable lights =
        build_light_table(s, env.get(), glm::vec3(0.0f), 1.0f, LightSelect::kPower);
    SceneExtras x;
    x.env = env.get();
    x.lights = &lights;
    SceneCounts c = scene_counts(s, env.get());
    c.lights = lights.lights.size();
    const std::uint64_t one = scene_layout(c, bvh_bytes(b), kSceneBufferReach).total_bytes();
    for (std::uint64_t max_buffer : {kSceneBufferReach, one / 3}) {
      const PackedScene kept = pack_scene(s, b, x, max_buffer);
      Scene freed_scene = s;
      bvh::Bvh freed_bvh = b;
      const PackedScene freed =
          pack_scene(freed_scene, freed_bvh, x, max_buffer, HostArrays::kRelease);
      ASSERT_EQ(kept.buffers.size(), freed.buffers.size());
      for (std::size_t i = 0; i < kept.buffers.size(); ++i)
        EXPECT_TRUE(kept.buffers[i] == freed.buffers[i]) << "buffer " << i;
      EXPECT_EQ(std::memcmp(&kept.desc, &freed.desc, sizeof(kept.desc)), 0);
      EXPECT_EQ(kept.buffer_map, freed.buffer_map);
      // Every byte outside the arrays is zero.
      const SceneLayout layout = scene_layout(c, bvh_bytes(b), max_buffer);
      for (std::size_t buffer = 0; buffer < freed.buffers.size(); ++buffer) {
        std::vector<char> in_array(freed.buffers[buffer].size(), 0);
        for (std::size_t a = 0; a < layout.places.size(); ++a)
          if (std::size_t(layout.places[a].buffer) == buffer)
            std::fill_n(in_array.begin() + std::ptrdiff_t(layout.places[a].offset), layout.sizes[a],
                        1);
        std::size_t nonzero_padding = 0;
        for (std::size_t k = 0; k < in_array.size(); ++k)
          nonzero_padding += !in_array[k] && freed.buffers[buffer][k] != 0;
        EXPECT_EQ(nonzero_padding, 0u) << "buffer " << buffer;
      }
      const Scene& f = freed_scene;
      for (const std::size_t capacity :
           {f.positions.capacity(), f.normals.capacity(), f.tangents.capacity(), f.uv0.capacity(),
            f.uv1.capacity(), f.color0.capacity(), f.indices.capacity(),
            f.triangle_material.capacity(), f.images.at(0).rgba.capacity(),
            freed_bvh.nodes.capacity(), freed_bvh.nodes8.capacity(), freed_bvh.triangles.capacity(),
            freed_bvh.blocks.capacity()})
        EXPECT_EQ(capacity, 0u);
      // The rest stays.
      EXPECT_EQ(f.materials.size(), s.materials.size());
      EXPECT_EQ(f.images.at(0).width, s.images.at(0).width);
      EXPECT_EQ(f.lights.size(), s.lights.size());
      EXPECT_EQ(f.cameras.size(), s.cameras.size());
      EXPECT_EQ(freed_bvh.stats.leaves, b.stats.leaves);
    }
  }
}

// The optional per-vertex arrays a program reads follow its features (kernels/geom/material.h and
// alpha.h read them only under these flags): texture coordinates for textures, tangents for normal
// maps, colours for COLOR_0 and for alpha; none for a plain scene; all with every feature.
TEST(PackedSize, OnlyTheVertexArraysTheProgramReadsArePacked) {
  const auto packed = [](const Scene& s) {
    const VertexArrays a = VertexArrays::of(SceneFeatures::of(s, false));
    return std::string(a.tangents ? "t" : "") + (a.uvs ? "u" : "") + (a.colors ? "c" : "");
  };
  Scene s = small_scene(10);  // a base-colour texture
  EXPECT_EQ(packed(s), "u");
  s.materials[0].normal_texture = 0;
  EXPECT_EQ(packed(s), "tu");
  s.materials[0].alpha_mode = AlphaMode::kMask;
  EXPECT_EQ(packed(s), "tuc");
  s.materials[0] = test::diffuse_material({0.5f, 0.5f, 0.5f});
  EXPECT_EQ(packed(s), "");
  s.color0[3] = glm::vec4(0.5f, 1.0f, 1.0f, 1.0f);  // COLOR_0
  EXPECT_EQ(packed(s), "c");
  const VertexArrays all = VertexArrays::of(SceneFeatures::all());
  EXPECT_TRUE(all.tangents && all.uvs && all.colors);

  // An array left out is empty in both the layout up front and pack_scene's buffers.
  const Scene t = small_scene(300);
  const bvh::Bvh b = build_bvh(t, 8);
  const LightTable lights =
      build_light_table(t, nullptr, glm::vec3(0.0f), 1.0f, LightSelect::kPower);
  const std::uint64_t vertex_bytes = t.positions.size() * sizeof(dev::float4);
  for (const VertexArrays arrays :
       {VertexArrays{}, VertexArrays{false, false, false}, VertexArrays{true, false, true}}) {
    SceneExtras x;
    x.lights = &lights;
    x.vertex_arrays = arrays;
    SceneCounts c = scene_counts(t, nullptr);
    c.lights = lights.lights.size();
    c.vertex_arrays = arrays;
    const SceneLayout layout = scene_layout(c, bvh_bytes(b), kSceneBufferReach);
    const PackedScene p = pack_scene(t, b, x);
    ASSERT_EQ(p.buffers.size(), 1u);
    EXPECT_EQ(layout.buffer_bytes.at(0), p.buffers[0].size());
    ASSERT_STREQ(scene_array_name(5), "tangent");  // 5, 6, 7: kArrayNames' order
    EXPECT_EQ(layout.sizes.at(5), arrays.tangents ? vertex_bytes : 0u);
    EXPECT_EQ(layout.sizes.at(6), arrays.uvs ? vertex_bytes : 0u);
    EXPECT_EQ(layout.sizes.at(7), arrays.colors ? vertex_bytes : 0u);
  }
}

// Each array starts on a 64-byte boundary, never crosses the end of a buffer, and starts a new
// buffer only when it would cross; the buffer map holds each array's buffer; refusals name the
// cause.
TEST(PackedSize, ArraysAreSplitOverBuffersWithoutCrossingOne) {
  const std::vector<std::uint64_t> sizes = {1000, 0, 5, 3000, 64, 4096, 1, 2500, 777, 0};
  for (std::uint64_t max_buffer : {4096u, 5000u, 8192u, 100000u}) {
    const SceneLayout layout = plan_scene_layout(sizes, max_buffer);
    ASSERT_EQ(layout.places.size(), sizes.size());
    std::uint64_t end = 0;
    int buffer = 0;
    for (std::size_t i = 0; i < sizes.size(); ++i) {
      const SceneLayout::Place p = layout.places[i];
      const std::uint64_t size = std::max<std::uint64_t>(sizes[i], 16);
      const std::uint64_t next = (end + 63) / 64 * 64;
      if (i > 0 && next + size <= max_buffer) {  // fits after the previous array
        EXPECT_EQ(p.buffer, buffer) << i;
        EXPECT_EQ(p.offset, next) << i;
      } else {
        EXPECT_EQ(p.buffer, i > 0 ? buffer + 1 : 0) << i;
        EXPECT_EQ(p.offset, 0u) << i;
      }
      buffer = p.buffer;
      end = p.offset + size;
      EXPECT_LE(end, max_buffer);
      EXPECT_EQ(layout.buffer_map() >> (3 * i) & 7, std::uint64_t(p.buffer));
      EXPECT_EQ(layout.buffer_bytes[p.buffer], std::max(layout.buffer_bytes[p.buffer], end));
    }
    EXPECT_EQ(layout.buffer_bytes.size(), std::size_t(buffer) + 1);
  }
  EXPECT_EQ(error_of([&] { plan_scene_layout(sizes, 4095); }),
            "scene too large for the device: its tangent array needs 4096 bytes, more than the "
            "device's largest buffer (4095 bytes)");
  // Eight buffers at most: nine arrays that each fill one are refused.
  const std::vector<std::uint64_t> nine(9, kGiB);
  EXPECT_EQ(plan_scene_layout({nine.begin(), nine.end() - 1}, kGiB).buffer_bytes.size(), 8u);
  EXPECT_EQ(error_of([&] { plan_scene_layout(nine, kGiB); }),
            "scene too large for the device: 9.00 GiB does not fit in 8 buffers of at most "
            "1.00 GiB (the device's largest buffer)");
  // A uint of 64-byte units reaches 256 GiB into a buffer: larger limits are capped there.
  const SceneLayout far = plan_scene_layout({200 * kGiB, 56 * kGiB, 1}, 1024 * kGiB);
  EXPECT_EQ(far.places[1].offset, 200 * kGiB);
  EXPECT_EQ(far.places[2].buffer, 1);
  EXPECT_EQ(far.buffer_map(), std::uint64_t(1) << 6);
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

// A scene of 20 million unshared triangles (60 million vertices, 80 bytes each on the device,
// about 5.8 GiB in all) fits in PoCL's buffers of 2 GiB, split over several, in either BVH layout;
// 60 million do not, refused from their counts alone.
TEST(PackedSize, ScenesLargerThanOneBufferAreSplit) {
  SceneCounts big;
  big.triangles = 20000000;
  big.vertices = 60000000;
  big.materials = 1;
  for (int width : {2, 8}) {
    const SceneLayout layout = scene_layout(big, min_bvh_bytes(big.triangles, width), 2 * kGiB);
    EXPECT_GE(layout.buffer_bytes.size(), 4u);
    EXPECT_GT(layout.total_bytes(), 5 * kGiB);
    SceneCounts huge = big;
    huge.triangles *= 3;
    huge.vertices *= 3;
    EXPECT_TRUE(
        refused([&] { scene_layout(huge, min_bvh_bytes(huge.triangles, width), 2 * kGiB); }));
    EXPECT_NO_THROW(scene_layout(huge, min_bvh_bytes(huge.triangles, width), 8 * kGiB));
  }
  // Textures count too: one 32768 x 32768 image is 4 GiB of texels, more than one 2 GiB buffer,
  // and fits in 4 GiB ones; 65536 x 65536 is 2^32 texels, past the uint texel offsets.
  SceneCounts textured;
  textured.triangles = 2;
  textured.vertices = 4;
  textured.images = 1;
  textured.texels = std::uint64_t(32768) * 32768;
  EXPECT_EQ(error_of([&] { scene_layout(textured, min_bvh_bytes(2, 8), 2 * kGiB); }),
            "scene too large for the device: its texel array needs 4.00 GiB, more than the "
            "device's largest buffer (2.00 GiB)");
  EXPECT_NO_THROW(scene_layout(textured, min_bvh_bytes(2, 8), 4 * kGiB));
  textured.texels = std::uint64_t(65536) * 65536;
  EXPECT_EQ(error_of([&] { scene_layout(textured, min_bvh_bytes(2, 8), kSceneBufferReach); }),
            "scene too large for the device: more than 2^32 texels in its images");
}

// render() refuses a scene too large for the device before it builds its BVH: nothing reaches the
// BVH cache. The scene is small but for an image that claims 65536 x 65536 texels (16 GiB; its
// pixels are never read, as the check comes first).
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
  EXPECT_TRUE(refused([&] { render(runtime, s, settings, options); }));
  EXPECT_TRUE(!fs::exists(dir) || fs::is_empty(dir)) << "a BVH was built and cached";
  fs::remove_all(dir);
  unsetenv("WAVEPATH_CACHE_DIR");
}

// A packed scene beyond what will hold it is refused, naming both sizes, instead of an allocation
// failure or (on a CPU device, where it is host memory) the system killing the process: a GPU's
// global memory, a CPU device's available host memory (0: unknown, not checked).
// The message of the wp::Error `f` throws; "" when it throws none.
template <typename F>
std::string error(const F& f) {
  try {
    f();
  } catch (const wp::Error& e) {
    return std::string(e.what());
  }
  return std::string();
}

TEST(PackedSize, SceneMemoryIsChecked) {
  DeviceEntry cpu, gpu;
  cpu.name = "cpu";
  gpu.name = "gpu";
  gpu.gpu = true;
  gpu.global_memory = 4'000'000'000ull;
  EXPECT_EQ(error([&] { check_scene_memory(4'000'000'000ull, cpu, 4'000'000'000ull); }), "");
  EXPECT_EQ(error([&] { check_scene_memory(1ull << 40, cpu, 0); }), "");
  EXPECT_EQ(error([&] { check_scene_memory(8'000'000'000ull, cpu, 4'500'000'000ull); }),
            "scene too large for this machine's memory: it packs into 8.00 GB, 4.50 GB are "
            "available");
  EXPECT_EQ(error([&] { check_scene_memory(4'000'000'000ull, gpu, 1); }), "");
  EXPECT_EQ(error([&] { check_scene_memory(5'000'000'000ull, gpu, 1ull << 40); }),
            "scene too large for the device: it packs into 5.00 GB, gpu has 4.00 GB");
}

// An image whose film (or other path-state buffer) the device cannot allocate is refused before
// anything is, naming the image, the bytes needed and the device's limit: one buffer beyond
// CL_DEVICE_MAX_MEM_ALLOC_SIZE, or all of them beyond CL_DEVICE_GLOBAL_MEM_SIZE.
TEST(PackedSize, ImageMemoryIsChecked) {
  DeviceEntry device;
  device.name = "dev";
  device.max_alloc = 1ull << 31;
  device.global_memory = 3ull << 30;
  RenderSettings s;
  const SceneFeatures features = SceneFeatures::all();
  s.width = s.height = 4096;  // 16 Mi pixels x 96 bytes: 1.5 GiB of film
  EXPECT_EQ(error([&] { check_state_memory(state_memory(s, features), s, device); }), "");
  s.width = 5461;  // 5461 x 4096 x 96 bytes: just under 2 GiB
  EXPECT_EQ(error([&] { check_state_memory(state_memory(s, features), s, device); }), "");
  s.width = 5462;  // just over
  EXPECT_EQ(error([&] { check_state_memory(state_memory(s, features), s, device); }),
            "image too large for the device: 5462 x 4096 needs a film buffer of 2147745792 bytes "
            "(2.00 GiB), more than the 2147483648 bytes (2.00 GiB) dev allocates at once "
            "(CL_DEVICE_MAX_MEM_ALLOC_SIZE)");
  device.max_alloc = 0;  // unknown: only the total is checked
  s.width = s.height = 16384;
  const StateMemory m = state_memory(s, features);
  EXPECT_EQ(error([&] { check_state_memory(m, s, device); }),
            "image too large for the device: 16384 x 16384 needs " + std::to_string(m.total()) +
                " bytes (" + human_bytes(m.total()) +
                ") of path state, queues and film, more than the 3221225472 bytes (3.00 GiB) of "
                "dev (CL_DEVICE_GLOBAL_MEM_SIZE)");
}

// A CPU device's default wave is the largest power of two of paths whose path state and queue
// slots fit its global memory cache, within [2^16, 2^20], swept across each power's threshold;
// a larger image is split evenly into the nearest whole number of such waves; a GPU, or a device
// that reports no cache, keeps min(pixels, 2^20) pixels (several samples of an image under
// kMultiSamplePaths pixels). An explicit --wave-size wins over both.
TEST(WaveShape, CpuWavesFitTheCache) {
  DeviceEntry cpu;
  cpu.gpu = false;
  const std::size_t per_path = 128;  // 112 B of fused state and four 4-byte queue slots
  for (std::size_t k = 16; k <= 20; ++k) {
    const std::size_t paths = std::size_t(1) << k;
    cpu.cache_bytes = paths * per_path;  // exactly 2^k paths fit
    EXPECT_EQ(auto_wave_paths(&cpu, per_path), paths) << k;
    cpu.cache_bytes = paths * per_path - 1;  // one byte short of them
    EXPECT_EQ(auto_wave_paths(&cpu, per_path), std::max(paths / 2, std::size_t(1) << 16)) << k;
  }
  cpu.cache_bytes = 1;  // smaller than one path: the floor
  EXPECT_EQ(auto_wave_paths(&cpu, per_path), std::size_t(1) << 16);
  cpu.cache_bytes = 1ull << 40;  // the ceiling
  EXPECT_EQ(auto_wave_paths(&cpu, per_path), std::size_t(1) << 20);
  cpu.cache_bytes = 0;  // not reported
  EXPECT_EQ(auto_wave_paths(&cpu, per_path), 0u);
  DeviceEntry gpu = cpu;
  gpu.gpu = true;
  gpu.cache_bytes = 32ull << 20;
  EXPECT_EQ(auto_wave_paths(&gpu, per_path), 0u);
  EXPECT_EQ(auto_wave_paths(nullptr, per_path), 0u);

  RenderSettings s;
  s.width = 1280, s.height = 720;
  const SceneFeatures features;   // the fused 112-byte state (PathState test below)
  cpu.cache_bytes = 32ull << 20;  // 2^18 paths of 128 bytes
  StateMemory m = state_memory(s, features, &cpu);
  EXPECT_EQ(m.wave.pixels, 230400u);  // 921600 pixels: 3.5 waves of 2^18, so 4 even ones
  EXPECT_EQ(m.wave.samples, 1u);
  EXPECT_EQ(m.path_state.bytes_per_path, 112u);
  // The nearest whole number of waves: up to 1.5 waves' pixels stay one wave, from there two.
  s.width = 393215, s.height = 1;  // 1.5 x 2^18 - 1
  EXPECT_EQ(state_memory(s, features, &cpu).wave.pixels, 393215u);
  s.width = 393216;  // 1.5 x 2^18: two waves
  EXPECT_EQ(state_memory(s, features, &cpu).wave.pixels, 196608u);
  s.width = 393217;  // the second wave one pixel short
  EXPECT_EQ(state_memory(s, features, &cpu).wave.pixels, 196609u);
  s.width = 640, s.height = 480;  // 1.17 waves: one
  EXPECT_EQ(state_memory(s, features, &cpu).wave.pixels, 307200u);
  s.width = 1280, s.height = 720;
  m = state_memory(s, features, &gpu);
  EXPECT_EQ(m.wave.pixels, 921600u);
  EXPECT_EQ(m.wave.samples, 1u);
  s.width = s.height = 100;  // 10^4 pixels: whole samples of them
  m = state_memory(s, features, &cpu);
  EXPECT_EQ(m.wave.pixels, 10000u);
  EXPECT_EQ(m.wave.samples, 26u);  // floor(2^18 / 10^4)
  cpu.cache_bytes = 8ull << 20;    // 2^16 paths
  EXPECT_EQ(state_memory(s, features, &cpu).wave.samples, 6u);
  s.wave_size = 50000;  // explicit: 5 samples whatever the device
  EXPECT_EQ(state_memory(s, features, &cpu).wave.samples, 5u);
  EXPECT_EQ(state_memory(s, features, &gpu).wave.samples, 5u);
}

// The kernels find every array wherever it lies: a textured, lit scene with an environment map,
// split over several buffers, renders bit for bit as in one, with either BVH layout (the CPU's,
// 8, in the default suite; both in ...Exhaustive, slow).
void expect_split_scene_renders_as_one(std::initializer_list<int> widths) {
  const Scene s = small_scene(200);
  ClRuntime runtime(select_device(""));
  RenderSettings settings;
  settings.width = 24;
  settings.height = 16;
  settings.spp = 2;
  settings.environment = small_map();
  for (int width : widths) {
    settings.bvh_width = width;
    settings.scene_buffer_bytes = 0;
    const Rendered one = render(runtime, s, settings);
    // A buffer a fifth of the scene: several buffers, checked through the same layout.
    std::vector<std::uint32_t> flags;
    bvh::BuildOptions o;
    o.width = width;
    const bvh::Bvh b = bvh::build(bvh_input(s, flags), o);
    const SceneCounts c = scene_counts(s, settings.environment.get());
    const std::uint64_t total = scene_layout(c, bvh_bytes(b), kSceneBufferReach).total_bytes();
    settings.scene_buffer_bytes = total / 5;
    ASSERT_GE(scene_layout(c, bvh_bytes(b), total / 5).buffer_bytes.size(), 4u);
    const Rendered split = render(runtime, s, settings);
    EXPECT_EQ(one.image.rgb, split.image.rgb) << "BVH width " << width;
    // And the render that frees the scene's arrays as it packs them (the CLI's) is the same, its
    // report counting the triangles it had.
    const Rendered freed = render(runtime, Scene(s), settings);
    EXPECT_EQ(one.image.rgb, freed.image.rgb) << "BVH width " << width;
    EXPECT_EQ(freed.report.triangles, s.triangle_count());
    EXPECT_EQ(freed.film.info().key, split.film.info().key);
    double sum = 0.0;
    for (float v : one.image.rgb) sum += v;
    EXPECT_GT(sum, 0.0);  // not trivially equal
  }
}

TEST(PackedSize, SplitSceneRendersExactlyAsOne) {
  expect_split_scene_renders_as_one({8});
}
TEST(PackedSize, SplitSceneRendersExactlyAsOneExhaustive) {
  expect_split_scene_renders_as_one({2, 8});
}

// The fused pipeline's path state is 112 bytes per path for any feature set (issue 21's bound), the
// split pipeline's 208 plus 16 per material extension field, AOVs 32 more; and no two fields
// overlap but the one alias path_state.def declares (the shadow ray's origin over the hit record,
// fused only): every field's array of `capacity` elements lies inside the buffer, apart from the
// others.
TEST(PathState, FusedStateIs112BytesAndSharesOnlyTheHitRecord) {
  constexpr std::size_t kCapacity = 1000;
  struct Field {
    const char* name;
    dev::uint offset;
    std::size_t bytes;  // per path, in this layout
  };
  const auto fields = [](const PathStateLayout& s, bool aov, bool fused,
                         const SceneFeatures& features) {
    std::vector<Field> v;
    const auto extension = [&](const std::string& needs) {
      for (const auto& [macro, on] : features.flags())
        if (on && needs.find(macro) != std::string::npos) return true;
      return false;
    };
#define WP_PATH_FIELD(type, name, description) \
  v.push_back({#name, s.layout.name, sizeof(dev::type)});
#define WP_PATH_AOV_FIELD(type, name, description) \
  v.push_back({#name, s.layout.name, aov ? sizeof(dev::type) : 0});
#define WP_PATH_INSTANCE_FIELD(type, name, description) \
  v.push_back({#name, s.layout.name, features.instances ? sizeof(dev::type) : 0});
#define WP_PATH_SURF_FIELD(type, name, description) \
  v.push_back({#name, s.layout.name, fused ? 0 : sizeof(dev::type)});
#define WP_PATH_OPT_FIELD(needs, type, name, description) \
  v.push_back({#name, s.layout.name, !fused && extension(needs) ? sizeof(dev::type) : 0});
#define WP_PATH_ALIAS_FIELD(type, name, other, description) \
  v.push_back({#name, s.layout.name, fused ? 0 : sizeof(dev::type)});
#include "kernels/shared/path_state.def"
#undef WP_PATH_ALIAS_FIELD
#undef WP_PATH_OPT_FIELD
#undef WP_PATH_SURF_FIELD
#undef WP_PATH_INSTANCE_FIELD
#undef WP_PATH_AOV_FIELD
#undef WP_PATH_FIELD
    return v;
  };
  SceneFeatures instanced = SceneFeatures::of(Scene{}, false);
  instanced.instances = true;
  for (const bool fused : {true, false})
    for (const bool aov : {false, true})
      for (const SceneFeatures& features :
           {SceneFeatures::all(), SceneFeatures::of(Scene{}, false), instanced}) {
        SCOPED_TRACE(std::string(fused ? "fused" : "split") + (aov ? ", AOVs" : ""));
        const PathStateLayout s = path_state_layout(kCapacity, aov, features, fused);
        const std::vector<Field> v = fields(s, aov, fused, features);
        std::size_t extensions = 0;
        for (const Field& f : v)
          extensions += std::string(f.name).rfind("surf_", 0) == 0 && f.bytes;
        const std::size_t expected = fused ? 112 : 208 + 16 * (extensions - 5);
        // A two-level BVH adds the hit's instance (4 bytes).
        EXPECT_EQ(s.bytes_per_path, expected + (aov ? 32 : 0) + (features.instances ? 4 : 0));
        for (std::size_t i = 0; i < v.size(); ++i) {
          EXPECT_LE(v[i].offset + v[i].bytes * kCapacity, s.bytes) << v[i].name;
          for (std::size_t j = i + 1; j < v.size(); ++j) {
            if (!v[i].bytes || !v[j].bytes) continue;
            const bool apart = v[i].offset + v[i].bytes * kCapacity <= v[j].offset ||
                               v[j].offset + v[j].bytes * kCapacity <= v[i].offset;
            EXPECT_TRUE(apart) << v[i].name << " and " << v[j].name << " overlap";
          }
        }
        if (fused) {
          EXPECT_EQ(s.layout.shadow_o, s.layout.hit);
        } else {
          EXPECT_NE(s.layout.shadow_o, s.layout.hit);
        }
      }
}

}  // namespace
