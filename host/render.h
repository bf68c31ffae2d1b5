// One render from a loaded scene to a linear image and a report: BVH build, device set-up,
// sample passes with progress, read-back.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "bvh/bvh.h"
#include "host/cl_runtime.h"
#include "host/image_io.h"
#include "host/scene.h"
#include "host/wavefront.h"

namespace wp {

struct RenderReport {
  std::string device;
  std::string features;       // the kernel features the program was built with
  std::string build_options;  // the program's build options
  std::size_t triangles = 0;
  bvh::BuildStats bvh;      // build_seconds: of the build, or of the cache look-up when cached
  bool bvh_cached = false;  // loaded from the BVH cache (bvh/bvh_cache.h)
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
  int scene_buffers = 0;          // the buffers it is split over (device_scene.h)
  StageTimes stages;              // with RenderSettings::profile
  int ranks = 1;  // processes whose samples this is (MPI, host/distributed.h); set by the caller
  double samples_per_second(const RenderSettings& s) const {
    return render_seconds > 0 ? double(s.width) * s.height * s.spp / render_seconds : 0.0;
  }
};

struct RenderOptions {
  bvh::BuildOptions bvh;   // the width is set per device (bvh_width)
  bool bvh_cache = false;  // look the BVH up in, and store it to, bvh::cache_dir()
  // Called after each sample pass with (passes done, passes in all, seconds since the start).
  std::function<void(int, int, double)> progress;
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

// The render key: one line naming everything that changes the image, so that films merge only
// with films of the same render (host/film.h). ';'-separated name=value fields: the scene's digest
// (Scene::digest), the environment map's (FNV-1a 64 of its texels) or none, width, height,
// max_depth, rr_depth, seed, background, env_intensity, env_rotation, strategy, mis_heuristic,
// light_select, camera, features, bvh_width, spatial_splits and the kernels' source digest. Not
// in it, as they do not change the image: the sample range, wave and work-group sizes, the scene
// buffer limit, the device, caching, outputs and reporting.
std::string render_key(const Scene& scene, const RenderSettings& settings, int bvh_width,
                       bool spatial_splits, std::uint64_t kernel_digest);

// Checks the ranges of user-facing settings; throws wp::Error naming the option.
void validate(const RenderSettings& settings);

// The BVH build input for `scene`: its triangles, and per triangle the WP_TRI_* flags its
// material implies (back-face culling for single-sided materials, alpha testing), kept in `flags`.
bvh::BuildInput bvh_input(const Scene& scene, std::vector<std::uint32_t>& flags);

// The BVH layout for `device`: settings.bvh_width if set, else 2 (binary, both child boxes in the
// parent) on GPUs and 8 (wide, float8 box tests) on CPUs.
int bvh_width(const DeviceEntry& device, const RenderSettings& settings);

}  // namespace wp
