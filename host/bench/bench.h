// wavepath-bench: what the benchmark files share. The options of the tool itself (the rest of
// the command line is Google Benchmark's), the one OpenCL runtime of the process, and the
// registration of each family of benchmarks.
#pragma once

#include <exception>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "host/device/cl_runtime.h"
#include "host/util/error.h"
#include "host/render/wavefront.h"
#include "host/scene/gltf_loader.h"

namespace wp::bench {

struct SceneSpec {
  std::string name;  // in benchmark names: the file's stem
  std::string path;
};

struct Options {
  std::vector<SceneSpec> scenes;
  int width = 640;
  int height = 480;
  std::string device;           // --device: index or name substring; empty: the default device
  int bvh_width = 0;            // --bvh-width 2|8; 0: the device's default (render.h)
  bool spatial_splits = false;  // --spatial-splits
  Instancing instancing = Instancing::kAuto;  // --instancing on|off|auto, as render's
  bool user_min_time = false;  // --benchmark_min_time given: no benchmark sets its own
};

// Set once in main before any benchmark runs.
struct Env {
  Options options;
  DeviceEntry device;
  ClRuntime* runtime = nullptr;
  bool failed = false;  // a benchmark reported an error: the process exits non-zero
};
Env& env();

// Every render the benchmarks make uses these settings: the image size of the options, spp and
// depths as `wavepath render`, and a white sky (background radiance 1) so that scenes without
// lights of their own still have light to sample and shadow rays to trace.
RenderSettings bench_settings(bool profile);

// Reports an error on the benchmark: it shows in the output with the message, and the process
// exits non-zero at the end (a broken benchmark must fail the smoke test).
void fail(benchmark::State& state, const std::string& message);

// Reports that a benchmark does not apply (e.g. a scene whose camera rays all escape has no
// bounce 1): shown like an error, but the exit status stays 0.
void skip(benchmark::State& state, const std::string& message);

// Runs a benchmark body, turning any exception into fail().
template <class Body>
void guarded(benchmark::State& state, Body&& body) {
  try {
    body();
  } catch (const Error& e) {
    fail(state, e.what());
  } catch (const cl::Error& e) {
    fail(state, std::string(e.what()) + " failed with " + cl_error_name(e.err()));
  } catch (const std::exception& e) {
    fail(state, e.what());
  }
}

// Registration, per scene (stage_bench.cpp, end_to_end.cpp).
void register_stage_benchmarks(const SceneSpec& scene);
void register_end_to_end_benchmarks(const SceneSpec& scene);

// The child process that measures a cold or warm start (end_to_end.cpp): `wavepath-bench
// --startup-probe SCENE WIDTH HEIGHT DEVICE` renders one pass and prints its timings on stdout.
inline constexpr const char* kStartupProbe = "--startup-probe";
int run_startup_probe(int argc, char** argv);

}  // namespace wp::bench
