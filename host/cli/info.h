// `wavepath info SCENE`: what a glTF file holds as wavepath loads it, what it does with each
// extension (host/scene/gltf_extensions.h), the device memory a render of it needs, and the state
// of its BVH in the cache; without an OpenCL device and without rendering.
//
// The memory is what a Wavefront allocates (host/render/wavefront.h): the packed scene
// (scene_layout of device_scene.h, with the light table's real light count and the BVH's real
// sizes), the path state of one wave, the queues, the counters and the film. The BVH's sizes are
// exact: it is loaded from the cache when there, else built (Embree; not stored), unless
// --no-bvh-build, which gives min_bvh_bytes' lower bound instead (marked an estimate). Assumed:
// the render's defaults beside --width, --height and --variant (fused pipeline, no AOVs, no
// environment map or background colour: those add an environment light and its tables), and a
// scene in one buffer (a device whose largest allocation splits it adds under 64 bytes of
// alignment per extra buffer).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "host/device/device_scene.h"
#include "host/device/scene_features.h"
#include "host/render/wavefront.h"
#include "host/scene/gltf_extensions.h"
#include "host/scene/scene.h"

namespace wp::cli {

struct InfoOptions {
  std::string scene;
  std::string variant;              // --variant, as render's
  std::string instancing = "auto";  // --instancing, as render's
  int width = RenderSettings{}.width, height = RenderSettings{}.height;
  int bvh_width = 0;  // 2 or 8; 0: both
  bool spatial_splits = false;
  bool no_bvh_build = false;
  bool json = false;
  std::string device;  // --device: the wave's device (auto_wave_paths); empty: a GPU's wave
};

void add_info_options(CLI::App* info, InfoOptions& options);

// One BVH layout: its sizes, the scene packed with it, and its cache entry.
struct BvhInfo {
  int width = 8;
  // Where the sizes come from: "cache" (the entry, loaded), "built" (built now, not stored) or
  // "estimate" (--no-bvh-build: min_bvh_bytes, a lower bound).
  std::string source;
  BvhBytes bytes;
  SceneLayout layout;  // the packed scene with these sizes
  // The cache: "valid" (a render loads it), "absent", "unusable" (present but failing the
  // checks of bvh_cache.h: a render rebuilds and replaces it), "no folder" (cache_dir() is
  // empty), "never" (a scene without triangles is never cached) or "per mesh" (an instanced
  // scene's two-level BVH: each mesh's tree is cached, built here without the cache).
  std::string cache;
  std::string cache_file;  // empty without a cache folder
  std::uint64_t cache_file_bytes = 0;
};

struct SceneInfo {
  std::vector<ExtensionUse> extensions;
  std::size_t emissive_materials = 0;
  std::size_t point_lights = 0, spot_lights = 0, directional_lights = 0;
  std::size_t emissive_triangles = 0;  // those the light table holds (not black everywhere)
  std::size_t table_lights = 0;        // the lights NEE chooses from
  SceneFeatures features;
  RenderSettings settings;  // the render's defaults but width and height
  StateMemory state;
  std::string wave_device;    // the device whose wave `state` holds (--device); empty: a GPU's
  std::vector<BvhInfo> bvhs;  // 8-wide (CPUs' default) first, then 2-wide (GPUs')
};

// The report of `scene` for `options`; builds the BVHs (unless --no-bvh-build) and the light
// table, reads the BVH cache and writes nothing.
// `step`, if set, is told of each BVH layout before it is looked up or built (seconds each for
// millions of triangles).
SceneInfo scene_info(const Scene& scene, const InfoOptions& options,
                     const std::function<void(const std::string&)>& step = {});

// The report for a person, and as one JSON object (one line).
std::string info_text(const Scene& scene, const SceneInfo& info);
std::string info_json(const Scene& scene, const SceneInfo& info);
// For a file refused for the extensions it requires: what can be said, the extensions.
std::string refused_text(const std::string& file, const std::vector<ExtensionUse>& uses);
std::string refused_json(const std::string& file, const std::string& error,
                         const std::vector<ExtensionUse>& uses);

// `wavepath info`: 0, or throws wp::Error like render (after printing what it can of a file
// refused for its extensions).
int info_command(const InfoOptions& options);

}  // namespace wp::cli
