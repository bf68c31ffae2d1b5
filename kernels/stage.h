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
#define WP_STAGE_PARAMS                                                                  \
  __global const uchar *scene_buf, SceneDesc scene_desc, __global uchar *path_buf,       \
      PathLayout path_layout, __global uint *queue_slots, __global uint *queue_counters, \
      Launch launch

/* Binds `scene`, `paths` and `queues` from WP_STAGE_PARAMS at the top of a kernel. */
#define WP_STAGE_BIND                                         \
  const SceneView scene = scene_bind(scene_buf, &scene_desc); \
  const Paths paths = paths_bind(path_buf, path_layout);      \
  const Queues queues = queues_bind(queue_slots, queue_counters, path_layout.capacity)

#endif /* WP_STAGE_H */
