/* The path state as kernels see it: one global pointer per field of shared/path_state.def, bound
 * from the single path buffer and its PathLayout at the start of every kernel. */
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

#endif /* WP_PATH_STATE_H */
