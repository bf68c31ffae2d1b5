/* Shadow rays for one path: the radiance the shadow ray carries (path_shadow_radiance) times the
 * transmittance along it is added to the path's radiance when the ray reaches its light.
 *
 * Without transmission in the program a shadow ray is an any-hit query: any surface occludes.
 * With it, smooth thin-walled transmitters (delta transmission that does not bend the ray, like
 * a window pane) let the ray pass with their transmittance (1 - F) x transmission x base colour
 * (bsdf.h, microfacet_weights), so that punctual lights and the sun shine through them as
 * they do in reality; BSDF sampling keeps its pdf through the same surfaces (sample_bsdf.h), so
 * the MIS weights of both strategies still sum to 1. Such rays go from surface to surface with
 * closest-hit queries, at most WP_SHADOW_MAX_LAYERS panes; a ray that meets more is taken as
 * occluded (a bias only beyond that many panes in a row). Entry point: trace_shadow.cl. */
#ifndef WP_INTEGRATOR_TRACE_SHADOW_H
#define WP_INTEGRATOR_TRACE_SHADOW_H

#include "stage.h"
#include "geom/material.h"
#include "traversal/traverse.h"

#define WP_SHADOW_MAX_LAYERS 16

/* The fields trace_shadow_path reads and writes, for the cache hints of the slot ahead. */
static inline void trace_shadow_prefetch(Paths paths, uint slot) {
  prefetch_path(paths, shadow_o, slot);
  prefetch_path(paths, shadow_d, slot);
  prefetch_path(paths, shadow_l, slot);
  prefetch_path(paths, radiance, slot);
}

/* A shadow ray that reaches its light unhindered: the path's radiance takes what the ray carries.
 */
static inline void shadow_ray_arrives(Paths paths, uint slot) {
  path_set_radiance(paths, slot, path_radiance(paths, slot) + path_shadow_radiance(paths, slot));
}

WP_STAGE_FN void trace_shadow_path(const SceneView* scene, Paths paths, Launch launch, uint slot) {
  const float3 o = path_shadow_origin(paths, slot), d = path_shadow_dir(paths, slot);
  const float tmax_light = path_shadow_tmax(paths, slot);
  /* The random numbers of the bounce that made the ray (sample_lights.h): the one before the
   * path's count, which roulette has moved on (roulette_compact.h). */
  const uint key =
      rng_bits(path_rng_at(slot, launch, path_bounce(paths, slot) - 1u), WP_DIM_ALPHA_SHADOW);
#if WP_FEATURE_TRANSMISSION
  const bool finite = tmax_light < INFINITY;
  const float3 target = o + d * tmax_light; /* the end point of a ray of finite length */
  float3 origin = o, transmit = (float3)(1.0f);
  float tmax = tmax_light;
  for (int layer = 0; layer <= WP_SHADOW_MAX_LAYERS; ++layer) {
    const TraceRay ray = trace_ray(origin, d, 0.0f, key);
    TraceHit hit;
    if (!bvh_trace(scene, &ray, tmax, &hit, false)) {
      path_set_radiance(paths, slot,
                        path_radiance(paths, slot) + path_shadow_radiance(paths, slot) * transmit);
      return;
    }
    bool front;
    const Surface s =
        resolve_surface(scene, trace_hit_instance(&hit), hit.tri, hit.u, hit.v, d, 0.0f, &front);
    if (layer == WP_SHADOW_MAX_LAYERS || !bsdf_has_delta(&s) || !bsdf_transmits(&s) ||
        bsdf_volume(&s))
      return; /* an occluder */
    transmit *= bsdf_pane_transmittance(&s, d);
    if (!(max3(transmit) > 0.0f)) return;
    origin = offset_origin(s.p, -s.ng, s.p_scale); /* s.ng faces the incoming ray */
    if (finite) tmax = dot(target - origin, d);
  }
#else
  const TraceRay ray = trace_ray(o, d, 0.0f, key);
  TraceHit hit;
  if (!bvh_trace(scene, &ray, tmax_light, &hit, true)) shadow_ray_arrives(paths, slot);
#endif
}

#if WP_SHADOW_PACKET
#if WP_BVH_WIDTH != 8 || WP_BVH_INSTANCES || WP_FEATURE_ALPHA || WP_FEATURE_TRANSMISSION
#error "WP_SHADOW_PACKET: plain any-hit queries on the wide layout only (traverse8_packet.h)"
#endif

/* The shadow rays of queue entries [first, first + WP_PACKET) as one packet: the same answers as
 * trace_shadow_path gives each (traverse8_packet.h). */
WP_STAGE_FN void trace_shadow_packet(const SceneView* scene, Paths paths, Queues queues,
                                     uint first) {
  uint slots[WP_PACKET];
  /* The single-ray stage's cache hints, for the entries WP_PREFETCH_AHEAD further on. */
  for (uint i = 0u; i < WP_PACKET; ++i) {
    uint ahead;
    if (prefetch_slot(queues, WP_QUEUE_SHADOW, first + i, &ahead))
      trace_shadow_prefetch(paths, ahead);
  }
  const int n = queue_get_run(queues, WP_QUEUE_SHADOW, first, WP_PACKET, slots);
  if (n == 0) return;
  float4 o[WP_PACKET], d[WP_PACKET];
  for (int i = 0; i < WP_PACKET; ++i) {
    const uint slot = slots[i < n ? i : 0];
    o[i] = path_load_shadow_o(paths, slot), d[i] = path_load_shadow_d(paths, slot);
  }
  PacketRays p = packet_rays8(o, d, &p.tmax); /* shadow_o.w: the ray's length */
  p.tmin = (float8)(0.0f);
  const int live = (1 << n) - 1;
  const int occluded = packet_any_hit(scene, &p, live);
  for (int i = 0; i < n; ++i)
    if (!(occluded & (1 << i))) shadow_ray_arrives(paths, slots[i]);
}
#endif

#endif /* WP_INTEGRATOR_TRACE_SHADOW_H */
