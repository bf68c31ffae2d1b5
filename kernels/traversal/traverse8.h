/* Ray traversal of the wide BVH (BvhNode8 / TriBlock4, shared/bvh_layout.h): closest hit and any
 * hit, for CPU devices, where one node's 8 boxes are tested with float8 operations and 4 triangles
 * with float4 operations (PoCL maps them to AVX/SSE lanes of one work-item).
 *
 * The order and arithmetic are those of the CPU reference (bvh/, width 8): all 8 boxes tested
 * against the current closest t; then in lane order, leaves intersected at once, inner children
 * collected and pushed nearest-on-top; the next node popped; an entry farther than the closest hit
 * skipped. Any hit may visit the children in any order (the reference's answer does not depend on
 * it: bvh_trace explains). Included by traverse.h, which provides TraceRay, TraceHit and the alpha
 * hook.
 */
#ifndef WP_TRAVERSE8_H
#define WP_TRAVERSE8_H

/* The watertight test (bvh/traverse_common.h) on the 4 lanes of a block of a leaf entered at
 * `tleaf`; updates *hit with the closest lane that is closer (hit_is_closer, traverse.h), each at
 * distance max(t, tleaf). */
static inline bool block_test(const SceneView* scene, const TraceRay* r,
                              __global const TriBlock4* b, float tleaf, TraceHit* hit) {
  const float4 az = b->v0[r->kz] - r->o_kz, bz = b->v1[r->kz] - r->o_kz,
               cz = b->v2[r->kz] - r->o_kz;
  const float4 ax = (b->v0[r->kx] - r->o_kx) - r->sx * az;
  const float4 ay = (b->v0[r->ky] - r->o_ky) - r->sy * az;
  const float4 bx = (b->v1[r->kx] - r->o_kx) - r->sx * bz;
  const float4 by = (b->v1[r->ky] - r->o_ky) - r->sy * bz;
  const float4 cx = (b->v2[r->kx] - r->o_kx) - r->sx * cz;
  const float4 cy = (b->v2[r->ky] - r->o_ky) - r->sy * cz;
  const float4 u_ = cx * by - cy * bx;
  const float4 v_ = ax * cy - ay * cx;
  const float4 w_ = bx * ay - by * ax;
  const int4 mixed =
      ((u_ < 0.0f) | (v_ < 0.0f) | (w_ < 0.0f)) & ((u_ > 0.0f) | (v_ > 0.0f) | (w_ > 0.0f));
  const float4 det = u_ + v_ + w_;
  const uint4 flags = b->flags;
  const int4 cull = ((flags & WP_TRI_CULL_BACKFACE) != 0) & (det < 0.0f);
  /* Most blocks end here, before the division (the same hits). */
  const int4 inside = ~mixed & (det != 0.0f) & ~cull;
  if (!any4(inside)) return false;
  const float4 inv = 1.0f / det;
  const float4 t = (u_ * (r->sz * az) + v_ * (r->sz * bz) + w_ * (r->sz * cz)) * inv;
  const float4 u = v_ * inv, v = w_ * inv;
  int4 ok = inside & (t > r->tmin);
  const float4 d = select(t, (float4)(tleaf), t < tleaf); /* the reference's fmax2 */
#if WP_FEATURE_ALPHA
  if (!any4(ok)) return false;
  /* Lanes in order, each by the reference's rule. */
  float tl[4], ul[4], vl[4];
  int okl[4];
  vstore4(d, 0, tl);
  vstore4(u, 0, ul);
  vstore4(v, 0, vl);
  vstore4(ok, 0, okl);
  const uint4 prim = b->prim;
  uint pl[4], fl[4];
  vstore4(prim, 0, pl);
  vstore4(flags, 0, fl);
  bool found = false;
  for (int i = 0; i < 4; ++i) {
    if (!okl[i] || !hit_is_closer(tl[i], pl[i], hit)) continue;
    if ((fl[i] & WP_TRI_ALPHA) && !alpha_passes(scene, pl[i], ul[i], vl[i], r->alpha_key)) continue;
    hit->t = tl[i], hit->u = ul[i], hit->v = vl[i], hit->tri = pl[i];
    found = true;
  }
  return found;
#else
  (void)scene;
  /* Without alpha that rule picks the least (d, prim) among the lanes closer than the hit so far:
   * found here without a branch per lane, the same hit (a branch per lane was slower on PoCL:
   * docs/performance.md, "Closest lane of a triangle block"). */
  const uint4 prim = b->prim;
  ok &= (d < hit->t) | ((d == hit->t) & (prim < hit->tri));
  if (!any4(ok)) return false;
  const float4 tm = select((float4)(INFINITY), d, ok);
  const float2 m2 = fmin(tm.lo, tm.hi);
  const float m = fmin(m2.x, m2.y);
  /* m is the least d of the lanes in ok; the lowest index among the lanes at m. */
  const int4 nearest = ok & (tm == m);
  const uint4 pm = select((uint4)(0xffffffffu), prim, nearest);
  const uint2 p2 = min(pm.lo, pm.hi);
  const uint p = min(p2.x, p2.y);
  const int4 at = nearest & (prim == p);
  const int lane = at.x ? 0 : at.y ? 1 : at.z ? 2 : 3;
  float ul[4], vl[4];
  vstore4(u, 0, ul);
  vstore4(v, 0, vl);
  hit->t = m, hit->u = ul[lane], hit->v = vl[lane], hit->tri = p;
  return true;
#endif
}

static inline bool leaf8_test(const SceneView* scene, const TraceRay* r, int ref, float tleaf,
                              TraceHit* hit, bool any_hit) {
  const int c = ~ref;
  __global const TriBlock4* b = (__global const TriBlock4*)scene->tris + (c >> 2);
  const int blocks = (c & 3) + 1;
  bool found = false;
  for (int i = 0; i < blocks; ++i) {
    if (block_test(scene, r, b + i, tleaf, hit)) {
      found = true;
      if (any_hit) return true;
    }
  }
  return found;
}

/* Cache hints (WP_PREFETCH: PoCL's CPU devices; a no-op elsewhere), through an integer as in
 * stage.h. */
#if WP_PREFETCH
#define bvh_prefetch(p) __builtin_prefetch((const void*)(size_t)(p), 0, 3)
#else
#define bvh_prefetch(p) ((void)(p))
#endif

/* The reference's minimum and maximum (bvh/traverse_common.h, fmin2 and fmax2), one instruction
 * each on a CPU, where fmin and fmax take three (their NaN rule). */
static inline float8 min8(float8 a, float8 b) {
  return select(a, b, b < a);
}
static inline float8 max8(float8 a, float8 b) {
  return select(a, b, a < b);
}

#endif /* WP_TRAVERSE8_H */
