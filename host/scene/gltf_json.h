// Members of extension objects (tinygltf::Value), read with the checks glTF's schemas make: the
// compressed-data extensions (gltf_meshopt.cpp, gltf_draco.cpp, gltf_textures.cpp) share them.
// Each throws wp::Error "WHERE: FIELD ..." naming the value's place.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>

#include <tiny_gltf.h>

#include "host/util/error.h"

namespace wp::gltf {

// The object of extension `name` in `extensions`, or null when absent; throws when it is not an
// object.
inline const tinygltf::Value* extension_object(const tinygltf::ExtensionMap& extensions,
                                               const char* name, const std::string& where) {
  const auto it = extensions.find(name);
  if (it == extensions.end()) return nullptr;
  if (!it->second.IsObject()) throw Error(where + ": " + name + " is not an object");
  return &it->second;
}

// A whole number >= `minimum` below 2^53 (JSON's exact integers): member `field` of `object`, or
// `fallback` when absent and not `required`.
inline std::uint64_t count_member(const tinygltf::Value& object, const char* field,
                                  const std::string& where, bool required,
                                  std::uint64_t fallback = 0, std::uint64_t minimum = 0) {
  if (!object.Has(field)) {
    if (required) throw Error(where + ": " + field + " is missing");
    return fallback;
  }
  const tinygltf::Value& v = object.Get(field);
  const double d = v.IsNumber() ? v.GetNumberAsDouble() : -1.0;
  if (!(d >= double(minimum)) || d >= 9007199254740992.0 || std::floor(d) != d)
    throw Error(where + ": " + field + " must be a whole number >= " + std::to_string(minimum));
  return static_cast<std::uint64_t>(d);
}

// A string member, or `fallback` when absent and not `required`.
inline std::string string_member(const tinygltf::Value& object, const char* field,
                                 const std::string& where, bool required,
                                 const std::string& fallback = "") {
  if (!object.Has(field)) {
    if (required) throw Error(where + ": " + field + " is missing");
    return fallback;
  }
  const tinygltf::Value& v = object.Get(field);
  if (!v.IsString()) throw Error(where + ": " + field + " is not a string");
  return v.Get<std::string>();
}

}  // namespace wp::gltf
