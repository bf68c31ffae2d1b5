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
 * both patterns. rng_bounce draws all the numbers of one bounce at once, the same numbers as
 * rng_get and rng_get2.
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

/* The integer functions below are defined for uint and uint8 (suffix 8), the hash and the Sobol'
 * helpers also for uint2 (suffix 2): the vector versions draw a pair (rng_get2) or all of a
 * bounce's numbers (rng_bounce) at once, in the lanes of one SIMD register on a CPU, the same
 * numbers bit for bit. */
#define WP_RNG_DEFINE_HASH(T, suffix)    \
  static inline T wp_hash##suffix(T x) { \
    x ^= x >> 16;                        \
    x *= 0x21f0aaadu;                    \
    x ^= x >> 15;                        \
    x *= 0xd35a2d97u;                    \
    x ^= x >> 15;                        \
    return x;                            \
  }
WP_RNG_DEFINE_HASH(uint, )
WP_RNG_DEFINE_HASH(uint2, 2)
WP_RNG_DEFINE_HASH(uint8, 8)

typedef struct Rng {
  uint pixel, sample, seed, bounce;
} Rng;

static inline Rng rng_make(uint pixel, uint sample, uint seed, uint bounce) {
  Rng r = {pixel, sample, seed, bounce};
  return r;
}

/* The 32 random bits of dimension `dim` (rng_bits8: of eight dimensions at once). */
#define WP_RNG_DEFINE_BITS(T, suffix)                                             \
  static inline T rng_bits##suffix(Rng r, T dim) {                                \
    T h = wp_hash##suffix(r.bounce * WP_DIMS_PER_BOUNCE + dim + wp_hash(r.seed)); \
    h = wp_hash##suffix(h ^ r.sample);                                            \
    return wp_hash##suffix(h ^ r.pixel);                                          \
  }
WP_RNG_DEFINE_BITS(uint, )
WP_RNG_DEFINE_BITS(uint8, 8)

/* The top 23 bits as the midpoint of their cell: an odd multiple of 2^-24 in (0, 1), never 0 or 1,
 * so no sample lands exactly on the edge of a domain (a triangle's side, a pole). Exact in float,
 * so rng_float8 gives the same numbers. */
static inline float rng_float(uint bits) {
  return (float)(bits >> 9) * (1.0f / 8388608.0f) + (1.0f / 16777216.0f);
}

static inline float8 rng_float8(uint8 bits) {
  return convert_float8(bits >> 9) * (1.0f / 8388608.0f) + (1.0f / 16777216.0f);
}

/* The dimensions of one bounce's random numbers, as rng_bounce returns them: lanes 0-4 are the
 * groups' first numbers (the light pick, the light point's u, the lobe, the BSDF direction's u,
 * roulette), lanes 5 and 6 the second numbers of the two pairs (v of the light point and of the
 * BSDF direction); lane 7 repeats lane 6. WP_BOUNCE_GROUPS names each lane's group (its first
 * dimension), WP_BOUNCE_SECOND marks the lanes that are a pair's second number. */
#define WP_BOUNCE_GROUPS                                                                        \
  ((uint8)(WP_DIM_LIGHT_PICK, WP_DIM_LIGHT_U, WP_DIM_BSDF_LOBE, WP_DIM_BSDF_U, WP_DIM_ROULETTE, \
           WP_DIM_LIGHT_U, WP_DIM_BSDF_U, WP_DIM_BSDF_U))
#define WP_BOUNCE_SECOND ((int8)(0, 0, 0, 0, 0, -1, -1, -1))

#if WP_SAMPLER == WP_SAMPLER_SOBOL

#define WP_RNG_DEFINE_SOBOL(T, suffix)                                  \
  static inline T rng_reverse_bits##suffix(T x) {                       \
    x = (x << 16) | (x >> 16);                                          \
    x = ((x & 0x00ff00ffu) << 8) | ((x >> 8) & 0x00ff00ffu);            \
    x = ((x & 0x0f0f0f0fu) << 4) | ((x >> 4) & 0x0f0f0f0fu);            \
    x = ((x & 0x33333333u) << 2) | ((x >> 2) & 0x33333333u);            \
    return ((x & 0x55555555u) << 1) | ((x >> 1) & 0x55555555u);         \
  }                                                                     \
  static inline T rng_nested_permute##suffix(T x, T seed) {             \
    x += seed;                                                          \
    x ^= x * 0x6a09e668u;                                               \
    x *= (seed >> 15) | 1u;                                             \
    x ^= x * 0xbb67ae84u;                                               \
    x += wp_hash##suffix(seed);                                         \
    x ^= x * 0x3c6ef372u;                                               \
    x *= (wp_hash##suffix(seed) >> 13) | 1u;                            \
    x ^= x * 0xa54ff53au;                                               \
    return x;                                                           \
  }                                                                     \
  static inline T rng_owen##suffix(T x, T seed) {                       \
    return rng_reverse_bits##suffix(                                    \
        rng_nested_permute##suffix(rng_reverse_bits##suffix(x), seed)); \
  }                                                                     \
  static inline T rng_taylor_shift##suffix(T index) {                   \
    index ^= (index >> 16) & 0x0000ffffu;                               \
    index ^= (index >> 8) & 0x00ff00ffu;                                \
    index ^= (index >> 4) & 0x0f0f0f0fu;                                \
    index ^= (index >> 2) & 0x33333333u;                                \
    return index ^ ((index >> 1) & 0x55555555u);                        \
  }

/* rng_reverse_bits: the bits of x in reverse order.
 *
 * rng_nested_permute: a seeded bijection of 32-bit words in which bit j of the result is bit j of
 * x flipped by a function of the seed and of x's bits below j only: adding, multiplying by an odd
 * number and xoring in x times an even number all carry information upwards only. The
 * seed-dependent odd multiplier makes the flip of bit j depend on the lower bits differently for
 * every seed.
 *
 * rng_owen: Owen scrambling of a binary fraction (bit 31 is the first digit): each digit is flipped
 * by a function of the digits before it. Used on the sample index too, where it shuffles the order
 * in which a group sees the sequence while mapping every aligned block of 2^k indices onto another
 * aligned block of 2^k.
 *
 * rng_taylor_shift: the second Sobol' dimension's generator matrix is Pascal's triangle mod 2
 * (direction numbers v_0 = 1/2, v_{k+1} = v_k xor v_k / 2), so with the index's bits as the
 * coefficients of a polynomial I(t), the point's digits are those of I(1 + t): a Taylor shift by 1,
 * which over GF(2) takes five shift-xor steps ((1 + t)^(2^j) = 1 + t^(2^j), so each half of a
 * block of 2^(j+1) coefficients adds its upper half to its lower one). The result is the point with
 * its digits reversed, which is what Owen scrambling permutes (rng_owen) before reversing. */
WP_RNG_DEFINE_SOBOL(uint, )
WP_RNG_DEFINE_SOBOL(uint2, 2)
WP_RNG_DEFINE_SOBOL(uint8, 8)

/* The scramble keys of a group's first and second dimensions, from its seed. */
#define WP_KEY_FIRST 0x5bd1e995u
#define WP_KEY_SECOND 0x1b873593u

/* The first Sobol' dimension, van der Corput, Owen-scrambled: owen(reverse(i)) =
 * reverse(permute(i)). */
static inline uint rng_van_der_corput(uint index, uint seed) {
  return rng_reverse_bits(rng_nested_permute(index, wp_hash(seed ^ WP_KEY_FIRST)));
}

/* The scramble seed of dimension group `dim` of this path at this bounce. */
#define WP_RNG_DEFINE_GROUP_SEED(T, suffix)                                                \
  static inline T rng_group_seed##suffix(Rng r, T dim) {                                   \
    return wp_hash##suffix(                                                                \
        wp_hash##suffix(r.bounce * WP_DIMS_PER_BOUNCE + dim + wp_hash(r.seed)) ^ r.pixel); \
  }
WP_RNG_DEFINE_GROUP_SEED(uint, )
WP_RNG_DEFINE_GROUP_SEED(uint8, 8)

/* One-dimensional: the scrambled van der Corput point of this group's shuffled sample index.
 * rng_get and rng_get2 are always inlined: left out of line (clang kept them so in the fused shade
 * kernel), they took 15% of a Cornell box render on PoCL; inlined, the fused kernel's time fell by
 * 7% (README, "Random numbers inlined"). */
static inline __attribute__((always_inline)) float rng_get(Rng r, uint dim) {
  const uint seed = rng_group_seed(r, dim);
  const uint index = rng_owen(r.sample, seed);
  return rng_float(rng_van_der_corput(index, seed));
}

/* Two-dimensional group (dim, dim + 1): the scrambled point of the first two Sobol' dimensions,
 * the first (van der Corput) and the second (its digits from rng_taylor_shift) in the two lanes of
 * a uint2, each with its own key, as rng_bounce does eight at a time (generate_camera_rays
 * 0.027 s -> 0.022 s on the Cornell box, 128 x 128, 96 spp, --profile, medians of 5). */
static inline __attribute__((always_inline)) float2 rng_get2(Rng r, uint dim) {
  const uint seed = rng_group_seed(r, dim);
  const uint index = rng_owen(r.sample, seed);
  const uint2 digits = (uint2)(index, rng_taylor_shift(index));
  const uint2 key = wp_hash2(seed ^ (uint2)(WP_KEY_FIRST, WP_KEY_SECOND));
  const uint2 bits = rng_reverse_bits2(rng_nested_permute2(digits, key));
  return (float2)(rng_float(bits.x), rng_float(bits.y));
}

/* All of a bounce's numbers (lanes: WP_BOUNCE_GROUPS), each exactly what rng_get or rng_get2 gives
 * (tested by Rng.BounceDrawEqualsTheOneByOneDraws), computed eight at a time: a CPU runs the lanes
 * in one SIMD register, a quarter of the instructions of seven scalar draws, with the depth of
 * one, so the shading kernel can draw them ahead of the work that needs them (shade.cl). */
static inline __attribute__((always_inline)) float8 rng_bounce(Rng r) {
  const uint8 seed = rng_group_seed8(r, WP_BOUNCE_GROUPS);
  const uint8 index = rng_owen8((uint8)(r.sample), seed);
  const uint8 second = as_uint8(WP_BOUNCE_SECOND);
  const uint8 digits = bitselect(index, rng_taylor_shift8(index), second);
  const uint8 key =
      wp_hash8(seed ^ bitselect((uint8)(WP_KEY_FIRST), (uint8)(WP_KEY_SECOND), second));
  return rng_float8(rng_reverse_bits8(rng_nested_permute8(digits, key)));
}

#else

static inline __attribute__((always_inline)) float rng_get(Rng r, uint dim) {
  return rng_float(rng_bits(r, dim));
}

/* As the Sobol' rng_bounce; here a pair's second number is the next dimension's (rng_get2). */
static inline __attribute__((always_inline)) float8 rng_bounce(Rng r) {
  const uint8 dim = WP_BOUNCE_GROUPS - as_uint8(WP_BOUNCE_SECOND); /* -(-1): the pair's next */
  return rng_float8(rng_bits8(r, dim));
}

static inline __attribute__((always_inline)) float2 rng_get2(Rng r, uint dim) {
  return (float2)(rng_get(r, dim), rng_get(r, dim + 1u));
}

#endif

#endif /* WP_RNG_H */
