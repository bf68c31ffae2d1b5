// glTF loader, gltf_textures.cpp: images, samplers, texture slots and KHR_texture_transform; errors
// naming the element; corrupted textured .glb files. Image decoding (image_decode.cpp): PNGs of
// every colour type and bit depth written here from the specification, JPEGs from libjpeg's
// compressor, broken files. Shared fixture: tests/gltf/gltf_files.h.
#include <cstdio>  // before jpeglib.h
#include <cstdlib>

#include <jpeglib.h>
#include <zlib.h>

#include "tests/gltf/compress_twin.h"
#include "tests/gltf/gltf_files.h"

namespace {

using namespace wp::test::gltf_files;  // NOLINT(google-build-using-namespace)

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
               "image 0 'junk': not a PNG, JPEG or WebP image");
  expect_error(
      with("[{\"source\":0}]", base0, R"("images":[{"uri":"nowhere.png"}])").write("t6.gltf"),
      "image 0 (nowhere.png): no image data");
  // Images decode together once the materials are read (on all hardware threads); of several
  // that cannot, the error names the first one used (base colour before emission), whichever
  // thread got to it.
  expect_error(with("[{\"source\":1},{\"source\":0}]",
                    R"({"pbrMetallicRoughness":{"baseColorTexture":{"index":0}},)"
                    R"("emissiveTexture":{"index":1}})",
                    R"("images":[{"name":"junk0","uri":"data:image/png;base64,AAAAAAAA"},)"
                    R"({"name":"junk1","uri":"data:image/png;base64,AAAAAAAA"}])")
                   .write("t7-two.gltf"),
               "image 1 'junk1': not a PNG, JPEG or WebP image");
  // PNGs that claim more than there is. stb_image_write writes the signature (8 bytes), IHDR (25;
  // width at 16, height at 20, CRC at 29, made anew here), then IDAT (its length at 33). An IDAT
  // claiming 1.9 GB in a 42 KB file made the decoder before libpng allocate 2 GiB (fuzzing);
  // libpng reads it in pieces, to the end of the data. A size that deflate's 1,032-fold expansion
  // of the rest of the file cannot reach is refused before the texels are allocated.
  const auto patched_png = [](std::size_t at, std::uint32_t value) {
    std::vector<unsigned char> png = encode_png(2, 2, kImage0);
    const auto put = [&](std::size_t to, std::uint32_t v) {
      for (std::size_t i = 0; i < 4; ++i)
        png[to + i] = static_cast<unsigned char>(v >> (24 - 8 * i));
    };
    put(at, value);
    put(29, static_cast<std::uint32_t>(crc32(0, &png[12], 17)));
    return R"("images":[{"uri":"data:image/png;base64,)" + base64(png) + R"("}])";
  };
  expect_error(with("[{\"source\":0}]", base0, patched_png(33, 0x6f71d329u)).write("t8.gltf"),
               "image 0: cannot decode the PNG: the data ends early (truncated)");
  expect_error(with("[{\"source\":0}]", base0, patched_png(16, 60000)).write("t9.gltf"),
               "bytes cannot hold its");
  // A JPEG whose frame header claims 16000 x 16000 pixels in a few hundred bytes is refused
  // before the texels are allocated (1 GiB); the same file at its own 2 x 2 loads.
  const auto patched_jpeg = [](int w, int h) {
    std::vector<unsigned char> jpeg = encode_jpeg(2, 2, kImage0);
    for (std::size_t i = 2; i + 8 < jpeg.size(); ++i)
      if (jpeg[i] == 0xff && jpeg[i + 1] == 0xc0) {  // SOF0: length, precision, height, width
        jpeg[i + 5] = static_cast<unsigned char>(h >> 8),
                 jpeg[i + 6] = static_cast<unsigned char>(h);
        jpeg[i + 7] = static_cast<unsigned char>(w >> 8),
                 jpeg[i + 8] = static_cast<unsigned char>(w);
        break;
      }
    return R"("images":[{"uri":"data:image/jpeg;base64,)" + base64(jpeg) + R"("}])";
  };
  expect_error(with("[{\"source\":0}]", base0, patched_jpeg(16000, 16000)).write("t11.gltf"),
               "cannot hold its 16000 x 16000 pixels");
  EXPECT_EQ(wp::load_gltf(with("[{\"source\":0}]", base0, patched_jpeg(2, 2)).write("t12.gltf"))
                .images.at(0)
                .width,
            2);
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
// Image decoding (image_decode.cpp) through the loader: image 0, named "img", of a textured square.

std::string image_gltf(const std::vector<unsigned char>& bytes, const std::string& mime,
                       const std::string& file) {
  Gltf g = textured_square({0});
  g.top = R"("images":[{"name":"img","uri":"data:)" + mime + ";base64," + base64(bytes) +
          R"("}],"textures":[{"source":0}])";
  g.materials = {R"({"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}})"};
  return g.write(file);
}

wp::Image loaded_image(const std::vector<unsigned char>& bytes, const std::string& mime,
                       const std::string& file) {
  return wp::load_gltf(image_gltf(bytes, mime, file)).images.at(0);
}

// A PNG written here from the specification (ISO/IEC 15948), with zlib for the compressed stream
// and the chunks' CRCs: the decoder is checked against the format, not against its own library's
// writer. Every row has filter type 0 (None); the image data is split over two IDAT chunks.
struct PngSpec {
  int width = 0, height = 0, color = 0, depth = 8;  // IHDR's colour type and bit depth
  bool adam7 = false;
  std::vector<unsigned> samples;       // width x height x channels, rows top down, `depth` bits
  std::vector<unsigned char> palette;  // PLTE: 3 bytes an entry
  std::vector<unsigned char> trns;     // tRNS as stored: alpha bytes, or 16-bit grey / RGB values
  bool gamma = false;                  // gAMA (1/2.2) and sRGB chunks, which must change no texel
};

int png_channels(int color) {
  return color == 2 ? 3 : color == 4 ? 2 : color == 6 ? 4 : 1;
}

void put_u32(std::vector<unsigned char>& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8)
    out.push_back(static_cast<unsigned char>(v >> shift));
}

void put_chunk(std::vector<unsigned char>& png, const char* type,
               const std::vector<unsigned char>& data) {
  put_u32(png, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = png.size();
  png.insert(png.end(), type, type + 4);
  png.insert(png.end(), data.begin(), data.end());
  put_u32(png, static_cast<std::uint32_t>(
                   crc32(0, png.data() + start, static_cast<uInt>(png.size() - start))));
}

std::vector<unsigned char> spec_png(const PngSpec& p) {
  // The passes' first column and row and their steps: Adam7's seven, or the whole image.
  static const int kAdam7[7][4] = {{0, 0, 8, 8}, {4, 0, 8, 8}, {0, 4, 4, 8}, {2, 0, 4, 4},
                                   {0, 2, 2, 4}, {1, 0, 2, 2}, {0, 1, 1, 2}};
  static const int kWhole[1][4] = {{0, 0, 1, 1}};
  const int n = png_channels(p.color);
  std::vector<unsigned char> rows;
  for (int pass = 0; pass < (p.adam7 ? 7 : 1); ++pass) {
    const int* at = p.adam7 ? kAdam7[pass] : kWhole[0];
    if (at[0] >= p.width) continue;  // an empty pass has no rows, not even their filter bytes
    for (int y = at[1]; y < p.height; y += at[3]) {
      rows.push_back(0);  // filter type None
      unsigned bits = 0, count = 0;
      for (int x = at[0]; x < p.width; x += at[2])
        for (int c = 0; c < n; ++c) {
          const unsigned v =
              p.samples[(std::size_t(y) * std::size_t(p.width) + std::size_t(x)) * std::size_t(n) +
                        std::size_t(c)];
          if (p.depth == 16) {
            rows.push_back(static_cast<unsigned char>(v >> 8));
            rows.push_back(static_cast<unsigned char>(v));
          } else {  // packed from the high bit down, as the format has it
            bits = bits << p.depth | v;
            count += unsigned(p.depth);
            if (count == 8) {
              rows.push_back(static_cast<unsigned char>(bits));
              bits = count = 0;
            }
          }
        }
      if (count) rows.push_back(static_cast<unsigned char>(bits << (8 - count)));
    }
  }
  uLongf packed_size = compressBound(static_cast<uLong>(rows.size()));
  std::vector<unsigned char> packed(packed_size);
  EXPECT_EQ(compress2(packed.data(), &packed_size, rows.data(), static_cast<uLong>(rows.size()), 9),
            Z_OK);
  packed.resize(packed_size);

  std::vector<unsigned char> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::vector<unsigned char> ihdr;
  put_u32(ihdr, std::uint32_t(p.width));
  put_u32(ihdr, std::uint32_t(p.height));
  ihdr.insert(ihdr.end(), {static_cast<unsigned char>(p.depth), static_cast<unsigned char>(p.color),
                           0, 0, static_cast<unsigned char>(p.adam7)});
  put_chunk(png, "IHDR", ihdr);
  if (p.gamma) {
    put_chunk(png, "gAMA", {0, 0, 0xb1, 0x8f});  // 45455: 1/2.2
    put_chunk(png, "sRGB", {0});
  }
  if (!p.palette.empty()) put_chunk(png, "PLTE", p.palette);
  if (!p.trns.empty()) put_chunk(png, "tRNS", p.trns);
  const auto half = packed.begin() + std::ptrdiff_t(packed.size() / 2);
  put_chunk(png, "IDAT", {packed.begin(), half});
  put_chunk(png, "IDAT", {half, packed.end()});
  put_chunk(png, "IEND", {});
  return png;
}

// The texels the specification gives `p`, as 8-bit RGBA, as the loader promises them
// (image_decode.h): grey of 1, 2, 4 bits times 255, 85, 17 (filling the 8 bits with copies of
// the sample), 16-bit samples' high byte; a palette entry and its tRNS alpha (255 past the tRNS
// entries); alpha 0 where a grey or RGB pixel equals tRNS's value at the file's bit depth, else
// 255 (or the file's alpha).
std::vector<unsigned char> spec_texels(const PngSpec& p) {
  const int n = png_channels(p.color);
  const auto to8 = [&](unsigned v) {
    return static_cast<unsigned char>(p.depth == 16 ? v >> 8 : v * 255 / ((1u << p.depth) - 1));
  };
  const auto trns16 = [&](std::size_t i) {
    return unsigned(p.trns[2 * i]) << 8 | p.trns[2 * i + 1];
  };
  std::vector<unsigned char> out;
  for (std::size_t i = 0; i < std::size_t(p.width) * std::size_t(p.height); ++i) {
    const unsigned* s = &p.samples[i * std::size_t(n)];
    if (p.color == 3) {
      out.insert(out.end(), &p.palette[3 * s[0]], &p.palette[3 * s[0]] + 3);
      out.push_back(s[0] < p.trns.size() ? p.trns[s[0]] : 255);
      continue;
    }
    const bool rgb = p.color & 2, alpha = p.color & 4;
    for (int c = 0; c < 3; ++c) out.push_back(to8(s[rgb ? c : 0]));
    bool transparent = !p.trns.empty();
    for (int c = 0; c < (rgb ? 3 : 1) && transparent; ++c)
      transparent = s[c] == trns16(std::size_t(c));
    out.push_back(alpha ? to8(s[n - 1]) : transparent ? 0 : 255);
  }
  return out;
}

// Random samples for every pixel; with tRNS, a third of the pixels take its colour (transparent)
// and another third differ from it only in the lowest bit of one channel (opaque): for 16 bits
// that bit is in the low byte, so the comparison must be at the file's bit depth, before the 16
// bits are cut to 8.
PngSpec random_png(int color, int depth, bool adam7, bool trns, int width, int height,
                   std::mt19937& rng) {
  PngSpec p;
  p.width = width, p.height = height, p.color = color, p.depth = depth, p.adam7 = adam7;
  const int n = png_channels(color);
  const unsigned top = color == 3 ? (1u << depth) - (depth == 8 ? 56 : 0) : (1u << depth);
  for (std::size_t i = 0; i < std::size_t(width * height * n); ++i)
    p.samples.push_back(static_cast<unsigned>(rng() % top));
  if (color == 3) {
    for (unsigned i = 0; i < 3 * top; ++i) p.palette.push_back(static_cast<unsigned char>(rng()));
    if (trns)  // fewer alphas than entries: the rest are opaque
      for (unsigned i = 0; i < top / 2 + 1; ++i)
        p.trns.push_back(static_cast<unsigned char>(rng()));
  } else if (trns) {
    std::vector<unsigned> key(static_cast<std::size_t>(n));
    for (unsigned& k : key) k = static_cast<unsigned>(rng() % (1u << depth));
    for (const unsigned k : key)
      p.trns.insert(p.trns.end(),
                    {static_cast<unsigned char>(k >> 8), static_cast<unsigned char>(k)});
    for (std::size_t i = 0; i < std::size_t(width * height); ++i) {
      if (i % 3 == 2) continue;
      for (int c = 0; c < n; ++c)
        p.samples[i * std::size_t(n) + std::size_t(c)] = key[std::size_t(c)];
      if (i % 3 == 1) {  // off by one in the lowest bit of one channel
        unsigned& v = p.samples[i * std::size_t(n) + (i / 3) % std::size_t(n)];
        v ^= 1;
      }
    }
  }
  return p;
}

void expect_texels(const wp::Image& got, const PngSpec& p) {
  ASSERT_EQ(got.width, p.width);
  ASSERT_EQ(got.height, p.height);
  const std::vector<unsigned char> want = spec_texels(p);
  ASSERT_EQ(got.rgba.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i)
    ASSERT_EQ(int(got.rgba[i]), int(want[i])) << "texel " << i / 4 << ", channel " << i % 4;
}

// Every colour type at every bit depth it allows, plain and Adam7-interlaced, with and without
// tRNS where the type allows one, each texel as the specification gives it. gAMA and sRGB chunks
// on half of them change nothing: texels are the file's samples, not colour-managed.
TEST(GltfLoader, PngEveryColourTypeAndBitDepth) {
  struct Type {
    int color;
    std::vector<int> depths;
  };
  const Type types[] = {
      {0, {1, 2, 4, 8, 16}}, {2, {8, 16}}, {3, {1, 2, 4, 8}}, {4, {8, 16}}, {6, {8, 16}}};
  std::mt19937 rng(11);
  int count = 0;
  for (const Type& t : types)
    for (const int depth : t.depths)
      for (const bool adam7 : {false, true})
        for (const bool trns : {false, true}) {
          if (trns && (t.color & 4)) continue;  // types with alpha have no tRNS
          PngSpec p = random_png(t.color, depth, adam7, trns, 13, 11, rng);
          p.gamma = count % 2 == 1;
          const std::string name = "png_c" + std::to_string(t.color) + "_d" +
                                   std::to_string(depth) + (adam7 ? "_adam7" : "") +
                                   (trns ? "_trns" : "");
          SCOPED_TRACE(name);
          expect_texels(loaded_image(spec_png(p), "image/png", name + ".gltf"), p);
          ++count;
        }
  EXPECT_EQ(count, 52);
  // Adam7 on images smaller than its 8 x 8 tile: passes without pixels have no rows.
  for (const auto& [w, h] :
       std::vector<std::pair<int, int>>{{1, 1}, {2, 1}, {1, 5}, {3, 3}, {9, 9}}) {
    const PngSpec p = random_png(6, 8, true, false, w, h, rng);
    SCOPED_TRACE(std::to_string(w) + " x " + std::to_string(h));
    expect_texels(loaded_image(spec_png(p), "image/png", "png_small_adam7.gltf"), p);
  }
}

// A smooth image: each component a product of slow sines over 40 x 24 texels (the last block
// column and row partly outside the image).
std::vector<unsigned char> smooth_samples(int width, int height, int components) {
  std::vector<unsigned char> s;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < components; ++c)
        s.push_back(static_cast<unsigned char>(std::lround(
            127.5 + 110.0 * std::sin(0.15 * x + 0.9 * c) * std::cos(0.11 * y - 0.5 * c))));
  return s;
}

// Baseline and progressive JPEGs of a smooth image at quality 100, grey, RGB and CMYK, decode to
// within a bound derived from what the codec rounds, of the texels given to the encoder. At
// quality 100 every quantisation step is 1: each DCT coefficient is rounded by at most 1/2, and
// JPEG's 8 x 8 DCT is orthonormal, so a block's texel errors have the same Euclidean norm as its
// coefficients' errors, at most sqrt(64) / 2 = 4, which bounds each of them. libjpeg's integer
// DCTs (forward and inverse) are within 1 of the exact ones (IEEE 1180's peak error), and the
// result is rounded: a grey texel within 5. RGB goes through YCbCr (each rounded, so each within
// 5.5), and back: B = Y + 1.772 (Cb - 128) is within 5.5 x 2.772 + 1/2, the largest of the three:
// 15. CMYK (Adobe's, inverted) is stored as it is, each of c, k within 5; the texel is c k / 255,
// within 5 + 5 + 1/2: 10. And the mean error is below one code: rounding errors spread evenly over
// +-1/2 are noise of 1/sqrt(12) ~ 0.29 (and the orthonormal DCT keeps that), which B's 1.772 x Cb
// and its own rounding take to about 0.8 at most. (Measured: largest errors 1 grey, 4 RGB, 1
// CMYK; mean errors 0.06, 0.48, 0.06; progressive files the same as baseline ones.)
TEST(GltfLoader, JpegWithinItsRounding) {
  const int w = 40, h = 24;
  for (const int components : {1, 3, 4})
    for (const bool progressive : {false, true}) {
      const std::string name = "jpeg_" + std::to_string(components) + (progressive ? "_prog" : "");
      SCOPED_TRACE(name);
      const std::vector<unsigned char> samples = smooth_samples(w, h, components);
      const wp::Image got =
          loaded_image(wp::test::jpeg_encode(samples, w, h, components, progressive), "image/jpeg",
                       name + ".gltf");
      ASSERT_EQ(got.width, w);
      ASSERT_EQ(got.height, h);
      const int bound = components == 1 ? 5 : components == 3 ? 15 : 10;
      double error_sum = 0;
      for (std::size_t i = 0; i < std::size_t(w * h); ++i) {
        const unsigned char* s = &samples[i * std::size_t(components)];
        for (std::size_t c = 0; c < 3; ++c) {
          const int want = components == 1   ? s[0]
                           : components == 3 ? s[c]
                                             : int(std::lround(s[c] * s[3] / 255.0));
          const int error = std::abs(int(got.rgba[4 * i + c]) - want);
          ASSERT_LE(error, bound) << "texel " << i << ", channel " << c;
          error_sum += error;
        }
        ASSERT_EQ(got.rgba[4 * i + 3], 255) << "texel " << i;
      }
      EXPECT_LT(error_sum / (3.0 * w * h), 1.0);
    }
}

// Broken images are one wp::Error naming the image, never a crash or a partial image: every
// PNG and JPEG cut short (each proper prefix: libpng reads to IEND, libjpeg to EOI), a PNG whose
// data fails its CRC or has too few rows, JPEGs of an unsupported sample precision or with a
// progressive scan script past the 500 scans a texture may have. (A bad Huffman table:
// CompressedEdges.WebpImages.)
TEST(GltfLoader, BrokenPngAndJpegAreOneError) {
  std::mt19937 rng(5);
  const std::vector<unsigned char> png = spec_png(random_png(6, 8, false, false, 7, 5, rng));
  for (std::size_t cut = 1; cut < png.size(); ++cut)
    expect_error(
        image_gltf({png.begin(), png.begin() + std::ptrdiff_t(cut)}, "image/png", "png_cut.gltf"),
        cut < 8 ? "image 0 'img': not a PNG, JPEG or WebP image"
                : "image 0 'img': cannot decode the PNG: ");
  // The first IDAT's data starts after the signature (8), IHDR (25) and its own length and type.
  std::vector<unsigned char> bad = png;
  bad[29] ^= 1;  // IHDR's CRC (after the signature, IHDR's length, type and 13 bytes)
  expect_error(image_gltf(bad, "image/png", "png_crc.gltf"),
               "image 0 'img': cannot decode the PNG: IHDR: CRC error");
  bad = png;
  bad[8 + 25 + 8] ^= 0x20;  // IDAT's first byte, the zlib header (inflated before the CRC's read)
  expect_error(image_gltf(bad, "image/png", "png_zlib.gltf"),
               "image 0 'img': cannot decode the PNG: IDAT: incorrect header check");
  PngSpec p = random_png(2, 8, false, false, 7, 5, rng);
  p.height = 2;  // the rows of 2 texels' height, in an IHDR (its CRC made anew) claiming 5
  p.samples.resize(7 * 2 * 3);
  std::vector<unsigned char> short_data = spec_png(p);
  short_data[8 + 8 + 7] = 5;  // the height's low byte
  const auto crc = static_cast<std::uint32_t>(crc32(0, &short_data[8 + 4], 17));
  for (int i = 0; i < 4; ++i)
    short_data[8 + 21 + std::size_t(i)] = static_cast<unsigned char>(crc >> (24 - 8 * i));
  expect_error(image_gltf(short_data, "image/png", "png_short.gltf"),
               "image 0 'img': cannot decode the PNG: Not enough image data");

  const std::vector<unsigned char> jpeg =
      wp::test::jpeg_encode(smooth_samples(16, 8, 3), 16, 8, 3, false);
  for (std::size_t cut = 1; cut < jpeg.size(); ++cut)
    expect_error(image_gltf({jpeg.begin(), jpeg.begin() + std::ptrdiff_t(cut)}, "image/jpeg",
                            "jpeg_cut.gltf"),
                 cut < 3 ? "image 0 'img': not a PNG, JPEG or WebP image"
                         : "image 0 'img': cannot decode the JPEG: ");
  std::vector<unsigned char> precision = jpeg;
  for (std::size_t i = 2; i + 4 < precision.size(); ++i)
    if (precision[i] == 0xff && precision[i + 1] == 0xc0) {  // SOF0: length, then the precision
      precision[i + 4] = 12;
      break;
    }
  expect_error(image_gltf(precision, "image/jpeg", "jpeg_12bit.gltf"),
               "image 0 'img': cannot decode the JPEG: Unsupported JPEG data precision 12");
  // A valid progressive script of 694 scans: the DC, then each AC coefficient alone in 11 scans
  // of successive approximation (bits 10 and up, then each lower bit).
  std::vector<jpeg_scan_info> scans = {{1, {0, 0, 0, 0}, 0, 0, 0, 0}};
  for (int k = 1; k < 64; ++k) {
    scans.push_back({1, {0, 0, 0, 0}, k, k, 0, 10});
    for (int bit = 10; bit > 0; --bit) scans.push_back({1, {0, 0, 0, 0}, k, k, bit, bit - 1});
  }
  ASSERT_EQ(scans.size(), 694u);
  expect_error(image_gltf(wp::test::jpeg_encode(smooth_samples(16, 8, 1), 16, 8, 1, false, scans),
                          "image/jpeg", "jpeg_scans.gltf"),
               "image 0 'img': cannot decode the JPEG: more than 500 progressive scans");
}

}  // namespace
