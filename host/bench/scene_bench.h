// One scene under benchmark: loaded, its BVH built as `wavepath render` builds it, and — each on
// first use — a Wavefront with a captured real wavefront state for the stage benchmarks, a
// profiling Wavefront for whole renders, and the Embree reference.
//
// The captured state: one wave (the first min(pixels, wave size) pixels, sample 0) run through
// the renderer's own start_wave / run_bounce, snapshotted where bounce 0 (the camera rays) and
// bounce 1 (the first BSDF-sampled rays) begin. A stage's input is that snapshot with the stages
// before it in the Stage enum run on it, launched as run_bounce launches them (run_bounce traces
// shadow rays last, which only adds to the radiance no other stage reads).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "bvh/bvh.h"
#include "host/bench/bench.h"
#include "host/bench/embree_ref.h"
#include "host/scene/scene.h"
#include "host/render/pipeline.h"
#include "host/render/wavefront.h"

namespace wp::bench {

inline constexpr int kBounces = 2;  // stage benchmarks at bounce 0 and bounce 1

struct BounceCapture {
  Wavefront::Snapshot start;   // queues and counters as run_bounce leaves them before its stages
  dev::Launch params{};        // as run_bounce receives them
  std::uint32_t rays = 0;      // ray queue length (params.queue_in)
  std::uint32_t surfaces = 0;  // surface queue length after shade_surface
  std::uint32_t shadows = 0;   // shadow queue length after sample_lights
};

// What one stage benchmark launches and on what.
struct StageJob {
  const Wavefront::Snapshot* input = nullptr;  // restored before every launch
  dev::Launch params{};
  std::uint32_t launch_items = 0;  // the launch size the renderer uses (an upper bound)
  std::uint32_t items = 0;         // the queue length the stage consumes: rays or paths
};

class SceneBench {
 public:
  explicit SceneBench(const SceneSpec& spec);

  const SceneSpec& spec() const { return spec_; }
  const Scene& scene() const { return scene_; }
  const bvh::Bvh& bvh() const { return bvh_; }
  std::uint32_t wave_paths() const { return wave_paths_; }

  // The stage benchmarks' Wavefront (no profiling of its own: launch_stage's events are read).
  Wavefront& stages();
  const BounceCapture& bounce(int b);
  // The launch of `stage` at bounce `b` (generate_camera_rays and accumulate: the wave's first
  // and last step, `b` ignored) with its input state, captured on first use. Only the most recent
  // input is kept: a path-state snapshot is tens of MB.
  StageJob stage_job(Stage stage, int b);

  // The end-to-end Wavefront, with profiling, after one untimed warm-up pass.
  Wavefront& render_wavefront();
  // The first of the next `count` sample indices (each bench pass renders new samples).
  std::uint32_t next_samples(std::uint32_t count = 1) {
    next_sample_ += count;
    return next_sample_ - count;
  }
  // The sum of the device buffers a Wavefront allocates for this scene: scene, path state,
  // queues, counters, film.
  std::size_t device_memory_bytes();

  const EmbreeRef& embree();

 private:
  void capture();

  SceneSpec spec_;
  Scene scene_;
  bvh::Bvh bvh_;
  std::uint32_t wave_paths_ = 0;
  std::unique_ptr<Wavefront> stages_;
  std::vector<BounceCapture> bounces_;
  Stage input_stage_ = Stage::kGenerateCameraRays;
  int input_bounce_ = -1;
  Wavefront::Snapshot input_;
  dev::Launch end_params_{};
  std::unique_ptr<Wavefront> render_;
  std::uint32_t next_sample_ = 0;
  std::optional<std::size_t> device_bytes_;
  std::unique_ptr<EmbreeRef> embree_;
};

// The scene being benchmarked. Benchmarks run in registration order, scene by scene, so one
// scene is kept at a time: asking for another releases the previous one.
SceneBench& scene_bench(const SceneSpec& spec);
// Releases the current scene (before the OpenCL runtime goes).
void release_scene_bench();

// The BVH build input of `scene` as the renderer makes it (render.cpp): per-triangle flags for
// back-face culling and alpha, filled into `flags`, which must outlive the input.
// The BVH options a render on the bench's device would use (width, spatial splits).
bvh::BuildOptions build_options();
// How the bench loads its scenes (--instancing).
LoadOptions load_options();

}  // namespace wp::bench
