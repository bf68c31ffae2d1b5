/* Test kernels for tests/test_sheen.cpp: the sheen lobe's functions (kernels/bsdf/sheen.h) on the
 * device, for the host to hold against its float64 evaluation of the extension's formulas. */
#include "bsdf/sheen.h"

/* Per item i: n = in[3i].xyz, wo = in[3i + 1].xyz with alpha in in[3i + 1].w, wi = in[3i + 2].xyz;
 * out[i] = (sheen_eval, sheen_lambda(n.wo), sheen_lambda(n.wi), 0). */
__kernel void eval_sheen(__global const float4* in, uint count, __global float4* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  const float3 n = in[3 * i].xyz, wo = in[3 * i + 1].xyz, wi = in[3 * i + 2].xyz;
  const float alpha = in[3 * i + 1].w;
  out[i] = (float4)(sheen_eval(n, wo, wi, alpha), sheen_lambda(dot(n, wo), alpha),
                    sheen_lambda(dot(n, wi), alpha), 0.0f);
}

/* Per item: in[i] = (cos, alpha); out[i] = (sheen_d(cos, alpha), sheen_lambda(cos, alpha)). */
__kernel void d_and_lambda(__global const float2* in, uint count, __global float2* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  out[i] = (float2)(sheen_d(in[i].x, in[i].y), sheen_lambda(in[i].x, in[i].y));
}

/* Per item: in[i] = (mu, roughness); out[i] = (sheen_albedo(mu, roughness), sheen_alpha(x)) with
 * x = roughness. */
__kernel void albedo_and_alpha(__global const float2* in, uint count, __global float2* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  out[i] = (float2)(sheen_albedo(in[i].x, in[i].y), sheen_alpha(in[i].y));
}

/* One item: the table's layout and stated errors in out[0..7], then the table as the device sees
 * it in out[8..], if it fits in `capacity` floats. */
__kernel void table_info(uint capacity, __global float* out) {
  if (get_global_id(0) != 0) return;
  out[0] = (float)WP_SHEEN_TABLE_NMU;
  out[1] = (float)WP_SHEEN_TABLE_NR;
  out[2] = WP_SHEEN_TABLE_SQRT_RMIN;
  out[3] = WP_SHEEN_TABLE_QUAD_ERROR;
  out[4] = WP_SHEEN_TABLE_INTERP_ERROR;
  out[5] = WP_SHEEN_TABLE_INTERP_ERROR_GRAZING;
  out[6] = WP_SHEEN_ROUGHNESS_MIN;
  out[7] = WP_SHEEN_ALPHA_MIN;
  const uint n = WP_SHEEN_TABLE_NR * WP_SHEEN_TABLE_NMU;
  if (n + 8 > capacity) return;
  for (uint k = 0; k < n; ++k) out[8 + k] = wp_sheen_albedo[k];
}

/* The no-NaN/Inf sweep: item i takes cos_o = cosines[i % nc] and cos_i = cosines[i / nc]; for each
 * azimuth phi_k = azimuths[k] of wi (wo in the x-z plane), each alpha and each normal of `normals`
 * (the frame is rotated so that normals[m] is the normal), it evaluates sheen_eval, sheen_d and
 * sheen_lambda of both cosines and sheen_albedo(cos_o, alpha as roughness); out[i] counts the
 * values that are NaN, infinite or negative. */
__kernel void finite_sweep(__global const float* cosines, uint nc, __global const float* azimuths,
                           uint na, __global const float* alphas, uint nalpha,
                           __global const float4* normals, uint nn, __global uint* out) {
  const uint i = get_global_id(0);
  if (i >= nc * nc) return;
  const float co = cosines[i % nc], ci = cosines[i / nc];
  const float so = sqrt(fmax(0.0f, 1.0f - co * co)), si = sqrt(fmax(0.0f, 1.0f - ci * ci));
  uint bad = 0;
  for (uint m = 0; m < nn; ++m) {
    const float3 n = normals[m].xyz;
    float3 t, b;
    make_basis(n, &t, &b);
    const float3 wo = so * t + co * n;
    for (uint k = 0; k < na; ++k) {
      const float3 wi = si * cos(azimuths[k]) * t + si * sin(azimuths[k]) * b + ci * n;
      for (uint a = 0; a < nalpha; ++a) {
        const float v[6] = {sheen_eval(n, wo, wi, alphas[a]), sheen_d(co, alphas[a]),
                            sheen_lambda(co, alphas[a]),      sheen_lambda(ci, alphas[a]),
                            sheen_albedo(co, alphas[a]),      sheen_alpha(alphas[a])};
        for (int q = 0; q < 6; ++q) bad += !isfinite(v[q]) || v[q] < 0.0f;
      }
    }
  }
  out[i] = bad;
}
