/* Test kernel of tests/test_rng.cpp: the random numbers of kernels/sampling/rng.h at given
 * coordinates, so that the host can check their distribution (uniformity, stratification,
 * independence). Built with -D WP_SAMPLER=0, 1 or 2.
 *
 * coords[i] = (pixel, sample, bounce, dim | pair << 16); out[i] = rng_get2(r, dim) when pair is 1,
 * else (rng_get(r, dim), 0). draw_bounce: out[i] = rng_bounce(r), all of a bounce's numbers at
 * once (the dim of coords[i] unused). sobol_pair_digits: out[i] = rng_sobol_pair_digits(in[i], p)
 * (Sobol' builds only). */
#include "sampling/rng.h"

__kernel void draw_rng(__global const uint4* coords, uint seed, uint count, __global float2* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  const uint4 c = coords[i];
  const Rng r = rng_make(c.x, c.y, seed, c.z);
  const uint dim = c.w & 0xffffu;
  out[i] = (c.w >> 16) != 0u ? rng_get2(r, dim) : (float2)(rng_get(r, dim), 0.0f);
}

__kernel void draw_bounce(__global const uint4* coords, uint seed, uint count,
                          __global float8* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  const uint4 c = coords[i];
  out[i] = rng_bounce(rng_make(c.x, c.y, seed, c.z));
}

#if WP_SAMPLER != WP_SAMPLER_INDEPENDENT
__kernel void sobol_pair_digits(__global const uint* in, uint p, uint count, __global uint2* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  out[i] = rng_sobol_pair_digits(in[i], p);
}
#endif
