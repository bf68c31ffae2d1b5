// The command line's options: what `wavepath render` and `wavepath merge` accept, the checks the
// options need beyond CLI11's, and the RenderSettings they make.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "host/cli/distributed.h"
#include "host/render/wavefront.h"
#include "host/scene/gltf_loader.h"

namespace wp::cli {

struct CliOptions {
  std::string scene;
  std::string variant;  // --variant: KHR_materials_variants name ("": the file's own materials)
  // The view (host/scene/view.h), as given: vectors of 3 (--orbit 2 or 3) numbers.
  std::vector<float> look_from, look_at, up, orbit, focus_on;
  float fov = 0.0f, aperture = 0.0f, focus_distance = 0.0f;
  std::vector<std::string> parts;  // merge: the .wpfilm files
  std::vector<std::string> outputs;
  std::string samples;  // --samples A:B
  std::string device;
  std::vector<float> env_color{0.0f, 0.0f, 0.0f};
  std::string env;
  std::string env_filter = "bilinear";
  std::string mipmaps = "on";
  std::string instancing = "auto";  // --instancing: auto, on or off
  std::string strategy = "mis";
  std::string heuristic = "power";
  std::string light_select = "power";
  std::string sampler = "sobol";
  std::string pipeline = "fused";
  bool no_rr = false;
  bool variance = false;
  bool no_bvh_cache = false;
  bool no_prefetch = false;
  bool no_shadow_packets = false;
  bool no_closest_packets = false;
  bool no_shade_packets = false;
  bool force_packets = false;
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
  bool denoise = false;           // --denoise: X.denoised.EXT beside each image output X.EXT
  double progress_every = 10;
  bool json = false;
  bool quiet = false;
};

// The --aov names, in the order of the film's layers.
extern const std::vector<std::string> kAovNames;

// Declares every option of `wavepath render` on `render`, bound to `cli` and `settings`.
void add_render_options(CLI::App* render, CliOptions& cli, wp::RenderSettings& settings);
// --instancing (render and info), and its value as the loader takes it.
void add_instancing_option(CLI::App* app, std::string& instancing);
wp::Instancing instancing_mode(const std::string& instancing);
// Declares every option of `wavepath merge` on `merge`.
void add_merge_options(CLI::App* merge, CliOptions& cli);

// Whether `path` names a film (.wpfilm) rather than an image.
bool is_film(const std::string& path);

// Fails before any rendering when an output could not be written at the end: outputs are written
// beside their destination under a temporary name and renamed into place (image_io.h), which
// needs a writable folder; an existing file that is not writable is not replaced either.
void check_outputs(const std::vector<std::string>& outputs);

// The files an image output set writes: `outputs`, and with --denoise X.denoised.EXT beside each
// image output X.EXT (denoise.h), in that order.
std::vector<std::string> written_files(const CliOptions& cli);

// --exposure is a finite number of stops in [-64, 64].
void check_exposure(const CliOptions& cli);

// The settings, checked before the scene is loaded: options, sample range, the environment map,
// and (on rank 0, which writes them) the outputs, so that a render that could not be saved fails
// before it starts.
void prepare_render(const CLI::App& render, CliOptions& cli, wp::RenderSettings& settings,
                    const wp::Ranks& ranks);

}  // namespace wp::cli
