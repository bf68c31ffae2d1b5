/* The glTF 2.0 material BSDF: metallic-roughness (specification, appendix B) with
 * KHR_materials_transmission, KHR_materials_ior and KHR_materials_volume, evaluated and
 * importance-sampled.
 *
 *   f = metallic * F_m * D V
 *     + (1 - metallic) * [ F_d * D V + (1 - F_d) * ((1 - t) * base / pi + t * base * BTDF) ]
 *   F_m = base + (1 - base) (1 - |v.h|)^5          (conductor, Schlick)
 *   F_d = s [f0 + (1 - f0) (1 - c)^5], f0 = ((ior - 1) / (ior + 1))^2, s the specular factor
 *         (KHR_materials_specular; 1 without it, 0 leaves a pure Lambertian), c the cosine on the
 * optically thinner side of the interface (so F_d = 1 beyond the critical angle: total internal
 *         reflection); for an opaque surface, seen from outside, this is exactly the
 *         specification's Schlick term at v.h
 *   D: GGX with alpha = roughness^2; V = G2 / (4 |n.l| |n.v|), G2 the height-correlated Smith term;
 *   t: transmission. BTDF: with KHR_materials_volume (WP_SURF_VOLUME) a rough dielectric
 *   interface (Walter et al. 2007: microfacet refraction with the generalised half vector,
 *   radiance scaled by 1/eta^2 for the change of medium); without it the surface is thin-walled
 *   and light passes through unbent: the transmitted lobe is the reflected one mirrored through
 *   the surface.
 *
 * A surface with roughness <= WP_DELTA_ROUGHNESS is perfectly smooth: its specular reflection and
 * transmission are delta lobes (a flag, not a pdf), which evaluation leaves out (they have no
 * density). The diffuse term stays an ordinary lobe.
 *
 * Sampling first picks a lobe - specular reflection, transmission or diffuse - with probabilities
 * proportional to their Fresnel-weighted albedo estimates at n.v (a function of wo alone), then a
 * direction: GGX visible normals for reflection and transmission, cosine-weighted for diffuse.
 * For non-delta lobes the returned pdf is the mixture density of all lobes at wi, the number
 * bsdf_eval returns for the pair. Directions are world-space unit vectors pointing away from the
 * surface; wo is toward the viewer. Surfaces seen from the back of a volume (the ray travels
 * inside) have the relative index of refraction 1 / ior.
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
  float3 p;      /* position */
  float p_scale; /* magnitude bound of p's computation, for offset_origin (common.h) */
  float3 ng;     /* geometric normal, on the side of wo */
  float3 ns;     /* shading normal, same side */
  float3 color;
  float metallic, roughness, ior, transmission;
  float specular; /* KHR_materials_specular specularFactor: scales the dielectric Fresnel term */
  uint flags;     /* WP_SURF_* */
} Surface;

typedef struct BsdfEval {
  float3 f;  /* BSDF value (no cosine), delta lobes excluded */
  float pdf; /* solid-angle density with which bsdf_sample would produce wi */
} BsdfEval;

typedef struct BsdfSample {
  float3 wi;
  float3 weight; /* f * |n.wi| / pdf, or a delta lobe's weight / its selection probability */
  float pdf;     /* 0 for a delta lobe */
  bool delta;
  bool valid; /* false: the path ends here (no direction, or one on the wrong side) */
} BsdfSample;

/* Lobe selection probabilities; they sum to 1. */
typedef struct Lobes {
  float spec, trans, diff;
} Lobes;

inline bool bsdf_has_delta(const Surface* s) {
  return s->roughness <= WP_DELTA_ROUGHNESS;
}
inline bool bsdf_transmits(const Surface* s) {
#if WP_FEATURE_TRANSMISSION
  return s->transmission > 0.0f && s->metallic < 1.0f;
#else
  (void)s;
  return false;
#endif
}
inline bool bsdf_volume(const Surface* s) {
#if WP_FEATURE_VOLUME
  return (s->flags & WP_SURF_VOLUME) != 0u;
#else
  (void)s;
  return false;
#endif
}
/* Nothing but delta lobes: light sampling cannot contribute (bsdf_eval is 0 everywhere). */
inline bool bsdf_only_delta(const Surface* s) {
  return bsdf_has_delta(s) && (s->metallic >= 1.0f || s->transmission >= 1.0f);
}

/* eta_t / eta_o: index of refraction across the interface relative to wo's side. */
inline float relative_ior(const Surface* s) {
  return bsdf_volume(s) && !(s->flags & WP_SURF_FRONT) ? 1.0f / s->ior : s->ior;
}

/* The dielectric Fresnel reflectance (Schlick) for a wave meeting the interface at cosine cos_o on
 * its side, eta = eta_other / eta_own. From the denser side the cosine of the refracted direction
 * is used, and beyond the critical angle everything is reflected. */
inline float fresnel_dielectric(float cos_o, float eta) {
  const float f0 = sqr((eta - 1.0f) / (eta + 1.0f));
  float c = cos_o;
  if (eta < 1.0f) {
    const float sin2_t = (1.0f - cos_o * cos_o) / (eta * eta);
    if (sin2_t >= 1.0f) return 1.0f;
    c = sqrt(1.0f - sin2_t);
  }
  return f0 + (1.0f - f0) * pow5(1.0f - c);
}

inline float3 schlick3(float3 f0, float c) {
  return f0 + (1.0f - f0) * pow5(1.0f - c);
}

/* The dielectric layer's reflectance at cosine cos_o: the Fresnel term scaled by the specular
 * factor. */
inline float dielectric_reflectance(const Surface* s, float cos_o, float eta) {
  return s->specular * fresnel_dielectric(cos_o, eta);
}

inline Lobes bsdf_lobes(const Surface* s, float cos_o, float eta) {
  const float m = s->metallic, fd = dielectric_reflectance(s, cos_o, eta);
  const float t = bsdf_transmits(s) ? s->transmission : 0.0f;
  const float albedo = luminance(s->color);
  const float w_spec = (1.0f - m) * fd + m * luminance(schlick3(s->color, cos_o));
  const float w_trans = (1.0f - m) * (1.0f - fd) * t * albedo;
  const float w_diff = (1.0f - m) * (1.0f - fd) * (1.0f - t) * albedo;
  const float total = w_spec + w_trans + w_diff;
  Lobes l = {1.0f, 0.0f, 0.0f};
  if (total > 0.0f) l.spec = w_spec / total, l.trans = w_trans / total, l.diff = w_diff / total;
  return l;
}

/* Smith Lambda for GGX; G2 = 1 / (1 + Lambda(o) + Lambda(i)) is the height-correlated term. */
inline float ggx_lambda(float cos_theta, float alpha) {
  const float c2 = cos_theta * cos_theta;
  const float tan2 = fmax(0.0f, 1.0f - c2) / fmax(c2, 1e-12f);
  return 0.5f * (sqrt(1.0f + alpha * alpha * tan2) - 1.0f);
}

/* Reflection: f and pdf of the specular and diffuse lobes for wi above the surface. */
inline void eval_reflection(const Surface* s, float3 wo, float3 wi, float eta, Lobes l,
                            BsdfEval* e) {
  const float cos_i = dot(s->ns, wi), cos_o = dot(s->ns, wo);
  const float3 h = normalize(wo + wi);
  const float v_dot_h = fmax(dot(wo, h), 0.0f);
  const float fd = dielectric_reflectance(s, v_dot_h, eta);
  const float t = bsdf_transmits(s) ? s->transmission : 0.0f;
  e->f = (1.0f - s->metallic) * (1.0f - fd) * (1.0f - t) * WP_INV_PI * s->color;
  e->pdf = l.diff * cosine_hemisphere_pdf(cos_i);
  if (bsdf_has_delta(s)) return;
  const float alpha = sqr(s->roughness);
  const float n_dot_h = fmax(dot(s->ns, h), 0.0f);
  const float dv = ggx_d(n_dot_h, alpha) * ggx_visibility(cos_i, cos_o, alpha);
  e->f += ((1.0f - s->metallic) * fd + s->metallic * schlick3(s->color, v_dot_h)) * dv;
  e->pdf += l.spec * ggx_reflection_pdf(cos_o, n_dot_h, alpha);
}

/* Rough transmission (wi below the surface); delta transmission has no density. */
inline void eval_transmission(const Surface* s, float3 wo, float3 wi, float eta, Lobes l,
                              BsdfEval* e) {
  const float alpha = sqr(s->roughness);
  const float cos_o = dot(s->ns, wo), cos_i = dot(s->ns, wi);
  const float3 tint = (1.0f - s->metallic) * s->transmission * s->color;
  if (!bsdf_volume(s)) { /* thin-walled: the reflection lobe mirrored through the surface */
    const float3 wr = wi - 2.0f * cos_i * s->ns;
    const float3 h = normalize(wo + wr);
    const float n_dot_h = fmax(dot(s->ns, h), 0.0f);
    const float fd = dielectric_reflectance(s, fmax(dot(wo, h), 0.0f), eta);
    e->f = tint * (1.0f - fd) * ggx_d(n_dot_h, alpha) * ggx_visibility(-cos_i, cos_o, alpha);
    e->pdf = l.trans * ggx_reflection_pdf(cos_o, n_dot_h, alpha);
    return;
  }
  float3 h = normalize(wo + eta * wi); /* generalised half vector */
  if (dot(h, s->ns) < 0.0f) h = -h;
  const float o_h = dot(wo, h), i_h = dot(wi, h);
  if (!(o_h > 0.0f && i_h < 0.0f)) return; /* microfacet seen from the wrong side */
  const float denom = i_h + o_h / eta;
  const float n_dot_h = dot(s->ns, h);
  const float d = ggx_d(n_dot_h, alpha);
  const float g2 = 1.0f / (1.0f + ggx_lambda(cos_o, alpha) + ggx_lambda(cos_i, alpha));
  const float fd = dielectric_reflectance(s, o_h, eta);
  const float jacobian = fabs(i_h) / (denom * denom); /* d omega_h / d omega_i */
  e->f = tint * ((1.0f - fd) * d * g2 * o_h * jacobian / (fabs(cos_i) * cos_o) / (eta * eta));
  e->pdf = l.trans * ggx_g1(cos_o, alpha) * o_h * d / cos_o * jacobian;
}

inline BsdfEval bsdf_eval(const Surface* s, float3 wo, float3 wi) {
  BsdfEval e = {(float3)(0.0f), 0.0f};
  const float cos_i = dot(s->ns, wi), cos_o = dot(s->ns, wo);
  if (!(cos_o > 0.0f)) return e;
  const float eta = relative_ior(s);
  const Lobes l = bsdf_lobes(s, cos_o, eta);
  const bool above = cos_i > 0.0f && dot(s->ng, wi) > 0.0f;
  const bool below = cos_i < 0.0f && dot(s->ng, wi) < 0.0f;
  if (above)
    eval_reflection(s, wo, wi, eta, l, &e);
  else if (below && l.trans > 0.0f && !bsdf_has_delta(s))
    eval_transmission(s, wo, wi, eta, l, &e);
  return e;
}

/* The delta lobes of a smooth surface: mirror reflection, or transmission (refracted with a
 * volume, straight through when thin-walled). */
inline BsdfSample sample_delta(const Surface* s, float3 wo, float cos_o, float eta, Lobes l,
                               bool transmit) {
  BsdfSample r;
  r.delta = true, r.pdf = 0.0f, r.valid = false;
  const float fd = dielectric_reflectance(s, cos_o, eta);
  if (!transmit) {
    r.wi = 2.0f * cos_o * s->ns - wo;
    r.weight = ((1.0f - s->metallic) * fd + s->metallic * schlick3(s->color, cos_o)) / l.spec;
    r.valid = dot(r.wi, s->ng) > 0.0f;
    return r;
  }
  float3 tint = (1.0f - s->metallic) * s->transmission * (1.0f - fd) * s->color / l.trans;
  if (bsdf_volume(s)) {
    const float sin2_t = (1.0f - cos_o * cos_o) / (eta * eta);
    const float cos_t = sqrt(fmax(0.0f, 1.0f - sin2_t)); /* l.trans > 0 excludes TIR */
    r.wi = normalize(-wo / eta + (cos_o / eta - cos_t) * s->ns);
    tint /= eta * eta;
  } else {
    r.wi = -wo;
  }
  r.weight = tint;
  r.valid = dot(r.wi, s->ng) < 0.0f;
  return r;
}

inline BsdfSample bsdf_sample(const Surface* s, float3 wo, float u_lobe, float2 u) {
  BsdfSample r;
  r.valid = false, r.delta = false, r.pdf = 0.0f;
  r.weight = (float3)(0.0f), r.wi = (float3)(0.0f);
  float3 t, b;
  make_basis(s->ns, &t, &b);
  const float3 wo_l = (float3)(dot(wo, t), dot(wo, b), dot(wo, s->ns));
  if (!(wo_l.z > 0.0f)) return r;
  const float eta = relative_ior(s);
  const Lobes l = bsdf_lobes(s, wo_l.z, eta);
  const bool spec = u_lobe < l.spec, trans = !spec && u_lobe < l.spec + l.trans;
  if ((spec || trans) && bsdf_has_delta(s)) return sample_delta(s, wo, wo_l.z, eta, l, trans);
  float3 wi_l;
  if (spec || trans) {
    const float3 h = sample_ggx_visible_normal(wo_l, sqr(s->roughness), u);
    const float o_h = dot(wo_l, h);
    wi_l = 2.0f * o_h * h - wo_l; /* reflection about the microfacet */
    if (trans && !bsdf_volume(s)) {
      wi_l.z = -wi_l.z; /* thin-walled: mirrored through the surface */
    } else if (trans) {
      const float sin2_t = (1.0f - o_h * o_h) / (eta * eta);
      if (sin2_t >= 1.0f) return r; /* total internal reflection at this microfacet */
      wi_l = -wo_l / eta + (o_h / eta - sqrt(1.0f - sin2_t)) * h;
    }
  } else {
    wi_l = sample_cosine_hemisphere(u);
  }
  /* A lobe's direction on the other side than the lobe covers (a reflection below the surface,
   * a transmission above it) has no density in that lobe: evaluating it there would mix in the
   * other side's lobes and break the pdf. It is lost, as it should be. */
  if (trans ? wi_l.z >= 0.0f : wi_l.z <= 0.0f) return r;
  r.wi = normalize(wi_l.x * t + wi_l.y * b + wi_l.z * s->ns);
  const BsdfEval e = bsdf_eval(s, wo, r.wi);
  if (!(e.pdf > 0.0f)) return r;
  r.pdf = e.pdf;
  r.weight = e.f * fabs(dot(s->ns, r.wi)) / e.pdf;
  r.valid = true;
  return r;
}

#endif /* WP_BSDF_H */
