// wavepath: the command line. `wavepath render SCENE`, `wavepath merge FILM...` and
// `wavepath devices` (host/cli/commands.h; their options in host/cli/options.h), and
// `wavepath info SCENE` (host/cli/info.h).
// Errors of every kind end here, in one place: one line on stderr, exit status 1.
#include <algorithm>
#include <chrono>
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

#include "host/cli/commands.h"
#include "host/cli/info.h"
#include "host/cli/options.h"

int main(int argc, char** argv) {
  using namespace wp::cli;
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
  add_render_options(render, cli, settings);
  CLI::App* merge = app.add_subcommand(
      "merge",
      "Merge .wpfilm films of one render's sample ranges (any order) into one film or image");
  add_merge_options(merge, cli);
  InfoOptions info_options;
  CLI::App* info = app.add_subcommand(
      "info",
      "Describe a glTF scene as wavepath loads it: contents, extensions, the device memory a "
      "render needs, the BVH cache; no device, no rendering");
  add_info_options(info, info_options);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // app.exit prints help and version (status 0) or the one-line error above; CLI11's own codes
    // (104, 106, ...) become 1, the status of every wavepath error.
    return app.exit(e) == 0 ? 0 : 1;
  }
  try {
    if (devices->parsed()) return list_devices();
    if (info->parsed()) return info_command(info_options);
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
