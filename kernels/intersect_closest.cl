/* Stage: closest-hit intersection (integrator/intersect_closest.h).
 * From: queue_in, the rays to trace.
 * To:   each slot's hit record; no queue (shade or shade_surface reads queue_in next). */
#include "integrator/intersect_closest.h"

__kernel void intersect_closest(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
  uint slot, ahead;
  if (prefetch_slot(queues, launch.queue_in, get_global_id(0), &ahead))
    intersect_prefetch(paths, ahead);
  if (queue_get(queues, launch.queue_in, get_global_id(0), &slot))
    intersect_path(&scene, paths, launch, slot);
}
