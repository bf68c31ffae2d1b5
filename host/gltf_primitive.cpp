#include "host/gltf_primitive.h"

#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat3x3.hpp>

#include "host/error.h"
#include "host/gltf_accessor.h"

namespace wp::gltf {
namespace {

constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();

// Integer attributes are accepted for every role (KHR_mesh_quantization; normalized u8/u16 for
// TEXCOORD_0 and COLOR_0 in core glTF).
const AccessorSpec kIndices{"indices", 1, 1, kIndexBits};
const AccessorSpec kPosition{"POSITION", 3, 3, kFloatBit | kIntegerBits};
const AccessorSpec kNormal{"NORMAL", 3, 3, kFloatBit | kIntegerBits};
const AccessorSpec kTexcoord{"TEXCOORD_0", 2, 2, kFloatBit | kIntegerBits};
const AccessorSpec kColor{"COLOR_0", 3, 4, kFloatBit | kIntegerBits};

int attribute(const tinygltf::Primitive& p, const char* name) {
  const auto it = p.attributes.find(name);
  return it == p.attributes.end() ? -1 : it->second;
}

// The vertex indices of the primitive's triangles, three per triangle, in glTF's order for the
// mode (spec 3.7.2.1). Every index is checked against `vertex_count`.
std::vector<std::uint32_t> triangle_corners(const tinygltf::Model& model,
                                            const tinygltf::Primitive& p, std::size_t vertex_count,
                                            std::size_t* leftover) {
  std::vector<std::uint32_t> list;
  if (p.indices >= 0) {
    list = AccessorReader(model, p.indices, kIndices).read_indices();
    for (std::size_t i = 0; i < list.size(); ++i) {
      if (list[i] >= vertex_count)
        throw Error("accessor " + std::to_string(p.indices) + " (indices): index " +
                    std::to_string(list[i]) + " at " + std::to_string(i) +
                    " is out of range (vertex count " + std::to_string(vertex_count) + ")");
    }
  } else {
    list.resize(vertex_count);
    std::iota(list.begin(), list.end(), 0u);
  }
  *leftover = 0;
  const int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    *leftover = list.size() % 3;
    list.resize(list.size() - *leftover);
    return list;
  }
  std::vector<std::uint32_t> tris;
  if (list.size() < 3) return tris;
  tris.reserve(3 * (list.size() - 2));
  for (std::size_t i = 0; i + 2 < list.size(); ++i) {
    std::uint32_t a = 0, b = 0, c = 0;
    if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {  // {v_i, v_i+(1+i%2), v_i+(2-i%2)}
      a = list[i], b = list[i + 1 + i % 2], c = list[i + 2 - i % 2];
    } else {  // fan: {v_i+1, v_i+2, v_0}
      a = list[i + 1], b = list[i + 2], c = list[0];
    }
    if (a == b || b == c || a == c) continue;  // strips join runs with degenerate triangles
    tris.insert(tris.end(), {a, b, c});
  }
  return tris;
}

// The vertices some triangle uses (compacted, in first-use order), in world space. `normal` is
// zero where the file has none or the one it has is unusable.
struct Vertices {
  std::vector<glm::vec3> position, normal;
  std::vector<glm::vec2> uv;
  std::vector<glm::vec4> color;
};

// n transforms like the inverse transpose of the 3x3 part, up to a positive factor; the cofactor
// matrix gives that without dividing by a determinant that may be zero.
glm::dmat3 normal_matrix(const glm::dmat4& world) {
  const glm::dmat3 m(world);
  glm::dmat3 cof(glm::cross(m[1], m[2]), glm::cross(m[2], m[0]), glm::cross(m[0], m[1]));
  return glm::determinant(m) < 0.0 ? -cof : cof;
}

// Attribute `name` of `p` when present, required to have POSITION's count (glTF requires equal
// counts across a primitive's attributes).
std::optional<AccessorReader> open_attribute(const tinygltf::Model& model,
                                             const tinygltf::Primitive& p, const char* name,
                                             const AccessorSpec& spec, std::size_t count) {
  const int index = attribute(p, name);
  if (index < 0) return std::nullopt;
  std::optional<AccessorReader> reader(std::in_place, model, index, spec);
  if (reader->count() != count)
    throw Error("accessor " + std::to_string(index) + " (" + name + "): count " +
                std::to_string(reader->count()) + " differs from POSITION's " +
                std::to_string(count));
  return reader;
}

Vertices read_vertices(const tinygltf::Model& model, const tinygltf::Primitive& p,
                       const AccessorReader& pos, const std::vector<std::uint32_t>& used,
                       const glm::dmat4& world) {
  const auto normal = open_attribute(model, p, "NORMAL", kNormal, pos.count());
  const auto uv = open_attribute(model, p, "TEXCOORD_0", kTexcoord, pos.count());
  const auto color = open_attribute(model, p, "COLOR_0", kColor, pos.count());
  const glm::dmat3 nm = normal_matrix(world);

  Vertices v;
  v.position.resize(used.size());
  v.normal.assign(used.size(), glm::vec3(0.0f));
  v.uv.assign(used.size(), glm::vec2(0.0f));
  v.color.assign(used.size(), glm::vec4(1.0f));
  float f[4] = {0.0f, 0.0f, 0.0f, 1.0f};
  for (std::size_t k = 0; k < used.size(); ++k) {
    pos.read(used[k], f);
    const glm::dvec4 w = world * glm::dvec4(f[0], f[1], f[2], 1.0);
    v.position[k] = glm::vec3(w);
    if (!std::isfinite(v.position[k].x) || !std::isfinite(v.position[k].y) ||
        !std::isfinite(v.position[k].z))
      throw Error("POSITION " + std::to_string(used[k]) + " is not finite (in world space)");
    if (normal) {
      normal->read(used[k], f);
      const glm::dvec3 n = nm * glm::dvec3(f[0], f[1], f[2]);
      const double len = glm::length(n);  // in double: the cofactor scales by scale squared
      if (len > 0.0 && std::isfinite(len)) v.normal[k] = glm::vec3(n / len);
    }
    if (uv) uv->read(used[k], glm::value_ptr(v.uv[k]));
    if (color) {
      f[3] = 1.0f;  // vec3 colours are opaque
      color->read(used[k], f);
      v.color[k] = glm::vec4(f[0], f[1], f[2], f[3]);
    }
  }
  return v;
}

std::uint32_t push_vertex(Scene& s, const glm::vec3& p, const glm::vec3& n, const glm::vec2& uv,
                          const glm::vec4& c) {
  s.positions.push_back(p);
  s.normals.push_back(n);
  s.uv0.push_back(uv);
  s.color0.push_back(c);
  return static_cast<std::uint32_t>(s.positions.size() - 1);
}

// Appends triangles over compacted vertex ids `tris`: shared vertices where all three corners
// have normals, unshared ones with the face normal otherwise.
void emit(const Vertices& v, const std::vector<std::uint32_t>& tris, bool flip,
          std::uint32_t material, Scene& s) {
  if (s.positions.size() + v.position.size() + tris.size() >= kUnused)
    throw Error("more vertices than 32-bit indices can address");
  std::vector<std::uint32_t> scene_index(v.position.size(), kUnused);
  const auto shared = [&](std::uint32_t k) {
    if (scene_index[k] == kUnused)
      scene_index[k] = push_vertex(s, v.position[k], v.normal[k], v.uv[k], v.color[k]);
    return scene_index[k];
  };
  const glm::vec3 zero(0.0f);
  for (std::size_t t = 0; t + 2 < tris.size(); t += 3) {
    const std::uint32_t k[3] = {tris[t], tris[t + (flip ? 2 : 1)], tris[t + (flip ? 1 : 2)]};
    if (v.normal[k[0]] != zero && v.normal[k[1]] != zero && v.normal[k[2]] != zero) {
      for (const std::uint32_t c : k) s.indices.push_back(shared(c));
    } else {
      const glm::dvec3 p0(v.position[k[0]]);  // double: tiny triangles must not underflow
      const glm::dvec3 face =
          glm::cross(glm::dvec3(v.position[k[1]]) - p0, glm::dvec3(v.position[k[2]]) - p0);
      const double len = glm::length(face);
      // A zero-area triangle has no face normal; any unit vector keeps normals unit.
      const glm::vec3 n = len > 0.0 ? glm::vec3(face / len) : glm::vec3(0.0f, 0.0f, 1.0f);
      for (const std::uint32_t c : k)
        s.indices.push_back(push_vertex(s, v.position[c], n, v.uv[c], v.color[c]));
    }
    s.triangle_material.push_back(material);
  }
}

}  // namespace

bool is_triangle_mode(int mode) {
  return mode < 0 || mode == TINYGLTF_MODE_TRIANGLES || mode == TINYGLTF_MODE_TRIANGLE_STRIP ||
         mode == TINYGLTF_MODE_TRIANGLE_FAN;
}

std::size_t append_primitive(const tinygltf::Model& model, const tinygltf::Primitive& primitive,
                             const glm::dmat4& world, std::uint32_t material, Scene& scene) {
  const AccessorReader pos(model, attribute(primitive, "POSITION"), kPosition);
  if (pos.count() >= kUnused) throw Error("more vertices than 32-bit indices can address");
  std::size_t leftover = 0;
  std::vector<std::uint32_t> tris = triangle_corners(model, primitive, pos.count(), &leftover);

  // Compact to the vertices in use: accessors may be shared by primitives that each use a part.
  std::vector<std::uint32_t> compact(pos.count(), kUnused);
  std::vector<std::uint32_t> used;
  for (std::uint32_t& corner : tris) {
    if (compact[corner] == kUnused) {
      compact[corner] = static_cast<std::uint32_t>(used.size());
      used.push_back(corner);
    }
    corner = compact[corner];
  }
  const Vertices v = read_vertices(model, primitive, pos, used, world);
  const bool flip = glm::determinant(glm::dmat3(world)) < 0.0;
  emit(v, tris, flip, material, scene);
  return leftover;
}

}  // namespace wp::gltf
