/* Stage: shadow rays.
 * From: WP_QUEUE_SHADOW (shadow_o/shadow_d, tmax in shadow_o.w, contribution in shadow_l).
 * To:   radiance += shadow_l x the transmittance along the ray, for every ray that reaches its
 *       light; the queue ends here.
 *
 * Without transmission in the program a shadow ray is an any-hit query: any surface occludes.
 * With it, smooth thin-walled transmitters (delta transmission that does not bend the ray, like
 * a window pane) let the ray pass with their transmittance (1 - F) x transmission x base colour
 * (bsdf.h, microfacet_weights), so that punctual lights and the sun shine through them as
 * they do in reality; BSDF sampling keeps its pdf through the same surfaces (sample_bsdf.cl), so
 * the MIS weights of both strategies still sum to 1. Such rays go from surface to surface with
 * closest-hit queries, at most WP_SHADOW_MAX_LAYERS panes; a ray that meets more is taken as
 * occluded (a bias only beyond that many panes in a row). */
#include "stage.h"
#include "material.h"
#include "traverse.h"

#define WP_SHADOW_MAX_LAYERS 16

__kernel void trace_shadow(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
  uint slot, ahead;
  if (prefetch_slot(queues, WP_QUEUE_SHADOW, get_global_id(0), &ahead)) {
    wp_prefetch(paths.shadow_o + ahead);
    wp_prefetch(paths.shadow_d + ahead);
    wp_prefetch(paths.shadow_l + ahead);
    wp_prefetch(paths.radiance + ahead);
  }
  if (!queue_get(queues, WP_QUEUE_SHADOW, get_global_id(0), &slot)) return;
  const float4 o = paths.shadow_o[slot];
  const float4 dw = paths.shadow_d[slot];
  const float3 d = dw.xyz;
  /* The random numbers of the bounce that made the ray (shadow_d.w, sample_lights.cl). */
  const uint key = rng_bits(path_rng_at(paths, slot, launch, as_uint(dw.w)), WP_DIM_ALPHA_SHADOW);
#if WP_FEATURE_TRANSMISSION
  const bool finite = o.w < INFINITY;
  const float3 target = o.xyz + d * o.w; /* the end point of a ray of finite length */
  float3 origin = o.xyz, transmit = (float3)(1.0f);
  float tmax = o.w;
  for (int layer = 0; layer <= WP_SHADOW_MAX_LAYERS; ++layer) {
    const TraceRay ray = trace_ray(origin, d, 0.0f, key);
    TraceHit hit;
    if (!bvh_trace(&scene, &ray, tmax, &hit, false)) {
      paths.radiance[slot].xyz += paths.shadow_l[slot].xyz * transmit;
      return;
    }
    const uint4 tv = scene.tri_vertices[hit.tri];
    bool front;
    const Surface s = resolve_surface(&scene, tv, hit.u, hit.v, d, &front);
    if (layer == WP_SHADOW_MAX_LAYERS || !bsdf_has_delta(&s) || !bsdf_transmits(&s) ||
        bsdf_volume(&s))
      return; /* an occluder */
    transmit *= microfacet_weights(&s, fabs(dot(s.ns, d)), relative_ior(&s)).transmit;
    if (!(max3(transmit) > 0.0f)) return;
    origin = offset_origin(s.p, -s.ng, s.p_scale); /* s.ng faces the incoming ray */
    if (finite) tmax = dot(target - origin, d);
  }
#else
  const TraceRay ray = trace_ray(o.xyz, d, 0.0f, key);
  TraceHit hit;
  if (!bvh_trace(&scene, &ray, o.w, &hit, true)) paths.radiance[slot] += paths.shadow_l[slot];
#endif
}
