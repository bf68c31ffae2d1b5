/* Stage: Russian roulette and compaction.
 * From: WP_QUEUE_SURFACE (paths that sampled a next ray in sample_bsdf).
 * To:   queue_out, the next bounce's ray queue, holding the survivors with their bounce count
 *       incremented. From bounce rr_depth on, a path survives with probability
 *       q = min(1, max throughput component) and its throughput is divided by q (unbiased);
 *       a path with zero throughput ends. */
#include "stage.h"
#include "surface.h"

__kernel void roulette_compact(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
  uint slot;
  if (!queue_get(queues, WP_QUEUE_SURFACE, get_global_id(0), &slot)) return;
  float4 beta = paths.throughput[slot];
  const float m = max3(beta.xyz);
  if (!(m > 0.0f)) return;
  const uint bounce = paths.info[slot].y;
  if (bounce + 1u >= launch.rr_depth && m < 1.0f) {
    if (rng_get(path_rng(paths, slot, launch), WP_DIM_ROULETTE) >= m) return;
    paths.throughput[slot] = (float4)(beta.xyz / m, beta.w);
  }
  paths.info[slot].y = bounce + 1u;
  queue_push(queues, launch.queue_out, slot);
}
