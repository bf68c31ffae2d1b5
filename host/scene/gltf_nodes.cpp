#include "host/scene/gltf_nodes.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "host/util/error.h"
#include "host/scene/gltf_accessor.h"
#include "host/scene/gltf_values.h"

namespace wp::gltf {
namespace {

// True when `v` is present; throws unless it has `size` finite numbers.
bool present(const std::vector<double>& v, std::size_t size, const std::string& where,
             const char* field) {
  if (v.empty()) return false;
  if (v.size() != size)
    throw Error(where + ": " + field + " needs " + std::to_string(size) + " numbers, has " +
                std::to_string(v.size()));
  for (const double x : v)
    if (!std::isfinite(x)) throw Error(where + ": " + field + " is not finite");
  return true;
}

// Unit direction of `v`, or `fallback` when `v` has no direction (a zero scale).
glm::dvec3 unit_or(const glm::dvec3& v, const glm::dvec3& fallback) {
  const double len = glm::length(v);
  return len > 0.0 && std::isfinite(len) ? v / len : fallback;
}

// The node's -Z (forward) and +Y (up, made orthogonal to forward) in world space, unit.
void orientation(const glm::dmat4& world, glm::vec3* forward, glm::vec3* up) {
  const glm::dmat3 m(world);
  const glm::dvec3 f = unit_or(-m[2], glm::dvec3(0.0, 0.0, -1.0));
  glm::dvec3 u = m[1] - glm::dot(m[1], f) * f;
  if (!(glm::length(u) > 1e-9 * glm::length(m[1]))) {  // +Y along forward: any perpendicular
    u = glm::cross(f, std::abs(f.x) < 0.9 ? glm::dvec3(1.0, 0.0, 0.0) : glm::dvec3(0.0, 1.0, 0.0));
  }
  *forward = glm::vec3(f);
  *up = glm::vec3(glm::normalize(u));
}

constexpr const char* kInstancing = "EXT_mesh_gpu_instancing";

// The extension's attributes object of `node`: null without the extension (*present false) or
// when it has no such object (*present true).
const tinygltf::Value* instancing_attributes(const tinygltf::Node& node, bool* present) {
  const auto it = node.extensions.find(kInstancing);
  *present = it != node.extensions.end();
  if (!*present) return nullptr;
  const tinygltf::Value& ext = it->second;
  if (!ext.IsObject() || !ext.Has("attributes") || !ext.Get("attributes").IsObject())
    return nullptr;
  return &ext.Get("attributes");
}

}  // namespace

std::optional<std::vector<glm::dmat4>> instance_transforms(const tinygltf::Model& model,
                                                           const tinygltf::Node& node, int index) {
  const std::string where = "node " + std::to_string(index) + ": " + kInstancing;
  bool present = false;
  const tinygltf::Value* attributes = instancing_attributes(node, &present);
  if (!present) return std::nullopt;
  if (!attributes) throw Error(where + " has no attributes object");
  constexpr unsigned kSnorm =
      component_bit(TINYGLTF_COMPONENT_TYPE_BYTE) | component_bit(TINYGLTF_COMPONENT_TYPE_SHORT);
  const AccessorSpec kTranslation{"TRANSLATION", 3, 3, kFloatBit};
  const AccessorSpec kRotation{"ROTATION", 4, 4, kFloatBit | kSnorm};
  const AccessorSpec kScale{"SCALE", 3, 3, kFloatBit};
  std::optional<AccessorReader> t, r, s;
  std::optional<std::size_t> count;
  for (const std::string& name : attributes->Keys()) {
    const tinygltf::Value& v = attributes->Get(name);
    if (!v.IsInt()) throw Error(where + ": attribute " + name + " is not an accessor index");
    const int accessor = v.GetNumberAsInt();
    const AccessorSpec* spec = name == "TRANSLATION" ? &kTranslation
                               : name == "ROTATION"  ? &kRotation
                               : name == "SCALE"     ? &kScale
                                                     : nullptr;
    std::optional<AccessorReader>& slot = name == "TRANSLATION" ? t : name == "ROTATION" ? r : s;
    std::size_t n = 0;
    if (spec) {
      try {
        slot.emplace(model, accessor, *spec);
      } catch (const Error& e) {
        throw Error(where + ": " + e.what());
      }
      if (name == "ROTATION" && !model.accessors[static_cast<std::size_t>(accessor)].normalized &&
          model.accessors[static_cast<std::size_t>(accessor)].componentType !=
              TINYGLTF_COMPONENT_TYPE_FLOAT)
        throw Error(where + ": ROTATION of integer components must be normalized");
      n = slot->count();
    } else {  // a custom attribute ("_ID"): only its count matters
      if (accessor < 0 || static_cast<std::size_t>(accessor) >= model.accessors.size())
        throw Error(where + ": attribute " + name + ": accessor " + std::to_string(accessor) +
                    " does not exist");
      n = model.accessors[static_cast<std::size_t>(accessor)].count;
    }
    if (count && n != *count)
      throw Error(where + ": attribute " + name + " has " + std::to_string(n) +
                  " instances, another has " + std::to_string(*count) + " (counts must be equal)");
    count = n;
  }
  if (!count) throw Error(where + ": no attributes");
  std::vector<glm::dmat4> out(*count, glm::dmat4(1.0));
  for (std::size_t i = 0; i < *count; ++i) {
    float f[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    glm::dmat4 m(1.0);
    if (t) {
      t->read(i, f);
      m = glm::translate(m, glm::dvec3(f[0], f[1], f[2]));
    }
    if (r) {
      r->read(i, f);
      const glm::dquat q(f[3], f[0], f[1], f[2]);  // glm: w first; glTF stores x, y, z, w
      const double len = glm::length(q);
      if (!(len > 0.0) || !std::isfinite(len))
        throw Error(where + ": ROTATION " + std::to_string(i) + " is not a rotation");
      m = m * glm::mat4_cast(q / len);
    }
    if (s) {
      s->read(i, f);
      m = glm::scale(m, glm::dvec3(f[0], f[1], f[2]));
    }
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 4; ++k)
        if (!std::isfinite(m[c][k]))
          throw Error(where + ": instance " + std::to_string(i) + " has a non-finite transform");
    out[i] = m;
  }
  return out;
}

std::size_t placements(const tinygltf::Model& model, const tinygltf::Node& node) {
  bool present = false;
  const tinygltf::Value* attributes = instancing_attributes(node, &present);
  if (!present) return 1;
  for (const std::string& name : attributes ? attributes->Keys() : std::vector<std::string>{})
    if (attributes->Get(name).IsInt())
      if (const std::size_t n = readable_count(model, attributes->Get(name).GetNumberAsInt()))
        return n;
  return 0;
}

glm::dmat4 local_transform(const tinygltf::Node& node, int index) {
  const std::string where = "node " + std::to_string(index);
  if (present(node.matrix, 16, where, "matrix")) return glm::make_mat4(node.matrix.data());
  glm::dmat4 t(1.0), r(1.0), s(1.0);
  if (present(node.translation, 3, where, "translation"))
    t = glm::translate(glm::dmat4(1.0), glm::make_vec3(node.translation.data()));
  if (present(node.rotation, 4, where, "rotation")) {
    glm::dquat q;  // glTF stores x, y, z, w
    q.x = node.rotation[0], q.y = node.rotation[1], q.z = node.rotation[2], q.w = node.rotation[3];
    const double len = glm::length(q);
    if (!(len > 0.0)) throw Error(where + ": rotation is a zero quaternion");
    r = glm::mat4_cast(q / len);  // exporters round; a unit quaternion keeps r a rotation
  }
  if (present(node.scale, 3, where, "scale"))
    s = glm::scale(glm::dmat4(1.0), glm::make_vec3(node.scale.data()));
  return t * r * s;
}

Camera make_camera(const tinygltf::Model& model, int index, const glm::dmat4& world) {
  if (index < 0 || static_cast<std::size_t>(index) >= model.cameras.size())
    throw Error("camera " + std::to_string(index) + " does not exist");
  const tinygltf::Camera& in = model.cameras[static_cast<std::size_t>(index)];
  const std::string where = "camera " + std::to_string(index) + " '" + in.name + "'";
  Camera out;
  out.name = in.name;
  // glTF's schema: yfov, znear, aspectRatio and zfar > 0 and zfar > znear for a perspective
  // camera; xmag and ymag not 0, znear >= 0, zfar > 0 and > znear for an orthographic one.
  // tinygltf gives 0 for an absent aspectRatio or (perspective) zfar: only those present are read.
  if (in.type == "perspective") {
    const tinygltf::PerspectiveCamera& p = in.perspective;
    out.type = CameraType::kPerspective;
    out.yfov = finite(p.yfov, where, "yfov");
    out.znear = finite(p.znear, where, "znear");
    require(p.yfov > 0.0, where, "yfov", "> 0", p.yfov);
    require(out.yfov < 3.14159f, where, "yfov", "< pi", p.yfov);  // a pinhole sees less than 180
    require(p.znear > 0.0, where, "znear", "> 0", p.znear);
    require(finite(p.aspectRatio, where, "aspectRatio") >= 0.0f, where, "aspectRatio", "> 0",
            p.aspectRatio);
    if (finite(p.zfar, where, "zfar") != 0.0f)
      require(p.zfar > p.znear, where, "zfar", "> znear", p.zfar);
  } else if (in.type == "orthographic") {
    const tinygltf::OrthographicCamera& o = in.orthographic;
    out.type = CameraType::kOrthographic;
    out.xmag = finite(o.xmag, where, "xmag");
    out.ymag = finite(o.ymag, where, "ymag");
    out.znear = finite(o.znear, where, "znear");
    require(o.xmag != 0.0, where, "xmag", "non-zero", o.xmag);
    require(o.ymag != 0.0, where, "ymag", "non-zero", o.ymag);
    require(o.znear >= 0.0, where, "znear", ">= 0", o.znear);
    require(finite(o.zfar, where, "zfar") > 0.0f, where, "zfar", "> 0", o.zfar);
    require(o.zfar > o.znear, where, "zfar", "> znear", o.zfar);
  } else {
    throw Error(where + ": unknown type '" + in.type + "'");
  }
  out.position = glm::vec3(world[3]);
  orientation(world, &out.forward, &out.up);
  return out;
}

int node_light(const tinygltf::Node& node, int index) {
  const auto it = node.extensions.find("KHR_lights_punctual");
  if (it == node.extensions.end()) return -1;
  const tinygltf::Value& ext = it->second;
  if (!ext.IsObject() || !ext.Has("light") || !ext.Get("light").IsInt())
    throw Error("node " + std::to_string(index) + ": KHR_lights_punctual has no integer 'light'");
  return ext.Get("light").GetNumberAsInt();
}

PunctualLight make_light(const tinygltf::Model& model, int index, const glm::dmat4& world,
                         std::vector<std::string>* warnings) {
  if (index < 0 || static_cast<std::size_t>(index) >= model.lights.size())
    throw Error("light " + std::to_string(index) + " does not exist");
  const tinygltf::Light& in = model.lights[static_cast<std::size_t>(index)];
  const std::string where = "light " + std::to_string(index) + " '" + in.name + "'";
  PunctualLight out;
  out.name = in.name;
  if (in.type == "point") {
    out.type = LightType::kPoint;
  } else if (in.type == "spot") {
    out.type = LightType::kSpot;
  } else if (in.type == "directional") {
    out.type = LightType::kDirectional;
  } else {
    throw Error(where + ": unknown type '" + in.type + "'");
  }
  glm::vec3 color(1.0f);
  if (present(in.color, 3, where, "color"))
    for (int i = 0; i < 3; ++i)
      color[i] = in_range(in.color[static_cast<std::size_t>(i)], 0.0, 1.0, where, "color");
  const float intensity = in_range(in.intensity, 0.0, HUGE_VAL, where, "intensity");
  const double brightest = double(intensity) * std::max({color.x, color.y, color.z});
  const double limited =
      at_most(brightest, kMaxRadiance, where, "intensity",
              "colour x intensity; the most radiance wavepath carries", warnings);
  // Within the limit, the float product as before the limit existed (the same images bit for
  // bit); beyond it, one scale for the three channels keeps the colour.
  out.intensity = limited < brightest
                      ? glm::vec3(glm::dvec3(color) * double(intensity) * (limited / brightest))
                      : color * intensity;
  out.range = finite(in.range, where, "range");  // tinygltf: 0 when absent (no range)
  require(in.range >= 0.0, where, "range", "> 0", in.range);
  // tinygltf fills glTF's cone defaults (0 and pi/4) for fields a spot light leaves out; the
  // extension asks 0 <= inner < outer <= pi/2.
  out.inner_cone = in_range(in.spot.innerConeAngle, 0.0, M_PI / 2, where, "innerConeAngle");
  out.outer_cone = in_range(in.spot.outerConeAngle, 0.0, M_PI / 2, where, "outerConeAngle");
  if (out.type == LightType::kSpot && !(out.inner_cone < out.outer_cone))
    throw Error(where + ": innerConeAngle " + number_text(in.spot.innerConeAngle) +
                " is not below outerConeAngle " + number_text(in.spot.outerConeAngle));
  out.position = glm::vec3(world[3]);
  out.direction = glm::vec3(unit_or(-glm::dmat3(world)[2], glm::dvec3(0.0, 0.0, -1.0)));
  return out;
}

}  // namespace wp::gltf
