// Internal to bvh/: the arithmetic both reference traversals (bvh_traverse.cpp: binary,
// bvh_traverse_wide.cpp: 8-wide) share. It is the oracle the OpenCL kernels
// (kernels/traversal/traverse.h, kernels/traversal/traverse8.h) are tested against, so it is the
// specification and the kernels copy it operation for operation (all float, no fused multiply-adds:
// wp_bvh is built with -ffp-contract=off, and OpenCL kernels need FP_CONTRACT OFF to match bit for
// bit):
//
//   slab test   inv_d[k] = 1 / (|d[k]| > 1e-20 ? d[k] : copysign(1e-20, d[k]))
//               t0 = (lo - o) * inv_d, t1 = (hi - o) * inv_d per axis
//               tnear = max(max(min(t0x,t1x), min(t0y,t1y)), max(min(t0z,t1z), tmin))
//               tfar  = min(min(max(t0x,t1x), max(t0y,t1y)), min(max(t0z,t1z), tmax_current))
//               entered iff tnear <= tfar
//   triangle    the watertight test of Woop, Benthin and Wald (JCGT 2013), see triangle_test();
//               its distance d = max(t, tleaf), tleaf the slab tnear of the leaf box it is
//               found in; a candidate iff tmin < t, accepted iff (d, prim) < (d_best, prim_best)
//               lexicographically (d < tmax before any hit), see hit_is_closer().
//
// Why d and the index: the closest hit must not depend on the order the walk visits nodes in, so
// that walks of different orders (nearest child first per ray, a packet's order for eight rays:
// kernels/traversal/traverse8_packet.h) give every ray the same answer. Two things would make it
// depend: (1) two triangles at the same distance (a ray through an edge both share hits both),
// where "the first found" wins; the lower scene triangle index wins instead. (2) Rounding: a box
// whose computed tnear exceeds the computed t of a triangle inside it by an ulp is culled by a hit
// between the two in one order and not in another. With d >= tleaf no box is ever culled by a hit
// its own content beats: boxes nest (bvh_check: every child box lies inside its parent's) and the
// slab distance (plane - o) * inv_d is monotone in the plane for a given ray, so every ancestor's
// computed tnear is <= its leaf's. The best hit's boxes are then entered whatever the order, and
// the answer is the least (d, prim) over all triangles in the leaves the ray enters within tmax.
// The hit record's t is d, at most a few ulps beyond t (a rounding of the same distance).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <utility>

#include "bvh.h"

namespace wp::bvh::detail {

inline std::uint32_t float_bits(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

inline float safe_rcp(float d) {
  return 1.0f / (std::fabs(d) > 1e-20f ? d : std::copysign(1e-20f, d));
}

// The ray's frame for the watertight triangle test: kz the axis of |d|'s largest component
// (the first on ties), kx and ky the two others in cyclic order, swapped when d[kz] < 0 so the
// triangle's winding, and so its facing, is kept; the shear sx, sy and the scale sz map d to
// (0, 0, 1).
struct RayFrame {
  int kx, ky, kz;
  float sx, sy, sz;
  explicit RayFrame(const glm::vec3& d) {
    const float ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    kz = ax >= ay ? (ax >= az ? 0 : 2) : (ay >= az ? 1 : 2);
    kx = kz == 2 ? 0 : kz + 1;
    ky = kx == 2 ? 0 : kx + 1;
    if (d[kz] < 0.0f) std::swap(kx, ky);
    sx = d[kx] / d[kz];
    sy = d[ky] / d[kz];
    sz = 1.0f / d[kz];
  }
};

struct PreparedRay {
  float ox, oy, oz, ix, iy, iz, tmin;
  RayFrame f;
  float o_kx, o_ky, o_kz;  // the origin in the frame's axes
  explicit PreparedRay(const Ray& r)
      : ox(r.o.x),
        oy(r.o.y),
        oz(r.o.z),
        ix(safe_rcp(r.d.x)),
        iy(safe_rcp(r.d.y)),
        iz(safe_rcp(r.d.z)),
        tmin(r.tmin),
        f(r.d),
        o_kx(r.o[f.kx]),
        o_ky(r.o[f.ky]),
        o_kz(r.o[f.kz]) {}
};

// NaN-free inputs only (the builder rejects non-finite vertices), so these agree with OpenCL's
// fmin/fmax.
inline float fmin2(float a, float b) {
  return b < a ? b : a;
}
inline float fmax2(float a, float b) {
  return a < b ? b : a;
}

// Slab test of the box [lo, hi] against [tmin, tmax]: returns whether it is entered, and its
// entry distance in `tnear` either way.
inline bool slab_test(const PreparedRay& r, float lox, float hix, float loy, float hiy, float loz,
                      float hiz, float tmax, float& tnear) {
  const float tx0 = (lox - r.ox) * r.ix, tx1 = (hix - r.ox) * r.ix;
  const float ty0 = (loy - r.oy) * r.iy, ty1 = (hiy - r.oy) * r.iy;
  const float tz0 = (loz - r.oz) * r.iz, tz1 = (hiz - r.oz) * r.iz;
  tnear = fmax2(fmax2(fmin2(tx0, tx1), fmin2(ty0, ty1)), fmax2(fmin2(tz0, tz1), r.tmin));
  const float tfar = fmin2(fmin2(fmax2(tx0, tx1), fmax2(ty0, ty1)), fmin2(fmax2(tz0, tz1), tmax));
  return tnear <= tfar;
}

// The closest-hit rule (the top of this file): a hit at distance d on triangle `prim` replaces
// `hit`, whose distance is `tmax` (the ray's tmax while there is none), iff (d, prim) is smaller.
inline bool hit_is_closer(float d, std::uint32_t prim, float tmax, const Hit& hit) {
  return d < tmax || (hit.hit && d == tmax && prim < hit.triangle);
}

// One stored triangle, whichever layout it comes from: v[vertex][axis].
struct TriangleData {
  float v[3][3];
  std::uint32_t flags;  // WP_TRI_*
  std::uint32_t prim;   // scene triangle index
};

// The watertight ray-triangle test (Woop, Benthin and Wald, JCGT 2(1) 2013). The vertices are
// moved to the ray's origin and sheared so that the ray runs along +z (RayFrame); the 2D edge
// functions U, V, W of the edges opposite v0, v1, v2 then say on which side of each edge the ray
// passes. Two triangles sharing an edge share its vertices bit for bit (the layouts store them
// unchanged) and compute that edge's function as a*b - c*d and c*d - a*b from the same two
// rounded products, so one is exactly the negative of the other: no ray passes between them.
// A hit needs U, V, W of one sign (zeros count for both, so a ray exactly on an edge hits both
// triangles rather than neither). det = U + V + W > 0 is a front-face hit (cross(v1 - v0,
// v2 - v0) faces against d); barycentrics u = V / det (of v1), v = W / det (of v2). No fused
// multiply-adds anywhere (see the top of this file): with them the two products of an edge
// function round differently and the symmetry is lost. Returns whether tmin < t and the hit's
// (d, prim), d = max(t, tleaf), is closer than `hit`'s (hit_is_closer, `tmax` its distance), and
// then fills `hit` with t = d.
inline bool triangle_test(const PreparedRay& r, const TriangleData& tri, float tleaf, float tmax,
                          Hit& hit) {
  const int kx = r.f.kx, ky = r.f.ky, kz = r.f.kz;
  const float az = tri.v[0][kz] - r.o_kz, bz = tri.v[1][kz] - r.o_kz, cz = tri.v[2][kz] - r.o_kz;
  const float ax = (tri.v[0][kx] - r.o_kx) - r.f.sx * az;
  const float ay = (tri.v[0][ky] - r.o_ky) - r.f.sy * az;
  const float bx = (tri.v[1][kx] - r.o_kx) - r.f.sx * bz;
  const float by = (tri.v[1][ky] - r.o_ky) - r.f.sy * bz;
  const float cx = (tri.v[2][kx] - r.o_kx) - r.f.sx * cz;
  const float cy = (tri.v[2][ky] - r.o_ky) - r.f.sy * cz;
  const float u_ = cx * by - cy * bx;
  const float v_ = ax * cy - ay * cx;
  const float w_ = bx * ay - by * ax;
  if ((u_ < 0.0f || v_ < 0.0f || w_ < 0.0f) && (u_ > 0.0f || v_ > 0.0f || w_ > 0.0f)) return false;
  const float det = u_ + v_ + w_;
  if (det == 0.0f) return false;
  if ((tri.flags & WP_TRI_CULL_BACKFACE) && det < 0.0f) return false;
  const float inv = 1.0f / det;
  const float t = (u_ * (r.f.sz * az) + v_ * (r.f.sz * bz) + w_ * (r.f.sz * cz)) * inv;
  if (!(t > r.tmin)) return false;
  const float d = fmax2(t, tleaf);
  if (!hit_is_closer(d, tri.prim, tmax, hit)) return false;
  hit.hit = true;
  hit.t = d, hit.u = v_ * inv, hit.v = w_ * inv;
  hit.triangle = tri.prim;
  return true;
}

// The width-8 traversal (bvh_traverse_wide.cpp): closest hit (any = false) or any hit within
// (ray.tmin, ray.tmax).
Hit trace_wide(const Bvh& bvh, const Ray& ray, bool any, std::int32_t root = 0);
Hit trace_binary(const Bvh& bvh, const Ray& ray, bool any, std::int32_t root = 0);
// A two-level BVH (bvh_two_level.cpp): every instance in turn, each with the ray in its mesh's
// space (object_ray), the closest hit over all of them.
Hit trace_instances(const Bvh& bvh, const Ray& ray, bool any);

}  // namespace wp::bvh::detail
