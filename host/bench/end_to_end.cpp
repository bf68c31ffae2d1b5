// End-to-end figures, per scene:
//   render/<scene>         whole sample passes: samples/s (items_per_second), the share of wall
//                          time each kernel runs (share_<stage>: its profiling events' durations
//                          summed, over the wall time) and the rest, the host's (share_host:
//                          launches, synchronisation, read-backs); bytes of path state per path
//                          and the device memory the renderer allocates
//   bvh_build/<scene>      the BVH build as the renderer does it, and the SAH cost of the tree
//   program_build/<scene>  program build and time to the first finished pass, cold (a fresh,
//                          empty kernel cache) and warm (the same cache again), each in a child
//                          process: an OpenCL implementation reads its cache settings once, when
//                          the process first uses it
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "host/accel/bvh_input.h"
#include "host/bench/bench.h"
#include "host/bench/scene_bench.h"
#include "host/scene/gltf_loader.h"
#include "host/render/render.h"

extern char** environ;

namespace wp::bench {

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// --- render ------------------------------------------------------------------------------------

void run_render(benchmark::State& state, const SceneSpec& spec) {
  SceneBench& sb = scene_bench(spec);
  Wavefront& wf = sb.render_wavefront();
  const StageTimes before = wf.stage_times();
  // A pass as the renderer makes it: as many samples as a wave holds (one, unless the image is
  // small: wavefront.h, kMultiSamplePaths).
  const auto samples = static_cast<std::uint32_t>(wf.samples_per_wave());
  double wall = 0;
  for (auto _ : state) {
    const auto start = Clock::now();
    wf.render_pass(sb.next_samples(samples), samples);
    const double seconds = since(start);
    state.SetIterationTime(seconds);
    wall += seconds;
  }
  const StageTimes& after = wf.stage_times();
  const RenderSettings s = bench_settings(true);
  const auto pixels = static_cast<benchmark::IterationCount>(s.width) * s.height;
  state.SetItemsProcessed(state.iterations() * pixels * samples);
  double kernels = 0;
  for (int i = 0; i < kStageCount; ++i) {
    const double share = (after.seconds[i] - before.seconds[i]) / wall;
    state.counters[std::string("share_") + kStageNames[i]] = share;
    kernels += share;
  }
  state.counters["share_host"] = 1.0 - kernels;
  state.counters["passes"] = static_cast<double>(state.iterations());
  state.counters["bytes_per_path"] = static_cast<double>(wf.path_state().bytes_per_path);
  state.counters["device_memory_bytes"] =
      benchmark::Counter(static_cast<double>(sb.device_memory_bytes()),
                         benchmark::Counter::kDefaults, benchmark::Counter::kIs1024);
  state.counters["wave_size"] = static_cast<double>(wf.wave_paths());
  state.counters["triangles"] = static_cast<double>(sb.scene().triangle_count());
  state.counters["instances"] = static_cast<double>(sb.scene().instances.size());
}

// --- bvh_build ---------------------------------------------------------------------------------

void run_bvh_build(benchmark::State& state, const SceneSpec& spec) {
  SceneBench& sb = scene_bench(spec);
  bvh::BuildStats stats;
  for (auto _ : state) {
    const bvh::Bvh bvh = build_scene_bvh(sb.scene(), build_options(), std::string());
    stats = bvh.stats;
  }
  state.counters["sah_cost"] = stats.sah_cost;
  state.counters["triangles"] = static_cast<double>(sb.scene().triangle_count());
  state.counters["triangle_refs"] = static_cast<double>(stats.triangle_refs);
  state.counters["nodes"] = static_cast<double>(stats.inner_nodes + stats.leaves);
  state.counters["max_depth"] = stats.max_depth;
}

// --- program_build -----------------------------------------------------------------------------

struct ProbeResult {
  double build_seconds = 0;
  double first_pass_seconds = 0;
};

// The environment of this process with the kernel caches of PoCL and of NVIDIA's driver moved to
// `cache_dir`.
std::vector<std::string> probe_environment(const std::string& cache_dir) {
  std::vector<std::string> out;
  for (char** e = environ; *e; ++e) {
    const std::string kv = *e;
    if (kv.rfind("POCL_CACHE_DIR=", 0) == 0 || kv.rfind("CUDA_CACHE_PATH=", 0) == 0) continue;
    out.push_back(kv);
  }
  out.push_back("POCL_CACHE_DIR=" + cache_dir);
  out.push_back("CUDA_CACHE_PATH=" + cache_dir);
  return out;
}

std::vector<char*> c_strings(std::vector<std::string>& v) {
  std::vector<char*> out;
  for (auto& s : v) out.push_back(s.data());
  out.push_back(nullptr);
  return out;
}

// Runs this executable as a startup probe with its kernel caches (the driver's and wavepath's
// program cache) in `cache_dir`.
ProbeResult probe(const SceneSpec& spec, const std::string& cache_dir) {
  const Options& o = env().options;
  std::vector<std::string> args = {"/proc/self/exe",
                                   kStartupProbe,
                                   spec.path,
                                   std::to_string(o.width),
                                   std::to_string(o.height),
                                   std::to_string(env().device.index),
                                   cache_dir};
  std::vector<std::string> vars = probe_environment(cache_dir);
  std::vector<char*> argv = c_strings(args), envp = c_strings(vars);
  int out[2];
  if (pipe(out) != 0) throw Error("startup probe: pipe failed");
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
  posix_spawn_file_actions_addclose(&actions, out[0]);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, "/proc/self/exe", &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  close(out[1]);
  std::string text;
  char buf[256];
  for (ssize_t n; rc == 0 && (n = read(out[0], buf, sizeof buf)) > 0;)
    text.append(buf, static_cast<std::size_t>(n));
  close(out[0]);
  int status = 0;
  if (rc != 0) throw Error(std::string("startup probe: cannot start: ") + std::strerror(rc));
  waitpid(pid, &status, 0);
  ProbeResult r;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 ||
      std::sscanf(text.c_str(), "build_seconds=%lf first_pass_seconds=%lf", &r.build_seconds,
                  &r.first_pass_seconds) != 2)
    throw Error("startup probe on " + spec.path + " failed (its error is printed above)");
  return r;
}

void run_program_build(benchmark::State& state, const SceneSpec& spec) {
  namespace fs = std::filesystem;
  std::string dir = (fs::temp_directory_path() / "wavepath-bench-cache-XXXXXX").string();
  if (!mkdtemp(dir.data())) throw Error("cannot create a temporary kernel cache folder");
  ProbeResult cold, warm;
  try {
    for (auto _ : state) {
      cold = probe(spec, dir);  // the folder is empty: everything is compiled
      warm = probe(spec, dir);  // now it holds the first probe's binaries
      state.SetIterationTime(cold.build_seconds);
    }
  } catch (...) {
    fs::remove_all(dir);
    throw;
  }
  fs::remove_all(dir);
  state.counters["cold_build_s"] = cold.build_seconds;
  state.counters["warm_build_s"] = warm.build_seconds;
  state.counters["cold_first_pass_s"] = cold.first_pass_seconds;
  state.counters["warm_first_pass_s"] = warm.first_pass_seconds;
}

template <class Run>
benchmark::internal::Benchmark* add(const std::string& family, const SceneSpec& scene, Run run) {
  const std::string name = family + "/" + scene.name;
  return benchmark::RegisterBenchmark(name.c_str(), [scene, run](benchmark::State& state) {
    guarded(state, [&] { run(state, scene); });
  });
}

}  // namespace

void register_end_to_end_benchmarks(const SceneSpec& scene) {
  auto* render = add("render", scene, run_render)->UseManualTime()->Unit(benchmark::kMillisecond);
  if (!env().options.user_min_time) render->MinTime(2.0);  // a few passes
  add("bvh_build", scene, run_bvh_build)->UseRealTime()->Unit(benchmark::kMillisecond);
  add("program_build", scene, run_program_build)
      ->UseManualTime()
      ->Iterations(1)
      ->Unit(benchmark::kMillisecond);
}

// The child of probe(): one pass of `wavepath render` with the benchmark's settings; the time to
// the first finished pass counts from here (device discovery and glTF loading included).
int run_startup_probe(int argc, char** argv) {
  const auto start = Clock::now();
  if (argc != 7) {
    std::fprintf(stderr, "usage: wavepath-bench %s SCENE WIDTH HEIGHT DEVICE CACHE_DIR\n",
                 kStartupProbe);
    return 2;
  }
  try {
    env().options.width = std::stoi(argv[3]);
    env().options.height = std::stoi(argv[4]);
    ClRuntime runtime(select_device(argv[5]));
    const Scene scene = load_gltf(argv[2], load_options());
    RenderSettings settings = bench_settings(false);
    settings.spp = 1;
    settings.kernel_cache_dir =
        argv[6];  // as `wavepath render` keeps it (host/device/program_cache.h)
    const double before_render = since(start);
    const Rendered r = render(runtime, scene, settings);
    std::printf("build_seconds=%.9f first_pass_seconds=%.9f\n", r.report.kernel_build_seconds,
                before_render + r.report.first_pass_seconds);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "wavepath-bench: startup probe: error: %s\n", e.what());
    return 1;
  }
}

}  // namespace wp::bench
