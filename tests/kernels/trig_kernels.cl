/* Test kernels of tests/test_sampling.cpp: cos_sin_turn (Sampling.CosSinTurn) at given fractions of
 * a turn, sample_concentric_disk (Sampling.ConcentricDisk) at given points of the square, and
 * atan2_poly (Sampling.Atan2Poly) with the other functions of kernels/util/elementary.h
 * (Elementary.*) at given arguments (kernels/sampling/warps.h includes it). */
#include "sampling/warps.h"

__kernel void cos_sin_turn_at(__global const float* u, uint count, __global float2* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  float c, s;
  cos_sin_turn(u[i], &c, &s);
  out[i] = (float2)(c, s);
}

__kernel void concentric_disk_at(__global const float2* u, uint count, __global float2* out) {
  const uint i = get_global_id(0);
  if (i < count) out[i] = sample_concentric_disk(u[i]);
}

__kernel void atan2_poly_at(__global const float2* yx, uint count, __global float* out) {
  const uint i = get_global_id(0);
  if (i < count) out[i] = atan2_poly(yx[i].x, yx[i].y);
}

/* out[i] = the elementary function `fn` of kernels/util/elementary.h at in[i] (0: exp_poly of x, 1:
 * log_poly of x, 2: log1p_poly of x, 3: powr_poly(x, y), 4: cbrt_poly of x, 5: log2_poly of x, 6:
 * cos_poly of x), (x, y) = in[i]. */
__kernel void elementary_at(__global const float2* in, uint count, uint fn, __global float* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  const float x = in[i].x, y = in[i].y;
  out[i] = fn == 0u   ? exp_poly(x)
           : fn == 1u ? log_poly(x)
           : fn == 2u ? log1p_poly(x)
           : fn == 3u ? powr_poly(x, y)
           : fn == 4u ? cbrt_poly(x)
           : fn == 5u ? log2_poly(x)
                      : cos_poly(x);
}
