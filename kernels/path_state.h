/* The path state as kernels see it: one global pointer per field of shared/path_state.def, bound
 * from the single path buffer and its PathLayout at the start of every kernel, and one getter and
 * setter per named lane:
 *
 *   path_bounce(paths, slot)             the lane's value
 *   path_set_bounce(paths, slot, value)  stores it, leaving the field's other lanes as they are
 *
 * These are the only code that indexes the path state (tests/test_kernel_tree.cpp checks that no
 * other kernel file does); prefetch_path (stage.h) takes a field's address, not a lane. */
#ifndef WP_PATH_STATE_H
#define WP_PATH_STATE_H

#include "common.h"

typedef struct Paths {
#define WP_PATH_FIELD(type, name, description) __global type* name;
#include "shared/path_state.def"
#undef WP_PATH_FIELD
} Paths;

static inline Paths paths_bind(__global uchar* base, PathLayout layout) {
  Paths p;
#define WP_PATH_FIELD(type, name, description) p.name = (__global type*)(base + layout.name);
#include "shared/path_state.def"
#undef WP_PATH_FIELD
  return p;
}

#define WP_PATH_FIELD(type, name, description)
#define WP_PATH_LANE(field, lanes, type, name, description)                \
  static inline type path_##name(Paths paths, uint slot) {                 \
    return paths.field[slot].lanes;                                        \
  }                                                                        \
  static inline void path_set_##name(Paths paths, uint slot, type value) { \
    paths.field[slot].lanes = value;                                       \
  }
#define WP_PATH_LANE_BITS(field, lane, type, stored, name, description)    \
  static inline type path_##name(Paths paths, uint slot) {                 \
    return as_##type(paths.field[slot].lane);                              \
  }                                                                        \
  static inline void path_set_##name(Paths paths, uint slot, type value) { \
    paths.field[slot].lane = as_##stored(value);                           \
  }
#include "shared/path_state.def"
#undef WP_PATH_LANE_BITS
#undef WP_PATH_LANE
#undef WP_PATH_FIELD

#endif /* WP_PATH_STATE_H */
