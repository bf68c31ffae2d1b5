/* Ray traversal of the flattened BVH (shared/bvh_layout.h): closest hit and any hit. The binary
 * layout is here; with -D WP_BVH_WIDTH=8 the wide one (traverse8.h) replaces it.
 *
 * The arithmetic is exactly that of the CPU reference (bvh/bvh_traverse.cpp), which the tests
 * compare against Embree: slab test with clamped reciprocal directions, the watertight triangle
 * test (bvh/traverse_common.h explains it) written in scalar operations (on PoCL the float3
 * builtins vectorise worse), nearer child first, leaves intersected as soon as they are reached.
 */
#ifndef WP_TRAVERSE_H
#define WP_TRAVERSE_H

#include "util/common.h"
#include "alpha.h"

/* No fused multiply-adds here: the CPU reference is written without them, and with contraction
 * the kernel's results differ from it in the last bits (and, measured on PoCL, some rays missed a
 * triangle the reference and Embree both hit). Exact agreement makes the kernel testable, and the
 * watertight test needs each edge function's two products rounded alike. */
#pragma OPENCL FP_CONTRACT OFF

typedef struct TraceRay {
  float ox, oy, oz;
  float ix, iy, iz; /* clamped reciprocal direction */
  float tmin;
  uint alpha_key; /* identifies the ray's path and bounce for stochastic alpha (alpha.h) */
  /* The watertight test's frame (bvh/traverse_common.h, RayFrame): axes kx, ky, kz, shear
   * sx, sy and scale sz, and the origin in those axes. */
  int kx, ky, kz;
  float sx, sy, sz;
  float o_kx, o_ky, o_kz;
#if WP_BVH_INSTANCES
  float dx, dy, dz; /* the direction, which a two-level BVH maps into each instance's space */
#endif
} TraceRay;

typedef struct TraceHit {
  float t, u, v;
  uint tri; /* scene triangle index; valid when t < the ray's tmax */
#if WP_BVH_INSTANCES
  uint inst; /* its instance (shared/bvh_layout.h) */
#endif
} TraceHit;

static inline float safe_rcp(float d) {
  return 1.0f / (fabs(d) > 1e-20f ? d : copysign(1e-20f, d));
}

static inline TraceRay trace_ray(float3 o, float3 d, float tmin, uint alpha_key) {
  TraceRay r;
  r.ox = o.x, r.oy = o.y, r.oz = o.z;
  r.ix = safe_rcp(d.x), r.iy = safe_rcp(d.y), r.iz = safe_rcp(d.z);
  r.tmin = tmin;
  r.alpha_key = alpha_key;
#if WP_BVH_INSTANCES
  r.dx = d.x, r.dy = d.y, r.dz = d.z;
#endif
  const float ax = fabs(d.x), ay = fabs(d.y), az = fabs(d.z);
  const int kz = ax >= ay ? (ax >= az ? 0 : 2) : (ay >= az ? 1 : 2);
  int kx = kz == 2 ? 0 : kz + 1;
  int ky = kx == 2 ? 0 : kx + 1;
  const float o3[3] = {o.x, o.y, o.z}, d3[3] = {d.x, d.y, d.z};
  if (d3[kz] < 0.0f) {
    const int k = kx;
    kx = ky;
    ky = k;
  }
  r.kx = kx, r.ky = ky, r.kz = kz;
  r.sx = d3[kx] / d3[kz];
  r.sy = d3[ky] / d3[kz];
  r.sz = 1.0f / d3[kz];
  r.o_kx = o3[kx], r.o_ky = o3[ky], r.o_kz = o3[kz];
  return r;
}

/* Slab test of one box; returns the entry distance, or INFINITY when the box is missed within
 * [tmin, tmax]. */
static inline float box_entry(const TraceRay* r, float lox, float hix, float loy, float hiy,
                              float loz, float hiz, float tmax) {
  const float tx0 = (lox - r->ox) * r->ix, tx1 = (hix - r->ox) * r->ix;
  const float ty0 = (loy - r->oy) * r->iy, ty1 = (hiy - r->oy) * r->iy;
  const float tz0 = (loz - r->oz) * r->iz, tz1 = (hiz - r->oz) * r->iz;
  const float tnear = fmax(fmax(fmin(tx0, tx1), fmin(ty0, ty1)), fmax(fmin(tz0, tz1), r->tmin));
  const float tfar = fmin(fmin(fmax(tx0, tx1), fmax(ty0, ty1)), fmin(fmax(tz0, tz1), tmax));
  return tnear <= tfar ? tnear : INFINITY;
}

/* The closest-hit rule (bvh/traverse_common.h, hit_is_closer): a hit at distance d on triangle
 * `prim` replaces *hit iff (d, prim) is smaller; before any hit hit->t is the ray's tmax and
 * hit->tri 0 (bvh_trace), which no index is below. The same answer in any visiting order (the
 * reference's comment), which packets of rays rely on (traverse8_packet.h). */
static inline bool hit_is_closer(float d, uint prim, const TraceHit* hit) {
  return d < hit->t || (d == hit->t && prim < hit->tri);
}

/* The watertight test against one stored triangle of a leaf entered at `tleaf`: at distance
 * max(t, tleaf) (the reference's d), updates *hit when that is closer. */
static inline bool triangle_test(const SceneView* scene, const TraceRay* r,
                                 __global const IsectTri* tri, float tleaf, TraceHit* hit) {
  __global const float* v0 = (__global const float*)&tri->v0;
  __global const float* v1 = (__global const float*)&tri->v1;
  __global const float* v2 = (__global const float*)&tri->v2;
  const float az = v0[r->kz] - r->o_kz, bz = v1[r->kz] - r->o_kz, cz = v2[r->kz] - r->o_kz;
  const float ax = (v0[r->kx] - r->o_kx) - r->sx * az;
  const float ay = (v0[r->ky] - r->o_ky) - r->sy * az;
  const float bx = (v1[r->kx] - r->o_kx) - r->sx * bz;
  const float by = (v1[r->ky] - r->o_ky) - r->sy * bz;
  const float cx = (v2[r->kx] - r->o_kx) - r->sx * cz;
  const float cy = (v2[r->ky] - r->o_ky) - r->sy * cz;
  const float u_ = cx * by - cy * bx;
  const float v_ = ax * cy - ay * cx;
  const float w_ = bx * ay - by * ax;
  if ((u_ < 0.0f || v_ < 0.0f || w_ < 0.0f) && (u_ > 0.0f || v_ > 0.0f || w_ > 0.0f)) return false;
  const float det = u_ + v_ + w_;
  if (det == 0.0f) return false;
  const uint flags = as_uint(tri->v1.w);
  if ((flags & WP_TRI_CULL_BACKFACE) && det < 0.0f) return false;
  const float inv = 1.0f / det;
  const float t = (u_ * (r->sz * az) + v_ * (r->sz * bz) + w_ * (r->sz * cz)) * inv;
  if (!(t > r->tmin)) return false;
  const float d = t < tleaf ? tleaf : t; /* the reference's fmax2 */
  const uint prim = as_uint(tri->v0.w);
  if (!hit_is_closer(d, prim, hit)) return false;
  const float u = v_ * inv, v = w_ * inv;
#if WP_FEATURE_ALPHA
  if ((flags & WP_TRI_ALPHA) && !alpha_passes(scene, prim, u, v, r->alpha_key)) return false;
#else
  (void)scene;
#endif
  hit->t = d, hit->u = u, hit->v = v, hit->tri = prim;
  return true;
}

/* Intersects the leaf [first, first + count), entered at `tleaf`; with `any`, stops at the first
 * hit. */
static inline bool leaf_test(const SceneView* scene, const TraceRay* r, int ref, int count,
                             float tleaf, TraceHit* hit, bool any) {
  bool found = false;
  __global const IsectTri* tri = scene->tris + ~ref;
  for (int i = 0; i < count; ++i) {
    if (triangle_test(scene, r, tri + i, tleaf, hit)) {
      found = true;
      if (any) return true;
    }
  }
  return found;
}

#ifndef WP_BVH_WIDTH
#define WP_BVH_WIDTH 2
#endif

#if WP_BVH_WIDTH == 8
#include "traverse8.h"
#define WP_WALK_NAME mesh_walk
#define WP_WALK_LEAF leaf8_test
#include "traverse8_walk.def"
/* The walks of eight rays at once, for the stages built with WP_SHADOW_PACKET or
 * WP_CLOSEST_PACKET. */
#include "traverse8_packet.h"
#else
#define WP_WALK_NAME mesh_walk
#define WP_WALK_LEAF leaf_test
#include "traverse_walk.def"
#endif

#if WP_BVH_INSTANCES
/* A two-level BVH (shared/bvh_layout.h): the top-level tree's leaves are instances, each walked
 * with the ray mapped into its mesh's space. The mapping's products are summed in the order of
 * the CPU reference (bvh/bvh_two_level.cpp, object_ray); distances along the ray are the same in
 * both spaces, so the hit record's t and the walk's bound carry across levels unchanged. */
static inline TraceRay object_trace_ray(__global const BvhInstance* inst, const TraceRay* r) {
  float o[3], d[3];
  for (int i = 0; i < 3; ++i) {
    const float4 m = inst->to_object[i];
    o[i] = ((m.x * r->ox + m.y * r->oy) + m.z * r->oz) + m.w;
    d[i] = (m.x * r->dx + m.y * r->dy) + m.z * r->dz;
  }
  return trace_ray((float3)(o[0], o[1], o[2]), (float3)(d[0], d[1], d[2]), r->tmin, r->alpha_key);
}

/* Instance `k`'s mesh against the world ray r; on a closer hit records the instance too. */
static inline bool instance_test(const SceneView* scene, const TraceRay* r, uint k, TraceHit* hit,
                                 bool any) {
  __global const BvhInstance* inst = scene->instances + k;
  const TraceRay o = object_trace_ray(inst, r);
  if (!mesh_walk(scene, &o, (int)inst->meta.x, hit, any)) return false;
  hit->inst = k;
  return true;
}

/* The instances refs[0, n), unused references (WP_NO_INSTANCE) skipped. */
static inline bool instances_test(const SceneView* scene, const TraceRay* r,
                                  __global const uint* refs, int n, TraceHit* hit, bool any) {
  bool found = false;
  for (int i = 0; i < n; ++i) {
    if (refs[i] == WP_NO_INSTANCE) continue;
    if (instance_test(scene, r, refs[i], hit, any)) {
      found = true;
      if (any) return true;
    }
  }
  return found;
}

#if WP_BVH_WIDTH == 8
/* A top-level leaf ~ref: 4 instance references per block (bvh_layout.h). */
static inline bool instance_leaf8(const SceneView* scene, const TraceRay* r, int ref, float tleaf,
                                  TraceHit* hit, bool any) {
  (void)tleaf; /* each instance's walk has its own leaves */
  const int c = ~ref;
  return instances_test(scene, r, scene->instance_refs + 4 * (c >> 2), 4 * ((c & 3) + 1), hit, any);
}
#define WP_WALK_NAME top_walk
#define WP_WALK_LEAF instance_leaf8
#include "traverse8_walk.def"
#else
/* A top-level leaf: `count` instance references from ~ref. */
static inline bool instance_leaf(const SceneView* scene, const TraceRay* r, int ref, int count,
                                 float tleaf, TraceHit* hit, bool any) {
  (void)tleaf; /* each instance's walk has its own leaves */
  return instances_test(scene, r, scene->instance_refs + ~ref, count, hit, any);
}
#define WP_WALK_NAME top_walk
#define WP_WALK_LEAF instance_leaf
#include "traverse_walk.def"
#endif
#endif /* WP_BVH_INSTANCES */

/* The instance of a hit (shared/bvh_layout.h): WP_NO_INSTANCE without a two-level BVH. */
static inline uint trace_hit_instance(const TraceHit* hit) {
#if WP_BVH_INSTANCES
  return hit->inst;
#else
  (void)hit;
  return WP_NO_INSTANCE;
#endif
}

/* Closest hit (any = false) or any hit (any = true) in (tmin, tmax). Returns whether something was
 * hit; the hit record holds the closest one found. */
static inline bool bvh_trace(const SceneView* scene, const TraceRay* r, float tmax, TraceHit* hit,
                             bool any) {
  hit->t = tmax;
  hit->tri = 0u; /* hit_is_closer: no tie with "no hit" */
#if WP_BVH_INSTANCES
  hit->inst = WP_NO_INSTANCE;
  return top_walk(scene, r, 0, hit, any);
#else
  return mesh_walk(scene, r, 0, hit, any);
#endif
}

#endif /* WP_TRAVERSE_H */
