/* The KHR_materials_sheen lobe (the ratified extension's implementation notes): Conty Estevez and
 * Kulla's "Charlie" sheen with its fitted visibility, and the directional albedo E that the
 * albedo-scaling layering needs.
 *
 *   f_sheen(wo, wi) = sheenColor * D(h) * V(wo, wi)
 *   D(h)  = (2 + 1/alpha) sin(theta_h)^(1/alpha) / (2 pi),  alpha = sheenRoughness^2 (sheen_alpha)
 *   V     = 1 / ((1 + Lambda(n.wo) + Lambda(n.wi)) 4 (n.wo) (n.wi))
 *   Lambda(c) = exp(l(c))                     for c < 0.5
 *             = exp(2 l(0.5) - l(1 - c))      otherwise
 *   l(x)  = a / (1 + b x^c) + d x + e, each of a..e mix(value at alpha 1, value at alpha 0,
 *           (1 - alpha)^2) of the fit's two rows (sheen_fit)
 *   base layer scaled by min(1 - max3(sheenColor) E(n.wo), 1 - max3(sheenColor) E(n.wi)),
 *   E(mu) = integral over the hemisphere of D V cos(theta_i) d omega_i, wo at cosine mu
 *           (sheen_albedo: sheen_table.h, written by tools/generators/gen_sheen_table.py)
 *
 * Conventions, as in bsdf.h: n is the unit shading normal, wo (toward the viewer) and wi unit
 * vectors pointing away from the surface, all in the same (world) frame. sheen_eval returns D V,
 * without the colour and without the cosine: f_sheen = sheenColor * sheen_eval(...), and it is 0
 * unless both n.wo and n.wi are > 0 (no transmission, nothing below the shading normal's
 * horizon). Every function here takes alpha = sheen_alpha(roughness) and clamps it into
 * [WP_SHEEN_ALPHA_MIN, 1] again (a NaN becomes the minimum), except sheen_albedo, which takes the
 * roughness itself (the table's axis) and clamps it into [WP_SHEEN_ROUGHNESS_MIN, 1]. Cosines
 * given as numbers are taken by magnitude and clamped to 1. Every result is finite and >= 0 for
 * every input, NaN and infinities included (tests/test_sheen.cpp, Sheen.FiniteEverywhere).
 *
 * E > 1. The lobe gains energy where its roughness is small or its view grazing, and the layering
 * must then clamp 1 - max3(sheenColor) E at 0: over mu >= 3.4e-5 the largest E is 0.95 (roughness
 * ~0.95, mu ~0.008) for roughness >= 0.26 and passes 1 below roughness 0.2596 (1.04 at 0.245, 2.94
 * at the clamp 0.07, at mu ~0.002), because the fitted Lambda is much smaller than the Smith
 * Lambda of D for small alpha (30-40% of it at roughness 0.1, 9-13% at 0.03); and at every
 * roughness E grows without bound as mu -> 0 (1.5 at mu 1e-6 for roughness 1), because the fit's
 * Lambda(0) = exp(a + e) is finite. sheen_table.h stays flat below mu = 3.4e-5.
 *
 * Float32 care. D is evaluated as K exp(log(sin^2 theta_h) / (2 alpha)), K = (2 + 1/alpha) /
 * (2 pi), with the logarithm taken as log1p(-cos^2) while cos^2 < 0.5 and as log(sin^2) from
 * |n x (wo + wi)|^2 (sheen_eval) or (1 - cos)(1 + cos) (sheen_d) otherwise. The lobe of a small
 * alpha lies where sin^2 = 1 - cos^2 is within ~alpha of 1, where float32 spaces its values
 * 6e-8 apart: pow(1 - cos^2, 1/(2 alpha)) as the extension writes it is off by ~3e-8 / alpha
 * relative (3e-4 at alpha 1e-4, and below alpha ~3e-8 the lobe falls between two floats), while
 * the form here is within a few ulps times the exponent |log(D / K)| (< 91 wherever D is a normal
 * float) at any alpha. h = n gives log = -inf and D = 0, never a NaN, and 1 / alpha is finite
 * for alpha > 3e-39: float32 itself needs only alpha > 0, the minimum below has another reason.
 * Lambda stays below exp(a + e) = 7.7e8 (at cosine 0), so V is finite unless (n.wo)(n.wi)
 * (1 + Lambda_o + Lambda_i) underflows, for (n.wo)(n.wi) below ~1e-47; sheen_eval then returns
 * FLT_MAX, not inf (the true value is beyond float32 there). Where |wo + wi|^2 underflows (both
 * within 1e-19 of the horizon and opposite) h has no float32 direction and sheen_eval returns 0.
 * exp, log, log1p, pow and cbrt are elementary.h's inlined polynomials, each with its stated bound,
 * which tests/test_sheen.cpp's error model takes (PoCL's out-of-line library calls took 19.5% of a
 * render of SheenChair).
 *
 * WP_SHEEN_ROUGHNESS_MIN = 0.07 (alpha 0.0049). Below it E keeps growing, like ~0.2 / roughness
 * (6.4 at roughness 0.03, 18 at 0.01), with features of width ~roughness in mu, too fine for the
 * table, and has no limit at roughness 0, the glTF default of sheenRoughnessFactor. 0.07 is the
 * minimum three.js and three-gpu-pathtracer apply to KHR_materials_sheen; OSL's own Charlie lobe
 * (Sony Imageworks, the fit's authors) clamps alpha at 0.06, roughness 0.245, just below where
 * E <= 1 starts. To change it, edit the value here and rerun tools/generators/gen_sheen_table.py
 * (it reads it from this file).
 */
#ifndef WP_SHEEN_H
#define WP_SHEEN_H

#include "util/common.h"
#include "util/elementary.h"
#include "sheen_table.h"

#define WP_SHEEN_ROUGHNESS_MIN 0.07f
#define WP_SHEEN_ALPHA_MIN (WP_SHEEN_ROUGHNESS_MIN * WP_SHEEN_ROUGHNESS_MIN)

static inline float sheen_clamp_alpha(float alpha) {
  return fmin(fmax(alpha, WP_SHEEN_ALPHA_MIN), 1.0f); /* fmax(NaN, m) = m */
}

/* alpha = roughness^2, roughness clamped into [WP_SHEEN_ROUGHNESS_MIN, 1]. */
static inline float sheen_alpha(float roughness) {
  const float r = fmin(fmax(roughness, WP_SHEEN_ROUGHNESS_MIN), 1.0f);
  return r * r;
}

/* D from log(sin^2 theta_h) (<= 0, -inf for h = n): K exp(log_sin2 / (2 alpha)). */
static inline float sheen_d_log(float log_sin2, float alpha) {
  alpha = sheen_clamp_alpha(alpha);
  const float inv = 1.0f / alpha;
  return (2.0f + inv) * (0.5f * WP_INV_PI) * exp_poly(fmin(log_sin2, 0.0f) * (0.5f * inv));
}

/* D(h) for h at cosine cos_h to the normal. */
static inline float sheen_d(float cos_h, float alpha) {
  const float c = fmin(fabs(cos_h), 1.0f);
  const float c2 = c * c;
  /* 1 - c is exact for c >= 0.5, so (1 - c)(1 + c) keeps sin^2's relative precision there. */
  const float log_sin2 = c2 < 0.5f ? log1p_poly(-c2) : log_poly((1.0f - c) * (1.0f + c));
  return sheen_d_log(log_sin2, alpha);
}

/* The fit's coefficients at one alpha, and l(0.5). */
typedef struct SheenFit {
  float a, b, c, d, e, l_half;
} SheenFit;

static inline float sheen_l(float x, const SheenFit* f) {
  return f->a / (1.0f + f->b * powr_poly(x, f->c)) + f->d * x + f->e;
}

static inline SheenFit sheen_fit(float alpha) {
  const float t = sqr(1.0f - sheen_clamp_alpha(alpha));
  SheenFit f;
  f.a = mix(21.5473f, 25.3245f, t);
  f.b = mix(3.82987f, 3.32435f, t);
  f.c = mix(0.19823f, 0.16801f, t);
  f.d = mix(-1.97760f, -1.27393f, t);
  f.e = mix(-4.32054f, -4.85967f, t);
  f.l_half = sheen_l(0.5f, &f);
  return f;
}

static inline float sheen_lambda_fit(float cos_theta, const SheenFit* f) {
  const float c = fmin(fabs(cos_theta), 1.0f); /* fmin(NaN, 1) = 1 */
  return c < 0.5f ? exp_poly(sheen_l(c, f)) : exp_poly(2.0f * f->l_half - sheen_l(1.0f - c, f));
}

/* Lambda(cos_theta) of the fitted visibility. */
static inline float sheen_lambda(float cos_theta, float alpha) {
  const SheenFit f = sheen_fit(alpha);
  return sheen_lambda_fit(cos_theta, &f);
}

/* D V for unit n, wo, wi (header: conventions); 0 unless n.wo > 0 and n.wi > 0. */
static inline float sheen_eval(float3 n, float3 wo, float3 wi, float alpha) {
  const float cos_o = dot(n, wo), cos_i = dot(n, wi);
  if (!(cos_o > 0.0f && cos_i > 0.0f)) return 0.0f;
  const float3 s = wo + wi; /* the half vector, unnormalised: n.s = cos_o + cos_i > 0 */
  const float len2 = dot(s, s);
  if (!(len2 >= FLT_MIN)) return 0.0f; /* |wo + wi| < 1e-19: h has no float32 direction */
  const float cos2 = sqr(cos_o + cos_i) / len2;
  float log_sin2;
  if (cos2 < 0.5f) {
    log_sin2 = log1p_poly(-cos2);
  } else {
    const float3 x = cross(n, s);
    log_sin2 = log_poly(dot(x, x) / len2);
  }
  const float d = sheen_d_log(log_sin2, alpha);
  if (!(d > 0.0f)) return 0.0f;
  const SheenFit f = sheen_fit(alpha);
  const float g_inv = 1.0f + sheen_lambda_fit(cos_o, &f) + sheen_lambda_fit(cos_i, &f);
  const float den = 4.0f * cos_o * g_inv * cos_i;
  return fmin(d / den, FLT_MAX); /* den = 0 (underflow): inf, saturated */
}

/* E(mu) for sheen roughness `roughness` (not alpha), bilinear in the table of sheen_table.h over
 * (cbrt(mu), sqrt(roughness)): mu clamped into [0, 1], roughness into [WP_SHEEN_ROUGHNESS_MIN, 1]
 * (a NaN becomes 0 or the minimum). Below mu = 1/31^3 the table is flat (sheen_table.h). */
static inline float sheen_albedo(float mu, float roughness) {
  const float x = cbrt_poly(fmin(fmax(mu, 0.0f), 1.0f)) * (float)(WP_SHEEN_TABLE_NMU - 1);
  const float r = fmin(fmax(roughness, WP_SHEEN_ROUGHNESS_MIN), 1.0f);
  const float y =
      fmax(0.0f, (sqrt(r) - WP_SHEEN_TABLE_SQRT_RMIN) *
                     ((float)(WP_SHEEN_TABLE_NR - 1) / (1.0f - WP_SHEEN_TABLE_SQRT_RMIN)));
  const int i = min((int)x, WP_SHEEN_TABLE_NMU - 2), j = min((int)y, WP_SHEEN_TABLE_NR - 2);
  const float fx = x - (float)i, fy = y - (float)j;
  const int k = j * WP_SHEEN_TABLE_NMU + i;
  const float e0 = mix(wp_sheen_albedo[k], wp_sheen_albedo[k + 1], fx);
  const float e1 =
      mix(wp_sheen_albedo[k + WP_SHEEN_TABLE_NMU], wp_sheen_albedo[k + WP_SHEEN_TABLE_NMU + 1], fx);
  return mix(e0, e1, fy);
}

#endif /* WP_SHEEN_H */
