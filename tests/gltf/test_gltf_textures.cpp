// glTF loader, gltf_textures.cpp: images, samplers, texture slots and KHR_texture_transform; errors
// naming the element; corrupted textured .glb files. Shared fixture: tests/gltf/gltf_files.h.
#include <zlib.h>

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

}  // namespace
