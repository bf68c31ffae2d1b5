/* The layers over the base: KHR_materials_sheen (the Charlie lobe of sheen.h, its albedo scaling
 * the base) and KHR_materials_clearcoat over everything (a GGX lobe about the coat normal, its
 * Fresnel share scaling what lies beneath): what they leave to the base, their own lobes' values,
 * densities and samples. */
#ifndef WP_BSDF_LAYERS_H
#define WP_BSDF_LAYERS_H

#include "bsdf/closure.h"
#include "bsdf/sheen.h"
#include "sampling/warps.h"

/* The layers over the base (KHR_materials_sheen, then KHR_materials_clearcoat on top), and the
 * lobes beside the base's (those and KHR_materials_diffuse_transmission). */
#define WP_BSDF_LAYERED (WP_FEATURE_CLEARCOAT || WP_FEATURE_SHEEN)
#define WP_BSDF_EXTRA_LOBES (WP_BSDF_LAYERED || WP_FEATURE_DIFFUSE_TRANSMISSION)

#if WP_FEATURE_CLEARCOAT
static inline bool coat_smooth(const Surface* s) {
  return sqr(s->clearcoat_roughness) < WP_DELTA_ALPHA;
}
/* The coat's share clearcoat x Fc, Fc Schlick's term for ior 1.5 (F0 0.04) at the coat normal's
 * cosine to wo (the extension's fresnel_coat): the layers beneath are scaled by 1 - this. */
static inline float coat_weight(const Surface* s, float3 wo) {
  if (!(s->clearcoat > 0.0f)) return 0.0f;
  return s->clearcoat * (0.04f + 0.96f * pow5(1.0f - fmin(fabs(dot(s->nc, wo)), 1.0f)));
}
#endif

#if WP_FEATURE_SHEEN
static inline bool has_sheen(const Surface* s) {
  return max3(s->sheen_color) > 0.0f;
}
/* 1 - max3(sheen colour) E: the share the sheen leaves to the base for one direction whose
 * sheen albedo is E (never below 0: E exceeds 1 for smooth sheens, kernels/bsdf/sheen.h). */
static inline float sheen_leaves_e(const Surface* s, float e) {
  return fmax(0.0f, 1.0f - max3(s->sheen_color) * e);
}
/* The same for the direction at cosine c, E from the table. */
static inline float sheen_leaves(const Surface* s, float c) {
  return sheen_leaves_e(s, sheen_albedo(fmin(fabs(c), 1.0f), s->sheen_roughness));
}
#endif

#if WP_BSDF_LAYERED
/* What the coat leaves to the layers beneath at wo: 1 - its share (1 without a coat). */
static inline float coat_leaves(const Surface* s, float3 wo) {
#if WP_FEATURE_CLEARCOAT
  return 1.0f - coat_weight(s, wo);
#else
  (void)s, (void)wo;
  return 1.0f;
#endif
}

/* What scales the base for the pair (wo, wi): what the coat leaves at wo (`top`, coat_leaves),
 * times the sheen's albedo scaling min(1 - max3(c) E(n.wo), 1 - max3(c) E(n.wi)) (the extension's
 * form). */
static inline float layer_base_scale(const Surface* s, float top, float cos_o, float cos_i) {
  float k = top;
#if WP_FEATURE_SHEEN
  if (has_sheen(s)) k *= fmin(sheen_leaves(s, cos_o), sheen_leaves(s, cos_i));
#endif
  (void)s, (void)cos_o, (void)cos_i;
  return k;
}
#endif

/* The layers' scaling of a delta lobe of the base from wo into wi. */
static inline float3 layered_delta(const Surface* s, float3 wo, float3 wi, float3 weight) {
#if WP_BSDF_LAYERED
  return weight * layer_base_scale(s, coat_leaves(s, wo), dot(s->ns, wo), dot(s->ns, wi));
#else
  (void)s, (void)wo, (void)wi;
  return weight;
#endif
}

#if WP_BSDF_LAYERED
/* The layers over the base for a wi above or below: the base's f scaled (layer_base_scale), the
 * sheen (its colour x D V of kernels/bsdf/sheen.h, under the coat) and the rough coat (GGX about
 * the coat normal, clearcoat x Fc x D V) added for wi above, with their pdfs (cosine-weighted for
 * the sheen, the coat normal's visible normals for the coat). Each lobe is counted with ns's
 * cosine, as the rest of the BSDF. */
static inline void eval_layers(const Surface* s, float3 wo, float3 wi, float cos_o, float cos_i,
                               bool above, Lobes l, BsdfEval* e) {
  float coat = 0.0f; /* the coat's share at wo */
#if WP_FEATURE_CLEARCOAT
  coat = coat_weight(s, wo);
#endif
  const float top = 1.0f - coat; /* what the coat leaves to the layers beneath (coat_leaves) */
  e->f *= layer_base_scale(s, top, cos_o, cos_i);
  if (!above) return;
#if WP_FEATURE_CLEARCOAT
  if (coat > 0.0f && !coat_smooth(s)) {
    const float co = dot(s->nc, wo), ci = dot(s->nc, wi);
    if (co > 0.0f && ci > 0.0f) {
      const float alpha = sqr(s->clearcoat_roughness);
      const float3 h = normalize(wo + wi);
      const float n_dot_h = fmax(dot(s->nc, h), 0.0f), sin2_h = sin2_between(s->nc, h);
      e->f += coat * ggx_d(n_dot_h, sin2_h, alpha) * ggx_visibility(ci, co, alpha);
      e->pdf += l.coat * ggx_reflection_pdf(co, n_dot_h, sin2_h, alpha);
    }
  }
#endif
#if WP_FEATURE_SHEEN
  if (has_sheen(s)) {
    e->f += top * s->sheen_color * sheen_eval(s->ns, wo, wi, sheen_alpha(s->sheen_roughness));
    e->pdf += l.sheen * cosine_hemisphere_pdf(cos_i);
  }
#endif
}
#endif

#if WP_FEATURE_CLEARCOAT
/* A direction from the coat's lobe (sample_extra_lobe's third): returns 1 with *r filled for the
 * smooth coat's delta lobe, or left invalid where the sample is lost; 0 with *wi_l (the sampling
 * frame t, b, ns of the base) to be evaluated as usual. */
static inline int coat_sample(const Surface* s, float3 wo, float3 t, float3 b, Lobes l, float2 u,
                              float3* wi_l, BsdfSample* r) {
  const float3 nc = s->nc;
  if (coat_smooth(s)) {
    r->delta = true;
    r->wi = 2.0f * dot(nc, wo) * nc - wo;
    r->weight = (float3)(coat_weight(s, wo) / l.coat);
    r->valid = dot(r->wi, s->ng) > 0.0f && dot(r->wi, s->ns) > 0.0f;
    return 1;
  }
  float3 tc, bc;
  make_basis(nc, &tc, &bc);
  const float3 oc = (float3)(dot(wo, tc), dot(wo, bc), dot(wo, nc));
  if (!(oc.z > 0.0f)) return 1; /* r stays invalid */
  const float3 h = sample_ggx_visible_normal(oc, sqr(s->clearcoat_roughness), u.x, u.y);
  const float3 ic = 2.0f * dot(oc, h) * h - oc;
  if (!(ic.z > 0.0f)) return 1; /* below the coat: no density in the coat's lobe, lost */
  const float3 w = ic.x * tc + ic.y * bc + ic.z * nc; /* to the sampling frame of ns */
  *wi_l = (float3)(dot(w, t), dot(w, b), dot(w, s->ns));
  return 0;
}
#endif

#endif /* WP_BSDF_LAYERS_H */
