// `wavepath info`, run as a user runs it: its counts against those read here from the glTF JSON
// with tinygltf (not through wavepath's loader), its camera indices against `render --camera`,
// the extension statuses of files that use a supported, an ignored and a refused extension, its
// memory figures and cache state against a render's, its JSON parsed strictly, and its errors.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "tests/cli_run.h"
#include "tests/test_assets.h"

namespace fs = std::filesystem;

namespace {

using json = nlohmann::json;
using wp::test::CliRun;

// What the file says, read with tinygltf and counted here: the default scene's nodes depth-first
// (children in order), the triangles of every triangle primitive they place, their cameras.
struct FileCounts {
  tinygltf::Model model;
  std::vector<int> nodes;  // in visiting order
  std::size_t triangles = 0, mesh_nodes = 0, gpu_instances = 0;
  bool default_material = false;  // a placed primitive without a material
  std::vector<int> cameras;       // glTF camera indices, in node order
};

FileCounts read_file(const std::string& path) {
  FileCounts f;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  const bool glb = fs::path(path).extension() == ".glb";
  const bool ok = glb ? loader.LoadBinaryFromFile(&f.model, &err, &warn, path)
                      : loader.LoadASCIIFromFile(&f.model, &err, &warn, path);
  EXPECT_TRUE(ok) << err;
  const tinygltf::Model& m = f.model;
  std::vector<int> stack(m.scenes[std::max(m.defaultScene, 0)].nodes);
  std::reverse(stack.begin(), stack.end());
  while (!stack.empty()) {
    const int index = stack.back();
    stack.pop_back();
    f.nodes.push_back(index);
    const tinygltf::Node& node = m.nodes[index];
    if (node.camera >= 0) f.cameras.push_back(node.camera);
    if (node.mesh >= 0) {
      ++f.mesh_nodes;
      std::size_t node_triangles = 0;
      for (const tinygltf::Primitive& p : m.meshes[node.mesh].primitives) {
        const std::size_t n =
            m.accessors[p.indices >= 0 ? p.indices : p.attributes.at("POSITION")].count;
        if (p.mode == 4) node_triangles += n / 3;
        if (p.mode == 5 || p.mode == 6) node_triangles += n >= 3 ? n - 2 : 0;
        f.default_material |= p.material < 0;
      }
      f.triangles += node_triangles;
      const auto ext = node.extensions.find("EXT_mesh_gpu_instancing");
      if (ext != node.extensions.end()) {
        const std::size_t n =
            m.accessors[ext->second.Get("attributes").Get("TRANSLATION").Get<int>()].count;
        f.gpu_instances += n;
        f.triangles += (n - 1) * node_triangles;  // a copy per instance
      }
    }
    for (auto it = node.children.rbegin(); it != node.children.rend(); ++it) stack.push_back(*it);
  }
  return f;
}

// Every run has a cache folder of its own, in the test's folder (empty unless a render fills it).
class InfoCli : public wp::test::FolderTest {
 protected:
  CliRun run(const std::string& args) {
    return wp::test::run_wavepath(dir_, args,
                                  "WAVEPATH_CACHE_DIR='" + (dir_ / "cache").string() + "'");
  }
  // `wavepath info SCENE ARGS --json`, which must succeed, parsed.
  json info(const std::string& scene, const std::string& args = "") {
    const CliRun r = run("info '" + scene + "' --json " + args);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
    return json::parse(r.out);  // throws (fails the test) on anything but one valid object
  }
  void expect_one_line_error(const CliRun& r, const std::string& cause) {
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.err.rfind("wavepath: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(cause), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  std::string cornell() const { return wp::test::source_path("scenes/cornell_box.gltf"); }
};

// Everything counted from the JSON agrees; the extensions are the file's list.
void expect_counts(const json& j, const FileCounts& f) {
  const tinygltf::Model& m = f.model;
  EXPECT_EQ(j["loaded"], true);
  EXPECT_EQ(j["triangles"], f.triangles);
  EXPECT_EQ(j["meshes"], m.meshes.size());
  EXPECT_EQ(j["mesh_instances"], f.mesh_nodes);
  EXPECT_EQ(j["gpu_instances"], f.gpu_instances);
  EXPECT_EQ(j["file_materials"], m.materials.size());
  EXPECT_EQ(j["materials"], m.materials.size() + (f.default_material ? 1 : 0));
  EXPECT_EQ(j["file_images"], m.images.size());
  EXPECT_EQ(j["file_textures"], m.textures.size());
  ASSERT_EQ(j["cameras"].size(), f.cameras.size());
  for (std::size_t i = 0; i < f.cameras.size(); ++i) {
    const tinygltf::Camera& c = m.cameras[f.cameras[i]];
    EXPECT_EQ(j["cameras"][i]["index"], i);
    EXPECT_EQ(j["cameras"][i]["name"], c.name);
    EXPECT_EQ(j["cameras"][i]["type"], c.type);
    if (c.type == "perspective") {
      EXPECT_NEAR(j["cameras"][i]["yfov"].get<double>(), c.perspective.yfov, 1e-5);
    }
  }
  std::vector<std::string> listed;
  for (const json& e : j["extensions"]) listed.push_back(e["name"]);
  EXPECT_EQ(listed, m.extensionsUsed);
}

const json* extension(const json& j, const std::string& name) {
  for (const json& e : j["extensions"])
    if (e["name"] == name) return &e;
  return nullptr;
}

TEST_F(InfoCli, CornellBoxCountsAreTheFiles) {
  const json j = info(cornell());
  expect_counts(j, read_file(cornell()));
  EXPECT_EQ(j["triangles"], 32);  // scenes/cornell_box.gltf: five walls, two boxes, a light
  EXPECT_EQ(j["emissive_materials"], 1);
  EXPECT_EQ(j["lights"]["emissive_triangles"], 2);
  EXPECT_EQ((*extension(j, "KHR_materials_emissive_strength"))["status"], "supported");
  ASSERT_EQ(j["bvh"].size(), 2u);  // both layouts, 8-wide (CPUs') first
  EXPECT_EQ(j["bvh"][0]["width"], 8);
  EXPECT_EQ(j["bvh"][1]["width"], 2);
  EXPECT_EQ(j["film_bytes"], 640 * 480 * 12 * 8);  // 12 64-bit words a pixel (film.h)
}

TEST_F(InfoCli, TextReport) {
  const CliRun r = run("info '" + cornell() + "'");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  for (const char* part :
       {"32 triangles", "cameras", "\"camera\" perspective", "KHR_materials_emissive_strength",
        "supported", "8-wide BVH", "2-wide BVH", "path state", "film", "BVH cache", "warnings"})
    EXPECT_NE(r.out.find(part), std::string::npos) << part << " in\n" << r.out;
}

// EXT_mesh_gpu_instancing: the node's mesh once per instance, 125 cubes of 12 triangles.
TEST_F(InfoCli, GpuInstancesArePlacedAndCounted) {
  WP_REQUIRE_MODEL(path, "SimpleInstancing/SimpleInstancing.glb");
  const FileCounts f = read_file(path);
  ASSERT_EQ(f.gpu_instances, 125u);  // the asset's README: a 5 x 5 x 5 grid of one cube
  const json j = info(path);
  expect_counts(j, f);
  EXPECT_EQ(j["triangles"], 125 * 12);
  EXPECT_EQ(j["instances"], 125);  // instanced by default: the cube stored once
  EXPECT_EQ(j["stored_triangles"], 12);
  EXPECT_EQ(j["gpu_instanced_nodes"], 1);
  const json* e = extension(j, "EXT_mesh_gpu_instancing");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ((*e)["status"], "supported");
  EXPECT_EQ((*e)["required"], false);
  EXPECT_TRUE(j["warnings"].empty());
}

TEST_F(InfoCli, SupportedMaterialExtensions) {
  WP_REQUIRE_MODEL(path, "ClearCoatTest/ClearCoatTest.glb");
  const json j = info(path, "--bvh-width 2");
  expect_counts(j, read_file(path));
  const json* e = extension(j, "KHR_materials_clearcoat");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ((*e)["status"], "supported");
  EXPECT_NE(j["features"].get<std::string>().find("clearcoat"), std::string::npos);
  ASSERT_EQ(j["bvh"].size(), 1u);
  EXPECT_EQ(j["bvh"][0]["width"], 2);
}

// The images materials use, as packed: RGBA8, 4 bytes a texel. DamagedHelmet's material uses
// four of its five textures (wavepath reads no occlusion texture), each a 2048 x 2048 image.
TEST_F(InfoCli, ImagesAsPacked) {
  WP_REQUIRE_MODEL(path, "DamagedHelmet/DamagedHelmet.glb");
  const FileCounts f = read_file(path);
  const tinygltf::Material& m = f.model.materials.at(0);
  std::vector<int> used = {m.pbrMetallicRoughness.baseColorTexture.index,
                           m.pbrMetallicRoughness.metallicRoughnessTexture.index,
                           m.normalTexture.index, m.emissiveTexture.index};
  const json j = info(path, "--no-bvh-build");
  ASSERT_EQ(j["images"].size(), used.size());
  for (std::size_t i = 0; i < used.size(); ++i) {
    const tinygltf::Image& image = f.model.images[f.model.textures[used[i]].source];
    EXPECT_EQ(j["images"][i]["width"], image.width);
    EXPECT_EQ(j["images"][i]["height"], image.height);
    EXPECT_EQ(j["images"][i]["bytes"], 4 * image.width * image.height);
  }
  EXPECT_EQ(j["bvh"][0]["source"], "estimate");
  EXPECT_EQ(j["bvh"][0]["exact"], false);
}

// A file requiring an extension wavepath lacks: the extensions on stdout, then one error line.
TEST_F(InfoCli, RefusedFileStillListsItsExtensions) {
  std::ofstream(dir_ / "avif.gltf")
      << R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[]}],)"
      << R"("extensionsUsed":["EXT_texture_avif","KHR_materials_clearcoat"],)"
      << R"("extensionsRequired":["EXT_texture_avif"]})";
  const CliRun r = run("info avif.gltf --json");
  expect_one_line_error(r, "requires unsupported extension EXT_texture_avif");
  const json j = json::parse(r.out);
  EXPECT_EQ(j["loaded"], false);
  ASSERT_EQ(j["extensions"].size(), 2u);
  EXPECT_EQ(j["extensions"][0]["status"], "refused");
  EXPECT_EQ(j["extensions"][0]["required"], true);
  EXPECT_EQ(j["extensions"][1]["status"], "supported");
  const CliRun text = run("info avif.gltf");
  EXPECT_EQ(text.status, 1);
  EXPECT_NE(text.out.find("refused"), std::string::npos) << text.out;
}

TEST_F(InfoCli, Errors) {
  expect_one_line_error(run("info nope.gltf"), "nope.gltf: no such file");
  std::ofstream(dir_ / "notes.gltf") << "# not glTF";
  expect_one_line_error(run("info notes.gltf"), "notes.gltf");
  expect_one_line_error(run("info '" + cornell() + "' --width 0"), "--width");
  expect_one_line_error(run("info '" + cornell() + "' --variant red"), "no material variant");
  expect_one_line_error(run("info '" + cornell() + "' --bvh-width 4"), "--bvh-width");
  expect_one_line_error(run("info"), "scene");
  for (const auto& e : fs::directory_iterator(dir_))
    EXPECT_TRUE(e.path().filename() == "notes.gltf") << "left behind: " << e.path();
}

// Each camera info lists is the one render --camera takes at that index; one past is an error.
TEST_F(InfoCli, CameraIndicesMatchRender) {
  WP_REQUIRE_MODEL(path, "Cameras/Cameras.gltf");
  const json j = info(path, "--no-bvh-build");
  expect_counts(j, read_file(path));
  ASSERT_EQ(j["cameras"].size(), 2u);  // the asset's README: a perspective and an orthographic
  EXPECT_EQ(j["cameras"][0]["type"], "perspective");
  EXPECT_EQ(j["cameras"][1]["type"], "orthographic");
  const std::string render = "render '" + path + "' --width 16 --height 16 --spp 1 -q -o c.pfm";
  EXPECT_EQ(run(render + " --camera 1").status, 0);
  expect_one_line_error(run(render + " --camera 2"), "the scene has 2 camera(s)");
}

// The memory figures are the render's; the cache state follows what a render stores, and info
// itself writes nothing.
TEST_F(InfoCli, MemoryAndCacheMatchRender) {
  const std::string size = "--width 64 --height 48";
  const json before = info(cornell(), size);
  EXPECT_FALSE(fs::exists(dir_ / "cache"));
  for (const json& b : before["bvh"]) {
    EXPECT_EQ(b["cache"], "absent");
    EXPECT_EQ(b["source"], "built");
    EXPECT_EQ(b["exact"], true);
  }
  const CliRun r =
      run("render '" + cornell() + "' " + size + " --bvh-width 8 --spp 1 -q --json -o out.pfm");
  ASSERT_EQ(r.status, 0) << r.err;
  const json rendered = json::parse(r.out);
  // The wave of the device the render ran on (a CPU device's fits its cache: auto_wave_paths).
  const json after =
      info(cornell(), size + " --device '" + rendered["device"].get<std::string>() + "'");
  const json& wide = after["bvh"][0];
  ASSERT_EQ(wide["width"], 8);
  EXPECT_EQ(wide["cache"], "valid");
  EXPECT_EQ(wide["source"], "cache");
  EXPECT_EQ(wide["cache_file_bytes"], fs::file_size(wide["cache_file"].get<std::string>()));
  EXPECT_EQ(after["bvh"][1]["cache"], "absent");  // the render built only its own layout
  EXPECT_EQ(wide["scene_bytes"], rendered["scene_bytes"]);
  EXPECT_EQ(wide["scene_bytes"], before["bvh"][0]["scene_bytes"]);
  EXPECT_EQ(after["bytes_per_path"], rendered["bytes_per_path"]);
  EXPECT_EQ(after["wave_paths"], rendered["wave_size"]);
  EXPECT_EQ(after["features"], rendered["features"]);
  // The lower bound is one.
  const json estimate = info(cornell(), size + " --no-bvh-build");
  EXPECT_EQ(estimate["bvh"][1]["source"], "estimate");
  EXPECT_LE(estimate["bvh"][1]["scene_bytes"], before["bvh"][1]["scene_bytes"]);
}

}  // namespace
