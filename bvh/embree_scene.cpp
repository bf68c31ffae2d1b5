#include "embree_scene.h"

#include <algorithm>
#include <cstring>
#include <string>

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

namespace {

// A scene of the triangles [first, first + count) of `indices`, with the vertices they use.
RTCScene mesh_scene(RTCDevice device, const glm::vec3* positions, const std::uint32_t* indices,
                    std::uint32_t first, std::uint32_t count, bool robust) {
  const std::uint32_t* idx = indices + 3 * std::size_t{first};
  std::uint32_t lo = 0, hi = 0;
  if (count > 0) {
    lo = *std::min_element(idx, idx + 3 * std::size_t{count});
    hi = *std::max_element(idx, idx + 3 * std::size_t{count});
  }
  RTCScene scene = rtcNewScene(device);
  if (robust) rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
  const std::size_t vertices = count > 0 ? std::size_t{hi} - lo + 1 : 0;
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
      g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertices));
  for (std::size_t i = 0; i < vertices; ++i) std::memcpy(v + 3 * i, &positions[lo + i], 12);
  auto* out = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(
      g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), count));
  for (std::size_t i = 0; i < 3 * std::size_t{count}; ++i) out[i] = idx[i] - lo;
  rtcCommitGeometry(g);
  rtcAttachGeometry(scene, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(scene);
  return scene;
}

}  // namespace

EmbreeInstances::EmbreeInstances(const glm::vec3* positions, const std::uint32_t* indices,
                                 const std::vector<MeshRange>& meshes,
                                 const std::vector<InstanceInput>& instances, bool robust) {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw Error("Embree: cannot create a device");
  for (const MeshRange& m : meshes)
    meshes_.push_back(mesh_scene(device_, positions, indices, m.first, m.count, robust));
  scene_ = rtcNewScene(device_);
  if (robust) rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
  for (const InstanceInput& in : instances) {
    RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(g, meshes_.at(in.mesh));
    float m[12];  // 3x4 column-major
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 3; ++r) m[3 * c + r] = static_cast<float>(in.to_world[c][r]);
    rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, m);
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene_, g);  // geometry IDs in order: the instance's index
    rtcReleaseGeometry(g);
    first_.push_back(meshes[in.mesh].first);
  }
  rtcCommitScene(scene_);
  if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) {
    rtcReleaseScene(scene_);
    for (RTCScene s : meshes_) rtcReleaseScene(s);
    rtcReleaseDevice(device_);
    throw Error("Embree: building a scene of " + std::to_string(instances.size()) +
                " instances failed");
  }
}

EmbreeInstances::~EmbreeInstances() {
  rtcReleaseScene(scene_);
  for (RTCScene s : meshes_) rtcReleaseScene(s);
  rtcReleaseDevice(device_);
}

Hit EmbreeInstances::intersect(const Ray& r) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh{};
  rh.ray = EmbreeScene::to_rtc(r);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene_, &ctx, &rh);
  Hit h;
  h.hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
  if (!h.hit) return h;
  h.t = rh.ray.tfar, h.u = rh.hit.u, h.v = rh.hit.v;
  h.instance = rh.hit.instID[0];
  h.triangle = first_[h.instance] + rh.hit.primID;
  return h;
}

bool EmbreeInstances::occluded(const Ray& r) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay ray = EmbreeScene::to_rtc(r);
  rtcOccluded1(scene_, &ctx, &ray);
  return ray.tfar < 0;
}

}  // namespace wp::bvh
