#include "host/scene/gltf_material.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "host/util/error.h"
#include "host/scene/gltf_values.h"

namespace wp::gltf {
namespace {

// Why an index of refraction above kMaxIor (scene.h) is clamped, for the warning.
constexpr const char* kIorLimit =
    "the largest index of refraction float32 carries through the transport";

// The object of material extension `name`, or null when the material does not use it. (tinygltf
// drops extension values that are not objects, and empty arrays and objects inside them: such
// fields read as absent.)
const tinygltf::Value* extension(const tinygltf::Material& m, const char* name,
                                 const std::string& where) {
  const auto it = m.extensions.find(name);
  if (it == m.extensions.end()) return nullptr;
  if (!it->second.IsObject()) throw Error(where + ": " + name + " is not an object");
  return &it->second;
}

// A number field of extension object `ext` (may be null), or `fallback` when either is absent.
float number(const tinygltf::Value* ext, const char* name, const char* field, float fallback,
             const std::string& where) {
  if (!ext || !ext->Has(field)) return fallback;
  const tinygltf::Value& v = ext->Get(field);
  if (!v.IsNumber()) throw Error(where + ": " + name + "." + field + " is not a number");
  return finite(v.GetNumberAsDouble(), where, field);
}

// A number field of `ext` within [lo, hi], or `fallback`.
float number_in(const tinygltf::Value* ext, const char* name, const char* field, float fallback,
                double lo, double hi, const std::string& where) {
  if (!ext || !ext->Has(field)) return fallback;
  return in_range(number(ext, name, field, fallback, where), lo, hi, where, field);
}

// An RGB field of `ext` with every component within [lo, hi], or `fallback`.
glm::vec3 color_in(const tinygltf::Value* ext, const char* field, glm::vec3 fallback, double lo,
                   double hi, const std::string& where) {
  if (!ext || !ext->Has(field)) return fallback;
  const tinygltf::Value& c = ext->Get(field);
  if (!c.IsArray() || c.ArrayLen() != 3) throw Error(where + ": " + field + " needs 3 numbers");
  glm::vec3 out;
  for (int i = 0; i < 3; ++i) {
    if (!c.Get(i).IsNumber()) throw Error(where + ": " + field + " is not numbers");
    out[i] = in_range(c.Get(i).GetNumberAsDouble(), lo, hi, where, field);
  }
  return out;
}

// The textureInfo field `field` of `ext` added to `textures` (-1: absent or unusable).
int texture(const tinygltf::Value* ext, const char* field, bool srgb, TextureTable& textures,
            const std::string& where) {
  if (!ext || !ext->Has(field)) return -1;
  const std::string at = where + ": " + field;
  return textures.add(texture_info(ext->Get(field), at), srgb, at);
}

// A number from material extension `name`, or `fallback` when the extension or the field is
// absent.
float extension_number(const tinygltf::Material& m, const char* name, const char* field,
                       float fallback, const std::string& where) {
  return number(extension(m, name, where), name, field, fallback, where);
}

AlphaMode alpha_mode(const std::string& mode, const std::string& where) {
  if (mode == "OPAQUE") return AlphaMode::kOpaque;
  if (mode == "MASK") return AlphaMode::kMask;
  if (mode == "BLEND") return AlphaMode::kBlend;
  throw Error(where + ": unknown alphaMode '" + mode + "'");
}

// KHR_materials_volume: thickness, attenuation colour and distance (absent: infinite, stored 0).
void read_volume(const tinygltf::Material& in, const std::string& where, Material& out) {
  const char* kName = "KHR_materials_volume";
  const tinygltf::Value* ext = extension(in, kName, where);
  if (!ext) return;
  out.thickness = extension_number(in, kName, "thicknessFactor", 0.0f, where);
  if (out.thickness < 0.0f) throw Error(where + ": negative thicknessFactor");
  out.attenuation_distance = extension_number(in, kName, "attenuationDistance", 0.0f, where);
  if (ext->Has("attenuationDistance") && !(out.attenuation_distance > 0.0f))
    throw Error(where + ": attenuationDistance must be positive");
  if (ext->Has("attenuationColor")) {
    const tinygltf::Value& c = ext->Get("attenuationColor");
    if (!c.IsArray() || c.ArrayLen() != 3)
      throw Error(where + ": attenuationColor needs 3 numbers");
    for (int i = 0; i < 3; ++i) {
      if (!c.Get(i).IsNumber()) throw Error(where + ": attenuationColor is not numbers");
      out.attenuation_color[i] =
          in_range(c.Get(i).GetNumberAsDouble(), 0.0, 1.0, where, "attenuationColor");
    }
  }
}

// Emission is emissiveFactor x emissive strength, in double: a strength near FLT_MAX is valid
// glTF but no radiance float32 can carry through the transport (scene.h: kMaxRadiance).
void read_emission(const tinygltf::Material& in, const std::string& where, Material& out,
                   std::vector<std::string>* warnings) {
  if (in.emissiveFactor.size() != 3)  // tinygltf fills [0, 0, 0] when absent
    throw Error(where + ": emissiveFactor needs 3 numbers, has " +
                std::to_string(in.emissiveFactor.size()));
  const float strength =
      extension_number(in, "KHR_materials_emissive_strength", "emissiveStrength", 1.0f, where);
  if (strength < 0.0f) throw Error(where + ": negative emissiveStrength");
  float factor[3];
  double brightest = 0.0;
  for (int i = 0; i < 3; ++i) {
    factor[i] =
        in_range(in.emissiveFactor[static_cast<std::size_t>(i)], 0.0, 1.0, where, "emissiveFactor");
    brightest = std::max(brightest, double(factor[i]) * double(strength));
  }
  const double limited = at_most(brightest, kMaxRadiance, where, "emission",
                                 "emissiveFactor x emissive strength; the most radiance wavepath "
                                 "carries",
                                 warnings);
  // Within the limit, the float product as before the limit existed (the same images bit for
  // bit); beyond it, one scale for the three channels keeps the colour.
  for (int i = 0; i < 3; ++i)
    out.emission[i] = limited < brightest
                          ? static_cast<float>(double(factor[i]) * strength * (limited / brightest))
                          : factor[i] * strength;
}

void read_factors(const tinygltf::Material& in, const std::string& where, Material& out,
                  std::vector<std::string>* warnings) {
  const tinygltf::PbrMetallicRoughness& pbr = in.pbrMetallicRoughness;
  if (pbr.baseColorFactor.size() != 4)
    throw Error(where + ": baseColorFactor needs 4 numbers, has " +
                std::to_string(pbr.baseColorFactor.size()));
  // Factors outside glTF's [0, 1] are errors (as for the Khronos validator): a negative colour
  // gave negative radiance, which the film cannot hold (kernels/shared/film.h).
  for (int i = 0; i < 4; ++i)
    out.base_color[i] = in_range(pbr.baseColorFactor[static_cast<std::size_t>(i)], 0.0, 1.0, where,
                                 "baseColorFactor");
  out.metallic = in_range(pbr.metallicFactor, 0.0, 1.0, where, "metallicFactor");
  out.roughness = in_range(pbr.roughnessFactor, 0.0, 1.0, where, "roughnessFactor");

  read_emission(in, where, out, warnings);

  out.double_sided = in.doubleSided;
  out.alpha_mode = alpha_mode(in.alphaMode, where);
  out.alpha_cutoff = finite(in.alphaCutoff, where, "alphaCutoff");
  require(in.alphaCutoff >= 0.0, where, "alphaCutoff", ">= 0", in.alphaCutoff);
  out.ior = extension_number(in, "KHR_materials_ior", "ior", 1.5f, where);
  require(out.ior == 0.0f || out.ior >= 1.0f, where, "ior", "0 or >= 1", out.ior);
  out.ior = float(at_most(out.ior, kMaxIor, where, "ior", kIorLimit, warnings));
  out.transmission = in_range(
      extension_number(in, "KHR_materials_transmission", "transmissionFactor", 0.0f, where), 0.0,
      1.0, where, "transmissionFactor");
  out.unlit = in.extensions.count("KHR_materials_unlit") != 0;
  read_volume(in, where, out);
}

// KHR_materials_specular: the factor scales the dielectric Fresnel term (F0 and F90), the colour
// tints F0 (kernels/bsdf/bsdf.h). specularColorFactor may exceed 1: the product with F0 is clamped.
void read_specular(const tinygltf::Material& in, const std::string& where, TextureTable& textures,
                   Material& out) {
  const char* kName = "KHR_materials_specular";
  const tinygltf::Value* ext = extension(in, kName, where);
  out.specular = number_in(ext, kName, "specularFactor", 1.0f, 0.0, 1.0, where);
  out.specular_color = color_in(ext, "specularColorFactor", glm::vec3(1.0f), 0.0, INFINITY, where);
  out.specular_texture = texture(ext, "specularTexture", false, textures, where);
  out.specular_color_texture = texture(ext, "specularColorTexture", true, textures, where);
}

// KHR_materials_clearcoat: a dielectric coat (ior 1.5) of its own roughness and normal texture.
void read_clearcoat(const tinygltf::Material& in, const std::string& where, TextureTable& textures,
                    Material& out) {
  const char* kName = "KHR_materials_clearcoat";
  const tinygltf::Value* ext = extension(in, kName, where);
  out.clearcoat = number_in(ext, kName, "clearcoatFactor", 0.0f, 0.0, 1.0, where);
  out.clearcoat_roughness =
      number_in(ext, kName, "clearcoatRoughnessFactor", 0.0f, 0.0, 1.0, where);
  out.clearcoat_texture = texture(ext, "clearcoatTexture", false, textures, where);
  out.clearcoat_roughness_texture =
      texture(ext, "clearcoatRoughnessTexture", false, textures, where);
  if (ext && ext->Has("clearcoatNormalTexture"))  // a normalTextureInfo: its scale
    out.clearcoat_normal_scale =
        number(&ext->Get("clearcoatNormalTexture"), "clearcoatNormalTexture", "scale", 1.0f, where);
  out.clearcoat_normal_texture = texture(ext, "clearcoatNormalTexture", false, textures, where);
}

// KHR_materials_sheen: a Charlie sheen lobe, off while the colour is black.
void read_sheen(const tinygltf::Material& in, const std::string& where, TextureTable& textures,
                Material& out) {
  const char* kName = "KHR_materials_sheen";
  const tinygltf::Value* ext = extension(in, kName, where);
  out.sheen_color = color_in(ext, "sheenColorFactor", glm::vec3(0.0f), 0.0, 1.0, where);
  out.sheen_roughness = number_in(ext, kName, "sheenRoughnessFactor", 0.0f, 0.0, 1.0, where);
  out.sheen_color_texture = texture(ext, "sheenColorTexture", true, textures, where);
  out.sheen_roughness_texture = texture(ext, "sheenRoughnessTexture", false, textures, where);
}

// KHR_materials_anisotropy: strength in [0, 1]; the rotation (radians, from the tangent toward
// the bitangent) may be any angle.
void read_anisotropy(const tinygltf::Material& in, const std::string& where, TextureTable& textures,
                     Material& out) {
  const char* kName = "KHR_materials_anisotropy";
  const tinygltf::Value* ext = extension(in, kName, where);
  out.anisotropy_strength = number_in(ext, kName, "anisotropyStrength", 0.0f, 0.0, 1.0, where);
  out.anisotropy_rotation = number(ext, kName, "anisotropyRotation", 0.0f, where);
  out.anisotropy_texture = texture(ext, "anisotropyTexture", false, textures, where);
}

// KHR_materials_iridescence: a thin film of index iridescenceIor (at least 1) and a thickness
// between the minimum and the maximum (nanometres, the maximum without a thickness texture).
void read_iridescence(const tinygltf::Material& in, const std::string& where,
                      TextureTable& textures, Material& out, std::vector<std::string>* warnings) {
  const char* kName = "KHR_materials_iridescence";
  const tinygltf::Value* ext = extension(in, kName, where);
  out.iridescence = number_in(ext, kName, "iridescenceFactor", 0.0f, 0.0, 1.0, where);
  out.iridescence_ior =
      float(at_most(number_in(ext, kName, "iridescenceIor", 1.3f, 1.0, INFINITY, where), kMaxIor,
                    where, "iridescenceIor", kIorLimit, warnings));
  out.iridescence_thickness_min =
      number_in(ext, kName, "iridescenceThicknessMinimum", 100.0f, 0.0, INFINITY, where);
  out.iridescence_thickness_max =
      number_in(ext, kName, "iridescenceThicknessMaximum", 400.0f, 0.0, INFINITY, where);
  out.iridescence_texture = texture(ext, "iridescenceTexture", false, textures, where);
  out.iridescence_thickness_texture =
      texture(ext, "iridescenceThicknessTexture", false, textures, where);
}

// KHR_materials_diffuse_transmission: the share of the diffuse lobe transmitted, and its colour.
void read_diffuse_transmission(const tinygltf::Material& in, const std::string& where,
                               TextureTable& textures, Material& out) {
  const char* kName = "KHR_materials_diffuse_transmission";
  const tinygltf::Value* ext = extension(in, kName, where);
  out.diffuse_transmission =
      number_in(ext, kName, "diffuseTransmissionFactor", 0.0f, 0.0, 1.0, where);
  out.diffuse_transmission_color =
      color_in(ext, "diffuseTransmissionColorFactor", glm::vec3(1.0f), 0.0, 1.0, where);
  out.diffuse_transmission_texture =
      texture(ext, "diffuseTransmissionTexture", false, textures, where);
  out.diffuse_transmission_color_texture =
      texture(ext, "diffuseTransmissionColorTexture", true, textures, where);
}

// The core textures and KHR_materials_transmission's. Colour textures (base colour, emissive, and
// the extensions' colour textures) are sRGB-encoded; the others hold linear data.
void read_textures(const tinygltf::Material& in, const std::string& where, TextureTable& textures,
                   Material& out) {
  const tinygltf::PbrMetallicRoughness& pbr = in.pbrMetallicRoughness;
  out.base_color_texture =
      textures.add(texture_info(pbr.baseColorTexture), true, where + ": baseColorTexture");
  out.metallic_roughness_texture = textures.add(texture_info(pbr.metallicRoughnessTexture), false,
                                                where + ": metallicRoughnessTexture");
  out.normal_texture =
      textures.add(texture_info(in.normalTexture), false, where + ": normalTexture");
  out.normal_scale = finite(in.normalTexture.scale, where, "normalTexture.scale");
  out.emissive_texture =
      textures.add(texture_info(in.emissiveTexture), true, where + ": emissiveTexture");
  out.transmission_texture = texture(extension(in, "KHR_materials_transmission", where),
                                     "transmissionTexture", false, textures, where);
  // The volume's thickness texture is checked, not read: a path tracer has the real geometry.
  const tinygltf::Value* volume = extension(in, "KHR_materials_volume", where);
  if (volume && volume->Has("thicknessTexture")) {
    const std::string at = where + ": thicknessTexture";
    textures.check(texture_info(volume->Get("thicknessTexture"), at), at);
  }
}

}  // namespace

Material default_material() {
  Material m;
  m.name = "default";
  return m;  // Material's member defaults are glTF's
}

Material convert_material(const tinygltf::Model& model, int index, TextureTable& textures,
                          std::vector<std::string>* warnings) {
  if (index < 0 || static_cast<std::size_t>(index) >= model.materials.size())
    throw Error("material " + std::to_string(index) + " does not exist");
  const tinygltf::Material& in = model.materials[static_cast<std::size_t>(index)];
  const std::string where = "material " + std::to_string(index) + " '" + in.name + "'";
  Material out;
  out.name = in.name;
  read_factors(in, where, out, warnings);
  read_textures(in, where, textures, out);
  read_specular(in, where, textures, out);
  read_clearcoat(in, where, textures, out);
  read_sheen(in, where, textures, out);
  read_anisotropy(in, where, textures, out);
  read_iridescence(in, where, textures, out, warnings);
  out.dispersion =
      float(at_most(number_in(extension(in, "KHR_materials_dispersion", where),
                              "KHR_materials_dispersion", "dispersion", 0.0f, 0.0, INFINITY, where),
                    kMaxDispersion, where, "dispersion",
                    "an Abbe number of 20 / 65536; the kernels' index per wavelength "
                    "stays within float32",
                    warnings));
  read_diffuse_transmission(in, where, textures, out);
  return out;
}

}  // namespace wp::gltf
