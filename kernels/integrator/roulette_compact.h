/* Russian roulette for one path: from bounce rr_depth on, a path survives with probability
 * q = min(1, m / rr_threshold), m its largest throughput component times the eta scale, and its
 * throughput is divided by q (unbiased): a survivor of roulette carries rr_threshold. A path with
 * zero throughput ends. The bounce count moves on for every path, also one that ends here:
 * trace_shadow, which runs after, finds the bounce of its shadow ray one below it. Used by
 * roulette_compact.cl and the fused shade.cl, and in eight lanes by its packets (roulette8). */
#ifndef WP_INTEGRATOR_ROULETTE_COMPACT_H
#define WP_INTEGRATOR_ROULETTE_COMPACT_H

#include "stage.h"

/* Roulette for the path in `slot` with u, its WP_DIM_ROULETTE number: true for a survivor, which
 * the caller pushes to the next bounce's ray queue. */
WP_STAGE_FN bool roulette(Paths paths, Queues queues, Launch launch, uint slot, float u) {
  const uint bounce = path_bounce(paths, slot);
  path_set_bounce(paths, slot, bounce + 1u);
  const float3 beta = path_throughput(paths, slot);
  /* sample_bsdf catches these first; a NaN is never dropped silently */
  if (!all(isfinite(beta)) || !isfinite(path_bsdf_pdf(paths, slot))) {
    count_nonfinite(queues);
    return false;
  }
  if (!(max3(beta) > 0.0f)) return false;
  /* Survival looks at the throughput without the 1/eta^2 factors of refraction (pbrt-v4's
   * etaScale): inside glass they would otherwise end paths that are about to leave it, where
   * the factor is undone. */
  const float m = max3(beta) * path_eta_scale(paths, slot) / launch.rr_threshold;
  if (bounce + 1u >= launch.rr_depth && m < 1.0f) {
    if (u >= m) return false;
    path_set_throughput(paths, slot, beta / m);
  }
  return true;
}

#if WP_SHADE_PACKET
/* roulette of eight lanes (common.h, shade_packet.h), for paths at `bounce` (before the count
 * moves on) whose new throughput is beta (0 where the BSDF sample failed; never NaN or infinite,
 * which sample_next_ray8 has dropped and counted) and eta scale eta: the lanes that survive, and
 * in *kept the throughput each path keeps (divided by m where roulette played and it survived). */
WP_LANES_FN int8 roulette8(Launch launch, uint8 bounce, Float3x8 beta, float8 eta, float8 u,
                           Float3x8* kept) {
  const float8 b = max3x8(beta);
  const float8 m = b * eta / launch.rr_threshold;
  const int8 play = bounce + 1u >= (uint8)(launch.rr_depth) && m < 1.0f;
  const int8 lost = play && u >= m;
  *kept = select3x8(beta, div3x8(beta, m), play && !lost);
  return b > 0.0f && !lost;
}
#endif

#endif /* WP_INTEGRATOR_ROULETTE_COMPACT_H */
