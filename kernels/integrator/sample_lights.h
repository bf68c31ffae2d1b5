/* Next-event estimation for one path: one light point sampled (lights.h), the BSDF evaluated
 * toward it, and a shadow ray that adds throughput * f * |cos| * L / pdf * w_light (mis.h) if
 * nothing occludes it. Nothing on surfaces with delta lobes alone; not called under
 * WP_STRATEGY_BSDF (Launch.strategy). Used by sample_lights.cl and the fused shade.cl. */
#ifndef WP_INTEGRATOR_SAMPLE_LIGHTS_H
#define WP_INTEGRATOR_SAMPLE_LIGHTS_H

#include "stage.h"
#include "lights/lights.h"
#include "lights/mis.h"
#include "geom/surface.h"

/* NEE at surface s, seen as v (bsdf_view at -ray_d), hit at distance t, of the path in `slot`
 * with the bounce's random numbers u (its light pick and light point), weighed for `strategy`
 * (MIS or NEE): a shadow ray for WP_QUEUE_SHADOW, true when there is one (the caller pushes it).
 * The fused pipeline's shadow ray takes the hit record's place, so t comes from the caller, which
 * read it before. */
WP_STAGE_FN bool sample_light_ray(const SceneView* scene, Paths paths, Queues queues, uint slot,
                                  const Surface* s, const BsdfView* v, float t,
                                  const BounceRandom* u, uint strategy) {
  if (scene->desc->light_count == 0 || bsdf_only_delta(s)) return false;
  const LightSample ls = sample_light(scene, s->p, u->light_pick, u->light_uv);
  if (!(ls.pdf > 0.0f)) return false;
  const float3 ray_d = path_ray_dir(paths, slot);
  const BsdfEval e = bsdf_eval_view(s, v, -ray_d, ls.wi);
  const float w = mis_weight_light(ls.pdf, e.pdf, ls.delta, strategy);
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

#if WP_SHADE_PACKET
/* sample_light_ray of eight lanes (common.h, shade_packet.h) for the paths in slots[i] whose bit
 * is set in `lanes`: their light is emissive triangle tri[i], or the constant background where
 * bit i of `env` is set (with or without a map), picked with probability pmf, the point at (ux,
 * uy); surface s (without a delta lobe) seen as v, hit at distance t along ray_d, throughput beta;
 * weighed for `strategy`. Returns the lanes with a shadow ray. */
WP_LANES_STEP uint sample_light_ray8(const SceneView* scene, Paths paths, Queues queues,
                                     const uint* slots, uint lanes, uint env, const Surface8* s,
                                     const BsdfView8* v, Float3x8 ray_d, float8 t, Float3x8 beta,
                                     const uint* tri, float8 pmf, float8 ux, float8 uy,
                                     uint strategy) {
  LightSample8 ls = sample_triangle8(scene, tri, s->p, ux, uy);
  const int8 sky = ((int8)(1, 2, 4, 8, 16, 32, 64, 128) & (int8)(env)) != 0;
  if (env != 0u) { /* env_sample */
    Float3x8 wi, li;
    float8 pdf;
#if WP_FEATURE_ENVIRONMENT
    if (scene->desc->env_width > 0u) {
      li = env_map_sample8(scene, ux, uy, &wi, &pdf);
    } else
#endif
    {
      const float3 bg = scene->desc->background.xyz;
      wi = env_sample_uniform8(ux, uy);
      li = (Float3x8){bg.x, bg.y, bg.z};
      pdf = (float8)(1.0f / (4.0f * WP_PI));
    }
    ls.wi = select3x8(ls.wi, wi, sky);
    ls.li = select3x8(ls.li, li, sky);
    ls.pdf = select(ls.pdf, pdf, sky);
    ls.dist = select(ls.dist, (float8)(INFINITY), sky);
  }
  ls.pdf *= pmf;
  float8 e_pdf;
  const Float3x8 f = bsdf_eval8(s, v, neg3x8(ray_d), ls.wi, &e_pdf);
  const float8 w = mis_weight_light8(ls.pdf, e_pdf, strategy);
  const float8 k = fabs(dot3x8(s->ns, ls.wi)) * w / ls.pdf;
  const Float3x8 c = {beta.x * f.x * ls.li.x * k, beta.y * f.y * ls.li.y * k,
                      beta.z * f.z * ls.li.z * k};
  const int8 lit = ls.pdf > 0.0f, finite = finite3x8(c);
  const int8 ray = lit && finite && max3x8(c) > 0.0f;
  uint rays = 0u;
#pragma unroll
  for (int i = 0; i < 8; ++i) {
    if (!((lanes >> i) & 1u)) continue;
    if (lane_set(lit, i) && !lane_set(finite, i)) count_nonfinite(queues);
    if (lane_set(ray, i)) rays |= 1u << i;
  }
  if (rays == 0u) return 0u;
  const Float3x8 o = surface_spawn8(s, ray_d, t, ls.wi);
  const Float3x8 to = sub3x8(ls.target, o);
  const float8 tmax = select(length3x8(to), (float8)(INFINITY), sky);
  const Float3x8 dir = select3x8(div3x8(to, tmax), ls.wi, sky);
#pragma unroll
  for (int i = 0; i < 8; ++i) {
    if (!((rays >> i) & 1u)) continue;
    path_store_shadow_o(paths, slots[i], lane3(o, i), lane_of(tmax, i));
    path_set_shadow_dir(paths, slots[i], lane3(dir, i));
    path_set_shadow_radiance(paths, slots[i], lane3(c, i));
  }
  return rays;
}
#endif

#endif /* WP_INTEGRATOR_SAMPLE_LIGHTS_H */
