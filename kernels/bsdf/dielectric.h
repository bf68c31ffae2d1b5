/* The dielectric interface's transmission (KHR_materials_transmission, _ior, _volume,
 * _dispersion): the relative index of refraction (per colour channel with dispersion), rough
 * transmission through a volume interface or a thin wall, and the delta lobes of a smooth
 * surface (mirror reflection, refraction, straight through). */
#ifndef WP_BSDF_DIELECTRIC_H
#define WP_BSDF_DIELECTRIC_H

#include "bsdf/closure.h"
#include "bsdf/fresnel.h"
#include "bsdf/layers.h"
#include "bsdf/microfacet.h"

#if WP_FEATURE_DISPERSION
/* KHR_materials_dispersion: the index of refraction at wavelength lambda (nanometres) from the
 * Abbe number V = 20 / dispersion, n(lambda) = n + (n - 1) / V (523655 / lambda^2 - 1.5168) (the
 * extension's formula: n at the d line, 587.6 nm, and n_F - n_C = (n - 1) / V). A path carries
 * one colour channel through dispersive refraction, each channel taken at one wavelength: R 630,
 * G 532, B 465 nm. */
static inline float dispersed_ior(float ior, float dispersion, uint channel) {
  const float lambda = channel == 1u ? 630.0f : channel == 2u ? 532.0f : 465.0f;
  const float n =
      ior + (ior - 1.0f) * (dispersion / 20.0f) * (523655.0f / (lambda * lambda) - 1.5168f);
  return fmin(fmax(1.0f, n), WP_MAX_IOR); /* within the indices the transport carries */
}
/* A surface whose transmission refracts with a wavelength-dependent index. */
static inline bool bsdf_dispersive(const Surface* s) {
  return s->dispersion > 0.0f && bsdf_volume(s) && bsdf_transmits(s);
}
/* A dispersive surface reached by a path of all three channels: sampling picks the channel
 * (bsdf_sample), and light sampling does not run there (bsdf_only_delta). */
static inline bool bsdf_choose_channel(const Surface* s) {
  return s->channel == 0u && bsdf_dispersive(s);
}
#endif

/* eta_t / eta_o: index of refraction across the interface relative to wo's side. */
static inline float relative_ior(const Surface* s) {
#if WP_FEATURE_DISPERSION
  if (s->channel != 0u && bsdf_dispersive(s)) {
    const float ior = dispersed_ior(s->ior, s->dispersion, s->channel);
    return !(s->flags & WP_SURF_FRONT) ? 1.0f / ior : ior;
  }
#endif
  return bsdf_volume(s) && !(s->flags & WP_SURF_FRONT) ? 1.0f / s->ior : s->ior;
}

/* A volume interface whose relative index is this close to 1 does not bend light: its
 * transmission is straight through, a delta lobe at any roughness. (The generalised half vector
 * wo + eta wi of a rough interface vanishes as eta -> 1: the transmitted lobe's width is
 * ~ alpha |eta - 1|, and its density ~ 1 / (eta - 1)^2 overflows float32.) Within 1e-3 of 1 the
 * refracted directions differ from straight by less than 1e-3 alpha radians. */
#define WP_ETA_STRAIGHT 1e-3f
static inline bool bsdf_straight_through(const Surface* s, float eta) {
  return !bsdf_volume(s) || fabs(eta - 1.0f) < WP_ETA_STRAIGHT;
}

/* Rough transmission (wi below the surface); delta transmission has no density. */
static inline void eval_transmission(const Surface* s, float3 wo, float3 wi, float eta, Lobes l,
                                     BsdfEval* e) {
  const float alpha = sqr(s->roughness), g = l.spec + l.trans;
  const float cos_o = dot(s->ns, wo), cos_i = dot(s->ns, wi);
  if (!bsdf_volume(s)) { /* thin-walled: the reflection lobe mirrored through the surface */
    const float3 wr = wi - 2.0f * cos_i * s->ns;
    const float3 h = normalize(wo + wr);
    const MicrofacetWeights w = microfacet_weights(s, fmax(dot(wo, h), 0.0f), eta);
    const float3 dvp = spec_reflection(s, wo, wr, h, cos_o, -cos_i);
    e->f = w.transmit * dvp.x * dvp.y;
    e->pdf = g * (1.0f - reflect_prob(w)) * dvp.z;
    return;
  }
  float3 h = normalize(wo + eta * wi); /* generalised half vector */
  if (dot(h, s->ns) < 0.0f) h = -h;
  const float o_h = dot(wo, h), i_h = dot(wi, h);
  if (!(o_h > 0.0f && i_h < 0.0f)) return; /* microfacet seen from the wrong side */
  const float denom = i_h + o_h / eta;
  float d, g2, g1;
#if WP_FEATURE_ANISOTROPY
  if (bsdf_anisotropic(s)) {
    const float2 a = aniso_alpha(s);
    const float lo = ggx_aniso_lambda(aniso_local(s, wo), a.x, a.y);
    d = ggx_aniso_d(aniso_local(s, h), a.x, a.y);
    g2 = 1.0f / (1.0f + lo + ggx_aniso_lambda(aniso_local(s, wi), a.x, a.y));
    g1 = 1.0f / (1.0f + lo);
  } else
#endif
  {
    const float n_dot_h = dot(s->ns, h);
    d = ggx_d(n_dot_h, sin2_between(s->ns, h), alpha);
    g2 = 1.0f / (1.0f + ggx_lambda(cos_o, alpha) + ggx_lambda(cos_i, alpha));
    g1 = ggx_g1(cos_o, alpha);
  }
  const float jacobian = fabs(i_h) / (denom * denom); /* d omega_h / d omega_i */
  const MicrofacetWeights w = microfacet_weights(s, o_h, eta);
  e->f = w.transmit * (d * g2 * o_h * jacobian / (fabs(cos_i) * cos_o) / (eta * eta));
  e->pdf = g * (1.0f - reflect_prob(w)) * g1 * o_h * d / cos_o * jacobian;
}

/* The delta lobes of a smooth surface: mirror reflection, or transmission (refracted with a
 * volume, straight through when thin-walled or index-matched). */
static inline BsdfSample sample_delta(const Surface* s, float3 wo, float cos_o, float eta, Lobes l,
                                      bool transmit) {
  BsdfSample r;
  r.delta = true, r.pdf = 0.0f, r.valid = false, r.eta_scale = 1.0f;
  if (!transmit) {
    r.wi = 2.0f * cos_o * s->ns - wo;
    r.weight = layered_delta(s, wo, r.wi, microfacet_weights(s, cos_o, eta).reflect / l.spec);
    r.valid = dot(r.wi, s->ng) > 0.0f;
    return r;
  }
  float3 tint = microfacet_weights(s, cos_o, eta).transmit / l.trans;
  if (!bsdf_straight_through(s, eta)) {
    const float sin2_t = (1.0f - cos_o * cos_o) / (eta * eta);
    /* Total internal reflection: the (1 - specular) that a specular factor below 1 leaves to
     * transmission has no direction to go; it is lost, as the model says. */
    if (sin2_t >= 1.0f) return r;
    const float cos_t = sqrt(1.0f - sin2_t);
    r.wi = normalize(-wo / eta + (cos_o / eta - cos_t) * s->ns);
  } else {
    r.wi = -wo;
  }
  if (bsdf_volume(s)) { /* radiance changes by 1 / eta^2 across an interface of media */
    tint /= eta * eta;
    r.eta_scale = eta * eta;
  }
  r.weight = layered_delta(s, wo, r.wi, tint);
  r.valid = dot(r.wi, s->ng) < 0.0f;
  return r;
}

/* Rough transmission through an index-matched volume interface (bsdf_straight_through): the
 * direction is -wo whatever the microfacet, a delta lobe. Its weight is the eta -> 1 limit of the
 * rough one, F at the sampled microfacet and G2 / G1 with wi = -wo: (1 + L) / (1 + 2 L), L the
 * Smith Lambda of wo. */
static inline BsdfSample sample_straight(const Surface* s, float3 wo, float cos_o, float eta,
                                         float o_h, float prob) {
  BsdfSample r;
  r.delta = true, r.pdf = 0.0f, r.eta_scale = eta * eta;
  r.wi = -wo;
  float lambda;
#if WP_FEATURE_ANISOTROPY
  if (bsdf_anisotropic(s)) {
    const float2 a = aniso_alpha(s);
    lambda = ggx_aniso_lambda(aniso_local(s, wo), a.x, a.y);
  } else
#endif
    lambda = ggx_lambda(cos_o, sqr(s->roughness));
  r.weight = layered_delta(s, wo, r.wi,
                           microfacet_weights(s, o_h, eta).transmit *
                               ((1.0f + lambda) / (1.0f + 2.0f * lambda) / (prob * eta * eta)));
  r.valid = dot(r.wi, s->ng) < 0.0f;
  return r;
}

#endif /* WP_BSDF_DIELECTRIC_H */
