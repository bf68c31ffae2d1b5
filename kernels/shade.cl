/* Stage (fused): everything a path does at a hit, in one kernel, so the surface is resolved once
 * and stays in registers instead of passing through the path state:
 * shade_surface (emission, environment, the surface), sample_lights (NEE: a shadow ray into
 * WP_QUEUE_SHADOW), sample_bsdf (the next ray) and roulette_compact (survivors into queue_out).
 * From: queue_in with the hit records of intersect_closest.
 * To:   queue_out (next rays) and WP_QUEUE_SHADOW, which trace_shadow then traces.
 * It calls the same functions as those four stages, in the same order per path, with the same
 * random numbers, so the image is the split pipeline's bit for bit (RenderSettings::fused; tested
 * by RenderKnown.FusedAndSplitShadingAreBitIdentical). The default pipeline (README, "Fused
 * shading"). */
#include "stage.h"
#include "surface.h"

WP_GROUP_KERNEL void shade(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
  WP_GROUP_SCRATCH(scan);
  uint slot = 0u;
  bool shadow = false, survives = false;
  uint ahead;
  if (prefetch_slot(queues, launch.queue_in, get_global_id(0), &ahead)) {
    wp_prefetch(paths.info + ahead);
    wp_prefetch(paths.hit + ahead);
    wp_prefetch(paths.ray_d + ahead);
    wp_prefetch(paths.throughput + ahead);
    wp_prefetch(paths.radiance + ahead);
    wp_prefetch(paths.ray_o + ahead);
  }
  if (queue_get(queues, launch.queue_in, get_global_id(0), &slot)) {
    /* The bounce's random numbers first, before the hit is resolved: their integer chains (about
     * 100 cycles deep) then run beside shade_hit's loads instead of holding up the light sample
     * that needs them (README, "Random numbers drawn first"). Not for a ray that left the scene:
     * drawn for nothing there, they cost scenes mostly background (FlightHelmet, 85% of camera
     * rays) more than they saved. Paths that end at a hit still draw them for nothing. */
    BounceRandom u = {0.0f, 0.0f, 0.0f, (float2)(0.0f), (float2)(0.0f)};
    if (paths.hit[slot].x < INFINITY) bounce_random(path_rng(paths, slot, launch), &u);
    Surface s;
    if (shade_hit(&scene, paths, launch, slot, &s)) {
#if WP_STRATEGY != WP_STRATEGY_BSDF
      shadow = sample_light_ray(&scene, paths, queues, slot, &s, &u);
#endif
      sample_next_ray(paths, queues, slot, &s, &u);
      survives = roulette(paths, queues, launch, slot, u.roulette);
    }
  }
#if WP_STRATEGY != WP_STRATEGY_BSDF
  queue_push_group2(queues, WP_QUEUE_SHADOW, shadow, launch.queue_out, survives, slot, scan);
#else
  queue_push_group(queues, launch.queue_out, survives, slot, scan);
#endif
}
