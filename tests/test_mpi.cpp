// Distributed rendering (host/cli/distributed.h): `mpirun -np 3 wavepath render` on one machine
// gives the single process's image and film bit for bit, also with more ranks than samples, and a
// failure on any rank ends the whole job with a non-zero status instead of a hang. Skips only when
// the build has no MPI or its launcher is gone (tools/setup.sh installs Open MPI).
#include <unistd.h>

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "host/film/film.h"
#include "tests/cli_run.h"
#include "tests/test_assets.h"

namespace {

namespace fs = std::filesystem;

// Open MPI's flags: three ranks whatever the number of cores, as root in containers, and no
// stdin (forwarding it delays the end of an aborted job by seconds). The whole job is bounded by
// `timeout`, so that a rank left waiting fails the test (status 124).
constexpr int kRanks = 3;
constexpr const char* kTimeoutSeconds = "120";

class Mpi : public ::testing::Test {
 protected:
  void SetUp() override {
#ifndef WP_HAVE_MPI
    GTEST_SKIP() << "wavepath was built without MPI (install libopenmpi-dev openmpi-bin, as "
                    "tools/setup.sh does, and configure again)";
#endif
    if (std::string(WP_MPIEXEC).empty() || access(WP_MPIEXEC, X_OK) != 0)
      GTEST_SKIP() << "no MPI launcher (mpiexec: '" WP_MPIEXEC "')";
    dir_ = fs::temp_directory_path() / ("wavepath_mpi_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }

  static std::string render_args() {
    return "render '" + wp::test::source_path("scenes/cornell_box.gltf") +
           "' --width 24 --height 16 -q ";
  }
  wp::test::CliRun single(const std::string& args) {
    return wp::test::run_wavepath(dir_, args);
  }
  wp::test::CliRun ranks(const std::string& args) {
    const std::string launcher = std::string("timeout ") + kTimeoutSeconds +
                                 " '" WP_MPIEXEC
                                 "' --oversubscribe --allow-run-as-root --stdin none -np " +
                                 std::to_string(kRanks);
    wp::test::CliRun r = wp::test::run_wavepath(dir_, args, launcher);
    EXPECT_NE(r.status, 124) << "mpirun timed out: " << r.err;
    return r;
  }
  std::string path(const std::string& name) const {
    return (dir_ / name).string();
  }

  // The same samples rendered by one process and by kRanks: films and images equal bit for bit.
  // Returns the ranks' JSON report.
  std::string expect_same_render(const std::string& samples,
                                 const std::string& render = render_args()) {
    SCOPED_TRACE(samples);
    const wp::test::CliRun one = single(render + samples + " -o one.pfm -o one.wpfilm");
    EXPECT_EQ(one.status, 0) << one.err;
    const wp::test::CliRun many = ranks(render + samples + " -o many.pfm -o many.wpfilm --json");
    EXPECT_EQ(many.status, 0) << many.err;
    if (one.status != 0 || many.status != 0) return many.out;
    // Ranks other than 0 print nothing, not even JSON; with -q rank 0 prints only the JSON.
    EXPECT_EQ(many.err.find("wavepath"), std::string::npos) << many.err;
    EXPECT_EQ(many.out.find('{'), many.out.rfind('{')) << many.out;
    EXPECT_NE(many.out.find("\"ranks\":" + std::to_string(kRanks)), std::string::npos) << many.out;

    EXPECT_EQ(wp::test::slurp(path("many.pfm")), wp::test::slurp(path("one.pfm")));
    const wp::Film a = wp::Film::read(path("one.wpfilm")), b = wp::Film::read(path("many.wpfilm"));
    EXPECT_TRUE(a.words() == b.words());
    EXPECT_EQ(a.info().sample_begin, b.info().sample_begin);
    EXPECT_EQ(a.info().sample_end, b.info().sample_end);
    EXPECT_EQ(a.info().key, b.info().key);
    // Every rank on the one device of this machine: the films' files are equal too.
    if (a.info().device == b.info().device) {
      EXPECT_EQ(wp::test::slurp(path("many.wpfilm")), wp::test::slurp(path("one.wpfilm")));
    }
    return many.out;
  }

  fs::path dir_;
};

TEST_F(Mpi, RanksRenderTheSingleProcessImageBitForBit) {
  expect_same_render("--spp 7");
  const wp::test::CliRun json = single(render_args() + "--spp 1 -o json.pfm --json");
  ASSERT_EQ(json.status, 0) << json.err;
  EXPECT_NE(json.out.find("\"ranks\":1"), std::string::npos) << json.out;
}

// Two samples for three ranks: the last rank has none and waits for the others; and a range that
// does not start at 0 is split from its own start.
TEST_F(Mpi, MoreRanksThanSamples) {
  expect_same_render("--samples 3:5");
}

// An instanced scene (SimpleInstancing: one cube placed by 125 EXT_mesh_gpu_instancing instances,
// rendered through the two-level BVH) under a white sky: the same bit for bit.
TEST_F(Mpi, InstancedSceneRanksRenderTheSingleProcessImageBitForBit) {
  WP_REQUIRE_MODEL(model, "SimpleInstancing/SimpleInstancing.glb");
  const std::string json = expect_same_render(
      "--spp 5", "render '" + model + "' --env-color 1,1,1 --width 24 --height 16 -q ");
  EXPECT_NE(json.find("\"instances\":125"), std::string::npos) << json;
  const wp::Film film = wp::Film::read(path("many.wpfilm"));
  EXPECT_NE(film.info().key.find(";instances=125"), std::string::npos) << film.info().key;
}

TEST_F(Mpi, AFailureEndsEveryRank) {
  // Every rank fails alike: one message, as from one process.
  const wp::test::CliRun missing = ranks("render missing.gltf -q -o m.pfm");
  EXPECT_NE(missing.status, 0);
  const std::string error = "wavepath: error: missing.gltf: no such file";
  ASSERT_NE(missing.err.find(error), std::string::npos) << missing.err;
  EXPECT_EQ(missing.err.find(error), missing.err.rfind(error)) << "repeated: " << missing.err;

  // Only rank 0 writes outputs, so only it fails; the others stop before rendering.
  const wp::test::CliRun unwritable = ranks(render_args() + "--spp 3 -o nowhere/x.pfm");
  EXPECT_NE(unwritable.status, 0);
  EXPECT_NE(unwritable.err.find("wavepath: error: rank 0: nowhere/x.pfm: folder nowhere does not "
                                "exist"),
            std::string::npos)
      << unwritable.err;
  EXPECT_FALSE(fs::exists(path("nowhere")));

  // Adaptive stops and checkpoints are refused under MPI (each rank would stop elsewhere).
  for (const std::string option :
       {"--time-limit 5", "--noise-threshold 0.1", "--checkpoint c.wpfilm", "--resume c.wpfilm"}) {
    const wp::test::CliRun r = ranks(render_args() + "--spp 3 -q -o y.pfm " + option);
    EXPECT_NE(r.status, 0) << option;
    EXPECT_NE(r.err.find("do not work under MPI yet"), std::string::npos)
        << option << ": " << r.err;
    EXPECT_FALSE(fs::exists(path("y.pfm"))) << option;
  }
}

}  // namespace
