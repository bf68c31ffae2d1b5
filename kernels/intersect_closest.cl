/* Stage: closest-hit intersection.
 * From: queue_in (rays in ray_o/ray_d, tmin in ray_o.w, tmax in ray_d.w).
 * To:   the hit record of each slot (t = INFINITY for a miss); no queue (shade_surface reads
 *       queue_in next). */
#include "stage.h"
#include "traverse.h"

__kernel void intersect_closest(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
  uint slot, ahead;
  if (prefetch_slot(queues, launch.queue_in, get_global_id(0), &ahead)) {
    wp_prefetch(paths.ray_o + ahead);
    wp_prefetch(paths.ray_d + ahead);
    wp_prefetch(paths.hit + ahead);
  }
  if (!queue_get(queues, launch.queue_in, get_global_id(0), &slot)) return;
  const float4 o = paths.ray_o[slot], d = paths.ray_d[slot];
  const uint key = rng_bits(path_rng(paths, slot, launch), WP_DIM_ALPHA_CLOSEST);
  const TraceRay ray = trace_ray(o.xyz, d.xyz, o.w, key);
  TraceHit hit;
  if (bvh_trace(&scene, &ray, d.w, &hit, false))
    paths.hit[slot] = (float4)(hit.t, hit.u, hit.v, as_float(hit.tri));
  else
    paths.hit[slot] = (float4)(INFINITY, 0.0f, 0.0f, 0.0f);
}
