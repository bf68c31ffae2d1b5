/* Camera rays. Pixel (x, y) has y = 0 at the top row; a sample at (x + jx, y + jy), jitter
 * uniform in the pixel (box filter), maps to NDC in [-1, 1]^2 with +y up. Camera.right/up hold
 * the image-plane half extents: tan(yfov/2) * aspect and tan(yfov/2) for a perspective camera
 * (aspect = width / height, glTF's convention), and xmag-or-derived / ymag for an orthographic
 * one. Nothing nearer than znear (measured along the view direction) is seen. */
#ifndef WP_CAMERA_H
#define WP_CAMERA_H

#include "common.h"

static inline void camera_ray(const Camera* cam, float2 ndc, float3* o, float3* d, float* tmin) {
  const float3 fwd = cam->forward.xyz;
  const float3 plane = ndc.x * cam->right.xyz + ndc.y * cam->up.xyz;
  const float znear = cam->position.w;
  if (cam->meta.x == WP_CAMERA_ORTHOGRAPHIC) {
    *o = cam->position.xyz + plane;
    *d = fwd;
    *tmin = znear;
  } else {
    *o = cam->position.xyz;
    *d = normalize(fwd + plane);
    *tmin = znear / dot(*d, fwd);
  }
}

#endif /* WP_CAMERA_H */
