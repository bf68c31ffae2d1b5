/* A triangle as the world sees it. In a two-level BVH (WP_BVH_INSTANCES, shared/bvh_layout.h)
 * the scene's vertex arrays hold each mesh once in its own space, and a hit or a light names the
 * instance that places it; these map the triangle's vertices into the world: positions by the
 * instance's transform (the inverse of the map the traversal uses), normals by its inverse
 * transpose and tangents by its 3x3 part (both renormalised), as the loader does when it flattens
 * a placement (host/scene/gltf_primitive.h).
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
/* The object-to-world map of an instance at (p, w) (w = 1 for points, 0 for directions): the
 * inverse of its to_object map x' = A x + t, A^-1 (p - w t), with A^-1 = [c0 c1 c2] / det(A) by
 * columns, c0 = r1 x r2, c1 = r2 x r0, c2 = r0 x r1 for A's rows r (its adjugate). */
static inline float3 instance_to_world(__global const BvhInstance* in, float3 p, float w) {
  const float4 a = in->to_object[0], b = in->to_object[1], c = in->to_object[2];
  const float3 c0 = cross(b.xyz, c.xyz), c1 = cross(c.xyz, a.xyz), c2 = cross(a.xyz, b.xyz);
  const float3 v = p - w * (float3)(a.w, b.w, c.w);
  return (c0 * v.x + c1 * v.y + c2 * v.z) / dot(a.xyz, c0);
}
#endif

static inline float3 placed_position(const SceneView* scene, uint inst, uint vertex) {
  const float3 p = scene->positions[vertex].xyz;
#if WP_BVH_INSTANCES
  return instance_to_world(scene->instances + inst, p, 1.0f);
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
  const float3 x = normalize(instance_to_world(scene->instances + inst, t.xyz, 0.0f));
  return (float4)(x, instance_mirrors(scene, inst) ? -t.w : t.w);
#else
  (void)inst;
  return t;
#endif
}

#endif /* WP_INSTANCE_H */
