// libFuzzer target: wp::load_environment on arbitrary bytes. Inputs starting with the OpenEXR
// magic (76 2f 31 01) are loaded as .exr (OpenEXR's reader, not instrumented here, so it is
// reached but not explored), all others as .hdr (the project's own bounded RGBE reader, the main
// target). The contract (host/lights/environment.h): any input ends in a map or in one wp::Error.
// Any other exception, a crash, a sanitizer report, a hang or a map whose tables disagree with its
// size or are not CDFs (the kernels would sample out of bounds) is a finding.
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstdint>
#include <cstring>
#include <string>

#include "host/lights/environment.h"
#include "host/util/error.h"
#include "tests/fuzz/fuzz_file.h"

namespace {

using wp::fuzz::invariant_failed;

// cdf[0..n]: finite, non-decreasing, within [0, 1], ending at 1 (or all 0 when `may_be_zero`).
void check_cdf(const float* cdf, std::size_t n, bool may_be_zero, const std::string& what) {
  if (cdf[0] != 0.0f) invariant_failed(what + " does not start at 0");
  for (std::size_t i = 1; i <= n; ++i)
    if (!std::isfinite(cdf[i]) || cdf[i] < cdf[i - 1] || cdf[i] > 1.0f)
      invariant_failed(what + " entry " + std::to_string(i) + " = " + std::to_string(cdf[i]));
  if (cdf[n] != 1.0f && !(may_be_zero && cdf[n] == 0.0f))
    invariant_failed(what + " ends at " + std::to_string(cdf[n]));
}

void check_environment(const wp::EnvironmentMap& env) {
  if (env.width <= 0 || env.height <= 0) invariant_failed("empty map loaded");
  const std::size_t w = std::size_t(env.width), h = std::size_t(env.height);
  if (env.texels.size() != w * h) invariant_failed("texel count is not width x height");
  if (env.marginal.size() != h + 1) invariant_failed("marginal is not height + 1 entries");
  if (env.conditional.size() != h * (w + 1))
    invariant_failed("conditional is not height x (width + 1) entries");
  for (const glm::vec4& t : env.texels)
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(t[k]) || t[k] < 0.0f) invariant_failed("negative or non-finite texel");
  if (!std::isfinite(env.mean_luminance) || env.mean_luminance < 0.0)
    invariant_failed("mean_luminance " + std::to_string(env.mean_luminance));
  check_cdf(env.marginal.data(), h, true, "marginal");
  for (std::size_t y = 0; y < h; ++y)
    check_cdf(env.conditional.data() + y * (w + 1), w, false,
              "conditional row " + std::to_string(y));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // WP_FUZZ_VERBOSE=1: one line per input, to check what a corpus or a crash input reaches.
  static const bool verbose = std::getenv("WP_FUZZ_VERBOSE") != nullptr;
  static const unsigned char kExrMagic[4] = {0x76, 0x2f, 0x31, 0x01};
  const bool exr = size >= 4 && std::memcmp(data, kExrMagic, 4) == 0;
  const std::string path = wp::fuzz::write_input(data, size, exr ? ".exr" : ".hdr");
  try {
    const wp::EnvironmentMap env = wp::load_environment(path);
    check_environment(env);
    if (verbose) std::fprintf(stderr, "loaded: %d x %d\n", env.width, env.height);
  } catch (const wp::Error& e) {
    // The documented outcome for malformed input.
    if (verbose) std::fprintf(stderr, "wp::Error: %s\n", e.what());
  }
  return 0;
}
