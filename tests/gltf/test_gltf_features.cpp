// The material extensions on their way from a glTF file to the kernels: the kernel features a
// scene turns on (host/device/scene_features.cpp) and the packed dev::Material
// (host/device/device_scene.cpp). Shared fixture: tests/gltf/gltf_files.h.
#include <cstring>

#include "bvh/bvh.h"
#include "host/accel/bvh_input.h"
#include "host/device/device_scene.h"
#include "host/device/scene_features.h"
#include "host/lights/light_table.h"
#include "tests/gltf/gltf_files.h"
#include "tests/scene_factory.h"

namespace {

using namespace wp::test::gltf_files;  // NOLINT(google-build-using-namespace)

// temp_dir() is removed after the tests (once per executable, so here only).
[[maybe_unused]] auto* const kCleanup = ::testing::AddGlobalTestEnvironment(new TempCleanup);

// The features of the textured square with the one material `material` (texture 0 exists).
wp::SceneFeatures features_of(const std::string& material) {
  Gltf g = textured_square({0});
  g.top = test_images() + R"(,"textures":[{"source":0}])";
  g.materials = {material};
  return wp::SceneFeatures::of(wp::load_gltf(g.write("features.gltf")), false);
}

// A scene without the extensions turns on what it did before they existed, in the same order,
// and none of theirs.
TEST(GltfFeatures, PlainSceneKeepsItsFlags) {
  const wp::SceneFeatures f = features_of("{}");
  const std::vector<std::pair<std::string, bool>> expected = {
      {"WP_FEATURE_PUNCTUAL_LIGHTS", false}, {"WP_FEATURE_SPOT_LIGHTS", false},
      {"WP_FEATURE_EMISSION", false},        {"WP_FEATURE_ENVIRONMENT", false},
      {"WP_FEATURE_VERTEX_COLORS", false},   {"WP_FEATURE_TEXTURES", false},
      {"WP_FEATURE_TEXTURE_LOD", false},     {"WP_FEATURE_NORMAL_MAPS", false},
      {"WP_FEATURE_ALPHA", false},           {"WP_FEATURE_UNLIT", false},
      {"WP_FEATURE_GLOSSY", true},  // glTF's default material is metallic
      {"WP_FEATURE_TRANSMISSION", false},    {"WP_FEATURE_VOLUME", false},
      {"WP_FEATURE_SPECULAR", false},        {"WP_FEATURE_CLEARCOAT", false},
      {"WP_FEATURE_SHEEN", false},           {"WP_FEATURE_ANISOTROPY", false},
      {"WP_FEATURE_IRIDESCENCE", false},     {"WP_FEATURE_DIFFUSE_TRANSMISSION", false},
      {"WP_FEATURE_DISPERSION", false}};
  EXPECT_EQ(f.flags(), expected);
  EXPECT_EQ(f.describe(), "glossy");
  // All features: every flag on.
  for (const auto& [name, on] : wp::SceneFeatures::all().flags()) EXPECT_TRUE(on) << name;
  EXPECT_EQ(wp::SceneFeatures::all().flags().size(), expected.size());
}

// Each extension turns on its feature, and the full BSDF (glossy) even on an otherwise
// Lambertian material (not metallic, specularFactor 0); factors that change nothing (a sheen
// roughness without colour, a zero clearcoat, dispersion without a refracting volume) turn on
// nothing but the textures they read; unlit materials use none of them.
TEST(GltfFeatures, EachExtensionTurnsOnItsFeature) {
  const std::string lambert = R"("pbrMetallicRoughness":{"metallicFactor":0})";
  const std::string no_specular = R"("KHR_materials_specular":{"specularFactor":0})";
  const auto material = [&](const std::string& extensions) {
    return "{" + lambert + R"(,"extensions":{)" + no_specular +
           (extensions.empty() ? "" : "," + extensions) + "}}";
  };
  EXPECT_EQ(features_of(material("")).describe(), "none");
  for (const auto& [extensions, expected] : std::vector<std::pair<std::string, std::string>>{
           {R"("KHR_materials_clearcoat":{"clearcoatFactor":0.5})", "glossy clearcoat"},
           {R"("KHR_materials_clearcoat":{"clearcoatTexture":{"index":0}})",
            "textures texture_lod"},
           {R"("KHR_materials_clearcoat":{"clearcoatFactor":1,)"
            R"("clearcoatNormalTexture":{"index":0}})",
            "textures texture_lod glossy clearcoat"},
           {R"("KHR_materials_sheen":{"sheenColorFactor":[0,0,0.5]})", "glossy sheen"},
           {R"("KHR_materials_sheen":{"sheenRoughnessFactor":0.5})", "none"},
           {R"("KHR_materials_sheen":{"sheenColorFactor":[1,1,1],)"
            R"("sheenColorTexture":{"index":0}})",
            "textures texture_lod glossy sheen"},
           {R"("KHR_materials_anisotropy":{"anisotropyStrength":0.5})", "glossy anisotropy"},
           {R"("KHR_materials_anisotropy":{"anisotropyRotation":1})", "none"},
           {R"("KHR_materials_iridescence":{"iridescenceFactor":1})", "glossy iridescence"},
           {R"("KHR_materials_iridescence":{"iridescenceThicknessTexture":{"index":0}})",
            "textures texture_lod"},
           {R"("KHR_materials_diffuse_transmission":{"diffuseTransmissionFactor":0.5})",
            "glossy diffuse_transmission"},
           {R"("KHR_materials_diffuse_transmission":{"diffuseTransmissionColorFactor":[1,0,0]})",
            "none"},
           {R"("KHR_materials_dispersion":{"dispersion":0.5})", "none"},
           {R"("KHR_materials_dispersion":{"dispersion":0.5},)"
            R"("KHR_materials_volume":{"thicknessFactor":1})",
            "none"},
           {R"("KHR_materials_dispersion":{"dispersion":0.5},)"
            R"("KHR_materials_transmission":{"transmissionFactor":1})",
            "glossy transmission"},
           {R"("KHR_materials_dispersion":{"dispersion":0.5},)"
            R"("KHR_materials_transmission":{"transmissionFactor":1},)"
            R"("KHR_materials_volume":{"thicknessFactor":1})",
            "glossy transmission volume dispersion"},
       }) {
    EXPECT_EQ(features_of(material(extensions)).describe(), expected) << extensions;
  }
  // KHR_materials_specular: the factor alone is the core BSDF's; a colour or a texture is more.
  for (const auto& [specular, expected] : std::vector<std::pair<std::string, std::string>>{
           {R"({"specularFactor":0.5})", "glossy"},
           {R"({"specularFactor":0,"specularColorFactor":[1,0.5,1]})", "glossy specular"},
           {R"({"specularFactor":0,"specularColorFactor":[1,1,1]})", "none"},
           {R"({"specularFactor":0,"specularTexture":{"index":0}})",
            "textures texture_lod glossy specular"},
           {R"({"specularFactor":0,"specularColorTexture":{"index":0}})",
            "textures texture_lod glossy specular"},
       }) {
    EXPECT_EQ(
        features_of("{" + lambert + R"(,"extensions":{"KHR_materials_specular":)" + specular + "}}")
            .describe(),
        expected)
        << specular;
  }
  // Unlit: none of it (its base colour texture would still count).
  EXPECT_EQ(features_of(R"({"extensions":{"KHR_materials_unlit":{},)"
                        R"("KHR_materials_clearcoat":{"clearcoatFactor":1,)"
                        R"("clearcoatTexture":{"index":0}},)"
                        R"("KHR_materials_sheen":{"sheenColorFactor":[1,1,1]},)"
                        R"("KHR_materials_anisotropy":{"anisotropyStrength":1},)"
                        R"("KHR_materials_iridescence":{"iridescenceFactor":1},)"
                        R"("KHR_materials_specular":{"specularColorFactor":[0,1,0]},)"
                        R"("KHR_materials_diffuse_transmission":{"diffuseTransmissionFactor":1}}})")
                .describe(),
            "unlit");
}

// The bytes the kernels read: every extension field in its place of dev::Material
// (kernels/shared/types.h), and for a material without the extensions the values that make them
// inert (the specular factor now in specular.w, extra.z zero, texture slots -1).
TEST(GltfFeatures, MaterialExtensionsArePacked) {
  wp::Scene s;
  s.materials.push_back(wp::Material{});  // glTF's defaults
  wp::Material m;
  m.normal_scale = 0.75f;
  m.thickness = 0.5f;
  m.specular = 0.25f;
  m.specular_color = {2.0f, 0.5f, 0.0f};
  m.clearcoat = 0.875f;
  m.clearcoat_roughness = 0.125f;
  m.clearcoat_normal_scale = 0.625f;
  m.sheen_color = {0.1f, 0.2f, 0.3f};
  m.sheen_roughness = 0.4f;
  m.anisotropy_strength = 0.6f;
  m.anisotropy_rotation = 0.5f;
  m.iridescence = 0.7f;
  m.iridescence_ior = 1.8f;
  m.iridescence_thickness_min = 200.0f;
  m.iridescence_thickness_max = 600.0f;
  m.dispersion = 0.35f;
  m.diffuse_transmission = 0.45f;
  m.diffuse_transmission_color = {0.9f, 0.8f, 0.7f};
  m.transmission_texture = 0;
  m.specular_texture = 1;
  m.specular_color_texture = 2;
  m.clearcoat_texture = 3;
  m.clearcoat_roughness_texture = 4;
  m.clearcoat_normal_texture = 5;
  m.sheen_color_texture = 6;
  m.sheen_roughness_texture = 7;
  m.anisotropy_texture = 8;
  m.iridescence_texture = 9;
  m.iridescence_thickness_texture = 10;
  m.diffuse_transmission_texture = 11;
  m.diffuse_transmission_color_texture = 12;
  s.materials.push_back(m);
  wp::Image image;
  image.width = image.height = 1;
  image.rgba = {255, 255, 255, 255};
  s.images.push_back(image);
  wp::TextureRef t;
  t.image = 0;
  s.textures.assign(13, t);
  wp::test::add_quad(s, {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, 0);
  wp::test::add_quad(s, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, 1);
  wp::test::finish_bounds(s);

  std::vector<std::uint32_t> flags;
  const wp::bvh::Bvh tree = wp::bvh::build(wp::bvh_input(s, flags), wp::bvh::BuildOptions{});
  const wp::LightTable lights =
      wp::build_light_table(s, nullptr, glm::vec3(1.0f), 1.0f, wp::LightSelect::kPower);
  wp::SceneExtras extras;
  extras.lights = &lights;
  const wp::PackedScene packed = wp::pack_scene(s, tree, extras);
  ASSERT_EQ(packed.buffers.size(), 1u);
  wp::dev::Material d[2];
  const std::size_t at = std::size_t(packed.desc.materials) * WP_SCENE_ALIGN;
  ASSERT_LE(at + sizeof d, packed.buffers[0].size());
  std::memcpy(d, packed.buffers[0].data() + at, sizeof d);

  const auto f4 = [](const wp::dev::float4& v) { return glm::vec4(v.x, v.y, v.z, v.w); };
  const auto i4 = [](const wp::dev::int4& v) { return glm::ivec4(v.x, v.y, v.z, v.w); };
  // Without the extensions.
  EXPECT_EQ(f4(d[0].extra), glm::vec4(1, 0, 0, 0));
  for (const wp::dev::int4& slots :
       {d[0].textures1, d[0].textures2, d[0].textures3, d[0].textures4})
    EXPECT_EQ(i4(slots), glm::ivec4(-1));
  EXPECT_EQ(f4(d[0].specular), glm::vec4(1, 1, 1, 1));
  EXPECT_EQ(f4(d[0].clearcoat), glm::vec4(0, 0, 1, 0));
  EXPECT_EQ(f4(d[0].sheen), glm::vec4(0));
  EXPECT_EQ(f4(d[0].anisotropy), glm::vec4(0, 1, 0, 0));
  EXPECT_EQ(f4(d[0].iridescence), glm::vec4(0, 1.3f, 100, 400));
  EXPECT_EQ(f4(d[0].diffuse_transmission), glm::vec4(1, 1, 1, 0));
  // With every field.
  EXPECT_EQ(f4(d[1].extra), glm::vec4(0.75f, 0.5f, 0.0f, 0.35f));
  EXPECT_EQ(i4(d[1].textures1), glm::ivec4(0, 1, 2, 3));
  EXPECT_EQ(i4(d[1].textures2), glm::ivec4(4, 5, 6, 7));
  EXPECT_EQ(i4(d[1].textures3), glm::ivec4(8, 9, 10, 11));
  EXPECT_EQ(i4(d[1].textures4), glm::ivec4(12, -1, -1, -1));
  EXPECT_EQ(f4(d[1].specular), glm::vec4(2.0f, 0.5f, 0.0f, 0.25f));
  EXPECT_EQ(f4(d[1].clearcoat), glm::vec4(0.875f, 0.125f, 0.625f, 0.0f));
  EXPECT_EQ(f4(d[1].sheen), glm::vec4(0.1f, 0.2f, 0.3f, 0.4f));
  EXPECT_EQ(f4(d[1].anisotropy), glm::vec4(0.6f, std::cos(0.5f), std::sin(0.5f), 0.0f));
  EXPECT_EQ(f4(d[1].iridescence), glm::vec4(0.7f, 1.8f, 200.0f, 600.0f));
  EXPECT_EQ(f4(d[1].diffuse_transmission), glm::vec4(0.9f, 0.8f, 0.7f, 0.45f));
}

}  // namespace
