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
 * f reduces to base / pi, and evaluation and sampling are Lambert's alone: the same values, without
 * the lobe machinery. Each extension's code compiles only with its WP_FEATURE_* (features.h).
 */
#ifndef WP_BSDF_H
#define WP_BSDF_H

#include "util/common.h"
#include "sampling/warps.h"
/* The extensions' pieces, whatever the features: each is used only where its feature is on. */
#include "ggx_aniso.h"
#include "iridescence.h"
#include "sheen.h"

/* A surface whose GGX alpha (roughness^2) is below this is perfectly smooth. The lobe of alpha
 * 1e-3 is ~0.06 degrees wide: narrower than any pixel of a sensible camera, and the float32
 * evaluation of a narrower one loses its precision (sampling/warps.h, ggx_d). */
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
#if WP_FEATURE_TEXTURE_LOD
  float curvature; /* of the surface across the triangle, on the side of wo (ray_cone.h) */
#endif
  /* The material extensions, each present only in programs built with its feature. */
#if WP_FEATURE_SPECULAR
  float3 specular_color; /* KHR_materials_specular colour: tints the dielectric F0 */
#endif
#if WP_FEATURE_CLEARCOAT
  float3 nc; /* the coat's normal (interpolated or coat-normal-mapped), on the side of wo */
  float clearcoat, clearcoat_roughness;
#endif
#if WP_FEATURE_SHEEN
  float3 sheen_color;
  float sheen_roughness;
#endif
#if WP_FEATURE_ANISOTROPY
  float3 aniso_t;   /* unit anisotropy direction, perpendicular to ns */
  float anisotropy; /* strength in [0, 1]: alpha along aniso_t is mix(alpha, 1, strength^2) */
#endif
#if WP_FEATURE_IRIDESCENCE
  float iridescence, iridescence_ior, iridescence_thickness; /* factor, film ior, nanometres */
#endif
#if WP_FEATURE_DIFFUSE_TRANSMISSION
  float3 dt_color;            /* diffuseTransmissionColor */
  float diffuse_transmission; /* diffuseTransmissionFactor */
#endif
#if WP_FEATURE_DISPERSION
  float dispersion; /* 20 / Abbe number */
  uint channel;     /* the path's colour channel once a dispersive refraction chose one (1 R,
                       2 G, 3 B: its ior is that wavelength's), else 0 */
#endif
} Surface;

#if WP_SHADE_PACKET
/* Eight Surfaces of untextured Lambertian materials (common.h, Float3x8): what bsdf_eval8 and
 * bsdf_sample8 read; front is WP_SURF_FRONT of flags. */
typedef struct Surface8 {
  Float3x8 p, ng, ns, color;
  float8 p_scale;
  int8 front;
} Surface8;
#endif

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
#if WP_FEATURE_DISPERSION
  uint channel; /* the path's channel after this sample (Surface.channel) */
#endif
} BsdfSample;

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

/* Lobe selection probabilities; they sum to 1. spec + trans is the probability of the
 * microfacet lobes together (reflection and transmission share one sampled microfacet normal and
 * choose between them per microfacet, reflect_prob); spec and trans apart are the
 * split at the macro normal, which is the split of a smooth surface's delta lobes. dtrans, sheen
 * and coat are 0 in programs without their features. */
typedef struct Lobes {
  float spec, trans, diff, dtrans, sheen, coat;
} Lobes;

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
#endif

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

/* bsdf_eval is forced inline on PoCL's CPU devices (the builds with WP_PREFETCH): with two callers
 * (NEE, bsdf_sample) clang kept it out of line in `shade`, a call per evaluation that took 13% of
 * a Cornell box render. Elsewhere the compiler decides: Oclgrind cannot run what an always-inlined
 * function returning a struct leaves behind (llvm.experimental.noalias.scope.decl, stage.h). */
#if WP_PREFETCH
#define WP_BSDF_EVAL_INLINE static inline __attribute__((always_inline))
#else
#define WP_BSDF_EVAL_INLINE static inline
#endif

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

#if !WP_FEATURE_GLOSSY

static inline BsdfView bsdf_view(const Surface* s, float3 wo) {
  BsdfView v = {dot(s->ns, wo)};
  return v;
}

/* Lambert: f = base / pi and the cosine-weighted pdf, for wi above both normals. */
WP_BSDF_EVAL_INLINE BsdfEval bsdf_eval_view(const Surface* s, const BsdfView* v, float3 wo,
                                            float3 wi) {
  (void)wo;
  BsdfEval e = {(float3)(0.0f), 0.0f};
  const float cos_i = dot(s->ns, wi);
  if (!(v->cos_o > 0.0f) || !(cos_i > 0.0f && dot(s->ng, wi) > 0.0f)) return e;
  e.f = WP_INV_PI * s->color;
  e.pdf = cosine_hemisphere_pdf(cos_i);
  return e;
}

/* A cosine-weighted direction; its weight f cos / pdf is the base colour. */
static inline BsdfSample bsdf_sample_view(const Surface* s, const BsdfView* v, float3 wo,
                                          float u_lobe, float2 u) {
  (void)wo, (void)u_lobe;
  BsdfSample r;
  r.valid = false, r.delta = false, r.pdf = 0.0f, r.eta_scale = 1.0f;
  r.weight = (float3)(0.0f), r.wi = (float3)(0.0f);
  if (!(v->cos_o > 0.0f)) return r;
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
#if WP_FEATURE_DISPERSION
  r.channel = s->channel;
#endif
  return r;
}

#if WP_SHADE_PACKET
/* bsdf_eval_view and bsdf_sample_view of eight lanes (common.h, Float3x8), cos_o being each
 * lane's BsdfView: f and the pdf in *pdf; the direction, its pdf in *pdf and whether it is valid
 * (the weight is the base colour). */
WP_LANES_FN Float3x8 bsdf_eval8(const Surface8* s, float8 cos_o, Float3x8 wi, float8* pdf) {
  const float8 cos_i = dot3x8(s->ns, wi);
  const int8 lit = cos_o > 0.0f && cos_i > 0.0f && dot3x8(s->ng, wi) > 0.0f;
  *pdf = select((float8)(0.0f), cosine_hemisphere_pdf8(cos_i), lit);
  Float3x8 f = {select((float8)(0.0f), WP_INV_PI * s->color.x, lit),
                select((float8)(0.0f), WP_INV_PI * s->color.y, lit),
                select((float8)(0.0f), WP_INV_PI * s->color.z, lit)};
  return f;
}

WP_LANES_FN Float3x8 bsdf_sample8(const Surface8* s, float8 cos_o, float8 ux, float8 uy,
                                  float8* pdf, int8* valid) {
  Float3x8 t, b;
  make_basis8(s->ns, &t, &b);
  const Float3x8 l = sample_cosine_hemisphere8(ux, uy);
  Float3x8 w = {l.x * t.x + l.y * b.x + l.z * s->ns.x, l.x * t.y + l.y * b.y + l.z * s->ns.y,
                l.x * t.z + l.y * b.z + l.z * s->ns.z};
  w = normalize3x8(w);
  const float8 cos_i = dot3x8(s->ns, w);
  *valid = cos_o > 0.0f && l.z > 0.0f && cos_i > 0.0f && dot3x8(s->ng, w) > 0.0f;
  *pdf = cosine_hemisphere_pdf8(cos_i);
  return w;
}
#endif

/* What a smooth thin-walled transmitter lets a shadow ray along d through: nothing, here. */
static inline float3 bsdf_pane_transmittance(const Surface* s, float3 d) {
  (void)s, (void)d;
  return (float3)(0.0f);
}

#else

static inline BsdfView bsdf_view(const Surface* s, float3 wo) {
  BsdfView v;
  v.cos_o = dot(s->ns, wo);
  v.eta = relative_ior(s);
  const Lobes none = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
  /* Only above the surface: the sheen table is looked up at cos_o. */
  v.lobes = v.cos_o > 0.0f ? bsdf_lobes(s, wo, v.cos_o, v.eta) : none;
  return v;
}

WP_BSDF_EVAL_INLINE BsdfEval bsdf_eval_view(const Surface* s, const BsdfView* v, float3 wo,
                                            float3 wi) {
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
}

/* The layers' scaling of a delta lobe of the base from wo into wi. */
static inline float3 layered_delta(const Surface* s, float3 wo, float3 wi, float3 weight) {
#if WP_BSDF_LAYERED
  return weight * layer_base_scale(s, coat_leaves(s, wo), dot(s->ns, wo), dot(s->ns, wi));
#else
  (void)s, (void)wo, (void)wi;
  return weight;
#endif
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

/* What a smooth thin-walled transmitter lets a shadow ray along d through (trace_shadow.h): the
 * weight of its delta transmission straight on, with the layers' scaling. */
static inline float3 bsdf_pane_transmittance(const Surface* s, float3 d) {
  const float c = fabs(dot(s->ns, d));
  return layered_delta(s, -d, d, microfacet_weights(s, c, relative_ior(s)).transmit);
}

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
    *wi_l = sample_cosine_hemisphere(u);
    wi_l->z = -wi_l->z;
    *trans = true;
    if (bsdf_volume(s)) r->eta_scale = sqr(relative_ior(s));
    return 0;
  }
  v -= l.dtrans;
#endif
#if WP_FEATURE_SHEEN
  if (v < l.sheen) {
    *wi_l = sample_cosine_hemisphere(u);
    return 0;
  }
  v -= l.sheen;
#endif
#if WP_FEATURE_CLEARCOAT
  if (v < l.coat) {
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
    const float3 h = sample_ggx_visible_normal(oc, sqr(s->clearcoat_roughness), u);
    const float3 ic = 2.0f * dot(oc, h) * h - oc;
    if (!(ic.z > 0.0f)) return 1; /* below the coat: no density in the coat's lobe, lost */
    const float3 w = ic.x * tc + ic.y * bc + ic.z * nc; /* to the sampling frame of ns */
    *wi_l = (float3)(dot(w, t), dot(w, b), dot(w, s->ns));
    return 0;
  }
#endif
  return 2;
}
#endif

static inline BsdfSample bsdf_sample_lobes(const Surface* s, const BsdfView* v, float3 wo,
                                           float u_lobe, float2 u) {
  BsdfSample r;
  r.valid = false, r.delta = false, r.pdf = 0.0f, r.eta_scale = 1.0f;
  r.weight = (float3)(0.0f), r.wi = (float3)(0.0f);
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
      h = sample_ggx_visible_normal(wo_l, sqr(s->roughness), u);
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
      wi_l = sample_cosine_hemisphere(u);
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
}

/* A direction from the lobes at wo. At a dispersive surface reached by a path of all channels
 * (KHR_materials_dispersion), one channel c is chosen first, uniformly, with the lobe number's
 * first third (u_lobe is reused, stretched, for the rest): the sample is that channel's BSDF's,
 * its weight 3 f_c cos / pdf_c on channel c alone (so each channel's expected weight is its
 * own), and the path keeps the channel. Its pdf is reported as 0: no light sample was taken
 * there (bsdf_only_delta), so what the direction finds counts in full. */
static inline BsdfSample bsdf_sample_view(const Surface* s, const BsdfView* v, float3 wo,
                                          float u_lobe, float2 u) {
#if WP_FEATURE_DISPERSION
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

#endif /* WP_FEATURE_GLOSSY */

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
