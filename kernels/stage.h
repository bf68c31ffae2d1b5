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

/* The random numbers of the path in `slot` at its current bounce. */
static inline Rng path_rng(Paths paths, uint slot, Launch launch) {
  const uint4 info = paths.info[slot];
  return rng_make(info.x, launch.sample, launch.seed, info.y);
}

#endif /* WP_STAGE_H */
