// glTF loader, gltf_primitive.cpp: triangle primitives (index types, strips and fans, flat and
// smooth normals, non-triangle modes), TEXCOORD_1 and tangents (supplied and generated). Shared
// fixture: tests/gltf/gltf_files.h.
#include "tests/gltf/gltf_files.h"

namespace {

using namespace wp::test::gltf_files;  // NOLINT(google-build-using-namespace)

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
  wp::LoadOptions flat;
  flat.instancing = wp::Instancing::kNever;  // the loader's own transform of the tangents
  const wp::Scene s = wp::load_gltf(g.write("tangents.gltf"), flat);
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

}  // namespace
