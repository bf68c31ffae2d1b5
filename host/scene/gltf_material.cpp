#include "host/scene/gltf_material.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "host/util/error.h"
#include "host/scene/gltf_values.h"

namespace wp::gltf {
namespace {

// The object of material extension `name`, or null when the material does not use it.
const tinygltf::Value* extension(const tinygltf::Material& m, const char* name,
                                 const std::string& where) {
  const auto it = m.extensions.find(name);
  if (it == m.extensions.end()) return nullptr;
  if (!it->second.IsObject()) throw Error(where + ": " + name + " is not an object");
  return &it->second;
}

// A number from a material extension's object, or `fallback` when the extension or the field is
// absent.
float extension_number(const tinygltf::Material& m, const char* name, const char* field,
                       float fallback, const std::string& where) {
  const tinygltf::Value* ext = extension(m, name, where);
  if (!ext || !ext->Has(field)) return fallback;
  const tinygltf::Value& v = ext->Get(field);
  if (!v.IsNumber()) throw Error(where + ": " + name + "." + field + " is not a number");
  return finite(v.GetNumberAsDouble(), where, field);
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
      out.attenuation_color[i] = finite(c.Get(i).GetNumberAsDouble(), where, "attenuationColor");
    }
  }
}

void read_factors(const tinygltf::Material& in, const std::string& where, Material& out) {
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

  if (in.emissiveFactor.size() != 3)  // tinygltf fills [0, 0, 0] when absent
    throw Error(where + ": emissiveFactor needs 3 numbers, has " +
                std::to_string(in.emissiveFactor.size()));
  const float strength =
      extension_number(in, "KHR_materials_emissive_strength", "emissiveStrength", 1.0f, where);
  if (strength < 0.0f) throw Error(where + ": negative emissiveStrength");
  for (int i = 0; i < 3; ++i)
    out.emission[i] = in_range(in.emissiveFactor[static_cast<std::size_t>(i)], 0.0, 1.0, where,
                               "emissiveFactor") *
                      strength;

  out.double_sided = in.doubleSided;
  out.alpha_mode = alpha_mode(in.alphaMode, where);
  out.alpha_cutoff = finite(in.alphaCutoff, where, "alphaCutoff");
  out.ior = extension_number(in, "KHR_materials_ior", "ior", 1.5f, where);
  out.transmission = in_range(
      extension_number(in, "KHR_materials_transmission", "transmissionFactor", 0.0f, where), 0.0,
      1.0, where, "transmissionFactor");
  out.unlit = in.extensions.count("KHR_materials_unlit") != 0;
  read_volume(in, where, out);
  // KHR_materials_specular: the factor scales the dielectric Fresnel term (kernels/bsdf.h);
  // specularColorFactor and the two textures are not applied yet.
  out.specular =
      in_range(extension_number(in, "KHR_materials_specular", "specularFactor", 1.0f, where), 0.0,
               1.0, where, "specularFactor");
}

// Colour textures (base colour, emissive) are sRGB-encoded; the others hold linear data.
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
  const tinygltf::Value* transmission = extension(in, "KHR_materials_transmission", where);
  if (transmission && transmission->Has("transmissionTexture")) {
    const std::string at = where + ": transmissionTexture";
    out.transmission_texture =
        textures.add(texture_info(transmission->Get("transmissionTexture"), at), false, at);
  }
}

}  // namespace

Material default_material() {
  Material m;
  m.name = "default";
  return m;  // Material's member defaults are glTF's
}

Material convert_material(const tinygltf::Model& model, int index, TextureTable& textures) {
  if (index < 0 || static_cast<std::size_t>(index) >= model.materials.size())
    throw Error("material " + std::to_string(index) + " does not exist");
  const tinygltf::Material& in = model.materials[static_cast<std::size_t>(index)];
  const std::string where = "material " + std::to_string(index) + " '" + in.name + "'";
  Material out;
  out.name = in.name;
  read_factors(in, where, out);
  read_textures(in, where, textures, out);
  return out;
}

}  // namespace wp::gltf
