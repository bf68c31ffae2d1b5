/* Test kernels for tests/test_energy.cpp: Monte Carlo estimates of a surface's directional albedo
 * (the fraction of light from direction wo that it scatters, reflected and transmitted) in a
 * white furnace, made the way the renderer makes them, so that the host can hold them against a
 * float64 quadrature of the documented BSDF (bsdf.h's header).
 *
 * The surface: shading and geometric normal tilted_normal() (not an axis, so the BSDF's own frame
 * is exercised), base colour `color` (grey: every channel alike, channel x reported), metallic,
 * roughness, ior and transmission in params, Surface flags in `flags`, wo at cosine cos_o to the
 * normal. Per sample i (hash stream of "pixel" i, kernels/rng.h), out[i] =
 *   x: BSDF sampling alone: bsdf_sample's weight (0 for an invalid sample);
 *   y: both strategies of the renderer with MIS: the BSDF sample weighted against a uniform
 *      sphere "light" (the constant background's NEE pdf, 1 / 4 pi), plus one uniform light sample
 *      f |cos| / p weighted against the BSDF's pdf; delta samples count with weight 1;
 *   z: 1 when any value on the way was NaN or infinite, else 0;
 *   w: unused. */
#include "bsdf.h"
#include "mis.h"
#include "rng.h"

inline float3 tilted_normal(void) {
  return normalize((float3)(0.3f, -0.5f, 0.8f));
}

inline bool finite3(float3 v) {
  return all(isfinite(v));
}

__kernel void albedo_estimates(float4 color, float4 params, uint flags, float cos_o, uint seed,
                               uint count, __global float4* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  Surface s = {0};
  s.ng = s.ns = tilted_normal();
  s.specular = 1.0f;
  s.color = color.xyz;
  s.metallic = params.x, s.roughness = params.y, s.ior = params.z, s.transmission = params.w;
  s.flags = flags;
  float3 t, b;
  make_basis(s.ns, &t, &b);
  const float sin_o = sqrt(fmax(0.0f, 1.0f - cos_o * cos_o));
  const float3 wo = sin_o * t + cos_o * s.ns;

  const Rng r = rng_make(i, 0u, seed, 0u);
  bool bad = false;
  const BsdfSample bs =
      bsdf_sample(&s, wo, rng_get(r, WP_DIM_BSDF_LOBE), rng_get2(r, WP_DIM_BSDF_U));
  const float p_light = 1.0f / (4.0f * WP_PI);
  float bsdf_only = 0.0f, mis = 0.0f;
  if (bs.valid) {
    bad |= !finite3(bs.weight) || !isfinite(bs.pdf);
    bsdf_only = bs.weight.x;
    mis = bs.weight.x * (bs.delta ? 1.0f : mis_weight(bs.pdf, p_light));
  }
  /* The light sample: a uniform direction on the sphere. */
  const float2 u = rng_get2(r, WP_DIM_LIGHT_U);
  const float z = 1.0f - 2.0f * u.x, rho = sqrt(fmax(0.0f, 1.0f - z * z));
  const float phi = 2.0f * WP_PI * u.y;
  const float3 wl = rho * cos(phi) * t + rho * sin(phi) * b + z * s.ns;
  const BsdfEval e = bsdf_eval(&s, wo, wl);
  bad |= !finite3(e.f) || !isfinite(e.pdf);
  if (e.pdf > 0.0f || e.f.x > 0.0f) mis += e.f.x * fabs(z) / p_light * mis_weight(p_light, e.pdf);
  bad |= !isfinite(mis);
  out[i] = (float4)(bsdf_only, mis, bad ? 1.0f : 0.0f, 0.0f);
}

/* mis_weight at the pairs of pdfs in `pairs` (x: own, y: other); out = the weights. */
__kernel void mis_weights(__global const float2* pairs, uint count, __global float* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  out[i] = mis_weight(pairs[i].x, pairs[i].y);
}
