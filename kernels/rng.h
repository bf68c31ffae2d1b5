/* Stateless randomness: every random number is a function of (pixel, sample, seed, bounce,
 * dimension), so an image does not depend on queue order, wave size, work-group size or device,
 * and sample ranges rendered apart merge exactly.
 *
 * Sample patterns (WP_SAMPLER, a program build option; features.h):
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
 * One group is chained instead: a light sample's (u, v) are the third and fourth Sobol'
 * dimensions of the order of the pair that chose the ray to the surface (the previous bounce's
 * BSDF direction; at bounce 0 the pixel jitter), so those two pairs form one four-dimensional
 * Sobol' set (rng_chained_group). The light pair alone then stratifies a little less (each
 * elementary interval of area 2^(t-k) holds 2^t of 2^k samples, t <= 2 instead of 0); on the
 * Lambertian Cornell box the image's relative MSE falls by 2.3% at 64 spp and 3.8% at 256 (README,
 * "Light samples chained to the ray").
 *
 * Sobol, padded (WP_SAMPLER_SOBOL_PADDED): the same, with the light pair in an order of its own
 * like every other group (the default pattern until the chain).
 *
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

#if WP_SAMPLER != WP_SAMPLER_INDEPENDENT

/* The light pair chained (WP_SAMPLER_SOBOL) or padded like the others (WP_SAMPLER_SOBOL_PADDED). */
#define WP_CHAIN_LIGHT (WP_SAMPLER == WP_SAMPLER_SOBOL)

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

/* The scramble keys of the third and fourth dimensions (the light pair, rng_chained_group). */
#define WP_KEY_THIRD 0x85ebca6bu
#define WP_KEY_FOURTH 0xc2b2ae35u

/* The third and fourth Sobol' dimensions (Joe and Kuo's direction numbers: primitive polynomials
 * x^2 + x + 1 with m = 1, 3 and x^3 + x + 1 with m = 1, 3, 1), digits reversed as
 * rng_taylor_shift gives the second's: entry [n][2 v + d] is dimension 2 + d's reversed digits of
 * the index v << 4n, the xor of the reversed direction numbers of v's bits, so the digits of any
 * index are the xor of one entry per nibble (the matrices are linear over GF(2)). Checked against
 * the direction-number recurrence by Rng.ThirdAndFourthSobolDimensionsMatchTheRecurrence. */
__constant uint wp_sobol23[8][32] = {
    {0x00000000u, 0x00000000u, 0x00000001u, 0x00000001u, 0x00000003u, 0x00000003u, 0x00000002u,
     0x00000002u, 0x00000006u, 0x00000004u, 0x00000007u, 0x00000005u, 0x00000005u, 0x00000007u,
     0x00000004u, 0x00000006u, 0x00000009u, 0x0000000au, 0x00000008u, 0x0000000bu, 0x0000000au,
     0x00000009u, 0x0000000bu, 0x00000008u, 0x0000000fu, 0x0000000eu, 0x0000000eu, 0x0000000fu,
     0x0000000cu, 0x0000000du, 0x0000000du, 0x0000000cu},
    {0x00000000u, 0x00000000u, 0x00000017u, 0x0000001fu, 0x0000003au, 0x0000002eu, 0x0000002du,
     0x00000031u, 0x00000071u, 0x00000045u, 0x00000066u, 0x0000005au, 0x0000004bu, 0x0000006bu,
     0x0000005cu, 0x00000074u, 0x000000a3u, 0x000000c9u, 0x000000b4u, 0x000000d6u, 0x00000099u,
     0x000000e7u, 0x0000008eu, 0x000000f8u, 0x000000d2u, 0x0000008cu, 0x000000c5u, 0x00000093u,
     0x000000e8u, 0x000000a2u, 0x000000ffu, 0x000000bdu},
    {0x00000000u, 0x00000000u, 0x00000116u, 0x0000011bu, 0x00000339u, 0x000002a4u, 0x0000022fu,
     0x000003bfu, 0x00000677u, 0x0000079au, 0x00000761u, 0x00000681u, 0x0000054eu, 0x0000053eu,
     0x00000458u, 0x00000425u, 0x000009aau, 0x00000b67u, 0x000008bcu, 0x00000a7cu, 0x00000a93u,
     0x000009c3u, 0x00000b85u, 0x000008d8u, 0x00000fddu, 0x00000cfdu, 0x00000ecbu, 0x00000de6u,
     0x00000ce4u, 0x00000e59u, 0x00000df2u, 0x00000f42u},
    {0x00000000u, 0x00000000u, 0x00001601u, 0x0000101eu, 0x00003903u, 0x0000302du, 0x00002f02u,
     0x00002033u, 0x00007706u, 0x00004041u, 0x00006107u, 0x0000505fu, 0x00004e05u, 0x0000706cu,
     0x00005804u, 0x00006072u, 0x0000aa09u, 0x0000a0c3u, 0x0000bc08u, 0x0000b0ddu, 0x0000930au,
     0x000090eeu, 0x0000850bu, 0x000080f0u, 0x0000dd0fu, 0x0000e082u, 0x0000cb0eu, 0x0000f09cu,
     0x0000e40cu, 0x0000d0afu, 0x0000f20du, 0x0000c0b1u},
    {0x00000000u, 0x00000000u, 0x00010117u, 0x0001f104u, 0x0003033au, 0x0002e28au, 0x0002022du,
     0x0003138eu, 0x00060671u, 0x000457dfu, 0x00070766u, 0x0005a6dbu, 0x0005054bu, 0x0006b555u,
     0x0004045cu, 0x00074451u, 0x000909a3u, 0x000c9baeu, 0x000808b4u, 0x000d6aaau, 0x000a0a99u,
     0x000e7924u, 0x000b0b8eu, 0x000f8820u, 0x000f0fd2u, 0x0008cc71u, 0x000e0ec5u, 0x00093d75u,
     0x000c0ce8u, 0x000a2efbu, 0x000d0dffu, 0x000bdfffu},
    {0x00000000u, 0x00000000u, 0x00171616u, 0x0011a105u, 0x003a3939u, 0x002a7289u, 0x002d2f2fu,
     0x003bd38cu, 0x00717777u, 0x0079e7dbu, 0x00666161u, 0x006846deu, 0x004b4e4eu, 0x00539552u,
     0x005c5858u, 0x00423457u, 0x00a3aaaau, 0x00b6dba4u, 0x00b4bcbcu, 0x00a77aa1u, 0x00999393u,
     0x009ca92du, 0x008e8585u, 0x008d0828u, 0x00d2ddddu, 0x00cf3c7fu, 0x00c5cbcbu, 0x00de9d7au,
     0x00e8e4e4u, 0x00e54ef6u, 0x00fff2f2u, 0x00f4eff3u},
    {0x00000000u, 0x00000000u, 0x01170001u, 0x0100011au, 0x033a0003u, 0x030002a7u, 0x022d0002u,
     0x020003bdu, 0x06710006u, 0x0400079eu, 0x07660007u, 0x05000684u, 0x054b0005u, 0x07000539u,
     0x045c0004u, 0x06000423u, 0x09a30009u, 0x0a000b6du, 0x08b40008u, 0x0b000a77u, 0x0a99000au,
     0x090009cau, 0x0b8e000bu, 0x080008d0u, 0x0fd2000fu, 0x0e000cf3u, 0x0ec5000eu, 0x0f000de9u,
     0x0ce8000cu, 0x0d000e54u, 0x0dff000du, 0x0c000f4eu},
    {0x00000000u, 0x00000000u, 0x16160017u, 0x1f001001u, 0x3939003au, 0x2e003003u, 0x2f2f002du,
     0x31002002u, 0x77770071u, 0x45004004u, 0x61610066u, 0x5a005005u, 0x4e4e004bu, 0x6b007007u,
     0x5858005cu, 0x74006006u, 0xaaaa00a3u, 0xc900a00au, 0xbcbc00b4u, 0xd600b00bu, 0x93930099u,
     0xe7009009u, 0x8585008eu, 0xf8008008u, 0xdddd00d2u, 0x8c00e00eu, 0xcbcb00c5u, 0x9300f00fu,
     0xe4e400e8u, 0xa200d00du, 0xf2f200ffu, 0xbd00c00cu},
};

static inline uint2 rng_sobol23_digits(uint index) {
  uint2 d = (uint2)(0u);
  for (uint n = 0u; n < 8u; ++n) d ^= vload2((index >> (4u * n)) & 15u, wp_sobol23[n]);
  return d;
}

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

/* The light pair (WP_DIM_LIGHT_U) has no sample order of its own: it takes the third and fourth
 * Sobol' dimensions of the order of the pair that chose the ray which found the surface -- the
 * BSDF direction of the bounce before, or the pixel jitter at bounce 0 -- so that the two pairs
 * are one four-dimensional Sobol' point set over the pixel's samples, stratified jointly: where
 * the ray lands and where on the light it looks are no longer paired at random. The group (as
 * rng_group_seed numbers it) whose order the light pair takes: (bounce - 1) * WP_DIMS_PER_BOUNCE
 * + WP_DIM_BSDF_U wraps through unsigned arithmetic to the previous bounce's BSDF group. */
static inline uint rng_chained_group(Rng r) {
#if WP_CHAIN_LIGHT
  return r.bounce != 0u ? WP_DIM_BSDF_U - WP_DIMS_PER_BOUNCE : WP_DIM_PIXEL_X;
#else
  (void)r;
  return WP_DIM_LIGHT_U;
#endif
}

/* The scramble keys of rng_bounce's lanes: the first or second dimension's of their group, the
 * third and fourth for the light pair. */
#if WP_CHAIN_LIGHT
#define WP_BOUNCE_KEYS                                                                          \
  ((uint8)(WP_KEY_FIRST, WP_KEY_THIRD, WP_KEY_FIRST, WP_KEY_FIRST, WP_KEY_FIRST, WP_KEY_FOURTH, \
           WP_KEY_SECOND, WP_KEY_SECOND))
#else
#define WP_BOUNCE_KEYS                                                                          \
  ((uint8)(WP_KEY_FIRST, WP_KEY_FIRST, WP_KEY_FIRST, WP_KEY_FIRST, WP_KEY_FIRST, WP_KEY_SECOND, \
           WP_KEY_SECOND, WP_KEY_SECOND))
#endif

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
 * 0.027 s -> 0.022 s on the Cornell box, 128 x 128, 96 spp, --profile, medians of 5). The light
 * pair instead takes the third and fourth dimensions in the order of rng_chained_group. */
static inline __attribute__((always_inline)) float2 rng_get2(Rng r, uint dim) {
  const bool chained = WP_CHAIN_LIGHT && dim == WP_DIM_LIGHT_U;
  const uint seed = rng_group_seed(r, chained ? rng_chained_group(r) : dim);
  const uint index = rng_owen(r.sample, seed);
  const uint2 digits =
      chained ? rng_sobol23_digits(index) : (uint2)(index, rng_taylor_shift(index));
  const uint2 key = wp_hash2(seed ^ (chained ? (uint2)(WP_KEY_THIRD, WP_KEY_FOURTH)
                                             : (uint2)(WP_KEY_FIRST, WP_KEY_SECOND)));
  const uint2 bits = rng_reverse_bits2(rng_nested_permute2(digits, key));
  return (float2)(rng_float(bits.x), rng_float(bits.y));
}

/* All of a bounce's numbers (lanes: WP_BOUNCE_GROUPS), each exactly what rng_get or rng_get2 gives
 * (tested by Rng.BounceDrawEqualsTheOneByOneDraws), computed eight at a time: a CPU runs the lanes
 * in one SIMD register, a quarter of the instructions of seven scalar draws, with the depth of
 * one, so the shading kernel can draw them ahead of the work that needs them (shade.cl). */
static inline __attribute__((always_inline)) float8 rng_bounce(Rng r) {
  uint8 group = WP_BOUNCE_GROUPS;
  group.s15 = (uint2)(rng_chained_group(r)); /* the light pair's lanes */
  const uint8 seed = rng_group_seed8(r, group);
  const uint8 index = rng_owen8((uint8)(r.sample), seed);
  uint8 digits = bitselect(index, rng_taylor_shift8(index), as_uint8(WP_BOUNCE_SECOND));
#if WP_CHAIN_LIGHT
  digits.s15 = rng_sobol23_digits(index.s1);
#endif
  const uint8 key = wp_hash8(seed ^ WP_BOUNCE_KEYS);
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
