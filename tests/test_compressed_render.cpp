// Compressed twins render as their originals (scene tier): the shared Duck (a textured mesh)
// compressed at test time with each codec (tests/gltf/compress_twin.h), rendered on PoCL under a
// constant sky with the same seed.
#include <cmath>

#include <gtest/gtest.h>

#include "host/render/render.h"
#include "tests/device_test.h"
#include "tests/gltf/compressed_scenes.h"

namespace {

using namespace wp;                    // NOLINT(google-build-using-namespace)
using namespace wp::test;              // NOLINT(google-build-using-namespace)
using namespace wp::test::compressed;  // NOLINT(google-build-using-namespace)

const auto* const kCleanup = ::testing::AddGlobalTestEnvironment(new gltf_files::TempCleanup);

class CompressedRender : public DeviceTest {
 protected:
  Rendered draw(const std::string& path) {
    RenderSettings s;
    s.width = 48;
    s.height = 36;
    s.spp = 16;
    s.background = glm::vec3(1.0f);
    s.max_depth = 4;
    return render(*runtime_, load_gltf(path), s);
  }
};

// Both images estimate the same one: per channel, the image means differ by less than 4 standard
// errors of their difference. Each mean's variance is the sum of its pixels' variances (of their
// means) over the pixel count squared; the two renders share their random numbers, which
// correlates them positively, so the difference's true variance is below the sum of the two and
// the bound is conservative (a false failure has odds below 1e-4).
void expect_same_estimate(const Rendered& a, const Rendered& b, const char* what) {
  const std::size_t pixels = a.image.rgb.size() / 3;
  ASSERT_EQ(b.image.rgb.size(), a.image.rgb.size());
  for (std::size_t c = 0; c < 3; ++c) {
    double mean_a = 0, mean_b = 0, var = 0;
    for (std::size_t i = c; i < a.image.rgb.size(); i += 3) {
      mean_a += a.image.rgb[i];
      mean_b += b.image.rgb[i];
      var += double(a.variance.rgb[i]) + double(b.variance.rgb[i]);
    }
    const double n = double(pixels);
    EXPECT_GT(mean_a / n, 0.01) << what << " channel " << c;  // not a black image
    EXPECT_LE(std::abs(mean_a - mean_b) / n, 4.0 * std::sqrt(var) / n) << what << " channel " << c;
  }
}

// Lossless WebP: the same texels on the same triangles, so the same image bit for bit.
TEST_F(CompressedRender, WebpTwinRendersIdentically) {
  WP_REQUIRE_MODEL(path, "Duck/Duck.glb");
  const Rendered original = draw(path);
  const Rendered webp = draw(write_twin(webp_twin(read_glb(path)), "duck_webp.glb"));
  EXPECT_EQ(webp.image.rgb, original.image.rgb);
}

// Meshopt keeps every vertex bit for bit but may start a triangle at another corner, which changes
// the rounding of the hit's barycentrics and the order the BVH builder sees (not bit for bit:
// measured); Draco's 14-bit positions move vertices by micrometres on the Duck. Either twin
// estimates the original's image.
TEST_F(CompressedRender, MeshoptAndDracoTwinsWithinTheStandardError) {
  WP_REQUIRE_MODEL(path, "Duck/Duck.glb");
  const Rendered original = draw(path);
  const Glb glb = read_glb(path);
  expect_same_estimate(original, draw(write_twin(meshopt_twin(glb), "duck_meshopt.glb")),
                       "meshopt");
  expect_same_estimate(original, draw(write_twin(draco_twin(glb, DracoBits{}), "duck_draco.glb")),
                       "Draco");
}

}  // namespace
