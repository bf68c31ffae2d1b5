// A render's options resolved once for a device and a scene: the BVH layout, the kernel features,
// the wave's shape and the device memory it needs, the packets and the program's build options.
// render() makes the plan; the Wavefront takes it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "bvh/bvh.h"
#include "host/device/cl_runtime.h"
#include "host/device/scene_features.h"
#include "host/render/path_state.h"
#include "host/render/settings.h"
#include "host/scene/scene.h"

namespace wp {

// The paths a wave of a small image holds by default (RenderSettings::wave_size): fewer waves
// per sample, so fewer launches that trace only the last bounces' few rays. 2^16 to 2^18 measured
// alike on PoCL (docs/performance.md, "Waves of several samples"); 2^18 for a GPU, which keeps
// about that many threads in flight.
constexpr std::size_t kMultiSamplePaths = std::size_t(1) << 18;

// The most bytes of one scene buffer on `device` with `settings`.
std::uint64_t scene_buffer_limit(const DeviceEntry& device, const RenderSettings& settings);

// The paths of one wave for `settings` (RenderSettings::wave_size): `pixels` pixels, `samples`
// samples of each. Without a wave size and with `auto_paths` (not 0): an image of more pixels in
// the nearest whole number of waves of auto_paths, evenly (at least one), a smaller one in whole
// samples up to auto_paths paths; without either, min(pixels, 2^20) pixels, several samples of a
// small image (kMultiSamplePaths).
struct WaveShape {
  std::size_t pixels = 0, samples = 1;
  std::size_t paths() const { return pixels * samples; }
};
WaveShape wave_shape(const RenderSettings& settings, std::size_t auto_paths = 0);

// The paths of a wave by default on `device` (null: unknown) for paths of `bytes_per_path` bytes
// of path state and queue slots: on a CPU device the largest power of two of them whose state fits
// the device's global memory cache (CL_DEVICE_GLOBAL_MEM_CACHE_SIZE, the last-level cache on
// PoCL), kept within [2^16, 2^20], so that every bounce's stages find the paths in the cache
// (docs/performance.md, "Waves that fit the cache"); 0 for a GPU or a device that reports no
// cache: wave_shape's other rule.
std::size_t auto_wave_paths(const DeviceEntry* device, std::size_t bytes_per_path);

// The largest --wave-size.
constexpr std::size_t kMaxWaveSize = std::size_t(1) << 24;

// The environment's WAVEPATH_WAVE_SIZE, the paths of a wave for renders that set no wave size
// (RenderSettings::wave_size 0) in place of the device's rule: the tests' second machine shape
// (.ci/run, docs/testing.md) and a tuning aid. 0 when unset or empty; throws wp::Error for a value
// that is not a whole number in [1, kMaxWaveSize].
std::size_t environment_wave_size();

// The device memory a Wavefront allocates besides the packed scene, for `settings` and a program
// of `features` (they decide the path state's optional fields).
struct StateMemory {
  WaveShape wave;
  PathStateLayout path_state;  // the path-state buffer (path_state.h)
  std::uint64_t queues = 0;    // WP_QUEUE_COUNT queues of a wave's path slots
  std::uint64_t counters = 0;  // WP_COUNTER_COUNT
  std::uint64_t film = 0;      // the film's fixed-point sums (kernels/shared/film.h)
  std::uint64_t total() const { return path_state.bytes + queues + counters + film; }
};
// `device`: the one the wave runs on (auto_wave_paths), null for wave_shape's rule without it.
// Without a wave size in `settings`, WAVEPATH_WAVE_SIZE (environment_wave_size) is taken as one.
StateMemory state_memory(const RenderSettings& settings, const SceneFeatures& features,
                         const DeviceEntry* device = nullptr);

// The kernel features a render of `scene` compiles in: all of them with settings.all_features,
// else those the scene (and settings.environment) uses; without texture_lod under --mipmaps off.
// texture_lod also decides whether the packed scene carries mip chains (SceneExtras::mipmaps,
// scene_counts).
SceneFeatures render_features(const Scene& scene, const RenderSettings& settings);

// The BVH layout for `device`: settings.bvh_width if set, else 2 (binary, both child boxes in the
// parent) on GPUs and 8 (wide, float8 box tests) on CPUs.
int bvh_width(const DeviceEntry& device, const RenderSettings& settings);

struct RenderPlan {
  // Before the BVH is built (plan_render).
  int bvh_width = 8;                     // the layout to build (bvh_width)
  SceneFeatures features;                // compiled into the program (render_features)
  std::uint64_t scene_buffer_limit = 0;  // the most bytes of one scene buffer
  StateMemory memory;                    // the wave's shape and the buffers besides the scene
  std::size_t local_size = 64;           // work-group size of every launch
  bool pocl_cpu = false;                 // PoCL's CPU device: cache hints and packets pay there
  // Once the BVH is built (plan_program): rays or paths per work-item, 1 or 8.
  std::uint32_t shadow_packet = 1;   // shadow rays (kernels/traversal/traverse8_packet.h)
  std::uint32_t closest_packet = 1;  // closest-hit rays, where a bounce uses packets
  std::uint32_t shade_packet = 1;    // paths of the fused shade kernel
  std::string program_options;       // the program's build options
};

// The plan of a render of `scene` with `settings` on `device`, up to the BVH: its layout, the
// features, the buffer limit, the wave and its memory, the work-group size.
RenderPlan plan_render(const DeviceEntry& device, const Scene& scene,
                       const RenderSettings& settings);
// The rest of the plan once `bvh` (built over the scene, of any width) exists: its width, the
// packets and the build options.
void plan_program(RenderPlan& plan, const RenderSettings& settings, const bvh::Bvh& bvh);

}  // namespace wp
