// wavepath's glTF extension support, in one table: the loader refuses and warns from it, and
// `wavepath info` reports from it, so the two cannot disagree. README.md's glTF extension table
// lists the same names with the same status (tests/gltf/test_gltf_extensions.cpp compares them).
//
// Each extension a file lists gets one status:
//   supported: wavepath reads it (whether the file requires it or only uses it);
//   ignored:   an optional extension wavepath does not read; the file loads without it, with a
//              warning saying what that means (e.g. EXT_mesh_gpu_instancing: each node's mesh
//              placed once, at the node's own transform);
//   refused:   a required extension wavepath does not read; the file is not loaded.
// An extension missing from the table is treated like an ignored one of the table, with a
// generic note.
#pragma once

#include <string>
#include <vector>

#include "host/util/error.h"

namespace wp {

enum class ExtensionSupport { kSupported, kIgnored, kRefused };

// "supported", "ignored", "refused".
const char* extension_support_name(ExtensionSupport support);

// An extension wavepath knows: supported, or ignored when optional (refused when required).
struct KnownExtension {
  const char* name;
  bool supported;
  const char* note;  // what wavepath does with it, one short phrase
};

// The table, sorted by name.
const std::vector<KnownExtension>& known_extensions();

// One extension as a file lists it, with what wavepath does with it.
struct ExtensionUse {
  std::string name;
  bool required = false;  // in extensionsRequired
  ExtensionSupport support = ExtensionSupport::kIgnored;
  std::string note;  // the table's, or a generic one for an unknown extension
};

// The extensions of `used` (extensionsUsed) and `required` (extensionsRequired; glTF has them
// in `used` too, but a file that lists one only there is read the same way), in the order of
// `used` then the rest of `required`, each once.
std::vector<ExtensionUse> extension_uses(const std::vector<std::string>& used,
                                         const std::vector<std::string>& required);

// Thrown by the loader when a file requires extensions wavepath does not support (status
// refused); `uses` is every extension the file lists, for reports.
class RefusedExtensions : public Error {
 public:
  RefusedExtensions(const std::string& message, std::vector<ExtensionUse> uses)
      : Error(message), uses_(std::move(uses)) {}
  const std::vector<ExtensionUse>& uses() const { return uses_; }

 private:
  std::vector<ExtensionUse> uses_;
};

}  // namespace wp
