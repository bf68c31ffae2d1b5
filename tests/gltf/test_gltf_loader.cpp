// glTF loader, gltf_loader.cpp: the file (.gltf, .glb), the scene and its node graph, extensions,
// the framing camera, malformed files (wp::Error naming the file and the cause, never a crash).
// Shared fixture: tests/gltf/gltf_files.h.
#include <set>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/matrix.hpp>

#include "tests/gltf/gltf_files.h"

namespace {

using namespace wp::test::gltf_files;  // NOLINT(google-build-using-namespace)

// temp_dir() is removed after the tests (once per executable, so here only).
[[maybe_unused]] auto* const kCleanup = ::testing::AddGlobalTestEnvironment(new TempCleanup);

TEST(GltfLoader, GlbMatchesGltf) {
  const wp::Scene s = wp::load_gltf(hierarchy().write_glb("hierarchy.glb"));
  check_hierarchy(s);
  // Content decides the format, not the extension.
  check_hierarchy(wp::load_gltf(hierarchy().write_glb("binary_named.gltf")));
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
  g.top = R"("extensionsUsed":["KHR_animation_pointer","KHR_materials_volume",)"
          R"("KHR_texture_transform","KHR_materials_unlit","KHR_materials_sheen"],)"
          R"("textures":[{"source":0}],"images":[{"uri":"data:image/png;base64,AAAA"}])";
  const wp::Scene s = wp::load_gltf(g.write("warn.gltf"));
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("KHR_animation_pointer"), std::string::npos) << s.warnings[0];
  EXPECT_TRUE(s.images.empty());
}

// GltfSummary: mesh 0 placed by two nodes (one with 3 EXT_mesh_gpu_instancing instances), mesh 1
// by none, a third node with no mesh; the file's lists as it has them. Four placements of one
// triangle load instanced by default (LoadOptions::instancing, kAuto).
TEST(GltfLoader, Summary) {
  Gltf g = one_triangle("");
  g.mesh({prim({{"POSITION", 0}})});
  const int offsets = g.vec3s({{0, 0, 0}, {5, 0, 0}, {10, 0, 0}});
  g.node(R"("mesh":0,"extensions":{"EXT_mesh_gpu_instancing":{"attributes":{"TRANSLATION":)" +
             std::to_string(offsets) + "}}}",
         true);
  g.node(R"("translation":[1,0,0])", true);
  g.top = R"("extensionsUsed":["EXT_mesh_gpu_instancing","KHR_texture_transform"],)"
          R"("extensionsRequired":["KHR_texture_transform"])";
  const wp::Scene s = wp::load_gltf(g.write("summary.gltf"));
  EXPECT_EQ(s.triangle_count(), 1u);
  EXPECT_EQ(s.instances.size(), 1u + 3u);
  EXPECT_EQ(s.world_triangle_count(), 1u + 3u);
  EXPECT_EQ(s.gltf.meshes, 2u);
  EXPECT_EQ(s.gltf.meshes_placed, 1u);
  EXPECT_EQ(s.gltf.mesh_nodes, 2u);
  EXPECT_EQ(s.gltf.gpu_instanced_nodes, 1u);
  EXPECT_EQ(s.gltf.gpu_instances, 3u);
  EXPECT_EQ(s.gltf.extensions_used,
            (std::vector<std::string>{"EXT_mesh_gpu_instancing", "KHR_texture_transform"}));
  EXPECT_EQ(s.gltf.extensions_required, std::vector<std::string>{"KHR_texture_transform"});
  EXPECT_EQ(s.gltf.materials, 0u);
  EXPECT_EQ(s.materials.size(), 1u);  // glTF's default material
}

// EXT_mesh_gpu_instancing: the node places its mesh once per instance, at node world x T x R x S
// (the extension's order), with ROTATION as normalized shorts and a mirroring SCALE among them:
// each instance's corners against that product in double, its winding kept counter-clockwise
// (the face normal is the transformed one's direction), and the counts before loading multiplied.
// Flattened (each instance a copy), and instanced (each instance that product, the mesh once).
TEST(GltfLoader, GpuInstancesArePlaced) {
  Gltf g;
  const int pos = g.vec3s({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  g.mesh({prim({{"POSITION", pos}})});
  const int t = g.vec3s({{0, 0, 0}, {5, 0, 0}, {0, 5, 0}});
  // Quaternions (x, y, z, w) x 32767: identity, 90 degrees about +Z, 180 degrees about +X.
  const int r = g.accessor(
      g.view(std::vector<std::int16_t>{0, 0, 0, 32767, 0, 0, 23170, 23170, 32767, 0, 0, 0}), 5122,
      3, "VEC4", R"(,"normalized":true)");
  const int sc = g.vec3s({{1, 1, 1}, {2, 2, 2}, {-1, 1, 1}});
  g.node(R"("mesh":0,"translation":[0,0,-3],"extensions":{"EXT_mesh_gpu_instancing":)"
         R"({"attributes":{"TRANSLATION":)" +
             std::to_string(t) + R"(,"ROTATION":)" + std::to_string(r) + R"(,"SCALE":)" +
             std::to_string(sc) + "}}}",
         true);
  g.top = R"("extensionsUsed":["EXT_mesh_gpu_instancing"])";
  wp::LoadOptions options;
  options.instancing = wp::Instancing::kNever;
  std::uint64_t counted = 0;
  options.check_counts = [&](const wp::LoadCounts& c) { counted = c.placements; };
  const std::string path = g.write("instances.gltf");
  const wp::Scene s = wp::load_gltf(path, options);
  options.instancing = wp::Instancing::kAlways;
  const wp::Scene instanced = wp::load_gltf(path, options);
  ASSERT_EQ(instanced.triangle_count(), 1u);
  ASSERT_EQ(instanced.instances.size(), 3u);
  check_invariants(s);
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_EQ(counted, 3u);
  ASSERT_EQ(s.triangle_count(), 3u);
  const auto rotation = [](double angle, glm::dvec3 axis) {
    return glm::rotate(glm::dmat4(1.0), angle, axis);
  };
  const glm::dmat4 node = glm::translate(glm::dmat4(1.0), glm::dvec3(0, 0, -3));
  const double half_pi = std::acos(0.0);
  // Rotation 1 is the normalized shorts' quaternion (0, 0, q, q), q = 23170 / 32767 = 0.707107,
  // renormalised: 90 degrees about +Z exactly.
  const glm::dmat4 instances[3] = {
      glm::dmat4(1.0),
      glm::translate(glm::dmat4(1.0), glm::dvec3(5, 0, 0)) * rotation(half_pi, {0, 0, 1}) *
          glm::scale(glm::dmat4(1.0), glm::dvec3(2.0)),
      glm::translate(glm::dmat4(1.0), glm::dvec3(0, 5, 0)) * rotation(2 * half_pi, {1, 0, 0}) *
          glm::scale(glm::dmat4(1.0), glm::dvec3(-1, 1, 1))};
  const vec3 local[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (std::size_t i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    const glm::dmat4 m = node * instances[i];
    for (int col = 0; col < 4; ++col)
      for (int row = 0; row < 4; ++row)
        EXPECT_NEAR(instanced.instances[i].to_world[col][row], m[col][row], 1e-12);
    // A mirrored triangle has two corners swapped (winding kept): compare the corners as a set.
    std::vector<vec3> got;
    for (int c = 0; c < 3; ++c) got.push_back(corner(s, i, c));
    for (const vec3& p : local) {
      const vec3 e(m * glm::dvec4(glm::dvec3(p), 1.0));
      EXPECT_TRUE(
          std::any_of(got.begin(), got.end(), [&](const vec3& x) { return near(x, e, 1e-5f); }))
          << e.x << " " << e.y << " " << e.z;
    }
    // The front: normals go by the inverse transpose, mirrored or not.
    const glm::dvec3 n =
        glm::normalize(glm::transpose(glm::inverse(glm::dmat3(m))) * glm::dvec3(0, 0, 1));
    EXPECT_TRUE(near(geometric_normal(s, i), vec3(n), 1e-5f));
  }
  EXPECT_LT(glm::determinant(glm::dmat3(node * instances[2])), 0.0);  // the mirrored one
}

// EXT_mesh_gpu_instancing's rules: attribute counts equal, integer rotations normalized, an
// attributes object; each broken one is an error naming the node and the extension.
TEST(GltfLoader, MalformedGpuInstancingIsAnError) {
  const auto error = [](const std::string& ext, const std::string& name) {
    Gltf g = one_triangle(R"("extensions":{"EXT_mesh_gpu_instancing":)" + ext + "}");
    g.vec3s({{0, 0, 0}, {1, 0, 0}});  // accessor 1: 2 items
    g.vec3s({{0, 0, 0}});             // accessor 2: 1 item
    g.accessor(g.view(std::vector<std::int8_t>{0, 0, 0, 127}), 5120, 1,
               "VEC4");  // 3: not normalized
    try {
      wp::load_gltf(g.write(name));
    } catch (const wp::Error& e) {
      return std::string(e.what());
    }
    return std::string("loaded");
  };
  for (const auto& [ext, cause] : std::vector<std::pair<std::string, std::string>>{
           {R"({"attributes":{"TRANSLATION":1,"SCALE":2}})", "counts must be equal"},
           {R"({"attributes":{"ROTATION":3}})", "must be normalized"},
           {R"({})", "no attributes object"},
           {R"({"attributes":{}})", "no attributes"},
           {R"({"attributes":{"TRANSLATION":9}})", "does not exist"}}) {
    const std::string e = error(ext, "bad_instancing.gltf");
    EXPECT_NE(e.find("node 0: EXT_mesh_gpu_instancing"), std::string::npos) << e;
    EXPECT_NE(e.find(cause), std::string::npos) << ext << ": " << e;
  }
}

// LoadOptions::check_counts sees the default scene's counts before any geometry is loaded: each
// placement of a mesh counts its triangles again; triangle lists count indices / 3 (a leftover
// index none), strips and fans at most n - 2 and at least 0; an accessor whose count no buffer
// holds counts nothing (the load then reports it). Throwing from the callback refuses the file
// with that reason, naming it.
TEST(GltfLoader, CountsBeforeLoading) {
  Gltf g;
  const int pos = g.vec3s({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 0, 0}});
  const int seven = g.indices(std::vector<std::uint16_t>{0, 1, 2, 1, 3, 2, 4});
  g.mesh({prim({{"POSITION", pos}}, seven)});  // mesh 0: 2 triangles and a leftover index
  g.mesh({prim({{"POSITION", pos}}, -1, 5)});  // mesh 1: a strip of 5 vertices
  const int child = g.node(R"("mesh":1)");
  g.node(R"("mesh":0)", true);
  g.node(R"("mesh":0,"translation":[5,0,0])", true);
  g.node(R"("mesh":1,"translation":[0,5,0],"children":[)" + std::to_string(child) + "]", true);
  g.node(R"("translation":[0,0,5])", true);  // no mesh
  std::vector<wp::LoadCounts> seen;
  wp::LoadOptions options;
  options.instancing = wp::Instancing::kNever;
  options.check_counts = [&](const wp::LoadCounts& c) { seen.push_back(c); };
  const wp::Scene s = wp::load_gltf(g.write("counts.gltf"), options);
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0].placements, 4u);
  EXPECT_EQ(seen[0].triangles, 4u);           // 2 x 2 from the lists
  EXPECT_EQ(seen[0].max_triangles, 4u + 6u);  // and up to 2 x (5 - 2) from the strips
  EXPECT_EQ(seen[0].meshes, 2u);              // each mesh once: what an instanced load holds
  EXPECT_EQ(seen[0].mesh_triangles, 2u);
  EXPECT_EQ(seen[0].mesh_max_triangles, 2u + 3u);
  EXPECT_FALSE(seen[0].instanced);
  // kAuto instances them: the copies would hold twice the meshes' triangles.
  EXPECT_TRUE(wp::use_instancing(wp::Instancing::kAuto, seen[0]));
  EXPECT_EQ(s.triangle_count(), 10u);  // this strip has no degenerate triangle
  EXPECT_GE(s.triangle_count(), seen[0].triangles);
  EXPECT_LE(s.triangle_count(), seen[0].max_triangles);

  Gltf lie = g;  // an accessor claiming 3 million vertices over 60 bytes counts nothing
  lie.accessors[static_cast<std::size_t>(pos)] =
      R"({"bufferView":0,"componentType":5126,"count":3000000,"type":"VEC3"})";
  lie.meshes[1] = "{\"primitives\":[" + prim({{"POSITION", pos}}) + "]}";  // a list now
  seen.clear();
  const std::string lie_path = lie.write("counts_lie.gltf");
  EXPECT_THROW(wp::load_gltf(lie_path, options), wp::Error);
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0].max_triangles, 4u);  // the index lists still count (their data is there)

  options.check_counts = [](const wp::LoadCounts& c) {
    throw wp::Error("refused at " + std::to_string(c.triangles) + " triangles");
  };
  const std::string path = g.write("counts_refused.gltf");
  try {
    wp::load_gltf(path, options);
    ADD_FAILURE() << "not refused";
  } catch (const wp::Error& e) {
    EXPECT_EQ(std::string(e.what()), path + ": refused at 4 triangles");
  }
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

TEST(GltfLoader, ErrorsNameFileAndCause) {
  Gltf g = one_triangle("");
  g.top = R"("extensionsUsed":["EXT_texture_avif"],)"
          R"("extensionsRequired":["EXT_texture_avif"])";
  expect_error(g.write("avif.gltf"), "requires unsupported extension EXT_texture_avif");

  const std::string missing = (temp_dir() / "missing.gltf").string();
  expect_error(missing, "no such file");
  const std::string bad_json = (temp_dir() / "bad.gltf").string();
  write_bytes(bad_json, R"({"asset":{"version":"2.0"},"nodes":[{"mesh":0})");
  expect_error(bad_json, "parse error");
  const std::string empty = (temp_dir() / "empty.gltf").string();
  write_bytes(empty, "");
  expect_error(empty, "empty file");
  expect_error(temp_dir().string(), "not a regular file (a directory)");
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

// Files that require any of the supported material extensions load, without warnings.
TEST(GltfLoader, RequiredMaterialExtensionsLoad) {
  const std::string names =
      R"("KHR_materials_specular","KHR_materials_clearcoat","KHR_materials_sheen",)"
      R"("KHR_materials_anisotropy","KHR_materials_iridescence","KHR_materials_dispersion",)"
      R"("KHR_materials_diffuse_transmission","KHR_materials_variants","KHR_materials_volume",)"
      R"("KHR_materials_transmission","KHR_materials_ior","KHR_materials_emissive_strength")";
  Gltf g = one_triangle("");
  g.top = "\"extensionsUsed\":[" + names + "],\"extensionsRequired\":[" + names + "]";
  const wp::Scene s = wp::load_gltf(g.write("required.gltf"));
  check_invariants(s);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
}

// KHR_materials_variants. Variants red, green, blue; materials m0, m1, m2. Mesh 0's primitives:
// A (m0; red -> m1, green and blue -> m2), B (no material; blue -> m1), C (m0, no mappings).
Gltf variants_file() {
  Gltf g;
  const int pos = g.vec3s({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const std::string a =
      R"({"attributes":{"POSITION":0},"material":0,"extensions":{"KHR_materials_variants":)"
      R"({"mappings":[{"material":1,"variants":[0]},{"material":2,"variants":[1,2]}]}}})";
  const std::string b = R"({"attributes":{"POSITION":0},"extensions":{"KHR_materials_variants":)"
                        R"({"mappings":[{"material":1,"variants":[2],"name":"blue B"}]}}})";
  g.mesh({a, b, prim({{"POSITION", pos}}, -1, -1, 0)});
  g.node("\"mesh\":0", true);
  g.materials = {R"({"name":"m0"})", R"({"name":"m1"})", R"({"name":"m2"})"};
  g.top = R"("extensionsUsed":["KHR_materials_variants"],"extensions":{)"
          R"("KHR_materials_variants":{"variants":[{"name":"red"},{"name":"green"},)"
          R"({"name":"blue"}]}})";
  return g;
}

// Each variant gives each primitive its mapped material, or its own where it has no mapping for
// the variant; no variant gives the file's own materials. Variants are different scenes to the
// render key: the digest differs from variant to variant and from the plain file.
TEST(GltfLoader, MaterialVariantsSelectMaterials) {
  const std::string path = variants_file().write("variants.gltf");
  const wp::Scene plain = wp::load_gltf(path);
  check_invariants(plain);
  EXPECT_TRUE(plain.warnings.empty()) << plain.warnings.front();
  EXPECT_EQ(plain.variants, (std::vector<std::string>{"red", "green", "blue"}));
  EXPECT_EQ(plain.variant, "");
  ASSERT_EQ(plain.materials.size(), 4u);  // m0, m1, m2 and the default for B
  EXPECT_EQ(plain.triangle_material, (std::vector<std::uint32_t>{0, 3, 0}));
  EXPECT_EQ(wp::load_gltf(path, wp::LoadOptions{""}).digest, plain.digest);
  std::set<std::uint64_t> digests = {plain.digest};
  for (const auto& [variant, materials] :
       std::vector<std::pair<std::string, std::vector<std::uint32_t>>>{
           {"red", {1, 3, 0}}, {"green", {2, 3, 0}}, {"blue", {2, 1, 0}}}) {
    SCOPED_TRACE(variant);
    const wp::Scene s = wp::load_gltf(path, wp::LoadOptions{variant});
    check_invariants(s);
    EXPECT_EQ(s.variant, variant);
    EXPECT_EQ(s.variants, plain.variants);
    EXPECT_EQ(s.triangle_material, materials);
    EXPECT_EQ(s.materials.size(), variant == "blue" ? 3u : 4u);  // the default: B's own
    EXPECT_TRUE(digests.insert(s.digest).second) << "digest shared with another variant";
    EXPECT_EQ(wp::load_gltf(path, wp::LoadOptions{variant}).digest, s.digest);  // and stable
  }
}

// The error of load_gltf(path, LoadOptions{variant}), which must be one line naming the file.
std::string variant_error(const std::string& path, const std::string& variant) {
  try {
    wp::load_gltf(path, wp::LoadOptions{variant});
  } catch (const wp::Error& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    return what.substr(path.size() + 2);
  }
  ADD_FAILURE() << "variant '" << variant << "' of " << path << " loaded";
  return "";
}

TEST(GltfLoader, UnknownMaterialVariantIsAnError) {
  const std::string path = variants_file().write("variants.gltf");
  EXPECT_EQ(variant_error(path, "purple"),
            "no material variant 'purple': the file's variants are 'red', 'green', 'blue'");
  EXPECT_EQ(variant_error(path, "Red"),  // names are matched exactly
            "no material variant 'Red': the file's variants are 'red', 'green', 'blue'");
  EXPECT_EQ(variant_error(one_triangle("").write("no_variants.gltf"), "red"),
            "no material variant 'red': the file has no variants (KHR_materials_variants)");
}

// Malformed variants and mappings are errors, whether or not a variant is selected.
TEST(GltfLoader, MalformedMaterialVariantsAreErrors) {
  const std::string kMesh = "mesh 0 primitive 0: KHR_materials_variants: ";
  for (const auto& [mappings, cause] : std::vector<std::pair<std::string, std::string>>{
           {R"([{"material":7,"variants":[0]}])", "mapping 0: material 7 does not exist"},
           {R"([{"material":1,"variants":[3]}])",
            "mapping 0: variant 3 does not exist (the file has 3 variants)"},
           {R"([{"material":1,"variants":[0]},{"material":2,"variants":[2,0]}])",
            "mapping 1: variant 0 is mapped twice"},
           {R"([{"variants":[0]}])", "mapping 0: no material index"},
           {R"([{"material":1}])", "mapping 0: variants is not an array"},
           {R"([{"material":1,"variants":["red"]}])",
            "mapping 0: a variant index is not an integer"},
           {R"({"material":1})", "mappings is not an array"},
       }) {
    SCOPED_TRACE(mappings);
    Gltf g = variants_file();
    g.meshes = {R"({"primitives":[{"attributes":{"POSITION":0},"extensions":{)"
                R"("KHR_materials_variants":{"mappings":)" +
                mappings + "}}}]}"};
    const std::string path = g.write("bad_mappings.gltf");
    expect_error(path, kMesh + cause);
    EXPECT_NE(variant_error(path, "red").find(cause), std::string::npos);
  }
  Gltf g = variants_file();
  g.top = R"("extensions":{"KHR_materials_variants":{"variants":[{"name":"red"},{"name":5}]}})";
  expect_error(g.write("bad_variants.gltf"), "KHR_materials_variants: variant 1 has no name");
  g.top = R"("extensions":{"KHR_materials_variants":{"variants":{}}})";
  expect_error(g.write("bad_variants.gltf"), "KHR_materials_variants: variants is not an array");
}

}  // namespace
