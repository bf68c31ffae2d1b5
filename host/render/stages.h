// The one stage list: the wavefront's kernels in pipeline order. It drives program assembly (each
// stage is kernels/<name>.cl defining __kernel <name>), launching, logging and per-kernel timing.
#pragma once

#include <array>

namespace wp {

enum class Stage : int {
  kGenerateCameraRays,  // new samples -> ray queue
  kIntersectClosest,    // ray queue -> hit records
  kShadeSurface,        // hits -> emission/background, surface records, surface queue
  kSampleLights,        // surface queue -> shadow queue (NEE)
  kTraceShadow,         // shadow queue -> unoccluded contributions
  kSampleBsdf,          // surface queue -> next rays, throughput, pdf, delta flag
  kRouletteCompact,     // surface queue -> next ray queue (survivors)
  kShade,               // fused: hits -> shadow queue, next ray queue (the four stages above but
                        // trace_shadow in one kernel; RenderSettings::fused)
  kAccumulate,          // wave -> film
};
inline constexpr int kStageCount = 9;

inline constexpr std::array<const char*, kStageCount> kStageNames = {
    "generate_camera_rays", "intersect_closest", "shade_surface", "sample_lights", "trace_shadow",
    "sample_bsdf",          "roulette_compact",  "shade",         "accumulate"};

inline const char* stage_name(Stage s) {
  return kStageNames[static_cast<int>(s)];
}

}  // namespace wp
