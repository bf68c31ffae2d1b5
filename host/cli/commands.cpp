#include "host/cli/commands.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <tuple>

#include "host/cli/progress.h"
#include "host/cli/stop_signals.h"
#include "host/device/cl_runtime.h"
#include "host/film/denoise.h"
#include "host/film/film.h"
#include "host/film/image_io.h"
#include "host/render/render.h"
#include "host/render/report_json.h"
#include "host/scene/gltf_loader.h"
#include "host/scene/view.h"
#include "host/util/error.h"

namespace wp::cli {

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

namespace {

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

// Writes every output as one set (image_io.h, write_files): images by extension from `film`'s
// mean (film_images: film.images(), which a render has made already), with the layers asked for
// (--variance, --aov), .wpfilm files from `film` itself, and with `denoiser` (--denoise) the
// denoised image beside each image output (its EXR without layers). The denoising runs before
// anything is written: an OIDN error leaves no output.
void write_outputs(const CliOptions& cli, const wp::Film& film, wp::FilmImages film_images,
                   const std::map<std::string, std::string>& exr_attributes,
                   const wp::Denoiser* denoiser) {
  wp::PngOptions png;
  png.exposure = cli.exposure;
  png.tonemap = wp::tonemap_from_name(cli.tonemap);
  std::vector<std::string> images;
  for (const auto& o : cli.outputs)
    if (!is_film(o)) images.push_back(o);
  const wp::ImageRgb image{film.info().width, film.info().height, std::move(film_images.mean)};
  std::vector<wp::ImageLayer> layers;
  if (cli.variance)
    layers.push_back({"variance", {"R", "G", "B"}, std::move(film_images.variance)});
  const auto no_aovs = [](const std::string& what) {
    return wp::Error(what + ": the film holds no AOVs (render it with --denoise or --aov)");
  };
  for (const std::string& aov : cli.aovs) {  // in the order given
    if (!film.info().aov) throw no_aovs("--aov " + aov);
    if (aov == "albedo") layers.push_back({aov, {"R", "G", "B"}, film_images.albedo});
    if (aov == "normal") layers.push_back({aov, {"X", "Y", "Z"}, film_images.normal});
    if (aov == "depth") layers.push_back({aov, {"Z"}, film_images.depth});
  }
  std::vector<wp::OutputFile> files = wp::image_files(images, image, exr_attributes, png, layers);
  // With a denoiser: the denoised image and what its files refer to until write_files is done.
  wp::ImageRgb denoised;
  std::vector<std::string> denoised_paths;
  const std::vector<wp::ImageLayer> no_layers;
  std::map<std::string, std::string> denoised_attributes = exr_attributes;
  if (denoiser && !images.empty()) {
    if (!film.info().aov) throw no_aovs("--denoise");
    denoised = {image.width, image.height,
                denoiser->denoise(image.width, image.height, image.rgb, film_images.albedo,
                                  film_images.normal)};
    for (const auto& o : images) denoised_paths.push_back(wp::denoised_path(o));
    denoised_attributes["wavepath:denoiser"] =
        denoiser->description() + ": RT filter, hdr, prefiltered albedo and normal, cleanAux";
    for (auto& f : wp::image_files(denoised_paths, denoised, denoised_attributes, png, no_layers))
      files.push_back(std::move(f));
  }
  for (const auto& o : cli.outputs)
    if (is_film(o)) files.push_back({o, [&film](const std::string& temp) { film.write(temp); }});
  wp::write_files(files);
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
  wp::RenderOptions options;
  if (cli.time_limit > 0)
    options.deadline = program_start + std::chrono::duration_cast<std::chrono::nanoseconds>(
                                           std::chrono::duration<double>(cli.time_limit));
  // Rank 0's passes stand for the job's: the ranks render at about the same pace.
  Progress progress(!cli.quiet && ranks.root(), isatty(STDERR_FILENO), cli.progress_every,
                    double(settings.width) * settings.height, options.deadline);
  // Read whole before loading the scene (a bad file fails at once) and before rendering (it may
  // be the --checkpoint file, which the render replaces).
  std::optional<wp::Film> resume;
  if (!cli.resume.empty()) resume = wp::Film::read(cli.resume);
  // Ranks on one machine spread over its devices, unless --device names one. The device is known
  // before the scene loads, so that a scene it cannot hold is refused from its counts.
  const wp::DeviceEntry device = wp::select_device(cli.device, ranks.local_rank());
  wp::LoadOptions load{cli.variant};
  load.instancing = wp::cli::instancing_mode(cli.instancing);
  load.check_counts = [&](const wp::LoadCounts& counts) {
    wp::check_scene_counts(counts, device, mine);
  };
  progress.step("loading " + cli.scene);
  wp::Scene scene = wp::load_gltf(cli.scene, load);
  // A camera the scene cannot give (an index past its cameras, a lens on an orthographic one, a
  // focus behind it) is known now, not only once the kernels are built and the BVH is made.
  (void)wp::choose_camera(scene, mine.camera, mine.view, float(mine.width) / float(mine.height));
  part.load_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!cli.quiet && ranks.root() && !scene.warnings.empty()) {
    progress.clear();
    for (const auto& w : scene.warnings) std::fprintf(stderr, "wavepath: warning: %s\n", w.c_str());
  }

  progress.step("starting " + device.name);
  wp::ClRuntime runtime(device);
  options.bvh.spatial_splits = cli.spatial_splits;
  options.bvh_cache = !cli.no_bvh_cache;
  options.noise_threshold = cli.noise_threshold;
  if (resume) options.resume = &*resume;
  options.setup_step = [&](const std::string& what) { progress.step(what); };
  options.progress = [&](int done, int total, double seconds, int rendered) {
    progress.update(done, total, seconds, rendered);
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
  // The scene is not read after: its arrays are freed as they are packed (one copy of them).
  part.result = wp::render(runtime, std::move(scene), mine, options);
  progress.finish();
  if (signals) part.stop_signal = signals->received();
  // From here (signals destroyed) a signal removes the outputs' temporary files and ends wavepath.
  return part;
}

// After the outputs are written: the warnings, the summary (JSON or a line on stderr) and the exit
// status, 128 + the signal that stopped the passes when one did.
int finish_render(const CliOptions& cli, const wp::RenderSettings& settings,
                  const wp::RenderReport& report, const RenderPart& part, double total_seconds) {
  if (report.nonfinite_samples > 0)
    std::fprintf(stderr, "wavepath: warning: %llu NaN/Inf samples were left out of the film\n",
                 static_cast<unsigned long long>(report.nonfinite_samples));
  const int done = int(report.sample_end) - settings.sample_begin;
  if (cli.json)
    std::cout << wp::report_json(settings, report, part.load_seconds, total_seconds,
                                 written_files(cli))
              << "\n";
  else if (!cli.quiet)
    std::fprintf(stderr,
                 "wavepath: %s: %d spp (samples %d:%u, %s) in %.2f s (%.3g samples/s) on %s; "
                 "wrote %s\n",
                 cli.scene.c_str(), done, settings.sample_begin, report.sample_end,
                 wp::stop_reason_name(report.stop), report.render_seconds,
                 report.samples_per_second(settings), report.device.c_str(),
                 join(written_files(cli)).c_str());
  if (const int stop_signal = part.stop_signal) {  // said even with --quiet: the exit status alone
                                                   // would not say what is kept
    std::fprintf(stderr, "wavepath: interrupted by %s after %d of %d samples; wrote %s%s\n",
                 wp::signal_name(stop_signal), done, settings.spp, join(written_files(cli)).c_str(),
                 cli.checkpoint.empty() ? ""
                                        : ("; the checkpoint " + cli.checkpoint +
                                           " continues with --resume " + cli.checkpoint)
                                              .c_str());
    return 128 + stop_signal;
  }
  return 0;
}

}  // namespace

std::pair<std::string, std::string> describe(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const wp::Error& e) {
    return {e.what(), e.details()};
  } catch (const cl::Error& e) {
    return {std::string("OpenCL: ") + e.what() + " failed with " + wp::cl_error_name(e.err()), ""};
  } catch (const std::bad_alloc&) {
    return {"out of memory (an allocation failed)", ""};
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
  std::optional<wp::Denoiser> denoiser;  // rank 0's, which writes the outputs
  const auto attempt = [&](const auto& step) {
    if (!mine.error.empty()) return;
    try {
      step();
    } catch (...) {
      if (ranks.size() == 1) throw;
      std::tie(mine.error, mine.details) = describe(std::current_exception());
    }
  };
  attempt([&] {
    prepare_render(render, cli, settings, ranks);
    if (cli.denoise && ranks.root()) denoiser = wp::Denoiser::load();  // fails before rendering
  });
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
    result.report.samples_rendered = result.film.info().samples();  // MPI: no resume
    result.report.nonfinite_samples = result.film.info().nonfinite_samples;
    result.report.device = result.film.info().device;
  }
  result.report.ranks = ranks.size();
  auto attributes = wp::exr_attributes(cli.scene, settings, result.report);
  attributes["wavepath:render_key"] = result.film.info().key;
  if (!cli.variant.empty()) attributes["wavepath:variant"] = cli.variant;
  // One rank's film is the render's, whose mean and variance render() has made already (the
  // same function of the same sums); merged films and AOVs need theirs.
  wp::FilmImages images;
  if (ranks.size() == 1 && !result.film.info().aov) {
    images.mean = std::move(result.image.rgb);
    images.variance = std::move(result.variance.rgb);
  } else {
    images = result.film.images();
  }
  write_outputs(cli, result.film, std::move(images), attributes, denoiser ? &*denoiser : nullptr);
  const double total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return finish_render(cli, settings, result.report, part, total);
}

int merge_command(CliOptions& cli) {
  check_outputs(written_files(cli));
  std::optional<wp::Denoiser> denoiser;
  if (cli.denoise) denoiser = wp::Denoiser::load();
  std::vector<wp::FilmInfo> parts;
  for (const auto& part : cli.parts) parts.push_back(wp::Film::read_info(part));
  if (cli.denoise && !parts[0].aov)
    throw wp::Error("--denoise: " + cli.parts[0] +
                    " holds no AOVs (render the parts with --denoise or --aov)");
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
  write_outputs(cli, merged, merged.images(), wp::film_exr_attributes(info),
                denoiser ? &*denoiser : nullptr);
  if (cli.json) {
    std::cout << "{\"parts\":" << parts.size() << ",\"spp\":" << info.samples()
              << ",\"sample_begin\":" << info.sample_begin << ",\"sample_end\":" << info.sample_end
              << ",\"width\":" << info.width << ",\"height\":" << info.height
              << ",\"device\":" << wp::json_string(info.device)
              << ",\"nonfinite_samples\":" << info.nonfinite_samples << ",\"outputs\":[";
    const std::vector<std::string> written = written_files(cli);
    for (std::size_t i = 0; i < written.size(); ++i)
      std::cout << (i ? "," : "") << wp::json_string(written[i]);
    std::cout << "]}\n";
  } else if (!cli.quiet) {
    std::fprintf(stderr, "wavepath: merged %zu film(s): samples %u:%u, %dx%d; wrote %s\n",
                 parts.size(), info.sample_begin, info.sample_end, info.width, info.height,
                 cli.outputs.front().c_str());
  }
  return 0;
}

}  // namespace wp::cli
