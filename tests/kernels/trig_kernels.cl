/* Test kernel of tests/test_sampling.cpp (Sampling.CosSinTurn): cos_sin_turn (kernels/sampling.h)
 * at given fractions of a turn. */
#include "sampling.h"

__kernel void cos_sin_turn_at(__global const float* u, uint count, __global float2* out) {
  const uint i = get_global_id(0);
  if (i < count) out[i] = cos_sin_turn(u[i]);
}
