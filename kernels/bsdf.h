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
 * A surface with roughness^2 < WP_DELTA_ALPHA is perfectly smooth: its specular reflection and
 * transmission are delta lobes (a flag, not a pdf), which evaluation leaves out (they have no
 * density). The diffuse term stays an ordinary lobe.
 *
 * Sampling first picks the microfacet lobes or the diffuse one, with probabilities proportional to
 * their Fresnel-weighted albedo estimates at n.v (a function of wo alone). The microfacet lobes
 * draw a normal h from GGX's visible normals and then choose reflection or transmission at that
 * microfacet, in proportion to its Fresnel weights at wo.h (as pbrt-v4's dielectric does); the
 * diffuse lobe is cosine-weighted.
 * For non-delta lobes the returned pdf is the mixture density of all lobes at wi, the number
 * bsdf_eval returns for the pair. Directions are world-space unit vectors pointing away from the
 * surface; wo is toward the viewer. Surfaces seen from the back of a volume (the ray travels
 * inside) have the relative index of refraction 1 / ior.
 *
 * Built with WP_FEATURE_GLOSSY 0 (a scene whose every scattering material has metallic 0,
 * specular factor 0 and no transmission: host/device/scene_features.cpp), f reduces to base / pi,
 * and evaluation and sampling are Lambert's alone: the same values, without the lobe machinery.
 */
#ifndef WP_BSDF_H
#define WP_BSDF_H

#include "common.h"
#include "sampling.h"

/* A surface whose GGX alpha (roughness^2) is below this is perfectly smooth. The lobe of alpha
 * 1e-3 is ~0.06 degrees wide: narrower than any pixel of a sensible camera, and the float32
 * evaluation of a narrower one loses its precision (sampling.h, ggx_d). */
#define WP_DELTA_ALPHA 1e-3f

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
  float3 weight;   /* f * |n.wi| / pdf, or a delta lobe's weight / its selection probability */
  float pdf;       /* 0 for a delta lobe */
  float eta_scale; /* eta^2 when the sample refracted into another medium (the 1/eta^2 in
                    * weight), else 1: Russian roulette divides it out of the throughput */
  bool delta;
  bool valid; /* false: the path ends here (no direction, or one on the wrong side) */
} BsdfSample;

/* Lobe selection probabilities; they sum to 1. spec + trans is the probability of the
 * microfacet lobes together (reflection and transmission share one sampled microfacet normal and
 * choose between them per microfacet, reflect_prob); spec and trans apart are the
 * split at the macro normal, which is the split of a smooth surface's delta lobes. */
typedef struct Lobes {
  float spec, trans, diff;
} Lobes;

static inline bool bsdf_has_delta(const Surface* s) {
#if WP_FEATURE_GLOSSY
  return sqr(s->roughness) < WP_DELTA_ALPHA;
#else
  (void)s; /* a Lambertian surface has no delta lobe at any roughness */
  return false;
#endif
}
static inline bool bsdf_transmits(const Surface* s) {
#if WP_FEATURE_TRANSMISSION
  return s->transmission > 0.0f && s->metallic < 1.0f;
#else
  (void)s;
  return false;
#endif
}
static inline bool bsdf_volume(const Surface* s) {
#if WP_FEATURE_VOLUME
  return (s->flags & WP_SURF_VOLUME) != 0u;
#else
  (void)s;
  return false;
#endif
}
/* Nothing but delta lobes: light sampling cannot contribute (bsdf_eval is 0 everywhere). */
static inline bool bsdf_only_delta(const Surface* s) {
  return bsdf_has_delta(s) && (s->metallic >= 1.0f || s->transmission >= 1.0f);
}

/* eta_t / eta_o: index of refraction across the interface relative to wo's side. */
static inline float relative_ior(const Surface* s) {
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

/* The dielectric Fresnel reflectance (Schlick) for a wave meeting the interface at cosine cos_o on
 * its side, eta = eta_other / eta_own. From the denser side the cosine of the refracted direction
 * is used, and beyond the critical angle everything is reflected. */
static inline float fresnel_dielectric(float cos_o, float eta) {
  const float f0 = sqr((eta - 1.0f) / (eta + 1.0f));
  float c = cos_o;
  if (eta < 1.0f) {
    const float sin2_t = (1.0f - cos_o * cos_o) / (eta * eta);
    if (sin2_t >= 1.0f) return 1.0f;
    c = sqrt(1.0f - sin2_t);
  }
  return f0 + (1.0f - f0) * pow5(1.0f - c);
}

static inline float3 schlick3(float3 f0, float c) {
  return f0 + (1.0f - f0) * pow5(1.0f - c);
}

/* The dielectric layer's reflectance at cosine cos_o: the Fresnel term scaled by the specular
 * factor. */
static inline float dielectric_reflectance(const Surface* s, float cos_o, float eta) {
  return s->specular * fresnel_dielectric(cos_o, eta);
}

/* The weights of a microfacet (or of the smooth surface) with wo at cosine c to it: the
 * dielectric layer's Fresnel term fd, the colour-valued reflection (metal and dielectric Fresnel)
 * and transmission ((1 - fd) of the dielectric layer's transmitted part). One Fresnel evaluation
 * serves all three. */
typedef struct MicrofacetWeights {
  float3 reflect, transmit;
  float fd;
} MicrofacetWeights;

static inline MicrofacetWeights microfacet_weights(const Surface* s, float c, float eta) {
  MicrofacetWeights w;
  w.fd = dielectric_reflectance(s, c, eta);
  w.reflect = (1.0f - s->metallic) * w.fd + s->metallic * schlick3(s->color, c);
  w.transmit = bsdf_transmits(s) ? (1.0f - s->metallic) * (1.0f - w.fd) * s->transmission * s->color
                                 : (float3)(0.0f);
  return w;
}

/* Probability of reflection (against transmission) once a microfacet has been chosen:
 * proportional to the luminance of its two weights. Choosing per microfacet, not with F at the
 * macro normal, keeps transmission through microfacets that are below the critical angle when the
 * macro surface is beyond it (light leaving rough glass at grazing angles). */
static inline float reflect_prob(MicrofacetWeights w) {
  const float r = luminance(w.reflect), t = luminance(w.transmit);
  return r + t > 0.0f ? r / (r + t) : 1.0f;
}

static inline Lobes bsdf_lobes(const Surface* s, float cos_o, float eta) {
  const MicrofacetWeights w = microfacet_weights(s, cos_o, eta);
  const float t = bsdf_transmits(s) ? s->transmission : 0.0f;
  const float w_spec = luminance(w.reflect), w_trans = luminance(w.transmit);
  const float w_diff = (1.0f - s->metallic) * (1.0f - w.fd) * (1.0f - t) * luminance(s->color);
  const float total = w_spec + w_trans + w_diff;
  Lobes l = {1.0f, 0.0f, 0.0f};
  if (total > 0.0f) l.spec = w_spec / total, l.trans = w_trans / total, l.diff = w_diff / total;
  return l;
}

/* Smith Lambda for GGX; G2 = 1 / (1 + Lambda(o) + Lambda(i)) is the height-correlated term. */
static inline float ggx_lambda(float cos_theta, float alpha) {
  const float c2 = cos_theta * cos_theta;
  const float tan2 = fmax(0.0f, 1.0f - c2) / fmax(c2, 1e-12f);
  return 0.5f * (sqrt(1.0f + alpha * alpha * tan2) - 1.0f);
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
  e->pdf = l.diff * cosine_hemisphere_pdf(cos_i);
  if (bsdf_has_delta(s)) return;
  const float alpha = sqr(s->roughness);
  const float n_dot_h = fmax(dot(s->ns, h), 0.0f), sin2_h = sin2_between(s->ns, h);
  const float dv = ggx_d(n_dot_h, sin2_h, alpha) * ggx_visibility(cos_i, cos_o, alpha);
  e->f += w.reflect * dv;
  e->pdf +=
      (l.spec + l.trans) * reflect_prob(w) * ggx_reflection_pdf(cos_o, n_dot_h, sin2_h, alpha);
}

/* Rough transmission (wi below the surface); delta transmission has no density. */
static inline void eval_transmission(const Surface* s, float3 wo, float3 wi, float eta, Lobes l,
                                     BsdfEval* e) {
  const float alpha = sqr(s->roughness), g = l.spec + l.trans;
  const float cos_o = dot(s->ns, wo), cos_i = dot(s->ns, wi);
  if (!bsdf_volume(s)) { /* thin-walled: the reflection lobe mirrored through the surface */
    const float3 wr = wi - 2.0f * cos_i * s->ns;
    const float3 h = normalize(wo + wr);
    const float n_dot_h = fmax(dot(s->ns, h), 0.0f), sin2_h = sin2_between(s->ns, h);
    const MicrofacetWeights w = microfacet_weights(s, fmax(dot(wo, h), 0.0f), eta);
    e->f = w.transmit * ggx_d(n_dot_h, sin2_h, alpha) * ggx_visibility(-cos_i, cos_o, alpha);
    e->pdf = g * (1.0f - reflect_prob(w)) * ggx_reflection_pdf(cos_o, n_dot_h, sin2_h, alpha);
    return;
  }
  float3 h = normalize(wo + eta * wi); /* generalised half vector */
  if (dot(h, s->ns) < 0.0f) h = -h;
  const float o_h = dot(wo, h), i_h = dot(wi, h);
  if (!(o_h > 0.0f && i_h < 0.0f)) return; /* microfacet seen from the wrong side */
  const float denom = i_h + o_h / eta;
  const float n_dot_h = dot(s->ns, h);
  const float d = ggx_d(n_dot_h, sin2_between(s->ns, h), alpha);
  const float g2 = 1.0f / (1.0f + ggx_lambda(cos_o, alpha) + ggx_lambda(cos_i, alpha));
  const float jacobian = fabs(i_h) / (denom * denom); /* d omega_h / d omega_i */
  const MicrofacetWeights w = microfacet_weights(s, o_h, eta);
  e->f = w.transmit * (d * g2 * o_h * jacobian / (fabs(cos_i) * cos_o) / (eta * eta));
  e->pdf = g * (1.0f - reflect_prob(w)) * ggx_g1(cos_o, alpha) * o_h * d / cos_o * jacobian;
}

#if !WP_FEATURE_GLOSSY

/* Lambert: f = base / pi and the cosine-weighted pdf, for wi above both normals. */
static inline BsdfEval bsdf_eval(const Surface* s, float3 wo, float3 wi) {
  BsdfEval e = {(float3)(0.0f), 0.0f};
  const float cos_i = dot(s->ns, wi);
  if (!(dot(s->ns, wo) > 0.0f) || !(cos_i > 0.0f && dot(s->ng, wi) > 0.0f)) return e;
  e.f = WP_INV_PI * s->color;
  e.pdf = cosine_hemisphere_pdf(cos_i);
  return e;
}

/* A cosine-weighted direction; its weight f cos / pdf is the base colour. */
static inline BsdfSample bsdf_sample(const Surface* s, float3 wo, float u_lobe, float2 u) {
  (void)u_lobe;
  BsdfSample r;
  r.valid = false, r.delta = false, r.pdf = 0.0f, r.eta_scale = 1.0f;
  r.weight = (float3)(0.0f), r.wi = (float3)(0.0f);
  if (!(dot(s->ns, wo) > 0.0f)) return r;
  float3 t, b;
  make_basis(s->ns, &t, &b);
  const float3 wi_l = sample_cosine_hemisphere(u);
  if (!(wi_l.z > 0.0f)) return r;
  r.wi = normalize(wi_l.x * t + wi_l.y * b + wi_l.z * s->ns);
  const float cos_i = dot(s->ns, r.wi);
  if (!(cos_i > 0.0f && dot(s->ng, r.wi) > 0.0f)) return r; /* bsdf_eval's pdf is 0 there */
  r.pdf = cosine_hemisphere_pdf(cos_i);
  r.weight = s->color;
  r.valid = true;
  return r;
}

#else

static inline BsdfEval bsdf_eval(const Surface* s, float3 wo, float3 wi) {
  BsdfEval e = {(float3)(0.0f), 0.0f};
  const float cos_i = dot(s->ns, wi), cos_o = dot(s->ns, wo);
  if (!(cos_o > 0.0f)) return e;
  const float eta = relative_ior(s);
  const Lobes l = bsdf_lobes(s, cos_o, eta);
  const bool above = cos_i > 0.0f && dot(s->ng, wi) > 0.0f;
  const bool below = cos_i < 0.0f && dot(s->ng, wi) < 0.0f;
  if (above)
    eval_reflection(s, wo, wi, eta, l, &e);
  else if (below && bsdf_transmits(s) && !bsdf_has_delta(s) &&
           !(bsdf_volume(s) && bsdf_straight_through(s, eta)))
    eval_transmission(s, wo, wi, eta, l, &e);
  return e;
}

/* The delta lobes of a smooth surface: mirror reflection, or transmission (refracted with a
 * volume, straight through when thin-walled or index-matched). */
static inline BsdfSample sample_delta(const Surface* s, float3 wo, float cos_o, float eta, Lobes l,
                                      bool transmit) {
  BsdfSample r;
  r.delta = true, r.pdf = 0.0f, r.valid = false, r.eta_scale = 1.0f;
  if (!transmit) {
    r.wi = 2.0f * cos_o * s->ns - wo;
    r.weight = microfacet_weights(s, cos_o, eta).reflect / l.spec;
    r.valid = dot(r.wi, s->ng) > 0.0f;
    return r;
  }
  float3 tint = microfacet_weights(s, cos_o, eta).transmit / l.trans;
  if (!bsdf_straight_through(s, eta)) {
    const float sin2_t = (1.0f - cos_o * cos_o) / (eta * eta);
    const float cos_t = sqrt(fmax(0.0f, 1.0f - sin2_t)); /* l.trans > 0 excludes TIR */
    r.wi = normalize(-wo / eta + (cos_o / eta - cos_t) * s->ns);
  } else {
    r.wi = -wo;
  }
  if (bsdf_volume(s)) { /* radiance changes by 1 / eta^2 across an interface of media */
    tint /= eta * eta;
    r.eta_scale = eta * eta;
  }
  r.weight = tint;
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
  const float lambda = ggx_lambda(cos_o, sqr(s->roughness));
  r.weight = microfacet_weights(s, o_h, eta).transmit *
             ((1.0f + lambda) / (1.0f + 2.0f * lambda) / (prob * eta * eta));
  r.valid = dot(r.wi, s->ng) < 0.0f;
  return r;
}

static inline BsdfSample bsdf_sample(const Surface* s, float3 wo, float u_lobe, float2 u) {
  BsdfSample r;
  r.valid = false, r.delta = false, r.pdf = 0.0f, r.eta_scale = 1.0f;
  r.weight = (float3)(0.0f), r.wi = (float3)(0.0f);
  float3 t, b;
  make_basis(s->ns, &t, &b);
  const float3 wo_l = (float3)(dot(wo, t), dot(wo, b), dot(wo, s->ns));
  if (!(wo_l.z > 0.0f)) return r;
  const float eta = relative_ior(s);
  const Lobes l = bsdf_lobes(s, wo_l.z, eta);
  const float g = l.spec + l.trans; /* the microfacet lobes */
  if (u_lobe < g && bsdf_has_delta(s)) return sample_delta(s, wo, wo_l.z, eta, l, u_lobe >= l.spec);
  float3 wi_l;
  bool trans = false;
  if (u_lobe < g) {
    const float3 h = sample_ggx_visible_normal(wo_l, sqr(s->roughness), u);
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
      if (sin2_t >= 1.0f) return r; /* cannot happen: p_reflect = 1 there */
      wi_l = -wo_l / eta + (o_h / eta - sqrt(1.0f - sin2_t)) * h;
      r.eta_scale = eta * eta;
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

#endif /* WP_FEATURE_GLOSSY */

#endif /* WP_BSDF_H */
