#include "host/bench/scene_bench.h"

#include <algorithm>

#include "host/accel/bvh_input.h"
#include "host/device/device_scene.h"
#include "host/scene/gltf_loader.h"
#include "host/render/render.h"
#include "host/util/error.h"

namespace wp::bench {

namespace {

// Where run_bounce begins a bounce: the surface and shadow queues and the next ray queue empty.
void reset_bounce_counters(Wavefront::Snapshot& s, const dev::Launch& p) {
  s.counters[WP_QUEUE_SURFACE] = 0;
  s.counters[WP_QUEUE_SHADOW] = 0;
  s.counters[p.queue_out] = 0;
}

bool in_bounce(Stage s) {
  return s != Stage::kGenerateCameraRays && s != Stage::kAccumulate;
}

}  // namespace

SceneBench::SceneBench(const SceneSpec& spec)
    : spec_(spec), scene_(load_gltf(spec.path, load_options())) {
  bvh_ = build_scene_bvh(scene_, build_options(), std::string());
  const RenderSettings s = bench_settings(false);
  const std::size_t pixels = std::size_t(s.width) * std::size_t(s.height);
  wave_paths_ = static_cast<std::uint32_t>(std::min(pixels, std::size_t(1) << 20));
}

LoadOptions load_options() {
  LoadOptions o;
  o.instancing = env().options.instancing;
  return o;
}

// The BVH options a render on the bench's device would use.
bvh::BuildOptions build_options() {
  bvh::BuildOptions o;
  o.width = bvh_width(env().runtime->device(), bench_settings(false));
  o.spatial_splits = env().options.spatial_splits;
  return o;
}

Wavefront& SceneBench::stages() {
  if (!stages_) {
    RenderSettings s = bench_settings(false);
    s.fused = false;  // the split stages are what the stage benchmarks time, one at a time
    s.wave_size = wave_paths_;  // sample 0 of the whole image, whatever a render's wave would be
    stages_ = std::make_unique<Wavefront>(*env().runtime, scene_, bvh_, s);
    wave_paths_ = static_cast<std::uint32_t>(stages_->wave_size());
    capture();
  }
  return *stages_;
}

void SceneBench::capture() {
  Wavefront& wf = *stages_;
  dev::Launch p = wf.start_wave(0, 0, wave_paths_);
  std::uint32_t rays = wave_paths_;
  bounces_.assign(kBounces, {});
  for (int b = 0; b < kBounces; ++b) {
    BounceCapture& c = bounces_[b];
    c.start = wf.snapshot();
    reset_bounce_counters(c.start, p);
    c.params = p;
    c.rays = rays;
    if (rays == 0) continue;
    rays = wf.run_bounce(p, rays);
    c.surfaces = wf.counter(WP_QUEUE_SURFACE);
    c.shadows = wf.counter(WP_QUEUE_SHADOW);
  }
}

const BounceCapture& SceneBench::bounce(int b) {
  stages();
  return bounces_.at(static_cast<std::size_t>(b));
}

// The bounce step of `stage` (pipeline.h): the split pipeline's, or the fused shade's.
const Step& bounce_step(Stage stage) {
  for (const Pipeline* pipeline : {&split_pipeline(), &fused_pipeline()})
    for (const Step& step : pipeline->bounce)
      if (step.stage == stage) return step;
  throw Error(std::string(stage_name(stage)) + " is not a stage of a pipeline's bounce");
}

StageJob SceneBench::stage_job(Stage stage, int b) {
  Wavefront& wf = stages();
  if (!in_bounce(stage)) b = 0;
  const BounceCapture& c = bounce(b);
  StageJob job;
  job.input = &input_;
  if (stage == Stage::kGenerateCameraRays) {
    job.params = wf.launch_params(0, 0, wave_paths_);
    job.params.queue_out = WP_QUEUE_RAY_A;
    job.launch_items = job.items = wave_paths_;
  } else if (stage == Stage::kAccumulate) {
    job.params = wf.launch_params(0, 0, wave_paths_);
    job.launch_items = job.items = wave_paths_;
  } else {
    const Step& step = bounce_step(stage);
    const auto length = [&](QueueRole q) {
      return q == QueueRole::kSurface ? c.surfaces : q == QueueRole::kShadow ? c.shadows : c.rays;
    };
    job.params = c.params;
    job.items = length(step.in);  // the paths it works on
    // As run_bounce launches it: over the bounce's rays, or exactly over its queue.
    job.launch_items = step.size == LaunchSize::kQueueLength ? job.items : c.rays;
  }
  if (input_bounce_ == b && input_stage_ == stage) return job;

  input_ = {};  // release the previous input before making the next
  wf.restore(c.start);
  if (stage == Stage::kAccumulate) {
    // The wave's remaining bounces, as the renderer runs them before accumulating.
    dev::Launch p = c.params;
    for (std::uint32_t rays = c.rays; rays > 0;) rays = wf.run_bounce(p, rays);
  } else if (in_bounce(stage)) {
    // The bounce's steps before this one, each over the bounce's rays (an upper bound of every
    // queue: the work-items past a queue's end return at once); the fused shade's input is
    // shade_surface's, the hits of intersect_closest.
    const Stage until = stage == Stage::kShade ? Stage::kShadeSurface : stage;
    for (const Step& step : split_pipeline().bounce) {
      if (step.stage == until) break;
      wf.launch_stage(step.stage, c.rays, c.params);
    }
  }
  wf.finish();
  input_ = wf.snapshot();
  input_stage_ = stage;
  input_bounce_ = b;
  return job;
}

Wavefront& SceneBench::render_wavefront() {
  if (!render_) {
    render_ = std::make_unique<Wavefront>(*env().runtime, scene_, bvh_, bench_settings(true));
    render_->render_pass(next_samples());  // first-touch costs stay out of the figures
  }
  return *render_;
}

std::size_t SceneBench::device_memory_bytes() {
  if (!device_bytes_) {
    // The Wavefront reports its scene buffers; the others' sizes follow from public pieces.
    Wavefront& wf = render_wavefront();
    const RenderSettings s = bench_settings(true);
    const std::size_t pixels = std::size_t(s.width) * std::size_t(s.height);
    device_bytes_ = wf.scene_bytes() + wf.path_state().bytes +
                    WP_QUEUE_COUNT * wf.wave_size() * sizeof(dev::uint) +
                    WP_COUNTER_COUNT * sizeof(dev::uint) + 2 * pixels * sizeof(dev::float4);
  }
  return *device_bytes_;
}

const EmbreeRef& SceneBench::embree() {
  if (!embree_) embree_ = std::make_unique<EmbreeRef>(scene_);
  return *embree_;
}

namespace {
std::unique_ptr<SceneBench> current;
}  // namespace

SceneBench& scene_bench(const SceneSpec& spec) {
  if (!current || current->spec().path != spec.path || current->spec().name != spec.name) {
    current.reset();  // the previous scene's device buffers go before the next one's come
    current = std::make_unique<SceneBench>(spec);
  }
  return *current;
}

void release_scene_bench() {
  current.reset();
}

}  // namespace wp::bench
