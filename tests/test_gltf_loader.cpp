// glTF loader: small synthetic files written by the tests (expected values derived by hand next
// to each), malformed input, and the shared real-world assets (skipped when absent).
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

namespace {

namespace fs = std::filesystem;
using glm::vec3;

constexpr float kPi = 3.14159265358979f;
constexpr int kU8 = 5121, kU16 = 5123, kU32 = 5125, kF32 = 5126, kI8 = 5120, kI16 = 5122;

const fs::path& temp_dir() {
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
[[maybe_unused]] auto* const kCleanup = ::testing::AddGlobalTestEnvironment(new TempCleanup);

std::string base64(const std::vector<unsigned char>& in) {
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

std::string join(const std::vector<std::string>& items) {
  std::string s;
  for (const std::string& item : items) s += (s.empty() ? "" : ",") + item;
  return s;
}

std::string list(const std::vector<int>& items) {
  std::vector<std::string> s;
  for (const int i : items) s.push_back(std::to_string(i));
  return "[" + join(s) + "]";
}

void write_bytes(const std::string& path, const std::string& bytes) {
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

std::string prim(const std::map<std::string, int>& attributes, int indices = -1, int mode = -1,
                 int material = -1) {
  std::vector<std::string> a;
  for (const auto& [name, index] : attributes)
    a.push_back("\"" + name + "\":" + std::to_string(index));
  return "{\"attributes\":{" + join(a) + "}" +
         (indices >= 0 ? ",\"indices\":" + std::to_string(indices) : "") +
         (mode >= 0 ? ",\"mode\":" + std::to_string(mode) : "") +
         (material >= 0 ? ",\"material\":" + std::to_string(material) : "") + "}";
}

::testing::AssertionResult near(const vec3& a, const vec3& b, float eps = 1e-5f) {
  if (glm::length(a - b) <= eps) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "(" << a.x << ", " << a.y << ", " << a.z << ") vs ("
                                       << b.x << ", " << b.y << ", " << b.z << ")";
}

vec3 corner(const wp::Scene& s, std::size_t t, int c) {
  return s.positions[s.indices[3 * t + static_cast<std::size_t>(c)]];
}

vec3 geometric_normal(const wp::Scene& s, std::size_t t) {
  return glm::normalize(
      glm::cross(corner(s, t, 1) - corner(s, t, 0), corner(s, t, 2) - corner(s, t, 0)));
}

// What every loaded scene guarantees (scene.h).
void check_invariants(const wp::Scene& s) {
  ASSERT_GT(s.triangle_count(), 0u);
  ASSERT_EQ(s.indices.size() % 3, 0u);
  ASSERT_EQ(s.triangle_material.size(), s.triangle_count());
  ASSERT_EQ(s.normals.size(), s.positions.size());
  ASSERT_EQ(s.uv0.size(), s.positions.size());
  ASSERT_EQ(s.color0.size(), s.positions.size());
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
void expect_error(const std::string& path, const std::string& needle) {
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
Gltf one_triangle(const std::string& body, const std::vector<vec3>& normals = {}) {
  Gltf g;
  std::map<std::string, int> a{{"POSITION", g.vec3s({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}})}};
  if (!normals.empty()) a["NORMAL"] = g.vec3s(normals);
  g.mesh({prim(a)});
  g.node("\"mesh\":0" + std::string(body.empty() ? "" : ",") + body, true);
  return g;
}

// ---------------------------------------------------------------------------------------------
// Transforms

// Parent: T(1,2,3) R_y(90 deg) S(2); child: matrix scaling x by 3 then translating (0,0,1).
// R_y(90) maps (x,y,z) to (z,y,-x). Corners: (0,0,0) -> C (0,0,1) -> S (0,0,2) -> R (2,0,0) ->
// T (3,2,3); (1,0,0) -> (3,0,1) -> (6,0,2) -> (2,0,-6) -> (3,2,-3); (0,1,0) -> (0,1,1) ->
// (0,2,2) -> (2,2,0) -> (3,4,3). Normals go by R diag(1/3,1,1) (inverse transpose, up to
// scale): (0,0,1) -> (1,0,0); (1,0,1)/sqrt2 -> R (1/3,0,1) = (1,0,-1/3) -> (3,0,-1)/sqrt10.
Gltf hierarchy() {
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

void check_hierarchy(const wp::Scene& s) {
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

TEST(GltfLoader, TrsAndMatrixThroughHierarchy) {
  const std::string path = hierarchy().write("hierarchy.gltf");
  const wp::Scene s = wp::load_gltf(path);
  EXPECT_EQ(s.source, path);
  EXPECT_TRUE(s.warnings.empty());
  check_hierarchy(s);
}

TEST(GltfLoader, GlbMatchesGltf) {
  const wp::Scene s = wp::load_gltf(hierarchy().write_glb("hierarchy.glb"));
  check_hierarchy(s);
  // Content decides the format, not the extension.
  check_hierarchy(wp::load_gltf(hierarchy().write_glb("binary_named.gltf")));
}

// Mirroring by scale (-1,1,1): corners (0,0,0), (-1,0,0), (0,1,0); the normal (0,0,1) maps to
// (0,0,1), and the winding must be swapped for the front (geometric normal) to stay +Z.
TEST(GltfLoader, MirroredNodeKeepsCounterClockwiseFront) {
  for (const bool with_normals : {true, false}) {
    const wp::Scene s = wp::load_gltf(
        one_triangle("\"scale\":[-1,1,1]",
                     with_normals ? std::vector<vec3>(3, {0, 0, 1}) : std::vector<vec3>{})
            .write("mirror.gltf"));
    check_invariants(s);
    EXPECT_TRUE(near(geometric_normal(s, 0), {0, 0, 1})) << with_normals;
    for (int c = 0; c < 3; ++c) EXPECT_TRUE(near(s.normals[s.indices[c]], {0, 0, 1}));
    EXPECT_TRUE(near(s.bounds_lo, {-1, 0, 0}));
  }
  // Two mirrors cancel: diag(-1,1,-1) keeps the winding; both normals become (0,0,-1).
  Gltf g = one_triangle("\"scale\":[1,1,-1]", std::vector<vec3>(3, {0, 0, 1}));
  g.node("\"scale\":[-1,1,1],\"children\":[0]");
  g.roots = {1};
  const wp::Scene s = wp::load_gltf(g.write("mirror2.gltf"));
  EXPECT_TRUE(near(corner(s, 0, 1), {-1, 0, 0}));
  EXPECT_TRUE(near(geometric_normal(s, 0), {0, 0, -1}));
  EXPECT_TRUE(near(s.normals[s.indices[0]], {0, 0, -1}));
}

// ---------------------------------------------------------------------------------------------
// Primitives

const std::vector<vec3> kQuad = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
const std::vector<int> kQuadCorners = {0, 1, 2, 0, 2, 3};

void check_quad(const wp::Scene& s) {
  check_invariants(s);
  ASSERT_EQ(s.triangle_count(), 2u);
  for (std::size_t i = 0; i < 6; ++i)
    EXPECT_TRUE(near(s.positions[s.indices[i]], kQuad[static_cast<std::size_t>(kQuadCorners[i])]))
        << "corner " << i;
}

template <typename T>
void check_indexed_quad(const char* name) {
  Gltf g;
  const int pos = g.vec3s(kQuad);
  const int idx = g.indices(std::vector<T>(kQuadCorners.begin(), kQuadCorners.end()));
  g.mesh({prim({{"POSITION", pos}}, idx)});
  g.node("\"mesh\":0", true);
  const wp::Scene s = wp::load_gltf(g.write(name));
  check_quad(s);
  EXPECT_EQ(s.positions.size(), 6u);  // no normals: flat, unshared
}

TEST(GltfLoader, IndexTypesAndNonIndexed) {
  check_indexed_quad<std::uint8_t>("u8.gltf");
  check_indexed_quad<std::uint16_t>("u16.gltf");
  check_indexed_quad<std::uint32_t>("u32.gltf");
  Gltf g;
  std::vector<vec3> corners;
  for (const int c : kQuadCorners) corners.push_back(kQuad[static_cast<std::size_t>(c)]);
  g.mesh({prim({{"POSITION", g.vec3s(corners)}})});
  g.node("\"mesh\":0", true);
  check_quad(wp::load_gltf(g.write("nonindexed.gltf")));
}

// Positions and normals interleaved in one view (stride 24), the normals at byteOffset 12.
TEST(GltfLoader, InterleavedStrideAndOffset) {
  std::vector<vec3> interleaved;
  for (const vec3& p : kQuad) interleaved.insert(interleaved.end(), {p, {0, 0, 1}});
  Gltf g;
  const int v = g.view(interleaved, 24);
  const int pos = g.accessor(v, kF32, 4, "VEC3");
  const int nrm = g.accessor(v, kF32, 4, "VEC3", ",\"byteOffset\":12");
  g.mesh(
      {prim({{"POSITION", pos}, {"NORMAL", nrm}}, g.indices<std::uint16_t>({0, 1, 2, 0, 2, 3}))});
  g.node("\"mesh\":0", true);
  const wp::Scene s = wp::load_gltf(g.write("interleaved.gltf"));
  check_quad(s);
  EXPECT_EQ(s.positions.size(), 4u);  // smooth normals: shared vertices
  for (const vec3& n : s.normals) EXPECT_TRUE(near(n, {0, 0, 1}));
}

// Strip v0..v4 = (0,1) (0,0) (1,1) (1,0) (2,1): triangles {v_i, v_i+(1+i%2), v_i+(2-i%2)} =
// (0,1,2) (1,3,2) (2,3,4), all counter-clockwise seen from +Z. Fan around v0 = (0,0) with
// v1..v4 = (1,0) (1,1) (0,1) (-1,1): {v_i+1, v_i+2, v_0} = (1,2,0) (2,3,0) (3,4,0).
TEST(GltfLoader, StripAndFanConversion) {
  const std::vector<vec3> strip = {{0, 1, 0}, {0, 0, 0}, {1, 1, 0}, {1, 0, 0}, {2, 1, 0}};
  const std::vector<vec3> fan = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {-1, 1, 0}};
  const std::vector<int> strip_corners = {0, 1, 2, 1, 3, 2, 2, 3, 4};
  const std::vector<int> fan_corners = {1, 2, 0, 2, 3, 0, 3, 4, 0};
  for (const bool is_strip : {true, false}) {
    const std::vector<vec3>& v = is_strip ? strip : fan;
    const std::vector<int>& expected = is_strip ? strip_corners : fan_corners;
    Gltf g;
    g.mesh({prim({{"POSITION", g.vec3s(v)}}, -1, is_strip ? 5 : 6)});
    g.node("\"mesh\":0", true);
    const wp::Scene s = wp::load_gltf(g.write("stripfan.gltf"));
    check_invariants(s);
    ASSERT_EQ(s.triangle_count(), 3u);
    for (std::size_t i = 0; i < 9; ++i)
      EXPECT_TRUE(near(s.positions[s.indices[i]], v[static_cast<std::size_t>(expected[i])]))
          << (is_strip ? "strip" : "fan") << " corner " << i;
    for (std::size_t t = 0; t < 3; ++t) {
      EXPECT_TRUE(near(geometric_normal(s, t), {0, 0, 1}));
      EXPECT_TRUE(near(s.normals[s.indices[3 * t]], {0, 0, 1}));
    }
  }
}

// Triangles (0,1,2) in z = 0 (face normal +Z) and (0,2,3) in x = 0 with v3 = (0,0,1) (face
// normal +X), sharing an edge. Without NORMAL both are flat with unshared vertices; with a
// zero-length normal at v3 only the second triangle is.
TEST(GltfLoader, AbsentOrZeroNormalsAreFlat) {
  const std::vector<vec3> pos = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (const bool zero_normal : {false, true}) {
    Gltf g;
    std::map<std::string, int> a{{"POSITION", g.vec3s(pos)}};
    if (zero_normal) a["NORMAL"] = g.vec3s({{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 0}});
    g.mesh({prim(a, g.indices<std::uint8_t>({0, 1, 2, 0, 2, 3}))});
    g.node("\"mesh\":0", true);
    const wp::Scene s = wp::load_gltf(g.write("flat.gltf"));
    check_invariants(s);
    ASSERT_EQ(s.triangle_count(), 2u);
    EXPECT_EQ(s.positions.size(), 6u);
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE(near(s.normals[s.indices[static_cast<std::size_t>(c)]], {0, 0, 1}));
      EXPECT_TRUE(near(s.normals[s.indices[static_cast<std::size_t>(3 + c)]], {1, 0, 0}));
    }
    EXPECT_NE(s.indices[0], s.indices[3]);  // v0 not shared across the crease
  }
}

// KHR_mesh_quantization positions (i16 normalized: 32767 -> 1, -32768 -> -1) and normals (i8
// normalized: 127 -> 1); TEXCOORD_0 u16 normalized; COLOR_0 u8 normalized VEC4 and u16
// normalized VEC3 (alpha 1).
TEST(GltfLoader, NormalizedAndQuantizedAttributes) {
  Gltf g;
  g.top =
      "\"extensionsUsed\":[\"KHR_mesh_quantization\"],"
      "\"extensionsRequired\":[\"KHR_mesh_quantization\"]";
  const std::string norm = ",\"normalized\":true";
  const int pos =
      g.accessor(g.view(std::vector<std::int16_t>{-32768, 0, 0, 32767, 0, 0, 0, 32767, 0}), kI16, 3,
                 "VEC3", norm);
  const int nrm = g.accessor(g.view(std::vector<std::int8_t>{0, 0, 127, 0, 0, 127, 0, 0, 127}), kI8,
                             3, "VEC3", norm);
  const int uv = g.accessor(g.view(std::vector<std::uint16_t>{0, 0, 65535, 0, 0, 65535}), kU16, 3,
                            "VEC2", norm);
  const int rgba =
      g.accessor(g.view(std::vector<std::uint8_t>{255, 0, 0, 255, 0, 255, 0, 51, 0, 0, 255, 0}),
                 kU8, 3, "VEC4", norm);
  const int rgb = g.accessor(g.view(std::vector<std::uint16_t>{65535, 0, 0, 0, 32768, 0, 0, 0, 0}),
                             kU16, 3, "VEC3", norm);
  g.mesh({prim({{"POSITION", pos}, {"NORMAL", nrm}, {"TEXCOORD_0", uv}, {"COLOR_0", rgba}}),
          prim({{"POSITION", pos}, {"NORMAL", nrm}, {"COLOR_0", rgb}})});
  g.node("\"mesh\":0", true);
  const wp::Scene s = wp::load_gltf(g.write("quantized.gltf"));
  check_invariants(s);
  ASSERT_EQ(s.triangle_count(), 2u);
  EXPECT_TRUE(s.warnings.empty());
  const std::vector<vec3> p = {{-1, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<glm::vec2> t = {{0, 0}, {1, 0}, {0, 1}};
  const std::vector<glm::vec4> c = {{1, 0, 0, 1}, {0, 1, 0, 0.2f}, {0, 0, 1, 0}};
  const std::vector<glm::vec4> c3 = {{1, 0, 0, 1}, {0, 32768 / 65535.0f, 0, 1}, {0, 0, 0, 1}};
  for (std::size_t i = 0; i < 3; ++i) {
    const std::uint32_t v = s.indices[i], w = s.indices[3 + i];
    EXPECT_TRUE(near(s.positions[v], p[i]));
    EXPECT_TRUE(near(s.normals[v], {0, 0, 1}));
    EXPECT_LT(glm::length(s.uv0[v] - t[i]), 1e-6f);
    EXPECT_LT(glm::length(s.color0[v] - c[i]), 1e-6f);
    EXPECT_LT(glm::length(s.uv0[w]), 1e-6f);  // TEXCOORD_0 absent: (0, 0)
    EXPECT_LT(glm::length(s.color0[w] - c3[i]), 1e-6f);
  }
}

// Sparse accessors: over a bufferView (vertex 1 replaced by (5,5,5)) and over zeros (no
// bufferView; vertices 1 and 2 set).
TEST(GltfLoader, SparseAccessors) {
  Gltf g;
  const int base = g.view(std::vector<vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const int idx = g.view(std::vector<std::uint16_t>{1, 2});
  const int val = g.view(std::vector<vec3>{{5, 5, 5}, {0, 1, 0}});
  const std::string sparse1 =
      ",\"sparse\":{\"count\":1,\"indices\":{\"bufferView\":" + std::to_string(idx) +
      ",\"componentType\":5123},\"values\":{" + "\"bufferView\":" + std::to_string(val) + "}}";
  const std::string sparse2 =
      ",\"sparse\":{\"count\":2,\"indices\":{\"bufferView\":" + std::to_string(idx) +
      ",\"componentType\":5123},\"values\":{" +
      "\"bufferView\":" + std::to_string(g.view(std::vector<vec3>{{1, 0, 0}, {0, 1, 0}})) + "}}";
  const int a1 = g.accessor(base, kF32, 3, "VEC3", sparse1);
  const int a2 = g.accessor(-1, kF32, 3, "VEC3", sparse2);
  g.mesh({prim({{"POSITION", a1}}), prim({{"POSITION", a2}})});
  g.node("\"mesh\":0", true);
  const wp::Scene s = wp::load_gltf(g.write("sparse.gltf"));
  check_invariants(s);
  ASSERT_EQ(s.triangle_count(), 2u);
  EXPECT_TRUE(near(corner(s, 0, 1), {5, 5, 5}));
  EXPECT_TRUE(near(corner(s, 0, 2), {0, 1, 0}));
  EXPECT_TRUE(near(corner(s, 1, 0), {0, 0, 0}));
  EXPECT_TRUE(near(corner(s, 1, 1), {1, 0, 0}));
  EXPECT_TRUE(near(corner(s, 1, 2), {0, 1, 0}));
}

// Points and lines are skipped with one warning per primitive, however often it is instanced.
TEST(GltfLoader, NonTrianglePrimitivesWarnOnce) {
  Gltf g = one_triangle("");
  g.mesh({prim({{"POSITION", 0}}, -1, 1), prim({{"POSITION", 0}}, -1, 0)});
  g.node("\"mesh\":1", true);
  g.node("\"mesh\":1", true);
  const wp::Scene s = wp::load_gltf(g.write("lines.gltf"));
  EXPECT_EQ(s.triangle_count(), 1u);
  ASSERT_EQ(s.warnings.size(), 2u);
  EXPECT_NE(s.warnings[0].find("LINES"), std::string::npos) << s.warnings[0];
  EXPECT_NE(s.warnings[1].find("POINTS"), std::string::npos) << s.warnings[1];
}

// ---------------------------------------------------------------------------------------------
// Materials, lights, cameras, scenes

// m0 has every supported field; m1 is empty (glTF defaults). Primitives: m0, none, m1, and a
// second mesh with none: the default material is appended once, after the file's materials.
TEST(GltfLoader, MaterialFactorsAndDefaultMaterial) {
  Gltf g = one_triangle("");
  g.materials = {
      R"({"name":"m0","pbrMetallicRoughness":{"baseColorFactor":[0.5,0.25,0.125,0.75],
          "metallicFactor":0.2,"roughnessFactor":0.7},"emissiveFactor":[1,0.5,0.25],
          "doubleSided":true,"alphaMode":"MASK","alphaCutoff":0.3,
          "extensions":{"KHR_materials_emissive_strength":{"emissiveStrength":4},
          "KHR_materials_ior":{"ior":1.33},"KHR_materials_transmission":{"transmissionFactor":0.9}}})",
      R"({"name":"m1","alphaMode":"BLEND"})"};
  g.meshes = {"{\"primitives\":[" +
                  join({prim({{"POSITION", 0}}, -1, -1, 0), prim({{"POSITION", 0}}),
                        prim({{"POSITION", 0}}, -1, -1, 1)}) +
                  "]}",
              "{\"primitives\":[" + prim({{"POSITION", 0}}) + "]}"};
  g.node("\"mesh\":1", true);
  const wp::Scene s = wp::load_gltf(g.write("materials.gltf"));
  check_invariants(s);
  ASSERT_EQ(s.materials.size(), 3u);
  EXPECT_EQ(s.triangle_material, (std::vector<std::uint32_t>{0, 2, 1, 2}));
  const wp::Material& m0 = s.materials[0];
  EXPECT_EQ(m0.name, "m0");
  EXPECT_EQ(m0.base_color, glm::vec4(0.5f, 0.25f, 0.125f, 0.75f));
  EXPECT_FLOAT_EQ(m0.metallic, 0.2f);
  EXPECT_FLOAT_EQ(m0.roughness, 0.7f);
  EXPECT_EQ(m0.emission, vec3(4, 2, 1));
  EXPECT_TRUE(m0.double_sided);
  EXPECT_EQ(m0.alpha_mode, wp::AlphaMode::kMask);
  EXPECT_FLOAT_EQ(m0.alpha_cutoff, 0.3f);
  EXPECT_FLOAT_EQ(m0.ior, 1.33f);
  EXPECT_FLOAT_EQ(m0.transmission, 0.9f);
  const wp::Material& m1 = s.materials[1];
  EXPECT_EQ(m1.alpha_mode, wp::AlphaMode::kBlend);
  for (const wp::Material* m : {&m1, &s.materials[2]}) {
    EXPECT_EQ(m->base_color, glm::vec4(1.0f));
    EXPECT_EQ(m->metallic, 1.0f);
    EXPECT_EQ(m->roughness, 1.0f);
    EXPECT_EQ(m->emission, vec3(0.0f));
    EXPECT_FALSE(m->double_sided);
    EXPECT_EQ(m->ior, 1.5f);
    EXPECT_EQ(m->transmission, 0.0f);
  }
  EXPECT_EQ(s.materials[2].alpha_mode, wp::AlphaMode::kOpaque);

  // Every primitive has a material: no default is added.
  Gltf h = one_triangle("");
  h.materials = {"{}"};
  h.meshes = {"{\"primitives\":[" + prim({{"POSITION", 0}}, -1, -1, 0) + "]}"};
  EXPECT_EQ(wp::load_gltf(h.write("one_material.gltf")).materials.size(), 1u);
}

// Parent P = T(0,0,5) R_x(90 deg); R_x(90) maps (x,y,z) to (x,-z,y). Point child at (1,2,0):
// (0,0,5) + (1,0,2) = (1,0,7). Spot child untransformed: at (0,0,5), direction R(0,0,-1) =
// (0,1,0). Directional root rotated R_y(90) ((x,y,z) -> (z,y,-x)): direction (-1,0,0).
TEST(GltfLoader, PunctualLights) {
  Gltf g = one_triangle("");
  g.top = R"("extensionsUsed":["KHR_lights_punctual"])";
  g.lights = {R"({"type":"point","color":[1,0.5,0.25],"intensity":8,"range":10,"name":"p"})",
              R"({"type":"spot","spot":{}})", R"({"type":"directional","intensity":3})",
              R"({"type":"spot","spot":{"innerConeAngle":0.1,"outerConeAngle":0.5}})"};
  const auto light = [](int i) {
    return "\"extensions\":{\"KHR_lights_punctual\":{\"light\":" + std::to_string(i) + "}}";
  };
  // Node 0 is the triangle; 1 is P with children 2 (point) and 3 (spot); 4 and 5 are roots.
  g.node("\"translation\":[0,0,5],\"rotation\":[0.70710678,0,0,0.70710678],\"children\":[2,3]",
         true);
  g.node("\"translation\":[1,2,0]," + light(0));
  g.node(light(1));
  g.node("\"rotation\":[0,0.70710678,0,0.70710678]," + light(2), true);
  g.node(light(3), true);
  const wp::Scene s = wp::load_gltf(g.write("lights.gltf"));
  ASSERT_EQ(s.lights.size(), 4u);
  const wp::PunctualLight &point = s.lights[0], &spot = s.lights[1];
  EXPECT_EQ(point.type, wp::LightType::kPoint);
  EXPECT_EQ(point.name, "p");
  EXPECT_TRUE(near(point.position, {1, 0, 7}));
  EXPECT_EQ(point.intensity, vec3(8, 4, 2));
  EXPECT_EQ(point.range, 10.0f);
  EXPECT_EQ(spot.type, wp::LightType::kSpot);
  EXPECT_TRUE(near(spot.position, {0, 0, 5}));
  EXPECT_TRUE(near(spot.direction, {0, 1, 0}));
  EXPECT_EQ(spot.intensity, vec3(1.0f));
  EXPECT_EQ(spot.range, 0.0f);
  EXPECT_EQ(spot.inner_cone, 0.0f);
  EXPECT_NEAR(spot.outer_cone, kPi / 4, 1e-6f);
  EXPECT_EQ(s.lights[2].type, wp::LightType::kDirectional);
  EXPECT_TRUE(near(s.lights[2].direction, {-1, 0, 0}));
  EXPECT_EQ(s.lights[2].intensity, vec3(3.0f));
  EXPECT_FLOAT_EQ(s.lights[3].inner_cone, 0.1f);
  EXPECT_FLOAT_EQ(s.lights[3].outer_cone, 0.5f);
}

// Roots A (T(0,1,0) S(2), child A1) and B. A1 = T(1,0,0) R_y(90) holds the orthographic camera:
// position (0,1,0) + 2 (1,0,0) = (2,1,0), forward R_y(-Z) = (-1,0,0), up +Y (scale ignored).
// B = T(0,0,5) R_x(90) holds the perspective one: forward (0,1,0), up R_x(+Y) = (0,0,1).
// Depth-first node order puts A1's camera first.
TEST(GltfLoader, CamerasInNodeOrder) {
  Gltf g = one_triangle("");
  g.cameras = {
      R"({"type":"perspective","perspective":{"yfov":0.7,"znear":0.1,"aspectRatio":1.5}})",
      R"({"type":"orthographic","orthographic":{"xmag":2,"ymag":1.5,"znear":0.01,"zfar":100}})"};
  g.node("\"translation\":[0,1,0],\"scale\":[2,2,2],\"children\":[3]", true);
  g.node("\"camera\":0,\"translation\":[0,0,5],\"rotation\":[0.70710678,0,0,0.70710678]", true);
  g.node("\"camera\":1,\"translation\":[1,0,0],\"rotation\":[0,0.70710678,0,0.70710678]");
  const wp::Scene s = wp::load_gltf(g.write("cameras.gltf"));
  ASSERT_EQ(s.cameras.size(), 2u);
  const wp::Camera &ortho = s.cameras[0], &persp = s.cameras[1];
  EXPECT_EQ(ortho.type, wp::CameraType::kOrthographic);
  EXPECT_TRUE(near(ortho.position, {2, 1, 0}));
  EXPECT_TRUE(near(ortho.forward, {-1, 0, 0}));
  EXPECT_TRUE(near(ortho.up, {0, 1, 0}));
  EXPECT_EQ(ortho.xmag, 2.0f);
  EXPECT_EQ(ortho.ymag, 1.5f);
  EXPECT_EQ(ortho.znear, 0.01f);
  EXPECT_EQ(persp.type, wp::CameraType::kPerspective);
  EXPECT_TRUE(near(persp.position, {0, 0, 5}));
  EXPECT_TRUE(near(persp.forward, {0, 1, 0}));
  EXPECT_TRUE(near(persp.up, {0, 0, 1}));
  EXPECT_EQ(persp.yfov, 0.7f);
  EXPECT_EQ(persp.znear, 0.1f);
}

// "scene": 1 picks the second scene; without "scene", scene 0 is used.
TEST(GltfLoader, DefaultScene) {
  Gltf g = one_triangle("");
  g.node("\"mesh\":0,\"translation\":[10,0,0]");
  g.scenes = R"("scene":1,"scenes":[{"nodes":[0]},{"nodes":[1]}])";
  EXPECT_TRUE(near(wp::load_gltf(g.write("scene1.gltf")).bounds_lo, {10, 0, 0}));
  g.scenes = R"("scenes":[{"nodes":[0]},{"nodes":[1]}])";
  EXPECT_TRUE(near(wp::load_gltf(g.write("scene0.gltf")).bounds_lo, {0, 0, 0}));
}

// Only unsupported extensions warn; an image no material uses is never decoded (this one could
// not be).
TEST(GltfLoader, ExtensionWarnings) {
  Gltf g = one_triangle("");
  g.top =
      R"("extensionsUsed":["KHR_materials_sheen","KHR_materials_volume","KHR_texture_transform",)"
      R"("KHR_materials_unlit"],"textures":[{"source":0}],)"
      R"("images":[{"uri":"data:image/png;base64,AAAA"}])";
  const wp::Scene s = wp::load_gltf(g.write("warn.gltf"));
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("KHR_materials_sheen"), std::string::npos) << s.warnings[0];
  EXPECT_TRUE(s.images.empty());
}

TEST(GltfLoader, FramingCamera) {
  wp::Scene s;
  s.bounds_lo = vec3(-1, 0, -3);
  s.bounds_hi = vec3(3, 2, 1);
  for (const float aspect : {1.0f, 0.5f, 2.0f}) {
    const wp::Camera c = wp::framing_camera(s, aspect);
    EXPECT_EQ(c.type, wp::CameraType::kPerspective);
    EXPECT_NEAR(c.yfov, kPi / 4, 1e-6f);
    EXPECT_LT(c.forward.z, -0.9f);  // along -Z ...
    EXPECT_LT(c.forward.y, 0.0f);   // ... slightly from above
    EXPECT_NEAR(glm::dot(c.forward, c.up), 0.0f, 1e-6f);
    const vec3 center(1, 1, -1);
    EXPECT_TRUE(near(glm::normalize(center - c.position), c.forward));
    // The bounding sphere (radius 3) touches the tighter side of the view.
    const float half = std::min(kPi / 8, std::atan(std::tan(kPi / 8) * aspect));
    EXPECT_NEAR(glm::length(center - c.position) * std::sin(half), 3.0f, 1e-4f);
  }
  s.bounds_lo = s.bounds_hi = vec3(4, 5, 6);  // a point
  const wp::Camera c = wp::framing_camera(s, 1.0f);
  EXPECT_TRUE(std::isfinite(c.position.x + c.position.y + c.position.z));
  EXPECT_GT(glm::length(c.position - vec3(4, 5, 6)), 0.0f);
  EXPECT_NEAR(glm::length(c.forward), 1.0f, 1e-6f);
}

// ---------------------------------------------------------------------------------------------
// Textures, TEXCOORD_1, tangents, unlit and volume

std::vector<unsigned char> encode_png(int w, int h, const std::vector<unsigned char>& rgba) {
  std::vector<unsigned char> png;
  stbi_write_png_to_func(
      [](void* out, void* data, int size) {
        auto* v = static_cast<std::vector<unsigned char>*>(out);
        v->insert(v->end(), static_cast<unsigned char*>(data),
                  static_cast<unsigned char*>(data) + size);
      },
      &png, w, h, 4, rgba.data(), 4 * w);
  return png;
}

std::string png_data_uri(int w, int h, const std::vector<unsigned char>& rgba) {
  return "data:image/png;base64," + base64(encode_png(w, h, rgba));
}

// Image 0: 2x2 RGBA (red, green / blue, half-transparent white); image 1: 1x1 grey.
const std::vector<unsigned char> kImage0 = {255, 0, 0,   255, 0,   255, 0,   255,
                                            0,   0, 255, 255, 255, 255, 255, 128};
std::string test_images() {
  return R"("images":[{"uri":")" + png_data_uri(2, 2, kImage0) + R"("},{"name":"grey","uri":")" +
         png_data_uri(1, 1, {90, 90, 90, 255}) + R"("}])";
}

// A unit square at z = 0 facing +z: TEXCOORD_0 = (x, 1 - y) (u mirrored: (1 - x, 1 - y)),
// TEXCOORD_1 = (2x, y), indices (0,1,2), (0,2,3); one primitive per material in `materials`.
Gltf textured_square(const std::vector<int>& materials, bool mirror_u = false) {
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

bool rows_near(const wp::TextureRef& t, vec3 u, vec3 v) {
  return glm::length(t.row_u - u) < 1e-6f && glm::length(t.row_v - v) < 1e-6f;
}

// Material 0 uses every texture slot; material 1 (unlit) shares material 0's emissive use of
// texture 0, which becomes one Scene::textures entry. Texture 0: sampler 0 (CLAMP_TO_EDGE /
// MIRRORED_REPEAT, NEAREST); 1: image 1, no sampler (REPEAT, bilinear); 2: image 0, sampler 1
// (defaults). The base colour's KHR_texture_transform is the extension's own example (offset
// [0, 1], rotation pi/2, scale 0.5: "the lower left quadrant, rotated") with a texCoord override.
TEST(GltfLoader, TexturesSamplersAndTransforms) {
  Gltf g = textured_square({0, 1});
  g.top = test_images() +
          R"(,"samplers":[{"wrapS":33071,"wrapT":33648,"magFilter":9728},{}],)"
          R"("textures":[{"source":0,"sampler":0},{"source":1},{"source":0,"sampler":1}])";
  g.materials = {
      R"({"pbrMetallicRoughness":{"baseColorTexture":{"index":0,"texCoord":0,"extensions":{)"
      R"("KHR_texture_transform":{"offset":[0,1],"rotation":1.5707963268,"scale":[0.5,0.5],)"
      R"("texCoord":1}}},"metallicRoughnessTexture":{"index":1,"texCoord":1}},)"
      R"("normalTexture":{"index":2,"scale":0.7},"emissiveTexture":{"index":0},)"
      R"("extensions":{"KHR_materials_transmission":{"transmissionFactor":0.5,)"
      R"("transmissionTexture":{"index":1}},"KHR_materials_volume":{"thicknessFactor":0.25,)"
      R"("attenuationDistance":2,"attenuationColor":[0.5,0.6,0.7]}}})",
      R"({"pbrMetallicRoughness":{"baseColorTexture":{"index":0}},)"
      R"("extensions":{"KHR_materials_unlit":{}}})"};
  const wp::Scene s = wp::load_gltf(g.write("textures.gltf"));
  check_invariants(s);
  ASSERT_EQ(s.images.size(), 2u);
  EXPECT_EQ(s.images[0].width, 2);
  EXPECT_EQ(s.images[0].height, 2);
  EXPECT_EQ(s.images[0].rgba, kImage0);
  EXPECT_EQ(s.images[1].rgba, (std::vector<std::uint8_t>{90, 90, 90, 255}));
  EXPECT_EQ(s.images[1].name, "grey");

  const wp::Material &m0 = s.materials[0], &m1 = s.materials[1];
  ASSERT_EQ(s.textures.size(), 5u);  // base, metal-rough, normal, emissive, transmission
  const wp::TextureRef& base = s.textures[std::size_t(m0.base_color_texture)];
  EXPECT_EQ(base.image, 0);
  EXPECT_EQ(base.wrap_s, wp::Wrap::kClampToEdge);
  EXPECT_EQ(base.wrap_t, wp::Wrap::kMirroredRepeat);
  EXPECT_TRUE(base.nearest && base.srgb);
  EXPECT_EQ(base.texcoord, 1);
  EXPECT_TRUE(rows_near(base, {0, 0.5f, 0}, {-0.5f, 0, 1}));  // (u, v) -> (v/2, 1 - u/2)
  const wp::TextureRef& mr = s.textures[std::size_t(m0.metallic_roughness_texture)];
  EXPECT_EQ(mr.image, 1);
  EXPECT_EQ(mr.wrap_s, wp::Wrap::kRepeat);
  EXPECT_FALSE(mr.nearest || mr.srgb);
  EXPECT_EQ(mr.texcoord, 1);
  EXPECT_TRUE(rows_near(mr, {1, 0, 0}, {0, 1, 0}));
  const wp::TextureRef& normal = s.textures[std::size_t(m0.normal_texture)];
  EXPECT_EQ(normal.image, 0);
  EXPECT_FALSE(normal.srgb || normal.nearest);
  EXPECT_FLOAT_EQ(m0.normal_scale, 0.7f);
  const wp::TextureRef& emissive = s.textures[std::size_t(m0.emissive_texture)];
  EXPECT_TRUE(emissive.srgb && emissive.nearest);
  EXPECT_EQ(emissive.texcoord, 0);
  EXPECT_EQ(m1.base_color_texture, m0.emissive_texture);  // the same use, shared
  const wp::TextureRef& trans = s.textures[std::size_t(m0.transmission_texture)];
  EXPECT_EQ(trans.image, 1);
  EXPECT_FALSE(trans.srgb);
  EXPECT_EQ(trans.texcoord, 0);
  EXPECT_FLOAT_EQ(m0.transmission, 0.5f);
  EXPECT_FLOAT_EQ(m0.thickness, 0.25f);
  EXPECT_FLOAT_EQ(m0.attenuation_distance, 2.0f);
  EXPECT_TRUE(near(m0.attenuation_color, {0.5f, 0.6f, 0.7f}));
  EXPECT_FALSE(m0.unlit);
  EXPECT_TRUE(m1.unlit);
  EXPECT_EQ(m1.thickness, 0.0f);
  EXPECT_EQ(m1.attenuation_distance, 0.0f);  // absent: infinite
  EXPECT_EQ(m1.normal_texture, -1);

  // A texture reads TEXCOORD_1, so every vertex has it.
  ASSERT_EQ(s.uv1.size(), s.positions.size());
  for (std::size_t i = 0; i < s.positions.size(); ++i)
    EXPECT_EQ(s.uv1[i], glm::vec2(2 * s.positions[i].x, s.positions[i].y));
  ASSERT_EQ(s.tangents.size(), s.positions.size());  // material 0 has a normal texture
}

// Without textures on set 1 and without normal textures, uv1 and tangents stay empty.
TEST(GltfLoader, Uv1AndTangentsOnlyWhenUsed) {
  Gltf g = textured_square({0});
  g.top = test_images() + R"(,"textures":[{"source":1}])";
  g.materials = {R"({"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}})"};
  const wp::Scene s = wp::load_gltf(g.write("plain_texture.gltf"));
  EXPECT_TRUE(s.uv1.empty());
  EXPECT_TRUE(s.tangents.empty());
  EXPECT_EQ(s.textures.size(), 1u);
}

// What every tangent guarantees: unit, orthogonal to its vertex normal (within `ortho`: supplied
// ones are only as orthogonal as the file's data), w = +-1.
void check_tangents(const wp::Scene& s, float ortho = 1e-5f) {
  ASSERT_EQ(s.tangents.size(), s.positions.size());
  for (std::size_t i = 0; i < s.tangents.size(); ++i) {
    const glm::vec4& t = s.tangents[i];
    ASSERT_NEAR(glm::length(vec3(t)), 1.0f, 1e-5f) << "vertex " << i;
    ASSERT_NEAR(glm::dot(vec3(t), s.normals[i]), 0.0f, ortho) << "vertex " << i;
    ASSERT_TRUE(t.w == 1.0f || t.w == -1.0f) << "vertex " << i;
  }
}

const std::string kNormalMapped = R"({"normalTexture":{"index":0}})";

// Supplied TANGENT (1,0,0,1) under R_z(90) S(-1, 2, 1): xyz = R S (1,0,0) = R (-1,0,0) = (0,-1,0);
// the mirror flips w to -1. Unmirrored (second node, R_z(90) only): (0,1,0), w = +1.
TEST(GltfLoader, SuppliedTangentsAreTransformed) {
  Gltf g;
  const int pos = g.vec3s({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const int nrm = g.vec3s({{0, 0, 1}, {0, 0, 1}, {0, 0, 1}});
  const int tan =
      g.accessor(g.view(std::vector<glm::vec4>(3, glm::vec4(1, 0, 0, 1))), kF32, 3, "VEC4");
  g.mesh({prim({{"POSITION", pos}, {"NORMAL", nrm}, {"TANGENT", tan}}, -1, -1, 0)});
  g.top = test_images() + R"(,"textures":[{"source":0}])";
  g.materials = {kNormalMapped};
  const std::string rz = R"("rotation":[0,0,0.70710678,0.70710678])";
  g.node("\"mesh\":0," + rz + ",\"scale\":[-1,2,1]", true);
  g.node("\"mesh\":0," + rz, true);
  const wp::Scene s = wp::load_gltf(g.write("tangents.gltf"));
  check_invariants(s);
  check_tangents(s);
  ASSERT_EQ(s.triangle_count(), 2u);
  for (int c = 0; c < 3; ++c) {
    const glm::vec4 mirrored = s.tangents[s.indices[std::size_t(c)]];
    const glm::vec4 plain = s.tangents[s.indices[std::size_t(3 + c)]];
    EXPECT_TRUE(near(vec3(mirrored), {0, -1, 0}));
    EXPECT_EQ(mirrored.w, -1.0f);
    EXPECT_TRUE(near(vec3(plain), {0, 1, 0}));
    EXPECT_EQ(plain.w, 1.0f);
  }
}

// Generated tangents on the square: dP/du = +x with the image upright (v runs down: its up is
// +y = cross(n, t), so w = +1); with u mirrored, dP/du = -x and cross(n, t) = -y points down the
// image, so w = -1 makes the bitangent point up again.
TEST(GltfLoader, GeneratedTangentsFollowUvs) {
  for (const bool mirror : {false, true}) {
    Gltf g = textured_square({0}, mirror);
    g.top = test_images() + R"(,"textures":[{"source":0}])";
    g.materials = {kNormalMapped};
    const wp::Scene s = wp::load_gltf(g.write("generated.gltf"));
    check_invariants(s);
    check_tangents(s);
    EXPECT_EQ(s.positions.size(), 4u);
    for (const glm::vec4& t : s.tangents)
      EXPECT_EQ(t, mirror ? glm::vec4(-1, 0, 0, -1) : glm::vec4(1, 0, 0, 1));
  }
}

// A mirrored UV seam: squares x in [0,1] (u = x) and [1,2] (u = 2 - x) share the vertices on
// x = 1 (same uv on both sides). Those are split, so each triangle's corners share its
// handedness: +x, w = +1 on the left; -x, w = -1 on the right. A curved strip (a quarter
// cylinder, normals radial) gets unit tangents orthogonal to its normals along the arc.
TEST(GltfLoader, GeneratedTangentsSplitMirrorSeams) {
  wp::Scene s;
  const std::vector<vec3> p = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0}, {2, 1, 0}};
  for (const vec3& x : p) {
    s.positions.push_back(x);
    s.normals.emplace_back(0, 0, 1);
    s.uv0.emplace_back(x.x <= 1 ? x.x : 2 - x.x, 1 - x.y);
    s.color0.emplace_back(1.0f);
    s.tangents.emplace_back(0.0f);
  }
  s.indices = {0, 1, 2, 0, 2, 3, 1, 4, 5, 1, 5, 2};
  s.triangle_material = {0, 0, 0, 0};
  wp::gltf::generate_tangents(s, 0, 0);
  check_tangents(s);
  EXPECT_EQ(s.positions.size(), 8u);  // vertices 1 and 2 split
  for (std::size_t t = 0; t < 4; ++t)
    for (std::size_t c = 0; c < 3; ++c)
      EXPECT_EQ(s.tangents[s.indices[3 * t + c]],
                t < 2 ? glm::vec4(1, 0, 0, 1) : glm::vec4(-1, 0, 0, -1));

  wp::Scene arc;
  for (int i = 0; i <= 8; ++i) {
    const float a = kPi / 2 * static_cast<float>(i) / 8;
    for (const float y : {0.0f, 1.0f}) {
      arc.positions.emplace_back(std::cos(a), y, std::sin(a));
      arc.normals.emplace_back(std::cos(a), 0, std::sin(a));
      arc.uv0.emplace_back(static_cast<float>(i) / 8, 1 - y);
      arc.color0.emplace_back(1.0f);
      arc.tangents.emplace_back(0.0f);
    }
    if (i == 0) continue;
    const auto k = static_cast<std::uint32_t>(2 * i);
    arc.indices.insert(arc.indices.end(), {k - 2, k + 1, k, k - 2, k - 1, k + 1});
    arc.triangle_material.insert(arc.triangle_material.end(), {0, 0});
  }
  wp::gltf::generate_tangents(arc, 0, 0);
  check_tangents(arc);
  for (std::size_t i = 0; i < arc.positions.size(); ++i) {  // along the arc (+u), w consistent
    EXPECT_GT(glm::dot(vec3(arc.tangents[i]), glm::cross(arc.normals[i], vec3(0, 1, 0))), 0.99f);
    EXPECT_EQ(arc.tangents[i].w, arc.tangents[0].w);
  }
}

TEST(GltfLoader, TextureErrorsNameTheElement) {
  const auto with = [](const std::string& textures, const std::string& material,
                       const std::string& images = test_images()) {
    Gltf g = textured_square({0});
    g.top = images + R"(,"samplers":[{"wrapS":1234}],"textures":)" + textures;
    g.materials = {material};
    return g;
  };
  const std::string base0 = R"({"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}})";
  expect_error(with("[{\"source\":0}]", R"({"emissiveTexture":{"index":5}})").write("t1.gltf"),
               "emissiveTexture: texture 5 does not exist");
  expect_error(with("[{\"source\":3}]", base0).write("t2.gltf"), "image 3 does not exist");
  expect_error(with("[{\"source\":0,\"sampler\":2}]", base0).write("t3.gltf"),
               "sampler 2 does not exist");
  expect_error(with("[{\"source\":0,\"sampler\":0}]", base0).write("t4.gltf"),
               "sampler 0: unknown wrapS 1234");
  expect_error(with("[{\"source\":0}]", base0,
                    R"("images":[{"name":"junk","uri":"data:image/png;base64,AAAAAAAA"}])")
                   .write("t5.gltf"),
               "image 0 'junk': cannot decode");
  expect_error(
      with("[{\"source\":0}]", base0, R"("images":[{"uri":"nowhere.png"}])").write("t6.gltf"),
      "image 0 (nowhere.png): no image data");
  // PNGs whose chunks claim more than there is, refused before stb_image allocates for them
  // (fuzzing: an IDAT claiming 1.9 GB in a 42 KB file took 2 GiB). stb_image_write writes the
  // signature (8 bytes), IHDR (25; width at 16, height at 20), then IDAT (its length at 33).
  const auto patched_png = [](std::size_t at, std::uint32_t value) {
    std::vector<unsigned char> png = encode_png(2, 2, kImage0);
    for (int i = 0; i < 4; ++i) png[at + i] = static_cast<unsigned char>(value >> (24 - 8 * i));
    return R"("images":[{"uri":"data:image/png;base64,)" + base64(png) + R"("}])";
  };
  expect_error(with("[{\"source\":0}]", base0, patched_png(33, 0x6f71d329u)).write("t8.gltf"),
               "image 0: PNG chunk at byte 33 claims 1869730601 bytes, more than the file has");
  expect_error(with("[{\"source\":0}]", base0, patched_png(16, 60000)).write("t9.gltf"),
               "bytes cannot hold its");
  expect_error(with("[{\"source\":0}]", R"({"normalTexture":{"index":0,"extensions":{)"
                                        R"("KHR_texture_transform":{"offset":[1]}}}})")
                   .write("t7.gltf"),
               "KHR_texture_transform.offset needs 2 numbers");
  expect_error(with("[{\"source\":0}]",
                    R"({"extensions":{"KHR_materials_volume":{"attenuationDistance":0}}})")
                   .write("t8.gltf"),
               "attenuationDistance must be positive");
  Gltf view = with("[{\"source\":0}]", base0, R"("images":[{"bufferView":7}])");
  view.views.resize(7, view.views[0]);
  view.views.push_back(R"({"buffer":0,"byteOffset":4,"byteLength":100000})");
  expect_error(view.write("t9.gltf"), "image 0: bufferView 7 exceeds buffer 0");
  // TEXCOORD_2 is not kept: that texture is left out, with a warning.
  const wp::Scene s = wp::load_gltf(
      with("[{\"source\":0}]",
           R"({"pbrMetallicRoughness":{"baseColorTexture":{"index":0,"texCoord":2}}})")
          .write("t10.gltf"));
  EXPECT_EQ(s.materials[0].base_color_texture, -1);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("TEXCOORD_2"), std::string::npos) << s.warnings[0];
}

// ---------------------------------------------------------------------------------------------
// Malformed input: wp::Error naming the file and the cause, never a crash.

TEST(GltfLoader, ErrorsNameFileAndCause) {
  Gltf g = one_triangle("");
  g.top = R"("extensionsUsed":["KHR_draco_mesh_compression"],)"
          R"("extensionsRequired":["KHR_draco_mesh_compression"])";
  expect_error(g.write("draco.gltf"), "requires unsupported extension KHR_draco_mesh_compression");

  const std::string missing = (temp_dir() / "missing.gltf").string();
  expect_error(missing, "no such file");
  const std::string bad_json = (temp_dir() / "bad.gltf").string();
  write_bytes(bad_json, R"({"asset":{"version":"2.0"},"nodes":[{"mesh":0})");
  expect_error(bad_json, "parse error");
  const std::string empty = (temp_dir() / "empty.gltf").string();
  write_bytes(empty, "");
  expect_error(empty, "empty file");
  expect_error(temp_dir().string(), "is a directory");
  const std::string not_glb = (temp_dir() / "text.glb").string();
  write_bytes(not_glb, "{}");
  expect_error(not_glb, "magic");

  Gltf none = one_triangle("");
  none.scenes = "";
  expect_error(none.write("noscene.gltf"), "no scenes");
}

TEST(GltfLoader, OutOfRangeDataIsAnError) {
  {  // accessor count beyond its bufferView
    Gltf g = one_triangle("");
    g.accessors[0] = R"({"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"})";
    expect_error(g.write("count.gltf"), "accessor 0 (POSITION)");
  }
  {  // index value beyond the vertices
    Gltf g = one_triangle("");
    g.meshes = {"{\"primitives\":[" + prim({{"POSITION", 0}}, g.indices<std::uint16_t>({0, 1, 7})) +
                "]}"};
    expect_error(g.write("index.gltf"), "index 7");
  }
  {  // bufferView beyond its buffer
    Gltf g = one_triangle("");
    g.views[0] = R"({"buffer":0,"byteOffset":4,"byteLength":36})";
    expect_error(g.write("view.gltf"), "exceeds buffer 0");
  }
  {  // missing accessor, matrix-typed accessor, attribute count mismatch
    Gltf g = one_triangle("");
    g.meshes = {"{\"primitives\":[" + prim({{"POSITION", 9}}) + "]}"};
    expect_error(g.write("noaccessor.gltf"), "accessor 9 (POSITION) does not exist");
    g.meshes = {"{\"primitives\":[" + prim({{"POSITION", g.accessor(0, kF32, 1, "MAT3")}}) + "]}"};
    expect_error(g.write("mat3.gltf"), "unsupported accessor type");
    g.meshes = {"{\"primitives\":[" + prim({{"POSITION", 0}, {"NORMAL", g.vec3s({{0, 0, 1}})}}) +
                "]}"};
    expect_error(g.write("mismatch.gltf"), "differs from POSITION");
  }
  {  // node graph: a cycle, a missing child, a missing mesh, a malformed transform
    Gltf g = one_triangle("\"children\":[1]");
    g.node("\"children\":[0]");
    expect_error(g.write("cycle.gltf"), "cycle");
    g.nodes[1] = "{\"children\":[5]}";
    expect_error(g.write("child.gltf"), "missing node 5");
    g.nodes = {"{\"mesh\":3}"};
    expect_error(g.write("nomesh.gltf"), "mesh 3 does not exist");
    g.nodes = {"{\"mesh\":0,\"rotation\":[0,0,1]}"};
    expect_error(g.write("rotation.gltf"), "rotation needs 4 numbers");
  }
  {  // a material and a light that do not exist
    Gltf g = one_triangle("");
    g.meshes = {"{\"primitives\":[" + prim({{"POSITION", 0}}, -1, -1, 2) + "]}"};
    expect_error(g.write("nomaterial.gltf"), "material 2 does not exist");
    Gltf h = one_triangle(R"("extensions":{"KHR_lights_punctual":{"light":0}})");
    expect_error(h.write("nolight.gltf"), "light 0 does not exist");
  }
}

// Values outside glTF's ranges are errors, as for the Khronos validator: a negative base colour
// or emission gave negative radiance, which the fixed-point film silently saturated to 0; a
// metallic factor of 1.5 was clamped without a word.
TEST(GltfLoader, OutOfRangeFactorsAreErrors) {
  for (const auto& [material, cause] : std::vector<std::pair<std::string, std::string>>{
           {R"({"pbrMetallicRoughness":{"baseColorFactor":[0.5,-0.1,0.5,1]}})",
            "baseColorFactor -0.1 is outside [0, 1]"},
           {R"({"pbrMetallicRoughness":{"baseColorFactor":[0.5,0.5,0.5,1.2]}})",
            "baseColorFactor 1.2 is outside [0, 1]"},
           {R"({"pbrMetallicRoughness":{"metallicFactor":1.5}})",
            "metallicFactor 1.5 is outside [0, 1]"},
           {R"({"pbrMetallicRoughness":{"roughnessFactor":-1}})",
            "roughnessFactor -1 is outside [0, 1]"},
           {R"({"emissiveFactor":[2,0,0]})", "emissiveFactor 2 is outside [0, 1]"},
           {R"({"extensions":{"KHR_materials_transmission":{"transmissionFactor":1.01}}})",
            "transmissionFactor 1.01 is outside [0, 1]"},
           {R"({"extensions":{"KHR_materials_specular":{"specularFactor":-0.5}}})",
            "specularFactor -0.5 is outside [0, 1]"},
       }) {
    Gltf g = one_triangle("");
    g.materials = {material};
    g.meshes = {"{\"primitives\":[" + prim({{"POSITION", 0}}, -1, -1, 0) + "]}"};
    expect_error(g.write("range.gltf"), "material 0 '': " + cause);
  }
  // The bounds themselves are valid.
  Gltf edge = one_triangle("");
  edge.materials = {R"({"pbrMetallicRoughness":{"baseColorFactor":[0,1,0,1],"metallicFactor":1,)"
                    R"("roughnessFactor":0},"emissiveFactor":[1,0,1]})"};
  edge.meshes = {"{\"primitives\":[" + prim({{"POSITION", 0}}, -1, -1, 0) + "]}"};
  EXPECT_NO_THROW(wp::load_gltf(edge.write("edge.gltf")));

  for (const auto& [light, cause] : std::vector<std::pair<std::string, std::string>>{
           {R"({"type":"point","intensity":-2})", "intensity -2 is outside [0, inf]"},
           {R"({"type":"point","color":[1,1.5,1]})", "color 1.5 is outside [0, 1]"},
           {R"({"type":"spot","spot":{"innerConeAngle":0.5,"outerConeAngle":0.5}})",
            "innerConeAngle 0.5 is not below outerConeAngle 0.5"},
           {R"({"type":"spot","spot":{"outerConeAngle":2}})",
            "outerConeAngle 2 is outside [0, 1.5708]"},
       }) {
    Gltf g = one_triangle("");
    g.top = R"("extensionsUsed":["KHR_lights_punctual"])";
    g.lights = {light};
    g.node(R"("extensions":{"KHR_lights_punctual":{"light":0}})", true);
    expect_error(g.write("light_range.gltf"), "light 0 '': " + cause);
  }
}

// JSON nested 20,000 deep overflowed the stack in tinygltf (SIGSEGV); it is refused up front, in
// .gltf text and in a .glb's JSON chunk. Brackets inside strings (with escaped quotes) do not
// count.
TEST(GltfLoader, DeeplyNestedJsonIsAnError) {
  const std::string deep = std::string(20000, '[') + std::string(20000, ']');
  Gltf g = one_triangle(R"("extras":)" + deep);
  expect_error(g.write("deep.gltf"), "JSON nested deeper than 64");
  expect_error(g.write_glb("deep.glb"), "JSON nested deeper than 64");
  Gltf limit = one_triangle(R"("extras":)" + std::string(60, '[') + std::string(60, ']'));
  EXPECT_EQ(wp::load_gltf(limit.write("deep60.gltf")).triangle_count(), 1u);
  Gltf strings = one_triangle(R"("name":"\"[[[[)" + std::string(200, '{') + R"(\\")");
  EXPECT_EQ(wp::load_gltf(strings.write("brackets_in_name.gltf")).triangle_count(), 1u);
}

// What the Khronos validator refuses is an error too, naming the element.
TEST(GltfLoader, ValidatorRejectionsAreErrors) {
  {  // glTF 1.0
    std::string json = one_triangle("").json(false);
    json.replace(json.find("\"2.0\""), 5, "\"1.0\"");
    const std::string path = (temp_dir() / "version1.gltf").string();
    write_bytes(path, json);
    expect_error(path, "asset.version \"1.0\" is not 2.x");
  }
  {  // byteStride 8 for 12-byte VEC3 elements: overlapping elements
    Gltf g;
    const int view = g.view(std::vector<float>(9, 0.5f), 8);
    g.mesh({prim({{"POSITION", g.accessor(view, kF32, 3, "VEC3")}})});
    g.node("\"mesh\":0", true);
    expect_error(g.write("stride.gltf"), "byteStride 8 is smaller than the element size 12");
  }
  {  // mode 7 (no such mode) beside a valid triangle primitive
    Gltf g = one_triangle("");
    g.meshes = {"{\"primitives\":[" + prim({{"POSITION", 0}}) + "," +
                prim({{"POSITION", 0}}, -1, 7) + "]}"};
    expect_error(g.write("mode7.gltf"), "mesh 0 primitive 1: mode 7 is not a glTF primitive mode");
  }
  // NaN or Inf in a float attribute: POSITION, NORMAL, TEXCOORD_0.
  const float nan = std::nanf(""), inf = INFINITY;
  for (const auto& [name, bad] : std::vector<std::pair<std::string, float>>{
           {"POSITION", nan}, {"NORMAL", inf}, {"TEXCOORD_0", nan}, {"TEXCOORD_0", -inf}}) {
    Gltf g = one_triangle("");
    const bool uv = name == "TEXCOORD_0";
    std::vector<float> values(uv ? 6 : 9, name == "NORMAL" ? 0.0f : 0.25f);
    if (name == "NORMAL") values[2] = values[5] = values[8] = 1.0f;
    values[uv ? 3 : 4] = bad;  // element 1
    std::map<std::string, int> a{{"POSITION", 0}};
    const int accessor = g.accessor(g.view(values), kF32, 3, uv ? "VEC2" : "VEC3");
    a[name] = accessor;
    g.meshes = {"{\"primitives\":[" + prim(a) + "]}"};
    expect_error(g.write("nonfinite.gltf"), "accessor " + std::to_string(accessor) + " (" + name +
                                                "): element 1 is not finite");
  }
  // A componentType that is no glTF type, for an attribute or for sparse indices (fuzzing found
  // 2561 in sparse indices shifting by a negative amount, caught only by UBSan).
  for (int type : {-1, 0, 2561, 5119, 5127, 5152, 70000}) {
    Gltf g;
    const int base = g.view(std::vector<vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
    const int idx = g.view(std::vector<std::uint16_t>{1, 0});
    const int val = g.view(std::vector<vec3>{{5, 5, 5}});
    const std::string sparse =
        ",\"sparse\":{\"count\":1,\"indices\":{\"bufferView\":" + std::to_string(idx) +
        ",\"componentType\":" + std::to_string(type) +
        "},\"values\":{\"bufferView\":" + std::to_string(val) + "}}";
    g.mesh({prim({{"POSITION", g.accessor(base, kF32, 3, "VEC3", sparse)}})});
    g.node("\"mesh\":0", true);
    expect_error(g.write("sparse_type.gltf"),
                 "accessor 0 (POSITION) sparse: unsupported index "
                 "component type " +
                     std::to_string(type));
    Gltf h;
    h.mesh(
        {prim({{"POSITION", h.accessor(h.view(std::vector<float>(9, 0.5f)), type, 3, "VEC3")}})});
    h.node("\"mesh\":0", true);
    // tinygltf refuses most such values itself ("Invalid `componentType`"), not 5127.
    expect_error(h.write("attribute_type.gltf"),
                 type == 5127 ? "unsupported component type 5127" : "omponentType");
  }
}

// An empty scene is valid glTF: no nodes, only a camera, or only non-triangle primitives. It loads
// with zero triangles, a warning, and bounds at the origin (framing_camera still works).
TEST(GltfLoader, EmptyScenesLoad) {
  Gltf none = one_triangle("");
  none.scenes = R"("scene":0,"scenes":[{"nodes":[]}])";
  Gltf nameless = one_triangle("");
  nameless.scenes = R"("scenes":[{}])";
  Gltf camera;
  camera.cameras = {R"({"type":"perspective","perspective":{"yfov":0.7,"znear":0.1}})"};
  camera.vec3s({{0, 0, 0}});  // an unused accessor: a buffer cannot be empty
  camera.node("\"camera\":0", true);
  Gltf lines = one_triangle("");
  lines.meshes = {"{\"primitives\":[" + prim({{"POSITION", 0}}, -1, 1) + "]}"};
  const std::vector<std::pair<const Gltf*, std::size_t>> cases = {
      {&none, 0}, {&nameless, 0}, {&camera, 1}, {&lines, 0}};
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const std::string path = cases[i].first->write("empty" + std::to_string(i) + ".gltf");
    const wp::Scene s = wp::load_gltf(path);
    EXPECT_EQ(s.triangle_count(), 0u) << path;
    EXPECT_EQ(s.cameras.size(), cases[i].second) << path;
    EXPECT_TRUE(near(s.bounds_lo, {0, 0, 0}) && near(s.bounds_hi, {0, 0, 0})) << path;
    EXPECT_TRUE(std::any_of(s.warnings.begin(), s.warnings.end(), [](const std::string& w) {
      return w.find("has no triangles") != std::string::npos;
    })) << path;
    const wp::Camera c = wp::framing_camera(s, 1.5f);
    EXPECT_TRUE(std::isfinite(c.position.x + c.position.y + c.position.z)) << path;
  }
}

// Every truncation of a valid .glb, and random byte corruptions of it, either load or throw
// wp::Error (run under ASan or valgrind to check for out-of-range reads).
TEST(GltfLoader, TruncatedAndCorruptedGlbNeverCrash) {
  const std::string bytes = hierarchy().glb();
  const std::string path = (temp_dir() / "mutant.glb").string();
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    write_bytes(path, bytes.substr(0, n));
    EXPECT_THROW(wp::load_gltf(path), wp::Error) << "truncated to " << n;
  }
  std::mt19937 rng(7);
  int loaded = 0;
  for (int i = 0; i < 1500; ++i) {
    std::string m = bytes;
    for (int k = 0; k < 1 + i % 3; ++k) m[rng() % m.size()] = "\x00\xff\x7f:,[]}\"-9e0"[rng() % 13];
    write_bytes(path, m);
    try {
      const wp::Scene s = wp::load_gltf(path);
      if (s.triangle_count() == 0) continue;  // e.g. a corrupted "mesh" key: a valid empty scene
      check_invariants(s);
      ++loaded;
    } catch (const wp::Error&) {
    }
  }
  EXPECT_GT(loaded, 0);  // some mutations are harmless (e.g. inside a name)
}

// The same for a .glb whose base colour and normal textures come from a PNG in a bufferView:
// corrupt images and views fail with wp::Error, never a crash or an out-of-range read.
TEST(GltfLoader, CorruptedTexturedGlbNeverCrashes) {
  Gltf g = textured_square({0});
  const int view = g.view(encode_png(2, 2, kImage0));
  g.top = R"("images":[{"bufferView":)" + std::to_string(view) +
          R"(,"mimeType":"image/png"}],"textures":[{"source":0}])";
  g.materials = {R"({"pbrMetallicRoughness":{"baseColorTexture":{"index":0}},)"
                 R"("normalTexture":{"index":0}})"};
  const std::string bytes = g.glb();
  const std::string path = (temp_dir() / "textured_mutant.glb").string();
  check_invariants(wp::load_gltf(g.write_glb("textured.glb")));
  std::mt19937 rng(3);
  for (int i = 0; i < 1000; ++i) {
    std::string m = bytes;
    for (int k = 0; k < 1 + i % 3; ++k) m[rng() % m.size()] = "\x00\xff\x7f:,[]}\"-9e0"[rng() % 13];
    write_bytes(path, m);
    try {
      const wp::Scene s = wp::load_gltf(path);
      if (s.triangle_count() > 0) check_invariants(s);  // an empty scene is valid
    } catch (const wp::Error&) {
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Real-world assets (../shared/assets; skipped when absent)

TEST(GltfAssets, Box) {
  WP_REQUIRE_MODEL(path, "Box/Box.glb");
  const wp::Scene s = wp::load_gltf(path);
  check_invariants(s);
  EXPECT_EQ(s.triangle_count(), 12u);
  EXPECT_EQ(s.materials.size(), 1u);
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_TRUE(near(s.bounds_lo, vec3(-0.5f)));
  EXPECT_TRUE(near(s.bounds_hi, vec3(0.5f)));
}

TEST(GltfAssets, Cameras) {
  WP_REQUIRE_MODEL(path, "Cameras/Cameras.gltf");
  const wp::Scene s = wp::load_gltf(path);
  check_invariants(s);
  ASSERT_EQ(s.cameras.size(), 2u);
  EXPECT_EQ(s.cameras[0].type, wp::CameraType::kPerspective);
  EXPECT_FLOAT_EQ(s.cameras[0].yfov, 0.7f);
  EXPECT_FLOAT_EQ(s.cameras[0].znear, 0.01f);
  EXPECT_EQ(s.cameras[1].type, wp::CameraType::kOrthographic);
  EXPECT_EQ(s.cameras[1].xmag, 1.0f);
  EXPECT_EQ(s.cameras[1].ymag, 1.0f);
  for (const wp::Camera& c : s.cameras) {
    EXPECT_TRUE(near(c.position, {0.5f, 0.5f, 3.0f}));
    EXPECT_TRUE(near(c.forward, {0, 0, -1}));
  }
}

TEST(GltfAssets, LightsPunctualLamp) {
  WP_REQUIRE_MODEL(path, "LightsPunctualLamp/LightsPunctualLamp.gltf");
  const wp::Scene s = wp::load_gltf(path);
  check_invariants(s);
  ASSERT_EQ(s.lights.size(), 5u);
  for (const wp::PunctualLight& l : s.lights) EXPECT_EQ(l.type, wp::LightType::kPoint);
}

// Mirrored nodes: smooth triangles' fronts (counter-clockwise) agree with their normals.
TEST(GltfAssets, NegativeScaleTest) {
  WP_REQUIRE_MODEL(path, "NegativeScaleTest/NegativeScaleTest.glb");
  const wp::Scene s = wp::load_gltf(path);
  check_invariants(s);
  std::size_t agree = 0;
  for (std::size_t t = 0; t < s.triangle_count(); ++t) {
    const vec3 n = s.normals[s.indices[3 * t]] + s.normals[s.indices[3 * t + 1]] +
                   s.normals[s.indices[3 * t + 2]];
    agree +=
        glm::dot(glm::cross(corner(s, t, 1) - corner(s, t, 0), corner(s, t, 2) - corner(s, t, 0)),
                 n) > 0.0f;
  }
  EXPECT_GT(agree, s.triangle_count() * 99 / 100);
}

TEST(GltfAssets, CornellBox) {
  WP_REQUIRE_MODEL(path, "CornellBox/CornellBox.glb");
  const wp::Scene s = wp::load_gltf(path);
  check_invariants(s);
  EXPECT_EQ(s.materials[0].emission, vec3(100.0f));  // emissiveFactor 1 x emissiveStrength 100
  EXPECT_TRUE(s.materials[0].double_sided);
  // The emitter's COLOR_0 is u16 normalized 65535 everywhere: exactly white.
  for (const glm::vec4& c : s.color0) EXPECT_EQ(c, glm::vec4(1.0f));
}

// COLOR_0 as float VEC4 that is not white everywhere.
TEST(GltfAssets, VertexColorTest) {
  WP_REQUIRE_MODEL(path, "VertexColorTest/VertexColorTest.glb");
  const wp::Scene s = wp::load_gltf(path);
  check_invariants(s);
  EXPECT_TRUE(std::any_of(s.color0.begin(), s.color0.end(),
                          [](const glm::vec4& c) { return c != glm::vec4(1.0f); }));
}

TEST(GltfAssets, MetalRoughSpheresNoTextures) {
  WP_REQUIRE_MODEL(path, "MetalRoughSpheresNoTextures/MetalRoughSpheresNoTextures.glb");
  const wp::Scene s = wp::load_gltf(path);
  check_invariants(s);
  EXPECT_EQ(s.triangle_count(), 1040409u);
  EXPECT_EQ(s.materials.size(), 99u);  // 98 + the default, used by 25 primitives
}

// Texture assets. Each README's claim, checked on what the loader produces.

// Texture orientation: TopLeft_TEXCOORD_0 (the README's example) spans u, v in [0, 0.4]; every
// textured material has one sRGB base colour texture on set 0 of the one image.
TEST(GltfAssets, TextureCoordinateTest) {
  WP_REQUIRE_MODEL(path, "TextureCoordinateTest/TextureCoordinateTest.glb");
  const wp::Scene s = wp::load_gltf(path);
  check_invariants(s);
  EXPECT_TRUE(s.warnings.empty());
  ASSERT_EQ(s.images.size(), 1u);
  EXPECT_GT(s.images[0].width, 0);
  EXPECT_EQ(s.images[0].rgba.size(), std::size_t(4 * s.images[0].width * s.images[0].height));
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_TRUE(s.textures[0].srgb);
  EXPECT_EQ(s.materials[0].base_color_texture, -1);  // BackPlaneMat
  for (std::size_t m = 1; m < s.materials.size(); ++m)
    EXPECT_EQ(s.materials[m].base_color_texture, 0) << s.materials[m].name;
  EXPECT_TRUE(s.uv1.empty());
  EXPECT_TRUE(s.tangents.empty());
}

// The wrap tests: REPEAT/CLAMP_TO_EDGE and REPEAT/MIRRORED_REPEAT on either axis.
TEST(GltfAssets, TextureSettingsTest) {
  WP_REQUIRE_MODEL(path, "TextureSettingsTest/TextureSettingsTest.glb");
  const wp::Scene s = wp::load_gltf(path);
  check_invariants(s);
  const auto wraps = [&](const char* material) {
    for (const wp::Material& m : s.materials)
      if (m.name == material) {
        const wp::TextureRef& t = s.textures.at(std::size_t(m.base_color_texture));
        return std::make_pair(t.wrap_s, t.wrap_t);
      }
    ADD_FAILURE() << "no material " << material;
    return std::make_pair(wp::Wrap::kRepeat, wp::Wrap::kRepeat);
  };
  using W = wp::Wrap;
  EXPECT_EQ(wraps("TextureClampMaterialT"), std::make_pair(W::kRepeat, W::kClampToEdge));
  EXPECT_EQ(wraps("TextureClampMaterialS"), std::make_pair(W::kClampToEdge, W::kRepeat));
  EXPECT_EQ(wraps("TextureMirrorMaterialT"), std::make_pair(W::kRepeat, W::kMirroredRepeat));
  EXPECT_EQ(wraps("TextureMirrorMaterialS"), std::make_pair(W::kMirroredRepeat, W::kRepeat));
  // The repeat tests clamp the other axis.
  EXPECT_EQ(wraps("TextureRepeatMaterialT"), std::make_pair(W::kClampToEdge, W::kRepeat));
  EXPECT_EQ(wraps("TextureRepeatMaterialS"), std::make_pair(W::kRepeat, W::kClampToEdge));
}

// sRGB for base colour and emissive, linear for metallic-roughness; the three 1x1 image variants
// (plain, gamma chunk, ICC profile) decode to the same texel: the metadata is ignored.
TEST(GltfAssets, TextureEncodingTest) {
  WP_REQUIRE_MODEL(path, "TextureEncodingTest/TextureEncodingTest.glb");
  const wp::Scene s = wp::load_gltf(path);
  check_invariants(s);
  const auto texel = [&](int texture) {
    const wp::Image& img = s.images.at(std::size_t(s.textures.at(std::size_t(texture)).image));
    return std::vector<std::uint8_t>(img.rgba.begin(), img.rgba.begin() + 4);
  };
  for (int m = 1; m <= 3; ++m) {
    EXPECT_TRUE(s.textures.at(std::size_t(s.materials[std::size_t(m)].base_color_texture)).srgb);
    EXPECT_TRUE(s.textures.at(std::size_t(s.materials[std::size_t(m + 4)].emissive_texture)).srgb);
    const int mr = s.materials[std::size_t(m + 8)].metallic_roughness_texture;
    EXPECT_FALSE(s.textures.at(std::size_t(mr)).srgb);
    EXPECT_EQ(texel(s.materials[std::size_t(m)].base_color_texture),
              texel(s.materials[1].base_color_texture));
    EXPECT_EQ(texel(mr), texel(s.materials[9].metallic_roughness_texture));
  }
}

// No TANGENT in the file: generated for every vertex, unit, orthogonal to the normal, +-1.
TEST(GltfAssets, NormalTangentTest) {
  WP_REQUIRE_MODEL(path, "NormalTangentTest/NormalTangentTest.glb");
  const wp::Scene s = wp::load_gltf(path);
  check_invariants(s);
  check_tangents(s);
  EXPECT_GE(s.materials[0].normal_texture, 0);
}

// TANGENT supplied (by a MikkTSpace exporter), UVs mirrored on half the cells. Generating them
// anew from the same positions, normals and UVs must reproduce the supplied handedness and,
// closely, the direction: the check that our generator's convention is glTF's.
TEST(GltfAssets, NormalTangentMirrorTest) {
  WP_REQUIRE_MODEL(path, "NormalTangentMirrorTest/NormalTangentMirrorTest.glb");
  const wp::Scene s = wp::load_gltf(path);
  check_invariants(s);
  check_tangents(s, 1e-3f);
  EXPECT_TRUE(std::any_of(s.tangents.begin(), s.tangents.end(),
                          [](const glm::vec4& t) { return t.w < 0.0f; }));
  wp::Scene g = s;
  wp::gltf::generate_tangents(g, 0, 0);
  check_tangents(g);
  std::size_t corners = 0, same_w = 0, close = 0;
  for (std::size_t k = 0; k < s.indices.size(); ++k, ++corners) {
    const glm::vec4 a = s.tangents[s.indices[k]], b = g.tangents[g.indices[k]];
    same_w += a.w == b.w;
    close += glm::dot(vec3(a), vec3(b)) > 0.9f;
  }
  EXPECT_GT(same_w, corners * 99 / 100) << same_w << " of " << corners;
  EXPECT_GT(close, corners * 95 / 100) << close << " of " << corners;
}

// Alpha modes and cutoffs as the README lists them (MASK without alphaCutoff: 0.5).
TEST(GltfAssets, AlphaBlendModeTest) {
  WP_REQUIRE_MODEL(path, "AlphaBlendModeTest/AlphaBlendModeTest.glb");
  const wp::Scene s = wp::load_gltf(path);
  check_invariants(s);
  std::map<std::string, const wp::Material*> by_name;
  for (const wp::Material& m : s.materials) by_name[m.name] = &m;
  using A = wp::AlphaMode;
  EXPECT_EQ(by_name.at("MatOpaque")->alpha_mode, A::kOpaque);
  EXPECT_EQ(by_name.at("MatBlend")->alpha_mode, A::kBlend);
  EXPECT_EQ(by_name.at("MatCutoff25")->alpha_mode, A::kMask);
  EXPECT_FLOAT_EQ(by_name.at("MatCutoff25")->alpha_cutoff, 0.25f);
  EXPECT_FLOAT_EQ(by_name.at("MatCutoff75")->alpha_cutoff, 0.75f);
  EXPECT_FLOAT_EQ(by_name.at("MatCutoffDefault")->alpha_cutoff, 0.5f);
  const wp::Image& img = s.images.at(
      std::size_t(s.textures.at(std::size_t(by_name.at("MatBlend")->base_color_texture)).image));
  bool partial = false;  // the texture carries an alpha ramp
  for (std::size_t i = 3; i < img.rgba.size(); i += 4)
    partial |= img.rgba[i] > 0 && img.rgba[i] < 255;
  EXPECT_TRUE(partial);
}

// The emissive texture reads TEXCOORD_1, which differs from TEXCOORD_0.
TEST(GltfAssets, MultiUVTest) {
  WP_REQUIRE_MODEL(path, "MultiUVTest/MultiUVTest.glb");
  const wp::Scene s = wp::load_gltf(path);
  check_invariants(s);
  ASSERT_EQ(s.uv1.size(), s.positions.size());
  EXPECT_EQ(s.textures.at(std::size_t(s.materials[0].emissive_texture)).texcoord, 1);
  EXPECT_EQ(s.textures.at(std::size_t(s.materials[0].base_color_texture)).texcoord, 0);
  EXPECT_NE(s.uv0, s.uv1);
}

// Requires KHR_texture_transform: loads, its normal textures scaled 5x (rotated for some).
TEST(GltfAssets, GlamVelvetSofa) {
  WP_REQUIRE_MODEL(path, "GlamVelvetSofa/GlamVelvetSofa.glb");
  const wp::Scene s = wp::load_gltf(path);
  check_invariants(s);
  check_tangents(s);
  std::size_t transformed = 0;
  for (const wp::Material& m : s.materials) {
    if (m.normal_texture < 0) continue;
    const wp::TextureRef& t = s.textures.at(std::size_t(m.normal_texture));
    EXPECT_NEAR(glm::length(glm::vec2(t.row_u.x, t.row_v.x)), 5.0f, 1e-4f) << m.name;
    ++transformed;
  }
  EXPECT_GT(transformed, 0u);
}

// Every model loads with triangles, except exactly those requiring an unsupported extension.
TEST(GltfAssets, AllModels) {
  const fs::path models = fs::path(wp::test::assets_dir()) / "models";
  if (!fs::is_directory(models)) GTEST_SKIP() << "no assets under " << models;
  const std::map<std::string, std::string> expected_failures = {
      {"IridescenceSuzanne", "KHR_materials_iridescence"}};
  int count = 0;
  for (const auto& dir : fs::directory_iterator(models)) {
    for (const auto& file : fs::directory_iterator(dir.path())) {
      const std::string ext = file.path().extension().string();
      if (ext != ".glb" && ext != ".gltf") continue;
      ++count;
      const std::string name = dir.path().filename().string();
      const auto failure = expected_failures.find(name);
      SCOPED_TRACE(file.path().string());
      if (failure != expected_failures.end()) {
        expect_error(file.path().string(), "requires unsupported extension " + failure->second);
      } else {
        check_invariants(wp::load_gltf(file.path().string()));
      }
    }
  }
  EXPECT_EQ(count, 39);
}

}  // namespace
