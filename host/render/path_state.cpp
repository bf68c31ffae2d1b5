#include "host/render/path_state.h"

#include <sstream>
#include <string>

#include "host/util/error.h"

namespace wp {

namespace {
// Whether `features` names (space-separated WP_FEATURE_* macros) one the program is built with.
bool uses_any(const SceneFeatures& scene, const std::string& features) {
  std::istringstream names(features);
  for (std::string name; names >> name;)
    for (const auto& [macro, on] : scene.flags())
      if (macro == name && on) return true;
  return false;
}
}  // namespace

PathStateLayout path_state_layout(std::size_t capacity, bool aov, const SceneFeatures& features,
                                  bool fused) {
  using namespace dev;
  PathStateLayout s;
  std::size_t offset = 0;
  const auto place = [&](std::size_t element_size) {
    const std::size_t at = offset;
    offset = (offset + element_size * capacity + 63) & ~std::size_t(63);
    s.bytes_per_path += element_size;
    if (offset > 0xffffffffu)
      throw Error("path state too large for 32-bit offsets; use a smaller wave");
    return static_cast<uint>(at);
  };
#define WP_PATH_FIELD(type, name, description) s.layout.name = place(sizeof(type));
#define WP_PATH_AOV_FIELD(type, name, description) s.layout.name = place(aov ? sizeof(type) : 0);
#define WP_PATH_INSTANCE_FIELD(type, name, description) \
  s.layout.name = place(features.instances ? sizeof(type) : 0);
#define WP_PATH_SURF_FIELD(type, name, description) s.layout.name = place(fused ? 0 : sizeof(type));
#define WP_PATH_OPT_FIELD(needs, type, name, description) \
  s.layout.name = place(!fused && uses_any(features, needs) ? sizeof(type) : 0);
#define WP_PATH_ALIAS_FIELD(type, name, other, description) \
  s.layout.name = fused ? s.layout.other : place(sizeof(type));
#include "kernels/shared/path_state.def"
#undef WP_PATH_ALIAS_FIELD
#undef WP_PATH_OPT_FIELD
#undef WP_PATH_SURF_FIELD
#undef WP_PATH_INSTANCE_FIELD
#undef WP_PATH_AOV_FIELD
#undef WP_PATH_FIELD
  s.layout.capacity = static_cast<uint>(capacity);
  s.bytes = offset;
  return s;
}

}  // namespace wp
