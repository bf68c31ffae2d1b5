#include "embree_scene.h"

#include <cstring>

namespace wp::bvh {

EmbreeScene::EmbreeScene(const glm::vec3* positions, std::size_t vertex_count,
                         const std::uint32_t* indices, std::size_t triangle_count, bool robust) {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw Error("Embree: cannot create a device");
  scene_ = rtcNewScene(device_);
  if (robust) rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
      g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertex_count));
  for (std::size_t i = 0; i < vertex_count; ++i) std::memcpy(v + 3 * i, &positions[i], 12);
  auto* idx = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(
      g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), triangle_count));
  std::memcpy(idx, indices, 3 * triangle_count * sizeof(std::uint32_t));
  rtcCommitGeometry(g);
  rtcAttachGeometry(scene_, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(scene_);
  if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) {
    rtcReleaseScene(scene_);
    rtcReleaseDevice(device_);
    throw Error("Embree: building a scene of " + std::to_string(triangle_count) +
                " triangles failed");
  }
}

EmbreeScene::~EmbreeScene() {
  rtcReleaseScene(scene_);
  rtcReleaseDevice(device_);
}

RTCRay EmbreeScene::to_rtc(const Ray& r) {
  RTCRay ray{};
  ray.org_x = r.o.x, ray.org_y = r.o.y, ray.org_z = r.o.z, ray.tnear = r.tmin;
  ray.dir_x = r.d.x, ray.dir_y = r.d.y, ray.dir_z = r.d.z, ray.tfar = r.tmax;
  ray.mask = ~0u;  // Embree skips geometry whose mask does not meet the ray's
  return ray;
}

Hit EmbreeScene::intersect(const Ray& r) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh{};
  rh.ray = to_rtc(r);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene_, &ctx, &rh);
  Hit h;
  h.hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
  h.t = rh.ray.tfar, h.u = rh.hit.u, h.v = rh.hit.v, h.triangle = rh.hit.primID;
  return h;
}

bool EmbreeScene::occluded(const Ray& r) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay ray = to_rtc(r);
  rtcOccluded1(scene_, &ctx, &ray);
  return ray.tfar < 0;  // Embree marks an occluded ray with tfar = -inf
}

}  // namespace wp::bvh
