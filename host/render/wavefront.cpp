#include "host/render/wavefront.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <memory>
#include <new>

#include "host/device/device_scene.h"
#include "host/util/error.h"
#include "host/util/fnv1a.h"
#include "host/scene/view.h"
#include "host/device/kernel_sources.h"
#include "host/render/pipeline.h"

namespace wp {

const char* sampler_name(Sampler s) {
  switch (s) {
    case Sampler::kSobol:
      return "sobol";
    case Sampler::kSobolPadded:
      return "sobol-padded";
    case Sampler::kIndependent:
      break;
  }
  return "independent";
}

namespace {

// The source of a program holding the kernels of `stages`.
std::string program_source(const std::vector<Stage>& stages) {
  std::vector<std::string> files;
  for (const Stage stage : stages) files.push_back(std::string(stage_name(stage)) + ".cl");
  return KernelSources().expand(files);
}

std::vector<Stage> all_stages() {
  std::vector<Stage> stages;
  for (int i = 0; i < kStageCount; ++i) stages.push_back(static_cast<Stage>(i));
  return stages;
}

const dev::Camera pick_camera(const Scene& scene, const RenderSettings& s) {
  const float aspect = static_cast<float>(s.width) / static_cast<float>(s.height);
  return device_camera(choose_camera(scene, s.camera, s.view, aspect), s.width, s.height);
}

}  // namespace

Wavefront::Wavefront(ClRuntime& runtime, const Scene& scene, const bvh::Bvh& bvh,
                     const RenderSettings& settings)
    : Wavefront(runtime, scene, bvh, settings, plan_render(runtime.device(), scene, settings),
                nullptr, nullptr) {}

Wavefront::Wavefront(ClRuntime& runtime, const Scene& scene, const bvh::Bvh& bvh,
                     const RenderSettings& settings, RenderPlan plan)
    : Wavefront(runtime, scene, bvh, settings, std::move(plan), nullptr, nullptr) {}

Wavefront::Wavefront(ClRuntime& runtime, Scene& scene, bvh::Bvh& bvh,
                     const RenderSettings& settings, RenderPlan plan, HostArrays host)
    : Wavefront(runtime, scene, bvh, settings, std::move(plan),
                host == HostArrays::kRelease ? &scene : nullptr,
                host == HostArrays::kRelease ? &bvh : nullptr) {}

Wavefront::Wavefront(ClRuntime& runtime, const Scene& scene, const bvh::Bvh& bvh,
                     const RenderSettings& settings, RenderPlan plan, Scene* owned_scene,
                     bvh::Bvh* owned_bvh)
    : rt_(runtime),
      settings_(settings),
      pipeline_(pipeline(settings.fused)),
      plan_(std::move(plan)) {
  if (plan_.program_options.empty()) plan_program(plan_, settings, bvh);
  // Tables built for the other filter (a map made with the default of build_environment_tables):
  // a copy with tables for this one, kept in settings_ for the upload.
  if (settings_.environment && settings_.environment->filter != settings_.env_filter) {
    auto rebuilt = std::make_shared<EnvironmentMap>(*settings_.environment);
    build_environment_tables(*rebuilt, settings_.env_filter);
    settings_.environment = std::move(rebuilt);
  }
  const EnvironmentMap* env = settings_.environment.get();
  lights_ = build_light_table(scene, env, settings.background, settings.env_intensity,
                              settings.light_select);
  try {
    upload(scene, bvh, owned_scene, owned_bvh);
    allocate_state();
  } catch (const cl::Error& e) {
    rethrow_cl(e, "allocating device memory on " + rt_.device().name);
  }
  build_program();
}

void Wavefront::upload(const Scene& scene, const bvh::Bvh& bvh, Scene* owned_scene,
                       bvh::Bvh* owned_bvh) {
  SceneExtras extras;
  extras.camera = pick_camera(scene, settings_);
  extras.background = settings_.background;
  extras.env = settings_.environment.get();
  extras.env_intensity = settings_.env_intensity;
  extras.env_rotation_degrees = settings_.env_rotation;
  extras.lights = &lights_;
  extras.mipmaps = plan_.features.texture_lod;
  extras.vertex_arrays = VertexArrays::of(plan_.features);
  // On a CPU device the kernels read the packed scene in place, which therefore stays here; a GPU
  // gets its own copy, and the host's goes at the end of this function.
  const bool in_place = !rt_.device().gpu;
  const std::uint64_t max_buffer = plan_.scene_buffer_limit;
  PackedScene packed = owned_scene && owned_bvh ? pack_scene(*owned_scene, *owned_bvh, extras,
                                                             max_buffer, HostArrays::kRelease)
                                                : pack_scene(scene, bvh, extras, max_buffer);
  scene_ = upload_scene(rt_.context(), packed, in_place);
  scene_buffer_count_ = static_cast<int>(packed.buffers.size());
  for (const auto& buffer : packed.buffers) scene_bytes_ += buffer.size();
  texture_bytes_ = packed.texel_bytes;
  mip_bytes_ = packed.mip_bytes;
  // Which buffer holds which array is part of the program (kernels/geom/scene.h); a scene in one
  // buffer leaves the options as they were.
  if (packed.buffer_map) {
    char map[64];
    std::snprintf(map, sizeof(map), " -D WP_SCENE_BUFFER_MAP=0x%llxul",
                  static_cast<unsigned long long>(packed.buffer_map));
    plan_.program_options += map;
  }
  if (in_place) packed_ = std::move(packed.buffers);
}

void Wavefront::allocate_state() {
  const cl::Context& ctx = rt_.context();
  path_buf_ = cl::Buffer(ctx, CL_MEM_READ_WRITE, plan_.memory.path_state.bytes);
  queue_slots_ = cl::Buffer(ctx, CL_MEM_READ_WRITE, plan_.memory.queues);
  counters_ = cl::Buffer(ctx, CL_MEM_READ_WRITE, plan_.memory.counters);
  const std::size_t film_words = plan_.memory.film / sizeof(std::uint64_t);
  film_ = cl::Buffer(ctx, CL_MEM_READ_WRITE, plan_.memory.film);
  // Zeroed by one write of host zeros over the whole buffer, not clEnqueueFillBuffer: Oclgrind
  // 21.10 (tests/test_oclgrind.sh) re-creates a buffer's whole initialisation state at every host
  // write, sized to that write, so a fill (stored one pattern at a time) or a partial write leaves
  // the entire buffer "uninitialised" to its --uninitialized check. The counters are 20 bytes; the
  // film's host zeros are as large as the copy film() reads back, and made once, by calloc: fresh
  // pages the C library knows to be zero, which the write then only reads (a std::vector's zeros
  // would be stored page by page first: 67 ms -> 45 ms here for a 1280 x 720 film).
  const std::vector<dev::uint> zero_counters(WP_COUNTER_COUNT, 0u);
  rt_.queue().enqueueWriteBuffer(counters_, CL_TRUE, 0, zero_counters.size() * sizeof(dev::uint),
                                 zero_counters.data());
  const std::unique_ptr<void, decltype(&std::free)> zero_film(
      std::calloc(film_words, sizeof(std::uint64_t)), &std::free);
  if (!zero_film) throw std::bad_alloc();
  rt_.queue().enqueueWriteBuffer(film_, CL_TRUE, 0, film_words * sizeof(std::uint64_t),
                                 zero_film.get());
}

// The program of this pipeline's stages, built (or taken from the kernel cache), and its kernels
// made and primed. An implementation that compiles every kernel of a program for its binary
// (PoCL, for the kernel cache) would otherwise compile the split stages for a fused render too, a
// third of a cold build's time. A test or benchmark that launches a stage of the other pipeline
// gets it from a program of every stage, built then (kernel()). Not from a program of the other
// stages alone: PoCL's code for a stage may depend on the program around it (the shared functions
// inlined or not, and the contractions into FMAs that follow), and the split stages of a program
// of only those four gave other ray origins than the fused kernel (Stages.ShadeDoesWhatThe...),
// where in a program of all nine they give the same bits. The source digest covers every stage, so
// that the render key does not depend on the pipeline.
void Wavefront::build_program() {
  const auto build_start = std::chrono::steady_clock::now();
  const std::string all = program_source(all_stages());
  source_digest_ = fnv1a64(all.data(), all.size());
  program_stages_ = pipeline_.stages();
  program_ =
      rt_.build(program_source(program_stages_), plan_.program_options, settings_.kernel_cache_dir);
  kernel_cached_ = rt_.cached_build();
  for (const Stage stage : pipeline_.stages()) kernel(stage);
  prime_kernels();
  try {
    for (const auto size : program_.getInfo<CL_PROGRAM_BINARY_SIZES>()) binary_bytes_ += size;
  } catch (const cl::Error&) {
    binary_bytes_ = 0;  // not every implementation reports binaries
  }
  build_seconds_ =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - build_start).count();
}

// Every stage kernel takes WP_STAGE_PARAMS (kernels/integrator/stage.h), accumulate the film after
// them. All but the Launch argument are set once, when the kernel is made.
cl::Kernel& Wavefront::kernel(Stage stage) {
  cl::Kernel& k = kernels_[static_cast<int>(stage)];
  if (k()) return k;
  const bool in_program =
      std::find(program_stages_.begin(), program_stages_.end(), stage) != program_stages_.end();
  if (!in_program && !other_program_())
    other_program_ =
        rt_.build(program_source(all_stages()), plan_.program_options, settings_.kernel_cache_dir);
  try {
    k = cl::Kernel(in_program ? program_ : other_program_, stage_name(stage));
    cl_uint arg = set_scene_args(k, 0, scene_);
    k.setArg(arg++, path_buf_);
    k.setArg(arg++, plan_.memory.path_state.layout);
    k.setArg(arg++, queue_slots_);
    k.setArg(arg++, counters_);
    launch_arg_ = arg++;
    if (stage == Stage::kAccumulate) k.setArg(arg++, film_);
  } catch (const cl::Error& e) {
    k = cl::Kernel();
    rethrow_cl(e,
               std::string("making the kernel ") + stage_name(stage) + " on " + rt_.device().name);
  }
  return k;
}

// Some implementations (PoCL) compile a kernel only at its first launch, for the work-group size
// of that launch. One empty launch of each of the pipeline's stages here makes that cost part of
// the build (where kernel_build_seconds reports it) instead of the first sample pass; the other
// pipeline's stages would add to the cold build for nothing.
void Wavefront::prime_kernels() {
  // An empty wave: no paths, no pixels, so every work-item returns at once (none gets to a
  // division by wave_pixels, nor reads path state).
  dev::Launch p = launch_params(0, 0, 0);
  p.queue_in = WP_QUEUE_RAY_A;
  p.queue_out = WP_QUEUE_RAY_B;
  try {
    for (const Stage stage : pipeline_.stages())
      launch(stage, static_cast<std::uint32_t>(plan_.local_size), p);
    rt_.queue().finish();
  } catch (const cl::Error& e) {
    rethrow_cl(e, "preparing the kernels on " + rt_.device().name);
  }
  pending_events_.clear();
}

cl::Event Wavefront::launch(Stage stage, std::uint32_t items, const dev::Launch& params) {
  if (items == 0) return cl::Event();
  if (stage == Stage::kTraceShadow) last_shadow_rays_ = items;  // its queue's exact length
  if (stage == Stage::kTraceShadow && plan_.shadow_packet > 1 && params.shadow_packet > 1)
    items = (items + plan_.shadow_packet - 1) / plan_.shadow_packet;
  if (stage == Stage::kShade || stage == Stage::kGenerateCameraRays)  // eight paths a work-item
    items = (items + plan_.shade_packet - 1) / plan_.shade_packet;
  if (stage == Stage::kIntersectClosest && plan_.closest_packet > 1 && params.packet > 1)
    items = (items + plan_.closest_packet - 1) / plan_.closest_packet;
  const std::size_t local = plan_.local_size;
  const std::size_t global = local ? (items + local - 1) / local * local : items;
  cl::Kernel& k = kernel(stage);
  cl::Event event;
  try {
    k.setArg(launch_arg_, params);
    rt_.queue().enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(global),
                                     local ? cl::NDRange(local) : cl::NullRange, nullptr, &event);
  } catch (const cl::Error& e) {
    rethrow_cl(e, std::string("launching ") + stage_name(stage));
  }
  if (settings_.profile) pending_events_.emplace_back(stage, event);
  if (stage == Stage::kIntersectClosest) last_intersect_ = event;
  if (stage == Stage::kTraceShadow) last_shadow_ = event;
  return event;
}

std::uint32_t Wavefront::read_counter(std::uint32_t index) {
  dev::uint value = 0;
  rt_.queue().enqueueReadBuffer(counters_, CL_TRUE, index * sizeof(dev::uint), sizeof(value),
                                &value);
  return value;
}

void Wavefront::write_queue(dev::uint queue, const std::vector<dev::uint>& slots) {
  if (slots.size() > wave_paths()) throw Error("write_queue: more slots than the wave holds");
  std::vector<dev::uint> counters(WP_QUEUE_COUNT, 0u);
  counters[queue] = static_cast<dev::uint>(slots.size());
  rt_.queue().enqueueWriteBuffer(counters_, CL_TRUE, 0, counters.size() * sizeof(dev::uint),
                                 counters.data());
  if (!slots.empty())
    rt_.queue().enqueueWriteBuffer(queue_slots_, CL_TRUE, queue * wave_paths() * sizeof(dev::uint),
                                   slots.size() * sizeof(dev::uint), slots.data());
}

dev::Launch Wavefront::launch_params(std::uint32_t sample, std::uint32_t first_pixel,
                                     std::uint32_t count, std::uint32_t samples) const {
  dev::Launch p{};
  p.width = static_cast<dev::uint>(settings_.width);
  p.height = static_cast<dev::uint>(settings_.height);
  p.pixel_offset = first_pixel;
  p.wave_pixels = count;
  p.path_count = count * samples;
  p.sample = sample;
  p.seed = settings_.seed;
  p.max_depth = static_cast<dev::uint>(settings_.max_depth);
  p.rr_depth = static_cast<dev::uint>(settings_.rr_depth);
  p.rr_threshold = settings_.rr_threshold;
  p.strategy =
      static_cast<dev::uint>(settings_.strategy);  // WP_STRATEGY_* (kernels/util/features.h)
  // Packets where the program has them; run_wave picks per bounce.
  p.packet = plan_.closest_packet;
  p.shadow_packet = plan_.shadow_packet;
  return p;
}

// Closest-hit packets (kernels/traversal/traverse8_packet.h) pay where a packet's rays share much
// of their walk (a small scene, coherent camera rays) and cost where they part (rays past the edges
// of objects toward the sky, glossy bounces: docs/performance.md, "Closest-hit rays in packets"),
// and no rule on the scene alone predicts which. So each bounce index takes turns of packets and
// single rays until each has traced kPacketTimingRays rays or been launched kPacketTimingLaunches
// times (deep bounces trace few rays), then keeps the faster per ray; the first wave, slower for
// a cold start whichever it uses, is not timed. The image does not depend on the choice (the
// walks give every ray the same hit), only the time. Shadow-ray packets likewise, timed apart:
// they pay on the Cornell box and cost on glossy models, whose shadow rays part (MetalRoughSpheres'
// bounce 1: 0.25 of Embree's rays/s in packets; docs/performance.md, "Shadow rays in packets of
// eight").
constexpr std::uint64_t kPacketTimingRays = 1u << 17;
constexpr int kPacketTimingLaunches = 2;
constexpr std::size_t kPacketTimingBounces = 8;  // deeper bounces share the last one's choice

int Wavefront::packet_mode(const std::vector<PacketTiming>& timing, std::uint32_t packet,
                           std::size_t bounce) const {
  if (packet <= 1) return 0;
  const std::size_t b = std::min(bounce, kPacketTimingBounces - 1);
  if (b >= timing.size()) return 0;
  const PacketTiming& t = timing[b];
  if (t.choice >= 0) return t.choice;
  return t.launches[1] < t.launches[0] ? 1 : 0;
}

void Wavefront::time_packets(std::vector<PacketTiming>& timing, std::uint32_t packet,
                             const cl::Event& event, std::size_t bounce, int mode,
                             std::uint32_t rays) {
  if (packet <= 1 || rays == 0 || waves_run_ == 0 || event() == nullptr) return;
  const std::size_t b = std::min(bounce, kPacketTimingBounces - 1);
  if (timing.size() <= b) timing.resize(b + 1);
  PacketTiming& t = timing[b];
  if (t.choice >= 0) return;
  event.wait();  // trace_shadow runs after the bounce's read-back: it may still be running
  const auto start = event.getProfilingInfo<CL_PROFILING_COMMAND_START>();
  const auto end = event.getProfilingInfo<CL_PROFILING_COMMAND_END>();
  t.seconds[mode] += static_cast<double>(end - start) * 1e-9;
  t.rays[mode] += rays;
  t.launches[mode] += 1;
  const auto timed = [&t](int m) {
    return t.rays[m] >= kPacketTimingRays || t.launches[m] >= kPacketTimingLaunches;
  };
  if (timed(0) && timed(1))
    t.choice = t.seconds[1] / static_cast<double>(t.rays[1]) <
                       t.seconds[0] / static_cast<double>(t.rays[0])
                   ? 1
                   : 0;
}

// One wave of paths through all bounces: the pipeline's start, bounces until no ray is left, end.
void Wavefront::run_wave(std::uint32_t sample, std::uint32_t first_pixel, std::uint32_t count,
                         std::uint32_t samples) {
  dev::Launch p = start_wave(sample, first_pixel, count, samples);
  std::size_t bounce = 0;
  for (std::uint32_t rays = p.path_count; rays > 0; ++bounce) {
    rays_traced_ += rays;
    const int mode = packet_mode(packet_timing_, plan_.closest_packet, bounce);
    const int shadow_mode = packet_mode(shadow_timing_, plan_.shadow_packet, bounce);
    p.packet = mode == 1 ? plan_.closest_packet : 1u;
    p.shadow_packet = shadow_mode == 1 ? plan_.shadow_packet : 1u;
    const std::uint32_t traced = rays;
    rays = run_bounce(p, rays, static_cast<int>(bounce));
    time_packets(packet_timing_, plan_.closest_packet, last_intersect_, bounce, mode, traced);
    time_packets(shadow_timing_, plan_.shadow_packet, last_shadow_, bounce, shadow_mode,
                 last_shadow_rays_);
  }
  ++waves_run_;
  run_step(pipeline_.end, p, 0);
}

dev::Launch Wavefront::start_wave(std::uint32_t sample, std::uint32_t first_pixel,
                                  std::uint32_t count, std::uint32_t samples) {
  dev::Launch p = launch_params(sample, first_pixel, count, samples);
  // The camera rays go to the queue the first bounce reads.
  p.queue_in = WP_QUEUE_RAY_A;
  p.queue_out = WP_QUEUE_RAY_A;
  run_step(pipeline_.start, p, 0);
  p.queue_out = WP_QUEUE_RAY_B;
  return p;
}

std::uint32_t Wavefront::launch_items(const Step& step, const dev::Launch& p, std::uint32_t rays,
                                      const QueueCounts* counts) const {
  switch (step.size) {
    case LaunchSize::kPaths:
      return p.path_count;
    case LaunchSize::kPixels:
      return p.wave_pixels;
    case LaunchSize::kRays:
      return rays;
    case LaunchSize::kQueueLength:
      break;
  }
  if (!counts) throw Error("launch_items: the queue lengths were not read back");
  return (*counts)[queue_index(step.in, p)];
}

void Wavefront::run_step(const Step& step, const dev::Launch& p, std::uint32_t rays,
                         const QueueCounts* counts) {
  launch(step.stage, launch_items(step, p, rays, counts), p);
}

Wavefront::QueueCounts Wavefront::read_queue_counts() {
  QueueCounts counts{};
  rt_.queue().enqueueReadBuffer(counters_, CL_TRUE, 0, counts.size() * sizeof(dev::uint),
                                counts.data());
  return counts;
}

// How many shadow-queue entries run_bounce launches trace_shadow over before the queue's count is
// read back: the share of shadow rays per ray of the same bounce in the last wave, times
// settings.shadow_ahead, of this bounce's rays (each ray makes at most one shadow ray), rounded
// up to whole work-groups so that the launch stops exactly there (the kernels skip only entries
// past the queue's length); 0 where there is no estimate, the setting is 0, or the shadow rays of
// this bounce index are still being timed (time_packets times one launch per bounce).
std::uint32_t Wavefront::shadow_ahead_items(const dev::Launch& p, std::uint32_t rays,
                                            int bounce) const {
  if (bounce < 0 || !(settings_.shadow_ahead > 0.0f)) return 0;
  const std::size_t b = static_cast<std::size_t>(bounce);
  if (b >= shadow_share_.size() || shadow_share_[b] < 0.0) return 0;
  if (plan_.shadow_packet > 1) {
    const std::size_t t = std::min(b, kPacketTimingBounces - 1);
    if (t >= shadow_timing_.size() || shadow_timing_[t].choice < 0) return 0;
  }
  const std::uint64_t unit =
      std::uint64_t(plan_.local_size) * (p.shadow_packet > 1 ? plan_.shadow_packet : 1u);
  // At most the bounce's rays (the share is >= 0); a wave's paths are far below 2^32 - unit.
  const double want = std::ceil(shadow_share_[b] * settings_.shadow_ahead * rays);
  const auto items = static_cast<std::uint64_t>(std::min(want, double(rays)));
  return static_cast<std::uint32_t>((items + unit - 1) / unit * unit);
}

// The bounce's counters are read without waiting and `step` (trace_shadow) launched over `ahead`
// entries at once, so the device goes on while the host wakes to the count; then the rest, if
// any, from where that launch stopped. Every entry is traced once: the same image. Returns the
// counters. (Read into a member: an exception before the wait leaves the device a place to
// write.)
Wavefront::QueueCounts Wavefront::launch_ahead(const Step& step, const dev::Launch& p,
                                               std::uint32_t ahead) {
  cl::Event counted;
  rt_.queue().enqueueReadBuffer(counters_, CL_FALSE, 0, ahead_counts_.size() * sizeof(dev::uint),
                                ahead_counts_.data(), nullptr, &counted);
  launch(step.stage, ahead, p);
  ++shadow_ahead_launches_;
  counted.wait();
  const std::uint32_t queued = ahead_counts_[queue_index(step.in, p)];
  if (queued > ahead) {
    dev::Launch rest = p;
    rest.shadow_first = ahead;
    launch(step.stage, queued - ahead, rest);
    ++shadow_rest_launches_;
  }
  return ahead_counts_;
}

std::uint32_t Wavefront::run_bounce(dev::Launch& p, std::uint32_t rays, int bounce) {
  // Empty the surface, shadow and output queues. One write of all queue counters from offset 0,
  // with queue_in's rewritten to the `rays` it already holds, rather than fills of the three: any
  // partial host write makes Oclgrind 21.10 treat the whole counter buffer as uninitialised (see
  // allocate_state). The nonfinite counter after them is not written: it persists (so Oclgrind
  // would call it uninitialised, were count_nonfinite ever reached; it must not be).
  last_shadow_rays_ = 0;  // launch() sets it where the bounce has shadow rays
  // The write does not wait (the queue runs in order): the host would otherwise sit out the last
  // bounce's trace_shadow, and the device the host's next launches.
  bounce_counts_.fill(0u);
  bounce_counts_[p.queue_in] = rays;
  rt_.queue().enqueueWriteBuffer(counters_, CL_FALSE, 0, bounce_counts_.size() * sizeof(dev::uint),
                                 bounce_counts_.data());
  QueueCounts counts{};
  // The bounce's one read-back, before the first step launched over an exact queue length; the
  // steps from there on push to no queue (pipeline.h), so it holds the next bounce's ray count.
  bool read = false;
  for (const Step& step : pipeline_.bounce) {
    if (step.size == LaunchSize::kQueueLength && !read) {
      const std::uint32_t ahead =
          step.stage == Stage::kTraceShadow ? shadow_ahead_items(p, rays, bounce) : 0;
      read = true;
      if (ahead != 0) {
        counts = launch_ahead(step, p, ahead);
        continue;
      }
      counts = read_queue_counts();
    }
    run_step(step, p, rays, read ? &counts : nullptr);
  }
  if (!read) counts = read_queue_counts();
  if (bounce >= 0 && rays > 0) {
    const std::size_t b = static_cast<std::size_t>(bounce);
    if (shadow_share_.size() <= b) shadow_share_.resize(b + 1, -1.0);
    shadow_share_[b] = double(counts[WP_QUEUE_SHADOW]) / double(rays);
  }
  const std::uint32_t next = counts[p.queue_out];
  std::swap(p.queue_in, p.queue_out);
  return next;
}

Wavefront::Snapshot Wavefront::snapshot() {
  Snapshot s;
  s.paths.resize(plan_.memory.path_state.bytes);
  s.slots.resize(WP_QUEUE_COUNT * wave_paths());
  s.counters.resize(WP_COUNTER_COUNT);
  auto& q = rt_.queue();
  q.enqueueReadBuffer(path_buf_, CL_FALSE, 0, s.paths.size(), s.paths.data());
  q.enqueueReadBuffer(queue_slots_, CL_FALSE, 0, s.slots.size() * sizeof(dev::uint),
                      s.slots.data());
  q.enqueueReadBuffer(counters_, CL_TRUE, 0, s.counters.size() * sizeof(dev::uint),
                      s.counters.data());
  return s;
}

void Wavefront::restore(const Snapshot& s) {
  auto& q = rt_.queue();
  q.enqueueWriteBuffer(path_buf_, CL_FALSE, 0, s.paths.size(), s.paths.data());
  q.enqueueWriteBuffer(queue_slots_, CL_FALSE, 0, s.slots.size() * sizeof(dev::uint),
                       s.slots.data());
  q.enqueueWriteBuffer(counters_, CL_TRUE, 0, s.counters.size() * sizeof(dev::uint),
                       s.counters.data());
}

void Wavefront::render_pass(std::uint32_t sample, std::uint32_t samples) {
  if (samples < 1 || samples > plan_.memory.wave.samples)
    throw Error("render_pass: the samples of a pass must fit one wave");
  const std::uint32_t pixels = static_cast<std::uint32_t>(settings_.width * settings_.height);
  try {
    for (std::uint32_t first = 0; first < pixels;
         first += static_cast<std::uint32_t>(plan_.memory.wave.pixels))
      run_wave(sample, first,
               std::min<std::uint32_t>(static_cast<std::uint32_t>(plan_.memory.wave.pixels),
                                       pixels - first),
               samples);
    rt_.queue().finish();
  } catch (const cl::Error& e) {
    rethrow_cl(e, "rendering on " + rt_.device().name);
  }
  if (settings_.profile) collect_profile();
}

void Wavefront::collect_profile() {
  for (auto& [stage, event] : pending_events_) {
    const auto start = event.getProfilingInfo<CL_PROFILING_COMMAND_START>();
    const auto end = event.getProfilingInfo<CL_PROFILING_COMMAND_END>();
    times_.seconds[static_cast<int>(stage)] += static_cast<double>(end - start) * 1e-9;
    times_.launches[static_cast<int>(stage)] += 1;
  }
  pending_events_.clear();
}

Film Wavefront::film(FilmInfo info) {
  if (info.width != settings_.width || info.height != settings_.height)
    throw Error("Wavefront::film: the film's size is not the render's");
  Film film(std::move(info));
  auto& words = film.words();
  try {
    rt_.queue().enqueueReadBuffer(film_, CL_TRUE, 0, words.size() * sizeof(std::uint64_t),
                                  words.data());
  } catch (const cl::Error& e) {
    rethrow_cl(e, "reading the film back from " + rt_.device().name);
  }
  return film;
}

void Wavefront::load_film(const Film& film) {
  if (film.info().width != settings_.width || film.info().height != settings_.height)
    throw Error("Wavefront::load_film: the film's size is not the render's");
  try {  // the whole buffer in one write, as in the constructor (Oclgrind's initialisation state)
    rt_.queue().enqueueWriteBuffer(film_, CL_TRUE, 0, film.words().size() * sizeof(std::uint64_t),
                                   film.words().data());
  } catch (const cl::Error& e) {
    rethrow_cl(e, "writing the film to " + rt_.device().name);
  }
}

std::uint64_t Wavefront::nonfinite_samples() {
  return read_counter(WP_COUNTER_NONFINITE);
}

}  // namespace wp
