/* Stage: hit resolution.
 * From: queue_in with the hit records of intersect_closest.
 * To:   misses add the background and end. Hits add the surface's emission, resolve the material
 *       into the surface record (surface.h) and go to WP_QUEUE_SURFACE, unless the path has had
 *       max_depth scattering events already, in which case it ends here.
 * Emission and background reached this way have MIS weight 1 for now: no other strategy samples
 * them yet (area lights and environment NEE come with the light-transport work). */
#include "stage.h"
#include "surface.h"

inline float3 interpolate3(__global const float4* a, uint4 tv, float u, float v) {
  return (1.0f - u - v) * a[tv.x].xyz + u * a[tv.y].xyz + v * a[tv.z].xyz;
}

/* Geometry and material at the hit; ray_d is the incoming direction. */
inline Surface resolve_surface(SceneView scene, uint4 tv, float4 hit, float3 ray_d,
                               const Material* m, bool* front) {
  Surface s;
  const float3 p0 = scene.positions[tv.x].xyz;
  const float3 p1 = scene.positions[tv.y].xyz;
  const float3 p2 = scene.positions[tv.z].xyz;
  s.p = (1.0f - hit.y - hit.z) * p0 + hit.y * p1 + hit.z * p2;
  const float3 n = cross(p1 - p0, p2 - p0);
  const float len = length(n);
  s.ng = len > 0.0f ? n / len : -ray_d; /* a degenerate triangle faces the ray */
  *front = dot(s.ng, ray_d) < 0.0f;
  if (!*front) s.ng = -s.ng;
  s.ns = normalize(interpolate3(scene.normals, tv, hit.y, hit.z));
  if (dot(s.ns, s.ng) < 0.0f) s.ns = -s.ns;
  /* An interpolated normal can face away from the viewer near silhouettes; shading with it would
   * reflect into the surface. Fall back to the true normal there. */
  if (!(dot(s.ns, -ray_d) > 1e-4f)) s.ns = s.ng;
  s.color = m->base_color.xyz;
#if WP_FEATURE_VERTEX_COLORS
  s.color *= interpolate3(scene.colors, tv, hit.y, hit.z);
#endif
  s.metallic = m->params.x;
  s.roughness = m->params.y;
  s.ior = m->params.z;
  s.transmission = m->params.w;
  return s;
}

__kernel void shade_surface(WP_STAGE_PARAMS) {
  WP_STAGE_BIND;
  uint slot;
  if (!queue_get(queues, launch.queue_in, get_global_id(0), &slot)) return;
  const float4 hit = paths.hit[slot];
  const float3 beta = paths.throughput[slot].xyz;
  const float3 ray_d = paths.ray_d[slot].xyz;
  if (!(hit.x < INFINITY)) {
    paths.radiance[slot].xyz += beta * scene_desc.background.xyz;
    return;
  }
  const uint4 tv = scene.tri_vertices[as_uint(hit.w)];
  const Material m = scene.materials[tv.w];
  bool front;
  const Surface s = resolve_surface(scene, tv, hit, ray_d, &m, &front);
#if WP_FEATURE_EMISSION
  if (front || (m.flags.x & WP_MAT_DOUBLE_SIDED)) paths.radiance[slot].xyz += beta * m.emission.xyz;
#endif
  if (paths.info[slot].y >= launch.max_depth) return;
  surface_store(paths, slot, &s);
  queue_push(queues, WP_QUEUE_SURFACE, slot);
}
