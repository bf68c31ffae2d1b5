/* A triangle as the world sees it. In a two-level BVH (WP_BVH_INSTANCES, shared/bvh_layout.h)
 * the scene's vertex arrays hold each mesh once in its own space, and a hit or a light names the
 * instance that places it; these map the triangle's vertices into the world: positions by the
 * instance's transform, normals by its inverse transpose and tangents by its 3x3 part (both
 * renormalised), as the loader does when it flattens a placement (host/scene/gltf_primitive.h).
 * A mirroring instance (negative determinant) reverses the winding: placed_triangle swaps
 * vertices 1 and 2 and the barycentrics with them, so that the front face stays counter-clockwise
 * in the world, and the tangents' handedness flips. Without WP_BVH_INSTANCES every function is
 * the identity (inst is WP_NO_INSTANCE). */
#ifndef WP_INSTANCE_H
#define WP_INSTANCE_H

#include "scene.h"

/* Whether instance `inst` mirrors (reverses the winding). */
static inline bool instance_mirrors(const SceneView* scene, uint inst) {
#if WP_BVH_INSTANCES
  return (scene->instances[inst].meta.z & WP_INSTANCE_MIRROR) != 0u;
#else
  (void)scene, (void)inst;
  return false;
#endif
}

/* Triangle `tri`'s vertex indices and material (tri_vertices), and the barycentrics *u, *v of
 * its vertices 1 and 2, in the world's winding. */
static inline uint4 placed_triangle(const SceneView* scene, uint inst, uint tri, float* u,
                                    float* v) {
  const uint4 tv = scene->tri_vertices[tri];
  if (instance_mirrors(scene, inst)) {
    const float t = *u;
    *u = *v, *v = t;
    return (uint4)(tv.x, tv.z, tv.y, tv.w);
  }
  return tv;
}

#if WP_BVH_INSTANCES
/* Row-major 3x4 times (p, w): w = 1 for points, 0 for directions. */
static inline float3 instance_map(__global const float4* rows, float3 p, float w) {
  return (float3)(dot(rows[0].xyz, p) + rows[0].w * w, dot(rows[1].xyz, p) + rows[1].w * w,
                  dot(rows[2].xyz, p) + rows[2].w * w);
}
#endif

static inline float3 placed_position(const SceneView* scene, uint inst, uint vertex) {
  const float3 p = scene->positions[vertex].xyz;
#if WP_BVH_INSTANCES
  return instance_map(scene->instances[inst].to_world, p, 1.0f);
#else
  (void)inst;
  return p;
#endif
}

static inline float3 placed_normal(const SceneView* scene, uint inst, uint vertex) {
  const float3 n = scene->normals[vertex].xyz;
#if WP_BVH_INSTANCES
  /* The inverse transpose: the columns of to_object's 3x3. */
  __global const float4* m = scene->instances[inst].to_object;
  return normalize(n.x * m[0].xyz + n.y * m[1].xyz + n.z * m[2].xyz);
#else
  (void)inst;
  return n;
#endif
}

static inline float4 placed_tangent(const SceneView* scene, uint inst, uint vertex) {
  const float4 t = scene->tangents[vertex];
#if WP_BVH_INSTANCES
  const float3 x = normalize(instance_map(scene->instances[inst].to_world, t.xyz, 0.0f));
  return (float4)(x, instance_mirrors(scene, inst) ? -t.w : t.w);
#else
  (void)inst;
  return t;
#endif
}

#endif /* WP_INSTANCE_H */
