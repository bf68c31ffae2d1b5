// Internal to bvh/: the arithmetic both reference traversals (bvh_traverse.cpp: binary,
// bvh_traverse_wide.cpp: 8-wide) share. It is the oracle the OpenCL kernels (kernels/traverse.h,
// kernels/traverse8.h) are tested against, so it is the specification and the kernels copy it
// operation for operation (all float, no fused multiply-adds: wp_bvh is built with
// -ffp-contract=off, and OpenCL kernels need FP_CONTRACT OFF to match bit for bit):
//
//   slab test   inv_d[k] = 1 / (|d[k]| > 1e-20 ? d[k] : copysign(1e-20, d[k]))
//               t0 = (lo - o) * inv_d, t1 = (hi - o) * inv_d per axis
//               tnear = max(max(min(t0x,t1x), min(t0y,t1y)), max(min(t0z,t1z), tmin))
//               tfar  = min(min(max(t0x,t1x), max(t0y,t1y)), min(max(t0z,t1z), tmax_current))
//               entered iff tnear <= tfar
//   triangle    Moller-Trumbore, cross and dot written out component by component (see below);
//               a hit iff tmin < t < tmax_current, so a later triangle replaces only if closer.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

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

struct PreparedRay {
  float ox, oy, oz, dx, dy, dz, ix, iy, iz, tmin;
  explicit PreparedRay(const Ray& r)
      : ox(r.o.x),
        oy(r.o.y),
        oz(r.o.z),
        dx(r.d.x),
        dy(r.d.y),
        dz(r.d.z),
        ix(safe_rcp(r.d.x)),
        iy(safe_rcp(r.d.y)),
        iz(safe_rcp(r.d.z)),
        tmin(r.tmin) {}
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

// One stored triangle, whichever layout it comes from.
struct TriangleData {
  float v0x, v0y, v0z;
  float e1x, e1y, e1z;
  float e2x, e2y, e2z;
  std::uint32_t flags;  // WP_TRI_*
  std::uint32_t prim;   // scene triangle index
};

// Moller-Trumbore. det > 0 is a front-face hit (cross(e1, e2) faces against d). Returns whether
// tmin < t < tmax, and then fills `hit`.
inline bool triangle_test(const PreparedRay& r, const TriangleData& tri, float tmax, Hit& hit) {
  const float px = r.dy * tri.e2z - r.dz * tri.e2y;  // p = cross(d, e2)
  const float py = r.dz * tri.e2x - r.dx * tri.e2z;
  const float pz = r.dx * tri.e2y - r.dy * tri.e2x;
  const float det = tri.e1x * px + tri.e1y * py + tri.e1z * pz;
  if (det == 0.0f) return false;
  if ((tri.flags & WP_TRI_CULL_BACKFACE) && det < 0.0f) return false;
  const float inv = 1.0f / det;
  const float sx = r.ox - tri.v0x, sy = r.oy - tri.v0y, sz = r.oz - tri.v0z;  // s = o - v0
  const float u = (sx * px + sy * py + sz * pz) * inv;
  if (u < 0.0f || u > 1.0f) return false;
  const float qx = sy * tri.e1z - sz * tri.e1y;  // q = cross(s, e1)
  const float qy = sz * tri.e1x - sx * tri.e1z;
  const float qz = sx * tri.e1y - sy * tri.e1x;
  const float v = (r.dx * qx + r.dy * qy + r.dz * qz) * inv;
  if (v < 0.0f || u + v > 1.0f) return false;
  const float t = (tri.e2x * qx + tri.e2y * qy + tri.e2z * qz) * inv;
  if (!(t > r.tmin && t < tmax)) return false;
  hit.hit = true;
  hit.t = t, hit.u = u, hit.v = v;
  hit.triangle = tri.prim;
  return true;
}

// The width-8 traversal (bvh_traverse_wide.cpp): closest hit (any = false) or any hit within
// (ray.tmin, ray.tmax).
Hit trace_wide(const Bvh& bvh, const Ray& ray, bool any);

}  // namespace wp::bvh::detail
