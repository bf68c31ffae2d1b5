#include "host/gltf_material.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "host/error.h"

namespace wp::gltf {
namespace {

float finite(double value, const std::string& where, const char* field) {
  if (!std::isfinite(value)) throw Error(where + ": " + field + " is not a finite number");
  return static_cast<float>(value);
}

// A number from a material extension's object, or `fallback` when the extension or the field is
// absent.
float extension_number(const tinygltf::Material& m, const char* extension, const char* field,
                       float fallback, const std::string& where) {
  const auto it = m.extensions.find(extension);
  if (it == m.extensions.end() || !it->second.IsObject() || !it->second.Has(field)) return fallback;
  const tinygltf::Value& v = it->second.Get(field);
  if (!v.IsNumber()) throw Error(where + ": " + extension + "." + field + " is not a number");
  return finite(v.GetNumberAsDouble(), where, field);
}

AlphaMode alpha_mode(const std::string& mode, const std::string& where) {
  if (mode == "OPAQUE") return AlphaMode::kOpaque;
  if (mode == "MASK") return AlphaMode::kMask;
  if (mode == "BLEND") return AlphaMode::kBlend;
  throw Error(where + ": unknown alphaMode '" + mode + "'");
}

}  // namespace

Material default_material() {
  Material m;
  m.name = "default";
  return m;  // Material's member defaults are glTF's
}

Material convert_material(const tinygltf::Model& model, int index) {
  if (index < 0 || static_cast<std::size_t>(index) >= model.materials.size())
    throw Error("material " + std::to_string(index) + " does not exist");
  const tinygltf::Material& in = model.materials[static_cast<std::size_t>(index)];
  const std::string where = "material " + std::to_string(index) + " '" + in.name + "'";
  const tinygltf::PbrMetallicRoughness& pbr = in.pbrMetallicRoughness;

  Material out;
  out.name = in.name;
  if (pbr.baseColorFactor.size() != 4)
    throw Error(where + ": baseColorFactor needs 4 numbers, has " +
                std::to_string(pbr.baseColorFactor.size()));
  for (int i = 0; i < 4; ++i)
    out.base_color[i] =
        finite(pbr.baseColorFactor[static_cast<std::size_t>(i)], where, "baseColorFactor");
  // Factors outside glTF's [0, 1] ranges would only make the shading code misbehave.
  out.metallic = std::clamp(finite(pbr.metallicFactor, where, "metallicFactor"), 0.0f, 1.0f);
  out.roughness = std::clamp(finite(pbr.roughnessFactor, where, "roughnessFactor"), 0.0f, 1.0f);

  if (in.emissiveFactor.size() != 3)  // tinygltf fills [0, 0, 0] when absent
    throw Error(where + ": emissiveFactor needs 3 numbers, has " +
                std::to_string(in.emissiveFactor.size()));
  const float strength =
      extension_number(in, "KHR_materials_emissive_strength", "emissiveStrength", 1.0f, where);
  if (strength < 0.0f) throw Error(where + ": negative emissiveStrength");
  for (int i = 0; i < 3; ++i)
    out.emission[i] =
        finite(in.emissiveFactor[static_cast<std::size_t>(i)], where, "emissiveFactor") * strength;

  out.double_sided = in.doubleSided;
  out.alpha_mode = alpha_mode(in.alphaMode, where);
  out.alpha_cutoff = finite(in.alphaCutoff, where, "alphaCutoff");
  out.ior = extension_number(in, "KHR_materials_ior", "ior", 1.5f, where);
  out.transmission = std::clamp(
      extension_number(in, "KHR_materials_transmission", "transmissionFactor", 0.0f, where), 0.0f,
      1.0f);
  return out;
}

}  // namespace wp::gltf
