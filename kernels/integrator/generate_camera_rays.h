/* Camera-ray generation for one path slot: the pixel and sample the slot stands for, the camera
 * ray through a jittered point of that pixel, and a fresh path (throughput 1, radiance 0,
 * bounce 0). Entry point: generate_camera_rays.cl. */
#ifndef WP_INTEGRATOR_GENERATE_CAMERA_RAYS_H
#define WP_INTEGRATOR_GENERATE_CAMERA_RAYS_H

#include "stage.h"
#include "camera.h"

/* Starts the path in `slot` of the wave (slot < launch.path_count). */
WP_STAGE_FN void start_path(const Camera* camera, Paths paths, Launch launch, uint slot) {
  const uint pixel = launch.pixel_offset + slot % launch.wave_pixels;
  const uint px = pixel % launch.width, py = pixel / launch.width;
  const float2 jitter =
      rng_get2(rng_make(pixel, path_sample(launch, slot), launch.seed, 0u), WP_DIM_PIXEL_X);
  const float2 ndc = (float2)(2.0f * ((float)px + jitter.x) / (float)launch.width - 1.0f,
                              1.0f - 2.0f * ((float)py + jitter.y) / (float)launch.height);
  float3 o, d;
  float tmin;
  camera_ray(camera, ndc, &o, &d, &tmin);
  path_set_ray_origin(paths, slot, o);
  path_set_ray_tmin(paths, slot, tmin);
  path_set_ray_dir(paths, slot, d);
  path_set_ray_tmax(paths, slot, INFINITY);
  path_set_throughput(paths, slot, (float3)(1.0f));
  path_set_bsdf_pdf(paths, slot, 0.0f); /* a camera ray: no BSDF sample to weigh against */
  path_set_radiance(paths, slot, (float3)(0.0f));
  path_set_eta_scale(paths, slot, 1.0f);
  path_set_pixel(paths, slot, pixel);
  path_set_bounce(paths, slot, 0u);
  path_set_flags(paths, slot, 0u);
  path_set_pane_distance(paths, slot, 0.0f);
#if WP_AOV
  path_set_aov_albedo(paths, slot, (float3)(0.0f));
  path_set_aov_depth(paths, slot, 0.0f);
  path_set_aov_normal(paths, slot, (float3)(0.0f));
  path_set_aov_recorded(paths, slot, 0.0f);
#endif
}

#endif /* WP_INTEGRATOR_GENERATE_CAMERA_RAYS_H */
