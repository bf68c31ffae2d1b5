/* What every wavefront stage kernel includes: the scene, the path state, the queues and the
 * randomness, and the one argument list all stage kernels share. */
#ifndef WP_STAGE_H
#define WP_STAGE_H

#include "common.h"
#include "rng.h"
#include "path_state.h"
#include "queues.h"
#include "scene.h"

/* The arguments every stage kernel takes, in this order (host/stages.h launches them typed). */
#define WP_STAGE_PARAMS                                                                          \
  WP_SCENE_PARAMS, __global uchar *path_buf, PathLayout path_layout, __global uint *queue_slots, \
      __global uint *queue_counters, Launch launch

/* Binds `scene`, `paths` and `queues` from WP_STAGE_PARAMS at the top of a kernel. */
#define WP_STAGE_BIND                                    \
  WP_SCENE_BIND(scene);                                  \
  const Paths paths = paths_bind(path_buf, path_layout); \
  const Queues queues = queues_bind(queue_slots, queue_counters, path_layout.capacity)

/* The sample index of the path in `slot`: a wave holds one or more samples of its pixels, one after
 * another (Launch.wave_pixels). */
static inline uint path_sample(Launch launch, uint slot) {
  return launch.sample + slot / launch.wave_pixels;
}

/* The random numbers of the path in `slot` at bounce `bounce`. */
static inline Rng path_rng_at(Paths paths, uint slot, Launch launch, uint bounce) {
  return rng_make(paths.info[slot].x, path_sample(launch, slot), launch.seed, bounce);
}

/* The random numbers of the path in `slot` at its current bounce. */
static inline Rng path_rng(Paths paths, uint slot, Launch launch) {
  return path_rng_at(paths, slot, launch, paths.info[slot].y);
}

#endif /* WP_STAGE_H */
