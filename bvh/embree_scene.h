// Embree's own acceleration structure and single-ray queries (rtcIntersect1 / rtcOccluded1) over
// a triangle mesh: the independent oracle the tests compare the reference traversal and the
// kernels with, and the reference the benchmarks time them against.
#pragma once

#include <embree3/rtcore.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "bvh.h"

namespace wp::bvh {

class EmbreeScene {
 public:
  // RTC_BUILD_QUALITY_HIGH; `robust` adds RTC_SCENE_FLAG_ROBUST (watertight-ish, slower: for
  // tests). Throws bvh::Error if Embree fails.
  EmbreeScene(const glm::vec3* positions, std::size_t vertex_count, const std::uint32_t* indices,
              std::size_t triangle_count, bool robust);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // Embree accepts t in [tmin, tmax], the project's traversals (tmin, tmax): they differ only on
  // the bounds.
  Hit intersect(const Ray& ray) const;
  bool occluded(const Ray& ray) const;
  RTCScene handle() const { return scene_; }

  static RTCRay to_rtc(const Ray& r);

 private:
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
};

// Embree's own two-level structure: a scene per mesh (the triangles [first, first + count) of
// `indices`, mesh i being meshes[i]) and an instance geometry (RTC_GEOMETRY_TYPE_INSTANCE) per
// instance, with its transform; the oracle and benchmark reference for build_two_level.
class EmbreeInstances {
 public:
  struct MeshRange {
    std::uint32_t first = 0, count = 0;
  };
  EmbreeInstances(const glm::vec3* positions, const std::uint32_t* indices,
                  const std::vector<MeshRange>& meshes, const std::vector<InstanceInput>& instances,
                  bool robust);
  ~EmbreeInstances();
  EmbreeInstances(const EmbreeInstances&) = delete;
  EmbreeInstances& operator=(const EmbreeInstances&) = delete;

  // Hit::triangle is the scene's triangle (first + Embree's primID), Hit::instance the index into
  // `instances`.
  Hit intersect(const Ray& ray) const;
  bool occluded(const Ray& ray) const;
  RTCScene handle() const { return scene_; }

 private:
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::vector<RTCScene> meshes_;
  std::vector<std::uint32_t> first_;  // per instance: its mesh's first triangle
};

}  // namespace wp::bvh
