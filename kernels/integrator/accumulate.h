/* Film accumulation: each sample's radiance added to its pixel's sums in fixed point (layout,
 * scale and ranges in shared/film.h): per channel the 128-bit sums S += a and
 * Q += floor(a^2 / 2^32), a = round(radiance * 2^32) saturated to [0, 2^64 - 1] (values from 2^32
 * on saturate). No sum overflows: a < 2^64 and a^2 / 2^32 < 2^96, so 2^20 samples (the most a film
 * holds) give S < 2^84 and Q < 2^116. Integer sums do not depend on the order of addition, so
 * films of sample ranges rendered apart merge bit for bit (host/film/film.h). A sample that is NaN
 * or infinite is not added; it is counted in counters[WP_COUNTER_NONFINITE] (the renderer reports
 * the count, the tests require 0) and weighs as 0 in the mean (S / 2^32 / spp).
 *
 * Radiance is never negative for a valid scene (emission, lights, the background and the
 * environment are non-negative, and so are BSDF values, cosines and MIS weights; the loader
 * refuses factors outside glTF's ranges). A negative value would saturate to 0. Entry point:
 * accumulate.cl. */
#ifndef WP_INTEGRATOR_ACCUMULATE_H
#define WP_INTEGRATOR_ACCUMULATE_H

#include "stage.h"
#include "shared/film.h"

/* v += (hi, lo), 128-bit values stored as two words, the low one first. */
static inline void film_add128(__global ulong* v, ulong lo, ulong hi) {
  const ulong sum = v[0] + lo;
  v[1] += hi + (sum < lo ? 1ul : 0ul); /* the carry; hi < 2^64 - 1 here, so no overflow */
  v[0] = sum;
}

/* round(v * 2^32), ties to even, saturated to [0, 2^64 - 1], for a finite v: what
 * convert_ulong_sat_rte(v * 2^32) gives, in a few instructions where PoCL expands that built-in
 * (and rint) into chains of range tests and branches. v * 2^32 is exact (a power of two). Below
 * 2^23, adding 2^23 leaves no fraction bits, so the sum is rounded to an integer by the float
 * addition itself (to nearest, ties to even: OpenCL's rounding mode) and subtracting 2^23 again
 * is exact; from 2^23 on a float is an integer already, and one below 2^64 converts to ulong
 * exactly. Checked against the host's film_fixed (nearbyint) on the rounding ties and the
 * saturation bounds by FilmKernel.AccumulateMatchesTheHostReference, and over floats from 2^-40
 * to 2^34 by its Densely twin. */
static inline ulong film_fixed(float v) {
  const float x = fmax(v * 0x1p32f, 0.0f);
  const float r = x < 0x1p23f ? (x + 0x1p23f) - 0x1p23f : x;
  return r < 0x1p64f ? convert_ulong(r) : ULONG_MAX;
}

/* Adds one channel's value v to the sums at `px` (the pixel's first word). */
static inline void film_add_value(__global ulong* px, uint channel, float v) {
  const ulong a = film_fixed(v);
  const ulong sq_lo = a * a, sq_hi = mul_hi(a, a); /* a^2, 128 bits */
  film_add128(px + WP_FILM_SUM(channel), a, 0ul);
  film_add128(px + WP_FILM_SQUARES(channel), (sq_hi << 32) | (sq_lo >> 32), sq_hi >> 32);
}

/* The sums' stride: 12 words per pixel, 26 with AOVs. */
#define WP_FILM_STRIDE WP_FILM_WORDS(WP_AOV)

#if WP_AOV
/* Adds one sample's AOVs: albedo, normal + 1 and depth, one 128-bit sum each (shared/film.h). */
static inline void film_add_aovs(__global ulong* px, float3 albedo, float3 normal, float depth) {
  const float a[3] = {albedo.x, albedo.y, albedo.z}, n[3] = {normal.x, normal.y, normal.z};
  for (uint c = 0; c < 3u; ++c) {
    film_add128(px + WP_FILM_ALBEDO(c), film_fixed(a[c]), 0ul);
    film_add128(px + WP_FILM_NORMAL(c), film_fixed(n[c] + 1.0f), 0ul);
  }
  film_add128(px + WP_FILM_DEPTH, film_fixed(depth), 0ul);
}
#endif

/* Adds every sample of the wave's pixel `first` (slots first, first + wave_pixels, ...: stage.h,
 * path_sample) to the film, so that no two work-items write one pixel. */
WP_STAGE_FN void accumulate_pixel(Paths paths, Queues queues, Launch launch, __global ulong* film,
                                  uint first) {
  __global ulong* px = film + (size_t)path_pixel(launch, first) * WP_FILM_STRIDE;
  for (uint slot = first; slot < launch.path_count; slot += launch.wave_pixels) {
#if WP_AOV /* every sample once, also one whose radiance is dropped below */
    film_add_aovs(px, path_aov_albedo(paths, slot), path_aov_normal(paths, slot),
                  path_aov_depth(paths, slot));
#endif
    const float3 l = path_radiance(paths, slot);
    if (!all(isfinite(l))) {
      count_nonfinite(queues);
      continue;
    }
    film_add_value(px, 0u, l.x);
    film_add_value(px, 1u, l.y);
    film_add_value(px, 2u, l.z);
  }
}

#endif /* WP_INTEGRATOR_ACCUMULATE_H */
