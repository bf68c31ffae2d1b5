/* Alpha for ray traversal: whether a hit on a triangle whose material has alphaMode MASK or BLEND
 * (IsectTri flag WP_TRI_ALPHA) counts. Alpha = base colour factor alpha x base colour texture
 * alpha x vertex colour alpha. MASK: a cutout, the surface is there where alpha >= alphaCutoff.
 * BLEND: stochastic transparency, the surface is there with probability alpha, decided by a hash
 * of the ray's `key` (path, sample, bounce, ray kind) and the triangle; it is stateless, so the
 * image stays independent of queue order, and the decisions for different triangles along one
 * ray are independent. Averaged over samples this is exactly "over" compositing of the layers. */
#ifndef WP_ALPHA_H
#define WP_ALPHA_H

#include "sampling/rng.h"
#include "geom/scene.h"
#include "texture/textures.h"

/* The material alpha of triangle `tri` at barycentrics (u, v) of its vertices 1 and 2. */
static inline float material_alpha(const SceneView* scene, uint tri, float u, float v) {
  const uint4 tv = scene->tri_vertices[tri];
  __global const Material* m = scene->materials + tv.w;
  const float w = 1.0f - u - v;
  float alpha = m->base_color.w *
                (w * scene->colors[tv.x].w + u * scene->colors[tv.y].w + v * scene->colors[tv.z].w);
#if WP_FEATURE_TEXTURES
  if (m->textures0.x >= 0) {
    const float4 uv = w * scene->uvs[tv.x] + u * scene->uvs[tv.y] + v * scene->uvs[tv.z];
    alpha *= texture_sample(scene, m->textures0.x, uv).w;
  }
#endif
  return alpha;
}

/* A uniform number in [0, 1) (a multiple of 2^-24) from the ray's key and the triangle. */
static inline float alpha_random(uint key, uint tri) {
  return (float)(wp_hash(key ^ wp_hash(tri ^ 0x9e3779b9u)) >> 8) * (1.0f / 16777216.0f);
}

static inline bool alpha_passes(const SceneView* scene, uint tri, float u, float v, uint key) {
  __global const Material* m = scene->materials + scene->tri_vertices[tri].w;
  const uint flags = m->flags.x;
  if (!(flags & (WP_MAT_ALPHA_MASK | WP_MAT_ALPHA_BLEND))) return true;
  const float alpha = material_alpha(scene, tri, u, v);
  if (flags & WP_MAT_ALPHA_MASK) return alpha >= m->emission.w;
  return alpha_random(key, tri) < alpha;
}

/* The probability that a ray finds triangle `tri` at (u, v): 1 for an opaque material, the cutout
 * test for MASK, alpha itself for BLEND (the stochastic test above passes with that
 * probability). Next-event estimation scales an emitter's radiance by it, so that light sampling
 * and BSDF sampling (whose rays see the emitter only where the traversal accepts it) estimate the
 * same light. */
static inline float alpha_coverage(const SceneView* scene, uint tri, float u, float v) {
  __global const Material* m = scene->materials + scene->tri_vertices[tri].w;
  const uint flags = m->flags.x;
  if (!(flags & (WP_MAT_ALPHA_MASK | WP_MAT_ALPHA_BLEND))) return 1.0f;
  const float alpha = material_alpha(scene, tri, u, v);
  if (flags & WP_MAT_ALPHA_MASK) return alpha >= m->emission.w ? 1.0f : 0.0f;
  return clamp(alpha, 0.0f, 1.0f);
}

#endif /* WP_ALPHA_H */
