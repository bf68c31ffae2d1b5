// glTF loader: the bounds of glTF 2.0's JSON schema (and of the extensions' schemas) on every
// number wavepath reads from cameras, materials, lights, samplers and texture infos, one row per
// rule: the value just inside is accepted, the value just outside refused with one line naming
// the element and the field. Shared fixture: tests/gltf/gltf_files.h.
#include "tests/gltf/gltf_files.h"

namespace {

using namespace wp::test::gltf_files;  // NOLINT(google-build-using-namespace)

// `json` is the element's object with `$` where the value goes; `error` what the refusal says.
struct Bound {
  const char* element;  // camera, material, light, sampler, textureInfo (a material's)
  std::string json;
  const char* inside;
  const char* outside;
  const char* error;
};

const std::string kPersp = R"({"type":"perspective","perspective":)";
const std::string kOrtho = R"({"type":"orthographic","orthographic":)";
const std::string kPbr = R"({"pbrMetallicRoughness":)";
std::string ext(const std::string& name, const std::string& body) {
  return R"({"extensions":{")" + name + R"(":)" + body + "}}";
}

const std::vector<Bound> kBounds = {
    // camera.perspective: yfov > 0 (and < pi: a pinhole), znear > 0, aspectRatio > 0 (0 reads
    // as absent), zfar > znear.
    {"camera", kPersp + R"({"yfov":$,"znear":0.1}})", "1e-6", "0", "yfov must be > 0 (got 0)"},
    {"camera", kPersp + R"({"yfov":$,"znear":0.1}})", "3.14", "3.1416", "yfov must be < pi"},
    {"camera", kPersp + R"({"yfov":0.7,"znear":$}})", "1e-6", "0", "znear must be > 0 (got 0)"},
    {"camera", kPersp + R"({"yfov":0.7,"znear":0.1,"aspectRatio":$}})", "1e-6", "-1e-6",
     "aspectRatio must be > 0"},
    {"camera", kPersp + R"({"yfov":0.7,"znear":0.1,"zfar":$}})", "0.1001", "0.1",
     "zfar must be > znear (got 0.1)"},
    {"camera", kPersp + R"({"yfov":0.7,"znear":0.1,"zfar":$}})", "1e30", "-1",
     "zfar must be > znear"},
    // camera.orthographic: xmag, ymag not 0; znear >= 0; zfar > 0 and > znear.
    {"camera", kOrtho + R"({"xmag":$,"ymag":1,"znear":0,"zfar":10}})", "-1e-6", "0",
     "xmag must be non-zero"},
    {"camera", kOrtho + R"({"xmag":1,"ymag":$,"znear":0,"zfar":10}})", "1e-6", "0",
     "ymag must be non-zero"},
    {"camera", kOrtho + R"({"xmag":1,"ymag":1,"znear":$,"zfar":10}})", "0", "-1e-6",
     "znear must be >= 0"},
    {"camera", kOrtho + R"({"xmag":1,"ymag":1,"znear":0,"zfar":$}})", "1e-6", "0",
     "zfar must be > 0"},
    {"camera", kOrtho + R"({"xmag":1,"ymag":1,"znear":1,"zfar":$}})", "1.001", "1",
     "zfar must be > znear"},
    // material: alphaCutoff >= 0; the factors in [0, 1] (emissiveFactor too).
    {"material", R"({"alphaCutoff":$})", "0", "-1e-6", "alphaCutoff must be >= 0"},
    {"material", kPbr + R"({"baseColorFactor":[$,0.5,0.5,1]}})", "1", "1.000001",
     "baseColorFactor"},
    {"material", kPbr + R"({"baseColorFactor":[0.5,0.5,0.5,$]}})", "0", "-1e-6", "baseColorFactor"},
    {"material", kPbr + R"({"metallicFactor":$}})", "1", "1.000001", "metallicFactor"},
    {"material", kPbr + R"({"metallicFactor":$}})", "0", "-1e-6", "metallicFactor"},
    {"material", kPbr + R"({"roughnessFactor":$}})", "1", "1.000001", "roughnessFactor"},
    {"material", kPbr + R"({"roughnessFactor":$}})", "0", "-1e-6", "roughnessFactor"},
    {"material", R"({"emissiveFactor":[$,0,0]})", "1", "1.000001", "emissiveFactor"},
    {"material", R"({"emissiveFactor":[0,0,$]})", "0", "-1e-6", "emissiveFactor"},
    // Material extensions.
    {"material", ext("KHR_materials_emissive_strength", R"({"emissiveStrength":$})"), "0", "-1e-6",
     "emissiveStrength"},
    {"material", ext("KHR_materials_ior", R"({"ior":$})"), "1", "0.999999",
     "ior must be 0 or >= 1"},
    {"material", ext("KHR_materials_ior", R"({"ior":$})"), "0", "1e-6", "ior must be 0 or >= 1"},
    {"material", ext("KHR_materials_transmission", R"({"transmissionFactor":$})"), "1", "1.000001",
     "transmissionFactor"},
    {"material", ext("KHR_materials_volume", R"({"thicknessFactor":$})"), "0", "-1e-6",
     "thicknessFactor"},
    {"material", ext("KHR_materials_volume", R"({"attenuationDistance":$})"), "1e-6", "0",
     "attenuationDistance"},
    {"material", ext("KHR_materials_volume", R"({"attenuationColor":[1,1,$]})"), "1", "1.000001",
     "attenuationColor"},
    {"material", ext("KHR_materials_volume", R"({"attenuationColor":[$,1,1]})"), "0", "-1e-6",
     "attenuationColor"},
    {"material", ext("KHR_materials_specular", R"({"specularFactor":$})"), "1", "1.000001",
     "specularFactor"},
    {"material", ext("KHR_materials_specular", R"({"specularColorFactor":[$,1,1]})"), "0", "-1e-6",
     "specularColorFactor"},
    {"material", ext("KHR_materials_clearcoat", R"({"clearcoatFactor":$})"), "1", "1.000001",
     "clearcoatFactor"},
    {"material", ext("KHR_materials_clearcoat", R"({"clearcoatRoughnessFactor":$})"), "0", "-1e-6",
     "clearcoatRoughnessFactor"},
    {"material", ext("KHR_materials_sheen", R"({"sheenColorFactor":[1,$,1]})"), "1", "1.000001",
     "sheenColorFactor"},
    {"material", ext("KHR_materials_sheen", R"({"sheenRoughnessFactor":$})"), "1", "1.000001",
     "sheenRoughnessFactor"},
    {"material", ext("KHR_materials_iridescence", R"({"iridescenceFactor":$})"), "1", "1.000001",
     "iridescenceFactor"},
    {"material", ext("KHR_materials_iridescence", R"({"iridescenceIor":$})"), "1", "0.999999",
     "iridescenceIor"},
    {"material", ext("KHR_materials_iridescence", R"({"iridescenceThicknessMinimum":$})"), "0",
     "-1e-6", "iridescenceThicknessMinimum"},
    {"material", ext("KHR_materials_iridescence", R"({"iridescenceThicknessMaximum":$})"), "0",
     "-1e-6", "iridescenceThicknessMaximum"},
    {"material", ext("KHR_materials_anisotropy", R"({"anisotropyStrength":$})"), "1", "1.000001",
     "anisotropyStrength"},
    {"material", ext("KHR_materials_dispersion", R"({"dispersion":$})"), "0", "-1e-6",
     "dispersion"},
    {"material", ext("KHR_materials_diffuse_transmission", R"({"diffuseTransmissionFactor":$})"),
     "1", "1.000001", "diffuseTransmissionFactor"},
    {"material",
     ext("KHR_materials_diffuse_transmission", R"({"diffuseTransmissionColorFactor":[$,1,1]})"),
     "0", "-1e-6", "diffuseTransmissionColorFactor"},
    // KHR_lights_punctual: intensity >= 0, colour in [0, 1], range > 0 (0 reads as absent),
    // 0 <= innerConeAngle < outerConeAngle <= pi/2.
    {"light", R"({"type":"point","intensity":$})", "0", "-1e-6", "intensity"},
    {"light", R"({"type":"point","color":[1,$,1]})", "1", "1.000001", "color"},
    {"light", R"({"type":"point","range":$})", "1e-6", "-1e-6", "range must be > 0"},
    {"light", R"({"type":"spot","spot":{"innerConeAngle":$}})", "0", "-1e-6", "innerConeAngle"},
    {"light", R"({"type":"spot","spot":{"outerConeAngle":$}})", "1.5707963", "1.5708",
     "outerConeAngle"},
    {"light", R"({"type":"spot","spot":{"innerConeAngle":$,"outerConeAngle":0.5}})", "0.4999",
     "0.5", "is not below outerConeAngle"},
    // sampler: magFilter, minFilter and wrap modes are enums; textureInfo.texCoord >= 0.
    {"sampler", R"({"magFilter":$})", "9729", "9730", "unknown magFilter 9730"},
    {"sampler", R"({"minFilter":$})", "9987", "9988", "unknown minFilter 9988"},
    {"sampler", R"({"minFilter":$})", "9729", "9730", "unknown minFilter 9730"},
    {"sampler", R"({"wrapS":$})", "33648", "33649", "unknown wrapS 33649"},
    {"textureInfo", kPbr + R"({"baseColorTexture":{"index":0,"texCoord":$}}})", "0", "-1",
     "texCoord -1 is negative"},
};

std::string with_value(std::string json, const char* value) {
  json.replace(json.find('$'), 1, value);
  return json;
}

// One triangle and the element of `b` holding `value`, written as a file.
std::string bound_file(const Bound& b, const char* value, const std::string& name) {
  Gltf g = one_triangle("");
  const std::string json = with_value(b.json, value);
  const std::string element = b.element;
  if (element == "camera") {
    g.cameras = {json};
    g.node("\"camera\":0", true);
  } else if (element == "material") {
    g.materials = {json};
  } else if (element == "light") {
    g.top = R"("extensionsUsed":["KHR_lights_punctual"])";
    g.lights = {json};
    g.node(R"("extensions":{"KHR_lights_punctual":{"light":0}})", true);
  } else {  // a texture: its sampler, or the material's texture info
    g.top = test_images() + R"(,"textures":[{"source":0)" +
            (element == "sampler" ? R"(,"sampler":0}],"samplers":[)" + json + "]" : "}]");
    g.materials = {element == "sampler" ? kPbr + R"({"baseColorTexture":{"index":0}}})" : json};
  }
  return g.write(name);
}

TEST(GltfBounds, EachSchemaRuleAcceptsInsideAndRefusesOutside) {
  for (std::size_t i = 0; i < kBounds.size(); ++i) {
    const Bound& b = kBounds[i];
    SCOPED_TRACE(std::string(b.element) + " " + with_value(b.json, "$"));
    const std::string name = "bound" + std::to_string(i);
    EXPECT_NO_THROW(wp::load_gltf(bound_file(b, b.inside, name + "_in.gltf"))) << b.inside;
    const std::string path = bound_file(b, b.outside, name + "_out.gltf");
    expect_error(path, b.error);
    try {
      wp::load_gltf(path);
    } catch (const wp::Error& e) {  // the element is named: "camera 0", "material 0", ...
      const std::string element = std::string(b.element) == "textureInfo" ? "material" : b.element;
      EXPECT_NE(std::string(e.what()).find(element + " 0"), std::string::npos) << e.what();
    }
  }
}

// Values glTF allows but float32 cannot carry through the transport are clamped, one warning per
// element naming it: emission (factor x strength, the colour kept) and a light's colour x
// intensity to 2^64, an index of refraction to 2^16 (scene.h); 1e39, beyond float32, reads as
// FLT_MAX. Values at the limits load as they are, without a warning.
TEST(GltfBounds, ValuesBeyondFloat32AreClampedWithAWarning) {
  const auto load = [](const std::string& material, const std::string& intensity,
                       const std::string& name) {
    Gltf g = one_triangle("");
    g.materials = {material};
    g.top = R"("extensionsUsed":["KHR_lights_punctual"])";
    g.lights = {R"({"type":"point","color":[1,0.5,0],"intensity":)" + intensity + "}"};
    g.node(R"("extensions":{"KHR_lights_punctual":{"light":0}})", true);
    return wp::load_gltf(g.write(name));
  };
  const double limit = wp::kMaxRadiance;
  const wp::Scene s =
      load(R"({"emissiveFactor":[1,0.5,0],"extensions":{"KHR_materials_emissive_strength":)"
           R"({"emissiveStrength":3.4e38},"KHR_materials_ior":{"ior":1e39},)"
           R"("KHR_materials_iridescence":{"iridescenceFactor":1,"iridescenceIor":1e30},)"
           R"("KHR_materials_dispersion":{"dispersion":1e30}}})",
           "1e38", "clamped.gltf");
  EXPECT_EQ(s.materials[0].emission, glm::vec3(float(limit), float(limit / 2), 0.0f));
  EXPECT_EQ(s.materials[0].ior, float(wp::kMaxIor));
  EXPECT_EQ(s.materials[0].iridescence_ior, float(wp::kMaxIor));
  EXPECT_EQ(s.materials[0].dispersion, float(wp::kMaxDispersion));
  EXPECT_EQ(s.lights[0].intensity, glm::vec3(float(limit), float(limit / 2), 0.0f));
  const std::vector<std::string> expected = {
      "material 0 '': emission 3.4e+38 clamped to 1.84467e+19",
      "material 0 '': ior 3.40282e+38 clamped to 65536",
      "material 0 '': iridescenceIor 1e+30 clamped to 65536",
      "material 0 '': dispersion 1e+30 clamped to 65536",
      "light 0 '': intensity 1e+38 clamped to 1.84467e+19"};
  ASSERT_EQ(s.warnings.size(), expected.size()) << join(s.warnings);
  for (std::size_t i = 0; i < expected.size(); ++i)
    EXPECT_NE(s.warnings[i].find(expected[i]), std::string::npos) << s.warnings[i];

  const wp::Scene at =
      load(R"({"emissiveFactor":[1,1,1],"extensions":{)"
           R"("KHR_materials_emissive_strength":{"emissiveStrength":1.8446744e19},)"
           R"("KHR_materials_ior":{"ior":65536},"KHR_materials_dispersion":{"dispersion":65536}}})",
           "1.8446744e19", "at_limits.gltf");
  EXPECT_TRUE(at.warnings.empty()) << join(at.warnings);
  EXPECT_EQ(at.materials[0].ior, 65536.0f);
  EXPECT_EQ(at.materials[0].dispersion, 65536.0f);
  // Just above the dispersion's limit: clamped, with its warning.
  const wp::Scene above = load(
      R"({"extensions":{"KHR_materials_dispersion":{"dispersion":65537}}})", "0", "above.gltf");
  EXPECT_EQ(above.materials[0].dispersion, 65536.0f);
  ASSERT_EQ(above.warnings.size(), 1u) << join(above.warnings);
  EXPECT_NE(above.warnings[0].find("dispersion 65537 clamped to 65536"), std::string::npos)
      << above.warnings[0];
}

}  // namespace
