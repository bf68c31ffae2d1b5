// wavepath-bench: every wavefront stage kernel on its own, on captured real wavefront state, with
// Embree on the same rays for the ray-tracing stages, plus end-to-end figures. Google Benchmark
// drives it (--benchmark_filter, --benchmark_format=json, --benchmark_repetitions, ...); its own
// options are taken out of the command line first. tools/bench_report.py turns the JSON into the
// tables of docs/performance.md.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "host/bench/bench.h"
#include "host/bench/scene_bench.h"

namespace wp::bench {

Env& env() {
  static Env e;
  return e;
}

RenderSettings bench_settings(bool profile) {
  RenderSettings s;
  s.width = env().options.width;
  s.height = env().options.height;
  s.background = glm::vec3(1.0f);
  s.profile = profile;
  s.bvh_width = env().options.bvh_width;
  return s;
}

void fail(benchmark::State& state, const std::string& message) {
  env().failed = true;
  std::fprintf(stderr, "wavepath-bench: error: %s\n", message.c_str());
  state.SkipWithError(message.c_str());
}

void skip(benchmark::State& state, const std::string& message) {
  state.SkipWithError(message.c_str());
}

namespace {

constexpr const char* kUsage =
    "wavepath-bench: the wavefront's stage kernels and whole renders, timed.\n"
    "\n"
    "Options of its own (the others are Google Benchmark's, listed below):\n"
    "  --scene FILE    a glTF scene (.gltf/.glb); repeatable. Default: scenes/cornell_box.gltf\n"
    "                  and, when <assets>/models exists, DamagedHelmet, FlightHelmet and\n"
    "                  MetalRoughSpheresNoTextures (<assets>: $WAVEPATH_ASSETS, else\n"
    "                  ../shared/assets beside the source tree)\n"
    "  --width N       image width in pixels (default 640)\n"
    "  --height N      image height in pixels (default 480)\n"
    "  --device D      OpenCL device index or name substring (default: first GPU, else CPU)\n"
    "  --bvh-width W   BVH layout, 2 or 8 (default: 2 on GPUs, 8 on CPUs)\n"
    "  --spatial-splits  build the BVH with spatial splits\n"
    "  --instancing M  meshes placed more than once: on (instances, a two-level BVH), off\n"
    "                  (flattened copies) or auto (default; as wavepath render --instancing)\n"
    "\n"
    "Benchmarks: <stage>/bounce<0|1>/<scene> and accumulate/final/<scene> (one kernel launch on\n"
    "captured state, device time), render/<scene>, bvh_build/<scene>, program_build/<scene>.\n"
    "Example: wavepath-bench --benchmark_format=json --benchmark_out=bench.json\n"
    "         python3 tools/bench_report.py bench.json\n\n";

std::string shell_quote(const std::string& s) {
  if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                        "0123456789_-+=/.,:@%") == std::string::npos)
    return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string scene_name(const std::string& path, const std::vector<SceneSpec>& taken) {
  const std::string stem = std::filesystem::path(path).stem().string();
  std::string name = stem;
  for (int i = 2;; ++i) {
    bool clash = false;
    for (const auto& s : taken) clash = clash || s.name == name;
    if (!clash) return name;
    name = stem + "_" + std::to_string(i);
  }
}

std::vector<std::string> default_scenes() {
  namespace fs = std::filesystem;
  std::vector<std::string> out = {std::string(WP_SOURCE_DIR) + "/scenes/cornell_box.gltf"};
  const char* assets_env = std::getenv("WAVEPATH_ASSETS");
  const fs::path assets = assets_env && *assets_env
                              ? fs::path(assets_env)
                              : fs::path(WP_SOURCE_DIR).parent_path() / "shared" / "assets";
  const fs::path models = assets / "models";
  if (!fs::is_directory(models)) return out;
  // SimpleInstancing: one mesh placed by 125 instances, traversed through the two-level BVH
  // (against Embree's own instancing).
  for (const char* m : {"DamagedHelmet/DamagedHelmet.glb", "FlightHelmet/FlightHelmet.gltf",
                        "MetalRoughSpheresNoTextures/MetalRoughSpheresNoTextures.glb",
                        "SimpleInstancing/SimpleInstancing.glb"})
    if (fs::exists(models / m)) out.push_back((models / m).lexically_normal().string());
  return out;
}

int parse_size(const std::string& option, const std::string& value) {
  try {
    std::size_t used = 0;
    const int v = std::stoi(value, &used);
    if (used == value.size() && v >= 1 && v <= 16384) return v;
  } catch (const std::exception&) {
  }
  throw Error(option + " must be an integer between 1 and 16384");
}

// Takes the tool's own options out of argv (Google Benchmark rejects what it does not know).
Options parse_options(int& argc, char** argv) {
  Options o;
  std::vector<std::string> scenes;
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i], value;
    bool own = false;
    if (arg == "--spatial-splits") {
      o.spatial_splits = true;
      continue;
    }
    for (const char* name :
         {"--scene", "--width", "--height", "--device", "--bvh-width", "--instancing"}) {
      const std::string n = name;
      if (arg == n) {
        if (i + 1 >= argc) throw Error(n + " needs a value");
        value = argv[++i];
      } else if (arg.rfind(n + "=", 0) == 0) {
        value = arg.substr(n.size() + 1);
      } else {
        continue;
      }
      own = true;
      arg = n;
      break;
    }
    if (!own) {
      if (arg.rfind("--benchmark_min_time", 0) == 0) o.user_min_time = true;
      if (arg == "--help") std::fputs(kUsage, stdout);
      argv[kept++] = argv[i];
      continue;
    }
    if (arg == "--scene") scenes.push_back(value);
    if (arg == "--width") o.width = parse_size(arg, value);
    if (arg == "--height") o.height = parse_size(arg, value);
    if (arg == "--device") o.device = value;
    if (arg == "--instancing") {
      if (value != "on" && value != "off" && value != "auto")
        throw Error("--instancing must be on, off or auto");
      o.instancing = value == "on"    ? Instancing::kAlways
                     : value == "off" ? Instancing::kNever
                                      : Instancing::kAuto;
    }
    if (arg == "--bvh-width") {
      o.bvh_width = parse_size(arg, value);
      if (o.bvh_width != 2 && o.bvh_width != 8) throw Error("--bvh-width must be 2 or 8");
    }
  }
  argc = kept;
  argv[argc] = nullptr;
  if (scenes.empty()) scenes = default_scenes();
  for (const auto& path : scenes) {
    if (!std::filesystem::exists(path)) throw Error("--scene " + path + ": no such file");
    o.scenes.push_back({scene_name(path, o.scenes), path});
  }
  return o;
}

void add_context(const std::string& command) {
  const Env& e = env();
  benchmark::AddCustomContext("wavepath_command", command);
  benchmark::AddCustomContext("opencl_device", e.device.name);
  benchmark::AddCustomContext("opencl_platform", e.device.platform_name);
  benchmark::AddCustomContext("opencl_version", e.device.version);
  benchmark::AddCustomContext("opencl_compute_units", std::to_string(e.device.compute_units));
  benchmark::AddCustomContext(
      "image", std::to_string(e.options.width) + "x" + std::to_string(e.options.height));
  std::string scenes;
  for (const auto& s : e.options.scenes)
    scenes += (scenes.empty() ? "" : ",") + s.name + "=" + s.path;
  benchmark::AddCustomContext("scenes", scenes);
}

}  // namespace

}  // namespace wp::bench

int main(int argc, char** argv) {
  using namespace wp::bench;
  if (argc > 1 && std::strcmp(argv[1], kStartupProbe) == 0) return run_startup_probe(argc, argv);
  try {
    std::string command;
    for (int i = 0; i < argc; ++i) command += (i ? " " : "") + shell_quote(argv[i]);
    env().options = parse_options(argc, argv);
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    env().device = wp::select_device(env().options.device);
    wp::ClRuntime runtime(env().device);
    env().runtime = &runtime;
    add_context(command);
    for (const auto& scene : env().options.scenes) {
      register_stage_benchmarks(scene);
      register_end_to_end_benchmarks(scene);
    }
    benchmark::RunSpecifiedBenchmarks();
    release_scene_bench();
    benchmark::Shutdown();
    return env().failed ? 1 : 0;
  } catch (const wp::Error& e) {
    std::fprintf(stderr, "wavepath-bench: error: %s\n", e.what());
    if (!e.details().empty()) std::fprintf(stderr, "%s\n", e.details().c_str());
    return 1;
  }
}
