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
 * The light and BSDF pairs are chained instead, two bounces to one order (rng_pair_source): the
 * BSDF order of an even bounce carries eight dimensions, that bounce's direction, the next
 * bounce's direction and the light points of the next two bounces, and the light point at bounce 0
 * takes dimensions 2, 3 of the pixel jitter's order (and a thin lens's point 4, 5). Each light
 * point is then stratified together with the direction of the ray that found its surface, and each
 * odd bounce's direction with the one before it, at the cost of pairs that alone stratify a little
 * less (dimensions 2-7 have t-values up to 3 where dimensions 0, 1 have 0: each elementary interval
 * of area 2^(t-k) holds 2^t of 2^k samples). Less error for the same samples than the padded
 * pattern, measured in docs/light-transport.md, "Chained sample pairs".
 *
 * Sobol, padded (WP_SAMPLER_SOBOL_PADDED): the same points, every pair in an order of its own
 * (the default pattern until 2026-11-25).
 *
 * Every point is uniformly distributed over the scrambles, so estimates stay unbiased.
 *
 * Outputs are odd multiples of 2^-24 in (0, 1) (rng_float). The alpha keys (rng_bits) are hashes in
 * both patterns. rng_bounce draws all the numbers of one bounce at once, the same numbers as
 * rng_get and rng_get2.
 */
#ifndef WP_RNG_H
#define WP_RNG_H

#include "util/common.h"
#include "util/features.h"

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
#define WP_DIM_LENS_U 11u       /* the thin lens's (u, v), bounce 0 only (camera.h) */
#define WP_DIM_LENS_V 12u
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

/* Pairs chained over two bounces (WP_SAMPLER_SOBOL, rng_pair_source) or each in an order of its
 * own (WP_SAMPLER_SOBOL_PADDED). */
#define WP_CHAIN_PAIRS (WP_SAMPLER == WP_SAMPLER_SOBOL)

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

/* Sobol' dimensions 2-7 as three pairs (Joe and Kuo's direction numbers, new-joe-kuo-6.21201:
 * primitive polynomials x^2 + x + 1, x^3 + x + 1, x^3 + x^2 + 1, x^4 + x + 1, x^4 + x^3 + 1 and
 * x^5 + x^2 + 1 with m = (1, 3), (1, 3, 1), (1, 1, 1), (1, 1, 3, 3), (1, 3, 5, 13) and
 * (1, 1, 5, 5, 17)), digits reversed as rng_taylor_shift gives the second dimension's: entry
 * [p - 1][n][2 v + c] is dimension 2 p + c's reversed digits of the index v << 4n, the xor of the
 * reversed direction numbers of v's bits, so the digits of any index are the xor of one entry per
 * nibble (the generator matrices are linear over GF(2)). Checked against the direction-number
 * recurrence by Rng.HigherSobolDimensionsMatchTheRecurrence. */
__constant uint wp_sobol_pairs[3][8][32] = {
    {{0x00000000u, 0x00000000u, 0x00000001u, 0x00000001u, 0x00000003u, 0x00000003u, 0x00000002u,
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
      0xe4e400e8u, 0xa200d00du, 0xf2f200ffu, 0xbd00c00cu}},
    {{0x00000000u, 0x00000000u, 0x00000001u, 0x00000001u, 0x00000002u, 0x00000002u, 0x00000003u,
      0x00000003u, 0x00000004u, 0x00000006u, 0x00000005u, 0x00000007u, 0x00000006u, 0x00000004u,
      0x00000007u, 0x00000005u, 0x0000000du, 0x0000000cu, 0x0000000cu, 0x0000000du, 0x0000000fu,
      0x0000000eu, 0x0000000eu, 0x0000000fu, 0x00000009u, 0x0000000au, 0x00000008u, 0x0000000bu,
      0x0000000bu, 0x00000008u, 0x0000000au, 0x00000009u},
     {0x00000000u, 0x00000000u, 0x0000001fu, 0x00000013u, 0x0000003bu, 0x00000024u, 0x00000024u,
      0x00000037u, 0x0000005eu, 0x0000006au, 0x00000041u, 0x00000079u, 0x00000065u, 0x0000004eu,
      0x0000007au, 0x0000005du, 0x000000b9u, 0x000000dfu, 0x000000a6u, 0x000000ccu, 0x00000082u,
      0x000000fbu, 0x0000009du, 0x000000e8u, 0x000000e7u, 0x000000b5u, 0x000000f8u, 0x000000a6u,
      0x000000dcu, 0x00000091u, 0x000000c3u, 0x00000082u},
     {0x00000000u, 0x00000000u, 0x0000015au, 0x00000107u, 0x000003f4u, 0x0000020eu, 0x000002aeu,
      0x00000309u, 0x00000685u, 0x00000615u, 0x000007dfu, 0x00000712u, 0x00000571u, 0x0000041bu,
      0x0000042bu, 0x0000051cu, 0x00000d0fu, 0x00000c28u, 0x00000c55u, 0x00000d2fu, 0x00000efbu,
      0x00000e26u, 0x00000fa1u, 0x00000f21u, 0x00000b8au, 0x00000a3du, 0x00000ad0u, 0x00000b3au,
      0x0000087eu, 0x00000833u, 0x00000924u, 0x00000934u},
     {0x00000000u, 0x00000000u, 0x0000115bu, 0x00001379u, 0x000023f6u, 0x000024fbu, 0x000032adu,
      0x00003782u, 0x00004681u, 0x00006b6du, 0x000057dau, 0x00007814u, 0x00006577u, 0x00004f96u,
      0x0000742cu, 0x00005cefu, 0x0000dd02u, 0x0000ddd1u, 0x0000cc59u, 0x0000cea8u, 0x0000fef4u,
      0x0000f92au, 0x0000efafu, 0x0000ea53u, 0x00009b83u, 0x0000b6bcu, 0x00008ad8u, 0x0000a5c5u,
      0x0000b875u, 0x00009247u, 0x0000a92eu, 0x0000813eu},
     {0x00000000u, 0x00000000u, 0x0001e144u, 0x00010012u, 0x000393cdu, 0x00020026u, 0x00027289u,
      0x00030034u, 0x0005a6dfu, 0x0006006cu, 0x0004479bu, 0x0007007eu, 0x00063512u, 0x0004004au,
      0x0007d456u, 0x00050058u, 0x000b4dbbu, 0x000c00d3u, 0x000aacffu, 0x000d00c1u, 0x0008de76u,
      0x000e00f5u, 0x00093f32u, 0x000f00e7u, 0x000eeb64u, 0x000a00bfu, 0x000f0a20u, 0x000b00adu,
      0x000d78a9u, 0x00080099u, 0x000c99edu, 0x0009008bu},
     {0x00000000u, 0x00000000u, 0x0014401eu, 0x00130114u, 0x003cd039u, 0x0024022au, 0x00289027u,
      0x0037033eu, 0x006df05au, 0x006a067fu, 0x0079b044u, 0x0079076bu, 0x00512063u, 0x004e0455u,
      0x0045607du, 0x005d0541u, 0x00dbb0b4u, 0x00df0cf7u, 0x00cff0aau, 0x00cc0de3u, 0x00e7608du,
      0x00fb0eddu, 0x00f32093u, 0x00e80fc9u, 0x00b640eeu, 0x00b50a88u, 0x00a200f0u, 0x00a60b9cu,
      0x008a90d7u, 0x009108a2u, 0x009ed0c9u, 0x008209b6u},
     {0x00000000u, 0x00000000u, 0x0101e145u, 0x0107127eu, 0x020393cfu, 0x020e26f5u, 0x0302728au,
      0x0309348bu, 0x0405a6dbu, 0x06156d78u, 0x0504479eu, 0x07127f06u, 0x06063514u, 0x041b4b8du,
      0x0707d451u, 0x051c59f3u, 0x0d0b4db6u, 0x0c28d1f9u, 0x0c0aacf3u, 0x0d2fc387u, 0x0f08de79u,
      0x0e26f70cu, 0x0e093f3cu, 0x0f21e572u, 0x090eeb6du, 0x0a3dbc81u, 0x080f0a28u, 0x0b3aaeffu,
      0x0b0d78a2u, 0x08339a74u, 0x0a0c99e7u, 0x0934880au},
     {0x00000000u, 0x00000000u, 0x1f144001u, 0x1378136bu, 0x3b3cd002u, 0x24f924ddu, 0x24289003u,
      0x378137b6u, 0x5e6df004u, 0x6b6b6b01u, 0x4179b005u, 0x7813786au, 0x65512006u, 0x4f924fdcu,
      0x7a456007u, 0x5cea5cb7u, 0xb9dbb00du, 0xdddddd02u, 0xa6cff00cu, 0xcea5ce69u, 0x82e7600fu,
      0xf924f9dfu, 0x9df3200eu, 0xea5ceab4u, 0xe7b64009u, 0xb6b6b603u, 0xf8a20008u, 0xa5cea568u,
      0xdc8a900bu, 0x924f92deu, 0xc39ed00au, 0x813781b5u}},
    {{0x00000000u, 0x00000000u, 0x00000001u, 0x00000001u, 0x00000003u, 0x00000002u, 0x00000002u,
      0x00000003u, 0x00000005u, 0x00000005u, 0x00000004u, 0x00000004u, 0x00000006u, 0x00000007u,
      0x00000007u, 0x00000006u, 0x0000000bu, 0x0000000au, 0x0000000au, 0x0000000bu, 0x00000008u,
      0x00000008u, 0x00000009u, 0x00000009u, 0x0000000eu, 0x0000000fu, 0x0000000fu, 0x0000000eu,
      0x0000000du, 0x0000000du, 0x0000000cu, 0x0000000cu},
     {0x00000000u, 0x00000000u, 0x0000001au, 0x00000011u, 0x00000029u, 0x00000024u, 0x00000033u,
      0x00000035u, 0x0000007cu, 0x00000048u, 0x00000066u, 0x00000059u, 0x00000055u, 0x0000006cu,
      0x0000004fu, 0x0000007du, 0x000000c7u, 0x000000b4u, 0x000000ddu, 0x000000a5u, 0x000000eeu,
      0x00000090u, 0x000000f4u, 0x00000081u, 0x000000bbu, 0x000000fcu, 0x000000a1u, 0x000000edu,
      0x00000092u, 0x000000d8u, 0x00000088u, 0x000000c9u},
     {0x00000000u, 0x00000000u, 0x0000017du, 0x0000016eu, 0x000003c4u, 0x00000279u, 0x000002b9u,
      0x00000317u, 0x00000478u, 0x00000410u, 0x00000505u, 0x0000057eu, 0x000007bcu, 0x00000669u,
      0x000006c1u, 0x00000707u, 0x000008cfu, 0x00000826u, 0x000009b2u, 0x00000948u, 0x00000b0bu,
      0x00000a5fu, 0x00000a76u, 0x00000b31u, 0x00000cb7u, 0x00000c36u, 0x00000dcau, 0x00000d58u,
      0x00000f73u, 0x00000e4fu, 0x00000e0eu, 0x00000f21u},
     {0x00000000u, 0x00000000u, 0x00001e62u, 0x0000144du, 0x000021e6u, 0x000028beu, 0x00003f84u,
      0x00003cf3u, 0x0000621eu, 0x0000457fu, 0x00007c7cu, 0x00005132u, 0x000043f8u, 0x00006dc1u,
      0x00005d9au, 0x0000798cu, 0x0000e621u, 0x0000925du, 0x0000f843u, 0x00008610u, 0x0000c7c7u,
      0x0000bae3u, 0x0000d9a5u, 0x0000aeaeu, 0x0000843fu, 0x0000d722u, 0x00009a5du, 0x0000c36fu,
      0x0000a5d9u, 0x0000ff9cu, 0x0000bbbbu, 0x0000ebd1u},
     {0x00000000u, 0x00000000u, 0x00011e63u, 0x00012458u, 0x000321e5u, 0x0002d892u, 0x00023f86u,
      0x0003fccau, 0x0005621bu, 0x0005ad23u, 0x00047c78u, 0x0004897bu, 0x000643feu, 0x000775b1u,
      0x00075d9du, 0x000651e9u, 0x000be62au, 0x0009cec7u, 0x000af849u, 0x0008ea9fu, 0x0008c7cfu,
      0x000b1655u, 0x0009d9acu, 0x000a320du, 0x000e8431u, 0x000c63e4u, 0x000f9a52u, 0x000d47bcu,
      0x000da5d4u, 0x000ebb76u, 0x000cbbb7u, 0x000f9f2eu},
     {0x00000000u, 0x00000000u, 0x001b1e79u, 0x0010016fu, 0x002a21ccu, 0x0020027bu, 0x00313fb5u,
      0x00300314u, 0x00796267u, 0x00500415u, 0x00627c1eu, 0x0040057au, 0x005343abu, 0x0070066eu,
      0x00485dd2u, 0x00600701u, 0x00cce6edu, 0x00a0082cu, 0x00d7f894u, 0x00b00943u, 0x00e6c721u,
      0x00800a57u, 0x00fdd958u, 0x00900b38u, 0x00b5848au, 0x00f00c39u, 0x00ae9af3u, 0x00e00d56u,
      0x009fa546u, 0x00d00e42u, 0x0084bb3fu, 0x00c00f2du},
     {0x00000000u, 0x00000000u, 0x01661f04u, 0x0110145cu, 0x03ee2208u, 0x0240289au, 0x02883d0cu,
      0x03503cc6u, 0x0401661fu, 0x04804537u, 0x0567791bu, 0x0590516bu, 0x07ef4417u, 0x06c06dadu,
      0x06895b13u, 0x07d079f1u, 0x0803ee22u, 0x0b4092e9u, 0x0965f126u, 0x0a5086b5u, 0x0bedcc2au,
      0x0900ba73u, 0x0a8bd32eu, 0x0810ae2fu, 0x0c02883du, 0x0fc0d7deu, 0x0d649739u, 0x0ed0c382u,
      0x0fecaa35u, 0x0d80ff44u, 0x0e8ab531u, 0x0c90eb18u},
     {0x00000000u, 0x00000000u, 0x1f040166u, 0x16e12536u, 0x220803eeu, 0x2792daebu, 0x3d0c0288u,
      0x3173ffddu, 0x661f0401u, 0x4105a933u, 0x791b0567u, 0x57e48c05u, 0x441707efu, 0x669773d8u,
      0x5b130689u, 0x707656eeu, 0xee220803u, 0x8269c6e1u, 0xf1260965u, 0x9488e3d7u, 0xcc2a0bedu,
      0xa5fb1c0au, 0xd32e0a8bu, 0xb31a393cu, 0x883d0c02u, 0xc36c6fd2u, 0x97390d64u, 0xd58d4ae4u,
      0xaa350fecu, 0xe4feb539u, 0xb5310e8au, 0xf21f900fu}}};

/* The reversed digits of Sobol' dimensions 2 p and 2 p + 1 (p = 1, 2, 3) of index. */
static inline uint2 rng_sobol_pair_digits(uint index, uint p) {
  uint2 d = (uint2)(0u);
  for (uint n = 0u; n < 8u; ++n) d ^= vload2((index >> (4u * n)) & 15u, wp_sobol_pairs[p - 1u][n]);
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

/* Where a pair of numbers comes from: the group (as rng_group_seed numbers it) whose scrambled
 * sample order it takes, and which of that order's Sobol' pairs (0: dimensions 0 and 1, p:
 * dimensions 2 p and 2 p + 1). */
typedef struct PairSource {
  uint group, pair;
} PairSource;

/* Chained (WP_CHAIN_PAIRS): the light and BSDF pairs of two bounces share one sample order, eight
 * dimensions, so the numbers of successive scattering events are stratified together instead of
 * paired at random. The BSDF order of an even bounce k carries the BSDF direction at k (dimensions
 * 0, 1), the BSDF direction at k + 1 (2, 3), the light point at k + 1 (4, 5) and the light point
 * at k + 2 (6, 7); the light point at bounce 0 takes dimensions 2, 3 of the pixel jitter's order,
 * and the lens point (a camera with an aperture) dimensions 4, 5, so the pixel, lens and first
 * light points are stratified together. So each light point shares an order with the direction of
 * the ray that found its surface, and each odd bounce's direction with the even one's before it. A
 * group k bounces back is the current one less k * WP_DIMS_PER_BOUNCE, through unsigned
 * wrap-around. Padded: every pair in an order of its own. */
static inline PairSource rng_pair_source(Rng r, uint dim) {
  PairSource s = {dim, 0u};
#if WP_CHAIN_PAIRS
  const bool odd = (r.bounce & 1u) != 0u;
  if (dim == WP_DIM_LENS_U) {
    s.group = WP_DIM_PIXEL_X, s.pair = 2u;
  } else if (dim == WP_DIM_LIGHT_U) {
    if (r.bounce == 0u) {
      s.group = WP_DIM_PIXEL_X, s.pair = 1u;
    } else {
      s.group = WP_DIM_BSDF_U - (odd ? 1u : 2u) * WP_DIMS_PER_BOUNCE, s.pair = odd ? 2u : 3u;
    }
  } else if (dim == WP_DIM_BSDF_U && odd) {
    s.group = WP_DIM_BSDF_U - WP_DIMS_PER_BOUNCE, s.pair = 1u;
  }
#else
  (void)r;
#endif
  return s;
}

/* The scramble keys of a pair's two dimensions: its order's pair p gets the first pair's keys
 * moved by p steps, so no two dimensions of one order share a scramble. */
#define WP_PAIR_KEY_STEP 0x9e3779b9u

/* One-dimensional: the scrambled van der Corput point of this group's shuffled sample index.
 * rng_get and rng_get2 are always inlined: clang kept them out of line in the fused shade kernel,
 * where the calls cost a large share of a render on PoCL (docs/performance.md, "Random numbers
 * inlined"). */
static inline __attribute__((always_inline)) float rng_sobol_get(Rng r, uint dim) {
  const uint seed = rng_group_seed(r, dim);
  const uint index = rng_owen(r.sample, seed);
  return rng_float(rng_van_der_corput(index, seed));
}

/* Two-dimensional group (dim, dim + 1): the scrambled point of a pair of Sobol' dimensions
 * (rng_pair_source) -- for the first two, the first (van der Corput) and the second (its digits
 * from rng_taylor_shift) -- in the two lanes of a uint2, each with its own key, as rng_bounce does
 * eight at a time: the two chains run side by side in one vector register. */
static inline __attribute__((always_inline)) float2 rng_sobol_get2(Rng r, uint dim) {
  const PairSource src = rng_pair_source(r, dim);
  const uint seed = rng_group_seed(r, src.group);
  const uint index = rng_owen(r.sample, seed);
  const uint2 digits = src.pair == 0u ? (uint2)(index, rng_taylor_shift(index))
                                      : rng_sobol_pair_digits(index, src.pair);
  const uint2 key =
      wp_hash2(seed ^ ((uint2)(WP_KEY_FIRST, WP_KEY_SECOND) + src.pair * WP_PAIR_KEY_STEP));
  const uint2 bits = rng_reverse_bits2(rng_nested_permute2(digits, key));
  return (float2)(rng_float(bits.x), rng_float(bits.y));
}

/* All of a bounce's numbers (lanes: WP_BOUNCE_GROUPS), each exactly what rng_get or rng_get2 gives
 * (tested by Rng.BounceDrawEqualsTheOneByOneDraws), computed eight at a time: a CPU runs the lanes
 * in one SIMD register, a quarter of the instructions of seven scalar draws, with the depth of
 * one, so the shading kernel can draw them ahead of the work that needs them (shade.cl). */
static inline __attribute__((always_inline)) float8 rng_sobol_bounce(Rng r) {
  const PairSource light = rng_pair_source(r, WP_DIM_LIGHT_U);
  const PairSource bsdf = rng_pair_source(r, WP_DIM_BSDF_U);
  uint8 group = WP_BOUNCE_GROUPS, pair = (uint8)(0u);
  group.s15 = (uint2)(light.group), pair.s15 = (uint2)(light.pair);
  group.s367 = (uint3)(bsdf.group), pair.s367 = (uint3)(bsdf.pair);
  const uint8 seed = rng_group_seed8(r, group);
  const uint8 index = rng_owen8((uint8)(r.sample), seed);
  const uint8 second = as_uint8(WP_BOUNCE_SECOND);
  uint8 digits = bitselect(index, rng_taylor_shift8(index), second);
  if (light.pair != 0u) digits.s15 = rng_sobol_pair_digits(index.s1, light.pair);
  if (bsdf.pair != 0u) {
    const uint2 d = rng_sobol_pair_digits(index.s3, bsdf.pair);
    digits.s367 = (uint3)(d.x, d.y, d.y);
  }
  const uint8 key =
      wp_hash8(seed ^ (bitselect((uint8)(WP_KEY_FIRST), (uint8)(WP_KEY_SECOND), second) +
                       pair * WP_PAIR_KEY_STEP));
  return rng_float8(rng_reverse_bits8(rng_nested_permute8(digits, key)));
}

#if WP_SHADE_PACKET
/* A bounce's numbers for eight paths (shade_packet.h), lanes being paths: pixel, sample and
 * bounce per lane, seed the render's. What rng_bounce gives path i in its lane j is here lane i
 * of the number for use j -- the same bits, integer arithmetic throughout -- for the uses the
 * shading has: the light pick (u[0]), the light point (u[1], u[2]), the BSDF direction (u[3],
 * u[4]), roulette (u[5]) and the lobe choice (u[6]). */
typedef struct RngLanes {
  uint8 pixel, sample, bounce;
  uint seed;
} RngLanes;

/* rng_group_seed of group `group` in every lane. */
WP_LANES_FN uint8 rng_group_seed_lanes(RngLanes r, uint8 group) {
  return wp_hash8(wp_hash8(r.bounce * WP_DIMS_PER_BOUNCE + group + wp_hash(r.seed)) ^ r.pixel);
}

/* rng_sobol_pair_digits of eight indices, the same pair p in every lane: the generator matrices'
 * columns (the entries of one-bit nibbles) xored in where the index has their bit, in the lanes. */
WP_LANES_FN void rng_sobol_pair_digits8(uint8 index, uint p, uint8* x, uint8* y) {
  __constant const uint(*t)[32] = wp_sobol_pairs[p - 1u];
  uint8 dx = (uint8)(0u), dy = (uint8)(0u);
#pragma unroll
  for (int j = 0; j < 32; ++j) {
    const uint8 has = as_uint8(as_int8(index << (uint)(31 - j)) >> 31);
    dx ^= has & t[j >> 2][2 << (j & 3)];
    dy ^= has & t[j >> 2][(2 << (j & 3)) + 1];
  }
  *x = dx, *y = dy;
}

/* A group's sample order in every lane: its scramble seed and its shuffled sample index. */
typedef struct RngOrderLanes {
  uint8 seed, index;
} RngOrderLanes;

WP_LANES_FN RngOrderLanes rng_order_lanes(RngLanes r, uint8 group) {
  const uint8 seed = rng_group_seed_lanes(r, group);
  const RngOrderLanes o = {seed, rng_owen8(r.sample, seed)};
  return o;
}

/* A pair of numbers (rng_get2's) of the order o, its pair `pair` in each lane; with one_d only
 * the first (rng_get's for a one-dimensional group of pair 0). */
WP_LANES_FN void rng_pair_lanes(RngOrderLanes o, uint8 pair, bool one_d, float8* u, float8* v) {
  const uint8 seed = o.seed, index = o.index;
  uint8 dx = index, dy = rng_taylor_shift8(index);
  for (uint q = 1u; q <= 3u; ++q) {
    const int8 in = pair == q;
    if (!any8(in)) continue;
    uint8 x, y;
    rng_sobol_pair_digits8(index, q, &x, &y);
    dx = select(dx, x, as_uint8(in)), dy = select(dy, y, as_uint8(in));
  }
  *u = rng_float8(rng_reverse_bits8(
      rng_nested_permute8(dx, wp_hash8(seed ^ (WP_KEY_FIRST + pair * WP_PAIR_KEY_STEP)))));
  if (!one_d)
    *v = rng_float8(rng_reverse_bits8(
        rng_nested_permute8(dy, wp_hash8(seed ^ (WP_KEY_SECOND + pair * WP_PAIR_KEY_STEP)))));
}

/* Without `pick`, `roulette` or `lobe` those numbers are left out (0.5 in their place), for
 * shading that does not read them: light picks that reuse the light point's number, no path at the
 * roulette's depth, a Lambertian BSDF. */
WP_LANES_FN void rng_bounce_lanes(RngLanes r, float8* u, bool pick, bool roulette, bool lobe) {
  float8 unused;
  const uint8 zero = (uint8)(0u);
  u[0] = u[5] = u[6] = (float8)(0.5f);
  if (pick)
    rng_pair_lanes(rng_order_lanes(r, (uint8)(WP_DIM_LIGHT_PICK)), zero, true, &u[0], &unused);
  if (lobe)
    rng_pair_lanes(rng_order_lanes(r, (uint8)(WP_DIM_BSDF_LOBE)), zero, true, &u[6], &unused);
  if (roulette)
    rng_pair_lanes(rng_order_lanes(r, (uint8)(WP_DIM_ROULETTE)), zero, true, &u[5], &unused);
  /* rng_pair_source, lane by lane */
  uint8 light_group = (uint8)(WP_DIM_LIGHT_U), light_pair = zero;
  uint8 bsdf_group = (uint8)(WP_DIM_BSDF_U), bsdf_pair = zero;
#if WP_CHAIN_PAIRS
  const int8 odd = (r.bounce & 1u) != 0u, first = r.bounce == 0u;
  light_group = select(select((uint8)(WP_DIM_BSDF_U - 2u * WP_DIMS_PER_BOUNCE),
                              (uint8)(WP_DIM_BSDF_U - WP_DIMS_PER_BOUNCE), as_uint8(odd)),
                       (uint8)(WP_DIM_PIXEL_X), as_uint8(first));
  light_pair =
      select(select((uint8)(3u), (uint8)(2u), as_uint8(odd)), (uint8)(1u), as_uint8(first));
  bsdf_group = select(bsdf_group, (uint8)(WP_DIM_BSDF_U - WP_DIMS_PER_BOUNCE), as_uint8(odd));
  bsdf_pair = select(zero, (uint8)(1u), as_uint8(odd));
#endif
  /* At odd bounces both pairs take the order of the BSDF direction one bounce back. */
  const RngOrderLanes light = rng_order_lanes(r, light_group);
  const RngOrderLanes bsdf =
      all8(bsdf_group == light_group) ? light : rng_order_lanes(r, bsdf_group);
  rng_pair_lanes(light, light_pair, false, &u[1], &u[2]);
  rng_pair_lanes(bsdf, bsdf_pair, false, &u[3], &u[4]);
}
#endif

#else

static inline __attribute__((always_inline)) float rng_independent_get(Rng r, uint dim) {
  return rng_float(rng_bits(r, dim));
}

/* As rng_sobol_bounce; here a pair's second number is the next dimension's (rng_get2). */
static inline __attribute__((always_inline)) float8 rng_independent_bounce(Rng r) {
  const uint8 dim = WP_BOUNCE_GROUPS - as_uint8(WP_BOUNCE_SECOND); /* -(-1): the pair's next */
  return rng_float8(rng_bits8(r, dim));
}

static inline __attribute__((always_inline)) float2 rng_independent_get2(Rng r, uint dim) {
  return (float2)(rng_independent_get(r, dim), rng_independent_get(r, dim + 1u));
}

#endif

/* The numbers of the sample pattern the program is built for (WP_SAMPLER): one (rng_get), a pair
 * of a two-dimensional group (rng_get2), all of a bounce's (rng_bounce, lanes WP_BOUNCE_GROUPS). */
static inline __attribute__((always_inline)) float rng_get(Rng r, uint dim) {
#if WP_SAMPLER != WP_SAMPLER_INDEPENDENT
  return rng_sobol_get(r, dim);
#else
  return rng_independent_get(r, dim);
#endif
}
static inline __attribute__((always_inline)) float2 rng_get2(Rng r, uint dim) {
#if WP_SAMPLER != WP_SAMPLER_INDEPENDENT
  return rng_sobol_get2(r, dim);
#else
  return rng_independent_get2(r, dim);
#endif
}
static inline __attribute__((always_inline)) float8 rng_bounce(Rng r) {
#if WP_SAMPLER != WP_SAMPLER_INDEPENDENT
  return rng_sobol_bounce(r);
#else
  return rng_independent_bounce(r);
#endif
}

#endif /* WP_RNG_H */
