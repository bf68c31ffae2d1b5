/* Stage: next-event estimation (light sampling).
 * From: WP_QUEUE_SURFACE.
 * To:   WP_QUEUE_SHADOW with a shadow ray toward one light and the radiance it adds if unoccluded.
 * One punctual light is chosen uniformly (probability 1 / light_count). Punctual lights are delta
 * distributions no BSDF sample can hit, so NEE is their only strategy: MIS weight 1. */
#include "stage.h"
#include "lights.h"
#include "surface.h"

__kernel void sample_lights(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
  uint slot;
  if (!queue_get(queues, WP_QUEUE_SURFACE, get_global_id(0), &slot)) return;
#if WP_FEATURE_PUNCTUAL_LIGHTS
  const uint count = scene.light_count;
  if (count == 0) return;
  const Surface s = surface_load(paths, slot);
  const Rng rng = path_rng(paths, slot, launch);
  const uint pick = min((uint)(rng_get(rng, WP_DIM_LIGHT_PICK) * (float)count), count - 1u);
  const LightSample ls = sample_punctual_light(scene.lights + pick, s.p);
  const BsdfEval e = bsdf_eval(&s, -paths.ray_d[slot].xyz, ls.wi);
  const float3 c = paths.throughput[slot].xyz * e.f * (dot(s.ns, ls.wi) * (float)count) * ls.li;
  if (!(max3(c) > 0.0f)) return;
  paths.shadow_o[slot] = (float4)(offset_origin(s.p, s.ng), ls.dist);
  paths.shadow_d[slot] = (float4)(ls.wi, 0.0f);
  paths.shadow_l[slot] = (float4)(c, 0.0f);
  queue_push(queues, WP_QUEUE_SHADOW, slot);
#endif
}
