/* Stage: hit resolution (integrator/shade_surface.h), of the split pipeline.
 * From: queue_in with the hit records of intersect_closest.
 * To:   misses and unlit surfaces end with their radiance added; hits add their emission, store
 *       the surface record (surface.h) and go to WP_QUEUE_SURFACE, unless the path has had
 *       max_depth scattering events already, in which case it ends here. */
#include "integrator/shade_surface.h"

WP_GROUP_KERNEL void shade_surface(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
  WP_GROUP_SCRATCH(scan);
  uint slot = 0u;
  bool scatters = false;
  if (queue_get(queues, launch.queue_in, get_global_id(0), &slot)) {
    Surface s;
    scatters = shade_hit(&scene, paths, launch, slot, &s);
    if (scatters) surface_store(paths, slot, &s);
  }
  queue_push_group(queues, WP_QUEUE_SURFACE, scatters, slot, scan);
}
