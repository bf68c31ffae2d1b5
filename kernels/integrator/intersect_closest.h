/* Closest-hit intersection for one path: its ray (path_ray_*) against the BVH, the hit record
 * (path_hit_*) out, t = INFINITY for a miss. Entry point: intersect_closest.cl. */
#ifndef WP_INTEGRATOR_INTERSECT_CLOSEST_H
#define WP_INTEGRATOR_INTERSECT_CLOSEST_H

#include "stage.h"
#include "traverse.h"

/* The fields intersect_path reads and writes, for the cache hints of the slot ahead. */
static inline void intersect_prefetch(Paths paths, uint slot) {
  prefetch_path(paths, ray_o, slot);
  prefetch_path(paths, ray_d, slot);
  prefetch_path(paths, hit, slot);
}

WP_STAGE_FN void intersect_path(const SceneView* scene, Paths paths, Launch launch, uint slot) {
  const uint key = rng_bits(path_rng(paths, slot, launch), WP_DIM_ALPHA_CLOSEST);
  const TraceRay ray = trace_ray(path_ray_origin(paths, slot), path_ray_dir(paths, slot),
                                 path_ray_tmin(paths, slot), key);
  TraceHit hit;
  if (bvh_trace(scene, &ray, INFINITY, &hit, false)) {
    path_store_hit(paths, slot, hit.t, hit.u, hit.v, hit.tri);
    path_set_hit_instance(paths, slot, trace_hit_instance(&hit)); /* a no-op without instances */
  } else {
    path_store_hit(paths, slot, INFINITY, 0.0f, 0.0f, 0u);
  }
}

#endif /* WP_INTEGRATOR_INTERSECT_CLOSEST_H */
