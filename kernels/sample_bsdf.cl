/* Stage: BSDF sampling.
 * From: WP_QUEUE_SURFACE.
 * To:   the next ray of each path (ray_o/ray_d), throughput *= f cos / pdf, the sample's pdf in
 *       throughput.w (0 for a delta lobe) and WP_PATH_DELTA in info.z, kept for MIS at the next
 *       hit. A path with no valid direction gets throughput 0; roulette_compact ends it, as it
 *       does a path whose throughput or pdf would be NaN/Inf (counted, queues.h). A refraction
 *       into another medium multiplies the eta scale (radiance.w) by eta^2. */
/* Through a smooth thin-walled transmitter the pdf, the flags and the distance are carried on
 * (see below). */
#include "stage.h"
#include "surface.h"

/* The next ray of the path in `slot` from surface s with the bounce's random numbers u (its lobe
 * choice and direction). Shared by this stage and the fused shade.cl. */
WP_STAGE_FN void sample_next_ray(Paths paths, Queues queues, uint slot, const Surface* s,
                                 const BounceRandom* u) {
  const BsdfSample bs = bsdf_sample(s, -paths.ray_d[slot].xyz, u->lobe, u->bsdf_uv);
  const float4 beta = paths.throughput[slot];
  const float3 next = beta.xyz * bs.weight;
  const bool finite = all(isfinite(next)) && isfinite(bs.pdf);
  if (bs.valid && !finite) count_nonfinite(queues);
  if (!bs.valid || !finite) {
    paths.throughput[slot] = (float4)(0.0f);
    return;
  }
  paths.radiance[slot].w *= bs.eta_scale;
#if WP_FEATURE_TRANSMISSION
  /* Straight through a smooth thin-walled transmitter, which shadow rays pass too (trace_shadow):
   * the path goes on along the direction the previous vertex sampled, so it keeps that sample's
   * pdf and flags for MIS at the next hit, and counts the distance to that vertex (info.w) for the
   * light's pdf there. */
  if (bs.delta && !bsdf_volume(s) && dot(bs.wi, s->ng) < 0.0f) {
    paths.throughput[slot] = (float4)(next, beta.w);
    paths.info[slot].w = as_uint(as_float(paths.info[slot].w) + paths.hit[slot].x);
  } else
#endif
  {
    paths.throughput[slot] = (float4)(next, bs.pdf);
    paths.info[slot].z = bs.delta ? WP_PATH_DELTA : 0u;
    paths.info[slot].w = as_uint(0.0f);
  }
  /* Leave on the side the new direction goes to (below for transmission). */
  paths.ray_o[slot] =
      (float4)(surface_spawn(s, paths.ray_d[slot].xyz, paths.hit[slot].x, bs.wi), 0.0f);
  paths.ray_d[slot] = (float4)(bs.wi, INFINITY);
}

__kernel void sample_bsdf(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
  uint slot;
  if (!queue_get(queues, WP_QUEUE_SURFACE, get_global_id(0), &slot)) return;
  const Surface s = surface_load(paths, slot);
  BounceRandom u;
  bounce_random(path_rng(paths, slot, launch), &u);
  sample_next_ray(paths, queues, slot, &s, &u);
}
