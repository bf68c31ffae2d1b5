/* Closest-hit intersection for one path: its ray (path_ray_*) against the BVH, the hit record
 * (path_hit_*) out, t = INFINITY for a miss. Entry point: intersect_closest.cl. */
#ifndef WP_INTEGRATOR_INTERSECT_CLOSEST_H
#define WP_INTEGRATOR_INTERSECT_CLOSEST_H

#include "stage.h"
#include "traversal/traverse.h"

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

#if WP_CLOSEST_PACKET
#if WP_BVH_WIDTH != 8 || WP_BVH_INSTANCES || WP_FEATURE_ALPHA
#error "WP_CLOSEST_PACKET: the wide layout without instances or alpha only (traverse8_packet.h)"
#endif

/* The rays of entries [first, first + WP_PACKET) of `queue` as one packet: the same hit records
 * as intersect_path gives each (traverse8_packet.h). */
WP_STAGE_FN void intersect_packet(const SceneView* scene, Paths paths, Queues queues, uint queue,
                                  uint first) {
  uint slots[WP_PACKET];
  /* The single-ray stage's cache hints, for the entries WP_PREFETCH_AHEAD further on. */
  for (uint i = 0u; i < WP_PACKET; ++i) {
    uint ahead;
    if (prefetch_slot(queues, queue, first + i, &ahead)) intersect_prefetch(paths, ahead);
  }
  const int n = queue_get_run(queues, queue, first, WP_PACKET, slots);
  if (n == 0) return;
  float4 o[WP_PACKET], d[WP_PACKET];
  for (int i = 0; i < WP_PACKET; ++i) {
    const uint slot = slots[i < n ? i : 0];
    o[i] = path_load_ray_o(paths, slot), d[i] = path_load_ray_d(paths, slot);
  }
  PacketRays p = packet_rays8(o, d, &p.tmin); /* ray_o.w: tmin */
  p.tmax = (float8)(INFINITY);
  PacketHit h;
  packet_closest(scene, &p, (1 << n) - 1, &h);
  float t[WP_PACKET], u[WP_PACKET], v[WP_PACKET];
  uint tri[WP_PACKET];
  vstore8(h.t, 0, t);
  vstore8(h.u, 0, u);
  vstore8(h.v, 0, v);
  vstore8(h.tri, 0, tri);
  /* A lane that hit nothing still holds packet_closest's start, intersect_path's miss record
   * (t = tmax = INFINITY, u = v = 0, triangle 0). */
  for (int i = 0; i < n; ++i) path_store_hit(paths, slots[i], t[i], u[i], v[i], tri[i]);
}
#endif

#endif /* WP_INTEGRATOR_INTERSECT_CLOSEST_H */
