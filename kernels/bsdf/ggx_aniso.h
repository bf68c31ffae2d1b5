/* Anisotropic GGX for KHR_materials_anisotropy: the normal distribution D, the Smith Lambda, G1
 * and the height-correlated visibility, visible-normal sampling and the density of the reflected
 * direction. Tests: tests/test_anisotropy.cpp (chi-square of the sampling against the pdf,
 * normalisation by quadrature, float64 references, agreement with warps.h's isotropic GGX).
 *
 * Frame: every direction is a unit vector in the local frame (t, b, n) of the anisotropy: x along
 * the anisotropy direction t (the glTF tangent rotated by anisotropyRotation and the texture's
 * direction), y along b = n x t, z along the shading normal n. ax is the GGX alpha along t, ay
 * along b; ggx_aniso_alphas gives them from the material (ratified extension text):
 *   alpha = roughness^2,  ax = mix(alpha, 1, strength^2),  ay = alpha.
 *
 *   D(h)      = 1 / (pi ax ay (hx^2 / ax^2 + hy^2 / ay^2 + hz^2)^2)
 *   Lambda(w) = (sqrt(1 + (ax^2 wx^2 + ay^2 wy^2) / wz^2) - 1) / 2
 *   G1(w)     = 1 / (1 + Lambda(w)),   G2(o, i) = 1 / (1 + Lambda(o) + Lambda(i))
 *
 * With ax == ay == alpha every function is the isotropic one of sampling/warps.h (ggx_d, ggx_g1,
 * ggx_visibility, sample_ggx_visible_normal, ggx_reflection_pdf) up to float rounding. The
 * sampled normal is the same sequence of operations (bit for bit on PoCL and on NVIDIA's OpenCL),
 * D too up to factors of exactly 1 (bit for bit on PoCL; NVIDIA's compiler fuses its sums into
 * FMAs differently, within 11 u = 11 * 2^-24 relative).
 *
 * Numerical guards:
 * - alpha floor: ax and ay are raised to WP_GGX_ANISO_ALPHA_MIN (1e-3, bsdf.h's WP_DELTA_ALPHA)
 *   by every function. KHR_materials_anisotropy makes lobes that are smooth across and rough
 *   along t (roughness 0, strength > 0: ay = 0), which are no delta lobe; the floor keeps D, its
 *   pdf and the sampler finite there (D <= 1 / (pi ax ay) <= 3.2e5). Below 1e-3 float32 would
 *   lose D's precision anyway (sampling/warps.h, ggx_d), and the isotropic BSDF treats such lobes
 *   as delta lobes, so the reduction to sampling/warps.h holds wherever that code uses GGX.
 * - grazing: Lambda's wz^2 is floored at 1e-12 as bsdf.h's ggx_lambda does (finite, ~5e5 ax at
 *   wz = 0); G1, the visibility and the pdf are written without 1 / wz, so they are finite at
 *   wz = 0 (G1 = 0, the pdf its grazing limit), where sampling/warps.h's ggx_reflection_pdf is 0/0.
 * - D's denominator is a sum of positive terms (no cancellation near h = n), Lambda is written
 *   as e / (2 (1 + sqrt(1 + e))), not (sqrt(1 + e) - 1) / 2, so its relative error stays a few
 *   ulp where Lambda is small.
 * - Lambda, G1 and the visibility depend on |wz| only: a direction below the surface (thin-walled
 *   or refracted transmission) has the masking of its mirror image. D is even in hz: the caller
 *   keeps h in the upper hemisphere, as for ggx_d. */
#ifndef WP_GGX_ANISO_H
#define WP_GGX_ANISO_H

#include "sampling/warps.h"

/* The smallest alpha the functions below use (see the guards above). */
#define WP_GGX_ANISO_ALPHA_MIN 1e-3f

/* (ax, ay) of KHR_materials_anisotropy from the material's roughness and the anisotropy strength
 * in [0, 1]: ax = mix(alpha, 1, strength^2) along t, ay = alpha along b, alpha = roughness^2.
 * Strength 0 gives (alpha, alpha) exactly. Not floored (the functions below floor). */
static inline float2 ggx_aniso_alphas(float roughness, float strength) {
  const float alpha = roughness * roughness, s2 = strength * strength;
  return (float2)(alpha * (1.0f - s2) + s2, alpha);
}

static inline float ggx_aniso_floor(float alpha) {
  return fmax(alpha, WP_GGX_ANISO_ALPHA_MIN); /* also maps NaN to the floor */
}

/* |(ax wx, ay wy, wz)|: w's length in the configuration stretched to alpha 1. */
static inline float ggx_aniso_stretched_length(float3 w, float ax, float ay) {
  const float x = ax * w.x, y = ay * w.y;
  return sqrt(x * x + y * y + w.z * w.z);
}

/* D(h), h in the local frame. Written as ax ay / (pi k^2) with
 * k = ax ay hz^2 + (ay / ax) hx^2 + (ax / ay) hy^2 (= ax ay (hx^2/ax^2 + hy^2/ay^2 + hz^2)):
 * for ax == ay the ratios are exactly 1 and this is ggx_d(hz, hx^2 + hy^2, ax) operation for
 * operation. */
static inline float ggx_aniso_d(float3 h, float ax, float ay) {
  ax = ggx_aniso_floor(ax), ay = ggx_aniso_floor(ay);
  const float a2 = ax * ay;
  const float k = a2 * h.z * h.z + ((ay / ax) * h.x * h.x + (ax / ay) * h.y * h.y);
  return a2 / (WP_PI * k * k);
}

/* Smith Lambda of direction w (either hemisphere). */
static inline float ggx_aniso_lambda(float3 w, float ax, float ay) {
  ax = ggx_aniso_floor(ax), ay = ggx_aniso_floor(ay);
  const float x = ax * w.x, y = ay * w.y;
  const float e = (x * x + y * y) / fmax(w.z * w.z, 1e-12f); /* tan^2 once stretched */
  return 0.5f * e / (1.0f + sqrt(1.0f + e));
}

/* Smith G1(w) = 1 / (1 + Lambda(w)) = 2 |wz| / (|wz| + |(ax wx, ay wy, wz)|): 0 at wz = 0. */
static inline float ggx_aniso_g1(float3 w, float ax, float ay) {
  ax = ggx_aniso_floor(ax), ay = ggx_aniso_floor(ay);
  const float z = fabs(w.z);
  return 2.0f * z / (z + ggx_aniso_stretched_length(w, ax, ay));
}

/* Height-correlated visibility V = G2(wo, wi) / (4 |wo.z| |wi.z|)
 *   = 0.5 / (|wi.z| |(ax wo.x, ay wo.y, wo.z)| + |wo.z| |(ax wi.x, ay wi.y, wi.z)|);
 * 0 when both are grazing. As ggx_visibility(wi.z, wo.z, alpha) for ax == ay == alpha. */
static inline float ggx_aniso_visibility(float3 wo, float3 wi, float ax, float ay) {
  ax = ggx_aniso_floor(ax), ay = ggx_aniso_floor(ay);
  const float go = fabs(wi.z) * ggx_aniso_stretched_length(wo, ax, ay);
  const float gi = fabs(wo.z) * ggx_aniso_stretched_length(wi, ax, ay);
  const float s = go + gi;
  return s > 0.0f ? 0.5f / s : 0.0f;
}

/* A microfacet normal h drawn from the normals visible from wo (wo.z >= 0):
 * density D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z. Heitz 2018: stretch wo by (ax, ay) to the
 * alpha-1 configuration, sample the projected visible half-disk there, unstretch. Returns a unit
 * h with h.z > 0 (the unstretched z is floored at 1e-7, as sampling/warps.h does). Operation for
 * operation sample_ggx_visible_normal when ax == ay. */
static inline float3 sample_ggx_aniso_visible_normal(float3 wo, float ax, float ay, float2 u) {
  ax = ggx_aniso_floor(ax), ay = ggx_aniso_floor(ay);
  const float3 vh = normalize((float3)(ax * wo.x, ay * wo.y, wo.z));
  const float len2 = vh.x * vh.x + vh.y * vh.y;
  const float3 t1 =
      len2 > 0.0f ? (float3)(-vh.y, vh.x, 0.0f) * rsqrt(len2) : (float3)(1.0f, 0.0f, 0.0f);
  const float3 t2 = cross(vh, t1);
  const float r = sqrt(u.x);
  float c, s_turn;
  cos_sin_turn(u.y, &c, &s_turn);
  const float p1 = r * c;
  const float s = 0.5f * (1.0f + vh.z);
  const float p2 = (1.0f - s) * sqrt(fmax(0.0f, 1.0f - p1 * p1)) + s * r * s_turn;
  const float3 nh = p1 * t1 + p2 * t2 + sqrt(fmax(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
  return normalize((float3)(ax * nh.x, ay * nh.y, fmax(1e-7f, nh.z)));
}

/* Density (solid angle) of wi = reflect(wo, h) = 2 (wo.h) h - wo when h is drawn as above:
 * D_wo(h) / (4 wo.h) = G1(wo) D(h) / (4 wo.z) = D(h) / (2 (wo.z + |(ax wo.x, ay wo.y, wo.z)|)).
 * 0 unless h.z > 0 and wo.h > 0 (h visible from wo); wo.z >= 0. For a pdf of wi, pass
 * h = normalize(wo + wi). */
static inline float ggx_aniso_reflection_pdf(float3 wo, float3 h, float ax, float ay) {
  if (!(h.z > 0.0f && dot(wo, h) > 0.0f && wo.z >= 0.0f)) return 0.0f;
  const float d = ggx_aniso_d(h, ax, ay);
  ax = ggx_aniso_floor(ax), ay = ggx_aniso_floor(ay);
  return d * 0.5f / (wo.z + ggx_aniso_stretched_length(wo, ax, ay));
}

#endif /* WP_GGX_ANISO_H */
