/* Sampling routines and their densities. Every routine here has a chi-square test against its pdf
 * (tests/test_sampling.cpp). Directions are in a local frame with the normal along +z. */
#ifndef WP_SAMPLING_H
#define WP_SAMPLING_H

#include "util/common.h"
#include "util/elementary.h"

/* Uniform on the unit disk (Shirley and Chiu's concentric mapping of the square, area-preserving):
 * pdf = 1 / pi. The disk angle is (pi/4) q or pi/2 - (pi/4) q with |q| <= 1, so cos_sin_quarter
 * serves both. */
static inline float2 sample_concentric_disk(float2 u) {
  const float2 s = 2.0f * u - 1.0f;
  if (s.x == 0.0f && s.y == 0.0f) return (float2)(0.0f);
  if (fabs(s.x) > fabs(s.y)) {
    const float2 cs = cos_sin_quarter((WP_PI / 4.0f) * (s.y / s.x));
    return (float2)(s.x * cs.x, s.x * cs.y);
  } /* phi = pi/2 - t: cos phi = sin t, sin phi = cos t */
  const float2 cs = cos_sin_quarter((WP_PI / 4.0f) * (s.x / s.y));
  return (float2)(s.y * cs.y, s.y * cs.x);
}

/* Cosine-weighted hemisphere (the concentric disk, lifted): pdf = cos(theta) / pi. */
static inline float3 sample_cosine_hemisphere(float2 u) {
  const float2 p = sample_concentric_disk(u);
  return (float3)(p.x, p.y, sqrt(fmax(0.0f, 1.0f - p.x * p.x - p.y * p.y)));
}

static inline float cosine_hemisphere_pdf(float cos_theta) {
  return fmax(cos_theta, 0.0f) * WP_INV_PI;
}

#if WP_SHADE_PACKET
/* sample_cosine_hemisphere and cosine_hemisphere_pdf of eight lanes (common.h, Float3x8). */
WP_LANES_FN Float3x8 sample_cosine_hemisphere8(float8 ux, float8 uy) {
  const float8 sx = 2.0f * ux - 1.0f, sy = 2.0f * uy - 1.0f;
  const int8 wide = fabs(sx) > fabs(sy);
  float8 c, s;
  cos_sin_quarter8(select((WP_PI / 4.0f) * (sx / sy), (WP_PI / 4.0f) * (sy / sx), wide), &c, &s);
  const int8 centre = sx == 0.0f && sy == 0.0f;
  Float3x8 r;
  r.x = select(select(sy * s, sx * c, wide), (float8)(0.0f), centre);
  r.y = select(select(sy * c, sx * s, wide), (float8)(0.0f), centre);
  r.z = sqrt(fmax(0.0f, 1.0f - r.x * r.x - r.y * r.y));
  return r;
}
WP_LANES_FN float8 cosine_hemisphere_pdf8(float8 cos_theta) {
  return fmax(cos_theta, 0.0f) * WP_INV_PI;
}
#endif

/* GGX (Trowbridge-Reitz) normal distribution D(h) for alpha = roughness^2, from the cosine and
 * the squared sine of h's angle to the normal. The textbook denominator cos^2 (alpha^2 - 1) + 1
 * cancels in float32 for small alpha: alpha^2 below half an ulp of 1 (alpha < 2.4e-4) makes
 * alpha^2 - 1 exactly -1, and the denominator 1 - cos^2 reaches 0 at h = n (D = inf, then NaN
 * weights); above that, alpha^2 keeps only a few bits. Written as alpha^2 cos^2 + sin^2, with
 * sin^2 computed directly (|n x h|^2, or x^2 + y^2 in a local frame), every term is positive and
 * no bits are lost. Callers keep alpha >= WP_DELTA_ALPHA (bsdf.h), so D stays finite. */
static inline float ggx_d(float cos_h, float sin2_h, float alpha) {
  const float a2 = alpha * alpha;
  const float k = a2 * cos_h * cos_h + sin2_h;
  return a2 / (WP_PI * k * k);
}

/* sin^2 of the angle between unit vectors n and h, without the cancellation of 1 - cos^2. */
static inline float sin2_between(float3 n, float3 h) {
  const float3 c = cross(n, h);
  return dot(c, c);
}

/* Smith G1 for GGX. */
static inline float ggx_g1(float n_dot_v, float alpha) {
  const float a2 = alpha * alpha;
  return 2.0f * n_dot_v / (n_dot_v + sqrt(a2 + (1.0f - a2) * n_dot_v * n_dot_v));
}

/* Height-correlated Smith visibility V = G2 / (4 |n.l| |n.v|) (glTF 2.0 appendix B). */
static inline float ggx_visibility(float n_dot_l, float n_dot_v, float alpha) {
  const float a2 = alpha * alpha;
  const float gv = n_dot_l * sqrt(n_dot_v * n_dot_v * (1.0f - a2) + a2);
  const float gl = n_dot_v * sqrt(n_dot_l * n_dot_l * (1.0f - a2) + a2);
  const float s = gv + gl;
  return s > 0.0f ? 0.5f / s : 0.0f;
}

/* A microfacet normal h drawn from the distribution of normals visible from v (v.z > 0):
 * density D_v(h) = G1(v) max(0, v.h) D(h) / v.z. Method: stretch v to the hemisphere
 * configuration, sample the projected visible half-disk, unstretch (Heitz 2018). */
static inline float3 sample_ggx_visible_normal(float3 v, float alpha, float2 u) {
  const float3 vh = normalize((float3)(alpha * v.x, alpha * v.y, v.z));
  const float len2 = vh.x * vh.x + vh.y * vh.y;
  const float3 t1 =
      len2 > 0.0f ? (float3)(-vh.y, vh.x, 0.0f) * rsqrt(len2) : (float3)(1.0f, 0.0f, 0.0f);
  const float3 t2 = cross(vh, t1);
  const float r = sqrt(u.x);
  const float2 cs = cos_sin_turn(u.y);
  const float p1 = r * cs.x;
  const float s = 0.5f * (1.0f + vh.z);
  const float p2 = (1.0f - s) * sqrt(fmax(0.0f, 1.0f - p1 * p1)) + s * r * cs.y;
  const float3 nh = p1 * t1 + p2 * t2 + sqrt(fmax(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
  return normalize((float3)(alpha * nh.x, alpha * nh.y, fmax(1e-7f, nh.z)));
}

/* Density of the reflected direction l = reflect(v, h) when h is sampled as above:
 * D_v(h) / (4 v.h) = G1(v) D(h) / (4 v.z). h's cosine and squared sine to the normal as in
 * ggx_d. */
static inline float ggx_reflection_pdf(float n_dot_v, float n_dot_h, float sin2_h, float alpha) {
  return ggx_g1(n_dot_v, alpha) * ggx_d(n_dot_h, sin2_h, alpha) / (4.0f * n_dot_v);
}

#endif /* WP_SAMPLING_H */
