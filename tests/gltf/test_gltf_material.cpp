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

}  // namespace
