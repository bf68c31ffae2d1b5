/* Camera rays. Pixel (x, y) has y = 0 at the top row; a sample at (x + jx, y + jy), jitter
 * uniform in the pixel (box filter), maps to NDC in [-1, 1]^2 with +y up. Camera.right/up hold
 * the image-plane half extents: tan(yfov/2) * aspect and tan(yfov/2) for a perspective camera
 * (aspect = width / height, glTF's convention), and xmag-or-derived / ymag for an orthographic
 * one. Nothing nearer than znear (measured along the view direction) is seen.
 *
 * Thin lens (perspective, Camera.lens.x > 0): the ray starts at a point uniform on the lens disc
 * of radius lens.x about the eye, perpendicular to the view direction, and passes through the
 * point where the pinhole ray of the same image point meets the plane of focus, lens.y along the
 * view direction. Points on that plane stay sharp; a point at depth z (along the view direction)
 * is spread over a disc of radius lens.x |1/lens.y - 1/z| on the image plane at distance 1 (the
 * plane that right/up span). Each ray carries the radiance it finds, unweighted, so a surface in
 * focus has the pinhole's pixel values. */
#ifndef WP_CAMERA_H
#define WP_CAMERA_H

#include "util/common.h"

/* Defined in sampling/warps.h, which is not included here: the program is one translation unit of
 * every stage, this file comes first in it, and traverse.h's `FP_CONTRACT OFF` holds for all that
 * follows it, sampling/warps.h included -- which must stay after it to keep its arithmetic. */
static inline float2 sample_concentric_disk(float2 u);

/* Whether camera_ray uses a lens sample: only then is one drawn. */
static inline bool camera_has_lens(const Camera* cam) {
#if WP_THIN_LENS
  return cam->lens.x > 0.0f;
#else
  (void)cam;
  return false;
#endif
}

static inline void camera_ray(const Camera* cam, float2 ndc, float2 lens_u, float3* o, float3* d,
                              float* tmin) {
  const float3 fwd = cam->forward.xyz;
  const float3 plane = ndc.x * cam->right.xyz + ndc.y * cam->up.xyz;
  const float znear = cam->position.w;
  if (cam->meta.x == WP_CAMERA_ORTHOGRAPHIC) {
    *o = cam->position.xyz + plane;
    *d = fwd;
    *tmin = znear;
    return;
  }
  *o = cam->position.xyz;
  *d = normalize(fwd + plane);
#if WP_THIN_LENS
  if (camera_has_lens(cam)) {
    /* The pinhole ray meets the plane of focus at focus / cos. */
    const float2 disk = cam->lens.x * sample_concentric_disk(lens_u);
    const float3 focus = *o + (cam->lens.y / dot(*d, fwd)) * *d;
    *o += disk.x * normalize(cam->right.xyz) + disk.y * normalize(cam->up.xyz);
    *d = normalize(focus - *o);
  }
#else
  (void)lens_u;
#endif
  *tmin = znear / dot(*d, fwd);
}

#if WP_SHADE_PACKET
/* camera_ray of eight lanes (common.h) for a pinhole camera (no lens, not orthographic): the
 * directions and their tmin; the origin is the eye. */
WP_LANES_FN Float3x8 camera_ray8(const Camera* cam, float8 ndc_x, float8 ndc_y, float8* tmin) {
  const float3 fwd = cam->forward.xyz, right = cam->right.xyz, up = cam->up.xyz;
  const Float3x8 plane = {ndc_x * right.x + ndc_y * up.x, ndc_x * right.y + ndc_y * up.y,
                          ndc_x * right.z + ndc_y * up.z};
  const Float3x8 f = {(float8)(fwd.x), (float8)(fwd.y), (float8)(fwd.z)};
  const Float3x8 d = normalize3x8((Float3x8){f.x + plane.x, f.y + plane.y, f.z + plane.z});
  *tmin = cam->position.w / dot3x8(d, f);
  return d;
}
#endif

#endif /* WP_CAMERA_H */
