/* The base's microfacet distribution: GGX with alpha = roughness^2 (sampling/warps.h), or
 * anisotropic GGX (ggx_aniso.h) where KHR_materials_anisotropy gives a strength: the specular
 * lobe's D, visibility and visible-normal density for a reflection, Smith's Lambda, and whether
 * the lobe is so narrow it is a delta lobe. */
#ifndef WP_BSDF_MICROFACET_H
#define WP_BSDF_MICROFACET_H

#include "bsdf/closure.h"
#include "bsdf/ggx_aniso.h"
#include "sampling/warps.h"

/* The base's specular lobes are anisotropic GGX (KHR_materials_anisotropy) in the frame (aniso_t,
 * cross(ns, aniso_t), ns) when the strength is > 0: alpha along aniso_t is mix(alpha, 1,
 * strength^2), across it alpha, kept >= WP_DELTA_ALPHA so that the distribution stays finite. */
#if WP_FEATURE_ANISOTROPY
static inline bool bsdf_anisotropic(const Surface* s) {
  return s->anisotropy > 0.0f;
}
static inline float2 aniso_alpha(const Surface* s) {
  const float a = sqr(s->roughness);
  return (float2)(mix(a, 1.0f, sqr(s->anisotropy)), fmax(a, WP_DELTA_ALPHA));
}
static inline float3 aniso_local(const Surface* s, float3 w) {
  const float3 b = cross(s->ns, s->aniso_t);
  return (float3)(dot(w, s->aniso_t), dot(w, b), dot(w, s->ns));
}
#endif

static inline bool bsdf_has_delta(const Surface* s) {
#if WP_FEATURE_GLOSSY
#if WP_FEATURE_ANISOTROPY
  if (bsdf_anisotropic(s)) return mix(sqr(s->roughness), 1.0f, sqr(s->anisotropy)) < WP_DELTA_ALPHA;
#endif
  return sqr(s->roughness) < WP_DELTA_ALPHA;
#else
  (void)s; /* a Lambertian surface has no delta lobe at any roughness */
  return false;
#endif
}
/* Smith Lambda for GGX; G2 = 1 / (1 + Lambda(o) + Lambda(i)) is the height-correlated term. */
static inline float ggx_lambda(float cos_theta, float alpha) {
  const float c2 = cos_theta * cos_theta;
  const float tan2 = fmax(0.0f, 1.0f - c2) / fmax(c2, 1e-12f);
  return 0.5f * (sqrt(1.0f + alpha * alpha * tan2) - 1.0f);
}

/* The base's specular lobe for the reflection of wo into wi about h (cosines cos_o, cos_i to ns):
 * x = D(h), y = V(wo, wi), z = the density of wi when h is drawn from the normals visible from
 * wo. */
static inline float3 spec_reflection(const Surface* s, float3 wo, float3 wi, float3 h, float cos_o,
                                     float cos_i) {
#if WP_FEATURE_ANISOTROPY
  if (bsdf_anisotropic(s)) {
    const float2 a = aniso_alpha(s);
    const float3 hl = aniso_local(s, h), ol = aniso_local(s, wo);
    return (float3)(ggx_aniso_d(hl, a.x, a.y),
                    ggx_aniso_visibility(ol, aniso_local(s, wi), a.x, a.y),
                    ggx_aniso_reflection_pdf(ol, hl, a.x, a.y));
  }
#endif
  (void)wo, (void)wi;
  const float alpha = sqr(s->roughness);
  const float n_dot_h = fmax(dot(s->ns, h), 0.0f), sin2_h = sin2_between(s->ns, h);
  return (float3)(ggx_d(n_dot_h, sin2_h, alpha), ggx_visibility(cos_i, cos_o, alpha),
                  ggx_reflection_pdf(cos_o, n_dot_h, sin2_h, alpha));
}

#endif /* WP_BSDF_MICROFACET_H */
