/* Stage (fused): everything a path does at a hit, in one kernel, so the surface is resolved once
 * and stays in registers instead of passing through the path state: shade_hit, sample_light_ray,
 * sample_next_ray and roulette (integrator/), the same functions in the same order per path,
 * with the same random numbers, as the split stages shade_surface, sample_lights, sample_bsdf and
 * roulette_compact, so the image is the split pipeline's bit for bit (tested by
 * RenderKnown.FusedAndSplitShadingAreBitIdentical). The default pipeline.
 * From: queue_in with the hit records of intersect_closest.
 * To:   queue_out (next rays) and WP_QUEUE_SHADOW, which trace_shadow then traces. */
#include "integrator/roulette_compact.h"
#include "integrator/sample_bsdf.h"
#include "integrator/sample_lights.h"
#include "integrator/shade_surface.h"
#include "integrator/shade_packet.h"

WP_GROUP_KERNEL void shade(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
  WP_GROUP_SCRATCH(scan);
#if WP_SHADE_PACKET
  /* Eight paths per work-item (integrator/shade_packet.h), each shaded as below. */
  uint slots[WP_SHADE_LANES], shadow, survives;
  shade_packet(&scene, paths, queues, launch, get_global_id(0) * WP_SHADE_LANES, slots, &shadow,
               &survives);
  queue_push_group2_lanes(queues, WP_QUEUE_SHADOW, shadow, launch.queue_out, survives, slots, scan);
#else
  uint slot = 0u;
  bool shadow = false, survives = false;
  uint ahead;
  if (prefetch_slot(queues, launch.queue_in, get_global_id(0), &ahead))
    shade_prefetch(paths, ahead);
  if (queue_get(queues, launch.queue_in, get_global_id(0), &slot)) {
    /* The bounce's random numbers first, before the hit is resolved: their integer chains then run
     * beside shade_hit's loads instead of holding up the light sample that needs them. Not for a
     * ray that left the scene, where they would be drawn for nothing (scenes mostly background pay
     * for them otherwise). Paths that end at a hit still draw them for nothing. */
    BounceRandom u = {0.0f, 0.0f, 0.0f, (float2)(0.0f), (float2)(0.0f)};
    /* Read before the shadow ray takes the hit record's place (shared/path_state.def). */
    const float t = path_hit_t(paths, slot);
    if (t < INFINITY) bounce_random(path_rng(paths, slot, launch), &u);
    Surface s;
    if (shade_hit(&scene, paths, launch, slot, &s)) {
      /* What the BSDF needs of the incoming direction, once for both samples. */
      const BsdfView v = bsdf_view(&s, -path_ray_dir(paths, slot));
      if (launch.strategy != WP_STRATEGY_BSDF)
        shadow = sample_light_ray(&scene, paths, queues, slot, &s, &v, t, &u, launch.strategy);
      sample_next_ray(paths, queues, slot, &s, &v, t, &u);
      survives = roulette(paths, queues, launch, slot, u.roulette);
    }
  }
  queue_push_group2(queues, WP_QUEUE_SHADOW, shadow, launch.queue_out, survives, slot, scan);
#endif
}
