/* Test kernels for tests/test_textures.cpp: texture sampling (textures.h), material alpha
 * (alpha.h) and the resolved surface (material.h), each over a scene packed by
 * host/device/device_scene.cpp and queried item by item. */
#include "alpha.h"
#include "material.h"
#include "textures.h"

/* out[i] = texture_sample(refs[i], uvs[i]). */
__kernel void sample_textures(WP_SCENE_PARAMS, __global const int* refs, __global const float4* uvs,
                              uint count, __global float4* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  WP_SCENE_BIND(scene);
  out[i] = texture_sample(&scene, refs[i], uvs[i]);
}

/* Per query (triangle, barycentrics u v as float bits, key): x = material_alpha, y =
 * alpha_passes (0 or 1). */
__kernel void alpha_queries(WP_SCENE_PARAMS, __global const uint4* queries, uint count,
                            __global float4* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  WP_SCENE_BIND(scene);
  const uint4 q = queries[i];
  const float u = as_float(q.y), v = as_float(q.z);
  out[i] = (float4)(material_alpha(&scene, q.x, u, v),
                    alpha_passes(&scene, q.x, u, v, q.w) ? 1.0f : 0.0f, 0.0f, 0.0f);
}

/* How often alpha_passes lets triangle `tri` through, and both `tri` and `tri2` (same key, as
 * for the layers along one ray), over keys 0..count-1: counts[0] and counts[1]. */
__kernel void alpha_frequency(WP_SCENE_PARAMS, uint tri, uint tri2, uint count,
                              __global uint* counts) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  WP_SCENE_BIND(scene);
  const uint key = wp_hash(i * 0x9e3779b9u + 17u); /* like rng_bits: a hash per path */
  const bool a = alpha_passes(&scene, tri, 0.25f, 0.25f, key);
  const bool b = alpha_passes(&scene, tri2, 0.25f, 0.25f, key);
  if (a) atomic_inc(counts);
  if (a && b) atomic_inc(counts + 1);
}

/* resolve_surface for (triangle, barycentrics) queries with ray directions: out holds, per
 * query, 4 float4s: (ns, front), (color, metallic), (roughness, transmission, 0, 0),
 * (material_emission, 0). */
__kernel void resolve_surfaces(WP_SCENE_PARAMS, __global const float4* queries,
                               __global const float4* rays, uint count, __global float4* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  WP_SCENE_BIND(scene);
  const float4 q = queries[i];
  const uint4 tv = scene.tri_vertices[as_uint(q.x)];
  bool front;
  const Surface s = resolve_surface(&scene, tv, q.y, q.z, rays[i].xyz, &front);
  out[4 * i] = (float4)(s.ns, front ? 1.0f : 0.0f);
  out[4 * i + 1] = (float4)(s.color, s.metallic);
  out[4 * i + 2] = (float4)(s.roughness, s.transmission, 0.0f, 0.0f);
  out[4 * i + 3] = (float4)(material_emission(&scene, tv, q.y, q.z), 0.0f);
}
