/* Stage: next-event estimation (light sampling).
 * From: WP_QUEUE_SURFACE.
 * To:   WP_QUEUE_SHADOW with a shadow ray toward one sampled light point and the radiance it adds
 *       if unoccluded: throughput * f * |cos| * L / pdf * w_light (lights.h, mis.h).
 * Skipped entirely with WP_STRATEGY_BSDF, and on surfaces with nothing but delta lobes. */
#include "stage.h"
#include "lights.h"
#include "mis.h"
#include "surface.h"

#if WP_STRATEGY != WP_STRATEGY_BSDF
/* NEE at surface s of the path in `slot` with the bounce's random numbers u (its light pick and
 * light point): a shadow ray for WP_QUEUE_SHADOW, true when there is one (the caller pushes it).
 * Shared by this stage and the fused shade.cl. */
WP_STAGE_FN bool sample_light_ray(const SceneView* scene, Paths paths, Queues queues, uint slot,
                                  const Surface* s, const BounceRandom* u) {
  if (scene->desc->light_count == 0 || bsdf_only_delta(s)) return false;
  const LightSample ls = sample_light(scene, s->p, u->light_pick, u->light_uv);
  if (!(ls.pdf > 0.0f)) return false;
  const BsdfEval e = bsdf_eval(s, -paths.ray_d[slot].xyz, ls.wi);
  const float w = mis_weight_light(ls.pdf, e.pdf, ls.delta);
  const float3 c =
      paths.throughput[slot].xyz * e.f * ls.li * (fabs(dot(s->ns, ls.wi)) * w / ls.pdf);
  if (!all(isfinite(c))) {
    count_nonfinite(queues);
    return false;
  }
  if (!(max3(c) > 0.0f)) return false;
  /* The shadow ray leaves the side of the surface the light is on (transmission can light the
   * back) and, for a light at a finite distance, runs from the moved origin to the light's target
   * point (itself moved off an area light's surface): neither end can hit the surface it is on. */
  const float3 o = surface_spawn(s, paths.ray_d[slot].xyz, paths.hit[slot].x, ls.wi);
  float3 dir = ls.wi;
  float tmax = INFINITY;
  if (ls.dist < INFINITY) {
    const float3 to = ls.target - o;
    tmax = length(to);
    dir = to / tmax;
  }
  paths.shadow_o[slot] = (float4)(o, tmax);
  /* w: the bounce, for the shadow ray's random numbers (trace_shadow runs after the path's bounce
   * count may have moved on, in the fused pipeline). */
  paths.shadow_d[slot] = (float4)(dir, as_float(paths.info[slot].y));
  paths.shadow_l[slot] = (float4)(c, 0.0f);
  return true;
}
#endif

WP_GROUP_KERNEL void sample_lights(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
#if WP_STRATEGY != WP_STRATEGY_BSDF
  WP_GROUP_SCRATCH(scan);
  uint slot = 0u;
  bool shadow = false;
  if (queue_get(queues, WP_QUEUE_SURFACE, get_global_id(0), &slot)) {
    const Surface s = surface_load(paths, slot);
    BounceRandom u;
    bounce_random(path_rng(paths, slot, launch), &u);
    shadow = sample_light_ray(&scene, paths, queues, slot, &s, &u);
  }
  queue_push_group(queues, WP_QUEUE_SHADOW, shadow, slot, scan);
#endif
}
