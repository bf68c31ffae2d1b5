/* Stateless randomness: every random number is a function of (pixel, sample, seed, bounce,
 * dimension), so an image does not depend on queue order, wave size, work-group size or device,
 * and sample ranges rendered apart merge exactly.
 *
 * Two sample patterns (WP_SAMPLER, a program build option; features.h):
 *
 * Independent: each number is a hash of its coordinates, applied in a chain, dimension first, then
 * sample, then pixel, each step a full 32-bit avalanche (a two-multiply integer mixer). Because the
 * dimension enters first, two paths whose (pixel, sample) collide at one dimension do not collide
 * at the others: no two paths share a whole random stream.
 *
 * Sobol (default): the numbers a pixel's samples draw for one dimension group -- the pixel jitter,
 * a light sample's (u, v), a BSDF sample's (u, v), and each one-dimensional choice -- are points of
 * an Owen-scrambled Sobol' sequence: the first 2^k samples of a pixel put exactly one point in
 * every elementary interval of area 2^-k (one per 2^-k interval in 1D), the same for every aligned
 * block of 2^k samples, so errors fall faster than 1/sqrt(samples) where the integrand is smooth in
 * those dimensions. Groups are decorrelated from one another by giving each its own scrambled order
 * of the sample index ("padding" by shuffling, as in Burley 2020, "Practical Hash-based Owen
 * Scrambling", JCGT 9(4)); scrambles are seeded by a hash of (pixel, seed, bounce, dimension).
 * Every point is uniformly distributed over the scrambles, so estimates stay unbiased.
 *
 * Outputs are odd multiples of 2^-24 in (0, 1) (rng_float). The alpha keys (rng_bits) are hashes in
 * both patterns.
 */
#ifndef WP_RNG_H
#define WP_RNG_H

#include "features.h"

/* Dimensions used at each bounce. */
#define WP_DIM_PIXEL_X 0u
#define WP_DIM_PIXEL_Y 1u
#define WP_DIM_LIGHT_PICK 2u
#define WP_DIM_LIGHT_U 3u
#define WP_DIM_LIGHT_V 4u
#define WP_DIM_BSDF_LOBE 5u
#define WP_DIM_BSDF_U 6u
#define WP_DIM_BSDF_V 7u
#define WP_DIM_ROULETTE 8u
#define WP_DIM_ALPHA_CLOSEST 9u /* stochastic alpha of the closest-hit ray (a key, see alpha.h) */
#define WP_DIM_ALPHA_SHADOW 10u /* ... and of the shadow ray */
#define WP_DIMS_PER_BOUNCE 16u

static inline uint wp_hash(uint x) {
  x ^= x >> 16;
  x *= 0x21f0aaadu;
  x ^= x >> 15;
  x *= 0xd35a2d97u;
  x ^= x >> 15;
  return x;
}

typedef struct Rng {
  uint pixel, sample, seed, bounce;
} Rng;

static inline Rng rng_make(uint pixel, uint sample, uint seed, uint bounce) {
  Rng r = {pixel, sample, seed, bounce};
  return r;
}

/* The 32 random bits of dimension `dim`. */
static inline uint rng_bits(Rng r, uint dim) {
  uint h = wp_hash(r.bounce * WP_DIMS_PER_BOUNCE + dim + wp_hash(r.seed));
  h = wp_hash(h ^ r.sample);
  return wp_hash(h ^ r.pixel);
}

/* The top 23 bits as the midpoint of their cell: an odd multiple of 2^-24 in (0, 1), never 0 or 1,
 * so no sample lands exactly on the edge of a domain (a triangle's side, a pole). */
static inline float rng_float(uint bits) {
  return (float)(bits >> 9) * (1.0f / 8388608.0f) + (1.0f / 16777216.0f);
}

#if WP_SAMPLER == WP_SAMPLER_SOBOL

static inline uint rng_reverse_bits(uint x) {
  x = (x << 16) | (x >> 16);
  x = ((x & 0x00ff00ffu) << 8) | ((x >> 8) & 0x00ff00ffu);
  x = ((x & 0x0f0f0f0fu) << 4) | ((x >> 4) & 0x0f0f0f0fu);
  x = ((x & 0x33333333u) << 2) | ((x >> 2) & 0x33333333u);
  return ((x & 0x55555555u) << 1) | ((x >> 1) & 0x55555555u);
}

/* A seeded bijection of 32-bit words in which bit j of the result is bit j of x flipped by a
 * function of the seed and of x's bits below j only: adding, multiplying by an odd number and
 * xoring in x times an even number all carry information upwards only. The seed-dependent odd
 * multiplier makes the flip of bit j depend on the lower bits differently for every seed. */
static inline uint rng_nested_permute(uint x, uint seed) {
  x += seed;
  x ^= x * 0x6a09e668u;
  x *= (seed >> 15) | 1u;
  x ^= x * 0xbb67ae84u;
  x += wp_hash(seed);
  x ^= x * 0x3c6ef372u;
  x *= (wp_hash(seed) >> 13) | 1u;
  x ^= x * 0xa54ff53au;
  return x;
}

/* Owen scrambling of a binary fraction (bit 31 is the first digit): each digit is flipped by a
 * function of the digits before it. Used on the sample index too, where it shuffles the order in
 * which a group sees the sequence while mapping every aligned block of 2^k indices onto another
 * aligned block of 2^k. */
static inline uint rng_owen(uint x, uint seed) {
  return rng_reverse_bits(rng_nested_permute(rng_reverse_bits(x), seed));
}

/* The second Sobol' dimension, Owen-scrambled. Its generator matrix is Pascal's triangle mod 2
 * (direction numbers v_0 = 1/2, v_{k+1} = v_k xor v_k / 2), so with the index's bits as the
 * coefficients of a polynomial I(t), the point's digits are those of I(1 + t): a Taylor shift by 1,
 * which over GF(2) takes five shift-xor steps ((1 + t)^(2^j) = 1 + t^(2^j), so each half of a
 * block of 2^(j+1) coefficients adds its upper half to its lower one). The result is the point
 * with its digits reversed, which is what Owen scrambling permutes (rng_owen) before reversing. */
static inline uint rng_sobol_second(uint index, uint seed) {
  index ^= (index >> 16) & 0x0000ffffu;
  index ^= (index >> 8) & 0x00ff00ffu;
  index ^= (index >> 4) & 0x0f0f0f0fu;
  index ^= (index >> 2) & 0x33333333u;
  index ^= (index >> 1) & 0x55555555u;
  return rng_reverse_bits(rng_nested_permute(index, wp_hash(seed ^ 0x1b873593u)));
}

/* The first Sobol' dimension, van der Corput, Owen-scrambled: owen(reverse(i)) =
 * reverse(permute(i)). */
static inline uint rng_van_der_corput(uint index, uint seed) {
  return rng_reverse_bits(rng_nested_permute(index, wp_hash(seed ^ 0x5bd1e995u)));
}

/* The scramble seed of dimension group `dim` of this path at this bounce. */
static inline uint rng_group_seed(Rng r, uint dim) {
  return wp_hash(wp_hash(r.bounce * WP_DIMS_PER_BOUNCE + dim + wp_hash(r.seed)) ^ r.pixel);
}

/* One-dimensional: the scrambled van der Corput point of this group's shuffled sample index.
 * rng_get and rng_get2 are always inlined: left out of line (clang kept them so in the fused shade
 * kernel), they took 15% of a Cornell box render on PoCL; inlined, the fused kernel's time fell by
 * 7% (README, "Random numbers inlined"). */
static inline __attribute__((always_inline)) float rng_get(Rng r, uint dim) {
  const uint seed = rng_group_seed(r, dim);
  const uint index = rng_owen(r.sample, seed);
  return rng_float(rng_van_der_corput(index, seed));
}

/* Two-dimensional group (dim, dim + 1): the scrambled point of the first two Sobol' dimensions. */
static inline __attribute__((always_inline)) float2 rng_get2(Rng r, uint dim) {
  const uint seed = rng_group_seed(r, dim);
  const uint index = rng_owen(r.sample, seed);
  return (float2)(rng_float(rng_van_der_corput(index, seed)),
                  rng_float(rng_sobol_second(index, seed)));
}

#else

static inline __attribute__((always_inline)) float rng_get(Rng r, uint dim) {
  return rng_float(rng_bits(r, dim));
}

static inline __attribute__((always_inline)) float2 rng_get2(Rng r, uint dim) {
  return (float2)(rng_get(r, dim), rng_get(r, dim + 1u));
}

#endif

#endif /* WP_RNG_H */
