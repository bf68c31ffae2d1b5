// One benchmark per stage kernel and bounce: `<stage>/bounce<b>/<scene>`. Every iteration
// launches the stage once, as the renderer does, on the stage's captured input, restored
// (untimed) before the iteration; the time is the launch's own device time from its profiling
// event. The two ray-tracing stages
// also trace their very rays with Embree in the same run: embree_ratio = our rays/s over Embree's.
// The two time the walk a render would keep for the bounce (packets or single rays).
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "host/bench/bench.h"
#include "host/bench/scene_bench.h"

namespace wp::bench {

namespace {

// How long Embree traces the same rays for its figure (after one warm-up pass).
constexpr double kEmbreeSeconds = 0.25;
// Launches of each closest-hit walk, alternated, that choose the one a row times (below).
constexpr int kWalkChoiceLaunches = 3;

double event_seconds(const cl::Event& e) {
  const auto start = e.getProfilingInfo<CL_PROFILING_COMMAND_START>();
  const auto end = e.getProfilingInfo<CL_PROFILING_COMMAND_END>();
  return static_cast<double>(end - start) * 1e-9;
}

// Stages whose output neither feeds their own work nor grows a queue: launched again on their
// own output they do the same work, so their input is restored once per benchmark run, not per
// launch (a restore copies the whole path state, tens of MB: far longer than these kernels take).
// generate_camera_rays overwrites what it writes; intersect_closest writes only the hit record;
// trace_shadow and accumulate only add to radiance and film. run_stage checks the queue counters.
bool repeatable(Stage s) {
  return s == Stage::kGenerateCameraRays || s == Stage::kIntersectClosest ||
         s == Stage::kTraceShadow || s == Stage::kAccumulate;
}

dev::float4 field(const Wavefront::Snapshot& s, dev::uint offset, dev::uint slot) {
  dev::float4 v;
  std::memcpy(&v, s.paths.data() + offset + std::size_t(slot) * sizeof(dev::float4), sizeof(v));
  return v;
}

struct QueuedRays {
  std::vector<dev::uint> slots;
  std::vector<RefRay> rays;
};

// The rays in queue `queue` of snapshot `s`, as stored for the stage that traces them: closest
// rays from tmin in ray_o.w to infinity, shadow rays from tmin 0 to shadow_o.w.
QueuedRays queued_rays(const Wavefront::Snapshot& s, const dev::PathLayout& layout,
                       std::size_t capacity, dev::uint queue, bool shadow) {
  QueuedRays q;
  q.slots.assign(s.slots.begin() + std::ptrdiff_t(queue * capacity),
                 s.slots.begin() + std::ptrdiff_t(queue * capacity + s.counters[queue]));
  for (const dev::uint slot : q.slots) {
    const dev::float4 o = field(s, shadow ? layout.shadow_o : layout.ray_o, slot);
    const dev::float4 d = field(s, shadow ? layout.shadow_d : layout.ray_d, slot);
    q.rays.push_back({{o.x, o.y, o.z},
                      shadow ? 0.0f : o.w,
                      {d.x, d.y, d.z},
                      shadow ? o.w : std::numeric_limits<float>::infinity()});
  }
  return q;
}

// The fraction of `slots` whose ray hit (closest) or was occluded (shadow) in the launches just
// made: a hit record with finite t; a radiance that the shadow ray's contribution did not change.
double our_hit_fraction(Wavefront& wf, const Wavefront::Snapshot& input,
                        const std::vector<dev::uint>& slots, bool shadow) {
  const dev::PathLayout& layout = wf.path_state().layout;
  const auto out =
      wf.read_paths<dev::float4>(shadow ? layout.radiance : layout.hit, wf.wave_size());
  std::size_t hits = 0;
  for (const dev::uint slot : slots) {
    if (shadow) {
      const dev::float4 before = field(input, layout.radiance, slot);
      hits += std::memcmp(&before, &out[slot], sizeof(before)) == 0;
    } else {
      hits += std::isfinite(out[slot].x);
    }
  }
  return slots.empty() ? 0.0 : static_cast<double>(hits) / static_cast<double>(slots.size());
}

// embree_ratio and what it is made of, for intersect_closest and trace_shadow, after the timed
// launches (whose results are still in the path state).
void embree_counters(benchmark::State& state, SceneBench& sb, Stage stage, const StageJob& job,
                     double our_seconds) {
  const bool shadow = stage == Stage::kTraceShadow;
  const dev::uint queue = shadow ? WP_QUEUE_SHADOW : job.params.queue_in;
  Wavefront& wf = sb.stages();
  const QueuedRays q =
      queued_rays(*job.input, wf.path_state().layout, wf.wave_size(), queue, shadow);
  if (q.rays.size() != job.items) throw Error("the captured queue does not hold the stage's rays");
  state.counters["hit_fraction"] = our_hit_fraction(wf, *job.input, q.slots, shadow);
  const unsigned threads = env().device.compute_units;
  const RefTiming ref = sb.embree().measure(q.rays, shadow, threads, kEmbreeSeconds);
  const double ours = static_cast<double>(job.items) / our_seconds;
  const double theirs = static_cast<double>(job.items) / ref.seconds_per_pass;
  state.counters["embree_ratio"] = ours / theirs;
  state.counters["embree_rays_per_second"] = theirs;
  state.counters["embree_threads"] = threads;
  state.counters["embree_hit_fraction"] =
      static_cast<double>(ref.hits) / static_cast<double>(q.rays.size());
}

void run_stage(benchmark::State& state, const SceneSpec& spec, Stage stage, int b) {
  SceneBench& sb = scene_bench(spec);
  Wavefront& wf = sb.stages();
  const StageJob job = sb.stage_job(stage, b);
  if (job.launch_items == 0) {
    skip(state, "bounce " + std::to_string(b) + " has no rays in this scene");
    return;
  }
  const bool restore_each = !repeatable(stage);
  wf.restore(*job.input);
  dev::Launch params = job.params;
  // As a render chooses per bounce (Wavefront::packet_mode): the ray-tracing stages' rays in
  // packets or one per work-item, whichever traces these rays faster, here over a few untimed
  // launches of each (the kernels write the same either way: intersect_closest the hit record,
  // trace_shadow the same radiance, which these launches add to and the timed ones go on adding
  // to). packet_speedup: the single walk's time over the packets'.
  dev::uint dev::Launch::*walk = stage == Stage::kIntersectClosest ? &dev::Launch::packet
                                 : stage == Stage::kTraceShadow    ? &dev::Launch::shadow_packet
                                                                   : nullptr;
  if (walk && params.*walk > 1) {
    double seconds[2] = {0.0, 0.0};
    for (int i = 0; i < 2 * kWalkChoiceLaunches; ++i) {
      dev::Launch p = params;
      p.*walk = i % 2 ? params.*walk : 1u;
      const cl::Event e = wf.launch_stage(stage, job.launch_items, p);
      e.wait();
      seconds[i % 2] += event_seconds(e);
    }
    if (seconds[0] <= seconds[1]) params.*walk = 1u;
    state.counters["packets"] = params.*walk > 1 ? 1.0 : 0.0;
    state.counters["packet_speedup"] = seconds[0] / seconds[1];
  }
  double total = 0;
  for (auto _ : state) {
    if (restore_each) wf.restore(*job.input);
    const cl::Event e = wf.launch_stage(stage, job.launch_items, params);
    e.wait();
    const double seconds = event_seconds(e);
    state.SetIterationTime(seconds);
    total += seconds;
  }
  for (dev::uint q = 0; q < WP_QUEUE_COUNT && !restore_each; ++q)
    if (wf.counter(q) != job.input->counters[q])
      throw Error(std::string(stage_name(stage)) +
                  " changes a queue: it must be restored before every launch (stage_bench.cpp)");
  const auto iterations = static_cast<double>(state.iterations());
  state.SetItemsProcessed(state.iterations() * static_cast<benchmark::IterationCount>(job.items));
  state.counters["rays"] = job.items;
  if ((stage == Stage::kIntersectClosest || stage == Stage::kTraceShadow) && job.items > 0)
    embree_counters(state, sb, stage, job, total / iterations);
}

void add(const SceneSpec& scene, Stage stage, const std::string& bounce, int b) {
  const std::string name = std::string(stage_name(stage)) + "/" + bounce + "/" + scene.name;
  benchmark::RegisterBenchmark(name.c_str(),
                               [scene, stage, b](benchmark::State& state) {
                                 guarded(state, [&] { run_stage(state, scene, stage, b); });
                               })
      ->UseManualTime()
      ->Unit(benchmark::kMillisecond);
}

}  // namespace

void register_stage_benchmarks(const SceneSpec& scene) {
  add(scene, Stage::kGenerateCameraRays, "bounce0", 0);
  for (int b = 0; b < kBounces; ++b) {
    for (const Step& step : split_pipeline().bounce)  // in the order the split pipeline runs them
      add(scene, step.stage, "bounce" + std::to_string(b), b);
    // The default (fused) pipeline's one shading kernel, on shade_surface's input.
    add(scene, Stage::kShade, "bounce" + std::to_string(b), b);
  }
  // After the wave's last bounce: the state it reads is that of every finished path.
  add(scene, Stage::kAccumulate, "final", 0);
}

}  // namespace wp::bench
