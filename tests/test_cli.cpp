// The command line, run as a user runs it: each documented bad input gives one clear line on
// stderr naming the cause and a non-zero exit, leaves no output file and overwrites nothing; a good
// run writes both images, records its settings in the EXR header and prints JSON.
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <png.h>

#include "host/film/image_io.h"
#include "tests/cli_run.h"
#include "tests/test_assets.h"

namespace fs = std::filesystem;

namespace {

using wp::test::CliRun;
using wp::test::slurp;

class Cli : public wp::test::FolderTest {
 protected:
  // Runs `wavepath args` in the test's folder with extra environment `env`.
  CliRun run(const std::string& args, const std::string& env = "") {
    return wp::test::run_wavepath(dir_, args, env);
  }

  // Asserts a failure with one line on stderr that contains `cause`, and no image left behind.
  void expect_error(const CliRun& r, const std::string& cause) {
    EXPECT_NE(r.status, 0) << r.err;
    EXPECT_NE(r.err.find(cause), std::string::npos) << "stderr: " << r.err;
    const auto first_newline = r.err.find('\n');
    EXPECT_TRUE(first_newline == std::string::npos || first_newline == r.err.size() - 1)
        << "more than one line: " << r.err;
    for (const auto& e : fs::directory_iterator(dir_)) {
      const std::string name = e.path().filename().string();
      EXPECT_TRUE(name == "keep.exr" || name == "scene.gltf" || name == "kernels")
          << "left behind: " << name;
    }
  }

  std::string cornell() const { return wp::test::source_path("scenes/cornell_box.gltf"); }
};

TEST_F(Cli, HelpDescribesRenderOptions) {
  const CliRun r = run("render --help");
  EXPECT_EQ(r.status, 0);
  for (const char* opt :
       {"--width", "--height", "--spp", "--camera", "--env-color", "--max-depth", "--seed",
        "--device", "--json", "--output", "--look-from", "--look-at", "--up", "--orbit", "--fov",
        "--aperture", "--focus-distance", "--focus-on"})
    EXPECT_NE(r.out.find(opt), std::string::npos) << opt;
}

TEST_F(Cli, DevicesListsAtLeastOneDevice) {
  const CliRun r = run("devices");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("default:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("OpenCL C"), std::string::npos) << r.out;
}

TEST_F(Cli, MissingSceneFile) {
  expect_error(run("render nope.gltf"), "nope.gltf");
}

TEST_F(Cli, MalformedScene) {
  std::ofstream(dir_ / "scene.gltf") << "{ this is not json";
  expect_error(run("render scene.gltf"), "scene.gltf");
}

TEST_F(Cli, BadOptionValues) {
  expect_error(run("render '" + cornell() + "' --width 0"), "--width");
  expect_error(run("render '" + cornell() + "' --spp 0"), "--spp");
  expect_error(run("render '" + cornell() + "' --height abc"), "height");
  expect_error(run("render '" + cornell() + "' --env-color 1,2"), "env-color");
  expect_error(run("render '" + cornell() + "' --env-color 1,-2,3"), "--env-color");
  expect_error(run("render '" + cornell() + "' --max-depth -1"), "--max-depth");
  expect_error(run("render '" + cornell() + "' --camera 7"), "--camera 7");
  expect_error(run("render '" + cornell() + "' --device 99"), "--device 99");
  expect_error(run("render '" + cornell() + "' --device no-such-device"), "no-such-device");
  expect_error(run("render '" + cornell() + "' -o out.jpg"), "out.jpg");
  expect_error(run("render '" + cornell() + "' -o missing_dir/out.exr"), "missing_dir");
  expect_error(run("render '" + cornell() + "' --features some"), "features");
  // The view (host/scene/view.h; its checks one by one in test_view): refused before rendering.
  expect_error(run("render '" + cornell() + "' --look-from 0,1,5"), "--look-at go together");
  expect_error(run("render '" + cornell() + "' --orbit 10"), "--orbit");
  expect_error(run("render '" + cornell() + "' --camera 0 --orbit 0,90"), "--camera and");
  expect_error(run("render '" + cornell() + "' --fov 0"), "--fov");
  expect_error(run("render '" + cornell() + "' --orbit 0,90 --aperture 0.1 --focus-on 0,0,50"),
               "not in front of the camera");
}

// CLI11's own exit codes (104, 106, ...) are not the documented 1; help and version still exit 0.
TEST_F(Cli, ParseErrorsExitWithStatusOne) {
  const std::string scene = "render '" + cornell() + "' ";
  for (const std::string& args :
       {scene + "--height abc", scene + "--spp 1.5", scene + "--no-such-option", scene + "--seed",
        scene + "--env-color 1,2", scene + "--tonemap sepia", std::string("render"),
        std::string(""), std::string("frobnicate")}) {
    const CliRun r = run(args);
    EXPECT_EQ(r.status, 1) << args << ": " << r.err;
    EXPECT_EQ(r.err.rfind("wavepath: error: ", 0), 0u) << args << ": " << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << args << ": " << r.err;
  }
  EXPECT_EQ(run("render --help").status, 0);
  EXPECT_EQ(run("--version").status, 0);
}

// Values CLI11 parses but wavepath cannot use: refused with status 1 before anything is loaded.
TEST_F(Cli, OutOfRangeOptionValues) {
  const std::string scene = "render '" + cornell() + "' ";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--camera -1", "--camera -1"},
      {"--camera 1", "--camera 1: the scene has 1 camera"},
      {"--exposure nan", "--exposure"},
      {"--exposure inf", "--exposure"},
      {"--exposure 1e6", "--exposure"},
      {"--spp 2000000", "--spp"},
      {"--local-size 4096", "--local-size"},
      {"--wave-size 100000000", "--wave-size"},
      {"--scene-buffer-kib 0", "--scene-buffer-kib"},
      {"--scene-buffer-kib 40000000", "--scene-buffer-kib"},
      // Not wrong, but the Cornell box's BVH does not fit in one KiB: the device's limit, named.
      {"--scene-buffer-kib 1", "scene too large for the device: its BVH triangle array needs"}};
  for (const auto& [args, cause] : cases) {
    const CliRun r = run(scene + args + " --width 8 --height 8 --spp 1");
    EXPECT_EQ(r.status, 1) << args;
    expect_error(r, cause);
  }
}

// An output that cannot be written is found before rendering: the folder is not writable, the
// output is a folder, or an existing file is not writable (which would otherwise be replaced).
// As root, permissions bind only when wavepath runs as another user: setpriv drops to nobody.
TEST_F(Cli, UnwritableOutputFailsBeforeRendering) {
  const std::string scene = "render '" + cornell() + "' --width 8 --height 8 --spp 1 ";
  fs::create_directories(dir_ / "keep.exr");
  expect_error(run(scene + "-o keep.exr"), "keep.exr: is a directory");
  fs::remove(dir_ / "keep.exr");

  std::string as_user;
  if (::geteuid() == 0) {
    if (!fs::exists("/usr/bin/setpriv")) GTEST_SKIP() << "root without setpriv";
    as_user = "/usr/bin/setpriv --reuid=65534 --regid=65534 --clear-groups";
  }
  // A folder ("kernels", which expect_error allows) not writable by the user wavepath runs as.
  const fs::path sub = dir_ / "kernels";
  fs::create_directories(sub);
  fs::permissions(sub, fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                           fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  expect_error(run(scene + "-o kernels/out.exr", as_user), "kernels is not writable");
  // Writable by all now, holding a read-only file.
  fs::permissions(sub, fs::perms::all);
  std::ofstream(sub / "keep.exr") << "old";
  fs::permissions(sub / "keep.exr",
                  fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  expect_error(run(scene + "-o kernels/keep.exr", as_user),
               "kernels/keep.exr: the existing file is not writable");
  EXPECT_EQ(slurp(sub / "keep.exr"), "old");
  EXPECT_EQ(std::distance(fs::directory_iterator(sub), fs::directory_iterator()), 1);
}

// SIGTERM while the outputs are written: the temporary files are removed and the process dies of
// the signal; no output appears. A forked writer of a large noisy image (slow to compress) is
// signalled as soon as its first temporary file exists.
TEST_F(Cli, InterruptedWriteLeavesNoTemporaryFile) {
  wp::ImageRgb img;
  img.width = img.height = 3000;
  img.rgb.resize(3 * std::size_t(img.width) * std::size_t(img.height));
  std::mt19937 rng(1);
  for (float& v : img.rgb) v = std::uniform_real_distribution<float>(0.0f, 4.0f)(rng);
  const std::vector<std::string> outputs = {(dir_ / "big.exr").string(),
                                            (dir_ / "big.png").string()};
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    try {
      wp::write_images(outputs, img, {});
    } catch (...) {
    }
    ::_exit(0);
  }
  const auto temporary = [&] {
    for (const auto& e : fs::directory_iterator(dir_))
      if (e.path().filename().string().find(".tmp") != std::string::npos) return true;
    return false;
  };
  bool seen = false;
  for (int i = 0; i < 20000 && !(seen = temporary()); ++i) ::usleep(500);
  ::kill(child, SIGTERM);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(seen) << "no temporary file appeared";
  ASSERT_TRUE(WIFSIGNALED(status)) << "the writer finished before the signal; status " << status;
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
  for (const auto& e : fs::directory_iterator(dir_))
    ADD_FAILURE() << "left behind: " << e.path().filename();
}

TEST_F(Cli, NoOpenClDevice) {
  // An empty vendor folder: the ICD loader finds no OpenCL implementation.
  fs::create_directories(dir_ / "kernels");
  expect_error(run("render '" + cornell() + "' --spp 1 --width 8 --height 8",
                   "OCL_ICD_VENDORS='" + (dir_ / "kernels").string() + "'"),
               "no OpenCL device");
}

// Texture images are decoded by Debian's libpng and libjpeg-turbo (host/scene/image_decode.cpp),
// not by stb_image, and PNGs are written by Debian's libstb (stb_image_write): libdraco exports a
// copy of stb_image and stb_image_write of its own, which the binary's calls would bind to where
// libdraco comes before libstb on its link line (CMakeLists.txt puts libstb first). The dynamic
// loader says what each of the binary's symbols binds to (glibc's LD_DEBUG, every symbol at start
// with LD_BIND_NOW).
TEST_F(Cli, ImagesThroughDebiansLibraries) {
  const CliRun r = run("--version", "LD_BIND_NOW=1 LD_DEBUG=bindings");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::pair<const char*, const char*> expected[] = {{"`stbi_write_png'", "/libstb.so"},
                                                          {"`png_read_row'", "/libpng16.so"},
                                                          {"`jpeg_read_scanlines'", "/libjpeg.so"}};
  int seen = 0;
  std::istringstream lines(r.err);
  for (std::string line; std::getline(lines, line);) {
    if (line.find("binding file " WP_WAVEPATH_BIN " ") == std::string::npos) continue;
    EXPECT_EQ(line.find("`stbi_load"), std::string::npos) << line;  // no stb_image decoding
    for (const auto& [symbol, library] : expected)
      if (line.find(symbol) != std::string::npos) {
        ++seen;
        EXPECT_NE(line.find(library), std::string::npos) << line;
      }
  }
  EXPECT_EQ(seen, 3) << r.err.substr(0, 2000);
}

TEST_F(Cli, KernelThatFailsToBuild) {
  // WAVEPATH_KERNEL_DIR overrides the embedded kernels; one with a syntax error must fail with
  // the first error line, followed by the build log.
  fs::create_directories(dir_ / "kernels");
  std::ofstream(dir_ / "kernels" / "trace_shadow.cl") << "__kernel void trace_shadow( {\n";
  const CliRun r = run("render '" + cornell() + "' --spp 1 --width 8 --height 8",
                       "WAVEPATH_KERNEL_DIR='" + (dir_ / "kernels").string() + "'");
  EXPECT_NE(r.status, 0);
  EXPECT_EQ(r.err.rfind("wavepath: error: kernel build failed on", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("trace_shadow.cl"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "render.exr"));
  EXPECT_FALSE(fs::exists(dir_ / "render.png"));
}

TEST_F(Cli, FailedRunOverwritesNothing) {
  std::ofstream(dir_ / "keep.exr") << "old";
  expect_error(run("render nope.gltf -o keep.exr"), "nope.gltf");
  EXPECT_EQ(slurp(dir_ / "keep.exr"), "old");
}

// A glTF scene without triangles is valid: it renders the background alone, and exits 0.
TEST_F(Cli, EmptySceneRendersTheBackground) {
  std::ofstream(dir_ / "scene.gltf")
      << R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[]}],"scene":0})";
  const CliRun r = run(
      "render scene.gltf --width 8 --height 6 --spp 1 -o out.exr --env-color 0.25,0.5,1 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_TRUE(fs::exists(dir_ / "out.exr"));
  const wp::ImageRgb img = wp::read_exr((dir_ / "out.exr").string());
  ASSERT_EQ(img.width, 8);
  ASSERT_EQ(img.height, 6);
  const float background[3] = {0.25f, 0.5f, 1.0f};
  for (std::size_t i = 0; i < img.rgb.size(); ++i)
    ASSERT_EQ(img.rgb[i], background[i % 3]) << "value " << i;
  EXPECT_NE(r.out.find("\"triangles\":0"), std::string::npos) << r.out;
}

// --tonemap and --exposure, for render and merge alike: the PNG holds png_encode (tonemap.h, tested
// in test_tonemap) of the linear pixel, for every tonemap. An empty scene gives a uniform image.
TEST_F(Cli, PngTonemaps) {
  std::ofstream(dir_ / "scene.gltf")
      << R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[]}],"scene":0})";
  const wp::Rgb background = {0.25f, 0.5f, 1.0f};
  const std::string common = " --exposure 1.5 --tonemap ";
  ASSERT_EQ(run("render scene.gltf --width 4 --height 2 --spp 1 -o bg.wpfilm -o render.png "
                "--env-color 0.25,0.5,1 -q" +
                common + "agx")
                .status,
            0);
  for (const std::string& name : wp::tonemap_names()) {
    SCOPED_TRACE(name);
    const std::string png = name == "agx" ? "render.png" : name + ".png";
    if (name != "agx") {
      const CliRun r = run("merge bg.wpfilm -o " + png + " -q" + common + name);
      ASSERT_EQ(r.status, 0) << r.err;
    }
    // Read with libpng's simplified API (a decoder independent of stb_image_write, which wrote
    // it): the file has no gAMA, sRGB or iCCP chunk, so 8-bit RGB comes back as it is stored.
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    ASSERT_TRUE(png_image_begin_read_from_file(&image, (dir_ / png).string().c_str()))
        << image.message;
    image.format = PNG_FORMAT_RGB;
    std::vector<unsigned char> got(PNG_IMAGE_SIZE(image));
    ASSERT_TRUE(png_image_finish_read(&image, nullptr, got.data(), 0, nullptr)) << image.message;
    ASSERT_EQ(image.width * image.height, 8u);
    const auto expected = wp::png_encode(background, {1.5f, wp::tonemap_from_name(name)});
    for (std::size_t i = 0; i < got.size(); ++i) ASSERT_EQ(got[i], expected[i % 3]) << i;
  }
}

TEST_F(Cli, RendersBothImagesWithSettingsAndJson) {
  const CliRun r = run("render '" + cornell() + "' --spp 2 --width 32 --height 24 --seed 5 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_TRUE(fs::exists(dir_ / "render.exr"));
  ASSERT_TRUE(fs::exists(dir_ / "render.png"));
  const wp::ImageRgb img = wp::read_exr((dir_ / "render.exr").string());
  EXPECT_EQ(img.width, 32);
  EXPECT_EQ(img.height, 24);
  const auto attrs = wp::read_exr_attributes((dir_ / "render.exr").string());
  EXPECT_EQ(attrs.at("wavepath:spp"), "2");
  EXPECT_EQ(attrs.at("wavepath:seed"), "5");
  // The JSON object is the last line of stdout.
  std::string last = r.out;
  while (!last.empty() && last.back() == '\n') last.pop_back();
  last = last.substr(last.find_last_of('\n') + 1);
  ASSERT_FALSE(last.empty());
  EXPECT_EQ(last.front(), '{');
  EXPECT_EQ(last.back(), '}');
  for (const char* key :
       {"\"spp\":2", "\"width\":32", "\"height\":24",
        "\"seconds\":", "\"samples_per_second\":", "\"device\":", "\"triangles\":",
        "\"kernel_build_seconds\":", "\"bvh_build_seconds\":", "\"nonfinite_samples\":0"})
    EXPECT_NE(last.find(key), std::string::npos) << key << " in " << last;
}

// --variant (KHR_materials_variants): listed in the help; a name the file lacks is a one-line
// error naming the file's variants (or saying it has none), before any device work.
TEST_F(Cli, UnknownMaterialVariantIsAnError) {
  const CliRun help = run("render --help");
  EXPECT_NE(help.out.find("--variant"), std::string::npos);
  expect_error(run("render '" + cornell() + "' --variant red"),
               "no material variant 'red': the file has no variants (KHR_materials_variants)");
  std::ofstream(dir_ / "scene.gltf") << R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[]}],)"
                                        R"("scene":0,"extensionsUsed":["KHR_materials_variants"],)"
                                        R"("extensions":{"KHR_materials_variants":{"variants":[)"
                                        R"({"name":"gold"},{"name":"silver"}]}}})";
  expect_error(run("render scene.gltf --variant bronze"),
               "no material variant 'bronze': the file's variants are 'gold', 'silver'");
}

// Two variants of one file are two scenes: their films do not merge (the render key's scene
// digest differs), while two parts of one variant do; the EXR header names the variant.
TEST_F(Cli, MaterialVariantsAreDifferentRenders) {
  // One triangle in front of the default camera; its material is red, or under "green" green.
  std::ofstream(dir_ / "scene.gltf")
      << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],)"
         R"("nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},)"
         R"("material":0,"extensions":{"KHR_materials_variants":{"mappings":[)"
         R"({"material":1,"variants":[1]}]}}}]}],)"
         R"("materials":[{"emissiveFactor":[1,0,0]},{"emissiveFactor":[0,1,0]}],)"
         R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",)"
         R"("min":[0,0,0],"max":[1,1,0]}],"bufferViews":[{"buffer":0,"byteLength":36}],)"
         R"("buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,)"
         R"(AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],)"
         R"("extensionsUsed":["KHR_materials_variants"],"extensions":{"KHR_materials_variants":)"
         R"({"variants":[{"name":"red"},{"name":"green"}]}}})";
  for (const char* args :
       {"--variant red --samples 0:1 -o red0.wpfilm -o red0.exr",
        "--variant red --samples 1:2 -o red1.wpfilm",
        "--variant green --samples 1:2 -o green1.wpfilm", "--samples 1:2 -o plain1.wpfilm"}) {
    const CliRun r = run(std::string("render scene.gltf --width 8 --height 6 -q ") + args);
    ASSERT_EQ(r.status, 0) << args << ": " << r.err;
  }
  EXPECT_EQ(wp::read_exr_attributes((dir_ / "red0.exr").string()).at("wavepath:variant"), "red");
  const CliRun same = run("merge red0.wpfilm red1.wpfilm -o red.exr");
  EXPECT_EQ(same.status, 0) << same.err;
  for (const char* other : {"green1.wpfilm", "plain1.wpfilm"}) {
    const CliRun r = run(std::string("merge red0.wpfilm ") + other + " -o mixed.exr");
    EXPECT_NE(r.status, 0) << other;
    EXPECT_NE(r.err.find("does not merge"), std::string::npos) << r.err;
  }
}

// The films of an instanced scene merge as any others: two sample ranges of SimpleInstancing (125
// instances of a cube, rendered through the two-level BVH) merge into the film and image of the
// whole range, bit for bit; a film of the same file flattened (--instancing off: the same image to
// float rounding, not bit for bit) is another render and does not merge with them.
TEST_F(Cli, InstancedFilmsMergeBitForBit) {
  WP_REQUIRE_MODEL(model, "SimpleInstancing/SimpleInstancing.glb");
  const std::string render = "render '" + model + "' --env-color 1,1,1 --width 16 --height 12 -q ";
  for (const char* args :
       {"--samples 0:5 -o all.wpfilm -o all.pfm", "--samples 0:2 -o a.wpfilm",
        "--samples 2:5 -o b.wpfilm", "--samples 2:5 --instancing off -o flat.wpfilm"}) {
    const CliRun r = run(render + args);
    ASSERT_EQ(r.status, 0) << args << ": " << r.err;
  }
  const CliRun merged = run("merge a.wpfilm b.wpfilm -o merged.wpfilm -o merged.pfm -q");
  ASSERT_EQ(merged.status, 0) << merged.err;
  EXPECT_EQ(slurp(dir_ / "merged.pfm"), slurp(dir_ / "all.pfm"));
  EXPECT_EQ(slurp(dir_ / "merged.wpfilm"), slurp(dir_ / "all.wpfilm"));
  const CliRun mixed = run("merge a.wpfilm flat.wpfilm -o mixed.pfm");
  EXPECT_NE(mixed.status, 0);
  EXPECT_NE(mixed.err.find("does not merge"), std::string::npos) << mixed.err;
  EXPECT_FALSE(fs::exists(dir_ / "mixed.pfm"));
}

}  // namespace
