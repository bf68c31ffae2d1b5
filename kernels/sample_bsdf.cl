/* Stage: BSDF sampling.
 * From: WP_QUEUE_SURFACE.
 * To:   the next ray of each path (ray_o/ray_d), throughput *= f cos / pdf, the sample's pdf in
 *       throughput.w (0 for a delta lobe) and WP_PATH_DELTA in info.z, kept for MIS at the next
 *       hit. A path with no valid direction gets throughput 0; roulette_compact ends it. */
#include "stage.h"
#include "surface.h"

__kernel void sample_bsdf(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
  uint slot;
  if (!queue_get(queues, WP_QUEUE_SURFACE, get_global_id(0), &slot)) return;
  const Surface s = surface_load(paths, slot);
  const Rng rng = path_rng(paths, slot, launch);
  const BsdfSample bs = bsdf_sample(&s, -paths.ray_d[slot].xyz, rng_get(rng, WP_DIM_BSDF_LOBE),
                                    rng_get2(rng, WP_DIM_BSDF_U));
  float4 beta = paths.throughput[slot];
  if (!bs.valid) {
    paths.throughput[slot] = (float4)(0.0f);
    return;
  }
  paths.throughput[slot] = (float4)(beta.xyz * bs.weight, bs.pdf);
  paths.info[slot].z = bs.delta ? WP_PATH_DELTA : 0u;
  /* Leave on the side the new direction goes to (below for transmission). */
  paths.ray_o[slot] =
      (float4)(surface_spawn(&s, paths.ray_d[slot].xyz, paths.hit[slot].x, bs.wi), 0.0f);
  paths.ray_d[slot] = (float4)(bs.wi, INFINITY);
}
