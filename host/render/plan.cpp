#include "host/render/plan.h"

#include <algorithm>
#include <cstdlib>

#include "host/util/error.h"
#include "host/device/device_scene.h"
#include "kernels/shared/film.h"
#include "kernels/shared/types.h"

namespace wp {

namespace {

// The one place where program build options are assembled: the scene's features and the
// settings that are compile-time constants of the kernels.
std::string program_options(const SceneFeatures& features, const RenderSettings& s, int bvh_width,
                            std::size_t group_size, bool prefetch) {
  std::string o = "-cl-std=CL1.2 -D WP_BVH_WIDTH=" + std::to_string(bvh_width);
  if (features.instances) o += " -D WP_BVH_INSTANCES=1";
  o += " -D WP_GROUP_SIZE=" + std::to_string(group_size);
  if (prefetch) o += " -D WP_PREFETCH=1";
  for (const auto& [name, on] : features.flags()) o += " -D " + name + "=" + (on ? "1" : "0");
  o += std::string(" -D WP_MIS_POWER=") + (s.mis_heuristic == MisHeuristic::kPower ? "1" : "0");
  // kernels/util/features.h's WP_SAMPLER_INDEPENDENT, _SOBOL and _SOBOL_PADDED.
  o += std::string(" -D WP_SAMPLER=") + (s.sampler == Sampler::kIndependent ? "0"
                                         : s.sampler == Sampler::kSobol     ? "1"
                                                                            : "2");
  if (s.aov) o += " -D WP_AOV=1";
  if (s.view.aperture > 0.0f) o += " -D WP_THIN_LENS=1";
  // Only with a map and bilinear lookup, so that nearest programs stay as they were.
  if (features.environment && s.env_filter == EnvFilter::kBilinear) o += " -D WP_ENV_BILINEAR=1";
  return o;
}

}  // namespace

std::uint64_t scene_buffer_limit(const DeviceEntry& device, const RenderSettings& settings) {
  if (settings.scene_buffer_bytes) return settings.scene_buffer_bytes;
  return device.max_alloc ? device.max_alloc : kSceneBufferReach;
}

WaveShape wave_shape(const RenderSettings& settings, std::size_t auto_paths) {
  const std::size_t pixels = std::size_t(settings.width) * std::size_t(settings.height);
  const std::size_t size = settings.wave_size ? settings.wave_size : auto_paths;
  WaveShape wave;
  if (!settings.wave_size && auto_paths && pixels > auto_paths) {
    // The nearest whole number of waves of auto_paths, the pixels spread evenly over them: no
    // short last wave paying a whole wave's launches, and an image up to 1.5 waves in one.
    const std::size_t waves = std::max<std::size_t>(1, (pixels + auto_paths / 2) / auto_paths);
    wave.pixels = (pixels + waves - 1) / waves;
    return wave;
  }
  wave.pixels = std::min(pixels, size ? size : std::size_t(1) << 20);
  const std::size_t multi = size ? size : kMultiSamplePaths;
  wave.samples = std::max<std::size_t>(1, multi / wave.pixels);
  return wave;
}

std::size_t auto_wave_paths(const DeviceEntry* device, std::size_t bytes_per_path) {
  if (!device || device->gpu || device->cache_bytes == 0 || bytes_per_path == 0) return 0;
  const std::size_t fit = static_cast<std::size_t>(device->cache_bytes / bytes_per_path);
  std::size_t paths = std::size_t(1) << 16;
  while (paths < (std::size_t(1) << 20) && paths * 2 <= fit) paths *= 2;
  return paths;
}

std::size_t environment_wave_size() {
  const char* text = std::getenv("WAVEPATH_WAVE_SIZE");
  if (!text || !*text) return 0;
  char* end = nullptr;
  const unsigned long long size = std::strtoull(text, &end, 10);
  if (*end != '\0' || text[0] == '-' || size == 0 || size > kMaxWaveSize)
    throw Error(std::string("WAVEPATH_WAVE_SIZE=") + text + ": must be a whole number from 1 to " +
                std::to_string(kMaxWaveSize));
  return static_cast<std::size_t>(size);
}

StateMemory state_memory(const RenderSettings& settings, const SceneFeatures& features,
                         const DeviceEntry* device) {
  StateMemory m;
  const std::size_t per_path =
      path_state_layout(1, settings.aov, features, settings.fused).bytes_per_path +
      WP_QUEUE_COUNT * sizeof(dev::uint);
  if (!settings.wave_size) {
    if (const std::size_t forced = environment_wave_size()) {
      RenderSettings with_wave = settings;
      with_wave.wave_size = forced;
      m.wave = wave_shape(with_wave);
    }
  }
  if (!m.wave.pixels) m.wave = wave_shape(settings, auto_wave_paths(device, per_path));
  m.path_state = path_state_layout(m.wave.paths(), settings.aov, features, settings.fused);
  m.queues = std::uint64_t(WP_QUEUE_COUNT) * m.wave.paths() * sizeof(dev::uint);
  m.counters = WP_COUNTER_COUNT * sizeof(dev::uint);
  const std::uint64_t pixels = std::uint64_t(settings.width) * std::uint64_t(settings.height);
  m.film = pixels * WP_FILM_WORDS(settings.aov) * sizeof(std::uint64_t);
  return m;
}

SceneFeatures render_features(const Scene& scene, const RenderSettings& settings) {
  SceneFeatures f = settings.all_features
                        ? SceneFeatures::all()
                        : SceneFeatures::of(scene, settings.environment != nullptr);
  if (!settings.mipmaps) f.texture_lod = false;
  f.instances = !scene.instances.empty();
  return f;
}

int bvh_width(const DeviceEntry& device, const RenderSettings& settings) {
  if (settings.bvh_width) return settings.bvh_width;
  return device.gpu ? 2 : 8;
}

RenderPlan plan_render(const DeviceEntry& device, const Scene& scene,
                       const RenderSettings& settings) {
  RenderPlan plan;
  plan.bvh_width = bvh_width(device, settings);
  plan.features = render_features(scene, settings);
  plan.scene_buffer_limit = scene_buffer_limit(device, settings);
  plan.memory = state_memory(settings, plan.features, &device);
  // An explicit work-group size always: left to itself, PoCL picks one per global size (a divisor
  // of it) and compiles every kernel again for each new one, seconds each time.
  plan.local_size = settings.local_size ? settings.local_size : 64;
  plan.pocl_cpu = !device.gpu && device.platform_name == "Portable Computing Language";
  return plan;
}

void plan_program(RenderPlan& plan, const RenderSettings& settings, const bvh::Bvh& bvh) {
  plan.bvh_width = bvh.width;
  const SceneFeatures& f = plan.features;
  // Cache hints in the stages that read path state through a queue (kernels/util/features.h,
  // WP_PREFETCH): on PoCL's CPU devices, where clang's __builtin_prefetch becomes a prefetch
  // instruction and every address space is one.
  const bool prefetch = settings.prefetch && plan.pocl_cpu;
  std::string& options = plan.program_options;
  options = program_options(f, settings, bvh.width, plan.local_size, prefetch);
  // Rays eight to a work-item (kernels/traversal/traverse8_packet.h) on the wide layout without
  // instances or alpha: shadow rays where they are plain any-hit queries (no transmission),
  // closest-hit rays always there. Only on PoCL's CPU devices, where it was measured
  // (docs/performance.md, "Shadow rays in packets of eight", "Closest-hit rays in packets"), unless
  // the settings force them (the Oclgrind tests). The same image either way.
  const bool packets_here = plan.pocl_cpu || settings.force_packets;
  const bool packets = packets_here && bvh.width == 8 && !f.instances && !f.alpha;
  plan.shadow_packet = settings.shadow_packets && packets && !f.transmission ? 8u : 1u;
  plan.closest_packet = settings.closest_packets && packets ? 8u : 1u;
  if (plan.shadow_packet > 1) options += " -D WP_SHADOW_PACKET=1";
  if (plan.closest_packet > 1) options += " -D WP_CLOSEST_PACKET=1";
  // In a scene of a few large triangles (at most kMaskedClosestBlocks blocks of four: the Cornell
  // box's kind) every packet reaches most triangles and whether any lane lies inside one is a coin
  // toss, so the closest-hit packet takes each triangle's lanes by mask instead of branching on
  // that; on a dense mesh the branch is predictable and skips the division (docs/performance.md,
  // "Closest-hit packets without a branch per triangle"). The same hits either way.
  constexpr std::size_t kMaskedClosestBlocks = 64;
  if (plan.closest_packet > 1 && bvh.blocks.size() <= kMaskedClosestBlocks)
    options += " -D WP_PACKET_MASKED_CLOSEST=1";
  // Shading eight paths per work-item, float8 lanes being paths, where every scattering surface
  // is Lambertian or glTF's metallic-roughness without extensions or transmission, textured or
  // not (kernels/integrator/shade_packet.h says what it needs).
  const bool plain = !f.transmission && !f.volume && !f.specular && !f.clearcoat && !f.sheen &&
                     !f.anisotropy && !f.iridescence && !f.diffuse_transmission && !f.dispersion &&
                     !f.instances;
  plan.shade_packet = settings.shade_packets && packets_here && plain && !settings.aov ? 8u : 1u;
  if (plan.shade_packet > 1) options += " -D WP_SHADE_PACKET=1";
  const bool forced = !plan.pocl_cpu &&
                      (plan.shade_packet > 1 || plan.shadow_packet > 1 || plan.closest_packet > 1);
  if (forced) options += " -D WP_PACKETS_FORCED=1";
}

}  // namespace wp
