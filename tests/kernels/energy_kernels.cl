/* Test kernels for tests/test_energy.cpp: Monte Carlo estimates of a surface's directional albedo
 * (the fraction of light from direction wo that it scatters, reflected and transmitted) in a
 * white furnace, made the way the renderer makes them, so that the host can hold them against a
 * float64 quadrature of the documented BSDF (bsdf.h's header).
 *
 * The surface: shading and geometric normal tilted_normal() (not an axis, so the BSDF's own frame
 * is exercised), base colour `color` (grey: every channel alike, channel x reported), metallic,
 * roughness, ior and transmission in params, Surface flags in `flags`, wo at cosine cos_o to the
 * normal. Per sample i (hash stream of "pixel" i, kernels/sampling/rng.h), out[i] =
 *   x: BSDF sampling alone: bsdf_sample's weight (0 for an invalid sample);
 *   y: both strategies of the renderer with MIS: the BSDF sample weighted against a uniform
 *      sphere "light" (the constant background's NEE pdf, 1 / 4 pi), plus one uniform light sample
 *      f |cos| / p weighted against the BSDF's pdf; as the integrator does, samples with pdf 0
 *      (delta lobes) count with weight 1 (mis_weight_bsdf_hit) and no light sample is taken
 *      where bsdf_only_delta;
 *   z: 1 when any value on the way was NaN or infinite, else 0;
 *   w: unused. */
#include "bsdf/bsdf.h"
#include "lights/mis.h"
#include "sampling/rng.h"

inline float3 tilted_normal(void) {
  return normalize((float3)(0.3f, -0.5f, 0.8f));
}

inline bool finite3(float3 v) {
  return all(isfinite(v));
}

/* One sample of both estimates, every channel (out's x and y above, as colours) and whether a
 * value on the way was NaN or infinite, for surface s seen from wo, with sample stream i of
 * `seed`; t, b complete s->ns to the frame the light sample is drawn in. */
typedef struct AlbedoSample {
  float3 bsdf_only, mis;
  bool bad;
  /* The BSDF sample's own fields, for dispersion_albedo_estimates' bookkeeping: valid, pdf and
   * the path's channel after it (BsdfSample.channel; 0 in programs without the feature). */
  bool valid;
  float pdf;
  uint channel;
} AlbedoSample;

inline AlbedoSample albedo_sample(const Surface* s, float3 wo, float3 t, float3 b, uint i,
                                  uint seed) {
  const Rng r = rng_make(i, 0u, seed, 0u);
  AlbedoSample a = {(float3)(0.0f), (float3)(0.0f), false, false, 0.0f, 0u};
  const BsdfSample bs =
      bsdf_sample(s, wo, rng_get(r, WP_DIM_BSDF_LOBE), rng_get2(r, WP_DIM_BSDF_U));
  a.valid = bs.valid, a.pdf = bs.pdf;
#if WP_FEATURE_DISPERSION
  a.channel = bs.channel;
#endif
  const float p_light = 1.0f / (4.0f * WP_PI);
  if (bs.valid) {
    a.bad |= !finite3(bs.weight) || !isfinite(bs.pdf);
    a.bsdf_only = bs.weight;
    a.mis = bs.weight * mis_weight_bsdf_hit(bs.pdf, p_light, WP_STRATEGY_MIS); /* delta: 1 */
  }
  /* The light sample: a uniform direction on the sphere; none where light sampling does not run
   * (bsdf_only_delta, as integrator/sample_lights.h). */
  if (!bsdf_only_delta(s)) {
    const float2 u = rng_get2(r, WP_DIM_LIGHT_U);
    const float z = 1.0f - 2.0f * u.x, rho = sqrt(fmax(0.0f, 1.0f - z * z));
    const float phi = 2.0f * WP_PI * u.y;
    const float3 wl = rho * cos(phi) * t + rho * sin(phi) * b + z * s->ns;
    const BsdfEval e = bsdf_eval(s, wo, wl);
    a.bad |= !finite3(e.f) || !isfinite(e.pdf);
    if (e.pdf > 0.0f || any(e.f > 0.0f))
      a.mis += e.f * (fabs(z) / p_light * mis_weight(p_light, e.pdf));
  }
  a.bad |= !finite3(a.mis) || !finite3(a.bsdf_only);
  return a;
}

/* The surface of both kernels without the extensions: each present one set to its absence
 * (specular colour 1, the rest 0), as resolve_extensions (material.h) leaves a material without
 * them. */
inline Surface plain_surface(float4 color, float4 params, uint flags) {
  Surface s = {0};
  s.ng = s.ns = tilted_normal();
  s.specular = 1.0f;
  s.color = color.xyz;
  s.metallic = params.x, s.roughness = params.y, s.ior = params.z, s.transmission = params.w;
  s.flags = flags;
#if WP_FEATURE_SPECULAR
  s.specular_color = (float3)(1.0f);
#endif
#if WP_FEATURE_CLEARCOAT
  s.nc = s.ns;
#endif
  return s;
}

__kernel void albedo_estimates(float4 color, float4 params, uint flags, float cos_o, uint seed,
                               uint count, __global float4* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  const Surface s = plain_surface(color, params, flags);
  float3 t, b;
  make_basis(s.ns, &t, &b);
  const float sin_o = sqrt(fmax(0.0f, 1.0f - cos_o * cos_o));
  const float3 wo = sin_o * t + cos_o * s.ns;
  const AlbedoSample a = albedo_sample(&s, wo, t, b, i, seed);
  out[i] = (float4)(a.bsdf_only.x, a.mis.x, a.bad ? 1.0f : 0.0f, 0.0f);
}

/* As albedo_estimates, with the layered extensions (bsdf.h), every colour grey:
 *   coat     (clearcoat factor, clearcoat roughness, -, -); the coat normal is ns
 *   sheen    (sheen colour, sheen roughness, -, -)
 *   spec     (specular factor, specular colour, -, -)
 *   aniso    (strength, angle in radians of the anisotropy direction from wo's azimuth, -, -)
 *   irid     (iridescence factor, film ior, thickness in nm, -)
 *   dtrans   (diffuse transmission factor, diffuse transmission colour, -, -)
 * An extension whose feature the program lacks is ignored. Per sample i, every channel:
 *   out[2 i]     = (BSDF sampling alone, rgb; 1 when a value was NaN or infinite, else 0),
 *   out[2 i + 1] = (MIS with the light sample, rgb; 0). */
__kernel void layered_albedo_estimates(float4 color, float4 params, uint flags, float cos_o,
                                       float4 coat, float4 sheen, float4 spec, float4 aniso,
                                       float4 irid, float4 dtrans, uint seed, uint count,
                                       __global float4* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  Surface s = plain_surface(color, params, flags);
  s.specular = spec.x;
  float3 t, b;
  make_basis(s.ns, &t, &b);
  const float sin_o = sqrt(fmax(0.0f, 1.0f - cos_o * cos_o));
  const float3 wo = sin_o * t + cos_o * s.ns;
#if WP_FEATURE_SPECULAR
  s.specular_color = (float3)(spec.y);
#endif
#if WP_FEATURE_CLEARCOAT
  s.clearcoat = coat.x, s.clearcoat_roughness = coat.y;
#endif
#if WP_FEATURE_SHEEN
  s.sheen_color = (float3)(sheen.x), s.sheen_roughness = sheen.y;
#endif
#if WP_FEATURE_ANISOTROPY
  s.anisotropy = aniso.x;
  s.aniso_t = cos(aniso.y) * t + sin(aniso.y) * b;
#endif
#if WP_FEATURE_IRIDESCENCE
  s.iridescence = irid.x, s.iridescence_ior = irid.y, s.iridescence_thickness = irid.z;
#endif
#if WP_FEATURE_DIFFUSE_TRANSMISSION
  s.diffuse_transmission = dtrans.x, s.dt_color = (float3)(dtrans.y);
#endif
  (void)coat, (void)sheen, (void)aniso, (void)irid, (void)dtrans;
  const AlbedoSample a = albedo_sample(&s, wo, t, b, i, seed);
  out[2 * i] = (float4)(a.bsdf_only, a.bad ? 1.0f : 0.0f);
  out[2 * i + 1] = (float4)(a.mis, 0.0f);
}

/* KHR_materials_dispersion (bsdf.h): as albedo_estimates for the surface with dispersion factor
 * `dispersion` and the path's channel `channel` (Surface.channel: 0 for a path of all three
 * channels, else the channel it chose earlier, 1 R, 2 G, 3 B). Per sample i, every channel:
 *   out[2 i]     = (BSDF sampling alone, rgb; 1 when a value was NaN or infinite, else 0),
 *   out[2 i + 1] = (MIS with the light sample, rgb; 1 when the channel bookkeeping of the
 *                  documented model was broken, else 0): with channel 0 at a dispersive surface,
 *                  the sample's channel is one of 1-3 and a valid sample's weight is 0 on the
 *                  other channels, its pdf is reported 0, and no light sample is taken
 *                  (bsdf_only_delta); with a channel preset, the sample keeps it. */
__kernel void dispersion_albedo_estimates(float4 color, float4 params, uint flags, float cos_o,
                                          float dispersion, uint channel, uint seed, uint count,
                                          __global float4* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  Surface s = plain_surface(color, params, flags);
  bool broken = false;
#if WP_FEATURE_DISPERSION
  s.dispersion = dispersion, s.channel = channel;
#else
  broken = dispersion > 0.0f; /* nothing to test in this program */
  (void)channel;
#endif
  float3 t, b;
  make_basis(s.ns, &t, &b);
  const float sin_o = sqrt(fmax(0.0f, 1.0f - cos_o * cos_o));
  const float3 wo = sin_o * t + cos_o * s.ns;
  const AlbedoSample a = albedo_sample(&s, wo, t, b, i, seed);
  const bool dispersive =
      dispersion > 0.0f && (flags & WP_SURF_VOLUME) && params.w > 0.0f && params.x < 1.0f;
  if (channel == 0u && dispersive) {
    broken |= a.channel < 1u || a.channel > 3u || !bsdf_only_delta(&s);
    if (a.valid) {
      const float w[3] = {a.bsdf_only.x, a.bsdf_only.y, a.bsdf_only.z};
      for (uint k = 0; k < 3u; ++k) broken |= k + 1u != a.channel && w[k] != 0.0f;
      broken |= a.pdf != 0.0f;
    }
  } else {
    broken |= a.channel != channel;
  }
  out[2 * i] = (float4)(a.bsdf_only, a.bad ? 1.0f : 0.0f);
  out[2 * i + 1] = (float4)(a.mis, broken ? 1.0f : 0.0f);
}

/* dispersed_ior at the points (ior, dispersion, channel, -) of `points`. */
__kernel void dispersed_iors(__global const float4* points, uint count, __global float* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
#if WP_FEATURE_DISPERSION
  out[i] = dispersed_ior(points[i].x, points[i].y, (uint)points[i].z);
#else
  out[i] = points[i].x;
#endif
}

/* sheen.h's and sheen_table.h's constants, for the host's model of the table: out[0..6] =
 * (NMU, NR, SQRT_RMIN, QUAD_ERROR, INTERP_ERROR, WP_SHEEN_ROUGHNESS_MIN,
 * INTERP_ERROR_GRAZING). */
__kernel void sheen_layout(__global float* out) {
  if (get_global_id(0) != 0) return;
  out[0] = (float)WP_SHEEN_TABLE_NMU, out[1] = (float)WP_SHEEN_TABLE_NR;
  out[2] = WP_SHEEN_TABLE_SQRT_RMIN, out[3] = (float)(WP_SHEEN_TABLE_QUAD_ERROR);
  out[4] = (float)(WP_SHEEN_TABLE_INTERP_ERROR), out[5] = WP_SHEEN_ROUGHNESS_MIN;
  out[6] = (float)(WP_SHEEN_TABLE_INTERP_ERROR_GRAZING);
}

/* sheen_albedo (the table's E) at the points (mu, sheen roughness) of `points`. */
__kernel void sheen_albedos(__global const float2* points, uint count, __global float* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  out[i] = sheen_albedo(points[i].x, points[i].y);
}

/* mis_weight at the pairs of pdfs in `pairs` (x: own, y: other); out = the weights. */
__kernel void mis_weights(__global const float2* pairs, uint count, __global float* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  out[i] = mis_weight(pairs[i].x, pairs[i].y);
}
