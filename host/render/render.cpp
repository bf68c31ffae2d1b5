#include "host/render/render.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "host/accel/bvh_cache.h"
#include "host/accel/bvh_input.h"
#include "host/device/device_scene.h"
#include "host/util/error.h"
#include "host/util/files.h"
#include "host/util/fnv1a.h"

namespace wp {

namespace {
double since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}
}  // namespace

void validate(const RenderSettings& s) {
  const auto check = [](bool ok, const std::string& what) {
    if (!ok) throw Error(what);
  };
  check(s.width >= 1 && s.width <= 16384, "--width must be between 1 and 16384");
  check(s.height >= 1 && s.height <= 16384, "--height must be between 1 and 16384");
  check(s.spp >= 1, "--spp must be at least 1");
  check(s.sample_begin >= 0 && s.spp <= int(WP_FILM_MAX_SAMPLES) - s.sample_begin,
        "--samples: the sample indices must lie within 0:1048576");
  check(s.max_depth >= 0 && s.max_depth <= 1024, "--max-depth must be between 0 and 1024");
  check(s.rr_depth >= 0, "--rr-depth must be at least 0");
  check(s.rr_threshold > 0.0f && s.rr_threshold <= 1.0f,
        "--rr-threshold must be greater than 0 and at most 1");
  check(s.bvh_width == 0 || s.bvh_width == 2 || s.bvh_width == 8, "--bvh-width must be 2 or 8");
  check(std::isfinite(s.env_intensity) && s.env_intensity >= 0.0f,
        "--env-intensity must be a finite, non-negative number");
  check(std::isfinite(s.env_rotation), "--env-rotation must be a finite number");
  for (int i = 0; i < 3; ++i)
    check(std::isfinite(s.background[i]) && s.background[i] >= 0.0f,
          "--env-color must be three finite, non-negative numbers");
}

std::string render_key(const Scene& scene, const RenderSettings& s, int bvh_width,
                       bool spatial_splits, std::uint64_t kernel_digest) {
  const auto num = [](float v) {  // 9 significant digits: every float reads back exactly
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", static_cast<double>(v));
    return std::string(buf);
  };
  std::string env = "none";
  if (s.environment) {
    std::uint64_t h = kFnv1aOffset;
    for (const glm::vec4& t : s.environment->texels) h = fnv1a64(&t[0], 3 * sizeof(float), h);
    env = std::to_string(s.environment->width) + "x" + std::to_string(s.environment->height) + ":" +
          hex64(h);
  }
  std::ostringstream k;
  k << "scene=" << hex64(scene.digest) << ";env=" << env << ";width=" << s.width
    << ";height=" << s.height << ";max_depth=" << s.max_depth << ";rr_depth=" << s.rr_depth
    << ";rr_threshold=" << num(s.rr_threshold) << ";seed=" << s.seed
    << ";background=" << num(s.background.x) << "," << num(s.background.y) << ","
    << num(s.background.z) << ";env_intensity=" << num(s.env_intensity)
    << ";env_rotation=" << num(s.env_rotation) << ";strategy="
    << (s.strategy == Strategy::kMis   ? "mis"
        : s.strategy == Strategy::kNee ? "nee"
                                       : "bsdf")
    << ";mis_heuristic=" << (s.mis_heuristic == MisHeuristic::kPower ? "power" : "balance")
    << ";light_select=" << (s.light_select == LightSelect::kPower ? "power" : "uniform")
    << ";sampler=" << sampler_name(s.sampler) << ";camera=" << s.camera
    << ";features=" << (s.all_features ? "all" : "scene") << ";bvh_width=" << bvh_width
    << ";spatial_splits=" << (spatial_splits ? 1 : 0) << ";aov=" << (s.aov ? 1 : 0)
    << ";kernels=" << hex64(kernel_digest);
  return k.str();
}

const char* stop_reason_name(StopReason reason) {
  switch (reason) {
    case StopReason::kComplete:
      return "complete";
    case StopReason::kTimeLimit:
      return "time_limit";
    case StopReason::kNoiseThreshold:
      return "noise_threshold";
    case StopReason::kInterrupted:
      return "interrupted";
  }
  return "unknown";
}

namespace {

// Bytes of memory the system says are available (/proc/meminfo's MemAvailable), or 0 when it
// does not say.
std::uint64_t available_memory() {
  std::FILE* f = std::fopen("/proc/meminfo", "r");
  if (!f) return 0;
  char line[256];
  unsigned long long kib = 0;
  while (std::fgets(line, sizeof line, f))
    if (std::sscanf(line, "MemAvailable: %llu kB", &kib) == 1) break;
  std::fclose(f);
  return std::uint64_t(kib) * 1024;
}

}  // namespace

void check_scene_memory(std::uint64_t bytes, const DeviceEntry& device, std::uint64_t available) {
  const auto gb = [](std::uint64_t b) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2f GB", double(b) / 1e9);
    return std::string(buf);
  };
  if (device.gpu) {
    if (device.global_memory && bytes > device.global_memory)
      throw Error("scene too large for the device: it packs into " + gb(bytes) + ", " +
                  device.name + " has " + gb(device.global_memory));
    return;
  }
  if (available && bytes > available)
    throw Error("scene too large for this machine's memory: it packs into " + gb(bytes) + ", " +
                gb(available) + " are available");
}

int bvh_width(const DeviceEntry& device, const RenderSettings& settings) {
  if (settings.bvh_width) return settings.bvh_width;
  return device.gpu ? 2 : 8;
}

Rendered render(ClRuntime& runtime, const Scene& scene, const RenderSettings& settings,
                const RenderOptions& options) {
  validate(settings);
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::uint32_t> flags;
  bvh::BuildOptions bvh_options = options.bvh;
  bvh_options.width = bvh_width(runtime.device(), settings);
  bool cached = false;
  // A scene too large for the device's buffers (device_scene.h) or its memory fails now, not
  // after its BVH is built (minutes for tens of millions of triangles) and cached: first with the
  // least BVH its triangles need, then, before it is cached, with the BVH built.
  const SceneCounts counts = scene_counts(scene, settings.environment.get());
  const std::uint64_t max_buffer = scene_buffer_limit(runtime.device(), settings);
  check_scene_memory(
      scene_layout(counts, min_bvh_bytes(counts.triangles, bvh_options.width), max_buffer)
          .total_bytes(),
      runtime.device(), available_memory());
  const bvh::Bvh bvh = bvh::build_cached(
      bvh_input(scene, flags), bvh_options, options.bvh_cache ? cache_dir() : std::string(),
      &cached, [&](const bvh::Bvh& built) {
        check_scene_memory(scene_layout(counts, bvh_bytes(built), max_buffer).total_bytes(),
                           runtime.device(), available_memory());
      });

  Wavefront wavefront(runtime, scene, bvh, settings);

  Rendered out;
  RenderReport& r = out.report;
  r.device = runtime.device().name;
  r.features = wavefront.features().describe();
  r.build_options = wavefront.build_options();
  r.triangles = scene.triangle_count();
  r.bvh = bvh.stats;
  r.bvh_cached = cached;
  r.kernel_cached = wavefront.kernel_cached();
  r.kernel_build_seconds = wavefront.build_seconds();
  r.kernel_binary_bytes = wavefront.binary_bytes();
  r.setup_seconds = since(start);
  r.wave_size = wavefront.wave_paths();
  r.bytes_per_path = wavefront.path_state().bytes_per_path;
  r.scene_bytes = wavefront.scene_bytes();
  r.scene_buffers = wavefront.scene_buffer_count();

  const std::uint32_t begin = static_cast<std::uint32_t>(settings.sample_begin);
  const std::uint32_t end = begin + static_cast<std::uint32_t>(settings.spp);
  FilmInfo info;
  info.width = settings.width;
  info.height = settings.height;
  info.aov = settings.aov;
  info.sample_begin = begin;
  info.key = render_key(scene, settings, bvh_options.width, bvh_options.spatial_splits,
                        wavefront.source_digest());
  info.device = r.device;
  std::uint32_t next = begin;  // the next sample index to render
  std::uint64_t resumed_nonfinite = 0;
  if (options.resume) {
    const FilmInfo& from = options.resume->info();
    FilmInfo want = info;
    want.sample_end = from.sample_end;
    const std::string problem = film_identity_problem(from, want);
    if (!problem.empty()) throw Error("the film to resume is of another render: " + problem);
    if (from.sample_begin != begin || from.sample_end > end)
      throw Error("the film to resume holds samples " + std::to_string(from.sample_begin) + ":" +
                  std::to_string(from.sample_end) + ", not the start of the requested " +
                  std::to_string(begin) + ":" + std::to_string(end));
    wavefront.load_film(*options.resume);
    next = from.sample_end;
    resumed_nonfinite = from.nonfinite_samples;
    info.device = join_devices(from.device, r.device);
  }
  // The film of samples [begin, next), read back from the device.
  const auto film_so_far = [&] {
    FilmInfo i = info;
    i.sample_end = next;
    i.nonfinite_samples = resumed_nonfinite + wavefront.nonfinite_samples();
    return wavefront.film(std::move(i));
  };

  if (options.passes_starting) options.passes_starting();
  const auto passes_start = std::chrono::steady_clock::now();
  auto last_checkpoint = passes_start;
  // The sample count at which the noise threshold is checked next.
  std::uint32_t next_check = begin + kNoiseMinSamples;
  while (next < end) {
    if (options.deadline && r.passes > 0) {
      const auto mean_pass = (std::chrono::steady_clock::now() - passes_start) / r.passes;
      if (std::chrono::steady_clock::now() + mean_pass > *options.deadline) {
        r.stop = StopReason::kTimeLimit;
        break;
      }
    }
    // The absolute sample index: the random numbers of sample s are the same in every part.
    // A pass renders as many samples as a wave holds (several for a small image), but stops at
    // the next noise check, so that the checks, and where they stop, do not depend on it.
    std::uint32_t samples = std::min<std::uint32_t>(
        static_cast<std::uint32_t>(wavefront.samples_per_wave()), end - next);
    if (options.noise_threshold > 0 && next_check > next)
      samples = std::min(samples, next_check - next);
    wavefront.render_pass(next, samples);
    next += samples;
    if (r.passes++ == 0) r.first_pass_seconds = since(start);
    if (options.progress)
      options.progress(int(next - begin), settings.spp, since(passes_start), r.passes);
    if (options.interrupted && options.interrupted()) {
      r.stop = StopReason::kInterrupted;
      break;
    }
    if (options.noise_threshold > 0 && next < end && next >= next_check) {
      const double e = relative_error(film_so_far().images());
      if (e <= options.noise_threshold) {
        r.stop = StopReason::kNoiseThreshold;
        break;
      }
      const double n = next - begin;
      const double predicted =
          std::ceil(n * (e / options.noise_threshold) * (e / options.noise_threshold));
      next_check = begin + static_cast<std::uint32_t>(std::clamp(predicted, n + 1, 2 * n));
    }
    if (options.checkpoint && next < end && since(last_checkpoint) >= options.checkpoint_every) {
      options.checkpoint(film_so_far());
      ++r.checkpoints;
      last_checkpoint = std::chrono::steady_clock::now();
    }
  }
  r.render_seconds = since(passes_start);
  r.nonfinite_samples = resumed_nonfinite + wavefront.nonfinite_samples();
  r.rays = wavefront.rays_traced();
  r.stages = wavefront.stage_times();
  out.film = film_so_far();
  r.sample_end = next;
  if (options.checkpoint) {
    options.checkpoint(out.film);
    ++r.checkpoints;
  }
  FilmImages images = out.film.images();
  r.relative_error = relative_error(images);
  out.image = {settings.width, settings.height, std::move(images.mean)};
  out.variance = {settings.width, settings.height, std::move(images.variance)};
  return out;
}

}  // namespace wp
