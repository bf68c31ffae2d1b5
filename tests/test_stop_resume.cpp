// Renders that stop early and go on: --time-limit, --noise-threshold, --checkpoint with SIGINT /
// SIGTERM, --resume, and the progress lines, through the command line as users run it. Every
// early stop is checked against an uninterrupted render of the samples it reports, bit for bit
// (films are integer sums, host/film/film.h).
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "host/film/film.h"
#include "host/film/image_io.h"
#include "host/render/render.h"
#include "tests/cli_run.h"
#include "tests/test_assets.h"

namespace {

namespace fs = std::filesystem;
using wp::test::CliRun;
using wp::test::json_number;
using wp::test::slurp;

class StopResume : public wp::test::FolderTest {
 protected:
  // The Cornell box at 24 x 16: about a millisecond per pass on PoCL here.
  static std::string scene_args() {
    return "render '" + wp::test::source_path("scenes/cornell_box.gltf") +
           "' --width 24 --height 16 ";
  }
  CliRun run(const std::string& args) const { return wp::test::run_wavepath(dir_, args); }
  std::set<std::string> files() const {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.insert(e.path().filename().string());
    return names;
  }

  // Renders samples 0:n uninterrupted to ref.pfm and ref.wpfilm, and expects `pfm` and `film` (in
  // the folder) to be the same image and the same sums, bit for bit.
  void expect_same_as_render_of(int n, const std::string& pfm, const std::string& film) const {
    const CliRun r =
        run(scene_args() + "--spp " + std::to_string(n) + " -q -o ref.pfm -o ref.wpfilm");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(slurp(path(pfm)), slurp(path("ref.pfm"))) << pfm << " vs " << n << " samples";
    const wp::Film a = wp::Film::read(path(film)), b = wp::Film::read(path("ref.wpfilm"));
    EXPECT_TRUE(a.words() == b.words()) << film << " vs " << n << " samples";
    EXPECT_EQ(a.info().sample_end, std::uint32_t(n));
  }

  // Starts `wavepath args` in the folder, stdout and stderr to out.txt and err.txt.
  pid_t spawn(const std::vector<std::string>& args) const {
    const pid_t pid = ::fork();
    if (pid == 0) {
      if (::chdir(dir_.c_str()) != 0) ::_exit(126);
      const int out = ::open("out.txt", O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int err = ::open("err.txt", O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(out, 1);
      ::dup2(err, 2);
      std::vector<char*> argv{const_cast<char*>(WP_WAVEPATH_BIN)};
      for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      ::execv(WP_WAVEPATH_BIN, argv.data());
      ::_exit(127);
    }
    return pid;
  }

  // Renders (for a very long time) with a checkpoint after every pass; once the checkpoint exists
  // (the passes run), sends `sig`. Returns the exit status (-1: not a normal exit).
  int render_and_interrupt(int sig) const {
    const pid_t pid =
        spawn({"render", wp::test::source_path("scenes/cornell_box.gltf"), "--width", "24",
               "--height", "16", "--spp", "1048576", "--checkpoint", "ck.wpfilm",
               "--checkpoint-every", "0", "--json", "-o", "img.pfm", "-o", "img.exr"});
    EXPECT_GT(pid, 0);
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (!fs::exists(dir_ / "ck.wpfilm") && std::chrono::steady_clock::now() < give_up)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    std::this_thread::sleep_for(std::chrono::milliseconds(200));  // a few checkpoints more
    ::kill(pid, sig);
    int raw = 0;
    ::waitpid(pid, &raw, 0);
    return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  }
};

// The first pass of a render always runs; no later one starts once the limit has passed. 1 ms
// passes before the first pass ends (loading and the OpenCL set-up alone take longer), so
// exactly one pass is rendered: the 100 samples a wave of 38,400 paths holds of the image's 384
// pixels. The wave is set, not the device's: a CPU whose cache gives a wave of 2^20 paths holds
// all 1000 samples in one pass (it then ends "complete", not "time_limit").
TEST_F(StopResume, TimeLimitAlwaysRendersTheFirstPass) {
  const CliRun r =
      run(scene_args() + "--spp 1000 --wave-size 38400 --time-limit 0.001 --json -q -o t.pfm");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(json_number(r.out, "passes"), 1) << r.out;
  EXPECT_EQ(json_number(r.out, "wave_size"), 38400) << r.out;
  EXPECT_EQ(json_number(r.out, "spp"), 100) << r.out;
  EXPECT_NE(r.out.find("\"stop\":\"time_limit\""), std::string::npos) << r.out;
  EXPECT_EQ(json_number(r.out, "spp_requested"), 1000) << r.out;
}

// WAVEPATH_WAVE_SIZE stands for --wave-size where none is given (the tests' second machine shape,
// .ci/run): 1000 paths hold two samples of the 384 pixels, so 5 samples take 3 passes; an explicit
// --wave-size wins over it; a value that is not a whole number in [1, 2^24] is one error line.
TEST_F(StopResume, EnvironmentWaveSizeStandsForTheOption) {
  CliRun r = wp::test::run_wavepath(dir_, scene_args() + "--spp 5 --json -q -o t.pfm",
                                    "WAVEPATH_WAVE_SIZE=1000");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(json_number(r.out, "wave_size"), 768) << r.out;
  EXPECT_EQ(json_number(r.out, "passes"), 3) << r.out;
  r = wp::test::run_wavepath(dir_, scene_args() + "--spp 5 --wave-size 384 --json -q -o t.pfm",
                             "WAVEPATH_WAVE_SIZE=1000");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(json_number(r.out, "passes"), 5) << r.out;
  for (const char* bad : {"0", "-5", "12x", "16777217"}) {
    r = wp::test::run_wavepath(dir_, scene_args() + "--spp 5 -q -o bad.pfm",
                               std::string("WAVEPATH_WAVE_SIZE=") + bad);
    EXPECT_EQ(r.status, 1) << bad;
    EXPECT_NE(r.err.find(std::string("WAVEPATH_WAVE_SIZE=") + bad + ": must be a whole number"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "bad.pfm")) << bad;
  }
}

// Pixel samples per second are spp x pixels / seconds, also where a pass (a wave) holds several
// samples of each of the 384 pixels: then passes < spp, and counting passes as samples (as
// wavepath once did) under-reports by spp / passes. The JSON prints %.6g: each figure within
// 5e-6 of its value, so the product within 1.1e-5.
TEST_F(StopResume, SamplesPerSecondCountsPixelSamples) {
  // --wave-size and the passes 12 samples take: 4608 slots hold all 12, 384 one.
  for (const auto& [wave, passes] : std::vector<std::pair<std::string, int>>{
           {"--wave-size 4608 ", 1}, {"--wave-size 384 ", 12}, {"--wave-size 1536 ", 3}}) {
    const CliRun r = run(scene_args() + wave + "--spp 12 --json -q -o t.pfm");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(json_number(r.out, "passes"), passes) << wave << r.out;
    EXPECT_EQ(json_number(r.out, "samples_rendered"), 12) << r.out;
    EXPECT_NEAR(json_number(r.out, "samples_per_second") * json_number(r.out, "seconds"),
                12.0 * 24 * 16, 1.1e-5 * 12 * 24 * 16)
        << wave << r.out;
  }
}

// A 2 s limit on a render of 2^20 passes (about 20 minutes here): it stops at a pass boundary,
// long before, with an image exactly that of its samples. The upper bound on its time is loose
// (the limit plus 10 s, for a loaded machine; a pass takes milliseconds): it tells a stop from
// a render that ran on, not how precisely the limit is kept.
TEST_F(StopResume, TimeLimitStopsWithTheSamplesDone) {
  const CliRun r =
      run(scene_args() + "--spp 1048576 --time-limit 2 --json -q -o t.pfm -o t.wpfilm -o t.exr");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("\"stop\":\"time_limit\""), std::string::npos) << r.out;
  const double spp = json_number(r.out, "spp");
  EXPECT_GE(spp, 1);
  EXPECT_LT(spp, 1048576);
  EXPECT_LT(json_number(r.out, "total_seconds"), 2.0 + 10.0) << r.out;
  const auto attributes = wp::read_exr_attributes(path("t.exr"));
  EXPECT_EQ(attributes.at("wavepath:stop"), "time_limit");
  EXPECT_EQ(attributes.at("wavepath:spp"), std::to_string(int(spp)));
  expect_same_as_render_of(int(spp), "t.pfm", "t.wpfilm");
}

// The estimator (film.h, relative_error) against the error the image really has: four 64-sample
// renders (seeds 1-4) against a 8192-sample reference (seed 99, whose own variance adds 64/8192
// = 0.8% to the measured squared error). The squared error of one render, a mean over 384
// pixels' chi-square-like terms, scattered by about 16% between seeds here (relative errors
// 0.125-0.156 against estimates of 0.141-0.145); the mean of four by about 8%, so the measured
// mean square may differ from the estimated one by 30% (about 4 standard deviations) at most.
// That is with independent samples, which the estimator assumes. With Sobol' points (the
// default) the pixels' sample variance overstates their error, so the estimate is an upper
// bound: measured / estimated <= 1.3.
TEST_F(StopResume, RelativeErrorEstimatesTheErrorAgainstAReference) {
  ASSERT_EQ(
      run(scene_args() + "--spp 8192 --seed 99 --sampler independent -q -o ref.wpfilm").status, 0);
  const wp::FilmImages ref = wp::Film::read(path("ref.wpfilm")).images();
  double eps = 0;
  for (const float v : ref.mean) eps += v;
  eps = 0.01 * eps / double(ref.mean.size());
  for (const char* sampler : {"independent", "sobol"}) {
    double measured = 0, estimated = 0;
    for (int seed = 1; seed <= 4; ++seed) {
      const CliRun r = run(scene_args() + "--spp 64 -q -o s.wpfilm --sampler " + sampler +
                           " --seed " + std::to_string(seed));
      ASSERT_EQ(r.status, 0) << r.err;
      const wp::FilmImages x = wp::Film::read(path("s.wpfilm")).images();
      double sum = 0;
      for (std::size_t i = 0; i + 2 < x.mean.size(); i += 3) {
        double err = 0, value = 3 * eps * eps;
        for (std::size_t c = i; c < i + 3; ++c) {
          err += (double(x.mean[c]) - ref.mean[c]) * (double(x.mean[c]) - ref.mean[c]);
          value += double(ref.mean[c]) * ref.mean[c];
        }
        sum += err / value;
      }
      measured += sum / double(x.mean.size() / 3) / 4;
      estimated += wp::relative_error(x) * wp::relative_error(x) / 4;
    }
    std::printf("%s: measured relMSE %g, estimated %g, ratio %.3f\n", sampler, measured, estimated,
                measured / estimated);
    if (std::string(sampler) == "independent")
      EXPECT_NEAR(measured / estimated, 1.0, 0.3)
          << "measured relMSE " << measured << ", estimated " << estimated;
    else
      EXPECT_LE(measured / estimated, 1.3)
          << "measured relMSE " << measured << ", estimated " << estimated;
  }
}

// relative_error's formula on images with known values: one pixel of mean (1, 2, 2) and
// variances (0.01, 0.02, 0.03) and one black pixel with variance 0: eps = 0.01 * 5/6, and the
// mean of 0.06 / (9 + 3 eps^2) and 0 / (3 eps^2).
TEST(RelativeError, Formula) {
  wp::FilmImages images;
  images.mean = {1, 2, 2, 0, 0, 0};
  images.variance = {0.01f, 0.02f, 0.03f, 0, 0, 0};
  const double eps = 0.01 * 5.0 / 6.0;
  EXPECT_NEAR(wp::relative_error(images), std::sqrt(0.06 / (9 + 3 * eps * eps) / 2), 1e-8);
  images.mean.assign(6, 0.0f);  // black: nothing to be relative to
  EXPECT_EQ(wp::relative_error(images), 0.0);
}

// It stops at the first check (16 samples, then at the counts the 1/sqrt(n) decay predicts)
// where the estimate is at most the threshold, with the estimate reported, and the image of
// exactly its samples.
TEST_F(StopResume, NoiseThresholdStopsOnceTheEstimateIsBelowIt) {
  const CliRun r =
      run(scene_args() + "--spp 100000 --noise-threshold 0.05 --json -q -o n.pfm -o n.wpfilm");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("\"stop\":\"noise_threshold\""), std::string::npos) << r.out;
  const double spp = json_number(r.out, "spp");
  EXPECT_GE(spp, wp::kNoiseMinSamples);
  EXPECT_LT(spp, 100000);
  const wp::Film film = wp::Film::read(path("n.wpfilm"));
  const double e = wp::relative_error(film.images());
  EXPECT_LE(e, 0.05);
  EXPECT_NEAR(json_number(r.out, "relative_error"), e, 1e-5 * e);
  expect_same_as_render_of(int(spp), "n.pfm", "n.wpfilm");
  // A threshold the requested samples cannot reach: all of them are rendered.
  const CliRun all = run(scene_args() + "--spp 20 --noise-threshold 0.001 --json -q -o a.pfm");
  ASSERT_EQ(all.status, 0) << all.err;
  EXPECT_EQ(json_number(all.out, "spp"), 20) << all.out;
  EXPECT_NE(all.out.find("\"stop\":\"complete\""), std::string::npos) << all.out;
}

// SIGINT while the passes run: the render ends after the current pass, writes every output and
// the checkpoint with the samples done, exits with 130, and leaves no temporary file. Resumed up
// to more samples, it gives the uninterrupted render's image and film, bit for bit.
TEST_F(StopResume, InterruptedRenderKeepsItsWorkAndResumesExactly) {
  ASSERT_EQ(render_and_interrupt(SIGINT), 130) << slurp(dir_ / "err.txt");
  const std::string err = slurp(dir_ / "err.txt"), out = slurp(dir_ / "out.txt");
  EXPECT_NE(err.find("wavepath: interrupted by SIGINT after"), std::string::npos) << err;
  EXPECT_NE(out.find("\"stop\":\"interrupted\""), std::string::npos) << out;
  EXPECT_EQ(files(),
            (std::set<std::string>{"ck.wpfilm", "img.pfm", "img.exr", "out.txt", "err.txt"}));
  const wp::Film ck = wp::Film::read(path("ck.wpfilm"));
  const int done = int(ck.info().sample_end);
  EXPECT_EQ(json_number(out, "spp"), done) << out;
  ASSERT_GE(done, 1);
  EXPECT_EQ(wp::read_exr_attributes(path("img.exr")).at("wavepath:stop"), "interrupted");

  // The image written is the checkpoint's; going on to done + 7 samples from it (replacing the
  // checkpoint as it goes) equals one render of done + 7 samples. A wave of the image's 384
  // pixels holds one sample, so the 7 new samples take 7 passes (a restart would take done + 7).
  expect_same_as_render_of(done, "img.pfm", "ck.wpfilm");
  const std::string more = std::to_string(done + 7);
  const CliRun r = run(scene_args() + "--spp " + more +
                       " --wave-size 384 --resume ck.wpfilm --checkpoint ck.wpfilm --json -q -o "
                       "res.pfm");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(json_number(r.out, "passes"), 7) << r.out;
  EXPECT_EQ(json_number(r.out, "spp"), done + 7) << r.out;
  // Throughput counts the samples this run rendered, not the resumed ones (%.6g: each printed
  // figure within 5e-6 of its value, so the product within 1.1e-5).
  EXPECT_EQ(json_number(r.out, "samples_rendered"), 7) << r.out;
  EXPECT_NEAR(json_number(r.out, "samples_per_second") * json_number(r.out, "seconds"),
              7.0 * 24 * 16, 1.1e-5 * 7 * 24 * 16)
      << r.out;
  expect_same_as_render_of(done + 7, "res.pfm", "ck.wpfilm");
}

TEST_F(StopResume, SigtermAlsoStopsGently) {
  ASSERT_EQ(render_and_interrupt(SIGTERM), 128 + SIGTERM) << slurp(dir_ / "err.txt");
  EXPECT_NE(slurp(dir_ / "err.txt").find("interrupted by SIGTERM"), std::string::npos);
  EXPECT_EQ(files(),
            (std::set<std::string>{"ck.wpfilm", "img.pfm", "img.exr", "out.txt", "err.txt"}));
  EXPECT_GE(wp::Film::read(path("ck.wpfilm")).info().sample_end, 1u);
}

// A film is only continued by the render it came from, from its first sample, to as many
// samples or more; anything else is one line and status 1, with no output written.
TEST_F(StopResume, ResumeRefusesAnotherRender) {
  ASSERT_EQ(run(scene_args() + "--spp 5 -q -o ck.wpfilm").status, 0);
  for (const auto& [args, cause] : std::vector<std::pair<std::string, std::string>>{
           {"--spp 9 --seed 3", "seed=0 vs seed=3"},
           {"--spp 9 --max-depth 3", "max_depth"},
           {"--spp 4", "holds samples 0:5, not the start of the requested 0:4"},
           {"--samples 1:9", "not the start of the requested 1:9"},
       }) {
    const CliRun r = run(scene_args() + args + " --resume ck.wpfilm -q -o x.pfm");
    EXPECT_EQ(r.status, 1) << args;
    EXPECT_EQ(r.err.rfind("wavepath: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(cause), std::string::npos) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "x.pfm")) << args;
  }
  // The other size is refused too; a film that is not one, as any malformed .wpfilm.
  const CliRun size = run("render '" + wp::test::source_path("scenes/cornell_box.gltf") +
                          "' --width 8 --height 8 --spp 9 --resume ck.wpfilm -q -o x.pfm");
  EXPECT_EQ(size.status, 1) << size.err;
  std::ofstream(dir_ / "bad.wpfilm") << "wavepath-film\n{}";
  const CliRun bad = run(scene_args() + "--spp 9 --resume bad.wpfilm -q -o x.pfm");
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("bad.wpfilm"), std::string::npos) << bad.err;
}

TEST_F(StopResume, BadOptionValues) {
  for (const std::string args :
       {"--time-limit -1", "--time-limit nan", "--time-limit 1e12", "--noise-threshold -0.1",
        "--noise-threshold inf", "--checkpoint c.exr", "--checkpoint-every 5",
        "--checkpoint ck.wpfilm --checkpoint-every -1", "--checkpoint nofolder/ck.wpfilm",
        "--progress-every -2", "--resume missing.wpfilm"}) {
    const CliRun r = run(scene_args() + "--spp 2 -q -o x.pfm " + args);
    EXPECT_EQ(r.status, 1) << args;
    EXPECT_EQ(r.err.rfind("wavepath: error: ", 0), 0u) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
    EXPECT_EQ(files(), std::set<std::string>{}) << args;
  }
}

// Without a terminal (here a file), one progress line per --progress-every seconds; with 0, one
// per pass (here one sample each: a wave of the image's 384 pixels); then the summary naming every
// file written. --quiet prints nothing.
TEST_F(StopResume, ProgressLinesInALog) {
  const CliRun r =
      run(scene_args() + "--spp 5 --wave-size 384 --progress-every 0 -o a.pfm -o b.exr");
  ASSERT_EQ(r.status, 0) << r.err;
  for (int i = 1; i <= 5; ++i)
    EXPECT_NE(r.err.find("wavepath: " + std::to_string(i) + "/5 spp ("), std::string::npos)
        << r.err;
  EXPECT_NE(r.err.find("samples/s"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("ETA"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("wrote a.pfm, b.exr"), std::string::npos) << r.err;
  const CliRun quiet = run(scene_args() + "--spp 5 --progress-every 0 -q -o a.pfm");
  EXPECT_EQ(quiet.err, "");
  // The default (10 s) prints no progress line for a render this short.
  const CliRun log = run(scene_args() + "--spp 5 -o a.pfm");
  EXPECT_EQ(log.err.find("/5 spp ("), std::string::npos) << log.err;
}

}  // namespace
