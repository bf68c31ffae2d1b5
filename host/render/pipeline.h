// The pipeline table: the wavefront's stage kernels, and for each pipeline (--pipeline fused or
// split) the stages one wave runs, in order, with the queues each reads and writes. It drives the
// wave loop (Wavefront::run_wave, run_bounce), which kernels are made and primed, the --profile
// names, wavepath-bench's stage captures, and the table in docs/architecture.md (written by
// pipeline_markdown; tests/test_pipeline.cpp checks that the page holds it).
//
// Each stage is kernels/<name>.cl, a short entry point over integrator/<name>.h; every stage kernel
// takes the same arguments (kernels/integrator/stage.h, WP_STAGE_PARAMS), accumulate the film after
// them.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "kernels/shared/types.h"

namespace wp {

enum class Stage : int {
  kGenerateCameraRays,
  kIntersectClosest,
  kShadeSurface,
  kSampleLights,
  kTraceShadow,
  kSampleBsdf,
  kRouletteCompact,
  kShade,  // fused: shade_surface, sample_lights, sample_bsdf and roulette_compact in one kernel
  kAccumulate,
};
inline constexpr int kStageCount = 9;

// The kernel names (and --profile / JSON stage_seconds keys), indexed by Stage.
inline constexpr std::array<const char*, kStageCount> kStageNames = {
    "generate_camera_rays", "intersect_closest", "shade_surface", "sample_lights", "trace_shadow",
    "sample_bsdf",          "roulette_compact",  "shade",         "accumulate"};

inline const char* stage_name(Stage s) {
  return kStageNames[static_cast<int>(s)];
}

// A queue by its role in a bounce (kernels/integrator/queues.h). The bounce's rays and the next
// bounce's are the two ray queues, which swap roles every bounce (Launch::queue_in, queue_out).
enum class QueueRole { kNone, kRaysIn, kRaysOut, kSurface, kShadow };

// The WP_QUEUE_* index of `role` in the bounce that `launch` describes; kNone has none.
std::uint32_t queue_index(QueueRole role, const dev::Launch& launch);
const char* queue_role_name(QueueRole role);

// How many work-items a stage is launched over.
enum class LaunchSize {
  kPaths,       // every path of the wave (generate_camera_rays)
  kPixels,      // every pixel of the wave (accumulate)
  kRays,        // the bounce's ray count: an upper bound of every bounce queue's length; the
                // work-items past the queue's end return at once
  kQueueLength  // exactly its input queue's length, read back from the device first (trace_shadow:
                // or an estimate launched before the read-back returns and then the rest,
                // Wavefront::run_bounce)
};

struct Step {
  Stage stage;
  QueueRole in;
  QueueRole out = QueueRole::kNone;
  QueueRole out2 = QueueRole::kNone;  // a second output queue (the fused shade's shadow rays)
  LaunchSize size = LaunchSize::kRays;
};

// One pipeline: the wave starts with `start`, runs `bounce` until no ray is left, ends with `end`.
// Within a bounce, the counters are read back once, before the first kQueueLength step; no step
// from there on may push to a queue (the ray count of the next bounce is read then).
struct Pipeline {
  const char* name;  // the --pipeline value
  Step start;
  std::vector<Step> bounce;
  Step end;
  // Every stage the pipeline launches, start to end.
  std::vector<Stage> stages() const;
};

const Pipeline& fused_pipeline();
const Pipeline& split_pipeline();
inline const Pipeline& pipeline(bool fused) {
  return fused ? fused_pipeline() : split_pipeline();
}

// Both pipelines as a Markdown table (stage, kernel file, logic, input, outputs, launched over),
// the block between the markers of docs/architecture.md's "The pipeline table".
std::string pipeline_markdown();

}  // namespace wp
