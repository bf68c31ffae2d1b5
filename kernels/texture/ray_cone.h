/* Ray cones: the footprint that chooses a texture's mip level (Akenine-Moller et al., "Texture
 * Level of Detail Strategies for Real-Time Ray Tracing", Ray Tracing Gems ch. 20, 2019, and
 * "Improved Shader and Texture Level of Detail Using Ray Cones", JCGT 10(1), 2021). Only in
 * programs built with WP_FEATURE_TEXTURE_LOD (--mipmaps on and a mip-mapped texture in the scene).
 *
 * Every path carries a cone about its ray: its width w at the ray's origin (world units) and its
 * spread angle g (radians, the cone's full angle; negative for a cone that converges), in the high
 * halves of the flags and bounce words (shared/path_state.def, path_state.h). The cone is an
 * eighth (WP_CONE_SCALE) of the footprint one sample stands for, below.
 *   camera      a pinhole starts with w = 0 and g = an eighth of the pixel's angle,
 *               2 tan(yfov / 2) / height; an orthographic camera with w = an eighth of the pixel's
 *               height, 2 ymag / height, and g = 0. A thin lens keeps the pinhole's cone.
 *   hit at t    w' = w + g t; the cone's footprint on the surface is an ellipse |w'| across
 *               and |w'| / |cos| along the ray's direction, cos the angle between the ray and
 *               the geometric normal.
 *   level       lambda = log2 |w'| + 1/2 log2(A_uv / A_world) + 1/2 log2(W H |det T|): the
 *               footprint's minor axis in texels of a W x H texture whose coordinates
 *               (transformed by KHR_texture_transform's T) cover A_uv where the triangle covers
 *               A_world; textures.h samples trilinearly at lambda (level 0 where lambda <= 0, as
 *               without mip-maps). The minor axis, not the major one: a trilinear lookup filters
 *               both directions alike, and at the major axis's level it would average across the
 *               ray by 1 / |cos| more than the footprint (at grazing angles whole stripes of a
 *               texture, and normal and roughness maps into other highlights, whatever the
 *               number of samples). At the minor axis's level it averages within the footprint
 *               everywhere; along the ray the pixel's samples, spread over the pixel, average
 *               what the lookup leaves. Measured in docs/performance.md, "Mip-mapped textures:
 *               error against time" (grazing angles).
 *   scattering  g' = g + 2 k w' for the surface's curvature k (below): a mirror on a sphere of
 *               radius R (k = 1/R) bends the rays across a footprint w' by 2 w'/R; plus, for a
 *               sample of a lobe that is not delta, an eighth of min(2 / sqrt(pi pdf), pi), the
 *               full angle of the cone whose solid angle is 1 / pdf (the solid angle the sample
 *               stands for): wide for a diffuse bounce (2 rad at normal incidence, so 0.25), narrow
 *               for a glossy one, 0 for a mirror. The curvature term is added at every hit
 *               (shade_surface.h), so also where a path goes straight through a smooth
 *               thin-walled transmitter, which adds no lobe spread: a flat pane leaves the cone
 *               as it was.
 * Why an eighth: the samples of a pixel are already spread over it (box filter) and each scattered
 * sample's neighbours over its lobe, so a cone as wide as a whole footprint blurs the image twice
 * over. Measured on DamagedHelmet seen small (tools/studies/mip_study.py's case, 256 x 256, the
 * model ~50 pixels across, 1024 spp): the mip-mapped image converges to a relMSE of 9.3e-5 from the
 * unfiltered one with an eighth (pbrt-v4's smallest scale of its ray differentials too), 2.4e-4
 * with a quarter (0.0064 with whole footprints, measured with the major axis's level), while its
 * relMSE at equal samples stays 1.2-1.75x below the unfiltered render's (docs/performance.md,
 * "Mip-mapped textures: error against time").
 * Emission and alpha are always looked up at level 0 (material_emission, alpha.h), so that the
 * light tables, light samples and shadow rays, which carry no cone, see the same values as the
 * paths. */
#ifndef WP_RAY_CONE_H
#define WP_RAY_CONE_H

#include "util/elementary.h"
#include "integrator/path_state.h"

#if WP_FEATURE_TEXTURE_LOD
/* The cone of the path in `slot` at its ray's origin: x width, y spread angle. */
static inline float2 path_cone(Paths paths, uint slot) {
  return (float2)(high_bf16(path_bounce_word(paths, slot)),
                  high_bf16(path_flags_word(paths, slot)));
}
/* Sets it, keeping the words' low halves (both words read before either is written, so that
 * the reads are path_cone's). */
static inline void path_set_cone(Paths paths, uint slot, float2 cone) {
  const uint bounce_word = path_bounce_word(paths, slot), flags_word = path_flags_word(paths, slot);
  path_set_bounce_word(paths, slot, with_high_bf16(bounce_word, cone.x));
  path_set_flags_word(paths, slot, with_high_bf16(flags_word, cone.y));
}

/* The fraction of a sample's footprint the cone covers (above). */
#define WP_CONE_SCALE 0.125f

/* The camera's cone for a ray of an image `height` pixels high (Camera.up spans half of it). */
static inline float2 camera_cone(const Camera* cam, uint height) {
  const float pixel = WP_CONE_SCALE * 2.0f * length(cam->up.xyz) / (float)height;
  return cam->meta.x == WP_CAMERA_ORTHOGRAPHIC ? (float2)(pixel, 0.0f) : (float2)(0.0f, pixel);
}

/* The curvature of the surface across triangle (p0, p1, p2) with unit vertex normals (n0, n1, n2)
 * on the side the ray sees: the mean over its edges of dn.dp / |dp|^2, 1/R on a sphere of radius R
 * seen from outside, -1/R from inside, 0 on a flat triangle. */
static inline float triangle_curvature(float3 p0, float3 p1, float3 p2, float3 n0, float3 n1,
                                       float3 n2) {
  const float3 e0 = p1 - p0, e1 = p2 - p1, e2 = p0 - p2;
  float k = 0.0f;
  const float d0 = dot(e0, e0), d1 = dot(e1, e1), d2 = dot(e2, e2);
  if (d0 > 0.0f) k += dot(n1 - n0, e0) / d0;
  if (d1 > 0.0f) k += dot(n2 - n1, e1) / d1;
  if (d2 > 0.0f) k += dot(n0 - n2, e2) / d2;
  return k * (1.0f / 3.0f);
}

/* The cone's width across a hit at distance t along its ray. */
static inline float cone_width_at(float2 cone, float t) {
  return cone.x + cone.y * t;
}

/* The spread of the cone that leaves a surface of curvature k (triangle_curvature) hit `width`
 * across, before the lobe's own spread: a mirror there bends the rays across the footprint by
 * twice the normal's turn, 2 k |width|. */
static inline float cone_spread_curved(float spread, float k, float width) {
  return spread + 2.0f * k * fabs(width);
}

/* The spread a sample of solid-angle density pdf adds (0 for a delta lobe: pdf 0). */
static inline float lobe_spread(float pdf) {
  return pdf > 0.0f ? WP_CONE_SCALE * fmin(2.0f * rsqrt(M_PI_F * pdf), M_PI_F) : 0.0f;
}

/* log2 of the cone's footprint at a hit, per texture coordinate set (x: TEXCOORD_0, y:
 * TEXCOORD_1), without the texture's own term (its 1/2 log2(W H |det T|), TextureRef.meta.w):
 * log2 |width| + 1/2 log2(A_uv / A_world), the footprint's minor axis (the file comment says why
 * not its major one). twice_area is |cross(p1 - p0, p2 - p0)|, the uv's are the three vertices'
 * (xy set 0, zw set 1). -INFINITY (level 0) for a zero width. */
static inline float2 footprint_lod(float width, float twice_area, float4 uv0, float4 uv1,
                                   float4 uv2) {
  const float4 a = uv1 - uv0, b = uv2 - uv0;
  const float2 uv_area = fabs((float2)(a.x * b.y - a.y * b.x, a.z * b.w - a.w * b.z));
  const float base = log2_poly(fabs(width)) - 0.5f * log2_poly(twice_area);
  return base + 0.5f * (float2)(log2_poly(uv_area.x), log2_poly(uv_area.y));
}
#endif

#endif /* WP_RAY_CONE_H */
