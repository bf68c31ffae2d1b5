/* Test kernels of tests/test_anisotropy.cpp: anisotropic GGX (kernels/bsdf/ggx_aniso.h).
 *
 * A sampling configuration is (v, p): v.xyz = wo, a unit direction in the frame of the bins
 * (tests/sphere_bins.h, the pole on the normal: (c, phi) -> (s cos phi, s sin phi, c),
 * s = sqrt(1 - c^2)); p = (ax, ay, cos psi, sin psi): the anisotropy direction t is the bins'
 * x axis turned by psi about the normal, t = (cos psi, sin psi, 0), b = n x t. wo and the
 * microfacet normals are taken to the anisotropy frame (t, b, n) for ggx_aniso.h and back, so a
 * turned frame checks that the routines hold for a view out of the (t, n) plane. */
/* As in the renderer's program, where traversal/traverse.h's FP_CONTRACT OFF comes before the
 * BSDF: without fused multiply-adds the isotropic routines (lane code, whose vector sums are
 * calls) and the anisotropic ones (float3 expressions) round alike. */
#pragma OPENCL FP_CONTRACT OFF
#include "bsdf/ggx_aniso.h"
#include "sampling/rng.h"

/* Sample kinds, in draw_aniso's dir.w. */
#define SK_INVALID 0.0f
#define SK_SMOOTH 1.0f

static inline float3 to_aniso(float3 w, float4 p) {
  return (float3)(p.z * w.x + p.w * w.y, -p.w * w.x + p.z * w.y, w.z);
}
static inline float3 from_aniso(float3 w, float4 p) {
  return (float3)(p.z * w.x - p.w * w.y, p.w * w.x + p.z * w.y, w.z);
}

/* The density of the reflected direction l (bins frame) seen from v.xyz: the eval side. */
static inline float reflection_pdf(float4 v, float4 p, float3 l) {
  const float3 h = normalize(v.xyz + l);
  return h.z > 0.0f ? ggx_aniso_reflection_pdf(to_aniso(v.xyz, p), to_aniso(h, p), p.x, p.y) : 0.0f;
}

static inline float rel_error(float x, float ref) {
  return x == ref ? 0.0f : fabs(x - ref) / fmax(fabs(ref), 1e-30f);
}

/* From: a configuration, a seed. To: `count` samples, dir = (l, SK_* kind), l = reflect(wo, h)
 * in the bins frame for h = sample_ggx_aniso_visible_normal; check = (relative error of the
 * sample's pdf, from the sampled h, against reflection_pdf at l; | |h| - 1 |; h.z in the
 * anisotropy frame; the pdf). Sample i uses the hash stream of "pixel" i (sampling/rng.h). */
__kernel void draw_aniso(float4 v, float4 p, uint seed, uint count, __global float4* dirs,
                         __global float4* checks) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  const Rng r = rng_make(i, 0u, seed, 0u);
  const float3 wo = to_aniso(v.xyz, p);
  const float3 h = sample_ggx_aniso_visible_normal(wo, p.x, p.y, rng_get2(r, WP_DIM_BSDF_U));
  const float pdf = ggx_aniso_reflection_pdf(wo, h, p.x, p.y);
  const float3 hb = from_aniso(h, p);
  const float3 l = 2.0f * dot(v.xyz, hb) * hb - v.xyz;
  dirs[i] = (float4)(l, pdf > 0.0f ? SK_SMOOTH : SK_INVALID);
  checks[i] = (float4)(pdf > 0.0f ? rel_error(pdf, reflection_pdf(v, p, l)) : 0.0f,
                       fabs(length(h) - 1.0f), h.z, pdf);
}

/* Midpoint rule with n x n points over rect = (c0, c1, phi0, phi1), in (theta, phi), c = cos
 * theta (as sampling_kernels.cl's rect_midpoint, pole on the normal). */
static inline float rect_midpoint(float4 v, float4 p, float4 rect, uint n) {
  const float t0 = acos(clamp(rect.y, -1.0f, 1.0f)), t1 = acos(clamp(rect.x, -1.0f, 1.0f));
  const float dt = (t1 - t0) / (float)n, dp = (rect.w - rect.z) / (float)n;
  float total = 0.0f;
  for (uint i = 0; i < n; ++i) {
    const float theta = t0 + ((float)i + 0.5f) * dt, cc = cos(theta), sn = sin(theta);
    float row = 0.0f; /* rows first: at most 512 terms per float sum */
    for (uint j = 0; j < n; ++j) {
      const float phi = rect.z + ((float)j + 0.5f) * dp;
      row += reflection_pdf(v, p, (float3)(sn * cos(phi), sn * sin(phi), cc));
    }
    total += row * sn;
  }
  return total * dt * dp;
}

/* From: a configuration and `count` bins (rects). To: per bin (integral of the pdf, error
 * estimate): the grid doubles from n0 x n0 points until the last two changes are at most
 * max(rel_tol * result, abs_tol) or n0 * 2^max_level points per axis are reached; the estimate
 * is the larger of the two changes (as sampling_kernels.cl's integrate_pdf). */
__kernel void integrate_aniso_pdf(float4 v, float4 p, __global const float4* rects, uint count,
                                  uint n0, float rel_tol, float abs_tol, uint max_level,
                                  __global float2* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  uint n = n0;
  float fine = rect_midpoint(v, p, rects[i], n), change = 0.0f, error = 0.0f;
  for (uint level = 1; level <= max_level; ++level) {
    n *= 2u;
    const float coarse = fine, previous = change;
    fine = rect_midpoint(v, p, rects[i], n);
    change = fabs(fine - coarse);
    error = fmax(change, previous);
    if (level >= 2 && error <= fmax(rel_tol * fabs(fine), abs_tol)) break;
  }
  out[i] = (float2)(fine, error);
}

/* Pointwise evaluation. In: per item a = (wo, ax), b = (w, ay), u; wo and w in the anisotropy
 * frame (w: a microfacet normal for D and the pdf, a second direction wi for the visibility).
 * Out: 8 float4 per item, out[8 i + k]:
 *   k = 0: (D(w), Lambda(wo), G1(wo), V(wo, w))
 *   k = 1: (pdf(wo, h = w), Lambda(w), G1(w), 0)
 *   k = 2: sampling/warps.h with alpha = ax: (ggx_d(w.z, w.x^2 + w.y^2), ggx_g1(wo.z),
 *          ggx_visibility(w.z, wo.z), ggx_reflection_pdf(wo.z, w.z, w.x^2 + w.y^2))
 *   k = 3: (h = sample_ggx_aniso_visible_normal(wo, ax, ay, u), pdf(wo, h))
 *   k = 4: (sample_ggx_visible_normal(wo, ax, u), 0)
 *   k = 5: (wi = reflect(wo, h), V(wo, wi))
 *   k = 6: (D(h), pdf(wo, normalize(wo + wi)) (the eval side's), 0, 0)
 *   k = 7: (ggx_aniso_alphas(ax, ay) (roughness ax, strength ay), 0, 0) */
__kernel void evaluate(__global const float4* a, __global const float4* b, __global const float2* u,
                       uint count, __global float4* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  const float3 wo = a[i].xyz, w = b[i].xyz;
  const float ax = a[i].w, ay = b[i].w;
  __global float4* o = out + 8 * (size_t)i;
  o[0] = (float4)(ggx_aniso_d(w, ax, ay), ggx_aniso_lambda(wo, ax, ay), ggx_aniso_g1(wo, ax, ay),
                  ggx_aniso_visibility(wo, w, ax, ay));
  o[1] = (float4)(ggx_aniso_reflection_pdf(wo, w, ax, ay), ggx_aniso_lambda(w, ax, ay),
                  ggx_aniso_g1(w, ax, ay), 0.0f);
  const float sin2 = w.x * w.x + w.y * w.y;
  o[2] = (float4)(ggx_d(w.z, sin2, ax), ggx_g1(wo.z, ax), ggx_visibility(w.z, wo.z, ax),
                  ggx_reflection_pdf(wo.z, w.z, sin2, ax));
  const float3 h = sample_ggx_aniso_visible_normal(wo, ax, ay, u[i]);
  o[3] = (float4)(h, ggx_aniso_reflection_pdf(wo, h, ax, ay));
  o[4] = (float4)(sample_ggx_visible_normal(wo, ax, u[i].x, u[i].y), 0.0f);
  const float3 wi = 2.0f * dot(wo, h) * h - wo;
  o[5] = (float4)(wi, ggx_aniso_visibility(wo, wi, ax, ay));
  o[6] = (float4)(ggx_aniso_d(h, ax, ay), ggx_aniso_reflection_pdf(wo, normalize(wo + wi), ax, ay),
                  0.0f, 0.0f);
  o[7] = (float4)(ggx_aniso_alphas(ax, ay), 0.0f, 0.0f);
}
