/* The scene as kernels see it: typed pointers into the one scene buffer (offsets in SceneDesc). */
#ifndef WP_SCENE_H
#define WP_SCENE_H

#include "common.h"

typedef struct SceneView {
  __global const BvhNode* nodes;
  __global const IsectTri* tris;
  __global const uint4* tri_vertices;
  __global const float4* positions;
  __global const float4* normals;
  __global const float4* uvs;
  __global const float4* colors;
  __global const Material* materials;
  __global const PunctualLight* lights;
  uint light_count;
} SceneView;

inline SceneView scene_bind(__global const uchar* base, const SceneDesc* d) {
  SceneView s;
  s.nodes = (__global const BvhNode*)(base + d->bvh_nodes);
  s.tris = (__global const IsectTri*)(base + d->isect_tris);
  s.tri_vertices = (__global const uint4*)(base + d->tri_vertices);
  s.positions = (__global const float4*)(base + d->positions);
  s.normals = (__global const float4*)(base + d->normals);
  s.uvs = (__global const float4*)(base + d->uvs);
  s.colors = (__global const float4*)(base + d->colors);
  s.materials = (__global const Material*)(base + d->materials);
  s.lights = (__global const PunctualLight*)(base + d->lights);
  s.light_count = d->light_count;
  return s;
}

#endif /* WP_SCENE_H */
