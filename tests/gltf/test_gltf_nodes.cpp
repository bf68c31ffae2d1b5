// glTF loader, gltf_nodes.cpp: node transforms through the hierarchy (and the winding under
// mirrors), cameras and KHR_lights_punctual lights placed by their nodes. Shared fixture:
// tests/gltf/gltf_files.h.
#include "tests/gltf/gltf_files.h"

namespace {

using namespace wp::test::gltf_files;  // NOLINT(google-build-using-namespace)

TEST(GltfLoader, TrsAndMatrixThroughHierarchy) {
  const std::string path = hierarchy().write("hierarchy.gltf");
  const wp::Scene s = wp::load_gltf(path);
  EXPECT_EQ(s.source, path);
  EXPECT_TRUE(s.warnings.empty());
  check_hierarchy(s);
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

}  // namespace
