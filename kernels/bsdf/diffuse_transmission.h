/* KHR_materials_diffuse_transmission: the dielectric base's diffuse light let through to the
 * other side, cosine-weighted there. */
#ifndef WP_BSDF_DIFFUSE_TRANSMISSION_H
#define WP_BSDF_DIFFUSE_TRANSMISSION_H

#include "bsdf/closure.h"
#include "bsdf/dielectric.h"
#include "bsdf/fresnel.h"
#include "sampling/warps.h"

#if WP_FEATURE_DIFFUSE_TRANSMISSION
/* Diffuse transmission (KHR_materials_diffuse_transmission) for wi below the surface: the
 * dielectric base's (1 - F) x (1 - transmission) x diffuseTransmission x colour / pi, F at the half
 * vector of wo and wi mirrored above the surface (as thin-walled transmission has it); into a
 * volume, radiance scales by 1 / eta^2 as for refraction. Its pdf is the cosine-weighted one
 * below. */
static inline void eval_diffuse_transmission(const Surface* s, float3 wo, float3 wi, float eta,
                                             Lobes l, BsdfEval* e) {
  if (!(s->diffuse_transmission > 0.0f)) return;
  const float cos_i = dot(s->ns, wi);
  const float3 h = normalize(wo + wi - 2.0f * cos_i * s->ns);
  const MicrofacetWeights w = microfacet_weights(s, fmax(dot(wo, h), 0.0f), eta);
  const float t = bsdf_transmits(s) ? s->transmission : 0.0f;
  float3 f = (1.0f - s->metallic) * (1.0f - w.fd) * (1.0f - t) * s->diffuse_transmission *
             WP_INV_PI * s->dt_color;
  if (bsdf_volume(s)) f /= eta * eta;
  e->f += f;
  e->pdf += l.dtrans * cosine_hemisphere_pdf(-cos_i);
}

/* A direction from the diffuse transmission's lobe (cosine-weighted below; sample_extra_lobe's
 * first): *wi_l in the sampling frame of ns, *trans set. */
static inline void diffuse_transmission_sample(const Surface* s, float2 u, float3* wi_l,
                                               bool* trans, BsdfSample* r) {
  *wi_l = sample_cosine_hemisphere(u.x, u.y);
  wi_l->z = -wi_l->z;
  *trans = true;
  if (bsdf_volume(s)) r->eta_scale = sqr(relative_ior(s));
}
#endif

#endif /* WP_BSDF_DIFFUSE_TRANSMISSION_H */
