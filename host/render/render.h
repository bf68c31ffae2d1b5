// One render from a loaded scene to a linear image and a report: BVH build, device set-up,
// sample passes with progress, read-back.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "bvh/bvh.h"
#include "host/device/cl_runtime.h"
#include "host/film/image_io.h"
#include "host/scene/gltf_loader.h"
#include "host/scene/scene.h"
#include "host/render/wavefront.h"

namespace wp {

// Why the sample passes ended.
enum class StopReason {
  kComplete,        // every requested sample was rendered
  kTimeLimit,       // RenderOptions::deadline
  kNoiseThreshold,  // RenderOptions::noise_threshold
  kInterrupted,     // RenderOptions::interrupted
};
// "complete", "time_limit", "noise_threshold", "interrupted" (JSON and EXR header values).
const char* stop_reason_name(StopReason reason);

// The fewest samples (in the film, resumed ones included) from which the noise threshold is
// checked: below, a pixel's variance estimate is too often 0 (no sample found the light yet).
constexpr int kNoiseMinSamples = 16;

struct RenderReport {
  std::string device;
  std::string features;       // the kernel features the program was built with
  std::string build_options;  // the program's build options
  std::size_t triangles = 0;  // stored: each instanced mesh once
  // An instanced scene's instances and the triangles they place (else 0 and `triangles`).
  std::uint64_t instances = 0, world_triangles = 0;
  bvh::BuildStats bvh;      // build_seconds: of the build, or of the cache look-up when cached
  bool bvh_cached = false;  // loaded from the BVH cache (host/accel/bvh_cache.h)
  bool kernel_cached =
      false;  // the program built from the kernel cache (host/device/program_cache.h)
  double kernel_build_seconds = 0;  // includes the OpenCL implementation's cache lookup
  std::size_t kernel_binary_bytes = 0;
  double setup_seconds = 0;       // BVH, upload, program: from scene to first pass
  double render_seconds = 0;      // sample passes, wall clock
  double first_pass_seconds = 0;  // from the call to the end of the first pass
  std::uint64_t nonfinite_samples = 0;
  std::uint64_t rays = 0;  // closest-hit rays traced (camera and bounce rays; not shadow rays)
  std::size_t wave_size = 0;
  std::size_t bytes_per_path = 0;
  std::uint64_t scene_bytes = 0;  // the packed scene on the device
  // Of it, the textures' texels, and of those the mip levels (at most a third of the rest).
  std::uint64_t texture_bytes = 0, mip_bytes = 0;
  int scene_buffers = 0;  // the buffers it is split over (device_scene.h)
  StageTimes stages;      // with RenderSettings::profile
  // Closest-hit rays per work-item in a packet (1: the program has none), and how each bounce
  // index traced its closest-hit rays (Wavefront::closest_packet, packet_timing).
  std::uint32_t closest_packet = 1;
  std::vector<PacketTiming> closest_packets;
  std::uint32_t shadow_packet = 1;  // the same for shadow rays
  std::vector<PacketTiming> shadow_packets;
  // trace_shadow launched ahead of its queue's count, and for the rest of a queue past such a
  // launch's estimate (Wavefront::run_bounce, RenderSettings::shadow_ahead); not in the JSON.
  std::uint64_t shadow_ahead_launches = 0, shadow_rest_launches = 0;
  // The film holds samples [settings.sample_begin, sample_end): all requested, or fewer when the
  // passes stopped early (`stop`).
  std::uint32_t sample_end = 0;
  int passes = 0;  // sample passes rendered by this call (resumed ones not)
  // Samples of every pixel rendered by this call (resumed ones not; all ranks' under MPI). A pass
  // holds several when the image is smaller than a wave.
  std::uint32_t samples_rendered = 0;
  StopReason stop = StopReason::kComplete;
  double relative_error = 0;  // the film's estimated relative error at the end (film.h)
  int checkpoints = 0;        // RenderOptions::checkpoint calls
  int ranks =
      1;  // processes whose samples this is (MPI, host/cli/distributed.h); set by the caller
  // Pixel samples per second of the passes: width x height x samples_rendered / render_seconds.
  double samples_per_second(const RenderSettings& s) const {
    return render_seconds > 0 ? double(s.width) * s.height * samples_rendered / render_seconds
                              : 0.0;
  }
};

struct RenderOptions {
  bvh::BuildOptions bvh;   // the width is set per device (bvh_width)
  bool bvh_cache = false;  // look the BVH up in, and store it to, cache_dir() (host/util/files.h)
  // Called after each sample pass with (samples in the film, samples requested, seconds since
  // the start of the passes, samples rendered by this call: the film's less any resumed).
  std::function<void(int, int, double, int)> progress;
  // Called as each step of the set-up before the passes starts, with what it does, e.g.
  // "building the BVH of 20000000 triangles" (the CLI's status line on a terminal).
  std::function<void(const std::string&)> setup_step;

  // Continue this film (a checkpoint) instead of starting from zero: the same render key and
  // size, and samples [sample_begin, k) with k <= sample_begin + spp of the settings. Its samples
  // are not rendered again, and the result is the film of one uninterrupted render, bit for bit.
  const Film* resume = nullptr;
  // Called once, just before the first sample pass (after the BVH and the kernels are built).
  std::function<void()> passes_starting;
  // Polled after every pass: true ends the passes (StopReason::kInterrupted).
  std::function<bool()> interrupted;
  // No pass is started that would end, at the mean pass time so far, after `deadline`; the first
  // pass of a call is always rendered (StopReason::kTimeLimit).
  std::optional<std::chrono::steady_clock::time_point> deadline;
  // > 0: end the passes once the film's estimated relative error (film.h, relative_error) is at
  // most this (StopReason::kNoiseThreshold). Checked from kNoiseMinSamples samples on, at sample
  // counts predicted from the last estimate e at n samples as n (e / threshold)^2 (the error
  // falls as 1/sqrt(n)), at least n + 1 and at most 2n: O(log) read-backs of the film, and the
  // samples at which it stops depend on the film alone, so the same render stops at the same
  // count on every device.
  double noise_threshold = 0;
  // Called with the film so far every `checkpoint_every` seconds (at a pass boundary) and once
  // after the last pass.
  std::function<void(const Film&)> checkpoint;
  double checkpoint_every = 0;
};

struct Rendered {
  ImageRgb image;     // the estimate of every pixel
  ImageRgb variance;  // the variance of each pixel's estimate (sample variance / spp)
  Film film;          // the sums both come from, with the render key and the sample range
  RenderReport report;
};

// Throws wp::Error on invalid settings or device failures.
Rendered render(ClRuntime& runtime, const Scene& scene, const RenderSettings& settings,
                const RenderOptions& options = {});
// The same render of a scene that is not needed after it: its geometry and images are freed as
// they are packed (HostArrays::kRelease), so that a large scene is not held twice; `scene` is left
// without them.
Rendered render(ClRuntime& runtime, Scene&& scene, const RenderSettings& settings,
                const RenderOptions& options = {});

// The render key: one line naming everything that changes the image, so that films merge only
// with films of the same render (host/film/film.h). ';'-separated name=value fields: the scene's
// digest (Scene::digest), the environment map's (FNV-1a 64 of its texels, then env_filter) or none,
// width, height,
// max_depth, rr_depth, seed, background, env_intensity, env_rotation, strategy, mis_heuristic,
// light_select, sampler, camera, features, bvh_width, spatial_splits, the kernels' source
// digest, and for an instanced scene its instance count. Not in it, as they do not change the
// image: the sample range, wave and work-group sizes, the scene buffer limit, the device, caching,
// outputs and reporting.
std::string render_key(const Scene& scene, const RenderSettings& settings, int bvh_width,
                       bool spatial_splits, std::uint64_t kernel_digest);

// Fails (wp::Error naming both sizes) when a packed scene of `bytes` cannot be held: on a GPU
// beyond its global memory, on a CPU device beyond `available` bytes of host memory (the packed
// scene is host memory there, used in place; 0: unknown, not checked), where the system would
// otherwise kill the process for memory. render() checks with /proc/meminfo's MemAvailable.
void check_scene_memory(std::uint64_t bytes, const DeviceEntry& device, std::uint64_t available);

// For LoadOptions::check_counts: fails (wp::Error naming the triangles, the placements and both
// sizes) when a scene of these counts cannot be held, before the loader allocates for it: the
// least packed scene its triangles need (their vertex references and light slots, the least BVH
// of `device`'s layout; check_scene_memory, and a single array larger than a device buffer) plus,
// in host memory, the loader's 16 bytes a triangle (indices, material). The CLI frees the loaded
// arrays while it packs them (HostArrays::kRelease), so the two are not held at once; the sum is
// still a lower bound of its peak for any mesh with at least 3 vertices per 8 triangles (closed
// meshes have about 1 per 2): after packing it holds the packed vertices (32 bytes each, left out
// of the least packed scene) and the light table (4 bytes a triangle). A mesh placed by many
// nodes counts once per placement when flattened, so such a scene is refused from its node count
// alone instead of growing until the system kills the process.
void check_scene_counts(const LoadCounts& counts, const DeviceEntry& device,
                        const RenderSettings& settings);
// The host part alone (for `wavepath info`, which packs nothing): the loader's 16 bytes a
// triangle against the memory available.
void check_host_counts(const LoadCounts& counts);

// Fails (wp::Error naming the image size, the bytes needed and the device's limit) when the
// buffers of `memory` cannot be allocated on `device`: one larger than CL_DEVICE_MAX_MEM_ALLOC_SIZE
// (the film, mostly: 96 bytes a pixel, 208 with AOVs), or all of them together beyond
// CL_DEVICE_GLOBAL_MEM_SIZE. render() checks before it allocates anything on the device.
void check_state_memory(const StateMemory& memory, const RenderSettings& settings,
                        const DeviceEntry& device);

// Checks the ranges of user-facing settings; throws wp::Error naming the option.
void validate(const RenderSettings& settings);

}  // namespace wp
