// libFuzzer target: wp::decode_image (host/scene/image_decode.h) on arbitrary bytes, the texture
// decoders without the glTF around them: PNG through libpng, JPEG through libjpeg-turbo, WebP
// through libwebp (Debian's libraries, not instrumented here: ASan sees the texel buffer wavepath
// allocates and they write, not their own). The contract: any input ends in an image or in one
// wp::Error. Any other exception, a crash, a sanitizer report, a hang, or an image whose size
// disagrees with its texels or exceeds the texture limit is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "host/scene/image_decode.h"
#include "host/util/error.h"
#include "tests/fuzz/fuzz_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // WP_FUZZ_VERBOSE=1: one line per input, to check what a corpus or a crash input reaches.
  static const bool verbose = std::getenv("WP_FUZZ_VERBOSE") != nullptr;
  wp::Image image;
  try {
    wp::decode_image(data, size, "image", image);
  } catch (const wp::Error& e) {
    // The documented outcome for malformed input.
    if (verbose) std::fprintf(stderr, "wp::Error: %s\n", e.what());
    return 0;
  }
  if (image.width <= 0 || image.height <= 0)
    wp::fuzz::invariant_failed("an image of " + std::to_string(image.width) + " x " +
                               std::to_string(image.height) + " texels");
  const std::size_t texels = std::size_t(image.width) * std::size_t(image.height);
  if (texels > (std::size_t(1) << 28)) wp::fuzz::invariant_failed("more texels than the limit");
  if (image.rgba.size() != 4 * texels)
    wp::fuzz::invariant_failed("rgba holds " + std::to_string(image.rgba.size()) +
                               " bytes, not 4 x width x height");
  if (verbose) std::fprintf(stderr, "decoded: %d x %d\n", image.width, image.height);
  return 0;
}
