/* The scene as kernels see it: typed pointers into the scene buffers (kernels/shared/types.h). */
#ifndef WP_SCENE_H
#define WP_SCENE_H

#include "util/common.h"

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
#if WP_BVH_INSTANCES
  __global const BvhInstance* instances;
  __global const uint* instance_refs;
#endif
  const SceneDesc* desc; /* counts, camera, background, environment parameters */
} SceneView;

/* The scene's kernel arguments: its buffers (unused ones repeat the first) and its SceneDesc. */
#define WP_SCENE_PARAMS                                                                         \
  __global const uchar *scene0, __global const uchar *scene1, __global const uchar *scene2,     \
      __global const uchar *scene3, __global const uchar *scene4, __global const uchar *scene5, \
      __global const uchar *scene6, __global const uchar *scene7, SceneDesc scene_desc

/* Declares `view`, the SceneView of WP_SCENE_PARAMS. Stages that never read the scene bind it
 * too (one argument list for all); the (void) keeps clang's -Wunused-variable quiet for them. */
#define WP_SCENE_BIND(view)                                                                  \
  __global const uchar* view##_buffers[WP_SCENE_BUFFERS] = {scene0, scene1, scene2, scene3,  \
                                                            scene4, scene5, scene6, scene7}; \
  const SceneView view = scene_bind(view##_buffers, &scene_desc);                            \
  (void)view

#ifndef WP_SCENE_BUFFER_MAP
#define WP_SCENE_BUFFER_MAP 0 /* every array in buffer 0 */
#endif
/* The buffer holding array `i` (SceneDesc's order, from 0 for bvh_nodes): a compile-time constant.
 */
#define WP_SCENE_BUFFER_OF(i) \
  ((uint)(((ulong)(WP_SCENE_BUFFER_MAP) >> (WP_SCENE_BUFFER_BITS * (i))) & (WP_SCENE_BUFFERS - 1)))

/* The first byte of the array that starts `offset` 64-byte units into `buffers[buffer]`. */
static inline __global const uchar* scene_array(__global const uchar* const* buffers, uint buffer,
                                                uint offset) {
  return buffers[buffer] + (ulong)offset * WP_SCENE_ALIGN;
}

#define WP_SCENE_ARRAY(type, i, offset) \
  ((__global const type*)scene_array(b, WP_SCENE_BUFFER_OF(i), d->offset))

static inline SceneView scene_bind(__global const uchar* const* b, const SceneDesc* d) {
  SceneView s;
  s.nodes = WP_SCENE_ARRAY(BvhNode, 0, bvh_nodes);
  s.tris = WP_SCENE_ARRAY(IsectTri, 1, isect_tris);
  s.tri_vertices = WP_SCENE_ARRAY(uint4, 2, tri_vertices);
  s.positions = WP_SCENE_ARRAY(float4, 3, positions);
  s.normals = WP_SCENE_ARRAY(float4, 4, normals);
  s.tangents = WP_SCENE_ARRAY(float4, 5, tangents);
  s.uvs = WP_SCENE_ARRAY(float4, 6, uvs);
  s.colors = WP_SCENE_ARRAY(float4, 7, colors);
  s.materials = WP_SCENE_ARRAY(Material, 8, materials);
  s.textures = WP_SCENE_ARRAY(TextureRef, 9, textures);
  s.images = WP_SCENE_ARRAY(TextureImage, 10, images);
  s.texels = WP_SCENE_ARRAY(uint, 11, texels);
  s.lights = WP_SCENE_ARRAY(Light, 12, lights);
  s.light_alias = WP_SCENE_ARRAY(LightAlias, 13, light_alias);
  s.tri_light = WP_SCENE_ARRAY(uint, 14, tri_light);
  s.env_texels = WP_SCENE_ARRAY(float4, 15, env_texels);
  s.env_marginal = WP_SCENE_ARRAY(float, 16, env_marginal);
  s.env_conditional = WP_SCENE_ARRAY(float, 17, env_conditional);
#if WP_BVH_INSTANCES
  s.instances = WP_SCENE_ARRAY(BvhInstance, 18, instances);
  s.instance_refs = WP_SCENE_ARRAY(uint, 19, instance_refs);
#endif
  s.desc = d;
  return s;
}

#endif /* WP_SCENE_H */
