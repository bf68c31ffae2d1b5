/* Basic definitions for every kernel: the shared types, constants and small vector helpers.
 *
 * Every function in kernels/ is `static inline`, never plain `inline`: OpenCL C takes C99's
 * rules, under which a plain inline definition emits no function, so a call the compiler chooses
 * not to inline (resolve_surface, bsdf_sample, leaf_test, ... for nvptx64 and amdgcn) is left
 * to an external symbol nothing defines and the program fails to link. PoCL inlines everything
 * and never shows it; tools/gpu_compile.py does. */
#ifndef WP_COMMON_H
#define WP_COMMON_H

#include "shared/types.h"
#include "features.h"

#define WP_PI 3.14159265358979323846f
#define WP_INV_PI 0.31830988618379067154f
#define WP_INF INFINITY

/* For the per-path bodies of the stages (integrator/<stage>.h), several called from their own
 * kernel and from the fused shade.cl: with two callers clang keeps them out of line, and the
 * surface they take by pointer then lives in a stack frame (local memory on GPUs, as ptxas shows
 * through tools/gpu_compile.py). */
#define WP_STAGE_FN static inline __attribute__((always_inline))

static inline float max3(float3 v) {
  return fmax(v.x, fmax(v.y, v.z));
}
static inline float luminance(float3 c) {
  return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}
static inline float sqr(float x) {
  return x * x;
}
static inline float pow5(float x) {
  const float x2 = x * x;
  return x2 * x2 * x;
}
static inline bool all_zero(float3 v) {
  return v.x == 0.0f && v.y == 0.0f && v.z == 0.0f;
}

/* An orthonormal basis around unit n (tangent t, bitangent b) without branches on the sign of n
 * (the construction of Duff et al. 2017). */
static inline void make_basis(float3 n, float3* t, float3* b) {
  const float s = n.z >= 0.0f ? 1.0f : -1.0f;
  const float a = -1.0f / (s + n.z);
  const float c = n.x * n.y * a;
  *t = (float3)(1.0f + s * n.x * n.x * a, s * c, -s * n.x);
  *b = (float3)(c, s + n.y * n.y * a, -n.y);
}

/* A ray origin just off a surface point p, on the side of unit normal n, for rays that must not
 * hit the surface they leave. `scale` bounds the magnitudes that went into computing p and into
 * intersecting the surface again (the largest component of |b0 p0| + |b1 p1| + |b2 p2| for a point
 * interpolated from a triangle's vertices: pbrt's error-bound idea): float rounding in both is a
 * small multiple of 2^-24 scale, whatever the ray's angle, so moving the origin by 2^-16 scale
 * along n clears it with a wide margin, at any scene scale and distance from the origin. */
static inline float offset_distance(float scale) {
  return scale * (1.0f / 65536.0f);
}

static inline float3 offset_origin(float3 p, float3 n, float scale) {
  return p + n * offset_distance(scale);
}

#endif /* WP_COMMON_H */
