/* Punctual lights (KHR_lights_punctual): point, spot and directional, all delta distributions.
 * Units: a point/spot intensity is radiant intensity in W/sr, so the irradiance it gives a
 * surface facing it at distance d is I / d^2; a directional light's is irradiance in W/m^2. */
#ifndef WP_LIGHTS_H
#define WP_LIGHTS_H

#include "common.h"

typedef struct LightSample {
  float3 wi;  /* unit direction from the shading point toward the light */
  float dist; /* distance to the light (INFINITY for a directional light) */
  float3 li;  /* irradiance at the point on a surface facing the light (before the cosine) */
} LightSample;

/* KHR_lights_punctual's recommended range window, applied only when a range is given. */
inline float range_window(float dist, float range) {
  if (range <= 0.0f) return 1.0f;
  return clamp(1.0f - pow(dist / range, 4.0f), 0.0f, 1.0f);
}

inline LightSample sample_punctual_light(__global const PunctualLight* light, float3 p) {
  LightSample s;
  const float4 pos = light->position;
  if (light->meta.x == WP_LIGHT_DIRECTIONAL) {
    s.wi = -light->direction.xyz;
    s.dist = INFINITY;
    s.li = light->intensity.xyz;
    return s;
  }
  const float3 to_light = pos.xyz - p;
  const float d2 = dot(to_light, to_light);
  s.dist = sqrt(d2);
  s.wi = to_light / s.dist;
  s.li = light->intensity.xyz * (range_window(s.dist, pos.w) / d2);
#if WP_FEATURE_SPOT_LIGHTS
  if (light->meta.x == WP_LIGHT_SPOT) {
    const float cd = dot(light->direction.xyz, -s.wi);
    const float a = clamp(cd * light->spot.x + light->spot.y, 0.0f, 1.0f);
    s.li *= a * a;
  }
#endif
  return s;
}

#endif /* WP_LIGHTS_H */
