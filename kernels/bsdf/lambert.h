/* Lambert's diffuse lobe, f = base / pi with the cosine-weighted density, for wi above both the
 * shading and the geometric normal: the whole BSDF of programs built without WP_FEATURE_GLOSSY
 * (bsdf.h), for one path and, in eight lanes, for the fused stage's shade packets
 * (integrator/shade_packet.h), from one source (bsdf/lambert.def). */

#ifndef WP_BSDF_LAMBERT_H
#define WP_BSDF_LAMBERT_H

#include "bsdf/closure.h"
#include "sampling/warps.h"

/* lambert_f and lambert_direction (lane code: util/lanes_begin.def). */
#define WP_LW 1
#include "bsdf/lambert.def"
#if WP_SHADE_PACKET
#define WP_LW 8
#include "bsdf/lambert.def"
#endif

/* lambert_f as a BsdfEval. */
WP_BSDF_EVAL_INLINE BsdfEval lambert_eval(const Surface* s, float cos_o, float3 wi) {
  BsdfEval e;
  e.f = lambert_f(s, cos_o, wi, &e.pdf);
  return e;
}

/* lambert_direction as a BsdfSample: its weight f cos / pdf is the base colour; an invalid one is
 * all zeros. */
static inline BsdfSample lambert_sample(const Surface* s, float cos_o, float2 u) {
  BsdfSample r;
  int valid;
  r.wi = lambert_direction(s, cos_o, u.x, u.y, &r.pdf, &valid);
  r.valid = valid, r.delta = false, r.eta_scale = 1.0f;
  r.weight = valid ? s->color : (float3)(0.0f);
  if (!valid) r.wi = (float3)(0.0f), r.pdf = 0.0f;
  return r;
}

#endif /* WP_BSDF_LAMBERT_H */
