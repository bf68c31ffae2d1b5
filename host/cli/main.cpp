// wavepath: the command line. `wavepath render SCENE`, `wavepath merge FILM...` and
// `wavepath devices`.
// Errors of every kind end here, in one place: one line on stderr, exit status 1.
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <tuple>
#include <utility>

#include <CLI/CLI.hpp>

#include "host/device/cl_runtime.h"
#include "host/cli/distributed.h"
#include "host/util/files.h"
#include "host/lights/environment.h"
#include "host/util/error.h"
#include "host/film/film.h"
#include "host/scene/gltf_loader.h"
#include "host/render/render.h"
#include "host/render/report_json.h"
#include "host/cli/stop_signals.h"

namespace {

struct CliOptions {
  std::string scene;
  std::vector<std::string> parts;  // merge: the .wpfilm files
  std::vector<std::string> outputs;
  std::string samples;  // --samples A:B
  std::string device;
  std::vector<float> env_color{0.0f, 0.0f, 0.0f};
  std::string env;
  std::string strategy = "mis";
  std::string heuristic = "power";
  std::string light_select = "power";
  std::string sampler = "sobol";
  std::string pipeline = "fused";
  bool no_rr = false;
  bool variance = false;
  bool no_bvh_cache = false;
  bool no_prefetch = false;
  bool no_kernel_cache = false;
  std::string features = "scene";
  std::string tonemap = "aces";
  float exposure = 0.0f;
  bool spatial_splits = false;
  std::uint64_t scene_buffer_kib = 0;
  double time_limit = 0;
  double noise_threshold = 0;
  std::string checkpoint;
  double checkpoint_every = 60;
  std::string resume;
  std::vector<std::string> aovs;  // --aov, in the order given
  double progress_every = 10;
  bool json = false;
  bool quiet = false;
};

int list_devices() {
  const auto devices = wp::enumerate_devices();
  if (devices.empty())
    throw wp::Error("no OpenCL platform found (install pocl-opencl-icd for CPUs)");
  // Memory in GiB: the device's global memory and its largest single buffer
  // (CL_DEVICE_MAX_MEM_ALLOC _SIZE), which bounds the packed scene (device_scene.h).
  const auto gib = [](unsigned long long bytes) { return double(bytes) / double(1ull << 30); };
  std::printf("%-5s %-11s %-16s %-8s %-10s %s\n", "index", "type", "OpenCL C", "memory",
              "max buffer", "platform / device");
  for (const auto& d : devices)
    std::printf("%-5d %-11s %-16s %-8.1f %-10.1f %s / %s\n", d.index, d.type.c_str(),
                d.c_version.substr(d.c_version.find("OpenCL C") == 0 ? 9 : 0).c_str(),
                gib(d.global_memory), gib(d.max_alloc), d.platform_name.c_str(), d.name.c_str());
  const wp::DeviceEntry def = wp::select_device("");
  std::printf("default: %d (%s)\n", def.index, def.name.c_str());
  return 0;
}

using wp::extension_of;

bool is_film(const std::string& path) {
  return extension_of(path) == ".wpfilm";
}

// Fails before any rendering when an output could not be written at the end: outputs are written
// beside their destination under a temporary name and renamed into place (image_io.h), which
// needs a writable folder; an existing file that is not writable is not replaced either.
void check_outputs(const std::vector<std::string>& outputs) {
  for (const auto& o : outputs) {
    const std::filesystem::path p(o);
    const std::string ext = extension_of(o);
    if (ext != ".exr" && ext != ".png" && ext != ".pfm" && ext != ".wpfilm")
      throw wp::Error(o + ": unsupported output format (use .exr, .png, .pfm or .wpfilm)");
    const std::filesystem::path dir = p.parent_path().empty() ? "." : p.parent_path();
    if (!std::filesystem::is_directory(dir))
      throw wp::Error(o + ": folder " + dir.string() + " does not exist");
    if (access(dir.c_str(), W_OK | X_OK) != 0)
      throw wp::Error(o + ": folder " + dir.string() + " is not writable (" + std::strerror(errno) +
                      ")");
    std::error_code ec;
    const auto status = std::filesystem::symlink_status(p, ec);
    if (std::filesystem::is_directory(status)) throw wp::Error(o + ": is a directory");
    if (std::filesystem::exists(status) && access(p.c_str(), W_OK) != 0)
      throw wp::Error(o + ": the existing file is not writable (" + std::strerror(errno) + ")");
  }
}

// --samples A:B (0 <= A < B <= 2^20) into settings.sample_begin and settings.spp. --spp N means
// 0:N, so both may be given only when they name the same range.
void apply_samples(const CLI::App& render, const CliOptions& cli, wp::RenderSettings& settings) {
  if (render.count("--samples") == 0) return;
  const std::string& text = cli.samples;
  const auto bad = [&] {
    return wp::Error("--samples " + text +
                     ": expected A:B with 0 <= A < B <= " + std::to_string(WP_FILM_MAX_SAMPLES));
  };
  const std::size_t colon = text.find(':');
  if (colon == std::string::npos) throw bad();
  const auto whole = [&](const std::string& digits) {
    if (digits.empty() || digits.size() > 8 ||
        digits.find_first_not_of("0123456789") != std::string::npos)
      throw bad();
    return std::stoi(digits);
  };
  const int begin = whole(text.substr(0, colon)), end = whole(text.substr(colon + 1));
  if (!(begin < end && end <= int(WP_FILM_MAX_SAMPLES))) throw bad();
  if (render.count("--spp") && !(begin == 0 && end == settings.spp))
    throw wp::Error("--spp " + std::to_string(settings.spp) + " and --samples " + text +
                    " disagree (--spp N means --samples 0:N); give one of them");
  settings.sample_begin = begin;
  settings.spp = end - begin;
}

const std::vector<std::string> kAovNames = {"albedo", "normal", "depth"};

// The PNG output's options, the same for render and merge.
void add_png_options(CLI::App* app, CliOptions& cli) {
  app->add_option("--tonemap", cli.tonemap, "PNG tonemap: aces or clamp")
      ->check(CLI::IsMember({"aces", "clamp"}))
      ->capture_default_str();
  app->add_option("--exposure", cli.exposure, "PNG exposure in stops")->capture_default_str();
}

void check_exposure(const CliOptions& cli) {
  if (!std::isfinite(cli.exposure) || std::abs(cli.exposure) > 64.0f)
    throw wp::Error("--exposure must be a finite number of stops between -64 and 64");
}

// Ranges CLI11 cannot express and wp::validate (render.h) does not cover: these are the command
// line's own, so they are checked here, before anything is loaded.
void check_options(const CLI::App& render, const CliOptions& cli,
                   const wp::RenderSettings& settings) {
  const auto check = [](bool ok, const std::string& what) {
    if (!ok) throw wp::Error(what);
  };
  // -1 is the internal "not given" value; a user who types it means a camera that cannot exist.
  check(render.count("--camera") == 0 || settings.camera >= 0,
        "--camera " + std::to_string(settings.camera) + ": camera indices start at 0");
  check_exposure(cli);
  check(settings.spp <= (1 << 20), "--spp must be at most 1048576");
  check(settings.wave_size <= (std::size_t{1} << 24), "--wave-size must be at most 16777216");
  check(settings.local_size <= 1024, "--local-size must be at most 1024");
  const auto seconds = [&](double v, const char* name) {
    check(std::isfinite(v) && v >= 0 && v <= 1e9,
          std::string(name) + " must be a number of seconds between 0 and 1e9");
  };
  seconds(cli.time_limit, "--time-limit");
  seconds(cli.checkpoint_every, "--checkpoint-every");
  seconds(cli.progress_every, "--progress-every");
  check(std::isfinite(cli.noise_threshold) && cli.noise_threshold >= 0,
        "--noise-threshold must be a relative error >= 0 (e.g. 0.01 for 1%)");
  check(render.count("--checkpoint-every") == 0 || !cli.checkpoint.empty(),
        "--checkpoint-every needs --checkpoint FILE");
  check(cli.checkpoint.empty() || is_film(cli.checkpoint),
        "--checkpoint " + cli.checkpoint + ": a checkpoint is a .wpfilm file");
  check(render.count("--scene-buffer-kib") == 0 ||
            (cli.scene_buffer_kib >= 1 && cli.scene_buffer_kib <= (std::uint64_t{1} << 25)),
        "--scene-buffer-kib must be between 1 and 33554432 (32 GiB)");
}

// Progress of the sample passes on stderr: on a terminal a bar redrawn after every pass; else
// (a log) one line every `every` seconds. Both give the samples done and requested, the time,
// the ETA (at the pass rate so far; no later than a time limit) and the pixel samples per second.
class Progress {
 public:
  Progress(bool enabled, bool terminal, double every, double pixels,
           std::optional<std::chrono::steady_clock::time_point> deadline)
      : enabled_(enabled),
        terminal_(terminal),
        every_(every),
        pixels_(pixels),
        deadline_(deadline),
        next_line_(every) {}

  void update(int done, int total, double seconds, int passes) {
    if (!enabled_ || (!terminal_ && seconds < next_line_)) return;
    const double rate = seconds > 0 ? passes / seconds : 0.0;  // passes per second
    double eta = rate > 0 ? (total - done) / rate : 0.0;
    if (deadline_)
      eta = std::min(
          eta,
          std::max(0.0, std::chrono::duration<double>(*deadline_ - std::chrono::steady_clock::now())
                            .count()));
    const double fraction = double(done) / total;
    if (terminal_) {
      char bar[21];
      const int full = static_cast<int>(fraction * 20);
      for (int i = 0; i < 20; ++i) bar[i] = i < full ? '#' : '.';
      bar[20] = 0;
      std::fprintf(stderr, "\r  [%s] %d/%d spp %5.1f%%  %6.1f s  ETA %6.1f s  %.3g samples/s ", bar,
                   done, total, 100.0 * fraction, seconds, eta, rate * pixels_);
      drawn_ = true;
    } else {
      std::fprintf(stderr, "wavepath: %d/%d spp (%.1f%%), %.1f s, ETA %.1f s, %.3g samples/s\n",
                   done, total, 100.0 * fraction, seconds, eta, rate * pixels_);
      if (every_ > 0)  // 0: a line after every pass
        while (next_line_ <= seconds) next_line_ += every_;
    }
    std::fflush(stderr);
  }
  // Ends the terminal's bar line, if one was drawn.
  void finish() {
    if (drawn_) std::fprintf(stderr, "\n");
    drawn_ = false;
  }

 private:
  bool enabled_, terminal_;
  double every_, pixels_;
  std::optional<std::chrono::steady_clock::time_point> deadline_;
  double next_line_;
  bool drawn_ = false;
};

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

// Writes every output as one set (image_io.h, write_files): images by extension from `film`'s
// mean, with the layers asked for (--variance, --aov), and .wpfilm files from `film` itself.
void write_outputs(const CliOptions& cli, const wp::Film& film,
                   const std::map<std::string, std::string>& exr_attributes) {
  wp::PngOptions png;
  png.exposure = cli.exposure;
  png.tonemap = cli.tonemap == "clamp" ? wp::Tonemap::kClamp : wp::Tonemap::kAces;
  std::vector<std::string> images;
  for (const auto& o : cli.outputs)
    if (!is_film(o)) images.push_back(o);
  wp::FilmImages film_images = film.images();
  const wp::ImageRgb image{film.info().width, film.info().height, std::move(film_images.mean)};
  std::vector<wp::ImageLayer> layers;
  if (cli.variance)
    layers.push_back({"variance", {"R", "G", "B"}, std::move(film_images.variance)});
  for (const std::string& aov : cli.aovs) {  // in the order given
    if (!film.info().aov) throw wp::Error("--aov " + aov + ": the film holds no AOVs");
    if (aov == "albedo") layers.push_back({aov, {"R", "G", "B"}, film_images.albedo});
    if (aov == "normal") layers.push_back({aov, {"X", "Y", "Z"}, film_images.normal});
    if (aov == "depth") layers.push_back({aov, {"Z"}, film_images.depth});
  }
  std::vector<wp::OutputFile> files = wp::image_files(images, image, exr_attributes, png, layers);
  for (const auto& o : cli.outputs)
    if (is_film(o)) files.push_back({o, [&film](const std::string& temp) { film.write(temp); }});
  wp::write_files(files);
}

// The settings, checked before the scene is loaded: options, sample range, the environment map,
// and (on rank 0, which writes them) the outputs, so that a render that could not be saved fails
// before it starts.
void prepare_render(const CLI::App& render, CliOptions& cli, wp::RenderSettings& settings,
                    const wp::Ranks& ranks) {
  if (cli.outputs.empty()) cli.outputs = {"render.exr", "render.png"};
  if (ranks.root()) check_outputs(cli.outputs);
  apply_samples(render, cli, settings);
  check_options(render, cli, settings);
  if (ranks.size() > 1 && (cli.time_limit > 0 || cli.noise_threshold > 0 ||
                           !cli.checkpoint.empty() || !cli.resume.empty()))
    throw wp::Error(
        "--time-limit, --noise-threshold, --checkpoint and --resume do not work under MPI yet "
        "(the ranks would have to agree where each stops); render sample ranges (--samples) "
        "and merge them instead");
  if (!cli.checkpoint.empty()) check_outputs({cli.checkpoint});
  settings.background = {cli.env_color[0], cli.env_color[1], cli.env_color[2]};
  settings.all_features = cli.features == "all";
  settings.aov = !cli.aovs.empty();
  settings.scene_buffer_bytes = cli.scene_buffer_kib * 1024;
  settings.strategy = cli.strategy == "nee"    ? wp::Strategy::kNee
                      : cli.strategy == "bsdf" ? wp::Strategy::kBsdf
                                               : wp::Strategy::kMis;
  settings.mis_heuristic =
      cli.heuristic == "balance" ? wp::MisHeuristic::kBalance : wp::MisHeuristic::kPower;
  settings.light_select =
      cli.light_select == "uniform" ? wp::LightSelect::kUniform : wp::LightSelect::kPower;
  settings.sampler = cli.sampler == "independent"    ? wp::Sampler::kIndependent
                     : cli.sampler == "sobol-padded" ? wp::Sampler::kSobolPadded
                                                     : wp::Sampler::kSobol;
  settings.fused = cli.pipeline == "fused";
  settings.prefetch = !cli.no_prefetch;
  if (!cli.no_kernel_cache) settings.kernel_cache_dir = wp::cache_dir();
  if (cli.no_rr) settings.rr_depth = std::numeric_limits<int>::max();
  wp::validate(settings);
  if (!cli.env.empty())
    settings.environment = std::make_shared<wp::EnvironmentMap>(wp::load_environment(cli.env));
}

// This process's share of the render: its slice of the samples (all of them without MPI)
// rendered on its device. None when an MPI job has more ranks than samples.
struct RenderPart {
  std::optional<wp::Rendered> result;
  double load_seconds = 0;
  int stop_signal = 0;  // the signal that ended the passes early (stop_signals.h), or 0
};

RenderPart render_part(const CliOptions& cli, const wp::RenderSettings& settings,
                       const wp::Ranks& ranks,
                       std::chrono::steady_clock::time_point program_start) {
  const auto start = std::chrono::steady_clock::now();
  RenderPart part;
  const wp::Ranks::Slice slice = ranks.slice(settings.sample_begin, settings.spp);
  if (slice.samples == 0) return part;
  wp::RenderSettings mine = settings;
  mine.sample_begin = slice.first;
  mine.spp = slice.samples;
  // Read whole before loading the scene (a bad file fails at once) and before rendering (it may
  // be the --checkpoint file, which the render replaces).
  std::optional<wp::Film> resume;
  if (!cli.resume.empty()) resume = wp::Film::read(cli.resume);
  const wp::Scene scene = wp::load_gltf(cli.scene);
  // Known now, not only once the kernels are built and the BVH is made.
  if (mine.camera >= 0 && static_cast<std::size_t>(mine.camera) >= scene.cameras.size())
    throw wp::Error("--camera " + std::to_string(mine.camera) + ": the scene has " +
                    std::to_string(scene.cameras.size()) + " camera(s)");
  part.load_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!cli.quiet && ranks.root())
    for (const auto& w : scene.warnings) std::fprintf(stderr, "wavepath: warning: %s\n", w.c_str());

  // Ranks on one machine spread over its devices, unless --device names one.
  wp::ClRuntime runtime(wp::select_device(cli.device, ranks.local_rank()));
  wp::RenderOptions options;
  options.bvh.spatial_splits = cli.spatial_splits;
  options.bvh_cache = !cli.no_bvh_cache;
  if (cli.time_limit > 0)
    options.deadline = program_start + std::chrono::duration_cast<std::chrono::nanoseconds>(
                                           std::chrono::duration<double>(cli.time_limit));
  options.noise_threshold = cli.noise_threshold;
  if (resume) options.resume = &*resume;
  // Rank 0's passes stand for the job's: the ranks render at about the same pace.
  Progress progress(!cli.quiet && ranks.root(), isatty(STDERR_FILENO), cli.progress_every,
                    double(settings.width) * settings.height, options.deadline);
  options.progress = [&](int done, int total, double seconds, int passes) {
    progress.update(done, total, seconds, passes);
  };
  if (!cli.checkpoint.empty()) {
    options.checkpoint_every = cli.checkpoint_every;
    options.checkpoint = [&](const wp::Film& film) {
      // Signals are only recorded meanwhile (StopSignals): the checkpoint is always completed.
      wp::write_files({{cli.checkpoint, [&film](const std::string& t) { film.write(t); }}},
                      /*signals_remove_and_exit=*/false);
    };
  }
  // Alone, a signal while the passes run stops them after the current one (stop_signals.h); in
  // an MPI job it ends the job, as every rank has to render its whole slice.
  std::optional<wp::StopSignals> signals;
  if (ranks.size() == 1) {
    signals.emplace();
    options.passes_starting = [&] { signals->arm(); };
    options.interrupted = [&] { return signals->received() != 0; };
  }
  part.result = wp::render(runtime, scene, mine, options);
  progress.finish();
  if (signals) part.stop_signal = signals->received();
  // From here (signals destroyed) a signal removes the outputs' temporary files and ends wavepath.
  return part;
}

// The message main() prints for an exception: one line, then the details (wp::Error's) if any.
std::pair<std::string, std::string> describe(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const wp::Error& e) {
    return {e.what(), e.details()};
  } catch (const cl::Error& e) {
    return {std::string("OpenCL: ") + e.what() + " failed with " + wp::cl_error_name(e.err()), ""};
  } catch (const std::exception& e) {
    return {e.what(), ""};
  } catch (...) {
    return {"unknown exception", ""};
  }
}

int render_command(const CLI::App& render, CliOptions& cli, wp::RenderSettings& settings,
                   std::chrono::steady_clock::time_point program_start) {
  const auto start = std::chrono::steady_clock::now();
  // One rank of one, unless started by mpirun (host/cli/distributed.h).
  const wp::Ranks ranks;
  // In an MPI job every rank reaches ranks.reduce, whatever fails where, so that none waits for
  // ever: a failure is kept in `mine` and the steps after it are skipped. Alone, it is thrown.
  wp::RankPart mine;
  RenderPart part;
  const auto attempt = [&](const auto& step) {
    if (!mine.error.empty()) return;
    try {
      step();
    } catch (...) {
      if (ranks.size() == 1) throw;
      std::tie(mine.error, mine.details) = describe(std::current_exception());
    }
  };
  attempt([&] { prepare_render(render, cli, settings, ranks); });
  // Options and outputs are agreed on before any rank spends time rendering.
  if (ranks.all(mine.error.empty()))
    attempt([&] { part = render_part(cli, settings, ranks, program_start); });
  if (part.result) {
    mine.film = std::move(part.result->film);
    mine.render_seconds = part.result->report.render_seconds;
    mine.rays = part.result->report.rays;
  }
  wp::Reduced all = ranks.reduce(std::move(mine));
  // The job's exit status is rank 0's: another rank's non-zero status would make mpirun kill the
  // job, maybe before rank 0 has printed why it failed.
  if (!ranks.root()) return 0;
  if (!all.ok) throw wp::Error(all.error, all.details);

  wp::Rendered& result = *part.result;
  result.film = std::move(all.film);
  if (ranks.size() > 1) {  // the report of every rank's samples
    result.report.render_seconds = all.render_seconds;
    result.report.rays = all.rays;
    result.report.nonfinite_samples = result.film.info().nonfinite_samples;
    result.report.device = result.film.info().device;
  }
  result.report.ranks = ranks.size();

  auto attributes = wp::exr_attributes(cli.scene, settings, result.report);
  attributes["wavepath:render_key"] = result.film.info().key;
  write_outputs(cli, result.film, attributes);
  const double total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (result.report.nonfinite_samples > 0)
    std::fprintf(stderr, "wavepath: warning: %llu NaN/Inf samples were left out of the film\n",
                 static_cast<unsigned long long>(result.report.nonfinite_samples));
  const int done = int(result.report.sample_end) - settings.sample_begin;
  if (cli.json)
    std::cout << wp::report_json(settings, result.report, part.load_seconds, total, cli.outputs)
              << "\n";
  else if (!cli.quiet)
    std::fprintf(stderr,
                 "wavepath: %s: %d spp (samples %d:%u, %s) in %.2f s (%.3g samples/s) on %s; "
                 "wrote %s\n",
                 cli.scene.c_str(), done, settings.sample_begin, result.report.sample_end,
                 wp::stop_reason_name(result.report.stop), result.report.render_seconds,
                 result.report.samples_per_second(settings), result.report.device.c_str(),
                 join(cli.outputs).c_str());
  if (const int stop_signal = part.stop_signal) {  // said even with --quiet: the exit status alone
                                                   // would not say what is kept
    std::fprintf(stderr, "wavepath: interrupted by %s after %d of %d samples; wrote %s%s\n",
                 wp::signal_name(stop_signal), done, settings.spp, join(cli.outputs).c_str(),
                 cli.checkpoint.empty() ? ""
                                        : ("; the checkpoint " + cli.checkpoint +
                                           " continues with --resume " + cli.checkpoint)
                                              .c_str());
    return 128 + stop_signal;
  }
  return 0;
}

// `wavepath merge`: films of one render's sample ranges, in any order, into one. Every part is
// read and checked (Film::read_info: without keeping its data) before anything is added or
// written: the same render key and size as the first part's, and ranges that neither overlap nor
// leave a gap (once sorted). Then the films are read again and added one at a time, in sample
// order, so that at most two are in memory.
int merge_command(CliOptions& cli) {
  check_outputs(cli.outputs);
  std::vector<wp::FilmInfo> parts;
  for (const auto& part : cli.parts) parts.push_back(wp::Film::read_info(part));
  for (std::size_t i = 1; i < parts.size(); ++i) {
    const std::string problem = wp::film_identity_problem(parts[0], parts[i]);
    if (!problem.empty())
      throw wp::Error(cli.parts[i] + " does not merge with " + cli.parts[0] + ": " + problem);
  }
  std::vector<std::size_t> order(parts.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return parts[a].sample_begin < parts[b].sample_begin;
  });
  for (std::size_t k = 1; k < order.size(); ++k) {
    const std::string problem = wp::film_merge_problem(parts[order[k - 1]], parts[order[k]]);
    if (!problem.empty())
      throw wp::Error(cli.parts[order[k - 1]] + " and " + cli.parts[order[k]] +
                      " do not merge: " + problem);
  }
  wp::Film merged = wp::Film::read(cli.parts[order[0]]);
  for (std::size_t k = 1; k < order.size(); ++k) {
    const std::string& part = cli.parts[order[k]];
    try {  // the file may have changed since its header was checked
      merged.add(wp::Film::read(part));
    } catch (const wp::Error& e) {
      if (std::string(e.what()).rfind(part, 0) == 0) throw;
      throw wp::Error(part + ": " + e.what());
    }
  }
  const wp::FilmInfo& info = merged.info();
  write_outputs(cli, merged, wp::film_exr_attributes(info));
  if (cli.json) {
    std::cout << "{\"parts\":" << parts.size() << ",\"spp\":" << info.samples()
              << ",\"sample_begin\":" << info.sample_begin << ",\"sample_end\":" << info.sample_end
              << ",\"width\":" << info.width << ",\"height\":" << info.height
              << ",\"device\":" << wp::json_string(info.device)
              << ",\"nonfinite_samples\":" << info.nonfinite_samples << ",\"outputs\":[";
    for (std::size_t i = 0; i < cli.outputs.size(); ++i)
      std::cout << (i ? "," : "") << wp::json_string(cli.outputs[i]);
    std::cout << "]}\n";
  } else if (!cli.quiet) {
    std::fprintf(stderr, "wavepath: merged %zu film(s): samples %u:%u, %dx%d; wrote %s\n",
                 parts.size(), info.sample_begin, info.sample_end, info.width, info.height,
                 cli.outputs.front().c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const auto program_start = std::chrono::steady_clock::now();  // --time-limit counts from here
  CLI::App app{"wavepath: an OpenCL wavefront path tracer for glTF 2.0 scenes", "wavepath"};
  app.require_subcommand(1);
  // Parse errors in one line, like every other error.
  app.failure_message([](const CLI::App*, const CLI::Error& e) {
    std::string what = e.what();
    std::replace(what.begin(), what.end(), '\n', ' ');
    return "wavepath: error: " + what + " (see --help)\n";
  });
  app.set_version_flag("--version", "wavepath 0.1.0");
  CLI::App* devices = app.add_subcommand("devices", "List OpenCL platforms and devices");

  CliOptions cli;
  wp::RenderSettings settings;
  CLI::App* render = app.add_subcommand("render", "Render a glTF scene to OpenEXR and/or PNG");
  render->add_option("scene", cli.scene, "glTF 2.0 file (.gltf or .glb)")->required();
  render->add_option("-o,--output", cli.outputs,
                     "Output file(s): .exr = linear float RGB with the settings in its header, "
                     ".png = 8-bit sRGB preview, .pfm = linear float RGB (Portable FloatMap), "
                     ".wpfilm = the film's exact sums, to merge with other sample ranges "
                     "(wavepath merge) [default: render.exr render.png]");
  render->add_option("--width", settings.width, "Image width in pixels")->capture_default_str();
  render->add_option("--height", settings.height, "Image height in pixels")->capture_default_str();
  render->add_option("--spp", settings.spp, "Samples per pixel (the same as --samples 0:N)")
      ->capture_default_str();
  render->add_option("--samples", cli.samples,
                     "Render only sample indices A to B-1 (0 <= A < B <= 1048576), a part of a "
                     "longer render: its .wpfilm output merges exactly with the other parts' "
                     "(wavepath merge); the image is the mean of these samples [default: 0:spp]");
  render->add_option("--time-limit", cli.time_limit,
                     "Stop starting sample passes once SECONDS have passed since wavepath started "
                     "(loading and building count): a pass is only started if, at the mean pass "
                     "time so far, it ends in time; at least one pass is rendered. The image "
                     "holds the samples done (JSON and EXR header: spp, stop) [default: none]");
  render->add_option("--noise-threshold", cli.noise_threshold,
                     "Stop once the image's estimated relative error (root mean over pixels of "
                     "variance / value^2, see README) is at most REL, e.g. 0.01; checked from 16 "
                     "samples on [default: none]");
  render->add_option("--checkpoint", cli.checkpoint,
                     "Keep the film so far in FILE (.wpfilm), written atomically every "
                     "--checkpoint-every seconds, when the passes end, and on SIGINT/SIGTERM/"
                     "SIGHUP (which stop the render after the current pass, write every output "
                     "with the samples so far and exit with 128 + the signal number)");
  render
      ->add_option("--checkpoint-every", cli.checkpoint_every,
                   "Seconds between checkpoints (0: after every pass)")
      ->capture_default_str();
  render->add_option("--resume", cli.resume,
                     "Continue the film in FILE (a checkpoint of the same scene and settings, "
                     "from the same first sample) up to the requested samples: the result is "
                     "bit-identical to one uninterrupted render");
  render
      ->add_option("--progress-every", cli.progress_every,
                   "When stderr is not a terminal (a log), a progress line every SECONDS (0: "
                   "after every pass); on a terminal a bar is redrawn after every pass")
      ->capture_default_str();
  render->add_option("--camera", settings.camera,
                     "Camera index in node order [default: the first, else one framing the scene]");
  render
      ->add_option("--env-color", cli.env_color,
                   "Constant background radiance R,G,B (linear) [default: 0,0,0]")
      ->delimiter(',')
      ->expected(3);
  render->add_option("--env", cli.env,
                     "Environment map: equirectangular .hdr or .exr, linear radiance; the centre "
                     "of the map is seen looking down -Z, +Y is up");
  render->add_option("--env-intensity", settings.env_intensity, "Scale of the environment map")
      ->capture_default_str();
  render
      ->add_option("--env-rotation", settings.env_rotation,
                   "Rotation of the environment map about +Y, degrees")
      ->capture_default_str();
  render
      ->add_option("--strategy", cli.strategy,
                   "Direct light: mis (NEE and BSDF sampling, MIS-weighted), nee (light "
                   "sampling only), bsdf (BSDF sampling only; punctual lights then add nothing)")
      ->check(CLI::IsMember({"mis", "nee", "bsdf"}))
      ->capture_default_str();
  render->add_option("--mis-heuristic", cli.heuristic, "MIS weights: power (beta 2) or balance")
      ->check(CLI::IsMember({"power", "balance"}))
      ->capture_default_str();
  render
      ->add_option("--light-select", cli.light_select,
                   "How NEE picks a light: power (proportional to estimated power) or uniform")
      ->check(CLI::IsMember({"power", "uniform"}))
      ->capture_default_str();
  render
      ->add_option("--sampler", cli.sampler,
                   "Sample pattern: sobol (Owen-scrambled Sobol' points per pixel: less error "
                   "for the same samples; the light and BSDF samples of successive bounces "
                   "stratified together), sobol-padded (the same points, every group of numbers "
                   "in an order of its own) or independent (a hash per random number)")
      ->check(CLI::IsMember({"sobol", "sobol-padded", "independent"}))
      ->capture_default_str();
  render
      ->add_option("--pipeline", cli.pipeline,
                   "fused (one kernel per bounce for all the work at a hit) or split (a kernel "
                   "per stage, for kernel work and per-stage timing); the same image bit for bit")
      ->check(CLI::IsMember({"fused", "split"}))
      ->capture_default_str();
  render->add_option("--max-depth", settings.max_depth, "Most scattering events per path")
      ->capture_default_str();
  render
      ->add_option("--rr-depth", settings.rr_depth,
                   "Russian roulette after this many scattering events")
      ->capture_default_str();
  render
      ->add_option("--rr-threshold", settings.rr_threshold,
                   "Russian roulette ends a path whose throughput (largest channel) m is below "
                   "this with probability 1 - m / threshold, and a survivor carries the "
                   "threshold; 1 gives pbrt's rule (survival probability = throughput)")
      ->capture_default_str();
  render->add_flag("--no-rr", cli.no_rr, "No Russian roulette (paths end only at --max-depth)");
  render->add_option("--seed", settings.seed, "Random seed (same seed, same image)")
      ->capture_default_str();
  render->add_option("--device", cli.device,
                     "OpenCL device: index or name substring (see `wavepath devices`) "
                     "[default: first GPU, else first CPU]");
  render
      ->add_option("--features", cli.features,
                   "Kernel specialisation: `scene` (only what the scene uses) or `all`")
      ->check(CLI::IsMember({"scene", "all"}))
      ->capture_default_str();
  add_png_options(render, cli);
  render->add_flag("--spatial-splits", cli.spatial_splits,
                   "Build the BVH with spatial splits (slower build, faster traversal)");
  render->add_option("--wave-size", settings.wave_size, "Path slots per wave [default: auto]");
  render->add_option("--bvh-width", settings.bvh_width,
                     "BVH layout: 2 (binary) or 8 (wide, float8 box tests) [default: 2 on GPUs, "
                     "8 on CPUs]");
  render->add_option("--local-size", settings.local_size, "Work-group size [default: 64]");
  render->add_flag("--no-prefetch", cli.no_prefetch,
                   "No cache hints for the path state (on by default on PoCL's CPU devices, "
                   "where they made renders 3-8% faster; the same image either way)");
  render->add_option("--scene-buffer-kib", cli.scene_buffer_kib,
                     "Most KiB per scene buffer; the scene is split over up to 8 [default: the "
                     "device's largest allocation, see `wavepath devices`]");
  render->add_flag("--no-bvh-cache", cli.no_bvh_cache,
                   "Build the BVH afresh; by default it is looked up in and stored to "
                   "$WAVEPATH_CACHE_DIR, else $XDG_CACHE_HOME/wavepath, else ~/.cache/wavepath");
  render->add_flag("--no-kernel-cache", cli.no_kernel_cache,
                   "Build the kernels from source; by default the built program is looked up in "
                   "and stored to the BVH cache's folder (~25 ms less start-up on PoCL)");
  render->add_flag("--variance", cli.variance,
                   "Also write the variance of each pixel's estimate (sample variance / spp): the "
                   "layer variance.R/G/B in EXR output, X.variance.pfm beside X.pfm");
  render
      ->add_option("--aov", cli.aovs,
                   "Also write these of the first surface that is not a perfect mirror or smooth "
                   "glass, averaged over the pixel's samples (comma-separated): albedo (base "
                   "colour; the background's for a miss), normal (world-space shading normal on "
                   "the camera's side, not renormalised), depth (metres from the camera to the "
                   "first hit, 0 for a miss): EXR layers albedo.R/G/B, normal.X/Y/Z, depth.Z; "
                   "X.albedo.pfm etc. beside X.pfm; kept in .wpfilm outputs")
      ->delimiter(',')
      ->check(CLI::IsMember(kAovNames));
  render->add_flag("--profile", settings.profile, "Time each kernel (adds stage times to --json)");
  render->add_flag("--json", cli.json,
                   "Print a JSON summary as the last line of stdout (spp, sample_begin, "
                   "sample_end, width, height, seconds, samples_per_second, device, triangles, "
                   "kernel_build_seconds, bvh_build_seconds, ...)");
  render->add_flag("-q,--quiet", cli.quiet, "No progress or warnings on stderr");

  CLI::App* merge = app.add_subcommand(
      "merge",
      "Merge .wpfilm films of one render's sample ranges (any order) into one film or image");
  merge
      ->add_option("films", cli.parts,
                   ".wpfilm files of the same render (scene and settings) and size whose sample "
                   "ranges (--samples) together form one range, without overlaps or gaps")
      ->required();
  merge
      ->add_option("-o,--output", cli.outputs,
                   "Output file(s): .exr, .png, .pfm (the merged image) and/or .wpfilm (the merged "
                   "film)")
      ->required();
  add_png_options(merge, cli);
  merge->add_flag("--variance", cli.variance,
                  "Also write the variance of each pixel's estimate (as render --variance)");
  merge
      ->add_option("--aov", cli.aovs,
                   "Also write these AOVs, which the films must hold (as render --aov)")
      ->delimiter(',')
      ->check(CLI::IsMember(kAovNames));
  merge->add_flag("--json", cli.json,
                  "Print a JSON summary (parts, spp, sample_begin, sample_end, width, height, "
                  "device, nonfinite_samples, outputs) as the last line of stdout");
  merge->add_flag("-q,--quiet", cli.quiet, "No summary on stderr");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // app.exit prints help and version (status 0) or the one-line error above; CLI11's own codes
    // (104, 106, ...) become 1, the status of every wavepath error.
    return app.exit(e) == 0 ? 0 : 1;
  }
  try {
    if (devices->parsed()) return list_devices();
    if (merge->parsed()) {
      check_exposure(cli);
      return merge_command(cli);
    }
    return render_command(*render, cli, settings, program_start);
  } catch (...) {
    const auto [message, details] = describe(std::current_exception());
    std::cerr << "wavepath: error: " << message << "\n";
    if (!details.empty()) std::cerr << details << "\n";
    return 1;
  }
}
