// The command line, run as a user runs it: each documented bad input gives one clear line on
// stderr naming the cause and a non-zero exit, leaves no output file and overwrites nothing; a good
// run writes both images, records its settings in the EXR header and prints JSON.
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "host/image_io.h"
#include "tests/test_assets.h"

namespace fs = std::filesystem;

namespace {

struct CliRun {
  int status = -1;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("wavepath_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Runs `wavepath args` in the test's folder with extra environment `env`.
  CliRun run(const std::string& args, const std::string& env = "") {
    const std::string cmd = "cd '" + dir_.string() + "' && " + env + " '" WP_WAVEPATH_BIN "' " +
                            args + " >out.txt 2>err.txt";
    CliRun r;
    const int raw = std::system(cmd.c_str());
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = slurp(dir_ / "out.txt");
    r.err = slurp(dir_ / "err.txt");
    fs::remove(dir_ / "out.txt");
    fs::remove(dir_ / "err.txt");
    return r;
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

  fs::path dir_;
};

TEST_F(Cli, HelpDescribesRenderOptions) {
  const CliRun r = run("render --help");
  EXPECT_EQ(r.status, 0);
  for (const char* opt : {"--width", "--height", "--spp", "--camera", "--env-color", "--max-depth",
                          "--seed", "--device", "--json", "--output"})
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
}

TEST_F(Cli, NoOpenClDevice) {
  // An empty vendor folder: the ICD loader finds no OpenCL implementation.
  fs::create_directories(dir_ / "kernels");
  expect_error(run("render '" + cornell() + "' --spp 1 --width 8 --height 8",
                   "OCL_ICD_VENDORS='" + (dir_ / "kernels").string() + "'"),
               "no OpenCL device");
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

}  // namespace
