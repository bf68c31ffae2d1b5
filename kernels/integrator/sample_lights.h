/* Next-event estimation for one path: one light point sampled (lights.h), the BSDF evaluated
 * toward it, and a shadow ray that adds throughput * f * |cos| * L / pdf * w_light (mis.h) if
 * nothing occludes it. Nothing on surfaces with delta lobes alone, nor with WP_STRATEGY_BSDF. Used
 * by sample_lights.cl and the fused shade.cl. */
#ifndef WP_INTEGRATOR_SAMPLE_LIGHTS_H
#define WP_INTEGRATOR_SAMPLE_LIGHTS_H

#include "stage.h"
#include "lights.h"
#include "mis.h"
#include "surface.h"

#if WP_STRATEGY != WP_STRATEGY_BSDF
/* NEE at surface s, seen as v (bsdf_view at -ray_d), hit at distance t, of the path in `slot`
 * with the bounce's random numbers u (its light pick and light point): a shadow ray for
 * WP_QUEUE_SHADOW, true when there is one (the caller pushes it). The fused pipeline's shadow ray
 * takes the hit record's place, so t comes from the caller, which read it before. */
WP_STAGE_FN bool sample_light_ray(const SceneView* scene, Paths paths, Queues queues, uint slot,
                                  const Surface* s, const BsdfView* v, float t,
                                  const BounceRandom* u) {
  if (scene->desc->light_count == 0 || bsdf_only_delta(s)) return false;
  const LightSample ls = sample_light(scene, s->p, u->light_pick, u->light_uv);
  if (!(ls.pdf > 0.0f)) return false;
  const float3 ray_d = path_ray_dir(paths, slot);
  const BsdfEval e = bsdf_eval_view(s, v, -ray_d, ls.wi);
  const float w = mis_weight_light(ls.pdf, e.pdf, ls.delta);
  const float3 c =
      path_throughput(paths, slot) * e.f * ls.li * (fabs(dot(s->ns, ls.wi)) * w / ls.pdf);
  if (!all(isfinite(c))) {
    count_nonfinite(queues);
    return false;
  }
  if (!(max3(c) > 0.0f)) return false;
  /* The shadow ray leaves the side of the surface the light is on (transmission can light the
   * back) and, for a light at a finite distance, runs from the moved origin to the light's target
   * point (itself moved off an area light's surface): neither end can hit the surface it is on. */
  const float3 o = surface_spawn(s, ray_d, t, ls.wi);
  float3 dir = ls.wi;
  float tmax = INFINITY;
  if (ls.dist < INFINITY) {
    const float3 to = ls.target - o;
    tmax = length(to);
    dir = to / tmax;
  }
  path_store_shadow_o(paths, slot, o, tmax);
  path_set_shadow_dir(paths, slot, dir);
  path_set_shadow_radiance(paths, slot, c);
  return true;
}
#endif

#endif /* WP_INTEGRATOR_SAMPLE_LIGHTS_H */
