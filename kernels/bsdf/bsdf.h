/* The glTF 2.0 material BSDF: metallic-roughness (specification, appendix B) with
 * KHR_materials_transmission, KHR_materials_ior and KHR_materials_volume, and the layered
 * extensions (specular, clearcoat, sheen, anisotropy, iridescence, diffuse transmission) and
 * dispersion (a path's colour channel, bsdf_sample), evaluated and importance-sampled.
 *
 * The base, per the specification and KHR_materials_specular's fresnel_mix:
 *   f_base = metallic * F_m * D V
 *          + (1 - metallic) * [ F_d * D V + (1 - max3 F_d) * ((1 - t) * diffuse + t * base * BTDF)
 * ] diffuse = (1 - dt) * base / pi above, dt * dtColor / pi below (KHR_materials_diffuse_
 *             transmission; dt = 0 without it; into a volume the part below also takes 1 / eta^2)
 *   F_m = base + (1 - base) (1 - |v.h|)^5          (conductor, Schlick)
 *   F_d = s [F0 + (1 - F0) (1 - c)^5], F0 = min(f0 * specularColor, 1), f0 = ((ior - 1) / (ior +
 *         1))^2, s the specular factor (KHR_materials_specular; 1 without it, 0 leaves a pure
 *         Lambertian), c the cosine on the optically thinner side of the interface (so F_d = s
 *         beyond the critical angle: total internal reflection); for an opaque surface, seen from
 *         outside, this is exactly the specification's Schlick term at v.h. With
 *         KHR_materials_iridescence both Fresnel terms are mixed with the thin film's
 *         (iridescence.h) by the iridescence factor: F_d -> mix(F_d, F_film(s F0), iridescence)
 *         (on the outside only: not from inside a volume), F_m -> mix(F_m, F_film(base),
 *         iridescence). At total internal reflection with s < 1, the 1 - s left to transmission
 *         is lost.
 *         The diffuse and transmitted part keeps 1 - max3(F_d) (F_d grey without specular colour
 *         or iridescence: then 1 - F_d).
 *   D: GGX with alpha = roughness^2; V = G2 / (4 |n.l| |n.v|), G2 the height-correlated Smith term.
 *      With KHR_materials_anisotropy (strength > 0) D and G2 are anisotropic GGX (ggx_aniso.h) with
 *      alpha mix(alpha, 1, strength^2) along the anisotropy direction and alpha across it.
 *   t: transmission. BTDF: with KHR_materials_volume (WP_SURF_VOLUME) a rough dielectric
 *   interface (Walter et al. 2007: microfacet refraction with the generalised half vector,
 *   radiance scaled by 1/eta^2 for the change of medium); without it the surface is thin-walled
 *   and light passes through unbent: the transmitted lobe is the reflected one mirrored through
 *   the surface. The diffuse transmission's Fresnel weight takes wi mirrored above the surface
 *   likewise.
 *
 * The layers over the base (KHR_materials_sheen, then KHR_materials_clearcoat over everything):
 *   f = cc Fc D_c V_c + (1 - cc Fc) [ sheenColor D_s V_s + S f_base ]
 *   Fc = 0.04 + 0.96 (1 - |nc.wo|)^5 at the coat normal nc (the extension's fresnel_coat, which
 *        takes n.v, not v.h, so that (1 - cc Fc) + cc Fc E_c <= 1); D_c V_c GGX about nc with
 *        alpha = clearcoatRoughness^2, for wi above nc. cc = 0 without the coat.
 *   D_s V_s: the Charlie sheen lobe of kernels/bsdf/sheen.h about ns (alpha = sheenRoughness^2),
 *        for wi above; S = min(1 - max3(sheenColor) E(|n.wo|), 1 - max3(sheenColor) E(|n.wi|)),
 *        E the lobe's directional albedo (a table, sheen.h), clamped at 0. S = 1 without sheen.
 * Every lobe is integrated against ns's cosine (f |ns.wi| is what the integrator multiplies).
 *
 * A surface with roughness^2 < WP_DELTA_ALPHA (anisotropic: mix(roughness^2, 1, strength^2), its
 * larger alpha) is perfectly smooth: its specular reflection and transmission are delta lobes (a
 * flag, not a pdf), which evaluation leaves out (they have no density), and a coat with
 * clearcoatRoughness^2 below it is a delta lobe too. The diffuse term
 * stays an ordinary lobe.
 *
 * Sampling first picks a lobe, with probabilities proportional to Fresnel-weighted albedo
 * estimates at n.v (a function of wo alone, bsdf_lobes): the base's microfacet lobes, diffuse,
 * diffuse transmission (cosine-weighted below), sheen (cosine-weighted) and coat (GGX visible
 * normals about nc), the base's scaled by what the layers leave it at wo. The microfacet lobes
 * draw a normal h from GGX's visible normals and then choose reflection or transmission at that
 * microfacet, in proportion to its Fresnel weights at wo.h (as pbrt-v4's dielectric does); the
 * diffuse lobe is cosine-weighted.
 * For non-delta lobes the returned pdf is the mixture density of all lobes at wi, the number
 * bsdf_eval returns for the pair. Directions are world-space unit vectors pointing away from the
 * surface; wo is toward the viewer. Surfaces seen from the back of a volume (the ray travels
 * inside) have the relative index of refraction 1 / ior.
 *
 * Built with WP_FEATURE_GLOSSY 0 (a scene whose every scattering material has metallic 0,
 * specular factor 0, no transmission and no layered extension: host/device/scene_features.cpp),
 * f reduces to base / pi, and evaluation and sampling are Lambert's alone (lambert.h): the same
 * values, without the lobe machinery. Each extension's code compiles only with its WP_FEATURE_*
 * (features.h).
 *
 * The lobes live in headers of their own: closure.h (the surface record and the results),
 * microfacet.h (GGX, anisotropic GGX), fresnel.h (dielectric, metal, specular colour,
 * iridescence), dielectric.h (index of refraction, dispersion, transmission, the delta lobes),
 * layers.h (sheen and clearcoat), diffuse_transmission.h, lambert.h. This file composes them: the
 * lobe probabilities, evaluation and sampling, where the feature switches choose what a program
 * has.
 */
#ifndef WP_BSDF_H
#define WP_BSDF_H

#include "util/common.h"
#include "bsdf/closure.h"
#include "bsdf/microfacet.h"
#include "bsdf/fresnel.h"
#include "bsdf/layers.h"
#include "bsdf/dielectric.h"
#include "bsdf/diffuse_transmission.h"
#include "bsdf/lambert.h"

/* The BSDF of WP_BSDF_PLAIN programs (lane code: util/lanes_begin.def). */
#if WP_BSDF_PLAIN
#define WP_LW 1
#include "bsdf/glossy.def"
#if WP_SHADE_PACKET
#define WP_LW 8
#include "bsdf/glossy.def"
#endif
#endif

/* Nothing but delta lobes: light sampling cannot contribute (bsdf_eval is 0 everywhere). Also
 * where a dispersive refraction has still to choose the path's channel: the sampled direction
 * then counts with MIS weight 1, as a delta lobe's. */
static inline bool bsdf_only_delta(const Surface* s) {
  bool only = bsdf_has_delta(s) && (s->metallic >= 1.0f || s->transmission >= 1.0f);
#if WP_FEATURE_SHEEN
  only = only && !has_sheen(s);
#endif
#if WP_FEATURE_CLEARCOAT
  only = only && !(s->clearcoat > 0.0f && !coat_smooth(s));
#endif
#if WP_FEATURE_DISPERSION
  only = only || bsdf_choose_channel(s);
#endif
  return only;
}

/* The lobes' probabilities at wo: proportional to their albedo estimates (the Fresnel-weighted
 * colour of each, the sheen's table albedo, the coat's share), each scaled as the layers above
 * scale it. */
static inline Lobes bsdf_lobes(const Surface* s, float3 wo, float cos_o, float eta) {
  MicrofacetWeights w = microfacet_weights(s, cos_o, eta);
  /* From inside a volume beyond the critical angle the macro normal's Fresnel term is 1, yet
   * microfacets at other angles let the diffuse lobes through: weigh those with the term at
   * normal incidence there, so that they keep a probability wherever they have a value. */
  if (eta < 1.0f && 1.0f - cos_o * cos_o >= eta * eta) w.fd = microfacet_weights(s, 1.0f, eta).fd;
  const float t = bsdf_transmits(s) ? s->transmission : 0.0f;
  float w_spec = luminance(w.reflect), w_trans = luminance(w.transmit);
  float w_diff = (1.0f - s->metallic) * (1.0f - w.fd) * (1.0f - t) * luminance(s->color);
  float total = w_spec + w_trans + w_diff;
  Lobes l = {1.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
#if WP_BSDF_EXTRA_LOBES
  float w_dtrans = 0.0f, w_sheen = 0.0f, w_coat = 0.0f;
#if WP_FEATURE_DIFFUSE_TRANSMISSION
  const float base = (1.0f - s->metallic) * (1.0f - w.fd) * (1.0f - t);
  w_diff = base * (1.0f - s->diffuse_transmission) * luminance(s->color);
  w_dtrans = base * s->diffuse_transmission * luminance(s->dt_color);
#endif
  float k = 1.0f; /* the layers' scaling of the base at wo */
#if WP_FEATURE_CLEARCOAT
  w_coat = coat_weight(s, wo);
  k = 1.0f - w_coat;
#endif
#if WP_FEATURE_SHEEN
  if (has_sheen(s)) { /* one table look-up for both (cos_o > 0: sheen_albedo clamps to 1) */
    const float e = sheen_albedo(cos_o, s->sheen_roughness);
    w_sheen = k * luminance(s->sheen_color) * e;
    k *= sheen_leaves_e(s, e);
  }
#endif
  w_spec *= k, w_trans *= k, w_diff *= k, w_dtrans *= k;
  total = w_spec + w_trans + w_diff + w_dtrans + w_sheen + w_coat;
  if (total > 0.0f) {
    l.dtrans = w_dtrans / total, l.sheen = w_sheen / total, l.coat = w_coat / total;
  }
#endif
  (void)wo;
  if (total > 0.0f) l.spec = w_spec / total, l.trans = w_trans / total, l.diff = w_diff / total;
  return l;
}

/* Reflection: f and pdf of the specular and diffuse lobes for wi above the surface. */
static inline void eval_reflection(const Surface* s, float3 wo, float3 wi, float eta, Lobes l,
                                   BsdfEval* e) {
  const float cos_i = dot(s->ns, wi), cos_o = dot(s->ns, wo);
  const float3 h = normalize(wo + wi);
  const float v_dot_h = fmax(dot(wo, h), 0.0f);
  const MicrofacetWeights w = microfacet_weights(s, v_dot_h, eta);
  const float t = bsdf_transmits(s) ? s->transmission : 0.0f;
  e->f = (1.0f - s->metallic) * (1.0f - w.fd) * (1.0f - t) * WP_INV_PI * s->color;
#if WP_FEATURE_DIFFUSE_TRANSMISSION
  e->f *= 1.0f - s->diffuse_transmission;
#endif
  e->pdf = l.diff * cosine_hemisphere_pdf(cos_i);
  if (bsdf_has_delta(s)) return;
  const float3 dvp = spec_reflection(s, wo, wi, h, cos_o, cos_i);
  const float dv = dvp.x * dvp.y;
  e->f += w.reflect * dv;
  e->pdf += (l.spec + l.trans) * reflect_prob(w) * dvp.z;
}

/* What the BSDF at a surface needs of wo alone, worked out once per scattering event
 * (bsdf_view) and shared by the NEE evaluation, the lobe choice and the evaluation of the sampled
 * direction, which would otherwise each work out the same numbers. bsdf_eval and bsdf_sample make
 * their own. */
typedef struct BsdfView {
  float cos_o; /* ns . wo */
#if WP_FEATURE_GLOSSY
  float eta;   /* relative_ior */
  Lobes lobes; /* bsdf_lobes at wo; all 0 where cos_o <= 0, which neither evaluates nor samples */
#endif
} BsdfView;

/* The view at wo (BsdfView). */
static inline BsdfView bsdf_view(const Surface* s, float3 wo) {
  BsdfView v;
  v.cos_o = dot(s->ns, wo);
#if WP_FEATURE_GLOSSY
  v.eta = relative_ior(s);
  Lobes none = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
#if WP_BSDF_PLAIN
  (void)wo;
  if (v.cos_o > 0.0f) none.diff = glossy_lobes(s, v.cos_o, v.eta, &none.spec);
  v.lobes = none;
#else
  /* Only above the surface: the sheen table is looked up at cos_o. */
  v.lobes = v.cos_o > 0.0f ? bsdf_lobes(s, wo, v.cos_o, v.eta) : none;
#endif
#endif
  return v;
}

/* f and pdf for the pair (wo, wi): Lambert's alone in programs without WP_FEATURE_GLOSSY; else the
 * base's reflection or transmission, the diffuse transmission and the layers. */
WP_BSDF_EVAL_INLINE BsdfEval bsdf_eval_view(const Surface* s, const BsdfView* v, float3 wo,
                                            float3 wi) {
#if !WP_FEATURE_GLOSSY
  (void)wo;
  return lambert_eval(s, v->cos_o, wi);
#elif WP_BSDF_PLAIN
  BsdfEval e;
  e.f = glossy_f(s, wo, wi, v->cos_o, v->eta, v->lobes.spec, v->lobes.diff, &e.pdf);
  return e;
#else
  BsdfEval e = {(float3)(0.0f), 0.0f};
  const float cos_i = dot(s->ns, wi), cos_o = v->cos_o;
  if (!(cos_o > 0.0f)) return e;
  const float eta = v->eta;
  const Lobes l = v->lobes;
  const bool above = cos_i > 0.0f && dot(s->ng, wi) > 0.0f;
  const bool below = cos_i < 0.0f && dot(s->ng, wi) < 0.0f;
  if (above)
    eval_reflection(s, wo, wi, eta, l, &e);
  else if (below && bsdf_transmits(s) && !bsdf_has_delta(s) &&
           !(bsdf_volume(s) && bsdf_straight_through(s, eta)))
    eval_transmission(s, wo, wi, eta, l, &e);
#if WP_FEATURE_DIFFUSE_TRANSMISSION
  if (below) eval_diffuse_transmission(s, wo, wi, eta, l, &e);
#endif
#if WP_BSDF_LAYERED
  if (above || below) eval_layers(s, wo, wi, cos_o, cos_i, above, l, &e);
#endif
  return e;
#endif
}

/* What a smooth thin-walled transmitter lets a shadow ray along d through (trace_shadow.h): the
 * weight of its delta transmission straight on, with the layers' scaling; nothing without
 * WP_FEATURE_GLOSSY (no transmission). */
static inline float3 bsdf_pane_transmittance(const Surface* s, float3 d) {
#if WP_FEATURE_GLOSSY
  const float c = fabs(dot(s->ns, d));
  return layered_delta(s, -d, d, microfacet_weights(s, c, relative_ior(s)).transmit);
#else
  (void)s, (void)d;
  return (float3)(0.0f);
#endif
}

#if WP_FEATURE_GLOSSY
#if WP_BSDF_EXTRA_LOBES
/* The lobes after the diffuse one, chosen by v = u_lobe - (spec + trans + diff) in the order
 * diffuse transmission, sheen, coat: sets *wi_l (local frame) and *trans and returns 0 when the
 * direction is then evaluated as usual; returns 1 with *r filled for the smooth coat's delta
 * lobe; 2 when v lies past every lobe (rounding), which falls back to the diffuse lobe. */
static inline int sample_extra_lobe(const Surface* s, float3 wo, float3 t, float3 b, Lobes l,
                                    float v, float2 u, float3* wi_l, bool* trans, BsdfSample* r) {
  (void)wo, (void)t, (void)b, (void)r;
#if WP_FEATURE_DIFFUSE_TRANSMISSION
  if (v < l.dtrans) {
    diffuse_transmission_sample(s, u, wi_l, trans, r);
    return 0;
  }
  v -= l.dtrans;
#endif
#if WP_FEATURE_SHEEN
  if (v < l.sheen) {
    *wi_l = sample_cosine_hemisphere(u.x, u.y);
    return 0;
  }
  v -= l.sheen;
#endif
#if WP_FEATURE_CLEARCOAT
  if (v < l.coat) return coat_sample(s, wo, t, b, l, u, wi_l, r);
#endif
  return 2;
}
#endif

static inline BsdfSample bsdf_sample_lobes(const Surface* s, const BsdfView* v, float3 wo,
                                           float u_lobe, float2 u) {
  BsdfSample r;
  r.valid = false, r.delta = false, r.pdf = 0.0f, r.eta_scale = 1.0f;
  r.weight = (float3)(0.0f), r.wi = (float3)(0.0f);
#if WP_BSDF_PLAIN
  if (!(v->cos_o > 0.0f)) return r;
  if (u_lobe < v->lobes.spec && bsdf_has_delta(s))
    return sample_delta(s, wo, v->cos_o, v->eta, v->lobes, false);
  int valid;
  const float3 wi = glossy_sample(s, wo, v->cos_o, v->eta, v->lobes.spec, v->lobes.diff, u_lobe,
                                  u.x, u.y, &r.weight, &r.pdf, &valid);
  if (!valid) {
    r.weight = (float3)(0.0f), r.pdf = 0.0f;
    return r;
  }
  r.wi = wi, r.valid = true;
  return r;
#else
  float3 t, b;
#if WP_FEATURE_ANISOTROPY
  if (bsdf_anisotropic(s)) {
    t = s->aniso_t;
    b = cross(s->ns, t);
  } else
#endif
    make_basis(s->ns, &t, &b);
  const float3 wo_l = (float3)(dot(wo, t), dot(wo, b), v->cos_o);
  if (!(wo_l.z > 0.0f)) return r;
  const float eta = v->eta;
  const Lobes l = v->lobes;
  const float g = l.spec + l.trans; /* the microfacet lobes */
  if (u_lobe < g && bsdf_has_delta(s)) return sample_delta(s, wo, wo_l.z, eta, l, u_lobe >= l.spec);
  float3 wi_l;
  bool trans = false;
  if (u_lobe < g) {
    float3 h;
#if WP_FEATURE_ANISOTROPY
    if (bsdf_anisotropic(s)) {
      const float2 a = aniso_alpha(s);
      h = sample_ggx_aniso_visible_normal(wo_l, a.x, a.y, u);
    } else
#endif
      h = sample_ggx_visible_normal(wo_l, sqr(s->roughness), u.x, u.y);
    const float o_h = dot(wo_l, h);
    const float p_reflect = reflect_prob(microfacet_weights(s, o_h, eta));
    trans = u_lobe >= g * p_reflect; /* u_lobe / g is uniform in [0, 1) here */
    wi_l = 2.0f * o_h * h - wo_l;    /* reflection about the microfacet */
    if (trans && !bsdf_volume(s)) {
      wi_l.z = -wi_l.z; /* thin-walled: mirrored through the surface */
    } else if (trans && bsdf_straight_through(s, eta)) {
      return sample_straight(s, wo, wo_l.z, eta, o_h, g * (1.0f - p_reflect));
    } else if (trans) {
      const float sin2_t = (1.0f - o_h * o_h) / (eta * eta);
      if (sin2_t >= 1.0f) return r; /* total internal reflection: lost (sample_delta) */
      wi_l = -wo_l / eta + (o_h / eta - sqrt(1.0f - sin2_t)) * h;
      r.eta_scale = eta * eta;
    }
  } else {
#if WP_BSDF_EXTRA_LOBES
    const float v = u_lobe - g - l.diff;
    const int extra = v >= 0.0f ? sample_extra_lobe(s, wo, t, b, l, v, u, &wi_l, &trans, &r) : 2;
    if (extra == 1) return r;
    if (extra == 2)
#endif
      wi_l = sample_cosine_hemisphere(u.x, u.y);
  }
  /* A lobe's direction on the other side than the lobe covers (a reflection below the surface,
   * a transmission above it) has no density in that lobe: evaluating it there would mix in the
   * other side's lobes and break the pdf. It is lost, as it should be. */
  if (trans ? wi_l.z >= 0.0f : wi_l.z <= 0.0f) return r;
  r.wi = normalize(wi_l.x * t + wi_l.y * b + wi_l.z * s->ns);
  const BsdfEval e = bsdf_eval_view(s, v, wo, r.wi);
  if (!(e.pdf > 0.0f)) return r;
  r.pdf = e.pdf;
  r.weight = e.f * fabs(dot(s->ns, r.wi)) / e.pdf;
  r.valid = true;
  return r;
#endif /* WP_BSDF_PLAIN */
}
#endif /* WP_FEATURE_GLOSSY */

/* A direction from the lobes at wo. At a dispersive surface reached by a path of all channels
 * (KHR_materials_dispersion), one channel c is chosen first, uniformly, with the lobe number's
 * first third (u_lobe is reused, stretched, for the rest): the sample is that channel's BSDF's,
 * its weight 3 f_c cos / pdf_c on channel c alone (so each channel's expected weight is its
 * own), and the path keeps the channel. Its pdf is reported as 0: no light sample was taken
 * there (bsdf_only_delta), so what the direction finds counts in full. Without WP_FEATURE_GLOSSY,
 * Lambert's (lambert.h). */
static inline BsdfSample bsdf_sample_view(const Surface* s, const BsdfView* v, float3 wo,
                                          float u_lobe, float2 u) {
#if !WP_FEATURE_GLOSSY
  (void)wo, (void)u_lobe;
  BsdfSample r = lambert_sample(s, v->cos_o, u);
#if WP_FEATURE_DISPERSION
  r.channel = s->channel;
#endif
  return r;
#elif WP_FEATURE_DISPERSION
  if (bsdf_choose_channel(s)) { /* the channel's ior: a view of its own */
    Surface sc = *s;
    const uint c = min((uint)(u_lobe * 3.0f), 2u);
    sc.channel = c + 1u;
    const BsdfView vc = bsdf_view(&sc, wo);
    BsdfSample r = bsdf_sample_lobes(&sc, &vc, wo, u_lobe * 3.0f - (float)c, u);
    const float3 mask =
        (float3)(c == 0u ? 3.0f : 0.0f, c == 1u ? 3.0f : 0.0f, c == 2u ? 3.0f : 0.0f);
    r.weight *= mask;
    r.pdf = 0.0f;
    r.channel = sc.channel;
    return r;
  }
  BsdfSample r = bsdf_sample_lobes(s, v, wo, u_lobe, u);
  r.channel = s->channel;
  return r;
#else
  return bsdf_sample_lobes(s, v, wo, u_lobe, u);
#endif
}

#if WP_SHADE_PACKET
/* bsdf_view, bsdf_eval_view and bsdf_sample_view of eight lanes (closure.h, Surface8), for the
 * shade packets' programs: Lambert's lobe, or WP_BSDF_PLAIN's BSDF at surfaces without a delta
 * lobe (those paths are shaded one at a time). The sample's weight in *weight, its density in
 * *pdf and whether there is one in *valid. */
WP_LANES_FN BsdfView8 bsdf_view8(const Surface8* s, Float3x8 wo) {
  BsdfView8 v;
  v.cos_o = dot3x8(s->ns, wo);
#if WP_FEATURE_GLOSSY
  v.eta = s->ior; /* relative_ior without volumes */
  float8 spec;
  const float8 diff = glossy_lobes8(s, v.cos_o, v.eta, &spec);
  const int8 above = v.cos_o > 0.0f;
  v.spec = select((float8)(0.0f), spec, above), v.diff = select((float8)(0.0f), diff, above);
#endif
  return v;
}

WP_LANES_FN Float3x8 bsdf_eval8(const Surface8* s, const BsdfView8* v, Float3x8 wo, Float3x8 wi,
                                float8* pdf) {
#if WP_FEATURE_GLOSSY
  return glossy_f8(s, wo, wi, v->cos_o, v->eta, v->spec, v->diff, pdf);
#else
  (void)wo;
  return lambert_f8(s, v->cos_o, wi, pdf);
#endif
}

WP_LANES_FN Float3x8 bsdf_sample8(const Surface8* s, const BsdfView8* v, Float3x8 wo, float8 u_lobe,
                                  float8 ux, float8 uy, Float3x8* weight, float8* pdf,
                                  int8* valid) {
#if WP_FEATURE_GLOSSY
  return glossy_sample8(s, wo, v->cos_o, v->eta, v->spec, v->diff, u_lobe, ux, uy, weight, pdf,
                        valid);
#else
  (void)wo, (void)u_lobe;
  *weight = s->color;
  return lambert_direction8(s, v->cos_o, ux, uy, pdf, valid);
#endif
}
#endif

/* f and pdf for the pair (wo, wi); bsdf_eval_view with a view made for it. */
WP_BSDF_EVAL_INLINE BsdfEval bsdf_eval(const Surface* s, float3 wo, float3 wi) {
  const BsdfView v = bsdf_view(s, wo);
  return bsdf_eval_view(s, &v, wo, wi);
}

/* A direction from the lobes at wo; bsdf_sample_view with a view made for it. */
static inline BsdfSample bsdf_sample(const Surface* s, float3 wo, float u_lobe, float2 u) {
  const BsdfView v = bsdf_view(s, wo);
  return bsdf_sample_view(s, &v, wo, u_lobe, u);
}

#endif /* WP_BSDF_H */
