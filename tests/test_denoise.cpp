// --denoise (host/film/denoise.h) through the command line: without Open Image Denoise it fails
// before rendering, in one line, writing nothing; with it, X.denoised.EXT lands beside each image
// output X.EXT and the raw image is unchanged; and the denoised 16-spp image is closer to a
// converged reference than the raw one, on the Cornell box and on a textured model.
//
// The tests that need OIDN skip, saying why, when the wavepath binary does not find it
// (tools/setup.sh --denoise installs it where it looks; CI runs that first).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "host/film/image_io.h"
#include "tests/cli_run.h"
#include "tests/test_assets.h"

namespace fs = std::filesystem;

namespace {

using wp::test::CliRun;

std::string quoted(const std::string& s) {
  return "'" + s + "'";
}

std::string cornell() {
  return quoted(wp::test::source_path("scenes/cornell_box.gltf"));
}

// Why the wavepath binary finds no OIDN (its own search, denoise.h), or "" when it does. --denoise
// loads the library before the scene: with a scene that does not exist, the error names OIDN
// when it is missing and the scene otherwise. Asked once per test process.
const std::string& oidn_missing() {
  static const std::string why = [] {
    const fs::path dir =
        fs::temp_directory_path() / ("wavepath_oidn_probe_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const CliRun r = wp::test::run_wavepath(dir, "render no_such_scene.gltf --denoise");
    fs::remove_all(dir);
    if (r.err.find("Open Image Denoise") == std::string::npos) return std::string();
    return r.err.substr(0, r.err.find('\n'));
  }();
  return why;
}

#define WP_REQUIRE_OIDN() \
  if (!oidn_missing().empty()) GTEST_SKIP() << "no Open Image Denoise: " << oidn_missing()

class DenoiseCli : public wp::test::FolderTest {
 protected:
  CliRun run(const std::string& args, const std::string& env = "") {
    return wp::test::run_wavepath(dir_, args, env);
  }
  // The names in the test's folder, sorted.
  std::vector<std::string> files() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename());
    std::sort(names.begin(), names.end());
    return names;
  }
  // A failure: exit status 1, one line on stderr that says `cause` and how to get OIDN, and no
  // file left in the folder but `keep`.
  void expect_oidn_error(const CliRun& r, const std::string& cause,
                         const std::vector<std::string>& keep = {}) {
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_EQ(r.err.rfind("wavepath: error: " + cause, 0), 0u) << r.err;
    EXPECT_NE(r.err.find("tools/setup.sh --denoise"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("WAVEPATH_OIDN"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
    EXPECT_EQ(files(), keep);
  }
};

// (a) WAVEPATH_OIDN naming no library: nothing rendered (the scene is not even read: a missing
// one is not what the error is about), nothing written, for render and merge alike.
TEST_F(DenoiseCli, WithoutTheLibraryFailsBeforeRenderingAndWritesNothing) {
  const std::string render =
      "render " + cornell() + " --width 16 --height 16 --spp 1 -o a.exr -o a.png --denoise";
  expect_oidn_error(run(render, "WAVEPATH_OIDN=/nonexistent/libOpenImageDenoise.so.2"),
                    "Open Image Denoise not found: WAVEPATH_OIDN=/nonexistent");
  expect_oidn_error(
      run("render no_such_scene.gltf --denoise -o a.exr", "WAVEPATH_OIDN=/nonexistent"),
      "Open Image Denoise not found");
  fs::create_directories(dir_ / "empty");
  expect_oidn_error(run(render, "WAVEPATH_OIDN=empty"),
                    "Open Image Denoise not found: WAVEPATH_OIDN=empty is a folder without",
                    {"empty"});
  fs::remove(dir_ / "empty");
  // A file that is not a shared library.
  std::FILE* f = std::fopen(path("libOpenImageDenoise.so.2").c_str(), "w");
  ASSERT_TRUE(f);
  std::fputs("not a library\n", f);
  std::fclose(f);
  expect_oidn_error(run(render, "WAVEPATH_OIDN=."),
                    "Open Image Denoise could not be loaded from WAVEPATH_OIDN",
                    {"libOpenImageDenoise.so.2"});
  fs::remove(path("libOpenImageDenoise.so.2"));
  expect_oidn_error(run("merge a.wpfilm -o m.exr --denoise", "WAVEPATH_OIDN=/nonexistent"),
                    "Open Image Denoise not found");
}

// An error OIDN reports (here: every device type turned off with OIDN's own variables, so that
// creating the device fails) is one line naming what was being done, exit 1, nothing written.
TEST_F(DenoiseCli, AnOidnErrorIsOneLineAndWritesNothing) {
  WP_REQUIRE_OIDN();
  const CliRun r = run("render " + cornell() + " --width 16 --height 16 --spp 1 -o a.exr --denoise",
                       "OIDN_DEVICE_CPU=0 OIDN_DEVICE_CUDA=0 OIDN_DEVICE_HIP=0 OIDN_DEVICE_SYCL=0 "
                       "OIDN_DEVICE_METAL=0");
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(r.err.rfind("wavepath: error: Open Image Denoise: creating a device: ", 0), 0u)
      << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
  EXPECT_EQ(files(), std::vector<std::string>{});
}

// With OIDN: X.denoised.EXT beside every image output (no layers, no companions), the raw image
// bit for bit the one a render without --denoise makes, the denoiser named in the EXR header, and
// merge --denoise the same from the film (films without AOVs refused).
TEST_F(DenoiseCli, WritesTheDenoisedImageBesideEachImageOutput) {
  WP_REQUIRE_OIDN();
  const std::string size = " --width 24 --height 16 --spp 4 -q";
  const CliRun r = run("render " + cornell() + size +
                       " --denoise --json -o a.exr -o a.png -o a.pfm -o a.wpfilm");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<std::string> expected = {
      "a.denoised.exr", "a.denoised.pfm", "a.denoised.png", "a.exr", "a.pfm", "a.png", "a.wpfilm"};
  EXPECT_EQ(files(), expected);
  EXPECT_NE(r.out.find("\"outputs\":[\"a.exr\",\"a.png\",\"a.pfm\",\"a.wpfilm\",\"a.denoised.exr\","
                       "\"a.denoised.png\",\"a.denoised.pfm\"]"),
            std::string::npos)
      << r.out;

  ASSERT_EQ(run("render " + cornell() + size + " -o plain.exr -o plain.wpfilm").status, 0);
  const wp::ImageRgb raw = wp::read_exr(path("a.exr")), plain = wp::read_exr(path("plain.exr"));
  EXPECT_EQ(raw.rgb, plain.rgb);
  const wp::ImageRgb denoised = wp::read_exr(path("a.denoised.exr"));
  ASSERT_EQ(denoised.rgb.size(), raw.rgb.size());
  EXPECT_NE(denoised.rgb, raw.rgb);
  for (const float v : denoised.rgb) ASSERT_TRUE(std::isfinite(v));
  EXPECT_EQ(wp::read_exr_attributes(path("a.denoised.exr"))["wavepath:denoiser"].rfind(
                "Open Image Denoise 2.", 0),
            0u);

  const CliRun m = run("merge a.wpfilm --denoise -q -o m.exr");
  ASSERT_EQ(m.status, 0) << m.err;
  // The same film, so the same input to OIDN; its CPU device need not be bit-reproducible.
  const wp::ImageRgb merged = wp::read_exr(path("m.denoised.exr"));
  ASSERT_EQ(merged.rgb.size(), denoised.rgb.size());
  for (std::size_t i = 0; i < merged.rgb.size(); ++i)
    ASSERT_NEAR(merged.rgb[i], denoised.rgb[i], 1e-3f * (1.0f + denoised.rgb[i])) << i;
  const CliRun none = run("merge plain.wpfilm --denoise -q -o n.exr");
  EXPECT_EQ(none.status, 1);
  EXPECT_NE(none.err.find("holds no AOVs"), std::string::npos) << none.err;
  EXPECT_FALSE(fs::exists(path("n.exr")));
}

// (b) Accuracy: relMSE against a converged reference, as tools/wavepath_tools/accuracy_lib.py measures it:
// mean over pixels and channels of ((x - r)^2 - v_r) / (r^2 + 0.01), where the reference's own
// variance v_r (--variance) is subtracted because its noise adds v_r to (x - r)^2 on average.
double rel_mse(const wp::ImageRgb& x, const wp::ImageRgb& r, const wp::ImageRgb& v_r) {
  double sum = 0;
  for (std::size_t i = 0; i < r.rgb.size(); ++i) {
    const double d = double(x.rgb[i]) - r.rgb[i];
    sum += (d * d - v_r.rgb[i]) / (double(r.rgb[i]) * r.rgb[i] + 0.01);
  }
  return sum / double(r.rgb.size());
}

class DenoiseAccuracy : public DenoiseCli {
 protected:
  // Renders `scene` (quoted, with its options) at 128 x 128: the reference (1024 spp, --variance,
  // a seed no compared render uses) and 16 spp with --denoise; returns {raw, denoised} relMSE.
  std::pair<double, double> measure(const std::string& scene) {
    const std::string common = "render " + scene + " --width 128 --height 128 -q ";
    const CliRun ref = run(common + "--spp 1024 --seed 987654321 --variance -o ref.exr");
    EXPECT_EQ(ref.status, 0) << ref.err;
    const CliRun x = run(common + "--spp 16 --seed 1 --denoise -o x.exr");
    EXPECT_EQ(x.status, 0) << x.err;
    if (ref.status != 0 || x.status != 0) return {0, 0};
    const wp::ImageRgb r = wp::read_exr(path("ref.exr")),
                       v_r = wp::read_exr(path("ref.exr"), "variance");
    double own = 0;  // the reference's own relMSE, estimated from its variance
    for (std::size_t i = 0; i < r.rgb.size(); ++i)
      own += v_r.rgb[i] / (double(r.rgb[i]) * r.rgb[i] + 0.01);
    own /= double(r.rgb.size());
    const double raw = rel_mse(wp::read_exr(path("x.exr")), r, v_r),
                 denoised = rel_mse(wp::read_exr(path("x.denoised.exr")), r, v_r);
    std::printf("relMSE: raw %.4g, denoised %.4g (%.3g x); the reference's own %.2g\n", raw,
                denoised, denoised / raw, own);
    return {raw, denoised};
  }
};

// The margin: denoised < raw / 2. docs/denoise.md measured (128 x 128, 16 spp, seeds 1-5,
// against 4096-spp references) denoised / raw of 0.070-0.083 on the Cornell box and 0.13-0.17 on
// the SheenChair (0.042 on the shared CornellBox.glb, one seed against 1024 spp); half leaves a
// factor of 3 or more for other noise (kernel changes move the samples), other OIDN 2.x versions
// and devices. The 1024-spp reference's own relMSE (about 2e-4 and 1.2e-4: a quarter of the
// denoised images' errors, a twentieth of the raw ones') is subtracted on average (v_r above), and
// what is left of it shifts raw and denoised alike.
constexpr double kMargin = 2.0;

TEST_F(DenoiseAccuracy, CornellBoxDenoisedIsCloserToTheReference) {
  WP_REQUIRE_OIDN();
  const auto [raw, denoised] = measure(cornell());
  EXPECT_LT(denoised * kMargin, raw);
}

// The shared models' Cornell box (glTF from bevy, an emissive ceiling lamp): a second shared model
// beside the chair. Measured ratio in docs/denoise.md.
TEST_F(DenoiseAccuracy, SharedCornellBoxDenoisedIsCloserToTheReference) {
  WP_REQUIRE_OIDN();
  WP_REQUIRE_MODEL(box, "CornellBox/CornellBox.glb");
  const auto [raw, denoised] = measure(quoted(box));
  EXPECT_LT(denoised * kMargin, raw);
}

// A textured model (fabric and wood textures, normal maps, sheen) lit by an environment map:
// the denoiser must not trade the noise for lost texture detail.
TEST_F(DenoiseAccuracy, TexturedSheenChairDenoisedIsCloserToTheReference) {
  WP_REQUIRE_OIDN();
  WP_REQUIRE_MODEL(chair, "SheenChair/SheenChair.gltf");
  const fs::path env = fs::path(wp::test::assets_dir()) / "env/empty_warehouse_01_1k.hdr";
  if (!fs::exists(env)) GTEST_SKIP() << "asset not found: " << env;
  const auto [raw, denoised] = measure(quoted(chair) + " --env " + quoted(env.string()));
  EXPECT_LT(denoised * kMargin, raw);
}

}  // namespace
