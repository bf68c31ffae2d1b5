/* Stage: shadow rays (any hit).
 * From: WP_QUEUE_SHADOW (shadow_o/shadow_d, tmax in shadow_o.w, contribution in shadow_l).
 * To:   radiance += shadow_l for every unoccluded ray; the queue ends here. */
#include "stage.h"
#include "traverse.h"

__kernel void trace_shadow(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
  uint slot;
  if (!queue_get(queues, WP_QUEUE_SHADOW, get_global_id(0), &slot)) return;
  const float4 o = paths.shadow_o[slot];
  const uint key = rng_bits(path_rng(paths, slot, launch), WP_DIM_ALPHA_SHADOW);
  const TraceRay ray = trace_ray(o.xyz, paths.shadow_d[slot].xyz, 0.0f, key);
  TraceHit hit;
  if (!bvh_trace(&scene, &ray, o.w, &hit, true)) paths.radiance[slot] += paths.shadow_l[slot];
}
