/* Stage: BSDF sampling (integrator/sample_bsdf.h), of the split pipeline.
 * From: WP_QUEUE_SURFACE.
 * To:   each path's next ray, throughput and MIS state; no queue (roulette_compact reads
 *       WP_QUEUE_SURFACE next). */
#include "integrator/sample_bsdf.h"

__kernel void sample_bsdf(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
  uint slot;
  if (!queue_get(queues, WP_QUEUE_SURFACE, get_global_id(0), &slot)) return;
  const Surface s = surface_load(paths, slot);
  BounceRandom u;
  bounce_random(path_rng(paths, slot, launch), &u);
  const BsdfView v = bsdf_view(&s, -path_ray_dir(paths, slot));
  sample_next_ray(paths, queues, slot, &s, &v, path_hit_t(paths, slot), &u);
}
