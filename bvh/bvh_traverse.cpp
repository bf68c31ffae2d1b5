// CPU reference traversal of the flattened BVH: the oracle the OpenCL kernels (kernels/traverse.h)
// are tested against, so the arithmetic below is the specification and the kernels copy it
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
//
// Traversal order at an inner node: both child boxes are tested against the current tmax; a hit
// leaf child is intersected right away (child 0 before child 1); of the hit inner children the
// nearer (smaller tnear, tie: child 0) is visited next and the other pushed on the stack.
#include <cmath>
#include <cstring>
#include <limits>

#include "bvh.h"
#include "host/error.h"

namespace wp::bvh {
namespace {

std::uint32_t float_bits(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

float safe_rcp(float d) {
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

// NaN-free inputs only (the builder rejects non-finite vertices), so std::min/max agree with
// OpenCL's fmin/fmax.
float fmin2(float a, float b) {
  return b < a ? b : a;
}
float fmax2(float a, float b) {
  return a < b ? b : a;
}

// Slab test; returns the entry distance, or +inf when the box is not entered within [tmin, tmax].
float box_entry(const PreparedRay& r, float lox, float hix, float loy, float hiy, float loz,
                float hiz, float tmax) {
  const float tx0 = (lox - r.ox) * r.ix, tx1 = (hix - r.ox) * r.ix;
  const float ty0 = (loy - r.oy) * r.iy, ty1 = (hiy - r.oy) * r.iy;
  const float tz0 = (loz - r.oz) * r.iz, tz1 = (hiz - r.oz) * r.iz;
  const float tnear =
      fmax2(fmax2(fmin2(tx0, tx1), fmin2(ty0, ty1)), fmax2(fmin2(tz0, tz1), r.tmin));
  const float tfar = fmin2(fmin2(fmax2(tx0, tx1), fmax2(ty0, ty1)), fmin2(fmax2(tz0, tz1), tmax));
  return tnear <= tfar ? tnear : std::numeric_limits<float>::infinity();
}

// Moller-Trumbore. det > 0 is a front-face hit (cross(e1, e2) faces against d).
bool triangle_test(const PreparedRay& r, const dev::IsectTri& tri, float tmax, Hit& hit) {
  const dev::float4 v0 = tri.v0, e1 = tri.e1, e2 = tri.e2;
  const float px = r.dy * e2.z - r.dz * e2.y;  // p = cross(d, e2)
  const float py = r.dz * e2.x - r.dx * e2.z;
  const float pz = r.dx * e2.y - r.dy * e2.x;
  const float det = e1.x * px + e1.y * py + e1.z * pz;
  if (det == 0.0f) return false;
  if ((float_bits(e1.w) & WP_TRI_CULL_BACKFACE) && det < 0.0f) return false;
  const float inv = 1.0f / det;
  const float sx = r.ox - v0.x, sy = r.oy - v0.y, sz = r.oz - v0.z;  // s = o - v0
  const float u = (sx * px + sy * py + sz * pz) * inv;
  if (u < 0.0f || u > 1.0f) return false;
  const float qx = sy * e1.z - sz * e1.y;  // q = cross(s, e1)
  const float qy = sz * e1.x - sx * e1.z;
  const float qz = sx * e1.y - sy * e1.x;
  const float v = (r.dx * qx + r.dy * qy + r.dz * qz) * inv;
  if (v < 0.0f || u + v > 1.0f) return false;
  const float t = (e2.x * qx + e2.y * qy + e2.z * qz) * inv;
  if (!(t > r.tmin && t < tmax)) return false;
  hit.hit = true;
  hit.t = t, hit.u = u, hit.v = v;
  hit.triangle = float_bits(v0.w);
  return true;
}

// Intersects leaf reference `ref` (count triangles) against (tmin, hit.t); with `any`, stops at
// the first hit. Returns whether anything was hit.
bool leaf_test(const Bvh& bvh, const PreparedRay& r, std::int32_t ref, std::int32_t count, Hit& hit,
               float& tmax, bool any) {
  bool found = false;
  const std::size_t first = static_cast<std::size_t>(~ref);
  for (std::int32_t i = 0; i < count; ++i) {
    if (triangle_test(r, bvh.triangles[first + static_cast<std::size_t>(i)], tmax, hit)) {
      found = true;
      tmax = hit.t;
      if (any) return true;
    }
  }
  return found;
}

// Closest hit (any = false) or any hit (any = true) within (ray.tmin, ray.tmax).
Hit trace(const Bvh& bvh, const Ray& ray, bool any) {
  Hit hit;
  if (bvh.nodes.empty()) return hit;
  const PreparedRay r(ray);
  constexpr float kMiss = std::numeric_limits<float>::infinity();
  float tmax = ray.tmax;
  std::int32_t stack[WP_BVH_STACK_SIZE];
  int sp = 0;
  std::int32_t node = 0;
  for (;;) {
    const dev::BvhNode& n = bvh.nodes[static_cast<std::size_t>(node)];
    const dev::float4 a = n.c0_xy, b = n.c1_xy, z = n.c01_z;
    const dev::int4 link = n.link;
    float t0 = box_entry(r, a.x, a.y, a.z, a.w, z.x, z.y, tmax);
    float t1 = box_entry(r, b.x, b.y, b.z, b.w, z.z, z.w, tmax);
    if (t0 < kMiss && link.x < 0) {
      if (leaf_test(bvh, r, link.x, link.z, hit, tmax, any) && any) return hit;
      t0 = kMiss;
    }
    if (t1 < kMiss && link.y < 0) {
      if (leaf_test(bvh, r, link.y, link.w, hit, tmax, any) && any) return hit;
      t1 = kMiss;
    }
    if (t0 < kMiss && t1 < kMiss) {
      const bool first0 = t0 <= t1;
      if (sp == WP_BVH_STACK_SIZE) throw Error("BVH traversal: stack overflow (tree too deep)");
      stack[sp++] = first0 ? link.y : link.x;
      node = first0 ? link.x : link.y;
    } else if (t0 < kMiss) {
      node = link.x;
    } else if (t1 < kMiss) {
      node = link.y;
    } else {
      if (sp == 0) break;
      node = stack[--sp];
    }
  }
  return hit;
}

}  // namespace

Hit intersect_closest(const Bvh& bvh, const Ray& ray) {
  return trace(bvh, ray, false);
}

bool occluded(const Bvh& bvh, const Ray& ray) {
  return trace(bvh, ray, true).hit;
}

bool intersect_triangle(const dev::IsectTri& tri, const Ray& ray, float tmax, Hit& hit) {
  return triangle_test(PreparedRay(ray), tri, tmax, hit);
}

}  // namespace wp::bvh
