/* Stage: camera-ray generation.
 * From: nothing; a new sample pass over the wave's pixels [pixel_offset, pixel_offset +
 * path_count). To:   every slot of the wave initialised (throughput 1, radiance 0, bounce 0) and in
 * queue_out. */
#include "stage.h"
#include "camera.h"

__kernel void generate_camera_rays(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
  const uint slot = get_global_id(0);
  if (slot >= launch.path_count) return;
  const uint pixel = launch.pixel_offset + slot % launch.wave_pixels;
  const uint px = pixel % launch.width, py = pixel / launch.width;
  const float2 jitter =
      rng_get2(rng_make(pixel, path_sample(launch, slot), launch.seed, 0u), WP_DIM_PIXEL_X);
  const float2 ndc = (float2)(2.0f * ((float)px + jitter.x) / (float)launch.width - 1.0f,
                              1.0f - 2.0f * ((float)py + jitter.y) / (float)launch.height);
  float3 o, d;
  float tmin;
  camera_ray(&scene_desc.camera, ndc, &o, &d, &tmin);
  paths.ray_o[slot] = (float4)(o, tmin);
  paths.ray_d[slot] = (float4)(d, INFINITY);
  paths.throughput[slot] = (float4)(1.0f, 1.0f, 1.0f, 0.0f);
  paths.radiance[slot] = (float4)(0.0f, 0.0f, 0.0f, 1.0f); /* w: eta scale (roulette_compact) */
  paths.info[slot] = (uint4)(pixel, 0u, 0u, 0u);
#if WP_AOV
  paths.aov_albedo[slot] = (float4)(0.0f);
  paths.aov_normal[slot] = (float4)(0.0f);
#endif
  queues.slots[launch.queue_out * queues.capacity + slot] = slot;
  if (slot == 0) queues.counters[launch.queue_out] = launch.path_count;
}
