/* Light sampling for next-event estimation, and the densities MIS needs for lights that BSDF
 * sampling found.
 *
 * Level 1: one light per shading point from the alias table (host/lights/light_table.h documents
 * the uniform and power-proportional probabilities); with few lights the pick reuses the first
 * coordinate of the point's 2D number (sample_light). Then, per light:
 * - punctual (KHR_lights_punctual), delta distributions: a point/spot intensity is radiant
 *   intensity in W/sr, giving irradiance I / d^2 (spot: times the recommended cone falloff); a
 *   directional light's intensity is irradiance in W/m^2;
 * - emissive triangle: a point uniform in its area, pdf 1/A converted to solid angle,
 *   d^2 / (A |cos theta_light|). The emitting side follows the glTF winding: the front face emits,
 *   the back face only when the material is double-sided (the same rule shade_surface applies to
 *   hits), and an emitter with alpha (MASK, BLEND) emits only with the probability that a ray
 *   finds it there (alpha.h, alpha_coverage);
 * - environment: environment.h's sampling, pdf in solid angle.
 * The returned pdf includes the light-choice probability. */
#ifndef WP_LIGHTS_H
#define WP_LIGHTS_H

#include "util/common.h"
#include "traversal/alpha.h"
#include "environment.h"
#include "geom/material.h"

typedef struct LightSample {
  float3 wi;     /* unit direction from the shading point toward the light */
  float dist;    /* distance to the light point (INFINITY for directional and environment) */
  float3 li;     /* arriving radiance (area, environment) or irradiance (delta lights), before the
                    cosine at the receiver and not divided by the pdf */
  float pdf;     /* solid-angle pdf incl. the light choice; for delta lights the choice pmf alone */
  bool delta;    /* a delta light: no BSDF sample can find it (MIS weight 1) */
  float3 target; /* where a shadow ray stops (finite dist only): the light point, moved off an
                    area light's surface toward the shading point so the ray cannot hit it */
} LightSample;

/* The light that u in (0, 1) picks from the alias table, its probability in *pmf, and in *rest
 * what is left of u within the pick: uniform in [0, 1) for each light picked, so it can serve as
 * a coordinate of the point on it (sample_light). */
static inline uint pick_light(const SceneView* scene, float u, float* pmf, float* rest) {
  const uint n = scene->desc->light_count;
  const float x = u * (float)n;
  const uint i = min((uint)x, n - 1u);
  const LightAlias e = scene->light_alias[i];
  const float f = x - (float)i;
  const bool own = f < e.prob;
  const uint chosen = own ? i : e.alias;
  *rest = fmin(own ? f / e.prob : (f - e.prob) / (1.0f - e.prob), 0x1.fffffep-1f);
  *pmf = scene->light_alias[chosen].pmf;
  return chosen;
}

#if WP_SHADE_PACKET
/* pick_light of eight numbers (common.h), the same expressions lane by lane: both of *rest's
 * quotients are computed and the one pick_light takes is kept. */
WP_LANES_FN uint8 pick_light8(const SceneView* scene, float8 u, float8* pmf, float8* rest) {
  const uint n = scene->desc->light_count;
  const float8 x = u * (float)n;
  const uint8 i = min(convert_uint8(x), (uint8)(n - 1u)); /* truncates, as (uint)x does */
  __global const float* table = (__global const float*)scene->light_alias;
  uint index[8];
  vstore8(i, 0, index);
  float4 entry[8];
#pragma unroll
  for (int k = 0; k < 8; ++k) entry[k] = vload4(index[k], table);
  float8 prob, alias, unused_pmf, unused_pad;
  transpose4x8(entry, &prob, &alias, &unused_pmf, &unused_pad);
  const float8 f = x - convert_float8(i);
  const int8 own = f < prob;
  const uint8 chosen = select(as_uint8(alias), i, as_uint8(own));
  *rest = fmin(select((f - prob) / (1.0f - prob), f / prob, own), 0x1.fffffep-1f);
  uint c[8];
  vstore8(chosen, 0, c);
  float p[8];
#pragma unroll
  for (int k = 0; k < 8; ++k) p[k] = scene->light_alias[c[k]].pmf;
  *pmf = vload8(0, p);
  return chosen;
}
#endif

/* KHR_lights_punctual's recommended range window, applied only when a range is given. */
static inline float range_window(float dist, float range) {
  if (range <= 0.0f) return 1.0f;
  const float q = dist / range, q2 = q * q;
  return clamp(1.0f - q2 * q2, 0.0f, 1.0f);
}

static inline LightSample sample_punctual(__global const Light* light, float3 p) {
  LightSample s;
  s.delta = true;
  s.pdf = 1.0f;
  if (light->meta.x == WP_LIGHT_DIRECTIONAL) {
    s.wi = -light->direction.xyz;
    s.dist = INFINITY;
    s.li = light->intensity.xyz;
    return s;
  }
  const float4 pos = light->position;
  const float3 to_light = pos.xyz - p;
  s.target = pos.xyz;
  const float d2 = dot(to_light, to_light);
  s.dist = sqrt(d2);
  s.wi = to_light / s.dist;
  s.li = light->intensity.xyz * (range_window(s.dist, pos.w) / d2);
#if WP_FEATURE_SPOT_LIGHTS
  if (light->meta.x == WP_LIGHT_SPOT) {
    const float cd = dot(light->direction.xyz, -s.wi);
    const float a = clamp(cd * light->spot.x + light->spot.y, 0.0f, 1.0f);
    s.li *= a * a;
  }
#endif
  return s;
}

/* Solid-angle density of reaching point q of triangle `tv` (area-uniform sampling) from distance
 * `dist` along a direction making cos_light with the triangle's normal. */
static inline float triangle_solid_angle_pdf(float area, float dist, float cos_light) {
  return dist * dist / (area * fabs(cos_light));
}

/* A point on triangle `tri` of instance `inst` (instance.h) for the shading point p. */
static inline LightSample sample_triangle(const SceneView* scene, uint inst, uint tri, float3 p,
                                          float2 u) {
  LightSample s;
  s.delta = false;
  s.pdf = 0.0f;
  s.li = (float3)(0.0f);
  float no_u = 0.0f, no_v = 0.0f;
  const uint4 tv = placed_triangle(scene, inst, tri, &no_u, &no_v);
  const float3 p0 = placed_position(scene, inst, tv.x);
  const float3 e1 = placed_position(scene, inst, tv.y) - p0;
  const float3 e2 = placed_position(scene, inst, tv.z) - p0;
  /* Uniform over the area: b1 = 1 - sqrt(u1)... written as barycentrics of v1 and v2. */
  const float r = sqrt(u.x);
  const float b1 = r * (1.0f - u.y), b2 = r * u.y;
  const float3 q = p0 + b1 * e1 + b2 * e2;
  const float3 p1 = p0 + e1, p2 = p0 + e2;
  const float q_scale = max3(fabs((1.0f - b1 - b2) * p0) + fabs(b1 * p1) + fabs(b2 * p2));
  const float3 n = cross(e1, e2);
  const float area2 = length(n);
  const float3 to_light = q - p;
  s.dist = length(to_light);
  s.wi = to_light / s.dist;
  const float cos_light = -dot(n, s.wi) / area2; /* > 0: the front faces the shading point */
  const bool double_sided = scene->materials[tv.w].flags.x & WP_MAT_DOUBLE_SIDED;
  if (!(s.dist > 0.0f) || !(cos_light > 0.0f || (double_sided && cos_light < 0.0f))) return s;
  s.pdf = triangle_solid_angle_pdf(0.5f * area2, s.dist, cos_light);
  s.target = offset_origin(q, cos_light > 0.0f ? n / area2 : -n / area2, q_scale);
  s.li = material_emission(scene, tv, b1, b2);
#if WP_FEATURE_ALPHA
  /* No light from a cut-out or see-through part; alpha_coverage takes the file's winding. */
  const bool mirrored = instance_mirrors(scene, inst);
  s.li *= alpha_coverage(scene, tri, mirrored ? b2 : b1, mirrored ? b1 : b2);
#endif
  return s;
}

#if WP_SHADE_PACKET
/* A light sample of eight lanes (common.h): LightSample's fields that a triangle's sample sets. */
typedef struct LightSample8 {
  Float3x8 wi, li, target;
  float8 dist, pdf;
} LightSample8;

/* sample_triangle of eight lanes, the triangles tri[i] (no instances, untextured emission) for
 * the shading points p at (ux, uy). */
WP_LANES_FN LightSample8 sample_triangle8(const SceneView* scene, const uint* tri, Float3x8 p,
                                          float8 ux, float8 uy) {
  uint i0[8], i1[8], i2[8];
  float4 e[8]; /* material_emission, untextured; w: double-sided */
#pragma unroll
  for (int i = 0; i < 8; ++i) {
    const uint4 tv = scene->tri_vertices[tri[i]];
    i0[i] = tv.x, i1[i] = tv.y, i2[i] = tv.z;
    __global const Material* m = scene->materials + tv.w;
    e[i] = (float4)(m->emission.xyz, (m->flags.x & WP_MAT_DOUBLE_SIDED) ? 1.0f : 0.0f);
  }
  Float3x8 li;
  float8 ds;
  transpose4x8(e, &li.x, &li.y, &li.z, &ds);
  LightSample8 s;
  const Float3x8 p0 = gather3x8(scene->positions, i0);
  const Float3x8 e1 = sub3x8(gather3x8(scene->positions, i1), p0);
  const Float3x8 e2 = sub3x8(gather3x8(scene->positions, i2), p0);
  const float8 r = sqrt(ux);
  const float8 b1 = r * (1.0f - uy), b2 = r * uy;
  const Float3x8 q = {p0.x + b1 * e1.x + b2 * e2.x, p0.y + b1 * e1.y + b2 * e2.y,
                      p0.z + b1 * e1.z + b2 * e2.z};
  const Float3x8 p1 = {p0.x + e1.x, p0.y + e1.y, p0.z + e1.z};
  const Float3x8 p2 = {p0.x + e2.x, p0.y + e2.y, p0.z + e2.z};
  const float8 q_scale =
      fmax(fabs((1.0f - b1 - b2) * p0.x) + fabs(b1 * p1.x) + fabs(b2 * p2.x),
           fmax(fabs((1.0f - b1 - b2) * p0.y) + fabs(b1 * p1.y) + fabs(b2 * p2.y),
                fabs((1.0f - b1 - b2) * p0.z) + fabs(b1 * p1.z) + fabs(b2 * p2.z)));
  const Float3x8 n = cross3x8(e1, e2);
  const float8 area2 = length3x8(n);
  const Float3x8 to_light = sub3x8(q, p);
  s.dist = length3x8(to_light);
  s.wi = div3x8(to_light, s.dist);
  const float8 cos_light = -dot3x8(n, s.wi) / area2;
  const int8 double_sided = ds != 0.0f;
  const int8 seen = s.dist > 0.0f && (cos_light > 0.0f || (double_sided && cos_light < 0.0f));
  /* triangle_solid_angle_pdf */
  const float8 area = 0.5f * area2;
  s.pdf = select((float8)(0.0f), s.dist * s.dist / (area * fabs(cos_light)), seen);
  s.target = offset_origin8(
      q, select3x8(div3x8(neg3x8(n), area2), div3x8(n, area2), cos_light > 0.0f), q_scale);
  s.li = select3x8((Float3x8){0.0f, 0.0f, 0.0f}, li, seen);
  return s;
}
#endif

/* With at most this many lights, one 2D number both picks the light (its first coordinate) and
 * places the point on it (what is left of that coordinate, and the second), as Mitsuba does: the
 * points of a pixel's samples then stay one stratified set over all the lights together (a quad
 * light of two triangles is sampled as well as one shape). Past it, the pick takes its own
 * number, so that the first coordinate keeps its bits (what is left of it has 23 - log2(lights)).
 */
#define WP_LIGHT_PICK_REUSE_MAX 64u

/* One light sample for the shading point p. */
static inline LightSample sample_light(const SceneView* scene, float3 p, float u_pick, float2 u) {
  float pmf, rest;
  const bool reuse = scene->desc->light_count <= WP_LIGHT_PICK_REUSE_MAX;
  const uint i = pick_light(scene, reuse ? u.x : u_pick, &pmf, &rest);
  if (reuse) u.x = rest;
  __global const Light* light = scene->lights + i;
  LightSample s;
  const uint type = light->meta.x;
  if (type == WP_LIGHT_TRIANGLE) {
    s = sample_triangle(scene, light->meta.z, light->meta.y, p, u);
  } else if (type == WP_LIGHT_ENVIRONMENT) {
    s.li = env_sample(scene, u, &s.wi, &s.pdf);
    s.dist = INFINITY;
    s.delta = false;
  } else {
#if WP_FEATURE_PUNCTUAL_LIGHTS
    s = sample_punctual(light, p);
#else
    s.pdf = 0.0f; /* no such light in the program's scenes */
#endif
  }
  s.pdf *= pmf;
  return s;
}

/* The pdf with which NEE would have produced the direction of a ray that hit emissive triangle
 * `tri` at distance dist with cos_light between ray and triangle normal. */
static inline float triangle_light_pdf(const SceneView* scene, uint inst, uint tri, float dist,
                                       float cos_light) {
  uint li = scene->tri_light[tri];
  if (li == WP_NO_LIGHT) return 0.0f;
#if WP_BVH_INSTANCES
  li += scene->instances[inst].meta.y; /* the instance's first light (types.h, tri_light) */
#endif
  const uint4 tv = scene->tri_vertices[tri];
  const float3 p0 = placed_position(scene, inst, tv.x);
  const float area = 0.5f * length(cross(placed_position(scene, inst, tv.y) - p0,
                                         placed_position(scene, inst, tv.z) - p0));
  return scene->light_alias[li].pmf * triangle_solid_angle_pdf(area, dist, cos_light);
}

/* The radiance an escaped ray with direction dir brings and, where want_pdf holds, in *pdf the pdf
 * with which NEE would have produced that direction (else 0), from one lookup of the map
 * (env_radiance_pdf). */
static inline float3 environment_hit(const SceneView* scene, float3 dir, bool want_pdf,
                                     float* pdf) {
  const uint li = scene->desc->env_light;
  const bool light = want_pdf && li != WP_NO_LIGHT;
  float env_pdf_dir;
  const float3 le = env_radiance_pdf(scene, dir, light, &env_pdf_dir);
  *pdf = light ? scene->light_alias[li].pmf * env_pdf_dir : 0.0f;
  return le;
}

#endif /* WP_LIGHTS_H */
