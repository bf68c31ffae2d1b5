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
  __global const float4* tangents;
  __global const float4* uvs;
  __global const float4* colors;
  __global const Material* materials;
  __global const TextureRef* textures;
  __global const TextureImage* images;
  __global const uint* texels;
  __global const Light* lights;
  __global const LightAlias* light_alias;
  __global const uint* tri_light;
  __global const float4* env_texels;
  __global const float* env_marginal;
  __global const float* env_conditional;
  const SceneDesc* desc; /* counts, camera, background, environment parameters */
} SceneView;

inline SceneView scene_bind(__global const uchar* base, const SceneDesc* d) {
  SceneView s;
  s.nodes = (__global const BvhNode*)(base + d->bvh_nodes);
  s.tris = (__global const IsectTri*)(base + d->isect_tris);
  s.tri_vertices = (__global const uint4*)(base + d->tri_vertices);
  s.positions = (__global const float4*)(base + d->positions);
  s.normals = (__global const float4*)(base + d->normals);
  s.tangents = (__global const float4*)(base + d->tangents);
  s.uvs = (__global const float4*)(base + d->uvs);
  s.colors = (__global const float4*)(base + d->colors);
  s.materials = (__global const Material*)(base + d->materials);
  s.textures = (__global const TextureRef*)(base + d->textures);
  s.images = (__global const TextureImage*)(base + d->images);
  s.texels = (__global const uint*)(base + d->texels);
  s.lights = (__global const Light*)(base + d->lights);
  s.light_alias = (__global const LightAlias*)(base + d->light_alias);
  s.tri_light = (__global const uint*)(base + d->tri_light);
  s.env_texels = (__global const float4*)(base + d->env_texels);
  s.env_marginal = (__global const float*)(base + d->env_marginal);
  s.env_conditional = (__global const float*)(base + d->env_conditional);
  s.desc = d;
  return s;
}

#endif /* WP_SCENE_H */
