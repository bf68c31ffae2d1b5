// CPU reference traversal of the binary layout (the arithmetic is in traverse_common.h) and the
// public entry points, which pick the traversal by bvh.width.
//
// Traversal order at an inner node: both child boxes are tested against the current tmax; a hit
// leaf child is intersected right away (child 0 before child 1); of the hit inner children the
// nearer (smaller tnear, tie: child 0) is visited next and the other pushed on the stack.
#include <limits>

#include "traverse_common.h"

namespace wp::bvh {
namespace {

using detail::PreparedRay;

// Slab test; returns the entry distance, or +inf when the box is not entered within [tmin, tmax].
float box_entry(const PreparedRay& r, float lox, float hix, float loy, float hiy, float loz,
                float hiz, float tmax) {
  float tnear;
  return detail::slab_test(r, lox, hix, loy, hiy, loz, hiz, tmax, tnear)
             ? tnear
             : std::numeric_limits<float>::infinity();
}

detail::TriangleData triangle_data(const dev::IsectTri& t) {
  return detail::TriangleData{
      {{t.v0.x, t.v0.y, t.v0.z}, {t.v1.x, t.v1.y, t.v1.z}, {t.v2.x, t.v2.y, t.v2.z}},
      detail::float_bits(t.v1.w),
      detail::float_bits(t.v0.w)};
}

// Intersects leaf reference `ref` (count triangles), entered at `tleaf`, against the closest hit so
// far (tmax its distance; triangle_test's rule); with `any`, stops at the first hit. Returns
// whether anything was hit.
bool leaf_test(const Bvh& bvh, const PreparedRay& r, std::int32_t ref, std::int32_t count,
               float tleaf, Hit& hit, float& tmax, bool any) {
  bool found = false;
  const std::size_t first = static_cast<std::size_t>(~ref);
  for (std::int32_t i = 0; i < count; ++i) {
    const dev::IsectTri& tri = bvh.triangles[first + static_cast<std::size_t>(i)];
    if (detail::triangle_test(r, triangle_data(tri), tleaf, tmax, hit)) {
      found = true;
      tmax = hit.t;
      if (any) return true;
    }
  }
  return found;
}

}  // namespace

namespace detail {

// Closest hit (any = false) or any hit (any = true) within (ray.tmin, ray.tmax), from node `root`.
Hit trace_binary(const Bvh& bvh, const Ray& ray, bool any, std::int32_t root) {
  Hit hit;
  if (bvh.nodes.empty()) return hit;
  const PreparedRay r(ray);
  constexpr float kMiss = std::numeric_limits<float>::infinity();
  float tmax = ray.tmax;
  std::int32_t stack[WP_BVH_STACK_SIZE];
  int sp = 0;
  std::int32_t node = root;
  for (;;) {
    const dev::BvhNode& n = bvh.nodes[static_cast<std::size_t>(node)];
    const dev::float4 a = n.c0_xy, b = n.c1_xy, z = n.c01_z;
    const dev::int4 link = n.link;
    float t0 = box_entry(r, a.x, a.y, a.z, a.w, z.x, z.y, tmax);
    float t1 = box_entry(r, b.x, b.y, b.z, b.w, z.z, z.w, tmax);
    if (t0 < kMiss && link.x < 0) {
      if (leaf_test(bvh, r, link.x, link.z, t0, hit, tmax, any) && any) return hit;
      t0 = kMiss;
    }
    if (t1 < kMiss && link.y < 0) {
      if (leaf_test(bvh, r, link.y, link.w, t1, hit, tmax, any) && any) return hit;
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

}  // namespace detail

Hit intersect_closest(const Bvh& bvh, const Ray& ray) {
  if (!bvh.instances.empty()) return detail::trace_instances(bvh, ray, false);
  return bvh.width == WP_BVH8_WIDTH ? detail::trace_wide(bvh, ray, false)
                                    : detail::trace_binary(bvh, ray, false);
}

bool occluded(const Bvh& bvh, const Ray& ray) {
  if (!bvh.instances.empty()) return detail::trace_instances(bvh, ray, true).hit;
  return (bvh.width == WP_BVH8_WIDTH ? detail::trace_wide(bvh, ray, true)
                                     : detail::trace_binary(bvh, ray, true))
      .hit;
}

bool intersect_triangle(const dev::IsectTri& tri, const Ray& ray, float tmax, Hit& hit) {
  // No leaf: its distance is t itself (tleaf = tmin < t).
  return detail::triangle_test(PreparedRay(ray), triangle_data(tri), ray.tmin, tmax, hit);
}

}  // namespace wp::bvh
