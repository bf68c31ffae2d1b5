/* Test kernels of tests/test_sampling.cpp: cos_sin_turn (Sampling.CosSinTurn) at given fractions of
 * a turn, sample_concentric_disk (Sampling.ConcentricDisk) at given points of the square and
 * atan2_poly (Sampling.Atan2Poly) at given (y, x) (kernels/sampling.h). */
#include "sampling.h"

__kernel void cos_sin_turn_at(__global const float* u, uint count, __global float2* out) {
  const uint i = get_global_id(0);
  if (i < count) out[i] = cos_sin_turn(u[i]);
}

__kernel void concentric_disk_at(__global const float2* u, uint count, __global float2* out) {
  const uint i = get_global_id(0);
  if (i < count) out[i] = sample_concentric_disk(u[i]);
}

__kernel void atan2_poly_at(__global const float2* yx, uint count, __global float* out) {
  const uint i = get_global_id(0);
  if (i < count) out[i] = atan2_poly(yx[i].x, yx[i].y);
}
