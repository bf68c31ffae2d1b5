/* Stage: film accumulation, once per sample pass and wave, after the last bounce.
 * From: every slot of the wave [0, path_count) (finished paths keep their slot).
 * To:   the film: two float4 per pixel, film[2 pixel] += (radiance, 1) and
 *       film[2 pixel + 1] += (radiance^2, 0), so the host has the mean and the sample variance of
 *       every pixel. A sample that is NaN or infinite is not added; it is counted in
 *       counters[WP_COUNTER_NONFINITE] (the renderer reports the count, the tests require 0). */
#include "stage.h"

__kernel void accumulate(WP_STAGE_PARAMS, __global float4* film) {
  WP_STAGE_BIND;
  const uint slot = get_global_id(0);
  if (slot >= launch.path_count) return;
  const float3 l = paths.radiance[slot].xyz;
  if (!all(isfinite(l))) {
    count_nonfinite(queues);
    return;
  }
  const uint pixel = paths.info[slot].x;
  film[2u * pixel] += (float4)(l, 1.0f);
  film[2u * pixel + 1u] += (float4)(l * l, 0.0f);
}
