/* Camera-ray generation for one path slot: the pixel and sample the slot stands for, the camera
 * ray through a jittered point of that pixel, and a fresh path (throughput 1, radiance 0,
 * bounce 0). Entry point: generate_camera_rays.cl. */
#ifndef WP_INTEGRATOR_GENERATE_CAMERA_RAYS_H
#define WP_INTEGRATOR_GENERATE_CAMERA_RAYS_H

#include "stage.h"
#include "camera.h"
#include "ray_cone.h"

/* Starts the path in `slot` of the wave (slot < launch.path_count). */
WP_STAGE_FN void start_path(const Camera* camera, Paths paths, Launch launch, uint slot) {
  const uint pixel = path_pixel(launch, slot);
  const uint px = pixel % launch.width, py = pixel / launch.width;
  const Rng rng = rng_make(pixel, path_sample(launch, slot), launch.seed, 0u);
  const float2 jitter = rng_get2(rng, WP_DIM_PIXEL_X);
  const float2 ndc = (float2)(2.0f * ((float)px + jitter.x) / (float)launch.width - 1.0f,
                              1.0f - 2.0f * ((float)py + jitter.y) / (float)launch.height);
  const float2 lens = camera_has_lens(camera) ? rng_get2(rng, WP_DIM_LENS_U) : (float2)(0.5f);
  float3 o, d;
  float tmin;
  camera_ray(camera, ndc, lens, &o, &d, &tmin);
  path_store_ray_o(paths, slot, o, tmin);
  path_store_ray_d(paths, slot, d, 0.0f);
  /* A camera ray: no BSDF sample to weigh against (pdf 0). */
  path_store_throughput(paths, slot, (float3)(1.0f), 0.0f);
  path_store_radiance(paths, slot, (float3)(0.0f), 1.0f);
#if WP_FEATURE_TEXTURE_LOD
  /* Flags and bounce 0, and the camera's ray cone (ray_cone.h). */
  const float2 cone = camera_cone(camera, launch.height);
  path_set_bounce_word(paths, slot, with_high_bf16(0u, cone.x));
  path_set_flags_word(paths, slot, with_high_bf16(0u, cone.y));
#else
  path_set_flags(paths, slot, 0u);
  path_set_bounce(paths, slot, 0u);
#endif
#if WP_AOV
  path_store_aov_albedo(paths, slot, (float3)(0.0f), 0.0f);
  path_store_aov_normal(paths, slot, (float3)(0.0f), 0.0f);
#endif
}

#endif /* WP_INTEGRATOR_GENERATE_CAMERA_RAYS_H */
