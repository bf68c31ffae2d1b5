/* What every wavefront stage includes: the scene, the path state, the queues and the randomness,
 * the one argument list all stage kernels share, and the helpers the stages have in common. Each
 * stage's logic is in integrator/<stage>.h; kernels/<stage>.cl is its entry point. */
#ifndef WP_STAGE_H
#define WP_STAGE_H

#include "util/common.h"
#include "sampling/rng.h"
#include "path_state.h"
#include "queues.h"
#include "geom/scene.h"

/* The arguments every stage kernel takes, in this order (host/render/wavefront.cpp binds them). */
#define WP_STAGE_PARAMS                                                                          \
  WP_SCENE_PARAMS, __global uchar *path_buf, PathLayout path_layout, __global uint *queue_slots, \
      __global uint *queue_counters, Launch launch

/* Binds `scene`, `paths` and `queues` from WP_STAGE_PARAMS at the top of a kernel. */
#define WP_STAGE_BIND                                    \
  WP_SCENE_BIND(scene);                                  \
  const Paths paths = paths_bind(path_buf, path_layout); \
  const Queues queues = queues_bind(queue_slots, queue_counters, path_layout.capacity)

/* Hints the cache at `p` (WP_PREFETCH; a no-op elsewhere). Through an integer: a CPU device's
 * address spaces are all one. */
#if WP_PREFETCH
#define wp_prefetch(p) __builtin_prefetch((const void*)(size_t)(p), 0, 3)
#else
#define wp_prefetch(p) ((void)(p))
#endif

/* The slot WP_PREFETCH_AHEAD entries after `index` in queue q, for prefetching; false past the
 * queue's end, or without WP_PREFETCH. */
static inline bool prefetch_slot(Queues queues, uint q, uint index, uint* slot) {
  return WP_PREFETCH && queue_get(queues, q, index + WP_PREFETCH_AHEAD, slot);
}

/* Hints the cache at path-state field `field` of `slot` (a field of Paths, not a lane). */
#define prefetch_path(paths, field, slot) wp_prefetch((paths).field + (slot))

/* The sample index of the path in `slot`: a wave holds one or more samples of its pixels, one after
 * another (Launch.wave_pixels). */
static inline uint path_sample(Launch launch, uint slot) {
  return launch.sample + slot / launch.wave_pixels;
}

/* The pixel the path in `slot` renders (pixels numbered row by row from the top). */
static inline uint path_pixel(Launch launch, uint slot) {
  return launch.pixel_offset + slot % launch.wave_pixels;
}

/* The random numbers of the path in `slot` at bounce `bounce`. */
static inline Rng path_rng_at(uint slot, Launch launch, uint bounce) {
  return rng_make(path_pixel(launch, slot), path_sample(launch, slot), launch.seed, bounce);
}

/* The random numbers of the path in `slot` at its current bounce. */
static inline Rng path_rng(Paths paths, uint slot, Launch launch) {
  return path_rng_at(slot, launch, path_bounce(paths, slot));
}

/* The random numbers one scattering event draws (rng.h's per-bounce dimensions), all at once
 * (rng_bounce): the fused kernel draws them before it needs any, as independent chains the CPU
 * overlaps; drawn at their point of use, each one's latency holds up the work that needs it. */
typedef struct BounceRandom {
  float light_pick, lobe, roulette;
  float2 light_uv, bsdf_uv;
} BounceRandom;

/* Written through a pointer rather than returned: an always-inlined function returning a struct
 * leaves llvm.experimental.noalias.scope.decl behind, which Oclgrind cannot run. */
static inline __attribute__((always_inline)) void bounce_random(Rng r, BounceRandom* u) {
  const float8 v = rng_bounce(r);
  u->light_pick = v.s0;
  u->light_uv = (float2)(v.s1, v.s5);
  u->lobe = v.s2;
  u->bsdf_uv = (float2)(v.s3, v.s6);
  u->roulette = v.s4;
}

#endif /* WP_STAGE_H */
