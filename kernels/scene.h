/* The scene as kernels see it: typed pointers into the scene buffers (locations in SceneDesc). */
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

/* The scene's kernel arguments: its buffers (unused ones repeat the first) and its SceneDesc. */
#define WP_SCENE_PARAMS                                                                         \
  __global const uchar *scene0, __global const uchar *scene1, __global const uchar *scene2,     \
      __global const uchar *scene3, __global const uchar *scene4, __global const uchar *scene5, \
      __global const uchar *scene6, __global const uchar *scene7, SceneDesc scene_desc

/* Declares `view`, the SceneView of WP_SCENE_PARAMS. */
#define WP_SCENE_BIND(view)                                                                  \
  __global const uchar* view##_buffers[WP_SCENE_BUFFERS] = {scene0, scene1, scene2, scene3,  \
                                                            scene4, scene5, scene6, scene7}; \
  const SceneView view = scene_bind(view##_buffers, &scene_desc)

/* The first byte of the array at `location` (kernels/shared/types.h). */
inline __global const uchar* scene_array(__global const uchar* const* buffers, uint location) {
  return buffers[location & (WP_SCENE_BUFFERS - 1)] +
         (ulong)(location & ~(uint)(WP_SCENE_BUFFERS - 1)) *
             (WP_SCENE_ALIGN >> WP_SCENE_BUFFER_BITS);
}

inline SceneView scene_bind(__global const uchar* const* b, const SceneDesc* d) {
  SceneView s;
  s.nodes = (__global const BvhNode*)scene_array(b, d->bvh_nodes);
  s.tris = (__global const IsectTri*)scene_array(b, d->isect_tris);
  s.tri_vertices = (__global const uint4*)scene_array(b, d->tri_vertices);
  s.positions = (__global const float4*)scene_array(b, d->positions);
  s.normals = (__global const float4*)scene_array(b, d->normals);
  s.tangents = (__global const float4*)scene_array(b, d->tangents);
  s.uvs = (__global const float4*)scene_array(b, d->uvs);
  s.colors = (__global const float4*)scene_array(b, d->colors);
  s.materials = (__global const Material*)scene_array(b, d->materials);
  s.textures = (__global const TextureRef*)scene_array(b, d->textures);
  s.images = (__global const TextureImage*)scene_array(b, d->images);
  s.texels = (__global const uint*)scene_array(b, d->texels);
  s.lights = (__global const Light*)scene_array(b, d->lights);
  s.light_alias = (__global const LightAlias*)scene_array(b, d->light_alias);
  s.tri_light = (__global const uint*)scene_array(b, d->tri_light);
  s.env_texels = (__global const float4*)scene_array(b, d->env_texels);
  s.env_marginal = (__global const float*)scene_array(b, d->env_marginal);
  s.env_conditional = (__global const float*)scene_array(b, d->env_conditional);
  s.desc = d;
  return s;
}

#endif /* WP_SCENE_H */
