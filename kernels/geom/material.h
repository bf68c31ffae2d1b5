/* Materials at a hit point: the surface record the BSDF works on, and the emitted radiance.
 *
 * resolve_surface() interpolates the triangle's attributes at barycentrics (u, v) and evaluates
 * the material there. Textures (base colour, metallic-roughness, normal, emissive, transmission),
 * KHR_texture_transform and KHR_materials_unlit are resolved here and nowhere else (alpha, which
 * decides whether a hit counts at all, in alpha.h). Each texture multiplies its factor, as glTF
 * specifies; everything texture-related compiles only with WP_FEATURE_TEXTURES (normal maps:
 * WP_FEATURE_NORMAL_MAPS). */
#ifndef WP_MATERIAL_H
#define WP_MATERIAL_H

#include "bsdf/bsdf.h"
#include "instance.h"
#include "texture/ray_cone.h"
#include "scene.h"
#include "texture/textures.h"

static inline float3 interpolate3(__global const float4* a, uint4 tv, float u, float v) {
  return (1.0f - u - v) * a[tv.x].xyz + u * a[tv.y].xyz + v * a[tv.z].xyz;
}

static inline float4 interpolate4(__global const float4* a, uint4 tv, float u, float v) {
  return (1.0f - u - v) * a[tv.x] + u * a[tv.y] + v * a[tv.z];
}

/* Emitted radiance of triangle `tri`'s material at barycentrics (u, v), whichever side:
 * emissive factor (x strength) x emissive texture. */
static inline float3 material_emission(const SceneView* scene, uint4 tv, float u, float v) {
  __global const Material* m = scene->materials + tv.w;
  float3 e = m->emission.xyz;
#if WP_FEATURE_TEXTURES
  const int tex = m->textures0.w;
  if (tex >= 0 && max3(e) > 0.0f)
    e *= texture_sample(scene, tex, interpolate4(scene->uvs, tv, u, v)).xyz;
#else
  (void)u;
  (void)v;
#endif
  return e;
}

#if WP_FEATURE_NORMAL_MAPS || WP_FEATURE_ANISOTROPY || WP_FEATURE_CLEARCOAT
/* The tangent frame at the point: tangent t (the interpolated vertex tangent made orthogonal to
 * n, the interpolated vertex normal on the front side) and bitangent cross(n, t) * w (glTF's
 * convention; w the handedness). Without a usable tangent any frame around n: a map's orientation
 * is lost there, not its tilt. */
static inline void tangent_frame(const SceneView* scene, uint inst, uint4 tv, float u, float v,
                                 float3 n, float3* t, float3* b) {
#if WP_BVH_INSTANCES
  const float4 t4 = (1.0f - u - v) * placed_tangent(scene, inst, tv.x) +
                    u * placed_tangent(scene, inst, tv.y) + v * placed_tangent(scene, inst, tv.z);
#else
  (void)inst;
  const float4 t4 = interpolate4(scene->tangents, tv, u, v);
#endif
  *t = t4.xyz - n * dot(n, t4.xyz);
  const float len = length(*t);
  if (len > 1e-6f) {
    *t /= len;
    *b = cross(n, *t) * (t4.w < 0.0f ? -1.0f : 1.0f);
  } else {
    make_basis(n, t, b);
  }
}
#endif

#if WP_FEATURE_NORMAL_MAPS || WP_FEATURE_CLEARCOAT
/* The normal of normal texture `tex` at the point, in the front side's frame: the tangent-space
 * normal (texel * 2 - 1, x and y times `scale`) in the tangent frame around n. */
static inline float3 normal_mapped(const SceneView* scene, int tex, float scale, uint inst,
                                   uint4 tv, float u, float v, TexPoint tp, float3 n) {
  float3 t, b;
  tangent_frame(scene, inst, tv, u, v, n, &t, &b);
  float3 c = texture_at(scene, tex, tp).xyz * 2.0f - 1.0f;
  c.xy *= scale;
  const float3 p = c.x * t + c.y * b + c.z * n;
  const float lp = length(p);
  return lp > 0.0f ? p / lp : n;
}

/* A normal-mapped normal ns can tilt so far from the geometric normal ng that the mirror
 * reflection of the direction to the viewer wo about it points below the surface, where the BSDF
 * has nothing to give: strongly tilted texels would turn black (a rasterizer still shows a
 * reflection there). As Blender Cycles does, bend ns toward ng just enough that this reflection
 * stays a little above the surface: the result is the half vector between wo and the reflection
 * lifted to height `lift` above the tangent plane. ns is returned unchanged otherwise. */
static inline float3 keep_reflection_above(float3 ns, float3 ng, float3 wo) {
  const float3 r = 2.0f * dot(wo, ns) * ns - wo;
  const float lift = fmin(0.9f * dot(wo, ng), 0.01f);
  if (dot(r, ng) >= lift) return ns;
  const float3 rt = r - ng * dot(r, ng); /* the reflection's part in the tangent plane */
  const float lt = length(rt);
  if (!(lt > 0.0f)) return ng;
  return normalize(wo + rt * (sqrt(1.0f - lift * lift) / lt) + lift * ng);
}
#endif

/* Base colour, metallic, roughness and transmission: factors x textures x vertex colour. */
static inline void resolve_material(const SceneView* scene, __global const Material* m, uint4 tv,
                                    float u, float v, TexPoint tp, Surface* s) {
  float3 color = m->base_color.xyz;
#if WP_FEATURE_VERTEX_COLORS
  color *= interpolate3(scene->colors, tv, u, v);
#else
  (void)tv, (void)u, (void)v; /* only vertex colours need the triangle (-Wunused-parameter) */
#endif
  const float4 q = m->params;
  s->metallic = q.x;
  s->roughness = q.y;
  s->ior = q.z;
  s->transmission = q.w;
  s->specular = m->specular.w; /* KHR_materials_specular factor */
#if WP_FEATURE_TEXTURES
  const int4 tex = m->textures0;
  if (tex.x >= 0) color *= texture_at(scene, tex.x, tp).xyz;
  if (tex.y >= 0) {
    const float4 mr = texture_at(scene, tex.y, tp); /* B: metallic, G: roughness */
    s->metallic *= mr.z;
    s->roughness *= mr.y;
  }
  if (m->textures1.x >= 0) s->transmission *= texture_at(scene, m->textures1.x, tp).x;
#else
  (void)tp, (void)scene;
#endif
  s->color = color;
}

/* Any material extension beyond metallic-roughness in the program. */
#define WP_BSDF_EXTENSIONS                                                                     \
  (WP_FEATURE_SPECULAR || WP_FEATURE_CLEARCOAT || WP_FEATURE_SHEEN || WP_FEATURE_ANISOTROPY || \
   WP_FEATURE_IRIDESCENCE || WP_FEATURE_DIFFUSE_TRANSMISSION || WP_FEATURE_DISPERSION)

#if WP_BSDF_EXTENSIONS
/* A texture's texel at the point, or 1 without the texture (or without textures in the
 * program): what multiplies a factor, as glTF specifies. */
static inline float4 texel_or_one(const SceneView* scene, int tex, TexPoint tp) {
#if WP_FEATURE_TEXTURES
  if (tex >= 0) return texture_at(scene, tex, tp);
#else
  (void)scene, (void)tex, (void)tp;
#endif
  return (float4)(1.0f);
}

/* The material extensions at the point, each only in programs with its feature: factors x
 * textures, the coat normal (the interpolated normal n_front, or the coat's normal texture, turned
 * to the side of wo like ns) and the anisotropy direction (the rotation and the texture's
 * direction in the tangent frame, made perpendicular to ns; a strength of 0 where no direction
 * is left). */
static inline void resolve_extensions(const SceneView* scene, __global const Material* m, uint inst,
                                      uint4 tv, float u, float v, TexPoint tp, float3 n_front,
                                      float3 wo, Surface* s) {
  (void)scene, (void)inst, (void)tv, (void)u, (void)v, (void)tp, (void)n_front, (void)wo;
#if WP_FEATURE_SPECULAR
  s->specular *= texel_or_one(scene, m->textures1.y, tp).w;
  s->specular_color = m->specular.xyz * texel_or_one(scene, m->textures1.z, tp).xyz;
#endif
#if WP_FEATURE_CLEARCOAT
  s->clearcoat = m->clearcoat.x * texel_or_one(scene, m->textures1.w, tp).x;
  s->clearcoat_roughness = m->clearcoat.y * texel_or_one(scene, m->textures2.x, tp).y;
  float3 nc = n_front;
#if WP_FEATURE_TEXTURES
  const bool coat_mapped = m->textures2.y >= 0;
  if (coat_mapped)
    nc = normal_mapped(scene, m->textures2.y, m->clearcoat.z, inst, tv, u, v, tp, nc);
#endif
  if (dot(nc, s->ng) < 0.0f) nc = -nc;
#if WP_FEATURE_TEXTURES
  if (coat_mapped) nc = keep_reflection_above(nc, s->ng, wo);
#endif
  s->nc = dot(nc, wo) > 1e-4f ? nc : s->ng;
#endif
#if WP_FEATURE_SHEEN
  const float4 sheen_c = texel_or_one(scene, m->textures2.z, tp);
  s->sheen_color = m->sheen.xyz * sheen_c.xyz;
  s->sheen_roughness = m->sheen.w * texel_or_one(scene, m->textures2.w, tp).w;
#endif
#if WP_FEATURE_ANISOTROPY
  float strength = m->anisotropy.x;
  float2 dir = m->anisotropy.yz; /* (cos, sin) of the rotation */
#if WP_FEATURE_TEXTURES
  if (m->textures3.x >= 0) {
    const float4 a = texture_at(scene, m->textures3.x, tp);
    const float2 d = a.xy * 2.0f - 1.0f; /* rotated by the rotation */
    dir = (float2)(dir.x * d.x - dir.y * d.y, dir.y * d.x + dir.x * d.y);
    strength *= a.z;
  }
#endif
  s->anisotropy = 0.0f, s->aniso_t = (float3)(0.0f); /* no direction: isotropic */
  if (strength > 0.0f) {
    float3 t, b;
    tangent_frame(scene, inst, tv, u, v, n_front, &t, &b);
    float3 d = dir.x * t + dir.y * b;
    d -= s->ns * dot(s->ns, d);
    const float len = length(d);
    if (len > 1e-6f) s->aniso_t = d / len, s->anisotropy = fmin(strength, 1.0f);
  }
#endif
#if WP_FEATURE_IRIDESCENCE
  s->iridescence = m->iridescence.x * texel_or_one(scene, m->textures3.y, tp).x;
  s->iridescence_ior = m->iridescence.y;
  s->iridescence_thickness = m->iridescence.w;
#if WP_FEATURE_TEXTURES
  if (m->textures3.z >= 0)
    s->iridescence_thickness =
        mix(m->iridescence.z, m->iridescence.w, texture_at(scene, m->textures3.z, tp).y);
#endif
#endif
#if WP_FEATURE_DIFFUSE_TRANSMISSION
  s->diffuse_transmission = m->diffuse_transmission.w * texel_or_one(scene, m->textures3.w, tp).w;
  s->dt_color = m->diffuse_transmission.xyz * texel_or_one(scene, m->textures4.x, tp).xyz;
#endif
#if WP_FEATURE_DISPERSION
  s->dispersion = m->extra.w;
  s->channel = 0u; /* the path's, set by the integrator (shade_hit, surface_load) */
#endif
}
#endif

/* The texture coordinates at barycentrics (u, v) of triangle tv and, with WP_FEATURE_TEXTURE_LOD,
 * the footprint there of a ray cone `cone_width` across (twice_area: |cross(p1 - p0, p2 - p0)|;
 * ray_cone.h). */
static inline TexPoint texture_point(const SceneView* scene, uint4 tv, float u, float v,
                                     float cone_width, float twice_area) {
  TexPoint tp;
#if WP_FEATURE_TEXTURES || WP_FEATURE_NORMAL_MAPS || WP_BSDF_EXTENSIONS
  tp.uv = interpolate4(scene->uvs, tv, u, v);
#else
  (void)scene, (void)tv, (void)u, (void)v;
  tp.uv = (float4)(0.0f);
#endif
#if WP_FEATURE_TEXTURE_LOD
  tp.lod =
      footprint_lod(cone_width, twice_area, scene->uvs[tv.x], scene->uvs[tv.y], scene->uvs[tv.z]);
#else
  (void)cone_width, (void)twice_area;
#endif
  return tp;
}

/* Geometry and material at a hit of a ray with direction ray_d on triangle `tri` of instance
 * `inst` (instance.h) at barycentrics (u, v), reached by a ray cone `cone_width` across there
 * (ray_cone.h; 0: full-resolution textures). *front tells whether the ray hit the front
 * (counter-clockwise) side; both normals are turned to face the ray. */
static inline Surface resolve_surface(const SceneView* scene, uint inst, uint tri, float u, float v,
                                      float3 ray_d, float cone_width, bool* front) {
  const uint4 tv = placed_triangle(scene, inst, tri, &u, &v);
  __global const Material* m = scene->materials + tv.w;
  Surface s;
  const float3 p0 = placed_position(scene, inst, tv.x);
  const float3 p1 = placed_position(scene, inst, tv.y);
  const float3 p2 = placed_position(scene, inst, tv.z);
  s.p = (1.0f - u - v) * p0 + u * p1 + v * p2;
  s.p_scale = max3(fabs((1.0f - u - v) * p0) + fabs(u * p1) + fabs(v * p2));
  const float3 n = cross(p1 - p0, p2 - p0);
  const float len = length(n);
  s.ng = len > 0.0f ? n / len : -ray_d; /* a degenerate triangle faces the ray */
  *front = dot(s.ng, ray_d) < 0.0f;
  if (!*front) s.ng = -s.ng;
  const TexPoint tp = texture_point(scene, tv, u, v, cone_width, len);
#if WP_FEATURE_TEXTURE_LOD
  s.curvature =
      triangle_curvature(p0, p1, p2, placed_normal(scene, inst, tv.x),
                         placed_normal(scene, inst, tv.y), placed_normal(scene, inst, tv.z));
  if (!*front) s.curvature = -s.curvature; /* the normals point to the front side */
#endif
#if WP_BVH_INSTANCES
  const float3 n_front =
      normalize((1.0f - u - v) * placed_normal(scene, inst, tv.x) +
                u * placed_normal(scene, inst, tv.y) + v * placed_normal(scene, inst, tv.z));
#else
  const float3 n_front = normalize(interpolate3(scene->normals, tv, u, v));
#endif
  s.ns = n_front;
#if WP_FEATURE_NORMAL_MAPS
  if (m->textures0.z >= 0)
    s.ns = normal_mapped(scene, m->textures0.z, m->extra.x, inst, tv, u, v, tp, n_front);
#endif
  /* Computed on the front side's frame; turned, like the interpolated normal, to the side the
   * ray sees (for a back-side hit that mirrors the whole front-side frame). */
  if (dot(s.ns, s.ng) < 0.0f) s.ns = -s.ns;
#if WP_FEATURE_NORMAL_MAPS
  if (m->textures0.z >= 0) s.ns = keep_reflection_above(s.ns, s.ng, -ray_d);
#endif
  /* An interpolated normal can face away from the viewer near silhouettes; shading with it would
   * reflect into the surface. Fall back to the true normal there. */
  if (!(dot(s.ns, -ray_d) > 1e-4f)) s.ns = s.ng;
  resolve_material(scene, m, tv, u, v, tp, &s);
#if WP_BSDF_EXTENSIONS
  resolve_extensions(scene, m, inst, tv, u, v, tp, n_front, -ray_d, &s);
#endif
  s.flags = *front ? WP_SURF_FRONT : 0u;
#if WP_FEATURE_UNLIT
  if (m->flags.x & WP_MAT_UNLIT) s.flags |= WP_SURF_UNLIT;
#endif
#if WP_FEATURE_VOLUME
  if (m->flags.x & WP_MAT_VOLUME) s.flags |= WP_SURF_VOLUME;
#endif
  return s;
}

#if WP_SHADE_PACKET
/* interpolate3 of eight lanes (common.h, Float3x8), the lanes' values at the corners given. */
WP_LANES_FN Float3x8 interpolate3x8(Float3x8 a0, Float3x8 a1, Float3x8 a2, float8 u, float8 v) {
  Float3x8 r = {(1.0f - u - v) * a0.x + u * a1.x + v * a2.x,
                (1.0f - u - v) * a0.y + u * a1.y + v * a2.y,
                (1.0f - u - v) * a0.z + u * a1.z + v * a2.z};
  return r;
}

/* resolve_surface of eight lanes for a program of untextured materials without instances whose
 * BSDF is Lambert's or WP_BSDF_PLAIN's (shade_packet.h): triangle tri[i] hit at (u, v) by a ray
 * along ray_d, lane by lane; its vertices and material in tv[i]. */
WP_LANES_FN Surface8 resolve_surface8(const SceneView* scene, const uint* tri, float8 u, float8 v,
                                      Float3x8 ray_d, uint4* tv) {
  uint i0[8], i1[8], i2[8];
  float4 c[8];
#if WP_FEATURE_GLOSSY
  float4 q[8];
  float specular[8];
#endif
#pragma unroll
  for (int i = 0; i < 8; ++i) {
    tv[i] = scene->tri_vertices[tri[i]];
    i0[i] = tv[i].x, i1[i] = tv[i].y, i2[i] = tv[i].z;
    c[i] = scene->materials[tv[i].w].base_color;
#if WP_FEATURE_GLOSSY
    q[i] = scene->materials[tv[i].w].params;
    specular[i] = scene->materials[tv[i].w].specular.w;
#endif
  }
  const Float3x8 p0 = gather3x8(scene->positions, i0), p1 = gather3x8(scene->positions, i1),
                 p2 = gather3x8(scene->positions, i2);
  Surface8 s;
  s.p = interpolate3x8(p0, p1, p2, u, v);
  s.p_scale = fmax(fabs((1.0f - u - v) * p0.x) + fabs(u * p1.x) + fabs(v * p2.x),
                   fmax(fabs((1.0f - u - v) * p0.y) + fabs(u * p1.y) + fabs(v * p2.y),
                        fabs((1.0f - u - v) * p0.z) + fabs(u * p1.z) + fabs(v * p2.z)));
  const Float3x8 n = cross3x8(sub3x8(p1, p0), sub3x8(p2, p0));
  const float8 len = length3x8(n);
  s.ng = select3x8(neg3x8(ray_d), div3x8(n, len), len > 0.0f);
  s.front = dot3x8(s.ng, ray_d) < 0.0f;
  s.ng = select3x8(neg3x8(s.ng), s.ng, s.front);
  const Float3x8 n_front =
      normalize3x8(interpolate3x8(gather3x8(scene->normals, i0), gather3x8(scene->normals, i1),
                                  gather3x8(scene->normals, i2), u, v));
  s.ns = select3x8(n_front, neg3x8(n_front), dot3x8(n_front, s.ng) < 0.0f);
  s.ns = select3x8(s.ng, s.ns, dot3x8(s.ns, neg3x8(ray_d)) > 1e-4f);
  float8 unused;
  transpose4x8(c, &s.color.x, &s.color.y, &s.color.z, &unused);
#if WP_FEATURE_GLOSSY /* resolve_material's (no transmission: WP_BSDF_PLAIN) */
  transpose4x8(q, &s.metallic, &s.roughness, &s.ior, &unused);
  s.specular = vload8(0, specular);
#endif
  return s;
}

/* Lane i of *s as resolve_surface gives it (for the functions of one path): the material's part
 * read again. */
WP_LANES_FN Surface surface_lane(const SceneView* scene, const Surface8* s, uint4 tv, int i) {
  Surface r;
  r.p = lane3(s->p, i);
  r.p_scale = lane_of(s->p_scale, i);
  r.ng = lane3(s->ng, i);
  r.ns = lane3(s->ns, i);
  TexPoint tp;
  tp.uv = (float4)(0.0f);
  resolve_material(scene, scene->materials + tv.w, tv, 0.0f, 0.0f, tp, &r);
  r.flags = lane_set(s->front, i) ? WP_SURF_FRONT : 0u;
  return r;
}
#endif

#endif /* WP_MATERIAL_H */
