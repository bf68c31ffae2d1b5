/* Stage: Russian roulette and compaction (integrator/roulette_compact.h), of the split pipeline.
 * From: WP_QUEUE_SURFACE (paths that sampled a next ray in sample_bsdf).
 * To:   queue_out, the next bounce's ray queue: the survivors, their bounce count moved on. */
#include "integrator/roulette_compact.h"

WP_GROUP_KERNEL void roulette_compact(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
  WP_GROUP_SCRATCH(scan);
  uint slot = 0u;
  bool survives = false;
  if (queue_get(queues, WP_QUEUE_SURFACE, get_global_id(0), &slot))
    survives = roulette(paths, queues, launch, slot,
                        rng_get(path_rng(paths, slot, launch), WP_DIM_ROULETTE));
  queue_push_group(queues, launch.queue_out, survives, slot, scan);
}
