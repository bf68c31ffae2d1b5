/* Texture sampling: a material's TextureRef (shared/types.h) at a point's texture coordinates.
 *
 * texture_sample() follows glTF's sampler semantics (those of OpenGL): KHR_texture_transform's
 * 2x3 matrix on the chosen TEXCOORD set, texel centres at ((i + 0.5) / width, (j + 0.5) / height)
 * with uv (0, 0) the top-left corner of the image, wrap modes REPEAT, CLAMP_TO_EDGE and
 * MIRRORED_REPEAT applied per axis to texel indices, and magnification filter NEAREST (the texel
 * containing the point) or LINEAR (bilinear over the four nearest texel centres). sRGB colour
 * textures are decoded with the exact sRGB EOTF per texel before filtering, so filtering averages
 * linear values; alpha is always linear.
 *
 * Minification: with WP_FEATURE_TEXTURE_LOD (--mipmaps on, the default, and a texture whose
 * sampler's minFilter is a mip-map mode or unset) a texture is looked up at the level of detail of
 * the path's ray cone (ray_cone.h), trilinearly in the host's mip chain (host/scene/mipmap.cpp):
 * a surface far away shows the mean of its texels instead of noise that only many samples average
 * away. Without it the minification filter is ignored: the pixel's average over many jittered
 * samples supersamples the texture (converging to the box-filtered footprint, noisily at low spp).
 */
#ifndef WP_TEXTURES_H
#define WP_TEXTURES_H

#include "geom/scene.h"
#include "srgb_lut.h"

/* Texel (x, y) of `img` (both in range) as RGBA in [0, 1], decoded to linear when srgb. */
static inline float4 texel_fetch(__global const uint* texels, TextureImage img, int x, int y,
                                 bool srgb) {
  const uint p = texels[img.offset + (uint)y * img.width + (uint)x];
  float4 c = (float4)((float)(p & 0xffu), (float)((p >> 8) & 0xffu), (float)((p >> 16) & 0xffu),
                      (float)(p >> 24)) *
             (1.0f / 255.0f);
  if (srgb) /* the table holds the sRGB EOTF of every code (srgb_lut.h) */
    c.xyz = (float3)(wp_srgb_lut[p & 0xffu], wp_srgb_lut[(p >> 8) & 0xffu],
                     wp_srgb_lut[(p >> 16) & 0xffu]);
  return c;
}

/* Texel index i (any integer) wrapped into [0, n) by WP_WRAP_* `mode`. */
static inline int wrap_texel(int i, int n, uint mode) {
  if (mode == WP_WRAP_CLAMP) return clamp(i, 0, n - 1);
  if (mode == WP_WRAP_MIRROR) {
    int m = i % (2 * n);
    if (m < 0) m += 2 * n;
    return m < n ? m : 2 * n - 1 - m;
  }
  int m = i % n;
  return m < 0 ? m + n : m;
}

/* A texture coordinate moved by whole wrap periods (1 for REPEAT, 2 for MIRRORED_REPEAT) into a
 * small range, or clamped just outside [0, 1] for CLAMP_TO_EDGE, so that texel indices computed
 * from it fit an int; wrap_texel then gives the same texels as for the original coordinate.
 * Coordinates beyond +-2^24 are taken as +-2^24 first: float32 holds only even integers there,
 * which both periods map to 0, as they map 2^24, so no finite coordinate's texel changes; an
 * infinite one (a transform of scale 3e38 times a coordinate above 1) or NaN becomes a texel too
 * (fmax and fmin return the other operand for NaN), where inf - floor(inf) was NaN. */
static inline float wrap_reduce(float u, uint mode) {
  if (mode == WP_WRAP_CLAMP) return fmin(fmax(u, -1.0f), 2.0f);
  u = fmin(fmax(u, -16777216.0f), 16777216.0f);
  if (mode == WP_WRAP_MIRROR) return u - 2.0f * floor(0.5f * u);
  return u - floor(u);
}

/* Bilinear lookup at texel-space position (x, y) of image (or mip level) img: the four texel
 * centres around it, each wrapped. */
static inline float4 texel_bilinear(__global const uint* texels, TextureImage img, float x, float y,
                                    uint wrap_s, uint wrap_t, bool srgb) {
  const int w = (int)img.width, h = (int)img.height;
  const float fx = x - 0.5f, fy = y - 0.5f; /* relative to texel centres */
  const float x0 = floor(fx), y0 = floor(fy);
  const float ax = fx - x0, ay = fy - y0;
  const int i0 = wrap_texel((int)x0, w, wrap_s), i1 = wrap_texel((int)x0 + 1, w, wrap_s);
  const int j0 = wrap_texel((int)y0, h, wrap_t), j1 = wrap_texel((int)y0 + 1, h, wrap_t);
  const float4 top =
      mix(texel_fetch(texels, img, i0, j0, srgb), texel_fetch(texels, img, i1, j0, srgb), ax);
  const float4 bottom =
      mix(texel_fetch(texels, img, i0, j1, srgb), texel_fetch(texels, img, i1, j1, srgb), ax);
  return mix(top, bottom, ay);
}

/* A texture reference resolved for one lookup: its image, sampler and the point's coordinates,
 * transformed and wrapped (texel-space position = st x the level's size). */
typedef struct TexLookup {
  TextureImage img;
  float2 st;
  uint meta_y;     /* wrap S, wrap T, WP_TEX_* flags */
  uint level_term; /* TextureRef.meta.w */
  uint set;        /* texture coordinate set */
} TexLookup;

/* Texture `ref` at the vertex texture coordinates uv01 (xy: TEXCOORD_0, zw: TEXCOORD_1). */
static inline TexLookup texture_lookup(const SceneView* scene, int ref, float4 uv01) {
  __global const TextureRef* t = scene->textures + ref;
  const uint4 meta = t->meta;
  TexLookup l;
  l.img = scene->images[meta.x];
  l.meta_y = meta.y;
  l.level_term = meta.w;
  l.set = meta.z;
  const float2 uv = meta.z == 1u ? uv01.zw : uv01.xy;
  const float4 ru = t->transform_u, rv = t->transform_v;
  l.st = (float2)(wrap_reduce(ru.x * uv.x + ru.y * uv.y + ru.z, meta.y & 0xffu),
                  wrap_reduce(rv.x * uv.x + rv.y * uv.y + rv.z, (meta.y >> 8) & 0xffu));
  return l;
}

/* Lookup l at level `img` (the image or one of its mip levels), bilinear, or NEAREST with
 * `nearest`. Always inlined, as texture_at is: clang kept both out of line in the shading kernel,
 * where a model's lookups (base colour, metal-roughness, normal, emission) then ran one call after
 * another, each waiting on its texels; inlined, their loads overlap (DamagedHelmet 1.12x the
 * samples/s on PoCL, docs/performance.md, "Texture lookups inlined"). */
static inline __attribute__((always_inline)) float4 texel_filtered(__global const uint* texels,
                                                                   TexLookup l, TextureImage img,
                                                                   bool nearest) {
  const uint wrap_s = l.meta_y & 0xffu, wrap_t = (l.meta_y >> 8) & 0xffu;
  const bool srgb = (l.meta_y & WP_TEX_SRGB) != 0u;
  const int w = (int)img.width, h = (int)img.height;
  /* Texel-space position: texel i covers [i, i + 1), its centre at i + 0.5. */
  const float x = l.st.x * (float)w, y = l.st.y * (float)h;
  if (nearest) {
    const int i = wrap_texel((int)floor(x), w, wrap_s), j = wrap_texel((int)floor(y), h, wrap_t);
    return texel_fetch(texels, img, i, j, srgb);
  }
  return texel_bilinear(texels, img, x, y, wrap_s, wrap_t, srgb);
}

/* Texture `ref` at the vertex texture coordinates uv01 (xy: TEXCOORD_0, zw: TEXCOORD_1), at full
 * resolution (level 0) with the sampler's magnification filter. */
static inline float4 texture_sample(const SceneView* scene, int ref, float4 uv01) {
  const TexLookup l = texture_lookup(scene, ref, uv01);
  return texel_filtered(scene->texels, l, l.img, (l.meta_y & WP_TEX_NEAREST) != 0u);
}

/* A point's texture coordinates, and with WP_FEATURE_TEXTURE_LOD the log2 of its ray cone's
 * footprint per coordinate set (ray_cone.h; -INFINITY: full resolution). */
typedef struct TexPoint {
  float4 uv; /* xy: TEXCOORD_0, zw: TEXCOORD_1 */
#if WP_FEATURE_TEXTURE_LOD
  float2 lod;
#endif
} TexPoint;

#if WP_FEATURE_TEXTURE_LOD
/* Mip level `level` of img (TextureImage.levels of them, level 0 the image;
 * host/scene/mipmap.cpp): each level halves the one before, rounding down, and follows it in the
 * texel array. */
static inline TextureImage mip_level(TextureImage img, uint level) {
  for (uint k = 0u; k < level; ++k) {
    img.offset += img.width * img.height;
    img.width = max(img.width >> 1, 1u);
    img.height = max(img.height >> 1, 1u);
  }
  return img;
}

/* Texture `ref` at a point seen through a ray cone: at its footprint's level lambda (the point's
 * lod for the texture's coordinate set plus the texture's own term, TextureRef.meta.w), bilinear
 * in the two levels around lambda and linear between them (trilinear); where lambda <= 0, or the
 * texture has no mip-maps (meta.w = -INFINITY), texture_sample's full-resolution lookup. */
static inline float4 texture_sample_lod(const SceneView* scene, int ref, float4 uv01, float2 lod) {
  const TexLookup l = texture_lookup(scene, ref, uv01);
  const float lambda = (l.set == 1u ? lod.y : lod.x) + as_float(l.level_term);
  if (!(lambda > 0.0f) || l.img.levels < 2u)
    return texel_filtered(scene->texels, l, l.img, (l.meta_y & WP_TEX_NEAREST) != 0u);
  const float last = (float)(l.img.levels - 1u);
  const float m = fmin(lambda, last);
  const float m0 = floor(m);
  const TextureImage a = mip_level(l.img, (uint)m0);
  const float4 ca = texel_filtered(scene->texels, l, a, false);
  if (m0 >= last) return ca;
  return mix(ca, texel_filtered(scene->texels, l, mip_level(a, 1u), false), m - m0);
}
#endif

/* Texture `ref` at point tp: through its ray cone with WP_FEATURE_TEXTURE_LOD, else at full
 * resolution. */
static inline __attribute__((always_inline)) float4 texture_at(const SceneView* scene, int ref,
                                                               TexPoint tp) {
#if WP_FEATURE_TEXTURE_LOD
  return texture_sample_lod(scene, ref, tp.uv, tp.lod);
#else
  return texture_sample(scene, ref, tp.uv);
#endif
}

#endif /* WP_TEXTURES_H */
