/* Stage: film accumulation, once per sample pass and wave, after the last bounce.
 * From: every slot of the wave [0, path_count) (finished paths keep their slot).
 * To:   film[pixel] += radiance. A sample that is NaN or infinite is not added; it is counted in
 *       counters[WP_COUNTER_NONFINITE] (the renderer reports the count, the tests require 0). */
#include "stage.h"

__kernel void accumulate(WP_STAGE_PARAMS, __global float4* film) {
  WP_STAGE_BIND;
  const uint slot = get_global_id(0);
  if (slot >= launch.path_count) return;
  const float3 l = paths.radiance[slot].xyz;
  if (!all(isfinite(l))) {
    atomic_inc(&queues.counters[WP_COUNTER_NONFINITE]);
    return;
  }
  film[paths.info[slot].x] += (float4)(l, 1.0f);
}
