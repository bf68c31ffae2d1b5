#include "host/cli/info.h"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <optional>

#include "host/accel/bvh_cache.h"
#include "host/accel/bvh_input.h"
#include "host/cli/options.h"
#include "host/cli/progress.h"
#include "host/lights/light_table.h"
#include "host/render/render.h"
#include "host/scene/gltf_loader.h"
#include "host/util/files.h"

namespace wp::cli {

void add_info_options(CLI::App* info, InfoOptions& o) {
  info->add_option("scene", o.scene, "glTF 2.0 file (.gltf or .glb)")->required();
  info->add_option("--variant", o.variant,
                   "Material variant (KHR_materials_variants) by name, as render takes it");
  add_instancing_option(info, o.instancing);
  info->add_option("--width", o.width, "Image width in pixels, for the film and the wave")
      ->capture_default_str();
  info->add_option("--height", o.height, "Image height in pixels, for the film and the wave")
      ->capture_default_str();
  info->add_option("--bvh-width", o.bvh_width,
                   "Report only this BVH layout: 8 (CPUs' default) or 2 (GPUs') [default: both]")
      ->check(CLI::IsMember({2, 8}));
  info->add_flag("--spatial-splits", o.spatial_splits,
                 "The BVH as render --spatial-splits builds it");
  info->add_flag("--no-bvh-build", o.no_bvh_build,
                 "Build no BVH that is not in the cache: its sizes are then a lower bound "
                 "(reported as an estimate)");
  info->add_option("--device", o.device,
                   "The OpenCL device a render would run on (index or name substring, as render "
                   "takes it), for the size of its wave: a CPU device's fits its cache [default: "
                   "none looked up; a GPU's wave, the largest]");
  info->add_flag("--json", o.json, "One JSON object on stdout instead of the report");
}

namespace {

// One layout's sizes from the cache, a build or the lower bound, and its cache entry's state.
BvhInfo bvh_info(const Scene& scene, const bvh::BuildInput& input, int width, bool spatial_splits,
                 bool build, const SceneCounts& counts) {
  BvhInfo b;
  b.width = width;
  bvh::BuildOptions options;
  options.width = width;
  options.spatial_splits = spatial_splits;
  const std::string dir = cache_dir();
  std::optional<bvh::Bvh> bvh;
  if (!scene.instances.empty()) {
    b.cache = "per mesh";  // a two-level BVH: each mesh's tree is an entry of its own
    if (build) {
      bvh = build_scene_bvh(scene, options, std::string());
      b.source = "built";
    }
  } else if (scene.triangle_count() == 0) {
    b.cache = "never";
  } else if (dir.empty()) {
    b.cache = "no folder";
  } else {
    const std::uint64_t key = bvh::cache_key(input, options);
    b.cache_file = bvh::cache_entry_path(dir, key);
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(b.cache_file, ec);
    b.cache_file_bytes = ec ? 0 : size;
    bvh = bvh::cache_load(dir, key, scene.triangle_count(), options);
    b.cache = bvh ? "valid" : ec ? "absent" : "unusable";
  }
  if (bvh && b.source.empty()) {
    b.source = "cache";
  } else if (!bvh && (build || scene.triangle_count() == 0)) {  // no triangles: nothing to build
    bvh = bvh::build(input, options);
    b.source = "built";
  }
  b.bytes = bvh ? bvh_bytes(*bvh) : min_bvh_bytes(counts.triangles, width);
  if (!bvh) b.source = "estimate";
  b.layout = scene_layout(counts, b.bytes, kSceneBufferReach);
  return b;
}

}  // namespace

SceneInfo scene_info(const Scene& scene, const InfoOptions& options,
                     const std::function<void(const std::string&)>& step) {
  SceneInfo info;
  info.extensions = extension_uses(scene.gltf.extensions_used, scene.gltf.extensions_required);
  for (const Material& m : scene.materials)
    info.emissive_materials += std::max({m.emission.x, m.emission.y, m.emission.z}) > 0.0f;
  for (const PunctualLight& l : scene.lights) {
    info.point_lights += l.type == LightType::kPoint;
    info.spot_lights += l.type == LightType::kSpot;
    info.directional_lights += l.type == LightType::kDirectional;
  }
  // The render's light table without an environment: black background, no map.
  const LightTable lights = build_light_table(scene, nullptr, glm::vec3(0.0f),
                                              info.settings.env_intensity, LightSelect::kPower);
  info.emissive_triangles = lights.emissive_triangles;
  info.table_lights = lights.lights.size();
  info.features = SceneFeatures::of(scene, false);
  info.settings.width = options.width;
  info.settings.height = options.height;
  if (options.device.empty()) {
    info.state = state_memory(info.settings, info.features);
  } else {
    const DeviceEntry device = select_device(options.device);
    info.state = state_memory(info.settings, info.features, &device);
    info.wave_device = device.name;
  }

  SceneCounts counts = scene_counts(scene, nullptr, info.features.texture_lod);
  counts.vertex_arrays = VertexArrays::of(info.features);
  counts.lights = lights.lights.size();
  std::vector<std::uint32_t> flags;
  const bvh::BuildInput input = bvh_input(scene, flags);
  for (const int width : {8, 2})
    if (options.bvh_width == 0 || options.bvh_width == width) {
      if (step)
        step("the " + std::to_string(width) + "-wide BVH of " +
             std::to_string(scene.triangle_count()) + " triangles");
      info.bvhs.push_back(
          bvh_info(scene, input, width, options.spatial_splits, !options.no_bvh_build, counts));
    }
  return info;
}

int info_command(const InfoOptions& options) {
  RenderSettings size;
  size.width = options.width;
  size.height = options.height;
  validate(size);  // --width and --height as render checks them
  // On a terminal, the step under way (loading, each BVH) on stderr, cleared before the report.
  Progress progress(true, isatty(STDERR_FILENO), 0.0, 0.0, std::nullopt);
  std::optional<Scene> scene;
  try {
    LoadOptions load(options.variant);
    load.instancing = instancing_mode(options.instancing);
    load.check_counts = check_host_counts;  // a scene the host cannot load is refused first
    progress.step("loading " + options.scene);
    scene = load_gltf(options.scene, load);
  } catch (const RefusedExtensions& e) {
    progress.clear();
    std::cout << (options.json ? refused_json(options.scene, e.what(), e.uses())
                               : refused_text(options.scene, e.uses()))
              << std::flush;
    throw;
  }
  const SceneInfo info =
      scene_info(*scene, options, [&](const std::string& what) { progress.step(what); });
  progress.clear();
  std::cout << (options.json ? info_json(*scene, info) : info_text(*scene, info)) << std::flush;
  return 0;
}

}  // namespace wp::cli
