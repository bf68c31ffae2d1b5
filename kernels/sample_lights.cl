/* Stage: next-event estimation (integrator/sample_lights.h), of the split pipeline.
 * From: WP_QUEUE_SURFACE.
 * To:   WP_QUEUE_SHADOW, the paths with a shadow ray toward a sampled light point; none under
 *       WP_STRATEGY_BSDF (Launch.strategy). */
#include "integrator/sample_lights.h"

WP_GROUP_KERNEL void sample_lights(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
  WP_GROUP_SCRATCH(scan);
  uint slot = 0u;
  bool shadow = false;
  if (launch.strategy != WP_STRATEGY_BSDF &&
      queue_get(queues, WP_QUEUE_SURFACE, get_global_id(0), &slot)) {
    const Surface s = surface_load(paths, slot);
    BounceRandom u;
    bounce_random(path_rng(paths, slot, launch), &u);
    const BsdfView v = bsdf_view(&s, -path_ray_dir(paths, slot));
    shadow = sample_light_ray(&scene, paths, queues, slot, &s, &v, path_hit_t(paths, slot), &u,
                              launch.strategy);
  }
  queue_push_group(queues, WP_QUEUE_SHADOW, shadow, slot, scan);
}
