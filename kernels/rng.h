/* Stateless randomness: every random number is a hash of (pixel, sample, seed, bounce, dimension),
 * so an image does not depend on queue order, wave size, work-group size or device, and sample
 * ranges rendered apart merge exactly.
 *
 * The hash is applied in a chain, dimension first, then sample, then pixel, each step a full
 * 32-bit avalanche (a two-multiply integer mixer). Because the dimension enters first, two paths
 * whose (pixel, sample) collide at one dimension do not collide at the others: no two paths share
 * a whole random stream. Outputs are multiples of 2^-24 in [0, 1).
 */
#ifndef WP_RNG_H
#define WP_RNG_H

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

static inline float rng_get(Rng r, uint dim) {
  return (float)(rng_bits(r, dim) >> 8) * (1.0f / 16777216.0f);
}

static inline float2 rng_get2(Rng r, uint dim) {
  return (float2)(rng_get(r, dim), rng_get(r, dim + 1u));
}

#endif /* WP_RNG_H */
