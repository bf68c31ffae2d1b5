/* Test kernels for tests/test_iridescence.cpp: kernels/bsdf/iridescence.h's functions at given
 * arguments, so that the host can hold them against its float64 spectral reference and limits.
 *
 * film: args[i] = (outside_ior, film_ior, thickness_nm, cos1), f0[i] = base F0 (xyz);
 *   out[i].xyz = iridescent_fresnel(...), out[i].w = 1 when any of it is NaN or infinite.
 * sensitivity: out[i].xyz = iridescence_sensitivity(opd[i]).
 * mixes: args[i] = (strength, film_ior, thickness_nm, cos1), extra[i] = (ior, specular, texture_g
 *   for iridescence_thickness_nm(100, 400, g): written to out_metal[i].w), colour[i] = base colour
 *   (xyz); out_dielectric[i] = (iridescence_dielectric_fresnel, iridescence_base_weight of it),
 *   out_metal[i].xyz = iridescence_metal_fresnel. */
#include "bsdf/iridescence.h"

__kernel void film(__global const float4* args, __global const float4* f0, uint count,
                   __global float4* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  const float4 a = args[i];
  const float3 f = iridescent_fresnel(a.x, a.y, f0[i].xyz, a.z, a.w);
  out[i] = (float4)(f, all(isfinite(f)) ? 0.0f : 1.0f);
}

__kernel void sensitivity(__global const float* opd, uint count, __global float4* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  out[i] = (float4)(iridescence_sensitivity(opd[i]), 0.0f);
}

__kernel void mixes(__global const float4* args, __global const float4* extra,
                    __global const float4* colour, uint count, __global float4* out_dielectric,
                    __global float4* out_metal) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  const float4 a = args[i], e = extra[i];
  const float3 fd = iridescence_dielectric_fresnel(a.x, a.y, a.z, e.x, e.y, a.w);
  out_dielectric[i] = (float4)(fd, iridescence_base_weight(fd));
  out_metal[i] = (float4)(iridescence_metal_fresnel(a.x, a.y, a.z, colour[i].xyz, a.w),
                          iridescence_thickness_nm(100.0f, 400.0f, e.z));
}
