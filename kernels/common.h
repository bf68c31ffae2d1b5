/* Basic definitions for every kernel: the shared types, constants and small vector helpers. */
#ifndef WP_COMMON_H
#define WP_COMMON_H

#include "shared/types.h"
#include "features.h"

#define WP_PI 3.14159265358979323846f
#define WP_INV_PI 0.31830988618379067154f
#define WP_INF INFINITY

inline float max3(float3 v) {
  return fmax(v.x, fmax(v.y, v.z));
}
inline float luminance(float3 c) {
  return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}
inline float sqr(float x) {
  return x * x;
}
inline float pow5(float x) {
  const float x2 = x * x;
  return x2 * x2 * x;
}
inline bool all_zero(float3 v) {
  return v.x == 0.0f && v.y == 0.0f && v.z == 0.0f;
}

/* An orthonormal basis around unit n (tangent t, bitangent b) without branches on the sign of n
 * (the construction of Duff et al. 2017). */
inline void make_basis(float3 n, float3* t, float3* b) {
  const float s = n.z >= 0.0f ? 1.0f : -1.0f;
  const float a = -1.0f / (s + n.z);
  const float c = n.x * n.y * a;
  *t = (float3)(1.0f + s * n.x * n.x * a, s * c, -s * n.x);
  *b = (float3)(c, s + n.y * n.y * a, -n.y);
}

/* A ray origin just off the surface at p on the side of unit normal n, robust at any scale: far
 * from the origin it moves p by a fixed number of float ULPs along n (so the offset grows with the
 * magnitude of p, as the rounding error of p does); near the origin, where ULPs are tiny, by a
 * small fixed distance. Secondary rays then start with tmin = 0. */
inline float3 offset_origin(float3 p, float3 n) {
  const float kNearOrigin = 1.0f / 32.0f;
  const float kFloatScale = 1.0f / 65536.0f;
  const float kIntScale = 256.0f;
  const int3 ulps = convert_int3(kIntScale * n);
  const float3 moved = as_float3(as_int3(p) + select(ulps, -ulps, as_int3(p) < 0));
  return select(moved, p + kFloatScale * n, fabs(p) < kNearOrigin);
}

#endif /* WP_COMMON_H */
