/* Traversal of the wide BVH (traverse8.h) for a packet of WP_PACKET rays in one work-item:
 * the lanes of float8 values are rays, not a node's children, so a node's child box is tested
 * against all of the packet's rays at once and a triangle likewise.
 *
 * The answer of each ray is the one traverse8_walk.def gives it: every lane carries its own mask
 * down the tree (a child is visited for the rays that entered its box, tested with that ray's own
 * arithmetic: the same slab and watertight tests, lane by lane, FP_CONTRACT off as in traverse.h),
 * and neither an any-hit answer nor a closest hit depends on the order of the visits (the closest
 * by its rule, bvh/traverse_common.h: the least distance, then the lowest triangle index, the
 * distance never below the entry of the leaf it is found in), so which rays share a packet
 * changes nothing. A ray leaves an any-hit packet's work at its first hit.
 *
 * Only for programs without instances and alpha (and, for shadow rays, transmission: they are
 * then plain any-hit queries, integrator/trace_shadow.h), on CPU devices with the wide layout: the
 * host picks them (host/render/wavefront.cpp, packet stages) and launches those stages over the
 * queue's length divided by WP_PACKET. */
#ifndef WP_TRAVERSE8_PACKET_H
#define WP_TRAVERSE8_PACKET_H

#define WP_PACKET 8

/* The packet's rays, lane i the TraceRay of ray i (traverse.h), the axes of the watertight frame
 * as lane masks. */
typedef struct PacketRays {
  float8 ox, oy, oz, ix, iy, iz, tmin, tmax;
  int8 kx1, kx2, ky1, ky2, kz1, kz2; /* axis k is 1 or 2 (else 0: x) */
  float8 sx, sy, sz, o_kx, o_ky, o_kz;
} PacketRays;

/* The packet of the rays with origins o[i].xyz and directions d[i].xyz, i < 8 (a caller with
 * fewer rays repeats one), trace_ray's quantities computed in the lanes with its expressions;
 * tmin and tmax are the caller's to set. *ow: the w components of o[i]. */
static inline PacketRays packet_rays8(const float4* o, const float4* d, float8* ow) {
  PacketRays p;
  float8 dx, dy, dz, unused;
  transpose4x8(o, &p.ox, &p.oy, &p.oz, ow);
  transpose4x8(d, &dx, &dy, &dz, &unused);
  const float8 tiny = (float8)(1e-20f); /* safe_rcp */
  p.ix = 1.0f / select(copysign(tiny, dx), dx, fabs(dx) > tiny);
  p.iy = 1.0f / select(copysign(tiny, dy), dy, fabs(dy) > tiny);
  p.iz = 1.0f / select(copysign(tiny, dz), dz, fabs(dz) > tiny);
  const float8 ax = fabs(dx), ay = fabs(dy), az = fabs(dz);
  const int8 kz = select(select((int8)(2), (int8)(1), ay >= az),
                         select((int8)(2), (int8)(0), ax >= az), ax >= ay);
  const int8 kx0 = select(kz + 1, (int8)(0), kz == 2);
  const int8 ky0 = select(kx0 + 1, (int8)(0), kx0 == 2);
  const int8 kz1 = kz == 1, kz2 = kz == 2;
  const float8 dkz = select(select(dx, dy, kz1), dz, kz2);
  const int8 swap = dkz < 0.0f;
  const int8 kx = select(kx0, ky0, swap), ky = select(ky0, kx0, swap);
  p.kx1 = kx == 1, p.kx2 = kx == 2, p.ky1 = ky == 1, p.ky2 = ky == 2, p.kz1 = kz1, p.kz2 = kz2;
  p.sx = select(select(dx, dy, p.kx1), dz, p.kx2) / dkz;
  p.sy = select(select(dx, dy, p.ky1), dz, p.ky2) / dkz;
  p.sz = 1.0f / dkz;
  p.o_kx = select(select(p.ox, p.oy, p.kx1), p.oz, p.kx2);
  p.o_ky = select(select(p.ox, p.oy, p.ky1), p.oz, p.ky2);
  p.o_kz = select(select(p.ox, p.oy, kz1), p.oz, kz2);
  return p;
}

/* Each lane's coordinate `k` (k1, k2: its masks) of the point (x, y, z). */
static inline float8 packet_axis(float x, float y, float z, int8 k1, int8 k2) {
  return select(select((float8)(x), (float8)(y), k1), (float8)(z), k2);
}

/* Lane i all ones where bit i of `bits` is set. */
static inline int8 lane_mask8(int bits) {
  return ((int8)(bits) & (int8)(1, 2, 4, 8, 16, 32, 64, 128)) != 0;
}

/* The lanes of `live` whose ray hits triangle j of block b beyond tmin, with each lane's t and
 * barycentrics: block_test's arithmetic (traverse8.h) for one triangle and eight rays. With
 * `early`, a triangle inside no lane's edges returns at once, before the division (t, u and v
 * unset). Without, every triangle's distances are computed: in a scene of few large triangles
 * (WP_PACKET_MASKED_CLOSEST) whether any of eight incoherent rays lies inside a triangle is a
 * branch taken at random, and its mispredictions cost the Cornell box's bounce rays more than the
 * divisions they skip; on a dense mesh the branch is predictable and pays (docs/performance.md,
 * "Closest-hit packets without a branch per triangle"). */
static inline int8 packet_triangle(const PacketRays* p, __global const TriBlock4* b, int j,
                                   int8 live, bool early, float8* t, float8* u, float8* v) {
  __global const float* v0 = (__global const float*)b->v0;
  __global const float* v1 = (__global const float*)b->v1;
  __global const float* v2 = (__global const float*)b->v2;
  const float v0x = v0[j], v0y = v0[4 + j], v0z = v0[8 + j];
  const float v1x = v1[j], v1y = v1[4 + j], v1z = v1[8 + j];
  const float v2x = v2[j], v2y = v2[4 + j], v2z = v2[8 + j];
  const float8 az = packet_axis(v0x, v0y, v0z, p->kz1, p->kz2) - p->o_kz;
  const float8 bz = packet_axis(v1x, v1y, v1z, p->kz1, p->kz2) - p->o_kz;
  const float8 cz = packet_axis(v2x, v2y, v2z, p->kz1, p->kz2) - p->o_kz;
  const float8 ax = (packet_axis(v0x, v0y, v0z, p->kx1, p->kx2) - p->o_kx) - p->sx * az;
  const float8 ay = (packet_axis(v0x, v0y, v0z, p->ky1, p->ky2) - p->o_ky) - p->sy * az;
  const float8 bx = (packet_axis(v1x, v1y, v1z, p->kx1, p->kx2) - p->o_kx) - p->sx * bz;
  const float8 by = (packet_axis(v1x, v1y, v1z, p->ky1, p->ky2) - p->o_ky) - p->sy * bz;
  const float8 cx = (packet_axis(v2x, v2y, v2z, p->kx1, p->kx2) - p->o_kx) - p->sx * cz;
  const float8 cy = (packet_axis(v2x, v2y, v2z, p->ky1, p->ky2) - p->o_ky) - p->sy * cz;
  const float8 u_ = cx * by - cy * bx;
  const float8 v_ = ax * cy - ay * cx;
  const float8 w_ = bx * ay - by * ax;
  const int8 mixed =
      ((u_ < 0.0f) | (v_ < 0.0f) | (w_ < 0.0f)) & ((u_ > 0.0f) | (v_ > 0.0f) | (w_ > 0.0f));
  const float8 det = u_ + v_ + w_;
  const uint flags = ((__global const uint*)&b->flags)[j];
  const int8 cull = (flags & WP_TRI_CULL_BACKFACE) ? det < 0.0f : (int8)(0);
  const int8 inside = live & ~mixed & (det != 0.0f) & ~cull;
  if (early && !any8(inside)) return (int8)(0);
  const float8 inv = 1.0f / det;
  *t = (u_ * (p->sz * az) + v_ * (p->sz * bz) + w_ * (p->sz * cz)) * inv;
  *u = v_ * inv, *v = w_ * inv;
  return inside & (*t > p->tmin);
}

/* Each lane's distance of a hit at t in a leaf entered at tleaf (the reference's fmax2). */
static inline float8 packet_distance(float8 t, float8 tleaf) {
  return select(t, tleaf, t < tleaf);
}

/* The lanes in `live` that some triangle of leaf ~ref, entered at `tleaf`, occludes. */
static inline int packet_leaf(const SceneView* scene, const PacketRays* p, int ref, float8 tleaf,
                              int live) {
  const int c = ~ref;
  __global const TriBlock4* b = (__global const TriBlock4*)scene->tris + (c >> 2);
  const int blocks = (c & 3) + 1;
  int hit = 0;
  for (int i = 0; i < blocks; ++i) {
    __global const uint* prim = (__global const uint*)&b[i].prim;
    for (int j = 0; j < 4; ++j) {
      if (prim[j] == 0xffffffffu) continue; /* an unused lane (bvh_layout.h) */
      float8 t, u, v;
      const int8 in = packet_triangle(p, b + i, j, lane_mask8(live & ~hit), true, &t, &u, &v);
      if (!any8(in)) continue;
      hit |= lane_bits8(in & (packet_distance(t, tleaf) < p->tmax));
      if (hit == live) return hit;
    }
  }
  return hit;
}

/* The slab test of child i of node n for the packet (traverse8_walk.def's, per ray: min and max of
 * both planes' distances are the near and far plane's, lo <= hi): each lane's tnear, and the bits
 * of the lanes that enter the box within (tmin, tmax). */
static inline int packet_box(const PacketRays* p, __global const BvhNode8* n, int i, float8 tmax,
                             float8* tnear) {
  const float lo_x = ((__global const float*)&n->lo_x)[i],
              hi_x = ((__global const float*)&n->hi_x)[i];
  const float lo_y = ((__global const float*)&n->lo_y)[i],
              hi_y = ((__global const float*)&n->hi_y)[i];
  const float lo_z = ((__global const float*)&n->lo_z)[i],
              hi_z = ((__global const float*)&n->hi_z)[i];
  const float8 t0x = (lo_x - p->ox) * p->ix, t1x = (hi_x - p->ox) * p->ix;
  const float8 t0y = (lo_y - p->oy) * p->iy, t1y = (hi_y - p->oy) * p->iy;
  const float8 t0z = (lo_z - p->oz) * p->iz, t1z = (hi_z - p->oz) * p->iz;
  *tnear = max8(max8(min8(t0x, t1x), min8(t0y, t1y)), max8(min8(t0z, t1z), p->tmin));
  const float8 tfar = min8(min8(max8(t0x, t1x), max8(t0y, t1y)), min8(max8(t0z, t1z), tmax));
  return lane_bits8(*tnear <= tfar);
}

/* The lanes of `live` whose ray is occluded: any hit in (tmin, tmax), from the root. */
static inline int packet_any_hit(const SceneView* scene, const PacketRays* p, int live) {
  __global const BvhNode8* nodes = (__global const BvhNode8*)scene->nodes;
  int stack_node[WP_BVH8_STACK_SIZE], stack_mask[WP_BVH8_STACK_SIZE];
  int sp = 0, node = 0, mask = live, occluded = 0;
  for (;;) {
    __global const BvhNode8* n = nodes + node;
    __global const int* cl = (__global const int*)&n->child;
    for (int i = 0; i < 8; ++i) {
      const int c = cl[i];
      if (c == 0) break; /* unused slots come last */
      float8 tnear;
      const int entered = mask & packet_box(p, n, i, p->tmax, &tnear);
      if (entered == 0) continue;
      if (c < 0) {
        occluded |= packet_leaf(scene, p, c, tnear, entered);
        if (occluded == live) return occluded;
        mask &= ~occluded;
      } else {
        stack_node[sp] = c;
        stack_mask[sp] = entered;
        ++sp;
      }
    }
    /* Next: the top entry with rays still looking. */
    for (;;) {
      if (sp == 0) return occluded;
      --sp;
      mask = stack_mask[sp] & ~occluded;
      if (mask != 0) break;
    }
    node = stack_node[sp];
  }
}

/* Each lane's closest hit: distance (the ray's tmax where there is none), barycentrics and scene
 * triangle index, as traverse8_walk.def's TraceHit. */
typedef struct PacketHit {
  float8 t, u, v;
  uint8 tri;
} PacketHit;

/* Leaf ~ref, entered at `tleaf` by the lanes in `live`: each lane's hit replaced by a closer one
 * (hit_is_closer's rule, lane by lane). */
static inline void packet_closest_leaf(const SceneView* scene, const PacketRays* p, int ref,
                                       float8 tleaf, int live, PacketHit* h) {
  const int c = ~ref;
  __global const TriBlock4* b = (__global const TriBlock4*)scene->tris + (c >> 2);
  const int blocks = (c & 3) + 1;
  const int8 live8 = lane_mask8(live);
  for (int i = 0; i < blocks; ++i) {
    __global const uint* prim = (__global const uint*)&b[i].prim;
    for (int j = 0; j < 4; ++j) {
      const uint pj = prim[j];
      if (pj == 0xffffffffu) continue; /* an unused lane (bvh_layout.h) */
      float8 t, u, v;
      const int8 in = packet_triangle(p, b + i, j, live8, !WP_PACKET_MASKED_CLOSEST, &t, &u, &v);
#if !WP_PACKET_MASKED_CLOSEST
      if (!any8(in)) continue;
#endif
      const float8 d = packet_distance(t, tleaf);
      const int8 take = in & ((d < h->t) | ((d == h->t) & ((uint8)(pj) < h->tri)));
#if !WP_PACKET_MASKED_CLOSEST
      if (!any8(take)) continue;
#endif
      h->t = select(h->t, d, take);
      h->u = select(h->u, u, take);
      h->v = select(h->v, v, take);
      h->tri = select(h->tri, (uint8)(pj), take);
    }
  }
}

/* The greatest of the lanes of `x` set in `bits` (bits != 0). */
static inline float packet_max(float8 x, int bits) {
  const float8 m = select((float8)(-INFINITY), x, lane_mask8(bits));
  const float4 m4 = max(m.lo, m.hi);
  const float2 m2 = max(m4.lo, m4.hi);
  return max(m2.x, m2.y);
}

/* The least of the lanes of `x` set in `bits` (bits != 0). */
static inline float packet_min(float8 x, int bits) {
  const float8 m = select((float8)(INFINITY), x, lane_mask8(bits));
  const float4 m4 = min(m.lo, m.hi);
  const float2 m2 = min(m4.lo, m4.hi);
  return min(m2.x, m2.y);
}

/* Each lane's closest hit in (tmin, tmax) for the rays in `live`, from the root: the single-ray
 * walk's answer, which does not depend on the visiting order (hit_is_closer). The order here is
 * the packet's: a node's children in slot order, leaves intersected at once, inner children pushed
 * by their nearest lane's tnear, nearest on top; an entry is skipped when that tnear is beyond the
 * farthest closest hit of its rays (a bound on each of them). */
static inline void packet_closest(const SceneView* scene, const PacketRays* p, int live,
                                  PacketHit* h) {
  __global const BvhNode8* nodes = (__global const BvhNode8*)scene->nodes;
  int stack_node[WP_BVH8_STACK_SIZE], stack_mask[WP_BVH8_STACK_SIZE];
  float stack_t[WP_BVH8_STACK_SIZE];
  h->t = p->tmax;
  h->u = h->v = (float8)(0.0f);
  h->tri = (uint8)(0u); /* hit_is_closer: no tie with "no hit" */
  int sp = 0, node = 0, mask = live;
  for (;;) {
    __global const BvhNode8* n = nodes + node;
    __global const int* cl = (__global const int*)&n->child;
    const int base = sp;
    for (int i = 0; i < 8; ++i) {
      const int c = cl[i];
      if (c == 0) break; /* unused slots come last */
      float8 tnear;
      const int entered = mask & packet_box(p, n, i, h->t, &tnear);
      if (entered == 0) continue;
      if (c < 0) {
        packet_closest_leaf(scene, p, c, tnear, entered, h);
        continue;
      }
      /* Pushed in decreasing order of the nearest lane's tnear (insertion, as the walk's). */
      const float t = packet_min(tnear, entered);
      int e = sp++;
      while (e > base && stack_t[e - 1] <= t) {
        stack_t[e] = stack_t[e - 1];
        stack_node[e] = stack_node[e - 1];
        stack_mask[e] = stack_mask[e - 1];
        --e;
      }
      stack_t[e] = t;
      stack_node[e] = c;
      stack_mask[e] = entered;
    }
    /* Next: the top entry that can still hold something closer for one of its rays. */
    for (;;) {
      if (sp == 0) return;
      --sp;
      mask = stack_mask[sp];
      if (!(stack_t[sp] > packet_max(h->t, mask))) break;
    }
    node = stack_node[sp];
  }
}

#endif /* WP_TRAVERSE8_PACKET_H */
