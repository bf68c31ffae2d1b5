// The reference the ray-tracing stage kernels are measured against: Embree's own single-ray
// queries (rtcIntersect1 for closest hits, rtcOccluded1 for shadow rays) on the scene's triangles,
// run by as many std::thread workers as the OpenCL device has compute units.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "bvh/embree_scene.h"

#include "host/scene/scene.h"

namespace wp::bench {

struct RefRay {
  float o[3];
  float tmin;
  float d[3];
  float tmax;  // may be infinite
};

struct RefTiming {
  double seconds_per_pass = 0;  // wall clock, all workers together
  std::size_t hits = 0;         // rays of one pass that hit (closest) or are occluded (shadow)
  std::size_t passes = 0;
};

class EmbreeRef {
 public:
  // An Embree scene over the scene's world-space triangles, built with RTC_BUILD_QUALITY_HIGH
  // (spatial splits) and default scene flags: Embree at its fastest for single rays. An instanced
  // scene (Scene::instances) is given to Embree as its own two-level structure, a scene per mesh
  // and an instance geometry per instance (bvh::EmbreeInstances).
  explicit EmbreeRef(const Scene& scene);

  // Traces every ray once untimed (warm-up), then repeatedly for at least `min_seconds` (and at
  // least one pass), `threads` workers taking chunks of rays from a shared counter.
  RefTiming measure(const std::vector<RefRay>& rays, bool occlusion, unsigned threads,
                    double min_seconds) const;

 private:
  std::unique_ptr<bvh::EmbreeScene> flat_;
  std::unique_ptr<bvh::EmbreeInstances> instanced_;
  RTCScene handle_ = nullptr;
};

}  // namespace wp::bench
