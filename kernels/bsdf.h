/* The glTF 2.0 metallic-roughness BRDF (specification, appendix B), evaluated and importance
 * sampled.
 *
 *   f = (1 - metallic) * [ (1 - F_d) * base / pi  +  F_d * D * V ]  +  metallic * F_m * D * V
 *   F_d = f0 + (1 - f0) (1 - |v.h|)^5,  f0 = ((ior - 1) / (ior + 1))^2   (0.04 for ior 1.5)
 *   F_m = base + (1 - base) (1 - |v.h|)^5
 *   D: GGX with alpha = roughness^2;  V: height-correlated Smith visibility, G2 / (4 n.l n.v).
 *
 * A surface with roughness <= WP_DELTA_ROUGHNESS has a perfectly smooth specular layer: a delta
 * lobe (mirror direction, h = n), which sampling chooses with a flag instead of a pdf and which
 * evaluation leaves out (it has no density). The diffuse term stays an ordinary lobe.
 *
 * Sampling picks the specular lobe with probability p_spec (its Fresnel-weighted share at n.v,
 * a function of the outgoing direction only) and the diffuse lobe otherwise (cosine-weighted);
 * the specular lobe samples GGX visible normals. For non-delta surfaces the returned pdf is the
 * mixture density of both lobes, the same number bsdf_eval returns for that pair of directions.
 * Directions are world-space unit vectors pointing away from the surface; wo is toward the viewer.
 */
#ifndef WP_BSDF_H
#define WP_BSDF_H

#include "common.h"
#include "sampling.h"

#define WP_DELTA_ROUGHNESS 0.01f

/* Surface flags. */
#define WP_SURF_UNLIT 1u  /* KHR_materials_unlit: shows `color`, scatters nothing */
#define WP_SURF_VOLUME 2u /* transmission bends rays (KHR_materials_volume); else thin-walled */
#define WP_SURF_FRONT 4u  /* the ray arrived on the front (counter-clockwise) side */

typedef struct Surface {
  float3 p;  /* position */
  float3 ng; /* geometric normal, on the side of wo */
  float3 ns; /* shading normal, same side */
  float3 color;
  float metallic, roughness, ior, transmission;
  uint flags; /* WP_SURF_* */
} Surface;

typedef struct BsdfEval {
  float3 f;  /* BSDF value (no cosine), delta lobes excluded */
  float pdf; /* solid-angle density with which bsdf_sample would produce wi */
} BsdfEval;

typedef struct BsdfSample {
  float3 wi;
  float3 weight; /* f * |n.wi| / pdf, or the delta lobe's reflectance / its selection probability */
  float pdf;     /* 0 for a delta lobe */
  bool delta;
  bool valid; /* false: the path ends here (no direction, or one below the surface) */
} BsdfSample;

inline float dielectric_f0(float ior) {
  return sqr((ior - 1.0f) / (ior + 1.0f));
}
inline float schlick1(float f0, float c) {
  return f0 + (1.0f - f0) * pow5(1.0f - c);
}
inline float3 schlick3(float3 f0, float c) {
  return f0 + (1.0f - f0) * pow5(1.0f - c);
}
inline bool bsdf_has_delta(const Surface* s) {
  return s->roughness <= WP_DELTA_ROUGHNESS;
}
/* Nothing but delta lobes: light sampling cannot contribute (bsdf_eval is 0 everywhere). */
inline bool bsdf_only_delta(const Surface* s) {
  return bsdf_has_delta(s) && s->metallic >= 1.0f;
}

/* Fresnel-weighted reflectance of the specular layer where the microfacet normal is h. */
inline float3 specular_fresnel(const Surface* s, float v_dot_h) {
  const float fd = schlick1(dielectric_f0(s->ior), v_dot_h);
  return (1.0f - s->metallic) * fd + s->metallic * schlick3(s->color, v_dot_h);
}

inline float specular_probability(const Surface* s, float n_dot_v) {
  const float fd = schlick1(dielectric_f0(s->ior), n_dot_v);
  const float w_spec = luminance(specular_fresnel(s, n_dot_v));
  const float w_diff = (1.0f - s->metallic) * (1.0f - fd) * luminance(s->color);
  const float total = w_spec + w_diff;
  return total > 0.0f ? w_spec / total : 1.0f;
}

inline BsdfEval bsdf_eval(const Surface* s, float3 wo, float3 wi) {
  BsdfEval e = {(float3)(0.0f), 0.0f};
  const float n_dot_l = dot(s->ns, wi), n_dot_v = dot(s->ns, wo);
  if (n_dot_l <= 0.0f || n_dot_v <= 0.0f || dot(s->ng, wi) <= 0.0f) return e;
  const float3 h = normalize(wo + wi);
  const float v_dot_h = fmax(dot(wo, h), 0.0f);
  const float fd = schlick1(dielectric_f0(s->ior), v_dot_h);
  const float p_spec = specular_probability(s, n_dot_v);
  e.f = (1.0f - s->metallic) * (1.0f - fd) * WP_INV_PI * s->color;
  e.pdf = (1.0f - p_spec) * cosine_hemisphere_pdf(n_dot_l);
  if (!bsdf_has_delta(s)) {
    const float alpha = sqr(s->roughness);
    const float n_dot_h = fmax(dot(s->ns, h), 0.0f);
    const float dv = ggx_d(n_dot_h, alpha) * ggx_visibility(n_dot_l, n_dot_v, alpha);
    e.f += specular_fresnel(s, v_dot_h) * dv;
    e.pdf += p_spec * ggx_reflection_pdf(n_dot_v, n_dot_h, alpha);
  }
  return e;
}

inline BsdfSample bsdf_sample(const Surface* s, float3 wo, float u_lobe, float2 u) {
  BsdfSample r;
  r.valid = false, r.delta = false, r.pdf = 0.0f;
  r.weight = (float3)(0.0f), r.wi = (float3)(0.0f);
  float3 t, b;
  make_basis(s->ns, &t, &b);
  const float3 wo_l = (float3)(dot(wo, t), dot(wo, b), dot(wo, s->ns));
  if (wo_l.z <= 0.0f) return r;
  const float p_spec = specular_probability(s, wo_l.z);
  float3 wi_l;
  if (u_lobe < p_spec) {
    if (bsdf_has_delta(s)) {
      r.wi = 2.0f * wo_l.z * s->ns - wo;
      r.weight = specular_fresnel(s, wo_l.z) / p_spec;
      r.delta = true;
      r.valid = dot(r.wi, s->ng) > 0.0f;
      return r;
    }
    const float3 h = sample_ggx_visible_normal(wo_l, sqr(s->roughness), u);
    wi_l = 2.0f * dot(wo_l, h) * h - wo_l;
  } else {
    wi_l = sample_cosine_hemisphere(u);
  }
  if (wi_l.z <= 0.0f) return r;
  r.wi = normalize(wi_l.x * t + wi_l.y * b + wi_l.z * s->ns);
  const BsdfEval e = bsdf_eval(s, wo, r.wi);
  if (!(e.pdf > 0.0f)) return r;
  r.pdf = e.pdf;
  r.weight = e.f * dot(s->ns, r.wi) / e.pdf;
  r.valid = true;
  return r;
}

#endif /* WP_BSDF_H */
