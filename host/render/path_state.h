// The path-state buffer: every field of kernels/shared/path_state.def for `capacity` path slots,
// each field a 64-byte aligned array in one buffer.
#pragma once

#include <cstddef>

#include "host/device/scene_features.h"
#include "kernels/shared/types.h"

namespace wp {

struct PathStateLayout {
  dev::PathLayout layout{};  // byte offsets per field, passed to every kernel
  std::size_t bytes = 0;     // total buffer size
  std::size_t bytes_per_path = 0;
};

// `aov`: with the AOV fields (WP_PATH_AOV_FIELD), else those take no memory. `fused`: for the
// fused pipeline, which keeps no surface record (WP_PATH_SURF_FIELD, WP_PATH_OPT_FIELD take no
// memory) and lays the shadow ray's origin over the hit record (WP_PATH_ALIAS_FIELD); the split
// pipeline's surface fields of material extensions (WP_PATH_OPT_FIELD) take memory only when
// `features` has one they name.
PathStateLayout path_state_layout(std::size_t capacity, bool aov = false,
                                  const SceneFeatures& features = SceneFeatures::all(),
                                  bool fused = false);

}  // namespace wp
