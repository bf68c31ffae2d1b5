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
#include "host/render/plan.h"
#include "host/render/settings.h"
#include "kernels/shared/types.h"

namespace wp {

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
  // been built over `scene`'s triangles. `plan`: plan_render's for this device and `settings`
  // (made here when not given), which the constructor completes for `bvh` (plan_program) unless
  // that was done.
  Wavefront(ClRuntime& runtime, const Scene& scene, const bvh::Bvh& bvh,
            const RenderSettings& settings);
  Wavefront(ClRuntime& runtime, const Scene& scene, const bvh::Bvh& bvh,
            const RenderSettings& settings, RenderPlan plan);
  // The same, freeing the host arrays of `scene` and `bvh` as they are packed with
  // HostArrays::kRelease (pack_scene): for a caller that reads neither's geometry afterwards.
  Wavefront(ClRuntime& runtime, Scene& scene, bvh::Bvh& bvh, const RenderSettings& settings,
            RenderPlan plan, HostArrays host);

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

  const SceneFeatures& features() const { return plan_.features; }
  const LightTable& lights() const { return lights_; }
  const PathStateLayout& path_state() const { return plan_.memory.path_state; }
  // Pixels per wave (one sample of each, or samples_per_wave() of them), and path slots per wave.
  std::size_t wave_size() const { return plan_.memory.wave.pixels; }
  std::size_t samples_per_wave() const { return plan_.memory.wave.samples; }
  std::size_t wave_paths() const { return plan_.memory.wave.pixels * plan_.memory.wave.samples; }
  const StageTimes& stage_times() const { return times_; }
  // Per bounce index, the last standing for it and every deeper bounce, how its closest-hit rays
  // were traced (run_wave); a bounce index not (yet) listed traces single rays. Empty where the
  // program has no closest-hit packets (closest_packet() == 1: GPUs, the binary BVH, instances,
  // alpha, RenderSettings::closest_packets off).
  const std::vector<PacketTiming>& packet_timing() const { return packet_timing_; }
  // Closest-hit rays per work-item where a bounce uses packets; 1 where the program has none.
  std::uint32_t closest_packet() const { return plan_.closest_packet; }
  // The same for shadow rays (no packets also with transmission).
  const std::vector<PacketTiming>& shadow_packet_timing() const { return shadow_timing_; }
  std::uint32_t shadow_packet() const { return plan_.shadow_packet; }
  std::string build_options() const { return plan_.program_options; }
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
            const RenderSettings& settings, RenderPlan plan, Scene* owned_scene,
            bvh::Bvh* owned_bvh);
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
  RenderPlan plan_;           // features, wave and memory, packets, build options (plan.h)
  LightTable lights_;
  // Whether each bounce's closest-hit rays go in packets (plan_.closest_packet > 1 only): the
  // faster per ray of the two, timed on the first waves (run_wave). The same image either way.
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
