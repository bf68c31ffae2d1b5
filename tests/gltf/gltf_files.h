// The glTF loader tests' shared fixture (tests/gltf/test_gltf_*.cpp, one file per loader file
// in host/scene/): glTF files assembled in memory (Gltf) and written to a temporary folder,
// and the checks every loaded scene must pass.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <unistd.h>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>
#include <stb_image_write.h>

#include "host/util/error.h"
#include "host/scene/gltf_loader.h"
#include "host/scene/gltf_primitive.h"
#include "tests/test_assets.h"

namespace wp::test::gltf_files {

namespace fs = std::filesystem;
using glm::vec3;

constexpr float kPi = 3.14159265358979f;
constexpr int kU8 = 5121, kU16 = 5123, kU32 = 5125, kF32 = 5126, kI8 = 5120, kI16 = 5122;

inline const fs::path& temp_dir() {
  static const fs::path dir = [] {
    // Memory-backed when available: the corruption test writes a few thousand small files.
    const fs::path root = fs::is_directory("/dev/shm") ? "/dev/shm" : fs::temp_directory_path();
    fs::path d = root / ("wp_gltf_test_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

class TempCleanup : public ::testing::Environment {
 public:
  void TearDown() override { fs::remove_all(temp_dir()); }
};

inline std::string base64(const std::vector<unsigned char>& in) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < in.size(); i += 3) {
    const unsigned v = (in[i] << 16u) | (i + 1 < in.size() ? in[i + 1] << 8u : 0u) |
                       (i + 2 < in.size() ? in[i + 2] : 0u);
    for (int k = 0; k < 4; ++k)
      out += (i + static_cast<std::size_t>(k) <= in.size()) ? kAlphabet[(v >> (18 - 6 * k)) & 63]
                                                            : '=';
  }
  return out;
}

inline std::string join(const std::vector<std::string>& items) {
  std::string s;
  for (const std::string& item : items) s += (s.empty() ? "" : ",") + item;
  return s;
}

inline std::string list(const std::vector<int>& items) {
  std::vector<std::string> s;
  for (const int i : items) s.push_back(std::to_string(i));
  return "[" + join(s) + "]";
}

inline void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// Assembles a glTF file: one buffer, and JSON arrays that tests fill with raw JSON objects.
struct Gltf {
  std::vector<unsigned char> bin;
  std::vector<std::string> views, accessors, meshes, nodes, materials, cameras, lights;
  std::vector<int> roots;
  std::string top;                 // extra top-level members, e.g. "extensionsUsed":[...]
  std::string scenes = "default";  // or raw members replacing "scene" and "scenes"

  template <typename T>
  int view(const std::vector<T>& data, std::size_t stride = 0) {
    while (bin.size() % 4) bin.push_back(0);
    const std::size_t offset = bin.size(), size = data.size() * sizeof(T);
    const auto* p = reinterpret_cast<const unsigned char*>(data.data());
    bin.insert(bin.end(), p, p + size);
    views.push_back("{\"buffer\":0,\"byteOffset\":" + std::to_string(offset) +
                    ",\"byteLength\":" + std::to_string(size) +
                    (stride ? ",\"byteStride\":" + std::to_string(stride) : "") + "}");
    return static_cast<int>(views.size()) - 1;
  }
  int accessor(int view_index, int component_type, std::size_t count, const std::string& type,
               const std::string& extra = "") {
    accessors.push_back(
        "{" +
        (view_index >= 0 ? "\"bufferView\":" + std::to_string(view_index) + "," : std::string()) +
        "\"componentType\":" + std::to_string(component_type) +
        ",\"count\":" + std::to_string(count) + ",\"type\":\"" + type + "\"" + extra + "}");
    return static_cast<int>(accessors.size()) - 1;
  }
  int vec3s(const std::vector<vec3>& v) { return accessor(view(v), kF32, v.size(), "VEC3"); }
  template <typename T>
  int indices(const std::vector<T>& v) {
    const int type = sizeof(T) == 1 ? kU8 : sizeof(T) == 2 ? kU16 : kU32;
    return accessor(view(v), type, v.size(), "SCALAR");
  }
  int mesh(const std::vector<std::string>& primitives) {
    meshes.push_back("{\"primitives\":[" + join(primitives) + "]}");
    return static_cast<int>(meshes.size()) - 1;
  }
  int node(const std::string& body, bool root = false) {
    nodes.push_back("{" + body + "}");
    if (root) roots.push_back(static_cast<int>(nodes.size()) - 1);
    return static_cast<int>(nodes.size()) - 1;
  }

  std::string json(bool glb) const {
    std::string s = "{\"asset\":{\"version\":\"2.0\"}";
    if (!top.empty()) s += "," + top;
    s += scenes == "default" ? ",\"scene\":0,\"scenes\":[{\"nodes\":" + list(roots) + "}]"
         : scenes.empty()    ? ""
                             : "," + scenes;
    const auto section = [&](const char* name, const std::vector<std::string>& items) {
      if (!items.empty()) s += ",\"" + std::string(name) + "\":[" + join(items) + "]";
    };
    section("nodes", nodes);
    section("meshes", meshes);
    section("materials", materials);
    section("cameras", cameras);
    section("accessors", accessors);
    section("bufferViews", views);
    s += ",\"buffers\":[{\"byteLength\":" + std::to_string(bin.size()) +
         (glb ? "" : ",\"uri\":\"data:application/octet-stream;base64," + base64(bin) + "\"") +
         "}]";
    if (!lights.empty())
      s += ",\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[" + join(lights) + "]}}";
    return s + "}";
  }
  std::string write(const std::string& name) const {
    const std::string path = (temp_dir() / name).string();
    write_bytes(path, json(false));
    return path;
  }
  std::string glb() const {
    std::string j = json(true), b(bin.begin(), bin.end());
    while (j.size() % 4) j += ' ';
    while (b.size() % 4) b += '\0';
    const auto u32 = [](std::size_t v) {
      const auto x = static_cast<std::uint32_t>(v);
      std::string s(4, '\0');
      std::memcpy(&s[0], &x, 4);
      return s;
    };
    return "glTF" + u32(2) + u32(12 + 8 + j.size() + 8 + b.size()) + u32(j.size()) + "JSON" + j +
           u32(b.size()) + std::string("BIN\0", 4) + b;
  }
  std::string write_glb(const std::string& name) const {
    const std::string path = (temp_dir() / name).string();
    write_bytes(path, glb());
    return path;
  }
};

inline std::string prim(const std::map<std::string, int>& attributes, int indices = -1,
                        int mode = -1, int material = -1) {
  std::vector<std::string> a;
  for (const auto& [name, index] : attributes)
    a.push_back("\"" + name + "\":" + std::to_string(index));
  return "{\"attributes\":{" + join(a) + "}" +
         (indices >= 0 ? ",\"indices\":" + std::to_string(indices) : "") +
         (mode >= 0 ? ",\"mode\":" + std::to_string(mode) : "") +
         (material >= 0 ? ",\"material\":" + std::to_string(material) : "") + "}";
}

inline ::testing::AssertionResult near(const vec3& a, const vec3& b, float eps = 1e-5f) {
  if (glm::length(a - b) <= eps) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "(" << a.x << ", " << a.y << ", " << a.z << ") vs ("
                                       << b.x << ", " << b.y << ", " << b.z << ")";
}

inline vec3 corner(const wp::Scene& s, std::size_t t, int c) {
  return s.positions[s.indices[3 * t + static_cast<std::size_t>(c)]];
}

inline vec3 geometric_normal(const wp::Scene& s, std::size_t t) {
  return glm::normalize(
      glm::cross(corner(s, t, 1) - corner(s, t, 0), corner(s, t, 2) - corner(s, t, 0)));
}

// What every loaded scene guarantees (scene.h).
inline void check_invariants(const wp::Scene& s) {
  ASSERT_GT(s.triangle_count(), 0u);
  ASSERT_EQ(s.indices.size() % 3, 0u);
  ASSERT_EQ(s.triangle_material.size(), s.triangle_count());
  ASSERT_EQ(s.normals.size(), s.positions.size());
  ASSERT_TRUE(s.uv0.empty() || s.uv0.size() == s.positions.size());        // empty: all (0, 0)
  ASSERT_TRUE(s.color0.empty() || s.color0.size() == s.positions.size());  // empty: all 1
  ASSERT_FALSE(s.materials.empty());
  for (const std::uint32_t i : s.indices) ASSERT_LT(i, s.positions.size());
  for (const std::uint32_t m : s.triangle_material) ASSERT_LT(m, s.materials.size());
  for (std::size_t i = 0; i < s.positions.size(); ++i) {
    const vec3& p = s.positions[i];
    ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
    ASSERT_TRUE(glm::all(glm::lessThanEqual(s.bounds_lo, p)) &&
                glm::all(glm::lessThanEqual(p, s.bounds_hi)));
    ASSERT_NEAR(glm::length(s.normals[i]), 1.0f, 1e-4f) << "vertex " << i;
  }
}

// Expects load_gltf(path) to throw wp::Error whose message names the path and `needle`.
inline void expect_error(const std::string& path, const std::string& needle) {
  try {
    wp::load_gltf(path);
    ADD_FAILURE() << path << " loaded; expected an error about " << needle;
  } catch (const wp::Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find(needle), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

// One triangle (0,0,0), (1,0,0), (0,1,0) in node `body`; with `normals`, one per corner.
inline Gltf one_triangle(const std::string& body, const std::vector<vec3>& normals = {}) {
  Gltf g;
  std::map<std::string, int> a{{"POSITION", g.vec3s({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}})}};
  if (!normals.empty()) a["NORMAL"] = g.vec3s(normals);
  g.mesh({prim(a)});
  g.node("\"mesh\":0" + std::string(body.empty() ? "" : ",") + body, true);
  return g;
}

// A two-level hierarchy (test_gltf_nodes.cpp; GLB and corruption tests in test_gltf_loader.cpp).
// Parent: T(1,2,3) R_y(90 deg) S(2); child: matrix scaling x by 3 then translating (0,0,1).
// R_y(90) maps (x,y,z) to (z,y,-x). Corners: (0,0,0) -> C (0,0,1) -> S (0,0,2) -> R (2,0,0) ->
// T (3,2,3); (1,0,0) -> (3,0,1) -> (6,0,2) -> (2,0,-6) -> (3,2,-3); (0,1,0) -> (0,1,1) ->
// (0,2,2) -> (2,2,0) -> (3,4,3). Normals go by R diag(1/3,1,1) (inverse transpose, up to
// scale): (0,0,1) -> (1,0,0); (1,0,1)/sqrt2 -> R (1/3,0,1) = (1,0,-1/3) -> (3,0,-1)/sqrt10.
inline Gltf hierarchy() {
  Gltf g;
  const float h = std::sqrt(0.5f);
  const int pos = g.vec3s({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const int nrm = g.vec3s({{0, 0, 1}, {h, 0, h}, {0, 0, 1}});
  g.mesh({prim({{"POSITION", pos}, {"NORMAL", nrm}})});
  g.node(
      "\"translation\":[1,2,3],\"rotation\":[0,0.70710678,0,0.70710678],\"scale\":[2,2,2],"
      "\"children\":[1]",
      true);
  g.node("\"mesh\":0,\"matrix\":[3,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,1,1]");
  return g;
}

inline void check_hierarchy(const wp::Scene& s) {
  check_invariants(s);
  ASSERT_EQ(s.triangle_count(), 1u);
  EXPECT_TRUE(near(corner(s, 0, 0), {3, 2, 3}));
  EXPECT_TRUE(near(corner(s, 0, 1), {3, 2, -3}));
  EXPECT_TRUE(near(corner(s, 0, 2), {3, 4, 3}));
  EXPECT_TRUE(near(s.normals[s.indices[0]], {1, 0, 0}));
  EXPECT_TRUE(near(s.normals[s.indices[1]], vec3(3, 0, -1) / std::sqrt(10.0f)));
  EXPECT_TRUE(near(geometric_normal(s, 0), {1, 0, 0}));
  EXPECT_TRUE(near(s.bounds_lo, {3, 2, -3}));
  EXPECT_TRUE(near(s.bounds_hi, {3, 4, 3}));
}

// A unit quad, indexed or not (test_gltf_primitive.cpp, test_gltf_accessor.cpp).
inline const std::vector<vec3> kQuad = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
inline const std::vector<int> kQuadCorners = {0, 1, 2, 0, 2, 3};

inline void check_quad(const wp::Scene& s) {
  check_invariants(s);
  ASSERT_EQ(s.triangle_count(), 2u);
  for (std::size_t i = 0; i < 6; ++i)
    EXPECT_TRUE(near(s.positions[s.indices[i]], kQuad[static_cast<std::size_t>(kQuadCorners[i])]))
        << "corner " << i;
}

template <typename T>
inline void check_indexed_quad(const char* name) {
  Gltf g;
  const int pos = g.vec3s(kQuad);
  const int idx = g.indices(std::vector<T>(kQuadCorners.begin(), kQuadCorners.end()));
  g.mesh({prim({{"POSITION", pos}}, idx)});
  g.node("\"mesh\":0", true);
  const wp::Scene s = wp::load_gltf(g.write(name));
  check_quad(s);
  EXPECT_EQ(s.positions.size(), 6u);  // no normals: flat, unshared
}

// Textures (test_gltf_textures.cpp; tangents in test_gltf_primitive.cpp).
// stb_image_write's callback appending to a std::vector<unsigned char>.
inline void append_bytes(void* out, void* data, int size) {
  auto* v = static_cast<std::vector<unsigned char>*>(out);
  v->insert(v->end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
}

inline std::vector<unsigned char> encode_png(int w, int h, const std::vector<unsigned char>& rgba) {
  std::vector<unsigned char> png;
  stbi_write_png_to_func(append_bytes, &png, w, h, 4, rgba.data(), 4 * w);
  return png;
}

inline std::vector<unsigned char> encode_jpeg(int w, int h,
                                              const std::vector<unsigned char>& rgba) {
  std::vector<unsigned char> jpeg;
  stbi_write_jpg_to_func(append_bytes, &jpeg, w, h, 4, rgba.data(), 90);
  return jpeg;
}

inline std::string png_data_uri(int w, int h, const std::vector<unsigned char>& rgba) {
  return "data:image/png;base64," + base64(encode_png(w, h, rgba));
}

// Image 0: 2x2 RGBA (red, green / blue, half-transparent white); image 1: 1x1 grey.
inline const std::vector<unsigned char> kImage0 = {255, 0, 0,   255, 0,   255, 0,   255,
                                                   0,   0, 255, 255, 255, 255, 255, 128};
inline std::string test_images() {
  return R"("images":[{"uri":")" + png_data_uri(2, 2, kImage0) + R"("},{"name":"grey","uri":")" +
         png_data_uri(1, 1, {90, 90, 90, 255}) + R"("}])";
}

// A unit square at z = 0 facing +z: TEXCOORD_0 = (x, 1 - y) (u mirrored: (1 - x, 1 - y)),
// TEXCOORD_1 = (2x, y), indices (0,1,2), (0,2,3); one primitive per material in `materials`.
inline Gltf textured_square(const std::vector<int>& materials, bool mirror_u = false) {
  Gltf g;
  const float a = mirror_u ? 1.0f : 0.0f, b = mirror_u ? -1.0f : 1.0f;
  const int pos = g.vec3s({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}});
  const int nrm = g.vec3s({{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}});
  const std::vector<glm::vec2> uv0 = {{a, 1}, {a + b, 1}, {a + b, 0}, {a, 0}};
  const std::vector<glm::vec2> uv1 = {{0, 0}, {2, 0}, {2, 1}, {0, 1}};
  const int t0 = g.accessor(g.view(uv0), kF32, 4, "VEC2");
  const int t1 = g.accessor(g.view(uv1), kF32, 4, "VEC2");
  const int idx = g.indices<std::uint16_t>({0, 1, 2, 0, 2, 3});
  std::vector<std::string> prims;
  for (const int m : materials)
    prims.push_back(prim(
        {{"POSITION", pos}, {"NORMAL", nrm}, {"TEXCOORD_0", t0}, {"TEXCOORD_1", t1}}, idx, -1, m));
  g.mesh(prims);
  g.node("\"mesh\":0", true);
  return g;
}

// What every tangent guarantees: unit, orthogonal to its vertex normal (within `ortho`: supplied
// ones are only as orthogonal as the file's data), w = +-1.
inline void check_tangents(const wp::Scene& s, float ortho = 1e-5f) {
  ASSERT_EQ(s.tangents.size(), s.positions.size());
  for (std::size_t i = 0; i < s.tangents.size(); ++i) {
    const glm::vec4& t = s.tangents[i];
    ASSERT_NEAR(glm::length(vec3(t)), 1.0f, 1e-5f) << "vertex " << i;
    ASSERT_NEAR(glm::dot(vec3(t), s.normals[i]), 0.0f, ortho) << "vertex " << i;
    ASSERT_TRUE(t.w == 1.0f || t.w == -1.0f) << "vertex " << i;
  }
}

}  // namespace wp::test::gltf_files
