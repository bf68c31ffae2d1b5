/* The environment: radiance of escaped rays, and its importance sampling for NEE.
 *
 * Without a map (env_width == 0) the environment is the constant background radiance, sampled
 * uniformly over the sphere. With a map: see host/environment.h for the direction convention. */
#ifndef WP_ENVIRONMENT_H
#define WP_ENVIRONMENT_H

#include "scene.h"

inline float3 env_radiance(const SceneView* scene, float3 dir) {
  (void)dir;
  return scene->desc->background.xyz;
}

/* Samples a direction toward the environment; returns its radiance, *pdf is the solid-angle
 * density (0 if nothing can be sampled). */
inline float3 env_sample(const SceneView* scene, float2 u, float3* dir, float* pdf) {
  const float z = 1.0f - 2.0f * u.x;
  const float r = sqrt(fmax(0.0f, 1.0f - z * z));
  const float phi = 2.0f * WP_PI * u.y;
  *dir = (float3)(r * cos(phi), z, r * sin(phi));
  *pdf = 1.0f / (4.0f * WP_PI);
  return env_radiance(scene, *dir);
}

inline float env_pdf(const SceneView* scene, float3 dir) {
  (void)scene;
  (void)dir;
  return 1.0f / (4.0f * WP_PI);
}

#endif /* WP_ENVIRONMENT_H */
