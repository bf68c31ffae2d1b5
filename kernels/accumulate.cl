/* Stage: film accumulation (integrator/accumulate.h), once per sample pass and wave, after the
 * last bounce.
 * From: every slot of the wave [0, path_count) (finished paths keep their slot), one work-item per
 *       pixel of the wave.
 * To:   the film, in fixed point. Each pixel is in one work-item and waves run one after another,
 *       so the adds need no atomics. */
#include "integrator/accumulate.h"

__kernel void accumulate(WP_STAGE_PARAMS, __global ulong* film) {
  WP_STAGE_BIND;
  const uint first = get_global_id(0);
  if (first < launch.wave_pixels) accumulate_pixel(paths, queues, launch, film, first);
}
