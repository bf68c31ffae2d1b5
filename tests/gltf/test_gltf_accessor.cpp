// glTF loader, gltf_accessor.cpp: reading accessors (stride and offset, normalized and quantized
// components, sparse accessors) and what the validator refuses in them.
// Shared fixture: tests/gltf/gltf_files.h.
#include "tests/gltf/gltf_files.h"

namespace {

using namespace wp::test::gltf_files;  // NOLINT(google-build-using-namespace)

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

}  // namespace
