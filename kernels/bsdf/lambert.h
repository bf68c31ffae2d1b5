/* Lambert's diffuse lobe, f = base / pi with the cosine-weighted density, for wi above both the
 * shading and the geometric normal: the whole BSDF of programs built without WP_FEATURE_GLOSSY
 * (bsdf.h), and, in eight lanes, of the fused stage's shade packets (integrator/shade_packet.h).
 * The twins sit beside their originals: the same header, so the same floating-point contraction
 * (docs/architecture.md, the shade packets). */

#ifndef WP_BSDF_LAMBERT_H
#define WP_BSDF_LAMBERT_H

#include "bsdf/closure.h"
#include "sampling/warps.h"

#if WP_SHADE_PACKET
/* Eight Surfaces of untextured Lambertian materials (common.h, Float3x8): what lambert_eval8 and
 * lambert_sample8 read; front is WP_SURF_FRONT of flags. */
typedef struct Surface8 {
  Float3x8 p, ng, ns, color;
  float8 p_scale;
  int8 front;
} Surface8;
#endif

/* f and pdf for wi, with cos_o = ns . wo. */
WP_BSDF_EVAL_INLINE BsdfEval lambert_eval(const Surface* s, float cos_o, float3 wi) {
  BsdfEval e = {(float3)(0.0f), 0.0f};
  const float cos_i = dot(s->ns, wi);
  if (!(cos_o > 0.0f) || !(cos_i > 0.0f && dot(s->ng, wi) > 0.0f)) return e;
  e.f = WP_INV_PI * s->color;
  e.pdf = cosine_hemisphere_pdf(cos_i);
  return e;
}

/* A cosine-weighted direction; its weight f cos / pdf is the base colour. */
static inline BsdfSample lambert_sample(const Surface* s, float cos_o, float2 u) {
  BsdfSample r;
  r.valid = false, r.delta = false, r.pdf = 0.0f, r.eta_scale = 1.0f;
  r.weight = (float3)(0.0f), r.wi = (float3)(0.0f);
  if (!(cos_o > 0.0f)) return r;
  float3 t, b;
  make_basis(s->ns, &t, &b);
  const float3 wi_l = sample_cosine_hemisphere(u);
  if (!(wi_l.z > 0.0f)) return r;
  r.wi = normalize(wi_l.x * t + wi_l.y * b + wi_l.z * s->ns);
  const float cos_i = dot(s->ns, r.wi);
  if (!(cos_i > 0.0f && dot(s->ng, r.wi) > 0.0f)) return r; /* lambert_eval's pdf is 0 there */
  r.pdf = cosine_hemisphere_pdf(cos_i);
  r.weight = s->color;
  r.valid = true;
  return r;
}

#if WP_SHADE_PACKET
/* lambert_eval and lambert_sample of eight lanes (common.h, Float3x8), cos_o being each lane's
 * ns . wo: f and the pdf in *pdf; the direction, its pdf in *pdf and whether it is valid
 * (the weight is the base colour). */
WP_LANES_FN Float3x8 lambert_eval8(const Surface8* s, float8 cos_o, Float3x8 wi, float8* pdf) {
  const float8 cos_i = dot3x8(s->ns, wi);
  const int8 lit = cos_o > 0.0f && cos_i > 0.0f && dot3x8(s->ng, wi) > 0.0f;
  *pdf = select((float8)(0.0f), cosine_hemisphere_pdf8(cos_i), lit);
  Float3x8 f = {select((float8)(0.0f), WP_INV_PI * s->color.x, lit),
                select((float8)(0.0f), WP_INV_PI * s->color.y, lit),
                select((float8)(0.0f), WP_INV_PI * s->color.z, lit)};
  return f;
}

WP_LANES_FN Float3x8 lambert_sample8(const Surface8* s, float8 cos_o, float8 ux, float8 uy,
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

#endif /* WP_BSDF_LAMBERT_H */
