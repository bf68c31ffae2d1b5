/* What a BSDF reads and returns: the surface record at a hit (Surface, filled by
 * geom/material.h; each extension's fields only in programs built with its feature), the value
 * and density of a pair of directions (BsdfEval), a sampled direction (BsdfSample), the lobe
 * probabilities at wo (Lobes), and the surface's predicates every lobe asks. */
#ifndef WP_BSDF_CLOSURE_H
#define WP_BSDF_CLOSURE_H

#include "util/common.h"

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

/* glTF's metallic-roughness BSDF alone: a glossy program without transmission, volume, dispersion
 * or a layered extension. Its BSDF is bsdf/glossy.def's, one source for one path and for the
 * shade packets' eight lanes. */
#define WP_BSDF_PLAIN                                                                              \
  (WP_FEATURE_GLOSSY && !WP_FEATURE_TRANSMISSION && !WP_FEATURE_VOLUME &&                          \
   !WP_FEATURE_DISPERSION && !WP_FEATURE_SPECULAR && !WP_FEATURE_CLEARCOAT && !WP_FEATURE_SHEEN && \
   !WP_FEATURE_ANISOTROPY && !WP_FEATURE_IRIDESCENCE && !WP_FEATURE_DIFFUSE_TRANSMISSION)

#if WP_SHADE_PACKET
/* Eight Surfaces in SIMD lanes (common.h, Float3x8) for the shade packets (integrator/
 * shade_packet.h): the fields of the materials those programs have, under the same names, so that
 * lane code (util/lanes_begin.def) reads either; front is WP_SURF_FRONT of flags. */
typedef struct Surface8 {
  Float3x8 p, ng, ns, color;
  float8 p_scale;
#if WP_FEATURE_GLOSSY
  float8 metallic, roughness, ior, specular;
#endif
  int8 front;
} Surface8;

/* bsdf_view of eight lanes (bsdf.h): ns . wo, and with WP_FEATURE_GLOSSY the relative index and
 * the specular and diffuse lobes' probabilities. */
typedef struct BsdfView8 {
  float8 cos_o;
#if WP_FEATURE_GLOSSY
  float8 eta, spec, diff;
#endif
} BsdfView8;
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

/* Lobe selection probabilities; they sum to 1. spec + trans is the probability of the
 * microfacet lobes together (reflection and transmission share one sampled microfacet normal and
 * choose between them per microfacet, reflect_prob); spec and trans apart are the
 * split at the macro normal, which is the split of a smooth surface's delta lobes. dtrans, sheen
 * and coat are 0 in programs without their features. */
typedef struct Lobes {
  float spec, trans, diff, dtrans, sheen, coat;
} Lobes;

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

/* bsdf_eval is forced inline on PoCL's CPU devices (the builds with WP_PREFETCH): with two callers
 * (NEE, bsdf_sample) clang kept it out of line in `shade`, a call per evaluation that took 13% of
 * a Cornell box render. Elsewhere the compiler decides: Oclgrind cannot run what an always-inlined
 * function returning a struct leaves behind (llvm.experimental.noalias.scope.decl, stage.h). */
#if WP_PREFETCH
#define WP_BSDF_EVAL_INLINE static inline __attribute__((always_inline))
#else
#define WP_BSDF_EVAL_INLINE static inline
#endif

#endif /* WP_BSDF_CLOSURE_H */
