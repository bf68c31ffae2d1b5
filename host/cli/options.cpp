#include "host/cli/options.h"

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>

#include "host/film/denoise.h"
#include "host/film/image_io.h"
#include "host/lights/environment.h"
#include "host/render/render.h"
#include "host/util/error.h"
#include "host/util/files.h"

namespace wp::cli {

const std::vector<std::string> kAovNames = {"albedo", "normal", "depth"};

using wp::extension_of;

bool is_film(const std::string& path) {
  return extension_of(path) == ".wpfilm";
}

void check_outputs(const std::vector<std::string>& outputs) {
  for (const auto& o : outputs) {
    const std::filesystem::path p(o);
    const std::string ext = extension_of(o);
    if (ext != ".exr" && ext != ".png" && ext != ".pfm" && ext != ".wpfilm")
      throw wp::Error(o + ": unsupported output format (use .exr, .png, .pfm or .wpfilm)");
    std::error_code ec;
    const auto status = std::filesystem::symlink_status(p, ec);
    if (std::filesystem::is_directory(status)) throw wp::Error(o + ": is a directory");
    wp::check_output_folder(o);  // by creating a file there: access(2) says yes to root
    if (std::filesystem::exists(status) && access(p.c_str(), W_OK) != 0)
      throw wp::Error(o + ": the existing file is not writable (" + std::strerror(errno) + ")");
  }
}

namespace {

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

// The PNG output's options, the same for render and merge.
void add_png_options(CLI::App* app, CliOptions& cli) {
  app->add_option("--tonemap", cli.tonemap,
                  "PNG tonemap: aces (Narkowicz's per-channel ACES fit), agx (three.js's AgX: "
                  "Blender 4's AgX base matrices with a polynomial sigmoid), "
                  "pbr-neutral (Khronos PBR Neutral, KhronosGroup/ToneMapping), clamp (none)")
      ->check(CLI::IsMember(wp::tonemap_names()))
      ->capture_default_str();
  app->add_option("--exposure", cli.exposure, "PNG exposure in stops")->capture_default_str();
}

// The view options as given (checked by wp::validate, view.h).
wp::View view_options(const CLI::App& render, const CliOptions& cli) {
  wp::View v;
  const auto vec = [](const std::vector<float>& x) { return glm::vec3(x[0], x[1], x[2]); };
  if (!cli.look_from.empty()) v.look_from = vec(cli.look_from);
  if (!cli.look_at.empty()) v.look_at = vec(cli.look_at);
  if (!cli.up.empty()) v.up = vec(cli.up);
  if (!cli.orbit.empty())
    v.orbit = glm::vec3(cli.orbit[0], cli.orbit[1], cli.orbit.size() > 2 ? cli.orbit[2] : 0.0f);
  if (!cli.focus_on.empty()) v.focus_on = vec(cli.focus_on);
  if (render.count("--fov")) v.fov = cli.fov;
  if (render.count("--focus-distance")) v.focus_distance = cli.focus_distance;
  v.aperture = cli.aperture;
  return v;
}

// --denoise, the same for render and merge.
void add_denoise_option(CLI::App* app, CliOptions& cli, const char* what) {
  app->add_flag("--denoise", cli.denoise,
                std::string("Also write X.denoised.exr/.png/.pfm beside each image output "
                            "X.exr/.png/.pfm: the image denoised by Intel Open Image Denoise's RT "
                            "filter, guided by the albedo and normal AOVs ") +
                    what +
                    "; loaded at run time from $WAVEPATH_OIDN (the library or its folder), "
                    "else what tools/setup.sh --denoise installs, else the system's "
                    "libOpenImageDenoise.so.2 (docs/denoise.md)");
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
  check(settings.wave_size <= kMaxWaveSize, "--wave-size must be at most 16777216");
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

// What to render and where to: outputs, size, samples, stopping rules, checkpoints, progress.
void add_output_options(CLI::App* app, CliOptions& cli, wp::RenderSettings& settings) {
  app->add_option("scene", cli.scene, "glTF 2.0 file (.gltf or .glb)")->required();
  app->add_option("-o,--output", cli.outputs,
                  "Output file(s): .exr = linear float RGB with the settings in its header, "
                  ".png = 8-bit sRGB preview, .pfm = linear float RGB (Portable FloatMap), "
                  ".wpfilm = the film's exact sums, to merge with other sample ranges "
                  "(wavepath merge) [default: render.exr render.png]");
  app->add_option("--width", settings.width, "Image width in pixels")->capture_default_str();
  app->add_option("--height", settings.height, "Image height in pixels")->capture_default_str();
  app->add_option("--spp", settings.spp, "Samples per pixel (the same as --samples 0:N)")
      ->capture_default_str();
  app->add_option("--samples", cli.samples,
                  "Render only sample indices A to B-1 (0 <= A < B <= 1048576), a part of a "
                  "longer render: its .wpfilm output merges exactly with the other parts' "
                  "(wavepath merge); the image is the mean of these samples [default: 0:spp]");
  app->add_option("--time-limit", cli.time_limit,
                  "Stop starting sample passes once SECONDS have passed since wavepath started "
                  "(loading and building count): a pass is only started if, at the mean pass "
                  "time so far, it ends in time; at least one pass is rendered. The image "
                  "holds the samples done (JSON and EXR header: spp, stop) [default: none]");
  app->add_option(
      "--noise-threshold", cli.noise_threshold,
      "Stop once the image's estimated relative error (root mean over pixels of "
      "variance / value^2, see docs/usage.md) is at most REL, e.g. 0.01; checked from 16 "
      "samples on [default: none]");
  app->add_option("--checkpoint", cli.checkpoint,
                  "Keep the film so far in FILE (.wpfilm), written atomically every "
                  "--checkpoint-every seconds, when the passes end, and on SIGINT/SIGTERM/"
                  "SIGHUP (which stop the render after the current pass, write every output "
                  "with the samples so far and exit with 128 + the signal number)");
  app->add_option("--checkpoint-every", cli.checkpoint_every,
                  "Seconds between checkpoints (0: after every pass)")
      ->capture_default_str();
  app->add_option("--resume", cli.resume,
                  "Continue the film in FILE (a checkpoint of the same scene and settings, "
                  "from the same first sample) up to the requested samples: the result is "
                  "bit-identical to one uninterrupted render");
  app->add_option("--progress-every", cli.progress_every,
                  "When stderr is not a terminal (a log), a progress line every SECONDS (0: "
                  "after every pass); on a terminal a bar is redrawn after every pass")
      ->capture_default_str();
}

// The camera: the file's, or one placed here, and its lens.
void add_camera_options(CLI::App* app, CliOptions& cli, wp::RenderSettings& settings) {
  app->add_option("--camera", settings.camera,
                  "Camera index in node order (`wavepath info` lists them) [default: the first, "
                  "else one framing the scene: its bounding sphere seen from +Z, 15 degrees "
                  "above]");
  const auto point = [&](const char* name, std::vector<float>& into, const char* help) {
    app->add_option(name, into, help)->delimiter(',')->expected(3)->type_name("X,Y,Z");
  };
  point("--look-from", cli.look_from,
        "Place a perspective camera at this point (scene units, world space, +Y up) looking at "
        "--look-at");
  point("--look-at", cli.look_at, "The point the --look-from camera looks at (the image centre)");
  point("--up", cli.up,
        "With --look-from or --orbit: the direction that is up in the image (projected onto "
        "it) [default: 0,1,0; --orbit: +Y, and through the poles its limit]");
  app->add_option("--orbit", cli.orbit,
                  "Place a perspective camera on a sphere about the centre of the scene's "
                  "bounds (the Khronos Render Fidelity convention): position = centre + "
                  "DISTANCE (sin PHI sin THETA, cos PHI, sin PHI cos THETA), degrees (THETA "
                  "azimuth from +Z towards +X, PHI from +Y; 0,90 looks from +Z); DISTANCE 0 or "
                  "left out: the bounding sphere just fits the view")
      ->delimiter(',')
      ->expected(2, 3)
      ->type_name("THETA,PHI[,DISTANCE]");
  app->add_option("--fov", cli.fov,
                  "Vertical field of view in degrees, for the camera used (a perspective one) "
                  "[default: the file camera's; 45 for --look-from, --orbit and the framing "
                  "camera, which then moves to fit the scene]");
  app->add_option("--aperture", cli.aperture,
                  "Thin lens: the lens radius in scene units (0: a pinhole, everything sharp); "
                  "points on the plane of focus stay sharp, others blur into discs");
  app->add_option("--focus-distance", cli.focus_distance,
                  "With --aperture: the distance of the plane of focus along the view direction "
                  "[default: the --look-at point's, the --orbit centre's, else the scene "
                  "centre's]");
  point("--focus-on", cli.focus_on, "With --aperture: focus on the plane through this point");
}

// The materials and the light around the scene.
void add_scene_options(CLI::App* app, CliOptions& cli, wp::RenderSettings& settings) {
  app->add_option("--variant", cli.variant,
                  "Material variant (KHR_materials_variants) by name: each primitive gets its "
                  "material for that variant, or its own where it has none; an unknown name "
                  "is an error listing the file's variants [default: the file's own materials]");
  app->add_option("--env-color", cli.env_color,
                  "Constant background radiance R,G,B (linear) [default: 0,0,0]")
      ->delimiter(',')
      ->expected(3);
  app->add_option("--env", cli.env,
                  "Environment map: equirectangular .hdr or .exr, linear radiance; the centre "
                  "of the map is seen looking down -Z, +Y is up");
  app->add_option("--env-filter", cli.env_filter,
                  "Environment map lookup: bilinear (interpolated between texel centres) or "
                  "nearest (the texel, blocky when magnified); importance sampling stays exact")
      ->check(CLI::IsMember({"bilinear", "nearest"}))
      ->capture_default_str();
  add_instancing_option(app, cli.instancing);
  app->add_option("--mipmaps", cli.mipmaps,
                  "Textures seen small: on (each path's ray cone picks a level of the texture's "
                  "mip chain, trilinear: less noise, slightly blurred) or off (full resolution "
                  "always; the pixel's samples average the texels)")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  app->add_option("--env-intensity", settings.env_intensity, "Scale of the environment map")
      ->capture_default_str();
  app->add_option("--env-rotation", settings.env_rotation,
                  "Rotation of the environment map about +Y, degrees")
      ->capture_default_str();
}

// The light transport: strategies, sample pattern, depth, roulette, seed.
void add_transport_options(CLI::App* app, CliOptions& cli, wp::RenderSettings& settings) {
  app->add_option("--strategy", cli.strategy,
                  "Direct light: mis (NEE and BSDF sampling, MIS-weighted), nee (light "
                  "sampling only), bsdf (BSDF sampling only; punctual lights then add nothing)")
      ->check(CLI::IsMember({"mis", "nee", "bsdf"}))
      ->capture_default_str();
  app->add_option("--mis-heuristic", cli.heuristic, "MIS weights: power (beta 2) or balance")
      ->check(CLI::IsMember({"power", "balance"}))
      ->capture_default_str();
  app->add_option("--light-select", cli.light_select,
                  "How NEE picks a light: power (proportional to estimated power) or uniform")
      ->check(CLI::IsMember({"power", "uniform"}))
      ->capture_default_str();
  app->add_option("--sampler", cli.sampler,
                  "Sample pattern: sobol (Owen-scrambled Sobol' points per pixel: less error "
                  "for the same samples; the light and BSDF samples of successive bounces "
                  "stratified together), sobol-padded (the same points, every group of numbers "
                  "in an order of its own) or independent (a hash per random number)")
      ->check(CLI::IsMember({"sobol", "sobol-padded", "independent"}))
      ->capture_default_str();
  app->add_option("--max-depth", settings.max_depth, "Most scattering events per path")
      ->capture_default_str();
  app->add_option("--rr-depth", settings.rr_depth,
                  "Russian roulette after this many scattering events")
      ->capture_default_str();
  app->add_option("--rr-threshold", settings.rr_threshold,
                  "Russian roulette ends a path whose throughput (largest channel) m is below "
                  "this with probability 1 - m / threshold, and a survivor carries the "
                  "threshold; 1 gives pbrt's rule (survival probability = throughput)")
      ->capture_default_str();
  app->add_flag("--no-rr", cli.no_rr, "No Russian roulette (paths end only at --max-depth)");
  app->add_option("--seed", settings.seed, "Random seed (same seed, same image)")
      ->capture_default_str();
}

// How it runs: pipeline, device, kernel features, BVH, waves, caches.
void add_engine_options(CLI::App* app, CliOptions& cli, wp::RenderSettings& settings) {
  app->add_option("--pipeline", cli.pipeline,
                  "fused (one kernel per bounce for all the work at a hit) or split (a kernel "
                  "per stage, for kernel work and per-stage timing); the same image bit for bit")
      ->check(CLI::IsMember({"fused", "split"}))
      ->capture_default_str();
  app->add_option("--device", cli.device,
                  "OpenCL device: index or name substring (see `wavepath devices`) "
                  "[default: first GPU, else first CPU]");
  app->add_option("--features", cli.features,
                  "Kernel specialisation: `scene` (only what the scene uses) or `all`")
      ->check(CLI::IsMember({"scene", "all"}))
      ->capture_default_str();
  app->add_flag("--spatial-splits", cli.spatial_splits,
                "Build the BVH with spatial splits (slower build, faster traversal)");
  app->add_option(
      "--wave-size", settings.wave_size,
      "Path slots per wave; above the image's pixel count a wave holds several samples "
      "[default: on a CPU device the largest power of two of paths whose state fits its "
      "cache, 2^16 to 2^20, the image split evenly into the nearest whole number of such waves; "
      "on a GPU min(pixels, 2^20), 2^18 for small images]");
  app->add_option("--bvh-width", settings.bvh_width,
                  "BVH layout: 2 (binary) or 8 (wide, float8 box tests) [default: 2 on GPUs, "
                  "8 on CPUs]");
  app->add_option("--local-size", settings.local_size, "Work-group size [default: 64]");
  app->add_flag("--no-prefetch", cli.no_prefetch,
                "No cache hints for the path state (on by default on PoCL's CPU devices, "
                "where they make renders faster; the same image either way)");
  app->add_flag("--no-shadow-packets", cli.no_shadow_packets,
                "Trace each shadow ray on its own (by default PoCL's CPU devices trace them eight "
                "to a work-item where they are plain any-hit queries, at each bounce where the "
                "first waves timed that faster; the same image either way)");
  app->add_flag("--no-closest-packets", cli.no_closest_packets,
                "Trace each closest-hit ray on its own (by default PoCL's CPU devices trace them "
                "eight to a work-item in scenes without instances or alpha; the same image either "
                "way)");
  app->add_flag("--no-shade-packets", cli.no_shade_packets,
                "Shade each path, and start its camera ray, on its own (by default PoCL's CPU "
                "devices take eight paths to a work-item in SIMD lanes where every surface is "
                "untextured, Lambertian or metallic-roughness without extensions or transmission, "
                "without instances or AOVs; the same image either way)");
  app->add_flag("--force-packets", cli.force_packets,
                "Use the eight-lane packet kernels (rays, shading and camera rays in SIMD lanes) "
                "on any device, for testing them elsewhere, e.g. under Oclgrind "
                "(tests/test_oclgrind.sh); by default only PoCL's CPU devices use them, where "
                "they were measured. The same image");
  app->add_option("--scene-buffer-kib", cli.scene_buffer_kib,
                  "Most KiB per scene buffer; the scene is split over up to 8 [default: the "
                  "device's largest allocation, see `wavepath devices`]");
  app->add_flag("--no-bvh-cache", cli.no_bvh_cache,
                "Build the BVH afresh; by default it is looked up in and stored to "
                "$WAVEPATH_CACHE_DIR, else $XDG_CACHE_HOME/wavepath, else ~/.cache/wavepath");
  app->add_flag("--no-kernel-cache", cli.no_kernel_cache,
                "Build the kernels from source; by default the built program is looked up in "
                "and stored to the BVH cache's folder (a faster start on PoCL)");
}

// What else is written or printed: PNG tone mapping, variance, AOVs, timing, JSON.
void add_report_options(CLI::App* app, CliOptions& cli, wp::RenderSettings& settings) {
  add_png_options(app, cli);
  app->add_flag("--variance", cli.variance,
                "Also write the variance of each pixel's estimate (sample variance / spp): the "
                "layer variance.R/G/B in EXR output, X.variance.pfm beside X.pfm");
  app->add_option("--aov", cli.aovs,
                  "Also write these of the first surface that is not a perfect mirror or smooth "
                  "glass, averaged over the pixel's samples (comma-separated): albedo (base "
                  "colour; the background's for a miss), normal (world-space shading normal on "
                  "the camera's side, not renormalised), depth (metres from the camera to the "
                  "first hit, 0 for a miss): EXR layers albedo.R/G/B, normal.X/Y/Z, depth.Z; "
                  "X.albedo.pfm etc. beside X.pfm; kept in .wpfilm outputs")
      ->delimiter(',')
      ->check(CLI::IsMember(kAovNames));
  add_denoise_option(app, cli, "(which it implies rendering)");
  app->add_flag("--profile", settings.profile, "Time each kernel (adds stage times to --json)");
  app->add_flag("--json", cli.json,
                "Print a JSON summary as the last line of stdout (spp, sample_begin, "
                "sample_end, width, height, seconds, samples_per_second, device, triangles, "
                "kernel_build_seconds, bvh_build_seconds, ...)");
  app->add_flag("-q,--quiet", cli.quiet, "No progress or warnings on stderr");
}

}  // namespace

std::vector<std::string> written_files(const CliOptions& cli) {
  std::vector<std::string> files = cli.outputs;
  if (cli.denoise)
    for (const auto& o : cli.outputs)
      if (!is_film(o)) files.push_back(wp::denoised_path(o));
  return files;
}

void check_exposure(const CliOptions& cli) {
  if (!std::isfinite(cli.exposure) || std::abs(cli.exposure) > 64.0f)
    throw wp::Error("--exposure must be a finite number of stops between -64 and 64");
}

void add_instancing_option(CLI::App* app, std::string& instancing) {
  app->add_option("--instancing", instancing,
                  "Meshes placed more than once: on (each mesh stored once, its placements as "
                  "instances of a two-level BVH), off (every placement a copy in world space) or "
                  "auto (on when the copies would hold at least twice the triangles of the "
                  "meshes)")
      ->check(CLI::IsMember({"auto", "on", "off"}))
      ->capture_default_str();
}

wp::Instancing instancing_mode(const std::string& instancing) {
  return instancing == "on"    ? wp::Instancing::kAlways
         : instancing == "off" ? wp::Instancing::kNever
                               : wp::Instancing::kAuto;
}

void add_render_options(CLI::App* render, CliOptions& cli, wp::RenderSettings& settings) {
  add_output_options(render, cli, settings);
  add_camera_options(render, cli, settings);
  add_scene_options(render, cli, settings);
  add_transport_options(render, cli, settings);
  add_engine_options(render, cli, settings);
  add_report_options(render, cli, settings);
}

void add_merge_options(CLI::App* app, CliOptions& cli) {
  app->add_option("films", cli.parts,
                  ".wpfilm files of the same render (scene and settings) and size whose sample "
                  "ranges (--samples) together form one range, without overlaps or gaps")
      ->required();
  app->add_option("-o,--output", cli.outputs,
                  "Output file(s): .exr, .png, .pfm (the merged image) and/or .wpfilm (the merged "
                  "film)")
      ->required();
  add_png_options(app, cli);
  app->add_flag("--variance", cli.variance,
                "Also write the variance of each pixel's estimate (as render --variance)");
  app->add_option("--aov", cli.aovs,
                  "Also write these AOVs, which the films must hold (as render --aov)")
      ->delimiter(',')
      ->check(CLI::IsMember(kAovNames));
  add_denoise_option(app, cli, "(the films must hold AOVs: rendered with --denoise or --aov)");
  app->add_flag("--json", cli.json,
                "Print a JSON summary (parts, spp, sample_begin, sample_end, width, height, "
                "device, nonfinite_samples, outputs) as the last line of stdout");
  app->add_flag("-q,--quiet", cli.quiet, "No summary on stderr");
}

void prepare_render(const CLI::App& render, CliOptions& cli, wp::RenderSettings& settings,
                    const wp::Ranks& ranks) {
  if (cli.outputs.empty()) cli.outputs = {"render.exr", "render.png"};
  if (ranks.root()) check_outputs(written_files(cli));
  apply_samples(render, cli, settings);
  check_options(render, cli, settings);
  if (ranks.size() > 1 && (cli.time_limit > 0 || cli.noise_threshold > 0 ||
                           !cli.checkpoint.empty() || !cli.resume.empty()))
    throw wp::Error(
        "--time-limit, --noise-threshold, --checkpoint and --resume do not work under MPI yet "
        "(the ranks would have to agree where each stops); render sample ranges (--samples) "
        "and merge them instead");
  if (!cli.checkpoint.empty()) check_outputs({cli.checkpoint});
  settings.view = view_options(render, cli);
  settings.background = {cli.env_color[0], cli.env_color[1], cli.env_color[2]};
  settings.all_features = cli.features == "all";
  settings.aov = !cli.aovs.empty() || cli.denoise;
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
  settings.shadow_packets = !cli.no_shadow_packets;
  settings.closest_packets = !cli.no_closest_packets;
  settings.shade_packets = !cli.no_shade_packets;
  settings.force_packets = cli.force_packets;
  if (!cli.no_kernel_cache) settings.kernel_cache_dir = wp::cache_dir();
  if (cli.no_rr) settings.rr_depth = std::numeric_limits<int>::max();
  wp::validate(settings);
  settings.env_filter =
      cli.env_filter == "nearest" ? wp::EnvFilter::kNearest : wp::EnvFilter::kBilinear;
  settings.mipmaps = cli.mipmaps == "on";
  if (!cli.env.empty()) {
    settings.environment =
        std::make_shared<wp::EnvironmentMap>(wp::load_environment(cli.env, settings.env_filter));
    wp::validate(settings);  // --env-intensity against the map's brightest texel
    if (!cli.quiet && ranks.root())
      for (const auto& w : settings.environment->warnings)
        std::fprintf(stderr, "wavepath: warning: %s\n", w.c_str());
  }
}

}  // namespace wp::cli
