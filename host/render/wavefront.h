// The wavefront path tracer on one OpenCL device: the scene and the path state in device buffers,
// the program specialised to the scene's features, and the render loop over the stage kernels.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "bvh/bvh.h"
#include "host/device/cl_runtime.h"
#include "host/lights/environment.h"
#include "host/film/film.h"
#include "host/lights/light_table.h"
#include "host/render/path_state.h"
#include "host/scene/scene.h"
#include "host/scene/view.h"
#include "host/device/scene_buffers.h"
#include "host/device/scene_features.h"
#include "host/render/pipeline.h"
#include "kernels/shared/types.h"

namespace wp {

enum class Strategy { kMis, kNee, kBsdf };
enum class MisHeuristic { kPower, kBalance };
// Sample pattern (kernels/sampling/rng.h): Owen-scrambled Sobol' points, the light and BSDF pairs
// of two bounces chained to one sample order (kSobol) or every group in an order of its own
// (kSobolPadded), or independent hashes.
enum class Sampler { kSobol, kIndependent, kSobolPadded };
// The --sampler name of a pattern ("sobol", "independent", "sobol-padded").
const char* sampler_name(Sampler s);

struct RenderSettings {
  int width = 640;
  int height = 480;
  int spp = 64;  // samples per pixel
  // The render takes sample indices [sample_begin, sample_begin + spp), within [0, 2^20): a
  // part of a longer render, whose films merge exactly (host/film/film.h).
  int sample_begin = 0;
  // Record albedo, normal and depth per sample too (AOVs, kernels/shared/film.h; FilmImages).
  bool aov = false;
  int max_depth = 12;  // scattering events per path at most
  // Russian roulette from this many scattering events on (>= max_depth: off); why 5: the study in
  // docs/accuracy.md, "Russian roulette".
  int rr_depth = 5;
  // Roulette's throughput threshold: from rr_depth on, a path whose throughput (largest channel,
  // kernels/integrator/roulette_compact.h) m is below it survives with probability
  // m / rr_threshold and then carries rr_threshold; at or above it, always. 1 is pbrt's rule
  // (survival probability = throughput); why 0.5: docs/accuracy.md, "the survival threshold".
  float rr_threshold = 0.5f;
  std::uint32_t seed = 0;      // the image is a pure function of (scene, settings, seed)
  glm::vec3 background{0.0f};  // radiance of escaped rays when there is no environment map
  std::shared_ptr<const EnvironmentMap> environment;  // optional
  float env_intensity = 1.0f;                         // scales the map
  float env_rotation = 0.0f;                          // degrees about +Y
  // The map's lookup (--env-filter); a map whose tables were built for the other filter gets
  // tables rebuilt for this one (Wavefront's constructor).
  EnvFilter env_filter = EnvFilter::kBilinear;
  // Minify textures through mip chains at the level of each path's ray cone (--mipmaps;
  // kernels/texture/ray_cone.h), where the scene has a texture whose sampler allows mip-maps.
  bool mipmaps = true;
  Strategy strategy = Strategy::kMis;
  MisHeuristic mis_heuristic = MisHeuristic::kPower;
  LightSelect light_select = LightSelect::kPower;
  Sampler sampler = Sampler::kSobol;
  int camera = -1;            // index into Scene::cameras; -1: the first, or a framing camera
  View view;                  // a camera placed from the command line, field of view, lens (view.h)
  bool all_features = false;  // build every kernel feature regardless of the scene
  // Path slots per wave; 0: the device's (auto_wave_paths, wave_shape) on a CPU device, else
  // min(pixels, 2^20), or for an image of fewer than kMultiSamplePaths pixels, as many whole
  // samples of it as fit in kMultiSamplePaths. A size above the pixel count also holds several
  // samples (its quotient by the pixel count).
  std::size_t wave_size = 0;
  std::size_t local_size = 0;  // work-group size; 0: 64
  bool profile = false;        // time every kernel launch with profiling events
  // One fused kernel per bounce for everything at a hit (kernels/shade.cl), or the split stages
  // (shade_surface, sample_lights, sample_bsdf, roulette_compact): the same image bit for bit
  // (pipeline.h). Fused by default: the faster on PoCL (docs/performance.md, "Fused shading").
  bool fused = true;
  // Cache hints for the path state ahead in each queue, on PoCL's CPU devices
  // (kernels/util/features.h, WP_PREFETCH); elsewhere nothing. The same image either way.
  bool prefetch = true;
  // Shadow rays traced eight to a work-item where they are plain any-hit queries, on PoCL's CPU
  // devices with the wide BVH (kernels/traversal/traverse8_packet.h), at the bounces where the
  // first waves timed that faster (Wavefront::packet_mode); elsewhere one each. The same image.
  bool shadow_packets = true;
  // Closest-hit rays likewise, where the program has no instances or alpha (the same walk's
  // closest-hit form: the answer does not depend on which rays share a packet).
  bool closest_packets = true;
  // trace_shadow launched before its queue's length is read back, over this times the share of
  // shadow rays the same bounce of the last wave had (Wavefront::run_bounce), the rest, if any,
  // once the length is known; 0: always after the read-back, over the exact length. The same
  // image; tests set it below 1 so that the rest is launched.
  float shadow_ahead = 1.03f;
  // The fused shade kernel eight paths per work-item (kernels/integrator/shade_packet.h) on
  // PoCL's CPU devices, in scenes of untextured Lambertian surfaces without instances or AOVs.
  // The same image.
  bool shade_packets = true;
  // The packet kernels above on any device, not only on PoCL's CPU devices (tests run them under
  // Oclgrind with it). The same image.
  bool force_packets = false;
  int bvh_width = 0;  // BVH layout: 2, 8, or 0 for the device's default (render.h)
  // Where built kernel programs are cached (host/device/program_cache.h; the command line passes
  // bvh::cache_dir()); empty: nothing is cached.
  std::string kernel_cache_dir;
  // Most bytes in one scene buffer (device_scene.h); 0: the device's largest allocation. Smaller
  // values split even small scenes over several buffers (tests).
  std::uint64_t scene_buffer_bytes = 0;
};

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

// Wall-clock seconds of device execution per stage (only with RenderSettings::profile).
struct StageTimes {
  std::array<double, kStageCount> seconds{};
  std::array<std::uint64_t, kStageCount> launches{};
};

// How the closest-hit rays of one bounce index were traced where the program has packets
// (Wavefront::packet_timing): intersect_closest's device seconds and rays for each walk while it
// was timed on the first waves, and the walk kept.
struct PacketTiming {
  double seconds[2] = {0.0, 0.0};  // intersect_closest's time [single rays, packets] ...
  std::uint64_t rays[2] = {0, 0};  // ... over these many rays
  int launches[2] = {0, 0};        // ... in these many launches
  int choice = -1;                 // 0 single rays, 1 packets, -1 still timing
};

class Wavefront {
 public:
  // Packs and uploads the scene, allocates the path state and builds the program. `bvh` must have
  // been built over `scene`'s triangles.
  Wavefront(ClRuntime& runtime, const Scene& scene, const bvh::Bvh& bvh,
            const RenderSettings& settings);
  // The same, freeing the host arrays of `scene` and `bvh` as they are packed with
  // HostArrays::kRelease (pack_scene): for a caller that reads neither's geometry afterwards.
  Wavefront(ClRuntime& runtime, Scene& scene, bvh::Bvh& bvh, const RenderSettings& settings,
            HostArrays host);

  // Renders sample indices [sample, sample + samples) for every pixel and adds them to the film;
  // 1 <= samples <= samples_per_wave().
  void render_pass(std::uint32_t sample, std::uint32_t samples = 1);
  // The device film read back: the sums of every pass rendered so far, which `info` describes
  // (its size must be the settings'; its sample range is the passes', as the caller knows them).
  Film film(FilmInfo info);
  // Replaces the device film's sums with `film`'s (a checkpoint to continue); its size must be the
  // settings'.
  void load_film(const Film& film);
  // NaN or infinite values dropped anywhere (queues.h, count_nonfinite).
  std::uint64_t nonfinite_samples();
  // Closest-hit rays (camera and bounce) traced by render_pass so far: a cost measure that, unlike
  // time, does not depend on what else the machine is doing.
  std::uint64_t rays_traced() const { return rays_traced_; }
  // The packed scene on the device: its bytes and the buffers they are split over.
  std::uint64_t scene_bytes() const { return scene_bytes_; }
  std::uint64_t texture_bytes() const { return texture_bytes_; }
  std::uint64_t mip_bytes() const { return mip_bytes_; }
  int scene_buffer_count() const { return scene_buffer_count_; }

  // Stage-level access for tests and benchmarks. Field offsets are those of path_state().layout,
  // e.g. write_paths(path_state().layout.ray_o, rays).
  // Returns the launch's event (with profiling information: the queue profiles).
  cl::Event launch_stage(Stage stage, std::uint32_t items, const dev::Launch& params) {
    return launch(stage, items, params);
  }
  template <class T>
  void write_paths(dev::uint field_offset, const std::vector<T>& values) {
    rt_.queue().enqueueWriteBuffer(path_buf_, CL_TRUE, field_offset, values.size() * sizeof(T),
                                   values.data());
  }
  template <class T>
  std::vector<T> read_paths(dev::uint field_offset, std::size_t count) {
    std::vector<T> values(count);
    rt_.queue().enqueueReadBuffer(path_buf_, CL_TRUE, field_offset, count * sizeof(T),
                                  values.data());
    return values;
  }
  // The wave loop in steps, for benchmarks that capture a real wavefront: start_wave generates
  // the camera rays of a wave and returns the launch parameters of its first bounce; run_bounce
  // runs one bounce's stages on `rays` queued rays and returns the next bounce's count, leaving
  // `params` ready for it; with the bounce's index (from 0) trace_shadow may be launched ahead of
  // its count (RenderSettings::shadow_ahead), without it only after.
  dev::Launch start_wave(std::uint32_t sample, std::uint32_t first_pixel, std::uint32_t count,
                         std::uint32_t samples = 1);
  std::uint32_t run_bounce(dev::Launch& params, std::uint32_t rays, int bounce = -1);
  // trace_shadow launches made ahead of their queue's count, and those for the rest of a queue
  // past such a launch's estimate (run_bounce).
  std::uint64_t shadow_ahead_launches() const { return shadow_ahead_launches_; }
  std::uint64_t shadow_rest_launches() const { return shadow_rest_launches_; }
  // The whole mutable device state except the film (path state, queues, counters), to replay a
  // stage on the same input many times.
  struct Snapshot {
    std::vector<unsigned char> paths;
    std::vector<dev::uint> slots, counters;
  };
  Snapshot snapshot();
  void restore(const Snapshot& s);
  std::uint32_t counter(std::uint32_t index) { return read_counter(index); }
  // Replaces queue `queue` (WP_QUEUE_*) with `slots` and sets its counter; zeroes the others.
  void write_queue(dev::uint queue, const std::vector<dev::uint>& slots);
  // Launch parameters of the wave of `count` pixels from `first_pixel`, `samples` samples of each
  // from index `sample`.
  dev::Launch launch_params(std::uint32_t sample, std::uint32_t first_pixel, std::uint32_t count,
                            std::uint32_t samples = 1) const;
  void finish() { rt_.queue().finish(); }

  const SceneFeatures& features() const { return features_; }
  const LightTable& lights() const { return lights_; }
  const PathStateLayout& path_state() const { return memory_.path_state; }
  // Pixels per wave (one sample of each, or samples_per_wave() of them), and path slots per wave.
  std::size_t wave_size() const { return wave_size_; }
  std::size_t samples_per_wave() const { return samples_per_wave_; }
  std::size_t wave_paths() const { return wave_size_ * samples_per_wave_; }
  const StageTimes& stage_times() const { return times_; }
  // Per bounce index, the last standing for it and every deeper bounce, how its closest-hit rays
  // were traced (run_wave); a bounce index not (yet) listed traces single rays. Empty where the
  // program has no closest-hit packets (closest_packet() == 1: GPUs, the binary BVH, instances,
  // alpha, RenderSettings::closest_packets off).
  const std::vector<PacketTiming>& packet_timing() const { return packet_timing_; }
  // Closest-hit rays per work-item where a bounce uses packets; 1 where the program has none.
  std::uint32_t closest_packet() const { return closest_packet_; }
  // The same for shadow rays (no packets also with transmission).
  const std::vector<PacketTiming>& shadow_packet_timing() const { return shadow_timing_; }
  std::uint32_t shadow_packet() const { return shadow_packet_; }
  std::string build_options() const { return options_; }
  // FNV-1a 64 of every stage kernel's source (includes expanded), whichever pipeline runs: part
  // of the render key (render.h), so films of different kernels do not merge.
  std::uint64_t source_digest() const { return source_digest_; }
  // Seconds spent building the program and compiling every kernel (see prime_kernels).
  double build_seconds() const { return build_seconds_; }
  // Size of the device program binary (implementation-specific: LLVM bitcode on PoCL, PTX on
  // NVIDIA), 0 if the implementation does not report one.
  std::size_t binary_bytes() const { return binary_bytes_; }
  // Whether the program came from the kernel cache (RenderSettings::kernel_cache_dir).
  bool kernel_cached() const { return kernel_cached_; }

 private:
  using QueueCounts = std::array<dev::uint, WP_QUEUE_COUNT>;
  // The constructor's steps: the packed scene to the device, the path state, queues, counters and
  // film allocated, the program built and this pipeline's kernels made and primed.
  // owned_scene and owned_bvh: null, or `scene` and `bvh`, whose host arrays packing then frees.
  Wavefront(ClRuntime& runtime, const Scene& scene, const bvh::Bvh& bvh,
            const RenderSettings& settings, Scene* owned_scene, bvh::Bvh* owned_bvh);
  void upload(const Scene& scene, const bvh::Bvh& bvh, Scene* owned_scene, bvh::Bvh* owned_bvh);
  void allocate_state();
  void build_program();
  void prime_kernels();
  // The kernel of `stage`, made with its arguments bound at its first use.
  cl::Kernel& kernel(Stage stage);

  void run_wave(std::uint32_t sample, std::uint32_t first_pixel, std::uint32_t count,
                std::uint32_t samples);
  // The work-items of `step` in the bounce `p` of `rays` rays; `counts`: the queue lengths read
  // back (needed by LaunchSize::kQueueLength steps only).
  std::uint32_t launch_items(const Step& step, const dev::Launch& p, std::uint32_t rays,
                             const QueueCounts* counts) const;
  void run_step(const Step& step, const dev::Launch& p, std::uint32_t rays,
                const QueueCounts* counts = nullptr);
  QueueCounts read_queue_counts();
  QueueCounts launch_ahead(const Step& step, const dev::Launch& p, std::uint32_t ahead);
  cl::Event launch(Stage stage, std::uint32_t items, const dev::Launch& params);
  std::uint32_t read_counter(std::uint32_t index);
  void collect_profile();

  ClRuntime& rt_;
  RenderSettings settings_;
  const Pipeline& pipeline_;  // the stages a wave runs (RenderSettings::fused)
  SceneFeatures features_;
  LightTable lights_;
  StateMemory memory_;  // the sizes of the buffers below but scene_
  std::size_t wave_size_ = 0;
  std::size_t samples_per_wave_ = 1;
  std::size_t local_size_ = 0;
  std::uint32_t shadow_packet_ =
      1;  // shadow rays per work-item (kernels/traversal/traverse8_packet.h)
  std::uint32_t closest_packet_ = 1;  // closest-hit rays per work-item where a bounce uses packets
  std::uint32_t shade_packet_ = 1;    // paths per work-item of the fused shade kernel
  // Whether each bounce's closest-hit rays go in packets (closest_packet_ > 1 only): the faster
  // per ray of the two, timed on the first waves (run_wave). The same image either way.
  std::vector<PacketTiming> packet_timing_, shadow_timing_;  // closest-hit and shadow rays
  int packet_mode(const std::vector<PacketTiming>& timing, std::uint32_t packet,
                  std::size_t bounce) const;
  void time_packets(std::vector<PacketTiming>& timing, std::uint32_t packet, const cl::Event& event,
                    std::size_t bounce, int mode, std::uint32_t rays);
  cl::Event last_intersect_, last_shadow_;  // the latest launches, for time_packets
  std::uint32_t last_shadow_rays_ = 0;      // the shadow rays of the latest run_bounce
  // The counters run_bounce writes without waiting: read by the device before the bounce's
  // blocking read-back returns, left alone until then.
  QueueCounts bounce_counts_{};
  // Shadow rays per ray of each bounce index in the latest wave that counted it (-1: none yet),
  // for the estimates of run_bounce's ahead launches, and those launches' counts.
  std::vector<double> shadow_share_;
  QueueCounts ahead_counts_{};  // the counters read back without waiting, for those launches
  std::uint64_t shadow_ahead_launches_ = 0, shadow_rest_launches_ = 0;
  std::uint32_t shadow_ahead_items(const dev::Launch& p, std::uint32_t rays, int bounce) const;
  std::size_t waves_run_ = 0;  // run_wave's count: the first wave (a cold start) is not timed
  double build_seconds_ = 0.0;
  std::size_t binary_bytes_ = 0;
  bool kernel_cached_ = false;
  std::uint64_t rays_traced_ = 0;
  std::string options_;
  std::uint64_t source_digest_ = 0;

  // The memory scene_ uses in place on a CPU device: declared first, so that it outlives the
  // buffers.
  std::vector<SceneBytes> packed_;
  SceneBuffers scene_;
  std::uint64_t scene_bytes_ = 0;
  std::uint64_t texture_bytes_ = 0, mip_bytes_ = 0;
  int scene_buffer_count_ = 0;
  cl::Buffer path_buf_, queue_slots_, counters_, film_;
  cl::Program program_;                // the pipeline's stages (build_program)
  std::vector<Stage> program_stages_;  // ... which are these
  cl::Program other_program_;  // every stage, built by kernel() for another pipeline's stage
  std::array<cl::Kernel, kStageCount> kernels_;  // indexed by Stage; made by kernel()
  cl_uint launch_arg_ = 0;                       // the index of the Launch argument
  std::vector<std::pair<Stage, cl::Event>> pending_events_;
  StageTimes times_;
};

}  // namespace wp
