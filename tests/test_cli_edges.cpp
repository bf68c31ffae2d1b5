// Input at the edges, through the command line as users meet it: files that are not regular files
// (a FIFO with no writer, a folder, a device) named as a scene, buffer, image, environment map or
// film; outputs that cannot be written; an image the device cannot hold; values glTF allows but
// float32 cannot carry. Each is one line `wavepath: error: ...` and status 1 (or a render without
// a NaN), never a hang: every run has `timeout` before it, so that a hang fails (status 124)
// instead of blocking the suite.
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "host/film/image_io.h"
#include "tests/cli_run.h"

namespace fs = std::filesystem;

namespace {

using wp::test::CliRun;

constexpr const char* kTimeout = "timeout 60";

// One triangle (0,0,-1), (1,0,-1), (0,1,-1) facing +Z, seen by a camera at the origin; its buffer
// and image are the files named `bin` and `png` (empty: none).
std::string triangle_gltf(const std::string& bin, const std::string& png,
                          const std::string& material = "{}") {
  std::string s = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,1]}],)"
                  R"("nodes":[{"mesh":0},{"camera":0,"translation":[0.3,0.3,0]}],)"
                  R"("cameras":[{"type":"perspective","perspective":{"yfov":0.5,"znear":0.01}}],)"
                  R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":0}]}],)"
                  R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",)"
                  R"("min":[0,0,-1],"max":[1,1,-1]}],)"
                  R"("bufferViews":[{"buffer":0,"byteLength":36}],)"
                  R"("buffers":[{"byteLength":36,"uri":")" +
                  bin + R"("}],"materials":[)" + material + "]";
  if (!png.empty()) s += R"(,"textures":[{"source":0}],"images":[{"uri":")" + png + R"("}])";
  return s + "}";
}

void write_triangle_bin(const fs::path& path) {
  const float p[9] = {0, 0, -1, 1, 0, -1, 0, 1, -1};
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(p), sizeof p);
}

class EdgeCli : public wp::test::FolderTest {
 protected:
  CliRun run(const std::string& args, const std::string& env = kTimeout) {
    return wp::test::run_wavepath(dir_, args, env);
  }

  // Status 1 and exactly one line on stderr, `wavepath: error: ` and then text containing `cause`.
  static void expect_error(const CliRun& r, const std::string& cause, const std::string& what) {
    EXPECT_EQ(r.status, 1) << what << ": " << r.err;
    EXPECT_EQ(r.err.rfind("wavepath: error: ", 0), 0u) << what << ": " << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << what << ": more than one line: " << r.err;
    EXPECT_NE(r.err.find(cause), std::string::npos) << what << ": " << r.err;
  }

  // Makes `name` in the folder a file of `kind`: a FIFO (no writer ever comes), a folder, or a
  // symbolic link to the character device /dev/zero (which never ends).
  void make_special(const std::string& name, const std::string& kind) {
    const fs::path p = dir_ / name;
    if (kind == "FIFO")
      ASSERT_EQ(::mkfifo(p.c_str(), 0644), 0);
    else if (kind == "directory")
      fs::create_directories(p);
    else
      fs::create_symlink("/dev/zero", p);
  }

  // The folder's entries other than those named in `keep`.
  std::vector<std::string> left_behind(const std::vector<std::string>& keep) const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(dir_)) {
      const std::string name = e.path().filename().string();
      if (std::find(keep.begin(), keep.end(), name) == keep.end()) out.push_back(name);
    }
    return out;
  }
};

const std::vector<std::pair<std::string, std::string>> kSpecialKinds = {
    {"FIFO", "a FIFO"}, {"directory", "a directory"}, {"device", "a character device"}};

// A scene, its buffer or image, an environment map or a film that is a FIFO, a folder or a device
// is refused at once, naming the file and what it is. (Before: a FIFO blocked open() forever and
// --env on one said "no such file".)
TEST_F(EdgeCli, NonRegularInputFilesAreRefusedAtOnce) {
  write_triangle_bin(dir_ / "tri.bin");
  std::ofstream(dir_ / "good.gltf") << triangle_gltf("tri.bin", "");
  ASSERT_EQ(run("info good.gltf").status, 0);  // the scene itself loads
  for (const auto& [kind, says] : kSpecialKinds) {
    const std::string cause = ": not a regular file (" + says + ")";
    const std::string s = "s_" + kind;
    make_special(s + ".gltf", kind);
    expect_error(run("info " + s + ".gltf"), s + ".gltf" + cause, kind + " scene");
    expect_error(run("render " + s + ".gltf -o out.exr"), s + ".gltf" + cause, kind + " scene");
    make_special(s + ".bin", kind);
    std::ofstream(dir_ / (s + "_buffer.gltf")) << triangle_gltf(s + ".bin", "");
    expect_error(run("info " + s + "_buffer.gltf"), s + ".bin" + cause, kind + " buffer");
    make_special(s + ".png", kind);
    std::ofstream(dir_ / (s + "_image.gltf")) << triangle_gltf("tri.bin", s + ".png");
    expect_error(run("info " + s + "_image.gltf"), s + ".png" + cause, kind + " image");
    for (const char* ext : {".hdr", ".exr"}) {
      make_special(s + ext, kind);
      expect_error(run("render good.gltf -o out.exr --env " + s + ext), s + ext + cause,
                   kind + " environment map");
    }
    make_special(s + ".wpfilm", kind);
    expect_error(run("merge " + s + ".wpfilm -o out.exr"), s + ".wpfilm" + cause, kind + " film");
    expect_error(run("render good.gltf -o out.exr --resume " + s + ".wpfilm"),
                 s + ".wpfilm" + cause, kind + " film to resume");
  }
  EXPECT_FALSE(fs::exists(dir_ / "out.exr"));
}

// An output that cannot be created is refused before rendering, whatever the reason, and as root
// too (where access(2) says yes): a folder that does not exist, a pseudo file system (/proc), a
// path that is a folder. Nothing is left behind and an output the user had is not overwritten.
TEST_F(EdgeCli, UnwritableOutputsAreRefusedBeforeRendering) {
  write_triangle_bin(dir_ / "tri.bin");
  std::ofstream(dir_ / "good.gltf") << triangle_gltf("tri.bin", "");
  std::ofstream(dir_ / "keep.exr") << "old";
  fs::create_directories(dir_ / "folder.exr");
  const std::string render = "render good.gltf --width 8 --height 8 --spp 1 --json -o keep.exr ";
  const std::string proc = "/proc/wavepath_edges_" + std::to_string(::getpid()) + ".exr";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"-o nowhere/out.png", "nowhere/out.png: folder nowhere does not exist"},
      {"-o " + proc, proc + ": folder /proc is not writable"},
      {"-o folder.exr", "folder.exr: is a directory"},
      {"--checkpoint " + proc.substr(0, proc.size() - 4) + ".wpfilm",
       "folder /proc is not writable"}};
  for (const auto& [args, cause] : cases) {
    const CliRun r = run(render + args);
    expect_error(r, cause, args);
    EXPECT_EQ(r.out, "") << args;  // no JSON report: nothing was rendered
    EXPECT_EQ(wp::test::slurp(dir_ / "keep.exr"), "old") << args;
    EXPECT_EQ(left_behind({"good.gltf", "tri.bin", "keep.exr", "folder.exr"}),
              std::vector<std::string>{})
        << args;
  }
  EXPECT_FALSE(fs::exists(proc));
}

// An image whose film the device cannot allocate is refused before any allocation, with the bytes
// it needs and the device's limit, not with OpenCL's CL_INVALID_BUFFER_SIZE. (PoCL's largest
// buffer is far below the 24 GiB of a 16384 x 16384 film; so is any GPU's today.)
TEST_F(EdgeCli, ImageTheDeviceCannotHoldIsRefusedWithBothSizes) {
  write_triangle_bin(dir_ / "tri.bin");
  std::ofstream(dir_ / "good.gltf") << triangle_gltf("tri.bin", "");
  const CliRun r = run("render good.gltf --width 16384 --height 16384 --spp 1 -o out.exr");
  expect_error(r,
               "image too large for the device: 16384 x 16384 needs a film buffer of 25769803776 "
               "bytes (24.00 GiB), more than the ",
               "16384 x 16384");
  EXPECT_NE(r.err.find("(CL_DEVICE_MAX_MEM_ALLOC_SIZE)"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out.exr"));
}

// A mesh placed by many nodes is a copy per node when flattened (--instancing off): 10^5 nodes
// placing one mesh of 10^5 triangles are 10^10 triangles, which no machine this runs on holds
// (their least packed size alone is 200 GB: 16 bytes of vertex references and 4 of light slot a
// triangle, before the BVH; `info`, which packs nothing, needs 160 GB to load them). The scene is
// refused from its counts, before its geometry is loaded: one line naming the triangles and
// placements, and the process never grows beyond the parsed file (the loaded triangles' indices
// alone would be 120 GB). The file is 3.6 MB of zero positions and 3.8 MB of JSON.
TEST_F(EdgeCli, SceneTooLargeFromItsPlacementsIsRefusedBeforeLoading) {
  constexpr int kNodes = 100000, kTriangles = 100000;
  const std::size_t bytes = std::size_t{3} * kTriangles * 3 * sizeof(float);
  {
    const std::vector<char> zeros(bytes, 0);
    std::ofstream(dir_ / "mesh.bin", std::ios::binary).write(zeros.data(), std::streamsize(bytes));
  }
  std::ofstream f(dir_ / "forest.gltf");
  f << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[)";
  for (int i = 0; i < kNodes; ++i) f << (i ? "," : "") << i;
  f << R"(]}],"nodes":[)";
  for (int i = 0; i < kNodes; ++i)
    f << (i ? "," : "") << R"({"mesh":0,"translation":[)" << i << ",0,0]}";
  f << R"(],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
    << R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" << 3 * kTriangles
    << R"(,"type":"VEC3","min":[0,0,0],"max":[0,0,0]}],)"
    << R"("bufferViews":[{"buffer":0,"byteLength":)" << bytes << R"(}],)"
    << R"("buffers":[{"byteLength":)" << bytes << R"(,"uri":"mesh.bin"}]})";
  f.close();
  // Flattened (--instancing off; by default its placements are instances of the mesh).
  const CliRun r =
      run("render forest.gltf --instancing off --width 64 --height 48 --spp 1 -o out.exr");
  expect_error(r, "scene too large: its 10000000000 triangles (100000 mesh placements, ",
               "placements");
  EXPECT_FALSE(fs::exists(dir_ / "out.exr"));
  // `wavepath info` packs nothing, but loading alone would take 160 GB: refused the same way.
  expect_error(run("info forest.gltf --instancing off"),
               "scene too large: its 10000000000 triangles (", "info");
  rusage usage{};
  ASSERT_EQ(::getrusage(RUSAGE_CHILDREN, &usage), 0);
  EXPECT_LT(usage.ru_maxrss, 1024L * 1024L) << "peak resident size of a child, KiB";
}

// Quads, one primitive each: (corner, edge u, edge v, material). Written as `name`.gltf with its
// buffer `name`.bin beside it, a camera at (0, 0.8, 3.5) looking down -Z and a point light.
struct Quad {
  float p[3], u[3], v[3];
  int material;
};

std::string quads_gltf(const fs::path& dir, const std::string& name, const std::vector<Quad>& quads,
                       const std::string& materials, const std::string& light,
                       const std::string& textures = "") {
  std::vector<float> data;
  std::string views, accessors, primitives;
  for (std::size_t q = 0; q < quads.size(); ++q) {
    const Quad& k = quads[q];
    const float w[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    const std::size_t offset = data.size() * 4;
    for (const int c : {0, 1, 2, 0, 2, 3})
      for (int i = 0; i < 3; ++i) {
        const float x = k.p[i] + w[c][0] * k.u[i] + w[c][1] * k.v[i];
        data.push_back(x);
        lo[i] = std::min(lo[i], x);
        hi[i] = std::max(hi[i], x);
      }
    const std::string n = std::to_string(q), sep = q ? "," : "";
    views += sep + R"({"buffer":0,"byteOffset":)" + std::to_string(offset) + R"(,"byteLength":72})";
    accessors += sep + R"({"bufferView":)" + n +
                 R"(,"componentType":5126,"count":6,"type":"VEC3",)" + R"("min":[)" +
                 std::to_string(lo[0]) + "," + std::to_string(lo[1]) + "," + std::to_string(lo[2]) +
                 R"(],"max":[)" + std::to_string(hi[0]) + "," + std::to_string(hi[1]) + "," +
                 std::to_string(hi[2]) + "]}";
    primitives += sep + R"({"attributes":{"POSITION":)" + n + R"(,"TEXCOORD_0":)" +
                  std::to_string(quads.size() + q) + R"(},"material":)" +
                  std::to_string(k.material) + "}";
  }
  // Every quad's texture coordinates: its corners' (u, v) weights, after all the positions.
  for (std::size_t q = 0; q < quads.size(); ++q) {
    const std::size_t offset = data.size() * 4;
    const float uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (const int c : {0, 1, 2, 0, 2, 3}) {
      data.push_back(uv[c][0]);
      data.push_back(uv[c][1]);
    }
    views += R"(,{"buffer":0,"byteOffset":)" + std::to_string(offset) + R"(,"byteLength":48})";
    accessors += R"(,{"bufferView":)" + std::to_string(quads.size() + q) +
                 R"(,"componentType":5126,"count":6,"type":"VEC2"})";
  }
  std::ofstream(dir / (name + ".bin"), std::ios::binary)
      .write(reinterpret_cast<const char*>(data.data()), std::streamsize(data.size() * 4));
  std::ofstream(dir / (name + ".gltf"))
      << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,1,2]}],)"
      << R"("nodes":[{"mesh":0},{"camera":0,"translation":[0,0.8,3.5]},)"
      << R"({"translation":[0.5,1,1],"extensions":{"KHR_lights_punctual":{"light":0}}}],)"
      << R"("cameras":[{"type":"perspective","perspective":{"yfov":0.8,"znear":0.01}}],)"
      << R"("meshes":[{"primitives":[)" << primitives << "]}],"
      << R"("accessors":[)" << accessors << R"(],"bufferViews":[)" << views << "],"
      << R"("buffers":[{"byteLength":)" << data.size() * 4 << R"(,"uri":")" << name << R"(.bin"}],)"
      << R"("extensionsUsed":["KHR_materials_emissive_strength","KHR_materials_ior",)"
      << R"("KHR_materials_transmission","KHR_materials_volume","KHR_lights_punctual",)"
      << R"("KHR_materials_dispersion","KHR_materials_iridescence","KHR_materials_specular",)"
      << R"("KHR_materials_anisotropy","KHR_materials_clearcoat","KHR_texture_transform"],)"
      << R"("materials":[)" << materials << "]," << textures
      << R"("extensions":{"KHR_lights_punctual":{"lights":[)" << light << "]}}}";
  return name + ".gltf";
}

// A Radiance .hdr of 8 x 4 flat RGBE pixels, each (m, m, m) x 2^(e - 136).
void write_hdr(const fs::path& path, unsigned char m, unsigned char e) {
  std::ofstream out(path, std::ios::binary);
  out << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 8\n";
  for (int i = 0; i < 32; ++i) out << m << m << m << e;
}

// Values glTF allows that float32 cannot carry through the transport: an emissive strength of
// 3.4e38 (x emissiveFactor), an ior of 1e39 (beyond float32: read as FLT_MAX), a light of
// intensity 1e38, an attenuationDistance of 1e-38 and an environment map of texels 1.7e38 (RGBE's
// largest). Clamped on load (to 2^64 radiance and an ior of 2^16, scene.h), each with one warning
// naming the element; the render drops no sample as NaN/Inf and its image is finite. Before:
// 1584 of 49152 samples were NaN/Inf without the map, tens of thousands with it.
TEST_F(EdgeCli, ValuesBeyondFloat32AreClampedAndRenderFinite) {
  const std::string materials =
      R"({"doubleSided":true},)"
      R"({"emissiveFactor":[1,0.5,1],"extensions":{"KHR_materials_emissive_strength":)"
      R"({"emissiveStrength":3.4e38}}},)"
      R"({"doubleSided":true,"pbrMetallicRoughness":{"roughnessFactor":0.2},"extensions":{)"
      R"("KHR_materials_ior":{"ior":1e39},"KHR_materials_transmission":{"transmissionFactor":1},)"
      R"("KHR_materials_volume":{"thicknessFactor":1}}},)"
      R"({"doubleSided":true,"extensions":{"KHR_materials_transmission":{"transmissionFactor":1},)"
      R"("KHR_materials_volume":{"thicknessFactor":1,"attenuationDistance":1e-38,)"
      R"("attenuationColor":[0.5,0.9,0.1]}}},)"
      R"({"doubleSided":true,"pbrMetallicRoughness":{"metallicFactor":1,"roughnessFactor":0.05}})";
  const std::vector<Quad> quads = {{{-2, 0, 2}, {4, 0, 0}, {0, 0, -4}, 0},
                                   {{-0.3f, 1.5f, 0.3f}, {0, 0, -0.6f}, {0.6f, 0, 0}, 1},
                                   {{-1, 0.2f, 0.5f}, {1, 0, 0}, {0, 1, 0}, 2},
                                   {{0, 0.2f, 0.6f}, {1, 0, 0}, {0, 1, 0}, 3},
                                   {{-2, 0, -1.5f}, {4, 0, 0}, {0, 2, 0}, 4}};
  const std::string scene = quads_gltf(dir_, "extreme", quads, materials,
                                       R"({"type":"point","color":[1,1,0.5],"intensity":1e38})");
  write_hdr(dir_ / "sky.hdr", 255, 255);
  const CliRun r =
      run("render " + scene + " --env sky.hdr --width 64 --height 48 --spp 16 --json -o out.exr");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(wp::test::json_number(r.out, "nonfinite_samples"), 0) << r.out;
  EXPECT_EQ(r.err.find("NaN"), std::string::npos) << r.err;
  for (const char* warning :
       {"wavepath: warning: extreme.gltf: material 1 '': emission 3.4e+38 clamped to 1.84467e+19",
        "wavepath: warning: extreme.gltf: material 2 '': ior 3.40282e+38 clamped to 65536",
        "wavepath: warning: extreme.gltf: light 0 '': intensity 1e+38 clamped to 1.84467e+19",
        "wavepath: warning: sky.hdr: 32 texels above 1.84467e+19 (the brightest 1.69477e+38) "
        "clamped to it"})
    EXPECT_NE(r.err.find(warning), std::string::npos) << warning << "\n" << r.err;
  const wp::ImageRgb image = wp::read_exr((dir_ / "out.exr").string());
  ASSERT_EQ(image.rgb.size(), 64u * 48u * 3u);
  for (const float v : image.rgb) ASSERT_TRUE(std::isfinite(v) && v >= 0.0f) << v;

  // Options are not clamped but refused: a map at the limit cannot be made brighter, nor can the
  // background exceed it.
  expect_error(
      run("render " + scene + " --env sky.hdr --env-intensity 2 -o out.exr"),
      "--env-intensity 2: the map's brightest texel (1.84467e+19) times it must be at most",
      "--env-intensity");
  expect_error(run("render " + scene + " --env-color 1e30,0,0 -o out.exr"),
               "--env-color must be at most the most radiance wavepath carries", "--env-color");
}

// Every number the material extensions leave unbounded, at 1e30 and at float32's largest (and
// beyond it, 1e39, read as FLT_MAX): dispersion, the volume's thickness and attenuation distance,
// the thin film's thicknesses and index, the specular colour, the anisotropy's rotation, the
// normal and coat normal textures' scales, a texture transform's offset, rotation and scale, and a
// point light's range. Each scene renders with no NaN/Inf sample and a finite, non-negative image;
// the dispersion is clamped with a warning (a dispersion of 1e30 put NaN samples in the film).
TEST_F(EdgeCli, ExtensionValuesAtTheirEdgesRenderFinite) {
  wp::ImageRgb texels;
  texels.width = texels.height = 4;
  for (int i = 0; i < 16; ++i)
    texels.rgb.insert(texels.rgb.end(), {0.1f * float(i % 4), 0.9f, 0.5f});
  wp::write_images({(dir_ / "t.png").string()}, texels, {});
  const std::string textures = R"("images":[{"uri":"t.png"}],"textures":[{"source":0}],)";
  for (const std::string v : {"1e30", "3.4e38", "1e39"}) {
    SCOPED_TRACE(v);
    const std::string volume = R"("KHR_materials_transmission":{"transmissionFactor":1},)"
                               R"("KHR_materials_volume":{"thicknessFactor":)" +
                               v + "}";
    const std::string materials =
        R"({"doubleSided":true},)"
        // 1, 2: dispersion over a common and the largest index
        R"({"doubleSided":true,"extensions":{)" +
        volume +
        R"(,"KHR_materials_dispersion":)"
        R"({"dispersion":)" +
        v +
        "}}},"
        R"({"doubleSided":true,"extensions":{)" +
        volume + R"(,"KHR_materials_ior":{"ior":)" + v +
        R"(},"KHR_materials_dispersion":{"dispersion":)" + v +
        "}}},"
        // 3: a thin film of any thickness and index
        R"({"doubleSided":true,"extensions":{"KHR_materials_iridescence":{"iridescenceFactor":1,)"
        R"("iridescenceIor":)" +
        v + R"(,"iridescenceThicknessMinimum":)" + v + R"(,"iridescenceThicknessMaximum":)" + v +
        R"(,"iridescenceThicknessTexture":)"
        R"({"index":0}}}},)"
        // 4: the specular colour over a transmitting and an opaque base
        R"({"doubleSided":true,"extensions":{"KHR_materials_specular":{"specularColorFactor":[)" +
        v + "," + v + "," + v +
        R"(]},"KHR_materials_transmission":{"transmissionFactor":0.5}}},)"
        // 5: anisotropy at any rotation, with a normal map of any scale
        R"({"doubleSided":true,"normalTexture":{"index":0,"scale":)" +
        v +
        R"(},"pbrMetallicRoughness":{"roughnessFactor":0.3},"extensions":{)"
        R"("KHR_materials_anisotropy":{"anisotropyStrength":1,"anisotropyRotation":)" +
        v +
        "}}},"
        // 6: a coat with a normal map of any scale
        R"({"doubleSided":true,"extensions":{"KHR_materials_clearcoat":{"clearcoatFactor":1,)"
        R"("clearcoatNormalTexture":{"index":0,"scale":)" +
        v +
        "}}}},"
        // 7: a texture transform of any offset, rotation and scale
        R"({"doubleSided":true,"pbrMetallicRoughness":{"baseColorTexture":{"index":0,)"
        R"("extensions":{"KHR_texture_transform":{"offset":[)" +
        v + "," + v + R"(],"rotation":)" + v + R"(,"scale":[)" + v + "," + v +
        R"(]}}}}},)"
        // 8: a volume that attenuates over any distance
        R"({"doubleSided":true,"extensions":{"KHR_materials_transmission":{"transmissionFactor":1},)"
        R"("KHR_materials_volume":{"thicknessFactor":1,"attenuationDistance":)" +
        v + R"(,"attenuationColor":[0.5,0.9,0.1]}}})";
    std::vector<Quad> quads = {{{-2, 0, 2}, {4, 0, 0}, {0, 0, -4}, 0}};
    for (int m = 1; m <= 8; ++m) {
      const float x = -1.6f + 0.8f * float((m - 1) % 4), y = m <= 4 ? 0.1f : 0.9f;
      quads.push_back({{x, y, 0.5f}, {0.7f, 0, 0}, {0, 0.7f, 0}, m});
    }
    const std::string scene = quads_gltf(
        dir_, "edge", quads, materials,
        R"({"type":"point","color":[1,1,1],"intensity":20,"range":)" + v + "}", textures);
    const CliRun r = run("render " + scene + " --width 64 --height 48 --spp 16 --json -o out.exr");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(wp::test::json_number(r.out, "nonfinite_samples"), 0) << r.out;
    EXPECT_NE(r.err.find("wavepath: warning: edge.gltf: material 1 '': dispersion"),
              std::string::npos)
        << r.err;
    const wp::ImageRgb image = wp::read_exr((dir_ / "out.exr").string());
    ASSERT_EQ(image.rgb.size(), 64u * 48u * 3u);
    for (const float c : image.rgb) ASSERT_TRUE(std::isfinite(c) && c >= 0.0f) << c;
  }
}

}  // namespace

// Compressed data wavepath cannot read: a texture whose only image is KTX2 (KHR_texture_basisu, no
// decoder in Debian) and a meshopt stream that does not decode. One line naming the cause, status
// 1, nothing written.
TEST_F(EdgeCli, CompressedDataThatCannotBeReadIsOneError) {
  write_triangle_bin(dir_ / "tri.bin");
  std::string basisu = triangle_gltf("tri.bin", "",
                                     R"({"pbrMetallicRoughness":)"
                                     R"({"baseColorTexture":{"index":0}}})");
  basisu.pop_back();  // the closing brace: the texture, its KTX2 image, the extension's lists
  basisu +=
      R"(,"textures":[{"extensions":{"KHR_texture_basisu":{"source":0}}}],)"
      R"("images":[{"uri":"t.ktx2","mimeType":"image/ktx2"}],)"
      R"("extensionsUsed":["KHR_texture_basisu"],"extensionsRequired":["KHR_texture_basisu"]})";
  std::ofstream(dir_ / "t.ktx2") << "\xabKTX 20\xbb\r\n\x1a\n";
  std::ofstream(dir_ / "basisu.gltf") << basisu;
  expect_error(
      run("render basisu.gltf -o out.exr"),
      "texture 0: KHR_texture_basisu (KTX2) images cannot be decoded and the texture has no "
      "fallback source",
      "KTX2 only");
  // tri.bin as a meshopt ATTRIBUTES stream: its first byte is not the codec's header (0xa0).
  std::string meshopt = triangle_gltf("tri.bin", "");
  const std::string view = R"("bufferViews":[{"buffer":0,"byteLength":36}])";
  meshopt.replace(meshopt.find(view), view.size(),
                  R"("bufferViews":[{"buffer":1,"byteLength":36,"byteStride":12,"extensions":)"
                  R"({"EXT_meshopt_compression":{"buffer":0,"byteLength":36,"byteStride":12,)"
                  R"("count":3,"mode":"ATTRIBUTES"}}}])");
  const std::string buffers = R"("buffers":[{"byteLength":36,"uri":"tri.bin"}])";
  meshopt.replace(meshopt.find(buffers), buffers.size(),
                  R"("buffers":[{"byteLength":36,"uri":"tri.bin"},{"byteLength":36,)"
                  R"("extensions":{"EXT_meshopt_compression":{"fallback":true}}}],)"
                  R"("extensionsUsed":["EXT_meshopt_compression"],)"
                  R"("extensionsRequired":["EXT_meshopt_compression"])");
  std::ofstream(dir_ / "meshopt.gltf") << meshopt;
  expect_error(run("render meshopt.gltf -o out.exr"),
               "bufferView 0 EXT_meshopt_compression: corrupt ATTRIBUTES data", "meshopt");
  EXPECT_EQ(left_behind({"tri.bin", "t.ktx2", "basisu.gltf", "meshopt.gltf"}),
            std::vector<std::string>{});
}
