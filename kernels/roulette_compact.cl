/* Stage: Russian roulette and compaction.
 * From: WP_QUEUE_SURFACE (paths that sampled a next ray in sample_bsdf).
 * To:   queue_out, the next bounce's ray queue, holding the survivors with their bounce count
 *       incremented. From bounce rr_depth on, a path survives with probability
 *       q = min(1, m / rr_threshold), m its largest throughput component times the eta scale, and
 *       its throughput is divided by q (unbiased): a survivor of roulette carries rr_threshold;
 *       a path with zero throughput ends. */
#include "stage.h"
#include "surface.h"

/* Roulette for the path in `slot` with u, its WP_DIM_ROULETTE number: true for a survivor, which
 * the caller pushes to queue_out. Shared by this stage and the fused shade.cl. */
WP_STAGE_FN bool roulette(Paths paths, Queues queues, Launch launch, uint slot, float u) {
  const float4 beta = paths.throughput[slot];
  if (!all(isfinite(beta))) { /* sample_bsdf catches these first; a NaN is never dropped silently */
    count_nonfinite(queues);
    return false;
  }
  if (!(max3(beta.xyz) > 0.0f)) return false;
  /* Survival looks at the throughput without the 1/eta^2 factors of refraction (pbrt-v4's
   * etaScale): inside glass they would otherwise end paths that are about to leave it, where
   * the factor is undone. */
  const float m = max3(beta.xyz) * paths.radiance[slot].w / launch.rr_threshold;
  const uint bounce = paths.info[slot].y;
  if (bounce + 1u >= launch.rr_depth && m < 1.0f) {
    if (u >= m) return false;
    paths.throughput[slot] = (float4)(beta.xyz / m, beta.w);
  }
  paths.info[slot].y = bounce + 1u;
  return true;
}

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
