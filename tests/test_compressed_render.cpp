// Compressed twins render as their originals (scene tier): the shared Duck (a textured mesh)
// compressed at test time with each codec (tests/gltf/compress_twin.h), rendered on PoCL under a
// constant sky with the same seed.
#include <gtest/gtest.h>

#include "host/render/render.h"
#include "tests/device_test.h"
#include "tests/gltf/compressed_scenes.h"
#include "tests/same_estimate.h"

namespace {

using namespace wp;                    // NOLINT(google-build-using-namespace)
using namespace wp::test;              // NOLINT(google-build-using-namespace)
using namespace wp::test::compressed;  // NOLINT(google-build-using-namespace)

const auto* const kCleanup = ::testing::AddGlobalTestEnvironment(new gltf_files::TempCleanup);

class CompressedRender : public DeviceTest {
 protected:
  Rendered draw(const std::string& path) {
    return render(*runtime_, load_gltf(path), twin_settings(48, 36, 16, 4, 1.0f));
  }
};

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
