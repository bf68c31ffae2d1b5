// The pipeline table (host/render/pipeline.h): its rules hold for both pipelines, and
// docs/architecture.md shows the table the code runs.
#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "host/render/pipeline.h"

namespace {

using wp::LaunchSize;
using wp::QueueRole;
using wp::Stage;
using wp::Step;

class Pipelines : public ::testing::TestWithParam<bool> {};

// What run_bounce relies on: the queues a step reads were filled earlier in the bounce (or are the
// bounce's rays); the next bounce's rays are pushed by exactly one step; after the read-back (the
// first kQueueLength step) nothing is pushed, so the lengths read then are final.
TEST_P(Pipelines, BounceStepsKeepTheQueueContract) {
  const wp::Pipeline& p = wp::pipeline(GetParam());
  std::set<QueueRole> filled{QueueRole::kRaysIn};
  int ray_pushes = 0;
  bool read_back = false;
  for (const Step& s : p.bounce) {
    SCOPED_TRACE(wp::stage_name(s.stage));
    EXPECT_TRUE(filled.count(s.in)) << "reads a queue nothing filled";
    EXPECT_TRUE(s.size == LaunchSize::kRays || s.size == LaunchSize::kQueueLength);
    read_back = read_back || s.size == LaunchSize::kQueueLength;
    for (const QueueRole out : {s.out, s.out2}) {
      if (out == QueueRole::kNone) continue;
      EXPECT_FALSE(read_back) << "pushes after the read-back";
      EXPECT_NE(out, QueueRole::kRaysIn);
      filled.insert(out);
      ray_pushes += out == QueueRole::kRaysOut;
    }
  }
  EXPECT_TRUE(read_back);
  EXPECT_EQ(ray_pushes, 1);
  EXPECT_EQ(p.start.stage, Stage::kGenerateCameraRays);
  EXPECT_EQ(p.start.out, QueueRole::kRaysIn);
  EXPECT_EQ(p.end.stage, Stage::kAccumulate);
}

INSTANTIATE_TEST_SUITE_P(Both, Pipelines, ::testing::Values(true, false),
                         [](const ::testing::TestParamInfo<bool>& p) {
                           return p.param ? "Fused" : "Split";
                         });

// Every stage kernel belongs to a pipeline; the two differ only in how a hit is shaded.
TEST(Pipeline, EveryStageIsRunByAPipeline) {
  std::set<Stage> run;
  for (const bool fused : {true, false})
    for (const Stage s : wp::pipeline(fused).stages()) run.insert(s);
  EXPECT_EQ(run.size(), std::size_t(wp::kStageCount));
  const auto fused = wp::fused_pipeline().stages(), split = wp::split_pipeline().stages();
  EXPECT_EQ(std::count(fused.begin(), fused.end(), Stage::kShade), 1);
  EXPECT_EQ(std::count(split.begin(), split.end(), Stage::kShade), 0);
}

TEST(Pipeline, QueueRolesNameTheLaunchQueues) {
  wp::dev::Launch launch{};
  launch.queue_in = WP_QUEUE_RAY_B;
  launch.queue_out = WP_QUEUE_RAY_A;
  EXPECT_EQ(wp::queue_index(QueueRole::kRaysIn, launch), WP_QUEUE_RAY_B);
  EXPECT_EQ(wp::queue_index(QueueRole::kRaysOut, launch), WP_QUEUE_RAY_A);
  EXPECT_EQ(wp::queue_index(QueueRole::kSurface, launch), WP_QUEUE_SURFACE);
  EXPECT_EQ(wp::queue_index(QueueRole::kShadow, launch), WP_QUEUE_SHADOW);
  EXPECT_ANY_THROW(wp::queue_index(QueueRole::kNone, launch));
}

// docs/architecture.md holds pipeline_markdown() between its markers, verbatim: regenerate it with
// the text this test prints when the table changes.
TEST(Pipeline, ArchitecturePageShowsTheTable) {
  std::ifstream in(std::string(WP_SOURCE_DIR) + "/docs/architecture.md");
  ASSERT_TRUE(in) << "docs/architecture.md not found";
  std::stringstream page;
  page << in.rdbuf();
  const std::string text = page.str();
  const std::string begin = "<!-- pipeline table: begin -->\n",
                    end = "<!-- pipeline table: end -->";
  const auto b = text.find(begin), e = text.find(end);
  ASSERT_NE(b, std::string::npos);
  ASSERT_NE(e, std::string::npos);
  const std::string shown = text.substr(b + begin.size(), e - b - begin.size());
  EXPECT_EQ(shown, wp::pipeline_markdown()) << "the table to paste:\n" << wp::pipeline_markdown();
}

}  // namespace
