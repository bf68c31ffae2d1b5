/* The path state as kernels see it: one global pointer per field of shared/path_state.def, bound
 * from the single path buffer and its PathLayout at the start of every kernel, and one getter and
 * setter per named lane:
 *
 *   path_bounce(paths, slot)             the lane's value
 *   path_set_bounce(paths, slot, value)  stores it, leaving the field's other lanes as they are
 *   path_store_ray_o(paths, slot, origin, tmin)
 *                                        stores a whole field from its lanes, in order
 *
 * These are the only code that indexes the path state (tests/test_kernel_tree.cpp checks that no
 * other kernel file does); prefetch_path (stage.h) takes a field's address, not a lane. */
#ifndef WP_PATH_STATE_H
#define WP_PATH_STATE_H

#include "util/common.h"

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

/* A whole field of one path, its lanes unnamed: path_load_<field>(paths, slot). Only for a stage
 * that gathers the same field of several paths into vectors (integrator/shade_packet.h); the
 * others read named lanes (below). */
#define WP_PATH_FIELD(type, name, description)                  \
  static inline type path_load_##name(Paths paths, uint slot) { \
    return paths.name[slot];                                    \
  }
#include "shared/path_state.def"
#undef WP_PATH_FIELD

/* A setter stores its lanes alone, through a pointer to the field's scalars: no load of the lanes
 * it keeps (an assignment to a swizzle would read the whole vector first), and the stores of a
 * field's lanes, one after another, can be merged into one. OpenCL C assumes no strict aliasing
 * unless built with -cl-strict-aliasing. */
#define WP_PATH_STORE_x(type, p, v) (((__global type*)(p))[0] = (v))
#define WP_PATH_STORE_y(type, p, v) (((__global type*)(p))[1] = (v))
#define WP_PATH_STORE_z(type, p, v) (((__global type*)(p))[2] = (v))
#define WP_PATH_STORE_w(type, p, v) (((__global type*)(p))[3] = (v))
#define WP_PATH_STORE_xyz(type, p, v) vstore3((v), 0, (__global float*)(p))

#define WP_PATH_FIELD(type, name, description)
#define WP_PATH_LANE(field, lanes, type, name, description)                \
  static inline type path_##name(Paths paths, uint slot) {                 \
    return paths.field[slot].lanes;                                        \
  }                                                                        \
  static inline void path_set_##name(Paths paths, uint slot, type value) { \
    WP_PATH_STORE_##lanes(type, paths.field + slot, value);                \
  }
#define WP_PATH_LANE_BITS(field, lane, type, stored, name, description)    \
  static inline type path_##name(Paths paths, uint slot) {                 \
    return as_##type(paths.field[slot].lane);                              \
  }                                                                        \
  static inline void path_set_##name(Paths paths, uint slot, type value) { \
    WP_PATH_STORE_##lane(stored, paths.field + slot, as_##stored(value));  \
  }
#define WP_PATH_STORE3(field, xyz, w, w_type, w_to_float)                               \
  static inline void path_store_##field(Paths paths, uint slot, float3 xyz, w_type w) { \
    paths.field[slot] = (float4)(xyz, w_to_float(w));                                   \
  }
#define WP_PATH_STORE4(field, vector, scalar, x, y, z, w, w_type, w_convert)                  \
  static inline void path_store_##field(Paths paths, uint slot, scalar x, scalar y, scalar z, \
                                        w_type w) {                                           \
    paths.field[slot] = (vector)(x, y, z, w_convert(w));                                      \
  }
#include "shared/path_state.def"
#undef WP_PATH_STORE4
#undef WP_PATH_STORE3
#undef WP_PATH_LANE_BITS
#undef WP_PATH_LANE
#undef WP_PATH_FIELD

/* The hit's instance (shared/bvh_layout.h): WP_NO_INSTANCE, and nothing stored, without a
 * two-level BVH. */
static inline uint path_hit_instance(Paths paths, uint slot) {
#if WP_BVH_INSTANCES
  return paths.hit_instance[slot];
#else
  (void)paths, (void)slot;
  return WP_NO_INSTANCE;
#endif
}
static inline void path_set_hit_instance(Paths paths, uint slot, uint instance) {
#if WP_BVH_INSTANCES
  paths.hit_instance[slot] = instance;
#else
  (void)paths, (void)slot, (void)instance;
#endif
}

/* The halves of the flags and bounce words (shared/path_state.def). The low halves hold the flags
 * and the bounce count (--max-depth stays below 2^16 - 1, so roulette's increment never carries
 * into the high half); the high halves hold the ray cone (ray_cone.h) as bfloat16, the upper 16
 * bits of a float rounded to nearest: 8 bits of precision (0.4%, 0.006 of a mip level) over
 * float's whole range. Programs without WP_FEATURE_TEXTURE_LOD keep the high halves 0 and read
 * and write the words whole. */
#if WP_FEATURE_TEXTURE_LOD
static inline uint bf16_from_float(float x) {
  const uint b = as_uint(x);
  return (b + 0x7fffu + ((b >> 16) & 1u)) >> 16; /* to nearest, ties to even; x finite */
}
static inline float bf16_to_float(uint h) {
  return as_float(h << 16);
}
static inline float high_bf16(uint word) {
  return bf16_to_float(word >> 16);
}
static inline uint with_high_bf16(uint word, float x) {
  return (word & 0xffffu) | (bf16_from_float(x) << 16);
}
#endif
static inline uint low_half(uint word) {
#if WP_FEATURE_TEXTURE_LOD
  return word & 0xffffu;
#else
  return word;
#endif
}
static inline uint with_low_half(uint word, uint low) {
#if WP_FEATURE_TEXTURE_LOD
  return (word & 0xffff0000u) | low;
#else
  return (void)word, low;
#endif
}
static inline uint path_bounce(Paths paths, uint slot) {
  return low_half(path_bounce_word(paths, slot));
}
static inline void path_set_bounce(Paths paths, uint slot, uint bounce) {
  path_set_bounce_word(paths, slot, with_low_half(path_bounce_word(paths, slot), bounce));
}
static inline uint path_flags(Paths paths, uint slot) {
  return low_half(path_flags_word(paths, slot));
}
static inline void path_set_flags(Paths paths, uint slot, uint flags) {
  path_set_flags_word(paths, slot, with_low_half(path_flags_word(paths, slot), flags));
}

#endif /* WP_PATH_STATE_H */
