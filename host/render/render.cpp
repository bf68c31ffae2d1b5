#include "host/render/render.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "host/accel/bvh_cache.h"
#include "host/accel/bvh_input.h"
#include "host/device/device_scene.h"
#include "host/scene/gltf_values.h"
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
  // Radiance beyond what float32 carries through the transport (scene.h).
  const std::string limit = " (" + gltf::number_text(kMaxRadiance) + " = 2^64)";
  for (int i = 0; i < 3; ++i)
    check(s.background[i] <= kMaxRadiance,
          "--env-color must be at most the most radiance wavepath carries" + limit);
  if (s.environment)
    check(double(s.env_intensity) * s.environment->max_radiance <= kMaxRadiance,
          "--env-intensity " + gltf::number_text(s.env_intensity) +
              ": the map's brightest texel (" + gltf::number_text(s.environment->max_radiance) +
              ") times it must be at most the most radiance wavepath carries" + limit);
  check_view(s.view, s.camera >= 0);
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
          hex64(h) + ";env_filter=" + env_filter_name(s.env_filter);
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
    << ";sampler=" << sampler_name(s.sampler) << ";mipmaps=" << (s.mipmaps ? "on" : "off")
    << ";camera=" << s.camera << ";view={" << view_text(s.view) << "}"
    << ";features=" << (s.all_features ? "all" : "scene") << ";bvh_width=" << bvh_width
    << ";spatial_splits=" << (spatial_splits ? 1 : 0) << ";aov=" << (s.aov ? 1 : 0)
    << ";kernels=" << hex64(kernel_digest);
  // An instanced scene traverses a two-level BVH (the same image to float rounding, not bit for
  // bit): its films do not merge with the flattened scene's. Only then, so that the keys of
  // flattened scenes stay as they were.
  if (!scene.instances.empty()) k << ";instances=" << scene.instances.size();
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

// "13.94 GB", as the memory errors write sizes.
std::string gb(std::uint64_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f GB", double(bytes) / 1e9);
  return buf;
}

}  // namespace

void check_scene_memory(std::uint64_t bytes, const DeviceEntry& device, std::uint64_t available) {
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

namespace {

// The start of check_scene_counts' and check_host_counts' errors.
std::string too_large(const LoadCounts& counts) {
  if (counts.instanced)
    return "scene too large: its " + std::to_string(counts.mesh_triangles) + " triangles in " +
           std::to_string(counts.meshes) + " meshes (placed " + std::to_string(counts.placements) +
           " times as instances) ";
  return "scene too large: its " + std::to_string(counts.triangles) + " triangles (" +
         std::to_string(counts.placements) + " mesh placements, each a copy of its mesh) ";
}

// The loader's bytes for `triangles`: three indices and a material each.
std::uint64_t loading_bytes(std::uint64_t triangles) {
  return triangles * (3 * sizeof(std::uint32_t) + sizeof(std::uint32_t));
}

}  // namespace

void check_host_counts(const LoadCounts& counts) {
  const std::uint64_t loading = loading_bytes(counts.stored_triangles()),
                      available = available_memory();
  if (available && loading > available)
    throw Error(too_large(counts) + "need at least " + gb(loading) + " of memory to load, " +
                gb(available) + " are available");
}

void check_scene_counts(const LoadCounts& counts, const DeviceEntry& device,
                        const RenderSettings& settings) {
  const std::string what = too_large(counts);
  SceneCounts least;
  least.triangles = counts.stored_triangles();
  if (counts.instanced) least.instances = counts.placements;
  std::uint64_t packed = 0;
  try {
    packed = scene_layout(least, min_bvh_bytes(least.triangles, bvh_width(device, settings)),
                          scene_buffer_limit(device, settings))
                 .total_bytes();
  } catch (const Error& e) {  // an array larger than a buffer, or more than the buffers
    throw Error(what + "cannot be packed: " + e.what());
  }
  const std::uint64_t loading = loading_bytes(least.triangles), available = available_memory();
  if (device.gpu) {
    if (device.global_memory && packed > device.global_memory)
      throw Error(what + "pack into at least " + gb(packed) + ", " + device.name + " has " +
                  gb(device.global_memory));
    check_host_counts(counts);
    return;
  }
  if (available && packed + loading > available)
    throw Error(what + "need at least " + gb(packed + loading) + " of memory (" + gb(packed) +
                " packed, " + gb(loading) + " to load them), " + gb(available) + " are available");
}

void check_state_memory(const StateMemory& memory, const RenderSettings& settings,
                        const DeviceEntry& device) {
  const std::string image =
      std::to_string(settings.width) + " x " + std::to_string(settings.height);
  const auto bytes = [](std::uint64_t b) {
    return std::to_string(b) + " bytes (" + human_bytes(b) + ")";
  };
  const std::pair<const char*, std::uint64_t> buffers[] = {
      {"film", memory.film}, {"path state", memory.path_state.bytes}, {"queue", memory.queues}};
  for (const auto& [name, size] : buffers)
    if (device.max_alloc && size > device.max_alloc)
      throw Error("image too large for the device: " + image + " needs a " + name + " buffer of " +
                  bytes(size) + ", more than the " + bytes(device.max_alloc) + " " + device.name +
                  " allocates at once (CL_DEVICE_MAX_MEM_ALLOC_SIZE)");
  if (device.global_memory && memory.total() > device.global_memory)
    throw Error("image too large for the device: " + image + " needs " + bytes(memory.total()) +
                " of path state, queues and film, more than the " + bytes(device.global_memory) +
                " of " + device.name + " (CL_DEVICE_GLOBAL_MEM_SIZE)");
}

namespace {

// The scene's BVH for `runtime`'s device, from the cache where allowed. A scene too large for the
// device's buffers (device_scene.h) or its memory fails before the build (minutes for tens of
// millions of triangles), with the least BVH its triangles need, and again before a fresh build is
// cached, with the BVH built.
bvh::Bvh scene_bvh(ClRuntime& runtime, const Scene& scene, const RenderSettings& settings,
                   const RenderPlan& plan, const RenderOptions& options,
                   const bvh::BuildOptions& bvh_options, bool* cached) {
  SceneCounts counts = scene_counts(scene, settings.environment.get(), plan.features.texture_lod);
  counts.vertex_arrays = VertexArrays::of(plan.features);
  const std::uint64_t max_buffer = plan.scene_buffer_limit;
  check_scene_memory(
      scene_layout(counts, min_bvh_bytes(counts.triangles, bvh_options.width), max_buffer)
          .total_bytes(),
      runtime.device(), available_memory());
  return build_scene_bvh(scene, bvh_options, options.bvh_cache ? cache_dir() : std::string(),
                         cached, [&](const bvh::Bvh& built) {
                           check_scene_memory(
                               scene_layout(counts, bvh_bytes(built), max_buffer).total_bytes(),
                               runtime.device(), available_memory());
                         });
}

// What the scene is: its triangles and instances, and its BVH's (before packing may free them).
void report_scene(RenderReport& r, const Scene& scene, const bvh::Bvh& bvh, bool bvh_cached) {
  r.triangles = scene.triangle_count();
  r.instances = scene.instances.size();
  r.world_triangles = scene.world_triangle_count();
  r.bvh = bvh.stats;
  r.bvh_cached = bvh_cached;
}

// What the set-up made: device, program, wave and scene sizes.
void report_setup(RenderReport& r, const ClRuntime& runtime, const Wavefront& wavefront) {
  r.device = runtime.device().name;
  r.features = wavefront.features().describe();
  r.build_options = wavefront.build_options();
  r.kernel_cached = wavefront.kernel_cached();
  r.kernel_build_seconds = wavefront.build_seconds();
  r.kernel_binary_bytes = wavefront.binary_bytes();
  r.wave_size = wavefront.wave_paths();
  r.bytes_per_path = wavefront.path_state().bytes_per_path;
  r.scene_bytes = wavefront.scene_bytes();
  r.texture_bytes = wavefront.texture_bytes();
  r.mip_bytes = wavefront.mip_bytes();
  r.scene_buffers = wavefront.scene_buffer_count();
}

// The sample passes of one render: samples [begin, end) into the wavefront's film, pass after
// pass, until every sample is rendered or a stop rule of RenderOptions ends them (deadline,
// interruption, noise threshold); checkpoints between passes.
class PassScheduler {
 public:
  PassScheduler(Wavefront& wavefront, const RenderSettings& settings, const RenderOptions& options,
                FilmInfo info, RenderReport& report)
      : wf_(wavefront),
        settings_(settings),
        options_(options),
        info_(std::move(info)),
        r_(report),
        begin_(static_cast<std::uint32_t>(settings.sample_begin)),
        end_(begin_ + static_cast<std::uint32_t>(settings.spp)),
        next_(begin_),
        next_check_(begin_ + kNoiseMinSamples) {}

  // Continues `film` (RenderOptions::resume): the same render, samples [begin, k) with k <= end.
  void resume(const Film& film) {
    const FilmInfo& from = film.info();
    FilmInfo want = info_;
    want.sample_end = from.sample_end;
    const std::string problem = film_identity_problem(from, want);
    if (!problem.empty()) throw Error("the film to resume is of another render: " + problem);
    if (from.sample_begin != begin_ || from.sample_end > end_)
      throw Error("the film to resume holds samples " + std::to_string(from.sample_begin) + ":" +
                  std::to_string(from.sample_end) + ", not the start of the requested " +
                  std::to_string(begin_) + ":" + std::to_string(end_));
    wf_.load_film(film);
    next_ = from.sample_end;
    resumed_nonfinite_ = from.nonfinite_samples;
    info_.device = join_devices(from.device, info_.device);
  }

  // Renders passes until the samples are done or a stop rule holds (r.stop says which).
  void run(std::chrono::steady_clock::time_point start) {
    passes_start_ = std::chrono::steady_clock::now();
    last_checkpoint_ = passes_start_;
    while (next_ < end_) {
      if (past_deadline()) {
        r_.stop = StopReason::kTimeLimit;
        break;
      }
      const std::uint32_t samples = next_pass_samples();
      wf_.render_pass(next_, samples);
      next_ += samples;
      r_.samples_rendered += samples;
      if (r_.passes++ == 0) r_.first_pass_seconds = since(start);
      if (options_.progress)
        options_.progress(int(next_ - begin_), settings_.spp, since(passes_start_),
                          int(r_.samples_rendered));
      if (options_.interrupted && options_.interrupted()) {
        r_.stop = StopReason::kInterrupted;
        break;
      }
      if (noise_below_threshold()) {
        r_.stop = StopReason::kNoiseThreshold;
        break;
      }
      if (options_.checkpoint && next_ < end_ &&
          since(last_checkpoint_) >= options_.checkpoint_every) {
        options_.checkpoint(film());
        ++r_.checkpoints;
        last_checkpoint_ = std::chrono::steady_clock::now();
      }
    }
    r_.render_seconds = since(passes_start_);
    r_.sample_end = next_;
  }

  // The film of samples [begin, next), read back from the device.
  Film film() {
    FilmInfo i = info_;
    i.sample_end = next_;
    i.nonfinite_samples = nonfinite();
    return wf_.film(std::move(i));
  }
  std::uint64_t nonfinite() { return resumed_nonfinite_ + wf_.nonfinite_samples(); }
  const std::string& device() const { return info_.device; }

 private:
  // No pass is started that would end, at the mean pass time so far, after the deadline; the
  // first pass of a call always is.
  bool past_deadline() const {
    if (!options_.deadline || r_.passes == 0) return false;
    const auto mean_pass = (std::chrono::steady_clock::now() - passes_start_) / r_.passes;
    return std::chrono::steady_clock::now() + mean_pass > *options_.deadline;
  }

  // As many samples as a wave holds (several for a small image), but no further than the next
  // noise check, so that the checks, and where they stop, do not depend on the wave size. The
  // sample indices are absolute: the random numbers of sample s are the same in every part.
  std::uint32_t next_pass_samples() const {
    std::uint32_t samples =
        std::min<std::uint32_t>(static_cast<std::uint32_t>(wf_.samples_per_wave()), end_ - next_);
    if (options_.noise_threshold > 0 && next_check_ > next_)
      samples = std::min(samples, next_check_ - next_);
    return samples;
  }

  // At a noise check (RenderOptions::noise_threshold): whether the film's estimated relative error
  // is at most the threshold; if not, the next check is where the error should fall to it.
  bool noise_below_threshold() {
    if (!(options_.noise_threshold > 0 && next_ < end_ && next_ >= next_check_)) return false;
    const double e = relative_error(film().images());
    if (e <= options_.noise_threshold) return true;
    const double n = next_ - begin_;
    const double ratio = e / options_.noise_threshold;
    const double predicted = std::ceil(n * ratio * ratio);
    next_check_ = begin_ + static_cast<std::uint32_t>(std::clamp(predicted, n + 1, 2 * n));
    return false;
  }

  Wavefront& wf_;
  const RenderSettings& settings_;
  const RenderOptions& options_;
  FilmInfo info_;
  RenderReport& r_;
  const std::uint32_t begin_, end_;
  std::uint32_t next_;        // the next sample index to render
  std::uint32_t next_check_;  // the sample count at which the noise threshold is checked next
  std::uint64_t resumed_nonfinite_ = 0;
  std::chrono::steady_clock::time_point passes_start_, last_checkpoint_;
};

// render(); `owned` is null or `scene`, whose host arrays are then freed as they are packed.
Rendered render_scene(ClRuntime& runtime, const Scene& scene, Scene* owned,
                      const RenderSettings& settings, const RenderOptions& options) {
  validate(settings);
  const auto start = std::chrono::steady_clock::now();
  // The options resolved once for this device and scene (plan.h); completed for the BVH below.
  RenderPlan plan = plan_render(runtime.device(), scene, settings);
  bvh::BuildOptions bvh_options = options.bvh;
  bvh_options.width = plan.bvh_width;
  check_state_memory(plan.memory, settings, runtime.device());
  const auto step = [&](const std::string& what) {
    if (options.setup_step) options.setup_step(what);
  };
  step((options.bvh_cache ? "finding or building the BVH of " : "building the BVH of ") +
       std::to_string(scene.triangle_count()) + " triangles" +
       (scene.instances.empty() ? std::string()
                                : " in " + std::to_string(scene.instances.size()) + " instances"));
  bool cached = false;
  bvh::Bvh bvh = scene_bvh(runtime, scene, settings, plan, options, bvh_options, &cached);
  plan_program(plan, settings, bvh);
  step("packing the scene and building the kernels");
  Rendered out;
  RenderReport& r = out.report;
  report_scene(r, scene, bvh, cached);
  // From here on, with `owned`, the scene's geometry and the BVH's arrays are gone (render_key
  // reads neither).
  Wavefront wavefront =
      owned ? Wavefront(runtime, *owned, bvh, settings, std::move(plan), HostArrays::kRelease)
            : Wavefront(runtime, scene, bvh, settings, std::move(plan));
  report_setup(r, runtime, wavefront);
  r.setup_seconds = since(start);
  FilmInfo info;
  info.width = settings.width;
  info.height = settings.height;
  info.aov = settings.aov;
  info.sample_begin = static_cast<std::uint32_t>(settings.sample_begin);
  info.key = render_key(scene, settings, bvh_options.width, bvh_options.spatial_splits,
                        wavefront.source_digest());
  info.device = r.device;
  PassScheduler passes(wavefront, settings, options, std::move(info), r);
  if (options.resume) passes.resume(*options.resume);
  if (options.passes_starting) options.passes_starting();
  passes.run(start);

  r.nonfinite_samples = passes.nonfinite();
  r.rays = wavefront.rays_traced();
  r.stages = wavefront.stage_times();
  r.closest_packet = wavefront.closest_packet();
  r.closest_packets = wavefront.packet_timing();
  r.shadow_packet = wavefront.shadow_packet();
  r.shadow_packets = wavefront.shadow_packet_timing();
  r.shadow_ahead_launches = wavefront.shadow_ahead_launches();
  r.shadow_rest_launches = wavefront.shadow_rest_launches();
  out.film = passes.film();
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

}  // namespace

Rendered render(ClRuntime& runtime, const Scene& scene, const RenderSettings& settings,
                const RenderOptions& options) {
  return render_scene(runtime, scene, nullptr, settings, options);
}

Rendered render(ClRuntime& runtime, Scene&& scene, const RenderSettings& settings,
                const RenderOptions& options) {
  return render_scene(runtime, scene, &scene, settings, options);
}

}  // namespace wp
