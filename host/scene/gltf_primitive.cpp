#include "host/scene/gltf_primitive.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat3x3.hpp>

#include "host/util/error.h"
#include "host/scene/gltf_accessor.h"

namespace wp::gltf {
namespace {

constexpr std::uint32_t kUnused = std::numeric_limits<std::uint32_t>::max();

// Integer attributes are accepted for every role (KHR_mesh_quantization; normalized u8/u16 for
// TEXCOORD_0 and COLOR_0 in core glTF).
const AccessorSpec kIndices{"indices", 1, 1, kIndexBits};
const AccessorSpec kPosition{"POSITION", 3, 3, kFloatBit | kIntegerBits};
const AccessorSpec kNormal{"NORMAL", 3, 3, kFloatBit | kIntegerBits};
const AccessorSpec kTexcoord{"TEXCOORD_0", 2, 2, kFloatBit | kIntegerBits};
const AccessorSpec kTexcoord1{"TEXCOORD_1", 2, 2, kFloatBit | kIntegerBits};
const AccessorSpec kTangent{"TANGENT", 4, 4, kFloatBit | kIntegerBits};
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

// Tangent xyz goes by `world`'s 3x3 (it lies in the surface, like an edge), renormalised; under
// a mirroring transform the bitangent cross(n, t) * w would flip relative to the mirrored
// surface, so w flips too.
glm::vec4 world_tangent(const glm::dmat3& m, bool mirror, const float* f) {
  const glm::dvec3 t = m * glm::dvec3(f[0], f[1], f[2]);
  const double len = glm::length(t);
  const float w = (f[3] < 0.0f) != mirror ? -1.0f : 1.0f;
  return len > 0.0 && std::isfinite(len) ? glm::vec4(glm::vec3(t / len), w) : glm::vec4(0, 0, 0, w);
}

// A primitive's vertices in world space, read from its accessors when appended: the loader keeps
// no copy of a primitive's vertices beside the scene's arrays (a 40-million-triangle mesh would
// need gigabytes more).
class VertexSource {
 public:
  VertexSource(const tinygltf::Model& model, const tinygltf::Primitive& p,
               const AccessorReader& pos, const glm::dmat4& world, const VertexNeeds& needs)
      : pos_(pos),
        normal_(open_attribute(model, p, "NORMAL", kNormal, pos.count())),
        uv_(open_attribute(model, p, "TEXCOORD_0", kTexcoord, pos.count())),
        color_(open_attribute(model, p, "COLOR_0", kColor, pos.count())),
        world_(world),
        linear_(world),
        normal_matrix_(normal_matrix(world)),
        mirror_(glm::determinant(linear_) < 0.0),
        uv0_needed_(needs.uv0),
        color0_needed_(needs.color0),
        uv1_needed_(needs.uv1),
        tangents_needed_(needs.tangents) {
    if (uv1_needed_) uv1_ = open_attribute(model, p, "TEXCOORD_1", kTexcoord1, pos.count());
    if (tangents_needed_) tangent_ = open_attribute(model, p, "TANGENT", kTangent, pos.count());
  }

  bool mirror() const { return mirror_; }
  bool has_tangents() const { return tangent_.has_value(); }

  // Vertex i's position in world space; throws where it is not finite.
  glm::vec3 position(std::uint32_t i) const {
    float f[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    pos_.read(i, f);
    const glm::vec3 p(world_ * glm::dvec4(f[0], f[1], f[2], 1.0));
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw Error("POSITION " + std::to_string(i) + " is not finite (in world space)");
    return p;
  }

  // Vertex i's unit normal in world space; zero where the file has none or an unusable one.
  glm::vec3 normal(std::uint32_t i) const {
    if (!normal_) return glm::vec3(0.0f);
    float f[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    normal_->read(i, f);
    const glm::dvec3 n = normal_matrix_ * glm::dvec3(f[0], f[1], f[2]);
    const double len = glm::length(n);  // in double: the cofactor scales by scale squared
    return len > 0.0 && std::isfinite(len) ? glm::vec3(n / len) : glm::vec3(0.0f);
  }

  // Appends vertex i with position p and normal n to every per-vertex array the scene keeps.
  std::uint32_t push(Scene& s, std::uint32_t i, const glm::vec3& p, const glm::vec3& n) const {
    s.positions.push_back(p);
    s.normals.push_back(n);
    if (uv0_needed_) {
      glm::vec2 uv(0.0f);
      if (uv_) uv_->read(i, glm::value_ptr(uv));
      s.uv0.push_back(uv);
    }
    if (color0_needed_) {
      float f[4] = {0.0f, 0.0f, 0.0f, 1.0f};  // vec3 colours are opaque
      if (color_) color_->read(i, f);
      s.color0.push_back(color_ ? glm::vec4(f[0], f[1], f[2], f[3]) : glm::vec4(1.0f));
    }
    if (uv1_needed_) {
      glm::vec2 uv1(0.0f);
      if (uv1_) uv1_->read(i, glm::value_ptr(uv1));
      s.uv1.push_back(uv1);
    }
    if (tangents_needed_) {
      float t[4] = {0.0f, 0.0f, 0.0f, 1.0f};
      if (tangent_) tangent_->read(i, t);
      s.tangents.push_back(tangent_ ? world_tangent(linear_, mirror_, t)
                                    : glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));
    }
    return static_cast<std::uint32_t>(s.positions.size() - 1);
  }

 private:
  const AccessorReader& pos_;
  std::optional<AccessorReader> normal_, uv_, color_, uv1_, tangent_;
  glm::dmat4 world_;
  glm::dmat3 linear_;  // world's 3x3: tangents
  glm::dmat3 normal_matrix_;
  bool mirror_;
  bool uv0_needed_, color0_needed_, uv1_needed_, tangents_needed_;
};

// Makes room for `extra` more vertices in every per-vertex array the scene keeps. A vector that
// must grow gets what is asked plus a quarter of what it holds, not twice its size: the arrays of
// a large scene are most of the loader's memory, and the reallocation holds both copies at once.
void reserve_vertices(Scene& s, std::size_t extra) {
  const std::size_t need = s.positions.size() + extra;
  if (need <= s.positions.capacity()) return;
  const std::size_t capacity = std::max(need, s.positions.size() + s.positions.size() / 4);
  s.positions.reserve(capacity);
  s.normals.reserve(capacity);
  for (auto* kept : {&s.uv0, &s.uv1})  // the optional arrays the scene keeps (VertexNeeds)
    if (kept->capacity()) kept->reserve(capacity);
  for (auto* kept : {&s.color0, &s.tangents})
    if (kept->capacity()) kept->reserve(capacity);
}

// A vertex's normal as emit() has found it: not looked at yet, usable, or missing (absent, zero
// or not finite after the transform).
enum : std::uint8_t { kNormalUnknown = 0, kNormalUsable = 1, kNormalMissing = 2 };

// Appends triangles over the primitive's vertex indices `tris`: shared vertices where all three
// corners have normals, unshared ones with the face normal otherwise, in the order of the
// triangles (first use). Counts the vertices first, so that the arrays grow once, by that much.
void emit(const VertexSource& v, std::size_t vertex_count, const std::vector<std::uint32_t>& tris,
          std::uint32_t material, Scene& s, const VertexNeeds& needs) {
  const bool flip = v.mirror();
  std::vector<std::uint8_t> normal_state(vertex_count, kNormalUnknown);
  const auto usable = [&](std::uint32_t i) {
    if (normal_state[i] == kNormalUnknown)
      normal_state[i] = v.normal(i) != glm::vec3(0.0f) ? kNormalUsable : kNormalMissing;
    return normal_state[i] == kNormalUsable;
  };
  const auto corners = [&](std::size_t t, std::uint32_t* k) {
    k[0] = tris[t], k[1] = tris[t + (flip ? 2 : 1)], k[2] = tris[t + (flip ? 1 : 2)];
    return usable(k[0]) && usable(k[1]) && usable(k[2]);
  };
  std::vector<std::uint32_t> scene_index(vertex_count, kUnused);
  std::size_t added = 0;  // first pass: how many vertices the triangles add
  for (std::size_t t = 0; t + 2 < tris.size(); t += 3) {
    std::uint32_t k[3];
    if (!corners(t, k)) {
      added += 3;
      continue;
    }
    for (const std::uint32_t c : k)
      if (scene_index[c] == kUnused) scene_index[c] = 0, ++added;
  }
  if (s.positions.size() + added >= kUnused)
    throw Error("more vertices than 32-bit indices can address");
  // A kept optional array has capacity from the first primitive on: reserve_vertices grows it.
  const auto keep = [&](bool needed, auto& array) {
    if (needed && array.capacity() == 0)
      array.reserve(std::max<std::size_t>(s.positions.capacity(), 1));
  };
  keep(needs.uv0, s.uv0);
  keep(needs.color0, s.color0);
  keep(needs.uv1, s.uv1);
  keep(needs.tangents, s.tangents);
  reserve_vertices(s, added);
  std::fill(scene_index.begin(), scene_index.end(), kUnused);
  const auto shared = [&](std::uint32_t c) {
    if (scene_index[c] == kUnused) scene_index[c] = v.push(s, c, v.position(c), v.normal(c));
    return scene_index[c];
  };
  for (std::size_t t = 0; t + 2 < tris.size(); t += 3) {
    std::uint32_t k[3];
    if (corners(t, k)) {
      for (const std::uint32_t c : k) s.indices.push_back(shared(c));
    } else {
      const glm::vec3 p[3] = {v.position(k[0]), v.position(k[1]), v.position(k[2])};
      const glm::dvec3 p0(p[0]);  // double: tiny triangles must not underflow
      const glm::dvec3 face = glm::cross(glm::dvec3(p[1]) - p0, glm::dvec3(p[2]) - p0);
      const double len = glm::length(face);
      // A zero-area triangle has no face normal; any unit vector keeps normals unit.
      const glm::vec3 n = len > 0.0 ? glm::vec3(face / len) : glm::vec3(0.0f, 0.0f, 1.0f);
      for (int j = 0; j < 3; ++j) s.indices.push_back(v.push(s, k[j], p[j], n));
    }
    s.triangle_material.push_back(material);
  }
}

// ---------------------------------------------------------------------------------------------
// Tangent generation (see generate_tangents in the header).

// One triangle's UV frame: unit tangent (dP/du) and bitangent (-dP/dv, the image's up), and the
// handedness of (face normal, tangent, bitangent); sign 0 where the UV mapping is degenerate.
struct FaceFrame {
  glm::dvec3 t{0.0}, up{0.0};
  int sign = 0;
};

FaceFrame face_frame(const Scene& s, const std::vector<glm::vec2>& uv, const std::uint32_t* c) {
  const glm::dvec3 p0(s.positions[c[0]]);
  const glm::dvec3 e1 = glm::dvec3(s.positions[c[1]]) - p0;
  const glm::dvec3 e2 = glm::dvec3(s.positions[c[2]]) - p0;
  const glm::dvec2 d1 = glm::dvec2(uv[c[1]]) - glm::dvec2(uv[c[0]]);
  const glm::dvec2 d2 = glm::dvec2(uv[c[2]]) - glm::dvec2(uv[c[0]]);
  const double det = d1.x * d2.y - d2.x * d1.y;
  FaceFrame f;
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return f;
  // P - p0 = a e1 + b e2 where (u, v) - uv0 = a d1 + b d2; differentiate a and b by u and v.
  const glm::dvec3 dpdu = (e1 * d2.y - e2 * d1.y) / det;
  const glm::dvec3 dpdv = (e2 * d1.x - e1 * d2.x) / det;
  const double lt = glm::length(dpdu), lb = glm::length(dpdv);
  if (!(lt > 0.0 && lb > 0.0) || !std::isfinite(lt + lb)) return f;
  f.t = dpdu / lt;
  f.up = -dpdv / lb;
  f.sign = glm::dot(glm::cross(glm::cross(e1, e2), f.t), f.up) < 0.0 ? -1 : 1;
  return f;
}

// The angle of triangle c at corner k, the weight of its frame at that vertex.
double corner_angle(const Scene& s, const std::uint32_t* c, int k) {
  const glm::dvec3 p(s.positions[c[k]]);
  const glm::dvec3 a = glm::dvec3(s.positions[c[(k + 1) % 3]]) - p;
  const glm::dvec3 b = glm::dvec3(s.positions[c[(k + 2) % 3]]) - p;
  const double la = glm::length(a), lb = glm::length(b);
  if (!(la > 0.0 && lb > 0.0)) return 0.0;
  return std::acos(std::clamp(glm::dot(a, b) / (la * lb), -1.0, 1.0));
}

// Appends a copy of vertex i (every per-vertex array) and returns it.
std::uint32_t duplicate_vertex(Scene& s, std::uint32_t i) {
  if (s.positions.size() + 1 >= kUnused)
    throw Error("more vertices than 32-bit indices can address");
  reserve_vertices(s, 1);
  s.positions.push_back(s.positions[i]);
  s.normals.push_back(s.normals[i]);
  if (!s.uv0.empty()) s.uv0.push_back(s.uv0[i]);
  if (!s.color0.empty()) s.color0.push_back(s.color0[i]);
  if (!s.uv1.empty()) s.uv1.push_back(s.uv1[i]);
  s.tangents.push_back(s.tangents[i]);
  return static_cast<std::uint32_t>(s.positions.size() - 1);
}

// Gives each vertex one handedness: the first sign among its triangles keeps the vertex, the
// other sign's triangles get a twin of it. Returns the sign of every vertex from `base` on
// (0: only triangles without a usable UV mapping).
std::vector<int> split_handedness(Scene& s, std::size_t first_triangle,
                                  const std::vector<FaceFrame>& frames, std::uint32_t base) {
  const std::size_t count = s.positions.size() - base;
  std::vector<int> sign(count, 0);
  std::vector<std::uint32_t> twin(count, kUnused);
  for (std::size_t t = first_triangle; t < s.triangle_count(); ++t) {
    const int f = frames[t - first_triangle].sign;
    for (std::size_t k = 3 * t; k < 3 * t + 3 && f != 0; ++k) {
      const std::uint32_t i = s.indices[k] - base;
      if (sign[i] == 0) sign[i] = f;
      if (sign[i] == f) continue;
      if (twin[i] == kUnused) twin[i] = duplicate_vertex(s, base + i);
      s.indices[k] = twin[i];
    }
  }
  sign.resize(s.positions.size() - base, 0);
  for (std::size_t i = 0; i < count; ++i)
    if (twin[i] != kUnused) sign[twin[i] - base] = -sign[i];
  return sign;
}

// The unit tangent at a vertex with unit normal n from the accumulated frames, handedness w.
glm::vec3 vertex_tangent(const glm::dvec3& n, const glm::dvec3& t_sum, const glm::dvec3& up_sum,
                         double w) {
  glm::dvec3 t = t_sum - n * glm::dot(n, t_sum);  // Gram-Schmidt
  if (!(glm::length(t) > 1e-12)) t = w * glm::cross(up_sum - n * glm::dot(n, up_sum), n);
  if (!(glm::length(t) > 1e-12)) {  // no usable UVs here: any direction in the tangent plane
    const glm::dvec3 axis = std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    t = glm::cross(n, glm::cross(axis, n));
  }
  return glm::vec3(glm::normalize(t));
}

}  // namespace

void generate_tangents(Scene& s, std::size_t first_triangle, int uv_set) {
  const std::vector<glm::vec2>& uv = uv_set == 1 ? s.uv1 : s.uv0;
  if (uv.size() != s.positions.size() || s.tangents.size() != s.positions.size())
    throw Error("tangent generation needs TEXCOORD_" + std::to_string(uv_set) + " and tangents");
  const std::size_t tris = s.triangle_count();
  if (first_triangle >= tris) return;
  std::vector<FaceFrame> frames(tris - first_triangle);
  for (std::size_t t = first_triangle; t < tris; ++t)
    frames[t - first_triangle] = face_frame(s, uv, &s.indices[3 * t]);
  // Per-vertex work covers only [base, end): the vertices these triangles use (a primitive's,
  // appended last) and the twins split_handedness appends.
  const std::uint32_t base =
      *std::min_element(s.indices.begin() + std::ptrdiff_t(3 * first_triangle), s.indices.end());
  const std::vector<int> sign = split_handedness(s, first_triangle, frames, base);

  const std::size_t n = s.positions.size() - base;
  std::vector<glm::dvec3> t_sum(n, glm::dvec3(0.0)), up_sum(n, glm::dvec3(0.0));
  std::vector<bool> touched(n, false);
  for (std::size_t t = first_triangle; t < tris; ++t) {
    const FaceFrame& f = frames[t - first_triangle];
    for (int k = 0; k < 3; ++k) {
      const std::size_t i = s.indices[3 * t + static_cast<std::size_t>(k)] - base;
      const double a = corner_angle(s, &s.indices[3 * t], k);
      t_sum[i] += a * f.t;
      up_sum[i] += a * f.up;
      touched[i] = true;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!touched[i]) continue;
    const double w = sign[i] < 0 ? -1.0 : 1.0;
    const glm::dvec3 normal(s.normals[base + i]);
    s.tangents[base + i] =
        glm::vec4(vertex_tangent(normal, t_sum[i], up_sum[i], w), static_cast<float>(w));
  }
}

bool is_triangle_mode(int mode) {
  return mode < 0 || mode == TINYGLTF_MODE_TRIANGLES || mode == TINYGLTF_MODE_TRIANGLE_STRIP ||
         mode == TINYGLTF_MODE_TRIANGLE_FAN;
}

std::size_t append_primitive(const tinygltf::Model& model, const tinygltf::Primitive& primitive,
                             const glm::dmat4& world, std::uint32_t material,
                             const VertexNeeds& needs, Scene& scene) {
  const AccessorReader pos(model, attribute(primitive, "POSITION"), kPosition);
  if (pos.count() >= kUnused) throw Error("more vertices than 32-bit indices can address");
  std::size_t leftover = 0;
  const std::vector<std::uint32_t> tris =
      triangle_corners(model, primitive, pos.count(), &leftover);
  const VertexSource v(model, primitive, pos, world, needs);
  const std::size_t first_triangle = scene.triangle_count();
  emit(v, pos.count(), tris, material, scene, needs);
  if (needs.tangents && !v.has_tangents())
    generate_tangents(scene, first_triangle, needs.tangent_uv);
  return leftover;
}

}  // namespace wp::gltf
