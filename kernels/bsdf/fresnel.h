/* The Fresnel terms: the dielectric layer's (Schlick at the cosine on the optically thinner side,
 * scaled by KHR_materials_specular's factor, tinted by its colour), the metal's (Schlick with
 * the base colour), each mixed with the thin film of KHR_materials_iridescence (iridescence.h);
 * and what one Fresnel evaluation gives a microfacet: its reflected and transmitted weights and
 * the probability of reflection there. */
#ifndef WP_BSDF_FRESNEL_H
#define WP_BSDF_FRESNEL_H

#include "bsdf/closure.h"
#include "bsdf/iridescence.h"

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

#define WP_BSDF_COLOURED_FRESNEL (WP_FEATURE_SPECULAR || WP_FEATURE_IRIDESCENCE)
#if WP_BSDF_COLOURED_FRESNEL
/* The dielectric layer's Fresnel term, colour-valued (KHR_materials_specular's fresnel_mix):
 * specular x Schlick with F0 = min(f0(eta) x specular colour, 1) and F90 = 1, at the cosine
 * fresnel_dielectric uses; with KHR_materials_iridescence mixed with the Fresnel term of the thin
 * film over a base of reflectance specular x F0 (iridescence.h) by the iridescence factor. */
static inline float3 dielectric_fresnel3(const Surface* s, float cos_o, float eta) {
  const float f0 = sqr((eta - 1.0f) / (eta + 1.0f));
  float c = cos_o;
  if (eta < 1.0f) {
    const float sin2_t = (1.0f - cos_o * cos_o) / (eta * eta);
    if (sin2_t >= 1.0f) return (float3)(s->specular);
    c = sqrt(1.0f - sin2_t);
  }
  float3 f0c = (float3)(f0);
#if WP_FEATURE_SPECULAR
  f0c = fmin(f0c * s->specular_color, 1.0f);
#endif
  float3 f = s->specular * schlick3(f0c, c);
#if WP_FEATURE_IRIDESCENCE
  /* The extension's dielectric case: the film over a base of reflectance specular x F0. */
  if (s->iridescence > 0.0f && eta >= 1.0f) /* the film is on the outside */
    f = mix(f,
            iridescent_fresnel(1.0f, s->iridescence_ior, s->specular * f0c,
                               s->iridescence_thickness, c),
            s->iridescence);
#endif
  return f;
}

/* The metal's Fresnel term: Schlick with F0 the base colour, mixed with the thin film's. */
static inline float3 metal_fresnel(const Surface* s, float c) {
  float3 f = schlick3(s->color, c);
#if WP_FEATURE_IRIDESCENCE
  if (s->iridescence > 0.0f)
    f = mix(f, iridescent_fresnel(1.0f, s->iridescence_ior, s->color, s->iridescence_thickness, c),
            s->iridescence);
#endif
  return f;
}
#endif

/* The weights of a microfacet (or of the smooth surface) with wo at cosine c to it: the
 * dielectric layer's Fresnel term fd (its largest channel where it has colour: the layers beneath
 * keep 1 - fd), the colour-valued reflection (metal and dielectric Fresnel) and transmission
 * ((1 - fd) of the dielectric layer's transmitted part). One Fresnel evaluation serves all three.
 */
typedef struct MicrofacetWeights {
  float3 reflect, transmit;
  float fd;
} MicrofacetWeights;

static inline MicrofacetWeights microfacet_weights(const Surface* s, float c, float eta) {
  MicrofacetWeights w;
#if WP_BSDF_COLOURED_FRESNEL
  const float3 fd = dielectric_fresnel3(s, c, eta);
  w.fd = max3(fd);
  w.reflect = (1.0f - s->metallic) * fd + s->metallic * metal_fresnel(s, c);
#else
  w.fd = dielectric_reflectance(s, c, eta);
  w.reflect = (1.0f - s->metallic) * w.fd + s->metallic * schlick3(s->color, c);
#endif
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

#endif /* WP_BSDF_FRESNEL_H */
