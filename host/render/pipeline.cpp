#include "host/render/pipeline.h"

#include "host/util/error.h"

namespace wp {

std::uint32_t queue_index(QueueRole role, const dev::Launch& launch) {
  switch (role) {
    case QueueRole::kRaysIn:
      return launch.queue_in;
    case QueueRole::kRaysOut:
      return launch.queue_out;
    case QueueRole::kSurface:
      return WP_QUEUE_SURFACE;
    case QueueRole::kShadow:
      return WP_QUEUE_SHADOW;
    case QueueRole::kNone:
      break;
  }
  throw Error("queue_index: a step without that queue");
}

const char* queue_role_name(QueueRole role) {
  switch (role) {
    case QueueRole::kRaysIn:
      return "rays";
    case QueueRole::kRaysOut:
      return "next rays";
    case QueueRole::kSurface:
      return "surface";
    case QueueRole::kShadow:
      return "shadow";
    case QueueRole::kNone:
      break;
  }
  return "";
}

namespace {

constexpr Step kGenerate{Stage::kGenerateCameraRays, QueueRole::kNone, QueueRole::kRaysIn,
                         QueueRole::kNone, LaunchSize::kPaths};
constexpr Step kIntersect{Stage::kIntersectClosest, QueueRole::kRaysIn};
// Shadow rays are traced last, over exactly their count: launched over the bounce's rays, as the
// other stages are, the work-groups past the queue's end (most of them where few rays find a
// surface or few lights are visible) cost more than the rays themselves. trace_shadow reads
// nothing the stages before it change after the shadow ray is made (the bounce for its random
// numbers travels with the ray). Wavefront::run_bounce may launch it over an estimate of that
// count before the count is back, and the rest of the queue after (RenderSettings::shadow_ahead).
constexpr Step kTraceShadow{Stage::kTraceShadow, QueueRole::kShadow, QueueRole::kNone,
                            QueueRole::kNone, LaunchSize::kQueueLength};
constexpr Step kAccumulate{Stage::kAccumulate, QueueRole::kNone, QueueRole::kNone, QueueRole::kNone,
                           LaunchSize::kPixels};

}  // namespace

std::vector<Stage> Pipeline::stages() const {
  std::vector<Stage> out{start.stage};
  for (const Step& s : bounce) out.push_back(s.stage);
  out.push_back(end.stage);
  return out;
}

const Pipeline& fused_pipeline() {
  static const Pipeline p{
      "fused",
      kGenerate,
      {kIntersect,
       {Stage::kShade, QueueRole::kRaysIn, QueueRole::kRaysOut, QueueRole::kShadow},
       kTraceShadow},
      kAccumulate};
  return p;
}

const Pipeline& split_pipeline() {
  static const Pipeline p{"split",
                          kGenerate,
                          {kIntersect,
                           {Stage::kShadeSurface, QueueRole::kRaysIn, QueueRole::kSurface},
                           {Stage::kSampleLights, QueueRole::kSurface, QueueRole::kShadow},
                           {Stage::kSampleBsdf, QueueRole::kSurface},
                           {Stage::kRouletteCompact, QueueRole::kSurface, QueueRole::kRaysOut},
                           kTraceShadow},
                          kAccumulate};
  return p;
}

namespace {

const char* launch_size_name(LaunchSize size) {
  switch (size) {
    case LaunchSize::kPaths:
      return "the wave's paths";
    case LaunchSize::kPixels:
      return "the wave's pixels";
    case LaunchSize::kRays:
      return "the bounce's rays";
    case LaunchSize::kQueueLength:
      return "its queue's length";
  }
  return "";
}

std::string markdown_rows(const Pipeline& p) {
  std::string out;
  const auto row = [&](const Step& s, const char* when) {
    const std::string name = stage_name(s.stage);
    std::string outputs = queue_role_name(s.out);
    if (s.out2 != QueueRole::kNone) outputs += std::string(", ") + queue_role_name(s.out2);
    const std::string logic =
        s.stage == Stage::kShade
            ? std::string("the four split stages' headers")
            : "[`integrator/" + name + ".h`](../kernels/integrator/" + name + ".h)";
    out += "| " + std::string(p.name) + " | " + when + " | `" + name + "` | [`kernels/" + name +
           ".cl`](../kernels/" + name + ".cl) | " + logic + " | " + queue_role_name(s.in) + " | " +
           outputs + " | " + launch_size_name(s.size) + " |\n";
  };
  row(p.start, "wave start");
  for (const Step& s : p.bounce) row(s, "each bounce");
  row(p.end, "wave end");
  return out;
}

}  // namespace

std::string pipeline_markdown() {
  return "| pipeline | when | stage | kernel | logic | reads queue | pushes to | launched over |\n"
         "|---|---|---|---|---|---|---|---|\n" +
         markdown_rows(fused_pipeline()) + markdown_rows(split_pipeline());
}

}  // namespace wp
