// Compressed glTF (host/scene/gltf_meshopt.cpp, gltf_draco.cpp, gltf_textures.cpp): twins of the
// shared models written at test time with the codecs' encoders (tests/gltf/compress_twin.h) load
// as their originals do, within the quantisation the encoder applied (each tolerance is derived
// beside its assertion); and malformed compressed data is one wp::Error, never a crash.
#include <cstring>
#include <functional>

#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

#include "host/util/error.h"
#include "tests/gltf/compressed_scenes.h"

namespace {

using namespace wp::test;              // NOLINT(google-build-using-namespace)
using namespace wp::test::compressed;  // NOLINT(google-build-using-namespace)
using nlohmann::json;

const auto* const kCleanup = ::testing::AddGlobalTestEnvironment(new gltf_files::TempCleanup);
using gltf_files::expect_error;

std::string stem(const std::string& path) {
  return fs::path(path).stem().string();
}

// The largest |coordinate| of any POSITION accessor (their min and max, which glTF requires).
double max_abs_position(const Glb& glb) {
  const json doc = json::parse(glb.json);
  double m = 0.0;
  for (const json& mesh : doc["meshes"])
    for (const json& prim : mesh["primitives"]) {
      const json& a = doc["accessors"][prim["attributes"]["POSITION"].get<std::size_t>()];
      for (const char* k : {"min", "max"})
        for (const json& v : a[k]) m = std::max(m, std::abs(v.get<double>()));
    }
  return m;
}

// Loads `path`: true when it loaded, false for a wp::Error (anything else fails the test).
bool loads(const std::string& path) {
  try {
    wp::load_gltf(path);
    return true;
  } catch (const wp::Error&) {
    return false;
  }
}

// Meshopt's codecs are lossless and keep the order of elements and triangles (a triangle may start
// at another corner): every triangle equal, bit for bit.
TEST(CompressedTwins, MeshoptIsExact) {
  const std::vector<std::string> models = twin_models();
  if (models.empty()) GTEST_SKIP() << "no shared models under " << assets_dir();
  for (const std::string& path : models) {
    const wp::Scene original = wp::load_gltf(path);
    const wp::Scene twin =
        wp::load_gltf(write_twin(meshopt_twin(read_glb(path)), stem(path) + "_meshopt.glb"));
    EXPECT_EQ(twin.triangle_count(), original.triangle_count()) << path;
    EXPECT_EQ(unmatched(original, twin, Tolerance{}), 0u) << path;
    EXPECT_EQ(twin.images.size(), original.images.size()) << path;
  }
}

// With filters: positions EXPONENTIAL with K mantissa bits: each element's components share the
// exponent of the largest, |v| < 2^e, mantissas of K bits (1 sign) make the unit 2^(e - K + 1) and
// rounding errs by half of it, 2^(e - K) <= |v|max 2^(1 - K) per component (|v|max >= 2^(e-1)):
// sqrt(3) |v|max 2^(1 - K) in length, times the placement's norm in world space. Normals
// OCTAHEDRAL with K-bit x, y (step h = 1 / (2^(K-1) - 1), each off by h / 2): the octahedron's
// point p moves by |(dx, dy, |dx| + |dy|)| <= h sqrt(1.5) and |p| >= 1 / sqrt(3), so the unit
// vector by at most sqrt(3) sqrt(1.5) h = 2.13 h; stored as 16-bit normalized integers (half a
// unit, 1 / 65534, per component); the loader's renormalisation at most doubles an error.
TEST(CompressedTwins, MeshoptFiltersWithinQuantisation) {
  const std::vector<std::string> models = twin_models();
  if (models.empty()) GTEST_SKIP() << "no shared models under " << assets_dir();
  MeshoptFilters filters;
  filters.on = true;
  filters.octahedral_bits = 12;
  filters.exponential_bits = 16;
  for (const std::string& path : models) {
    const Glb glb = read_glb(path);
    const wp::Scene original = wp::load_gltf(path);
    const wp::Scene twin =
        wp::load_gltf(write_twin(meshopt_twin(glb, filters), stem(path) + "_meshopt_f.glb"));
    Tolerance tol;
    tol.position = std::sqrt(3.0) * max_abs_position(glb) *
                       std::ldexp(1.0, 1 - filters.exponential_bits) * placement_norm(path) +
                   1e-6;
    const double h = 1.0 / ((1 << (filters.octahedral_bits - 1)) - 1);
    tol.normal = 2.0 * (2.13 * h + std::sqrt(3.0) / 65534.0);
    EXPECT_EQ(unmatched(original, twin, tol), 0u)
        << path << ": position tolerance " << tol.position << ", normal " << tol.normal;
  }
}

// Draco quantises each attribute on a grid over its bounding box: step = the largest extent /
// (2^q - 1), each component off by at most half a step (positions: sqrt(3) step / 2 in length,
// times the placement's norm in world space; texture coordinates step / 2 per component). Normals
// are octahedral with q bits over [-1, 1] (step h = 2 / (2^q - 2)): 2.13 h as above, doubled for
// renormalisation. A float32 rounding of a few ulps of the extent is added.
TEST(CompressedTwins, DracoWithinQuantisation) {
  const std::vector<std::string> models = twin_models();
  if (models.empty()) GTEST_SKIP() << "no shared models under " << assets_dir();
  for (const bool edgebreaker : {true, false}) {
    DracoBits bits;
    bits.edgebreaker = edgebreaker;
    for (const std::string& path : models) {
      DracoSteps steps;
      const Glb twin_glb = draco_twin(read_glb(path), bits, &steps);
      const wp::Scene original = wp::load_gltf(path);
      const wp::Scene twin = wp::load_gltf(
          write_twin(twin_glb, stem(path) + (edgebreaker ? "_draco_eb.glb" : "_draco_seq.glb")));
      const double step = *std::max_element(steps.position.begin(), steps.position.end());
      const double step_uv = *std::max_element(steps.texcoord.begin(), steps.texcoord.end());
      Tolerance tol;
      tol.position = std::sqrt(3.0) * step / 2.0 * placement_norm(path) * (1.0 + 1e-4) + 1e-6;
      tol.uv = step_uv / 2.0 * (1.0 + 1e-4) + 1e-6;
      tol.normal = 2.0 * 2.13 * 2.0 / ((1 << bits.normal) - 2);
      EXPECT_EQ(unmatched(original, twin, tol), 0u)
          << path << (edgebreaker ? " (edgebreaker)" : " (sequential)") << ": position tolerance "
          << tol.position << ", uv " << tol.uv << ", normal " << tol.normal;
    }
  }
}

// Lossless WebP keeps every texel (exact RGBA); the geometry is the original's.
TEST(CompressedTwins, WebpTexelsEqual) {
  std::size_t textured = 0;
  for (const std::string& path : twin_models()) {
    const wp::Scene original = wp::load_gltf(path);
    // Models with images up to 1024 x 1024 (lossless WebP of DamagedHelmet's 2048 x 2048 maps
    // takes seconds).
    if (original.images.empty() ||
        std::any_of(original.images.begin(), original.images.end(),
                    [](const wp::Image& i) { return i.width * i.height > 1024 * 1024; }))
      continue;
    ++textured;
    const wp::Scene twin =
        wp::load_gltf(write_twin(webp_twin(read_glb(path)), stem(path) + "_webp.glb"));
    ASSERT_EQ(twin.images.size(), original.images.size()) << path;
    for (std::size_t i = 0; i < original.images.size(); ++i) {
      EXPECT_EQ(twin.images[i].width, original.images[i].width) << path << " image " << i;
      EXPECT_EQ(twin.images[i].height, original.images[i].height) << path << " image " << i;
      EXPECT_TRUE(twin.images[i].rgba == original.images[i].rgba) << path << " image " << i;
    }
    EXPECT_EQ(unmatched(original, twin, Tolerance{}), 0u) << path;
  }
  if (textured == 0) GTEST_SKIP() << "no textured shared models under " << assets_dir();
}

// ---------------------------------------------------------------------------------------------
// Malformed compressed data. A unit quad (positions, normals, texture coordinates, 16-bit
// indices) built here, compressed by the twin writers, then broken.

Glb quad() {
  const float pos[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const float nrm[] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  const float uv[] = {0, 1, 1, 1, 1, 0, 0, 0};
  const std::uint16_t idx[] = {0, 1, 2, 0, 2, 3};
  Glb g;
  const auto add = [&](const void* data, std::size_t size) {
    const std::size_t at = g.bin.size();
    g.bin.insert(g.bin.end(), static_cast<const unsigned char*>(data),
                 static_cast<const unsigned char*>(data) + size);
    return json{{"buffer", 0}, {"byteOffset", at}, {"byteLength", size}};
  };
  json doc = {{"asset", {{"version", "2.0"}}},
              {"scene", 0},
              {"scenes", {{{"nodes", {0}}}}},
              {"nodes", {{{"mesh", 0}}}}};
  doc["bufferViews"] = {add(pos, sizeof pos), add(nrm, sizeof nrm), add(uv, sizeof uv),
                        add(idx, sizeof idx)};
  doc["accessors"] = {
      {{"bufferView", 0},
       {"componentType", 5126},
       {"count", 4},
       {"type", "VEC3"},
       {"min", {0, 0, 0}},
       {"max", {1, 1, 0}}},
      {{"bufferView", 1}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}},
      {{"bufferView", 2}, {"componentType", 5126}, {"count", 4}, {"type", "VEC2"}},
      {{"bufferView", 3}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}}};
  doc["meshes"] = {
      {{"primitives",
        {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}, {"TEXCOORD_0", 2}}}, {"indices", 3}}}}}};
  doc["buffers"] = {{{"byteLength", g.bin.size()}}};
  g.json = doc.dump();
  return g;
}

// `glb` with its JSON changed by `edit` (and its binary chunk by `edit_bin`), written as NAME.
std::string broken(
    const Glb& glb, const std::string& name, const std::function<void(json&)>& edit,
    const std::function<void(std::vector<unsigned char>&, const json&)>& edit_bin = nullptr) {
  Glb out = glb;
  json doc = json::parse(glb.json);
  edit(doc);
  if (edit_bin) edit_bin(out.bin, doc);
  out.json = doc.dump();
  return write_twin(out, name);
}

json& meshopt_ext(json& doc, std::size_t view) {
  return doc["bufferViews"][view]["extensions"]["EXT_meshopt_compression"];
}

TEST(CompressedEdges, QuadTwinsLoad) {
  const wp::Scene q = wp::load_gltf(write_twin(quad(), "quad.glb"));
  ASSERT_EQ(q.triangle_count(), 2u);
  for (const Glb& twin : {meshopt_twin(quad()), draco_twin(quad(), DracoBits{}), webp_twin(quad())})
    EXPECT_EQ(
        unmatched(q, wp::load_gltf(write_twin(twin, "quad_twin.glb")), Tolerance{1e-3, 1e-2, 1e-3}),
        0u);
}

TEST(CompressedEdges, MeshoptStreamsThatLie) {
  const Glb m = meshopt_twin(quad());
  // View 0 (POSITION): 4 elements of 12 bytes.
  expect_error(broken(m, "mo_trunc.glb",
                      [](json& d) {
                        json& e = meshopt_ext(d, 0);
                        e["byteLength"] = e["byteLength"].get<int>() / 2;
                      }),
               "corrupt ATTRIBUTES data");
  expect_error(broken(
                   m, "mo_header.glb", [](json&) {},
                   [](std::vector<unsigned char>& bin, const json& d) {
                     bin[d["bufferViews"][0]["extensions"]["EXT_meshopt_compression"]["byteOffset"]
                             .get<std::size_t>()] ^= 0xff;
                   }),
               "corrupt ATTRIBUTES data");
  expect_error(broken(m, "mo_count.glb",
                      [](json& d) {
                        meshopt_ext(d, 0)["count"] = 1000000;
                        d["bufferViews"][0]["byteLength"] = 12000000;
                      }),
               "cannot decode from");
  expect_error(broken(m, "mo_count100.glb",
                      [](json& d) {
                        meshopt_ext(d, 0)["count"] = 100;
                        d["bufferViews"][0]["byteLength"] = 1200;
                      }),
               "exceed buffer 1");  // the fallback buffer's byteLength cannot hold them
  expect_error(broken(m, "mo_count100_room.glb",
                      [](json& d) {
                        meshopt_ext(d, 0)["count"] = 100;
                        d["bufferViews"][0]["byteLength"] = 1200;
                        d["buffers"][1]["byteLength"] = 100000;
                      }),
               "corrupt ATTRIBUTES data");  // the stream has data for 4
  expect_error(broken(m, "mo_length.glb", [](json& d) { d["bufferViews"][0]["byteLength"] = 36; }),
               "is not EXT_meshopt_compression's count x byteStride");
  expect_error(broken(m, "mo_stride.glb",
                      [](json& d) {
                        meshopt_ext(d, 0)["byteStride"] = 6;
                        d["bufferViews"][0].erase("byteStride");
                        d["bufferViews"][0]["byteLength"] = 24;
                      }),
               "divisible by 4");
  expect_error(
      broken(m, "mo_range.glb", [](json& d) { meshopt_ext(d, 0)["byteOffset"] = 1u << 30; }),
      "exceed buffer 0");
  expect_error(broken(m, "mo_fallback.glb", [](json& d) { meshopt_ext(d, 0)["buffer"] = 1; }),
               "fallback buffer without data");
  expect_error(broken(m, "mo_mode.glb", [](json& d) { meshopt_ext(d, 0)["mode"] = "ZIP"; }),
               "mode 'ZIP'");
  expect_error(
      broken(m, "mo_filter.glb", [](json& d) { meshopt_ext(d, 3)["filter"] = "OCTAHEDRAL"; }),
      "take no filter");
  // The index stream cut at every length: an error or a load, nothing else.
  const json doc = json::parse(m.json);
  const int length = doc["bufferViews"][3]["extensions"]["EXT_meshopt_compression"]["byteLength"];
  for (int cut = 0; cut < length; ++cut)
    loads(broken(m, "mo_cut.glb", [&](json& d) { meshopt_ext(d, 3)["byteLength"] = cut; }));
}

// The primitive's Draco data: the bufferView the extension names.
std::size_t draco_view(const json& d) {
  return d["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["bufferView"];
}

// The Draco header's counts are checked before Draco decodes (Draco allocates from them: a fuzzed
// 232-byte payload of version 1.1 asked for 2.56 GB): the bitstream version the extension
// specifies (2.2), no more faces than the indices accessor holds triangles, no more points than
// the attributes' accessors or the faces' corners. The header (the Draco bitstream specification):
// "DRACO", major, minor, encoder type, method (0 sequential: faces, points as varints at 11 and
// 12; 1 edgebreaker: traversal type at 11, encoded vertices, faces), 2 bytes of flags. The quad's
// counts (4 points, 2 faces) take one byte each.
TEST(CompressedEdges, DracoHeaderCountsAreCheckedBeforeDecoding) {
  const Glb m = draco_twin(quad(), DracoBits{});
  const json doc = json::parse(m.json);
  const std::size_t at = doc["bufferViews"][draco_view(doc)]["byteOffset"];
  ASSERT_EQ(std::string(m.bin.begin() + long(at), m.bin.begin() + long(at) + 5), "DRACO");
  const int method = m.bin[at + 8];
  ASSERT_TRUE(method == 0 || method == 1) << method;
  const std::size_t faces = at + (method == 0 ? 11 : 13), points = at + (method == 0 ? 12 : 12);
  ASSERT_EQ(m.bin[faces], 2);
  ASSERT_EQ(m.bin[points], 4);
  const auto patch = [&](const char* name, std::size_t byte, unsigned char value) {
    return broken(
        m, name, [](json&) {},
        [=](std::vector<unsigned char>& bin, const json&) { bin[byte] = value; });
  };
  expect_error(patch("dr_v11.glb", at + 5, 1), "Draco bitstream version 1.2");
  expect_error(patch("dr_faces.glb", faces, 0x7f), "announces 127 faces, more than");
  expect_error(patch("dr_points.glb", points, 5), "announces 5 points, more than accessor");
  expect_error(patch("dr_magic.glb", at, 'X'), "no DRACO signature");
}

// A Draco primitive's accessors hold no data before it is decoded: what they claim is counted
// before anything is decoded, so a scene claiming more than the device holds is refused first
// (check_counts throws) and Draco never sees it.
TEST(CompressedEdges, DracoClaimsAreCountedBeforeDecoding) {
  const Glb m = draco_twin(quad(), DracoBits{});
  const std::string path = broken(m, "dr_claim.glb", [](json& d) {
    const std::size_t a = d["meshes"][0]["primitives"][0]["indices"];
    d["accessors"][a]["count"] = 3000000000u;
  });
  wp::LoadOptions options;
  std::uint64_t seen = 0;
  options.check_counts = [&](const wp::LoadCounts& c) {
    seen = c.stored_triangles();
    throw wp::Error("refused from its counts");
  };
  try {
    wp::load_gltf(path, options);
    ADD_FAILURE() << "loaded";
  } catch (const wp::Error& e) {
    EXPECT_NE(std::string(e.what()).find("refused from its counts"), std::string::npos) << e.what();
  }
  EXPECT_EQ(seen, 1000000000u);
  // Accepted (no check), the header's 2 faces are within the claim; the decoded mesh then
  // differs from it.
  expect_error(path, "differs from the decoded 6");
}

TEST(CompressedEdges, DracoDataThatLies) {
  const Glb m = draco_twin(quad(), DracoBits{});
  expect_error(broken(m, "dr_trunc.glb",
                      [](json& d) {
                        json& v = d["bufferViews"][draco_view(d)];
                        v["byteLength"] = v["byteLength"].get<int>() / 2;
                      }),
               "KHR_draco_mesh_compression");
  expect_error(broken(m, "dr_count.glb",
                      [](json& d) {
                        const std::size_t a =
                            d["meshes"][0]["primitives"][0]["attributes"]["POSITION"];
                        d["accessors"][a]["count"] = 5;
                      }),
               "differs from the decoded 4 points");
  expect_error(broken(m, "dr_indices.glb",
                      [](json& d) {
                        const std::size_t a = d["meshes"][0]["primitives"][0]["indices"];
                        d["accessors"][a]["count"] = 9;
                      }),
               "differs from the decoded 6");
  expect_error(broken(m, "dr_id.glb",
                      [](json& d) {
                        d["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]
                         ["attributes"]["POSITION"] = 99;
                      }),
               "no attribute 99");
  expect_error(broken(m, "dr_type.glb",
                      [](json& d) {
                        const std::size_t a =
                            d["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"];
                        d["accessors"][a]["type"] = "VEC3";
                      }),
               "has 3 components, the Draco attribute 2");
  expect_error(
      broken(m, "dr_mode.glb", [](json& d) { d["meshes"][0]["primitives"][0]["mode"] = 1; }),
      "Draco primitives are TRIANGLES");
  // Every truncation and every byte flipped: an error or a load, nothing else.
  const json doc = json::parse(m.json);
  const json& view = doc["bufferViews"][draco_view(doc)];
  const std::size_t at = view["byteOffset"], length = view["byteLength"];
  for (std::size_t cut = 0; cut < length; ++cut)
    loads(broken(m, "dr_cut.glb",
                 [&](json& d) { d["bufferViews"][draco_view(d)]["byteLength"] = cut; }));
  for (std::size_t i = 0; i < length; ++i)
    loads(broken(
        m, "dr_flip.glb", [](json&) {},
        [&](std::vector<unsigned char>& bin, const json&) { bin[at + i] ^= 0x5a; }));
}

// A texture whose image is WebP. `image` replaces the image's bytes.
std::string textured_quad(const std::string& name, const std::vector<unsigned char>& image,
                          const json& texture) {
  Glb g = quad();
  json doc = json::parse(g.json);
  while (g.bin.size() % 4) g.bin.push_back(0);
  doc["bufferViews"].push_back(
      {{"buffer", 0}, {"byteOffset", g.bin.size()}, {"byteLength", image.size()}});
  g.bin.insert(g.bin.end(), image.begin(), image.end());
  doc["buffers"][0]["byteLength"] = g.bin.size();
  doc["images"] = {{{"bufferView", doc["bufferViews"].size() - 1}, {"mimeType", "image/webp"}}};
  doc["textures"] = {texture};
  doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  doc["meshes"][0]["primitives"][0]["material"] = 0;
  doc["extensionsUsed"] = {"EXT_texture_webp", "KHR_texture_basisu"};
  doc["extensionsRequired"] = {"EXT_texture_webp", "KHR_texture_basisu"};
  g.json = doc.dump();
  return write_twin(g, name);
}

const std::vector<unsigned char> kTexels = {255, 0, 0,   255, 0,   255, 0,   255,
                                            0,   0, 255, 255, 255, 255, 255, 128};

json webp_texture(int source) {
  return {{"extensions", {{"EXT_texture_webp", {{"source", source}}}}}};
}

TEST(CompressedEdges, WebpImages) {
  const std::vector<unsigned char> webp = webp_lossless(kTexels.data(), 2, 2);
  // EXT_texture_webp's source, no fallback `source` (the extension is required): the texels.
  const wp::Scene s = wp::load_gltf(textured_quad("webp_ok.glb", webp, webp_texture(0)));
  ASSERT_EQ(s.images.size(), 1u);
  EXPECT_TRUE(s.images[0].rgba == kTexels);
  expect_error(textured_quad("webp_source.glb", webp, webp_texture(7)), "image 7 does not exist");
  // Cut at every length: an error naming the image, never a partial image.
  for (std::size_t cut = 0; cut < webp.size(); ++cut) {
    const std::vector<unsigned char> part(webp.begin(), webp.begin() + std::ptrdiff_t(cut));
    EXPECT_FALSE(loads(textured_quad("webp_cut.glb", part, webp_texture(0)))) << cut;
  }
  // A VP8X header with the animation flag (RIFF, WEBP, VP8X chunk of 10 bytes: flags 0x02, 3
  // reserved bytes, canvas width - 1 and height - 1 in 24 bits each): refused in one line.
  std::vector<unsigned char> anim = {'R',  'I', 'F', 'F', 22,  0,   0,  0, 'W', 'E',
                                     'B',  'P', 'V', 'P', '8', 'X', 10, 0, 0,   0,
                                     0x02, 0,   0,   0,   1,   0,   0,  1, 0,   0};
  expect_error(textured_quad("webp_anim.glb", anim, webp_texture(0)), "animated");
  // Found by fuzz_webp: 18 bytes that stb_image, the decoder before libpng and libjpeg, read as a
  // 4608 x 47698 TGA (no signature), 880 MB filled for seconds. Only PNG, JPEG and WebP are
  // decoded, each recognised by its signature.
  const std::vector<unsigned char> tga = {0, 0, 2, 0x3a, 0,    0x7a, 0,    0,    0,
                                          0, 0, 0, 0,    0x12, 0x52, 0xba, 0x10, 0x7c};
  expect_error(textured_quad("tga.glb", tga, webp_texture(0)), "not a PNG, JPEG or WebP image");
  // Found by fuzz_webp: a JPEG whose Huffman table counts 2,204 codes; Debian's stb_image wrote
  // them past its 257-entry arrays (UBSan). libjpeg refuses a table of more than 256 codes.
  const std::vector<unsigned char> dht = {
      0xff, 0xd8, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xc4, 0x43, 0x31,
      0x00, 0x30, 0x60, 0x00, 0x00, 0xe0, 0x00, 0x00, 0x00, 0xff, 0xff, 0xff, 0xff, 0x33,
      0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xfe, 0x27, 0xff, 0xff, 0x00, 0x01};
  expect_error(textured_quad("dht.glb", dht, webp_texture(0)),
               "cannot decode the JPEG: Bogus Huffman table definition");
  std::vector<unsigned char> junk = webp;
  for (std::size_t i = 12; i < junk.size(); ++i) junk[i] = static_cast<unsigned char>(i * 37);
  EXPECT_FALSE(loads(textured_quad("webp_junk.glb", junk, webp_texture(0))));
}

// KHR_texture_basisu: KTX2 is not decoded; the texture's fallback `source` is used, and a texture
// in use without one is an error naming the extension.
TEST(CompressedEdges, BasisuUsesTheFallbackOrFails) {
  const std::vector<unsigned char> webp = webp_lossless(kTexels.data(), 2, 2);
  const json basisu = {{"extensions", {{"KHR_texture_basisu", {{"source", 0}}}}}};
  expect_error(textured_quad("basisu_none.glb", webp, basisu),
               "texture 0: KHR_texture_basisu (KTX2) images cannot be decoded and the texture has "
               "no fallback source");
  json with_fallback = basisu;
  with_fallback["source"] = 0;
  const wp::Scene s = wp::load_gltf(textured_quad("basisu_fallback.glb", webp, with_fallback));
  ASSERT_EQ(s.images.size(), 1u);
  EXPECT_TRUE(s.images[0].rgba == kTexels);
}

}  // namespace
