// Seeds for the compressed-data fuzz targets, made by compressing models with the codecs' own
// encoders (tests/gltf/compress_twin.h), so nothing binary is committed:
//
//   make_compressed_seeds OUT_DIR [ASSETS_DIR]
//
// writes OUT_DIR/gltf/twin_*.glb (whole compressed twins for fuzz_gltf, when under 64 KB),
// OUT_DIR/draco/, OUT_DIR/meshopt/ and OUT_DIR/webp/ (the payloads with the headers
// tests/fuzz/fuzz_compressed.cpp reads), and OUT_DIR/image/: JPEGs (grey, RGB and CMYK, baseline
// and progressive) and a lossless WebP for fuzz_image. Always a built-in quad; with ASSETS_DIR
// (../shared/assets), also Box, BoxTextured, Duck and DamagedHelmet's compressed data.
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/gltf/compress_twin.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using wp::test::Glb;

constexpr std::size_t kMaxSeed = 64 * 1024;

void put_u32(std::vector<unsigned char>& out, std::uint32_t v) {
  const auto* p = reinterpret_cast<const unsigned char*>(&v);
  out.insert(out.end(), p, p + 4);
}

std::vector<unsigned char> view_bytes(const Glb& g, const json& doc, std::size_t view) {
  const json& v = doc["bufferViews"][view];
  const std::size_t at = v.value("byteOffset", std::size_t{0}), n = v["byteLength"];
  return {g.bin.begin() + std::ptrdiff_t(at), g.bin.begin() + std::ptrdiff_t(at + n)};
}

void seed(const fs::path& dir, const std::string& name, const std::vector<unsigned char>& bytes) {
  if (bytes.size() > kMaxSeed) return;
  fs::create_directories(dir);
  wp::test::write_file((dir / name).string(), bytes);
}

// The payloads of the twins of `g`, named after `name`.
void seeds_of(const Glb& g, const std::string& name, const fs::path& out) {
  seed(out / "gltf", "twin_" + name + "_meshopt.glb",
       wp::test::glb_bytes(wp::test::meshopt_twin(g)));
  wp::test::MeshoptFilters filters;
  filters.on = true;
  const Glb mf = wp::test::meshopt_twin(g, filters);
  seed(out / "gltf", "twin_" + name + "_meshopt_filters.glb", wp::test::glb_bytes(mf));
  const json mdoc = json::parse(mf.json);
  for (std::size_t v = 0; v < mdoc["bufferViews"].size(); ++v) {
    const json& view = mdoc["bufferViews"][v];
    if (!view.contains("extensions")) continue;
    const json& e = view["extensions"]["EXT_meshopt_compression"];
    const std::string mode = e["mode"], filter = e.value("filter", "NONE");
    std::vector<unsigned char> s = {static_cast<unsigned char>(mode == "ATTRIBUTES"  ? 0
                                                               : mode == "TRIANGLES" ? 1
                                                                                     : 2),
                                    static_cast<unsigned char>(filter == "OCTAHEDRAL"    ? 1
                                                               : filter == "QUATERNION"  ? 2
                                                               : filter == "EXPONENTIAL" ? 3
                                                                                         : 0),
                                    static_cast<unsigned char>(e["byteStride"].get<int>()), 0};
    put_u32(s, e["count"]);
    const std::size_t at = e["byteOffset"], n = e["byteLength"];
    s.insert(s.end(), mf.bin.begin() + std::ptrdiff_t(at), mf.bin.begin() + std::ptrdiff_t(at + n));
    seed(out / "meshopt", name + "_view" + std::to_string(v) + ".bin", s);
  }
  for (const bool edgebreaker : {true, false}) {
    wp::test::DracoBits bits;
    bits.edgebreaker = edgebreaker;
    const Glb d = wp::test::draco_twin(g, bits);
    const std::string kind = edgebreaker ? "_eb" : "_seq";
    seed(out / "gltf", "twin_" + name + "_draco" + kind + ".glb", wp::test::glb_bytes(d));
    const json doc = json::parse(d.json);
    for (std::size_t m = 0; m < doc["meshes"].size(); ++m) {
      const json& p = doc["meshes"][m]["primitives"][0];
      if (!p.contains("extensions")) continue;
      const json& e = p["extensions"]["KHR_draco_mesh_compression"];
      std::vector<unsigned char> s;
      put_u32(s, doc["accessors"][p["attributes"]["POSITION"].get<std::size_t>()]["count"]);
      put_u32(s, doc["accessors"][p["indices"].get<std::size_t>()]["count"]);
      for (const char* a : {"POSITION", "NORMAL", "TEXCOORD_0"})
        s.push_back(static_cast<unsigned char>(e["attributes"].value(a, 255)));
      s.push_back(0);
      const std::vector<unsigned char> data = view_bytes(d, doc, e["bufferView"]);
      s.insert(s.end(), data.begin(), data.end());
      seed(out / "draco", name + "_mesh" + std::to_string(m) + kind + ".bin", s);
    }
  }
  const json doc = json::parse(g.json);
  if (!doc.contains("images") || doc["images"].empty()) return;
  const Glb w = wp::test::webp_twin(g);
  seed(out / "gltf", "twin_" + name + "_webp.glb", wp::test::glb_bytes(w));
  const json wdoc = json::parse(w.json);
  for (std::size_t i = 0; i < wdoc["images"].size(); ++i)
    seed(out / "webp", name + "_image" + std::to_string(i) + ".webp",
         view_bytes(w, wdoc, wdoc["images"][i]["bufferView"]));
}

// A unit quad: the built-in seed (its texture seed is a WebP made in main).
Glb quad() {
  const float data[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 0,
                        0, 1, 0, 0, 1, 0, 0, 1, 0, 1, 1, 1, 1, 0, 0, 0};
  const std::uint16_t idx[] = {0, 1, 2, 0, 2, 3};
  Glb g;
  g.bin.assign(reinterpret_cast<const unsigned char*>(data),
               reinterpret_cast<const unsigned char*>(data) + sizeof data);
  g.bin.insert(g.bin.end(), reinterpret_cast<const unsigned char*>(idx),
               reinterpret_cast<const unsigned char*>(idx) + sizeof idx);
  g.bin.resize(g.bin.size() + 2);
  json doc = json::parse(R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],
    "nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0,"NORMAL":1,
    "TEXCOORD_0":2},"indices":3}]}],"accessors":[
    {"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
    {"bufferView":1,"componentType":5126,"count":4,"type":"VEC3"},
    {"bufferView":2,"componentType":5126,"count":4,"type":"VEC2"},
    {"bufferView":3,"componentType":5123,"count":6,"type":"SCALAR"}],"bufferViews":[
    {"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":48},
    {"buffer":0,"byteOffset":96,"byteLength":32},{"buffer":0,"byteOffset":128,"byteLength":12}],
    "buffers":[{"byteLength":144}]})");
  g.json = doc.dump();
  return g;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: make_compressed_seeds OUT_DIR [ASSETS_DIR]\n");
    return 2;
  }
  const fs::path out = argv[1];
  try {
    seeds_of(quad(), "quad", out);
    const unsigned char texels[] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 9, 9, 9, 128};
    seed(out / "webp", "quad.webp", wp::test::webp_lossless(texels, 2, 2));
    seed(out / "image", "quad.webp", wp::test::webp_lossless(texels, 2, 2));
    for (const int components : {1, 3, 4})
      for (const bool progressive : {false, true}) {
        std::vector<unsigned char> samples;
        for (int i = 0; i < 24 * 16 * components; ++i)
          samples.push_back(static_cast<unsigned char>(i * 37 % 251));
        seed(out / "image",
             "jpeg" + std::to_string(components) + (progressive ? "_progressive" : "") + ".jpg",
             wp::test::jpeg_encode(samples, 24, 16, components, progressive));
      }
    // An earlier finding's shape: a baseline JPEG whose frame header claims 16000 x 16000 pixels
    // over a few hundred bytes (a decoder that trusts it allocates 1 GiB before reading the scan).
    std::vector<unsigned char> big =
        wp::test::jpeg_encode(std::vector<unsigned char>(24 * 16, 9), 24, 16, 1, false);
    for (std::size_t i = 0; i + 8 < big.size(); ++i)
      if (big[i] == 0xff && big[i + 1] == 0xc0) {  // SOF0: length, precision, height, width
        big[i + 5] = big[i + 7] = 16000 >> 8;
        big[i + 6] = big[i + 8] = 16000 & 0xff;
        break;
      }
    seed(out / "image", "jpeg_claims_16000.jpg", big);
    if (argc > 2) {
      for (const char* m : {"Box/Box.glb", "BoxTextured/BoxTextured.glb", "Duck/Duck.glb",
                            "DamagedHelmet/DamagedHelmet.glb"}) {
        const fs::path path = fs::path(argv[2]) / "models" / m;
        if (!fs::exists(path)) continue;
        const Glb g = wp::test::read_glb(path.string());
        // DamagedHelmet's 2048 x 2048 maps would make megabyte WebP seeds: only its meshes.
        if (std::string(m).rfind("Damaged", 0) == 0) {
          json doc = json::parse(g.json);
          doc.erase("images");
          doc.erase("textures");
          doc.erase("materials");
          for (json& mesh : doc["meshes"])
            for (json& p : mesh["primitives"]) p.erase("material");
          Glb bare = g;
          bare.json = doc.dump();
          seeds_of(bare, path.stem().string(), out);
        } else {
          seeds_of(g, path.stem().string(), out);
        }
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_compressed_seeds: %s\n", e.what());
    return 1;
  }
  return 0;
}
