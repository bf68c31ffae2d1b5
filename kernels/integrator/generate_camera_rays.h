/* Camera-ray generation for one path slot: the pixel and sample the slot stands for, the camera
 * ray through a jittered point of that pixel, and a fresh path (throughput 1, radiance 0,
 * bounce 0). Entry point: generate_camera_rays.cl. */
#ifndef WP_INTEGRATOR_GENERATE_CAMERA_RAYS_H
#define WP_INTEGRATOR_GENERATE_CAMERA_RAYS_H

#include "stage.h"
#include "camera/camera.h"
#include "texture/ray_cone.h"

/* A fresh path in `slot` on the camera ray (o, d) that starts at tmin. */
WP_STAGE_FN void begin_path(const Camera* camera, Paths paths, Launch launch, uint slot, float3 o,
                            float3 d, float tmin) {
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
  (void)camera;
  (void)launch;
  path_set_flags(paths, slot, 0u);
  path_set_bounce(paths, slot, 0u);
#endif
#if WP_AOV
  path_store_aov_albedo(paths, slot, (float3)(0.0f), 0.0f);
  path_store_aov_normal(paths, slot, (float3)(0.0f), 0.0f);
#endif
}

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
  begin_path(camera, paths, launch, slot, o, d, tmin);
}

#if WP_SHADE_PACKET
/* Starts the paths in slots [first, first + 8) of the wave as start_path does each (a program
 * that shades in packets: integrator/shade_packet.h), a pinhole camera's rays and the Sobol'
 * samplers' pixel jitter in the lanes (rng_pair_lanes); path by path otherwise, and for the last
 * slots of a wave short of eight. */
WP_STAGE_FN void start_paths8(const Camera* camera, Paths paths, Launch launch, uint first) {
  const uint n = min(8u, launch.path_count - first);
  if (WP_SAMPLER == WP_SAMPLER_INDEPENDENT || n < 8u || camera_has_lens(camera) ||
      camera->meta.x == WP_CAMERA_ORTHOGRAPHIC) {
    for (uint i = 0u; i < n; ++i) start_path(camera, paths, launch, first + i);
    return;
  }
#if WP_SAMPLER != WP_SAMPLER_INDEPENDENT
  uint pixel[8], sample[8], px[8], py[8];
  /* The first slot's pixel and sample by division; the others, where the eight slots are one
   * sample's consecutive pixels spread over at most two rows, by counting on from it (integer
   * divisions path by path took a fifth of this stage). */
  const uint in_wave = first % launch.wave_pixels;
  if (in_wave + 7u < launch.wave_pixels && launch.width >= 8u) {
    const uint p0 = launch.pixel_offset + in_wave, s0 = path_sample(launch, first);
    const uint x0 = p0 % launch.width, y0 = p0 / launch.width;
    for (uint i = 0u; i < 8u; ++i) {
      const bool next_row = x0 + i >= launch.width;
      pixel[i] = p0 + i, sample[i] = s0;
      px[i] = next_row ? x0 + i - launch.width : x0 + i, py[i] = next_row ? y0 + 1u : y0;
    }
  } else {
    for (int i = 0; i < 8; ++i) {
      pixel[i] = path_pixel(launch, first + (uint)i),
      sample[i] = path_sample(launch, first + (uint)i);
      px[i] = pixel[i] % launch.width, py[i] = pixel[i] / launch.width;
    }
  }
  const RngLanes r = {vload8(0, pixel), vload8(0, sample), (uint8)(0u), launch.seed};
  float8 jx, jy; /* rng_get2's pixel jitter */
  rng_pair_lanes(rng_order_lanes(r, (uint8)(WP_DIM_PIXEL_X)), (uint8)(0u), false, &jx, &jy);
  const float8 ndc_x = 2.0f * (convert_float8(vload8(0, px)) + jx) / (float)launch.width - 1.0f;
  const float8 ndc_y = 1.0f - 2.0f * (convert_float8(vload8(0, py)) + jy) / (float)launch.height;
  float8 tmin;
  const Float3x8 d = camera_ray8(camera, ndc_x, ndc_y, &tmin);
  for (int i = 0; i < 8; ++i)
    begin_path(camera, paths, launch, first + (uint)i, camera->position.xyz, lane3(d, i),
               lane_of(tmin, i));
#endif
}
#endif

#endif /* WP_INTEGRATOR_GENERATE_CAMERA_RAYS_H */
