#include "host/scene/gltf_prepass.h"

#include <algorithm>
#include <cstdint>
#include <string_view>

#include <nlohmann/json.hpp>

namespace wp::gltf {
namespace {

using nlohmann::json;

constexpr const char* kMeshopt = "EXT_meshopt_compression";
constexpr const char* kDraco = "KHR_draco_mesh_compression";

// What a placeholder buffer becomes for tinygltf: one byte, dropped after parsing.
constexpr const char* kOneByte = "data:application/octet-stream;base64,AA==";

bool lists(const json& doc, const char* name) {
  for (const char* key : {"extensionsUsed", "extensionsRequired"}) {
    const auto it = doc.find(key);
    if (it != doc.end() && it->is_array() &&
        std::any_of(it->begin(), it->end(),
                    [&](const json& v) { return v.is_string() && v == name; }))
      return true;
  }
  return false;
}

// object.extensions.NAME when it is an object, else null.
const json* extension(const json& object, const char* name) {
  const auto ext = object.find("extensions");
  if (ext == object.end() || !ext->is_object()) return nullptr;
  const auto it = ext->find(name);
  return it != ext->end() && it->is_object() ? &*it : nullptr;
}

bool marked_fallback(const json& buffer) {
  const json* meshopt = extension(buffer, kMeshopt);
  if (!meshopt) return false;
  const auto fallback = meshopt->find("fallback");
  return fallback != meshopt->end() && fallback->is_boolean() && fallback->get<bool>();
}

bool meshopt_placeholders(json& doc, bool glb, PlaceholderBuffers* placeholders) {
  const auto buffers = doc.find("buffers");
  if (buffers == doc.end() || !buffers->is_array()) return false;
  bool changed = false;
  for (std::size_t i = 0; i < buffers->size(); ++i) {
    json& b = (*buffers)[i];
    if (!b.is_object()) continue;
    if (!marked_fallback(b) && (b.contains("uri") || (glb && i == 0))) continue;
    const auto length = b.find("byteLength");
    std::uint64_t declared = 0;
    if (length != b.end() && length->is_number_unsigned()) declared = length->get<std::uint64_t>();
    (*placeholders)[static_cast<int>(i)] = declared;
    b["uri"] = kOneByte;
    b["byteLength"] = 1;
    changed = true;
  }
  return changed;
}

bool draco_indices(json& doc) {
  const auto meshes = doc.find("meshes");
  const auto accessors = doc.find("accessors");
  if (meshes == doc.end() || !meshes->is_array() || accessors == doc.end() ||
      !accessors->is_array())
    return false;
  bool changed = false;
  for (const json& mesh : *meshes) {
    const auto primitives = mesh.is_object() ? mesh.find("primitives") : mesh.end();
    if (primitives == mesh.end() || !primitives->is_array()) continue;
    for (const json& p : *primitives) {
      if (!p.is_object()) continue;
      const json* draco = extension(p, kDraco);
      const auto indices = p.find("indices");
      if (!draco || indices == p.end() || !indices->is_number_unsigned()) continue;
      const auto view = draco->find("bufferView");
      const std::uint64_t index = indices->get<std::uint64_t>();
      if (view == draco->end() || !view->is_number_unsigned() || index >= accessors->size())
        continue;
      json& accessor = (*accessors)[index];
      if (!accessor.is_object() || accessor.contains("bufferView")) continue;
      accessor["bufferView"] = *view;
      changed = true;
    }
  }
  return changed;
}

}  // namespace

bool mentions_compression(const char* text, std::size_t size) {
  const std::string_view view(text, size);
  return view.find(kMeshopt) != std::string_view::npos ||
         view.find(kDraco) != std::string_view::npos;
}

bool prepare_compressed_json(std::string& text, bool glb, PlaceholderBuffers* placeholders) {
  if (!mentions_compression(text.data(), text.size())) return false;
  json doc = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!doc.is_object()) return false;
  bool changed = false;
  if (lists(doc, kMeshopt)) changed |= meshopt_placeholders(doc, glb, placeholders);
  if (lists(doc, kDraco)) changed |= draco_indices(doc);
  if (changed) text = doc.dump();
  return changed;
}

}  // namespace wp::gltf
