/* Materials at a hit point: the surface record the BSDF works on, and the emitted radiance.
 *
 * resolve_surface() interpolates the triangle's attributes at barycentrics (u, v) and evaluates
 * the material there. Textures (base colour, metallic-roughness, normal, emissive, transmission),
 * KHR_texture_transform, alpha and KHR_materials_unlit are resolved here and nowhere else. */
#ifndef WP_MATERIAL_H
#define WP_MATERIAL_H

#include "bsdf.h"
#include "scene.h"

inline float3 interpolate3(__global const float4* a, uint4 tv, float u, float v) {
  return (1.0f - u - v) * a[tv.x].xyz + u * a[tv.y].xyz + v * a[tv.z].xyz;
}

/* Emitted radiance of triangle `tri`'s material at barycentrics (u, v), whichever side. */
inline float3 material_emission(const SceneView* scene, uint4 tv, float u, float v) {
  (void)u;
  (void)v;
  return scene->materials[tv.w].emission.xyz;
}

/* Geometry and material at a hit of a ray with direction ray_d on triangle tv at barycentrics
 * (u, v). *front tells whether the ray hit the front (counter-clockwise) side; both normals are
 * turned to face the ray. */
inline Surface resolve_surface(const SceneView* scene, uint4 tv, float u, float v, float3 ray_d,
                               bool* front) {
  __global const Material* m = scene->materials + tv.w;
  Surface s;
  const float3 p0 = scene->positions[tv.x].xyz;
  const float3 p1 = scene->positions[tv.y].xyz;
  const float3 p2 = scene->positions[tv.z].xyz;
  s.p = (1.0f - u - v) * p0 + u * p1 + v * p2;
  const float3 n = cross(p1 - p0, p2 - p0);
  const float len = length(n);
  s.ng = len > 0.0f ? n / len : -ray_d; /* a degenerate triangle faces the ray */
  *front = dot(s.ng, ray_d) < 0.0f;
  if (!*front) s.ng = -s.ng;
  s.ns = normalize(interpolate3(scene->normals, tv, u, v));
  if (dot(s.ns, s.ng) < 0.0f) s.ns = -s.ns;
  /* An interpolated normal can face away from the viewer near silhouettes; shading with it would
   * reflect into the surface. Fall back to the true normal there. */
  if (!(dot(s.ns, -ray_d) > 1e-4f)) s.ns = s.ng;
  s.color = m->base_color.xyz;
#if WP_FEATURE_VERTEX_COLORS
  s.color *= interpolate3(scene->colors, tv, u, v);
#endif
  const float4 q = m->params;
  s.metallic = q.x;
  s.roughness = q.y;
  s.ior = q.z;
  s.transmission = q.w;
  s.flags = *front ? WP_SURF_FRONT : 0u;
#if WP_FEATURE_UNLIT
  if (m->flags.x & WP_MAT_UNLIT) s.flags |= WP_SURF_UNLIT;
#endif
#if WP_FEATURE_VOLUME
  if (m->flags.x & WP_MAT_VOLUME) s.flags |= WP_SURF_VOLUME;
#endif
  return s;
}

#endif /* WP_MATERIAL_H */
