#include "host/render.h"

#include <chrono>
#include <cmath>

#include "host/error.h"

namespace wp {

namespace {
double since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}
}  // namespace

void validate(const RenderSettings& s) {
  const auto check = [](bool ok, const std::string& what) {
    if (!ok) throw Error(what);
  };
  check(s.width >= 1 && s.width <= 16384, "--width must be between 1 and 16384");
  check(s.height >= 1 && s.height <= 16384, "--height must be between 1 and 16384");
  check(s.spp >= 1, "--spp must be at least 1");
  check(s.max_depth >= 0 && s.max_depth <= 1024, "--max-depth must be between 0 and 1024");
  check(s.rr_depth >= 0, "--rr-depth must be at least 0");
  for (int i = 0; i < 3; ++i)
    check(std::isfinite(s.background[i]) && s.background[i] >= 0.0f,
          "--env-color must be three finite, non-negative numbers");
}

Rendered render(ClRuntime& runtime, const Scene& scene, const RenderSettings& settings,
                const RenderOptions& options) {
  validate(settings);
  const auto start = std::chrono::steady_clock::now();
  bvh::BuildInput input;
  input.positions = scene.positions.data();
  input.indices = scene.indices.data();
  input.triangle_count = scene.triangle_count();
  std::vector<std::uint32_t> flags(scene.triangle_count());
  for (std::size_t i = 0; i < flags.size(); ++i) {
    const Material& m = scene.materials[scene.triangle_material[i]];
    flags[i] = (m.double_sided ? 0u : WP_TRI_CULL_BACKFACE) |
               (m.alpha_mode != AlphaMode::kOpaque ? WP_TRI_ALPHA : 0u);
  }
  input.triangle_flags = flags.data();
  const bvh::Bvh bvh = bvh::build(input, options.bvh);

  const double build_before = runtime.build_seconds();
  Wavefront wavefront(runtime, scene, bvh, settings);

  Rendered out;
  RenderReport& r = out.report;
  r.device = runtime.device().name;
  r.features = wavefront.features().describe();
  r.build_options = wavefront.build_options();
  r.triangles = scene.triangle_count();
  r.bvh = bvh.stats;
  r.kernel_build_seconds = runtime.build_seconds() - build_before;
  r.setup_seconds = since(start);
  r.wave_size = wavefront.wave_size();
  r.bytes_per_path = wavefront.path_state().bytes_per_path;

  const auto passes_start = std::chrono::steady_clock::now();
  for (int s = 0; s < settings.spp; ++s) {
    wavefront.render_pass(static_cast<std::uint32_t>(s));
    if (s == 0) r.first_pass_seconds = since(start);
    if (options.progress) options.progress(s + 1, settings.spp, since(start));
  }
  r.render_seconds = since(passes_start);
  r.nonfinite_samples = wavefront.nonfinite_samples();
  r.stages = wavefront.stage_times();
  out.image.width = settings.width;
  out.image.height = settings.height;
  out.image.rgb = wavefront.image(static_cast<std::uint32_t>(settings.spp));
  return out;
}

}  // namespace wp
