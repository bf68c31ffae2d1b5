// glTF loader, gltf_material.cpp: material factors and extensions, the default material, and
// factors outside glTF's ranges (lights' too: both go through gltf_values.h). Shared fixture:
// tests/gltf/gltf_files.h.
#include "tests/gltf/gltf_files.h"

namespace {

using namespace wp::test::gltf_files;  // NOLINT(google-build-using-namespace)

// m0 has every supported field; m1 is empty (glTF defaults). Primitives: m0, none, m1, and a
// second mesh with none: the default material is appended once, after the file's materials.
TEST(GltfLoader, MaterialFactorsAndDefaultMaterial) {
  Gltf g = one_triangle("");
  g.materials = {
      R"({"name":"m0","pbrMetallicRoughness":{"baseColorFactor":[0.5,0.25,0.125,0.75],
          "metallicFactor":0.2,"roughnessFactor":0.7},"emissiveFactor":[1,0.5,0.25],
          "doubleSided":true,"alphaMode":"MASK","alphaCutoff":0.3,
          "extensions":{"KHR_materials_emissive_strength":{"emissiveStrength":4},
          "KHR_materials_ior":{"ior":1.33},"KHR_materials_transmission":{"transmissionFactor":0.9}}})",
      R"({"name":"m1","alphaMode":"BLEND"})"};
  g.meshes = {"{\"primitives\":[" +
                  join({prim({{"POSITION", 0}}, -1, -1, 0), prim({{"POSITION", 0}}),
                        prim({{"POSITION", 0}}, -1, -1, 1)}) +
                  "]}",
              "{\"primitives\":[" + prim({{"POSITION", 0}}) + "]}"};
  g.node("\"mesh\":1", true);
  const wp::Scene s = wp::load_gltf(g.write("materials.gltf"));
  check_invariants(s);
  ASSERT_EQ(s.materials.size(), 3u);
  EXPECT_EQ(s.triangle_material, (std::vector<std::uint32_t>{0, 2, 1, 2}));
  const wp::Material& m0 = s.materials[0];
  EXPECT_EQ(m0.name, "m0");
  EXPECT_EQ(m0.base_color, glm::vec4(0.5f, 0.25f, 0.125f, 0.75f));
  EXPECT_FLOAT_EQ(m0.metallic, 0.2f);
  EXPECT_FLOAT_EQ(m0.roughness, 0.7f);
  EXPECT_EQ(m0.emission, vec3(4, 2, 1));
  EXPECT_TRUE(m0.double_sided);
  EXPECT_EQ(m0.alpha_mode, wp::AlphaMode::kMask);
  EXPECT_FLOAT_EQ(m0.alpha_cutoff, 0.3f);
  EXPECT_FLOAT_EQ(m0.ior, 1.33f);
  EXPECT_FLOAT_EQ(m0.transmission, 0.9f);
  const wp::Material& m1 = s.materials[1];
  EXPECT_EQ(m1.alpha_mode, wp::AlphaMode::kBlend);
  for (const wp::Material* m : {&m1, &s.materials[2]}) {
    EXPECT_EQ(m->base_color, glm::vec4(1.0f));
    EXPECT_EQ(m->metallic, 1.0f);
    EXPECT_EQ(m->roughness, 1.0f);
    EXPECT_EQ(m->emission, vec3(0.0f));
    EXPECT_FALSE(m->double_sided);
    EXPECT_EQ(m->ior, 1.5f);
    EXPECT_EQ(m->transmission, 0.0f);
  }
  EXPECT_EQ(s.materials[2].alpha_mode, wp::AlphaMode::kOpaque);

  // Every primitive has a material: no default is added.
  Gltf h = one_triangle("");
  h.materials = {"{}"};
  h.meshes = {"{\"primitives\":[" + prim({{"POSITION", 0}}, -1, -1, 0) + "]}"};
  EXPECT_EQ(wp::load_gltf(h.write("one_material.gltf")).materials.size(), 1u);
}

// Values outside glTF's ranges are errors, as for the Khronos validator: a negative base colour
// or emission gave negative radiance, which the fixed-point film silently saturated to 0; a
// metallic factor of 1.5 was clamped without a word.
TEST(GltfLoader, OutOfRangeFactorsAreErrors) {
  for (const auto& [material, cause] : std::vector<std::pair<std::string, std::string>>{
           {R"({"pbrMetallicRoughness":{"baseColorFactor":[0.5,-0.1,0.5,1]}})",
            "baseColorFactor -0.1 is outside [0, 1]"},
           {R"({"pbrMetallicRoughness":{"baseColorFactor":[0.5,0.5,0.5,1.2]}})",
            "baseColorFactor 1.2 is outside [0, 1]"},
           {R"({"pbrMetallicRoughness":{"metallicFactor":1.5}})",
            "metallicFactor 1.5 is outside [0, 1]"},
           {R"({"pbrMetallicRoughness":{"roughnessFactor":-1}})",
            "roughnessFactor -1 is outside [0, 1]"},
           {R"({"emissiveFactor":[2,0,0]})", "emissiveFactor 2 is outside [0, 1]"},
           {R"({"extensions":{"KHR_materials_transmission":{"transmissionFactor":1.01}}})",
            "transmissionFactor 1.01 is outside [0, 1]"},
           {R"({"extensions":{"KHR_materials_specular":{"specularFactor":-0.5}}})",
            "specularFactor -0.5 is outside [0, 1]"},
       }) {
    Gltf g = one_triangle("");
    g.materials = {material};
    g.meshes = {"{\"primitives\":[" + prim({{"POSITION", 0}}, -1, -1, 0) + "]}"};
    expect_error(g.write("range.gltf"), "material 0 '': " + cause);
  }
  // The bounds themselves are valid.
  Gltf edge = one_triangle("");
  edge.materials = {R"({"pbrMetallicRoughness":{"baseColorFactor":[0,1,0,1],"metallicFactor":1,)"
                    R"("roughnessFactor":0},"emissiveFactor":[1,0,1]})"};
  edge.meshes = {"{\"primitives\":[" + prim({{"POSITION", 0}}, -1, -1, 0) + "]}"};
  EXPECT_NO_THROW(wp::load_gltf(edge.write("edge.gltf")));

  for (const auto& [light, cause] : std::vector<std::pair<std::string, std::string>>{
           {R"({"type":"point","intensity":-2})", "intensity -2 is outside [0, inf]"},
           {R"({"type":"point","color":[1,1.5,1]})", "color 1.5 is outside [0, 1]"},
           {R"({"type":"spot","spot":{"innerConeAngle":0.5,"outerConeAngle":0.5}})",
            "innerConeAngle 0.5 is not below outerConeAngle 0.5"},
           {R"({"type":"spot","spot":{"outerConeAngle":2}})",
            "outerConeAngle 2 is outside [0, 1.5708]"},
       }) {
    Gltf g = one_triangle("");
    g.top = R"("extensionsUsed":["KHR_lights_punctual"])";
    g.lights = {light};
    g.node(R"("extensions":{"KHR_lights_punctual":{"light":0}})", true);
    expect_error(g.write("light_range.gltf"), "light 0 '': " + cause);
  }
}

// Each material extension's fields, by extension: what a material gets with the extension absent,
// present but empty (the defaults of the extensions' schemas), and with every factor given.
const std::vector<std::string> kExtensionNames = {"KHR_materials_specular",
                                                  "KHR_materials_clearcoat",
                                                  "KHR_materials_sheen",
                                                  "KHR_materials_anisotropy",
                                                  "KHR_materials_iridescence",
                                                  "KHR_materials_dispersion",
                                                  "KHR_materials_diffuse_transmission"};

void expect_extension_defaults(const wp::Material& m) {
  EXPECT_EQ(m.specular, 1.0f);
  EXPECT_EQ(m.specular_color, vec3(1.0f));
  EXPECT_EQ(m.clearcoat, 0.0f);
  EXPECT_EQ(m.clearcoat_roughness, 0.0f);
  EXPECT_EQ(m.clearcoat_normal_scale, 1.0f);
  EXPECT_EQ(m.sheen_color, vec3(0.0f));
  EXPECT_EQ(m.sheen_roughness, 0.0f);
  EXPECT_EQ(m.anisotropy_strength, 0.0f);
  EXPECT_EQ(m.anisotropy_rotation, 0.0f);
  EXPECT_EQ(m.iridescence, 0.0f);
  EXPECT_FLOAT_EQ(m.iridescence_ior, 1.3f);
  EXPECT_EQ(m.iridescence_thickness_min, 100.0f);
  EXPECT_EQ(m.iridescence_thickness_max, 400.0f);
  EXPECT_EQ(m.dispersion, 0.0f);
  EXPECT_EQ(m.diffuse_transmission, 0.0f);
  EXPECT_EQ(m.diffuse_transmission_color, vec3(1.0f));
  for (const int t : {m.specular_texture, m.specular_color_texture, m.clearcoat_texture,
                      m.clearcoat_roughness_texture, m.clearcoat_normal_texture,
                      m.sheen_color_texture, m.sheen_roughness_texture, m.anisotropy_texture,
                      m.iridescence_texture, m.iridescence_thickness_texture,
                      m.diffuse_transmission_texture, m.diffuse_transmission_color_texture})
    EXPECT_EQ(t, -1);
}

TEST(GltfLoader, MaterialExtensionDefaults) {
  std::string empty;
  for (const std::string& name : kExtensionNames)
    empty += (empty.empty() ? "" : ",") + ("\"" + name + "\":{}");
  Gltf g = one_triangle("");
  g.top = R"("extensionsUsed":[")" + kExtensionNames[0] + "\"]";
  g.materials = {"{\"extensions\":{" + empty + "}}", "{}"};
  g.meshes = {"{\"primitives\":[" + prim({{"POSITION", 0}}, -1, -1, 0) + "," +
              prim({{"POSITION", 0}}, -1, -1, 1) + "]}"};
  const wp::Scene s = wp::load_gltf(g.write("extension_defaults.gltf"));
  check_invariants(s);
  ASSERT_EQ(s.materials.size(), 2u);
  for (const wp::Material& m : s.materials) {
    SCOPED_TRACE(&m == &s.materials[0] ? "empty extensions" : "no extensions");
    expect_extension_defaults(m);
  }
  EXPECT_TRUE(s.textures.empty());
  EXPECT_TRUE(s.tangents.empty());  // nothing needs a tangent frame
}

TEST(GltfLoader, MaterialExtensionFactors) {
  Gltf g = one_triangle("");
  g.materials = {R"({"extensions":{
      "KHR_materials_specular":{"specularFactor":0.25,"specularColorFactor":[2,0.5,0]},
      "KHR_materials_clearcoat":{"clearcoatFactor":0.75,"clearcoatRoughnessFactor":0.125},
      "KHR_materials_sheen":{"sheenColorFactor":[1,0.5,0.25],"sheenRoughnessFactor":0.375},
      "KHR_materials_anisotropy":{"anisotropyStrength":0.625,"anisotropyRotation":-7.5},
      "KHR_materials_iridescence":{"iridescenceFactor":0.5,"iridescenceIor":1.8,
        "iridescenceThicknessMinimum":200,"iridescenceThicknessMaximum":600},
      "KHR_materials_dispersion":{"dispersion":0.4},
      "KHR_materials_diffuse_transmission":{"diffuseTransmissionFactor":0.3,
        "diffuseTransmissionColorFactor":[0.1,0.2,0.3]}}})"};
  g.meshes = {"{\"primitives\":[" + prim({{"POSITION", 0}}, -1, -1, 0) + "]}"};
  const wp::Scene s = wp::load_gltf(g.write("extension_factors.gltf"));
  check_invariants(s);
  const wp::Material& m = s.materials.at(0);
  EXPECT_FLOAT_EQ(m.specular, 0.25f);
  EXPECT_EQ(m.specular_color, vec3(2.0f, 0.5f, 0.0f));  // above 1 is valid: F0 is clamped
  EXPECT_FLOAT_EQ(m.clearcoat, 0.75f);
  EXPECT_FLOAT_EQ(m.clearcoat_roughness, 0.125f);
  EXPECT_EQ(m.clearcoat_normal_scale, 1.0f);
  EXPECT_EQ(m.sheen_color, vec3(1.0f, 0.5f, 0.25f));
  EXPECT_FLOAT_EQ(m.sheen_roughness, 0.375f);
  EXPECT_FLOAT_EQ(m.anisotropy_strength, 0.625f);
  EXPECT_FLOAT_EQ(m.anisotropy_rotation, -7.5f);  // any angle
  EXPECT_FLOAT_EQ(m.iridescence, 0.5f);
  EXPECT_FLOAT_EQ(m.iridescence_ior, 1.8f);
  EXPECT_FLOAT_EQ(m.iridescence_thickness_min, 200.0f);
  EXPECT_FLOAT_EQ(m.iridescence_thickness_max, 600.0f);
  EXPECT_FLOAT_EQ(m.dispersion, 0.4f);
  EXPECT_FLOAT_EQ(m.diffuse_transmission, 0.3f);
  EXPECT_TRUE(near(m.diffuse_transmission_color, {0.1f, 0.2f, 0.3f}));
  // An anisotropic material needs a tangent frame: generated (the triangle has no TEXCOORD_0, so
  // any tangent orthogonal to the normal).
  check_tangents(s);
}

// Every extension texture in its slot (each use told apart by its KHR_texture_transform offset
// k, row_u.z = k), sRGB exactly for the colour ones; a clearcoat normal texture keeps its scale
// and texCoord. KHR_materials_volume's thicknessTexture is checked but not read: its image (1) is
// never decoded.
TEST(GltfLoader, MaterialExtensionTextures) {
  const auto tex = [](int k, const std::string& extra = "") {
    return R"({"index":0,"extensions":{"KHR_texture_transform":{"offset":[)" + std::to_string(k) +
           ",0]}}" + extra + "}";
  };
  Gltf g = textured_square({0});
  g.top = test_images() + R"(,"textures":[{"source":0},{"source":1}])";
  g.materials = {
      R"({"extensions":{"KHR_materials_specular":{"specularTexture":)" + tex(1) +
      R"(,"specularColorTexture":)" + tex(2) +
      R"(},"KHR_materials_clearcoat":{"clearcoatFactor":1,"clearcoatTexture":)" + tex(3) +
      R"(,"clearcoatRoughnessTexture":)" + tex(4) + R"(,"clearcoatNormalTexture":)" +
      tex(5, R"(,"scale":0.5,"texCoord":1)") + R"(},"KHR_materials_sheen":{"sheenColorTexture":)" +
      tex(6) + R"(,"sheenRoughnessTexture":)" + tex(7) +
      R"(},"KHR_materials_anisotropy":{"anisotropyTexture":)" + tex(8) +
      R"(},"KHR_materials_iridescence":{"iridescenceTexture":)" + tex(9) +
      R"(,"iridescenceThicknessTexture":)" + tex(10) +
      R"(},"KHR_materials_diffuse_transmission":{"diffuseTransmissionTexture":)" + tex(11) +
      R"(,"diffuseTransmissionColorTexture":)" + tex(12) +
      R"(},"KHR_materials_volume":{"thicknessFactor":1,"thicknessTexture":{"index":1}}}})"};
  const wp::Scene s = wp::load_gltf(g.write("extension_textures.gltf"));
  check_invariants(s);
  const wp::Material& m = s.materials.at(0);
  const std::vector<std::pair<int, bool>> slots = {// (texture, sRGB) for k = 1, 2, ...
                                                   {m.specular_texture, false},
                                                   {m.specular_color_texture, true},
                                                   {m.clearcoat_texture, false},
                                                   {m.clearcoat_roughness_texture, false},
                                                   {m.clearcoat_normal_texture, false},
                                                   {m.sheen_color_texture, true},
                                                   {m.sheen_roughness_texture, false},
                                                   {m.anisotropy_texture, false},
                                                   {m.iridescence_texture, false},
                                                   {m.iridescence_thickness_texture, false},
                                                   {m.diffuse_transmission_texture, false},
                                                   {m.diffuse_transmission_color_texture, true}};
  ASSERT_EQ(s.textures.size(), slots.size());
  for (std::size_t k = 0; k < slots.size(); ++k) {
    SCOPED_TRACE("slot " + std::to_string(k + 1));
    ASSERT_GE(slots[k].first, 0);
    const wp::TextureRef& t = s.textures[std::size_t(slots[k].first)];
    EXPECT_EQ(t.row_u.z, float(k + 1));
    EXPECT_EQ(t.srgb, slots[k].second);
    EXPECT_EQ(t.image, 0);
    EXPECT_EQ(t.texcoord, k == 4 ? 1 : 0);
  }
  EXPECT_EQ(m.clearcoat_normal_scale, 0.5f);
  EXPECT_EQ(s.images.size(), 1u);  // the thickness texture's image is not decoded
  // A clearcoat normal texture needs tangents; with no base normal texture they follow its set
  // (TEXCOORD_1 = (2x, y): v runs up the image, so the bitangent cross(n, t) w points down y).
  check_tangents(s);
  for (const glm::vec4& t : s.tangents) EXPECT_EQ(t, glm::vec4(1, 0, 0, -1));
}

// Tangents are kept for a material that needs a tangent frame (a normal or clearcoat normal
// texture, anisotropy) and for no other: generated from TEXCOORD_0 by default.
TEST(GltfLoader, TangentsForAnisotropyAndClearcoatNormals) {
  for (const auto& [material, tangents] : std::vector<std::pair<std::string, bool>>{
           {R"({"extensions":{"KHR_materials_anisotropy":{"anisotropyStrength":0.5}}})", true},
           {R"({"extensions":{"KHR_materials_anisotropy":{"anisotropyTexture":{"index":0}}}})",
            true},
           {R"({"extensions":{"KHR_materials_clearcoat":{"clearcoatNormalTexture":{"index":0}}}})",
            true},
           {R"({"extensions":{"KHR_materials_anisotropy":{"anisotropyRotation":1}}})", false},
           {R"({"extensions":{"KHR_materials_clearcoat":{"clearcoatFactor":1,)"
            R"("clearcoatTexture":{"index":0}}}})",
            false}}) {
    SCOPED_TRACE(material);
    Gltf g = textured_square({0});
    g.top = test_images() + R"(,"textures":[{"source":0}])";
    g.materials = {material};
    const wp::Scene s = wp::load_gltf(g.write("tangent_needs.gltf"));
    check_invariants(s);
    if (!tangents) {
      EXPECT_TRUE(s.tangents.empty());
      continue;
    }
    check_tangents(s);
    for (const glm::vec4& t : s.tangents) EXPECT_EQ(t, glm::vec4(1, 0, 0, 1));  // TEXCOORD_0
  }
}

// The extensions' ranges and types, as the Khronos validator checks them: one line naming the
// material and the field.
TEST(GltfLoader, MaterialExtensionErrors) {
  for (const auto& [extensions, cause] : std::vector<std::pair<std::string, std::string>>{
           {R"("KHR_materials_specular":{"specularColorFactor":[1,-0.1,1]})",
            "specularColorFactor -0.1 is outside [0, inf]"},
           {R"("KHR_materials_specular":{"specularColorFactor":[1,1]})",
            "specularColorFactor needs 3 numbers"},
           {R"("KHR_materials_specular":{"specularTexture":{"index":7}})",
            "specularTexture: texture 7 does not exist"},
           {R"("KHR_materials_clearcoat":{"clearcoatFactor":1.5})",
            "clearcoatFactor 1.5 is outside [0, 1]"},
           {R"("KHR_materials_clearcoat":{"clearcoatRoughnessFactor":-1})",
            "clearcoatRoughnessFactor -1 is outside [0, 1]"},
           {R"("KHR_materials_clearcoat":{"clearcoatNormalTexture":{"index":0,"scale":"x"}})",
            "clearcoatNormalTexture.scale is not a number"},
           {R"("KHR_materials_clearcoat":{"clearcoatTexture":{"texCoord":0}})",
            "clearcoatTexture has no valid index"},
           {R"("KHR_materials_sheen":{"sheenColorFactor":[0,2,0]})",
            "sheenColorFactor 2 is outside [0, 1]"},
           {R"("KHR_materials_sheen":{"sheenRoughnessFactor":1.25})",
            "sheenRoughnessFactor 1.25 is outside [0, 1]"},
           {R"("KHR_materials_anisotropy":{"anisotropyStrength":1.5})",
            "anisotropyStrength 1.5 is outside [0, 1]"},
           {R"("KHR_materials_anisotropy":{"anisotropyStrength":-0.5})",
            "anisotropyStrength -0.5 is outside [0, 1]"},
           {R"("KHR_materials_anisotropy":{"anisotropyRotation":"left"})",
            "KHR_materials_anisotropy.anisotropyRotation is not a number"},
           {R"("KHR_materials_iridescence":{"iridescenceFactor":2})",
            "iridescenceFactor 2 is outside [0, 1]"},
           {R"("KHR_materials_iridescence":{"iridescenceIor":0.5})",
            "iridescenceIor 0.5 is outside [1, inf]"},
           {R"("KHR_materials_iridescence":{"iridescenceThicknessMinimum":-1})",
            "iridescenceThicknessMinimum -1 is outside [0, inf]"},
           {R"("KHR_materials_iridescence":{"iridescenceThicknessMaximum":-400})",
            "iridescenceThicknessMaximum -400 is outside [0, inf]"},
           {R"("KHR_materials_dispersion":{"dispersion":-0.25})",
            "dispersion -0.25 is outside [0, inf]"},
           {R"("KHR_materials_diffuse_transmission":{"diffuseTransmissionFactor":1.25})",
            "diffuseTransmissionFactor 1.25 is outside [0, 1]"},
           {R"("KHR_materials_diffuse_transmission":{"diffuseTransmissionColorFactor":[1,1,1.5]})",
            "diffuseTransmissionColorFactor 1.5 is outside [0, 1]"},
           {R"("KHR_materials_volume":{"thicknessFactor":1,"thicknessTexture":{"index":3}})",
            "thicknessTexture: texture 3 does not exist"},
       }) {
    Gltf g = one_triangle("");
    g.materials = {"{\"extensions\":{" + extensions + "}}"};
    g.meshes = {"{\"primitives\":[" + prim({{"POSITION", 0}}, -1, -1, 0) + "]}"};
    expect_error(g.write("extension_range.gltf"), "material 0 '': " + cause);
  }
  // The bounds themselves are valid.
  Gltf edge = one_triangle("");
  edge.materials = {R"({"extensions":{"KHR_materials_clearcoat":{"clearcoatFactor":1,)"
                    R"("clearcoatRoughnessFactor":0},"KHR_materials_iridescence":{)"
                    R"("iridescenceIor":1,"iridescenceThicknessMinimum":0},)"
                    R"("KHR_materials_specular":{"specularColorFactor":[0,100,0]},)"
                    R"("KHR_materials_anisotropy":{"anisotropyStrength":1}}})"};
  edge.meshes = {"{\"primitives\":[" + prim({{"POSITION", 0}}, -1, -1, 0) + "]}"};
  EXPECT_NO_THROW(wp::load_gltf(edge.write("extension_edge.gltf")));
}

}  // namespace
