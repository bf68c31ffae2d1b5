/* Test kernels for tests/test_textures.cpp: texture sampling (textures.h), material alpha
 * (alpha.h) and the resolved surface (material.h), each over a scene packed by
 * host/device/device_scene.cpp and queried item by item. */
#include "traversal/alpha.h"
#include "geom/material.h"
#include "texture/textures.h"

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
  const Surface s =
      resolve_surface(&scene, WP_NO_INSTANCE, as_uint(q.x), q.y, q.z, rays[i].xyz, 0.0f, &front);
  out[4 * i] = (float4)(s.ns, front ? 1.0f : 0.0f);
  out[4 * i + 1] = (float4)(s.color, s.metallic);
  out[4 * i + 2] = (float4)(s.roughness, s.transmission, 0.0f, 0.0f);
  out[4 * i + 3] = (float4)(material_emission(&scene, tv, q.y, q.z), 0.0f);
}

/* out[i] = texture_sample_lod(refs[i], uvs[i], (lods[i], lods[i])): both coordinate sets at the
 * footprint level lods[i] (before the texture's own term). */
__kernel void sample_textures_lod(WP_SCENE_PARAMS, __global const int* refs,
                                  __global const float4* uvs, __global const float* lods,
                                  uint count, __global float4* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  WP_SCENE_BIND(scene);
  out[i] = texture_sample_lod(&scene, refs[i], uvs[i], (float2)(lods[i]));
}

/* Ray cones of camera rays (ray_cone.h, material.h's texture_point), per query (triangle and
 * texture index as uint bits, barycentrics u v; the ray's direction and hit distance t): the mip
 * level lambda the texture is looked up at, (lambda, the cone's width at the hit, 0, 0). */
__kernel void camera_ray_levels(WP_SCENE_PARAMS, __global const float4* queries,
                                __global const float4* rays, uint height, uint count,
                                __global float4* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  WP_SCENE_BIND(scene);
  const float4 q = queries[i], ray = rays[i];
  const uint4 tv = scene.tri_vertices[as_uint(q.x)];
  const float3 p0 = scene.positions[tv.x].xyz, p1 = scene.positions[tv.y].xyz;
  const float3 p2 = scene.positions[tv.z].xyz;
  const float3 n = cross(p1 - p0, p2 - p0);
  const float width = cone_width_at(camera_cone(&scene.desc->camera, height), ray.w);
  const TexPoint tp = texture_point(&scene, tv, q.z, q.w, width, length(n));
  __global const TextureRef* t = scene.textures + as_uint(q.y);
  const float lambda = (t->meta.z == 1u ? tp.lod.y : tp.lod.x) + as_float(t->meta.w);
  out[i] = (float4)(lambda, width, 0.0f, 0.0f);
}

/* A cone through bounces as the stages carry it (shade_surface.h, sample_bsdf.h), each bounce i
 * given as (hit distance, curvature, pdf of the sample that leaves, 0), its width and spread
 * stored between bounces as the path state holds them (bfloat16 halves, path_state.h). out[i]:
 * (width at hit i, spread leaving it, 0, 0). */
__kernel void cone_bounces(float2 start, __global const float4* bounces, uint count,
                           __global float4* out) {
  if (get_global_id(0) != 0u) return;
  uint width_word = with_high_bf16(0u, start.x), spread_word = with_high_bf16(0u, start.y);
  for (uint i = 0u; i < count; ++i) {
    const float4 b = bounces[i];
    const float2 cone = (float2)(high_bf16(width_word), high_bf16(spread_word));
    const float width = cone_width_at(cone, b.x);
    width_word = with_high_bf16(width_word, width);
    spread_word = with_high_bf16(spread_word, cone_spread_curved(cone.y, b.y, width));
    spread_word = with_high_bf16(spread_word, high_bf16(spread_word) + lobe_spread(b.z));
    out[i] = (float4)(high_bf16(width_word), high_bf16(spread_word), 0.0f, 0.0f);
  }
}

/* triangle_curvature of triangles given by 6 float4s each (p0, p1, p2, n0, n1, n2). */
__kernel void curvatures(__global const float4* tris, uint count, __global float* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  __global const float4* t = tris + 6 * i;
  out[i] = triangle_curvature(t[0].xyz, t[1].xyz, t[2].xyz, t[3].xyz, t[4].xyz, t[5].xyz);
}
