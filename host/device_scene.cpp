#include "host/device_scene.h"

#include <cmath>
#include <cstring>

#include <glm/geometric.hpp>

#include "host/error.h"

namespace wp {

namespace {

dev::float4 f4(glm::vec3 v, float w = 0.0f) {
  return {v.x, v.y, v.z, w};
}
dev::float4 f4(glm::vec4 v) {
  return {v.x, v.y, v.z, v.w};
}

// Appends `items` at the next 64-byte boundary and returns its offset.
template <class T>
dev::uint append(std::vector<unsigned char>& bytes, const std::vector<T>& items) {
  const std::size_t offset = (bytes.size() + 63) & ~std::size_t(63);
  const std::size_t size = items.size() * sizeof(T);
  if (offset + size > 0xffffffffu) throw Error("scene too large for 32-bit buffer offsets");
  bytes.resize(offset + std::max<std::size_t>(size, 16));
  if (size) std::memcpy(bytes.data() + offset, items.data(), size);
  return static_cast<dev::uint>(offset);
}

dev::Material device_material(const Material& m) {
  dev::Material d{};
  d.base_color = f4(m.base_color);
  d.emission = f4(m.emission);
  d.params = {m.metallic, m.roughness, m.ior, m.transmission};
  d.flags = {m.double_sided ? WP_MAT_DOUBLE_SIDED : 0u, 0u, 0u, 0u};
  return d;
}

dev::PunctualLight device_light(const PunctualLight& l) {
  dev::PunctualLight d{};
  d.position = f4(l.position, l.range);
  d.direction = f4(glm::normalize(l.direction));
  d.intensity = f4(l.intensity);
  // KHR_lights_punctual's recommended spot falloff: saturate(cd * scale + offset)^2.
  const float cos_outer = std::cos(l.outer_cone), cos_inner = std::cos(l.inner_cone);
  const float scale = 1.0f / std::max(0.001f, cos_inner - cos_outer);
  d.spot = {scale, -cos_outer * scale, 0.0f, 0.0f};
  const dev::uint type = l.type == LightType::kPoint  ? WP_LIGHT_POINT
                         : l.type == LightType::kSpot ? WP_LIGHT_SPOT
                                                      : WP_LIGHT_DIRECTIONAL;
  d.meta = {type, 0u, 0u, 0u};
  return d;
}

}  // namespace

dev::Camera device_camera(const Camera& c, int width, int height) {
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  const glm::vec3 forward = glm::normalize(c.forward);
  const glm::vec3 right = glm::normalize(glm::cross(forward, c.up));
  const glm::vec3 up = glm::cross(right, forward);
  float half_w, half_h;
  if (c.type == CameraType::kPerspective) {
    half_h = std::tan(0.5f * c.yfov);
    half_w = half_h * aspect;
  } else {
    half_h = c.ymag;
    half_w = c.ymag * aspect;
  }
  dev::Camera d{};
  d.position = f4(c.position, c.znear);
  d.forward = f4(forward);
  d.right = f4(right * half_w);
  d.up = f4(up * half_h);
  d.meta = {c.type == CameraType::kPerspective ? WP_CAMERA_PERSPECTIVE : WP_CAMERA_ORTHOGRAPHIC, 0u,
            0u, 0u};
  return d;
}

PackedScene pack_scene(const Scene& scene, const bvh::Bvh& bvh, const dev::Camera& camera,
                       glm::vec3 background) {
  const std::size_t tris = scene.triangle_count();
  const std::size_t verts = scene.positions.size();
  std::vector<dev::uint4> tri_vertices(tris);
  for (std::size_t i = 0; i < tris; ++i)
    tri_vertices[i] = {scene.indices[3 * i], scene.indices[3 * i + 1], scene.indices[3 * i + 2],
                       scene.triangle_material[i]};
  std::vector<dev::float4> positions(verts), normals(verts), uvs(verts), colors(verts);
  for (std::size_t i = 0; i < verts; ++i) {
    positions[i] = f4(scene.positions[i]);
    normals[i] = f4(scene.normals[i]);
    const glm::vec2 uv = i < scene.uv0.size() ? scene.uv0[i] : glm::vec2(0.0f);
    uvs[i] = {uv.x, uv.y, 0.0f, 0.0f};
    colors[i] = i < scene.color0.size() ? f4(scene.color0[i]) : dev::float4{1, 1, 1, 1};
  }
  std::vector<dev::Material> materials;
  for (const Material& m : scene.materials) materials.push_back(device_material(m));
  std::vector<dev::PunctualLight> lights;
  for (const PunctualLight& l : scene.lights) lights.push_back(device_light(l));

  PackedScene p;
  dev::SceneDesc& d = p.desc;
  d.camera = camera;
  d.background = f4(background);
  d.bvh_nodes = append(p.bytes, bvh.nodes);
  d.isect_tris = append(p.bytes, bvh.triangles);
  d.tri_vertices = append(p.bytes, tri_vertices);
  d.positions = append(p.bytes, positions);
  d.normals = append(p.bytes, normals);
  d.uvs = append(p.bytes, uvs);
  d.colors = append(p.bytes, colors);
  d.materials = append(p.bytes, materials);
  d.lights = append(p.bytes, lights);
  d.light_count = static_cast<dev::uint>(lights.size());
  d.triangle_count = static_cast<dev::uint>(tris);
  return p;
}

}  // namespace wp
